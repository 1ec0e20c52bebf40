//! Skjermo's step eight stems at a time: the fast CPU path.
//!
//! `cpu::skjermo::skjermo_step` is the reference (the twin of `skjermo_step.wgsl`, one stem per
//! invocation). This module computes the same step on groups of eight stems held as
//! structure-of-arrays lanes (`wide::f32x8`), with the per-stem constants that do not change
//! between steps folded in at setup:
//!
//! * the parent's curve enters only through its displacement from rest, because a Bézier is
//!   linear in its control points: `B(P_rest + Δ, a) = B(P_rest, a) + B(Δ, a)`, so the shift of
//!   the attachment point is `Σ Bⱼ(a) Δⱼ` and the tangent is the rest tangent plus `B'(Δ, a)`;
//! * the rest attachment frame `F_rest` is stored, and every control point moves by
//!   `shift + (F_now − F_rest) · local`, which is exactly zero when nothing moved, so still air
//!   still reproduces the rest curves bit for bit;
//! * `p2_weight^exponent` is computed once per step, not once per stem.
//!
//! Wind fields of the paper's kind (constant and sum of sines, eqs. 11–14) are evaluated on
//! all eight lanes at once (a polynomial sine; integer sharpness by repeated multiplication);
//! other field kinds fall back to the scalar `wind_at` per lane. Results agree with the
//! reference to rounding (tested), and are identical whatever the thread count: every group is
//! computed by the same instructions whichever thread runs it.

use super::skjermo::{RawSkjermoStem, bezier_d};
use crate::cpu::wind_sample::field_at;
use crate::model::NONE;
use crate::wind::raw::{RawField, RawWave, kind};
use glam::Vec3;
use rayon::prelude::*;
use wide::{CmpGt, f32x8};

/// Stems per lane group.
pub const LANES: usize = 8;

type V = f32x8;

/// Three lanes of eight: x, y and z of eight vectors.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct V3 {
    /// x of each lane.
    pub x: V,
    /// y of each lane.
    pub y: V,
    /// z of each lane.
    pub z: V,
}

impl V3 {
    const ZERO: Self = Self { x: V::ZERO, y: V::ZERO, z: V::ZERO };
    #[inline(always)]
    fn splat(v: Vec3) -> Self {
        Self { x: V::splat(v.x), y: V::splat(v.y), z: V::splat(v.z) }
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self { x: self.x + o.x, y: self.y + o.y, z: self.z + o.z }
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self { x: self.x - o.x, y: self.y - o.y, z: self.z - o.z }
    }
    #[inline(always)]
    fn scale(self, s: V) -> Self {
        Self { x: self.x * s, y: self.y * s, z: self.z * s }
    }
    #[inline(always)]
    fn dot(self, o: Self) -> V {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    #[inline(always)]
    fn cross(self, o: Self) -> Self {
        Self { x: self.y * o.z - o.y * self.z, y: self.z * o.x - o.z * self.x, z: self.x * o.y - o.x * self.y }
    }
    #[inline(always)]
    fn length(self) -> V {
        self.dot(self).sqrt()
    }
    #[inline(always)]
    fn select(mask: V, a: Self, b: Self) -> Self {
        Self { x: mask.blend(a.x, b.x), y: mask.blend(a.y, b.y), z: mask.blend(a.z, b.z) }
    }
    /// `axis_or`: normalised where longer than 1e-6, else `fallback`.
    #[inline(always)]
    fn axis_or(self, fallback: Self) -> Self {
        let l = self.length();
        let ok = l.cmp_gt(V::splat(1e-6));
        let safe = ok.blend(l, V::ONE);
        // One reciprocal, as `animate::skjermo::unit_or`: the same rounding as the reference,
        // so the rest frames it builds are reproduced bit for bit.
        Self::select(ok, self.scale(V::ONE / safe), fallback)
    }
    /// glam's `normalize_or_zero`.
    #[inline(always)]
    fn normalize_or_zero(self) -> Self {
        let l = self.length();
        let ok = l.cmp_gt(V::ZERO) & l.is_finite();
        let safe = ok.blend(l, V::ONE);
        Self::select(ok, self.scale(V::ONE / safe), Self::ZERO)
    }
    /// glam's `any_orthogonal_vector`.
    #[inline(always)]
    fn any_orthogonal(self) -> Self {
        let m = self.x.abs().cmp_gt(self.y.abs());
        Self { x: m.blend(-self.z, V::ZERO), y: m.blend(V::ZERO, self.z), z: m.blend(self.x, -self.y) }
    }
    fn lane(&self, l: usize) -> Vec3 {
        Vec3::new(self.x.as_array_ref()[l], self.y.as_array_ref()[l], self.z.as_array_ref()[l])
    }
    fn from_lanes(v: [Vec3; LANES]) -> Self {
        Self { x: V::from(v.map(|a| a.x)), y: V::from(v.map(|a| a.y)), z: V::from(v.map(|a| a.z)) }
    }
}

/// The attachment frame `[T, N, B]` from a curve tangent and an orientation vector, as
/// `animate::skjermo::frame`.
#[inline(always)]
fn frame(tangent: V3, o: V3) -> [V3; 3] {
    let tan = tangent.axis_or(V3::splat(Vec3::Y));
    let n = o.sub(tan.scale(o.dot(tan)));
    // The fallback normal (O along the tangent) is computed only when a lane needs it.
    let n = if n.length().cmp_gt(V::splat(1e-6)).all() {
        n.axis_or(V3::ZERO)
    } else {
        n.axis_or(tan.any_orthogonal().axis_or(V3::splat(Vec3::X)))
    };
    [tan, n, tan.cross(n)]
}

/// Per-group constants of eight stems (padding lanes have no parent and zero sizes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StemLanes {
    /// Parent stem of each lane (`NONE` for a trunk or a padding lane).
    pub parent: [u32; LANES],
    /// Bernstein weights of the attachment parameter on the parent's curve.
    pub w: [V; 4],
    /// Weights of the derivative's differences `(3s², 6st, 3t²)`.
    pub dw: [V; 3],
    /// Rest tangent of the parent's curve at the attachment (a trunk: its own at 0).
    pub tan_rest: V3,
    /// Rest attachment frame.
    pub f_rest: [V3; 3],
    /// Control points relative to the attachment in the attachment frame.
    pub local: [V3; 4],
    /// Rest control points P1..P3.
    pub rest: [V3; 3],
    /// Static bend per (m/s)², rad·s²/m².
    pub drag: V,
    /// Arc length, m.
    pub length: V,
}

/// Per-group state of eight stems: control-point displacements and orientation vectors.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StateLanes {
    /// Displacements of P0..P3 from rest.
    pub delta: [V3; 4],
    /// Orientation vector O handed to children.
    pub orient: V3,
}

impl StateLanes {
    /// One stem's displacement of control point `j`.
    pub fn delta(&self, lane: usize, j: usize) -> Vec3 {
        self.delta[j].lane(lane)
    }
    /// One stem's orientation vector.
    pub fn orient(&self, lane: usize) -> Vec3 {
        self.orient.lane(lane)
    }
}

/// Builds the lane groups from the reference's per-stem constants; `rest_orient` gives each
/// stem's rest orientation vector. Returns the groups and the rest state.
pub fn build(stems: &[RawSkjermoStem], rest_orient: &[[f32; 4]]) -> (Vec<StemLanes>, Vec<StateLanes>) {
    let v = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
    let groups = stems.len().div_ceil(LANES);
    let mut lanes = Vec::with_capacity(groups);
    let mut state = Vec::with_capacity(groups);
    for g in 0..groups {
        let ks: [Option<usize>; LANES] = std::array::from_fn(|l| Some(g * LANES + l).filter(|&k| k < stems.len()));
        let parent = ks.map(|k| k.map_or(NONE, |k| stems[k].parent));
        let attach = ks.map(|k| k.map_or(0.0, |k| stems[k].attach));
        let has_parent = |l: usize| parent[l] != NONE;
        let w: [V; 4] = std::array::from_fn(|j| {
            V::from(std::array::from_fn::<f32, LANES, _>(|l| {
                if !has_parent(l) {
                    return 0.0;
                }
                let (t, s) = (attach[l], 1.0 - attach[l]);
                [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t][j]
            }))
        });
        let dw: [V; 3] = std::array::from_fn(|j| {
            V::from(std::array::from_fn::<f32, LANES, _>(|l| {
                if !has_parent(l) {
                    return 0.0;
                }
                let (t, s) = (attach[l], 1.0 - attach[l]);
                [3.0 * s * s, 6.0 * s * t, 3.0 * t * t][j]
            }))
        });
        let tan = ks.map(|k| {
            k.map_or(Vec3::ZERO, |k| {
                let st = &stems[k];
                if st.parent == NONE {
                    bezier_d(&st.rest.map(v), 0.0)
                } else {
                    bezier_d(&stems[st.parent as usize].rest.map(v), st.attach)
                }
            })
        });
        let o_rest = ks
            .map(|k| k.map_or(Vec3::X, |k| if stems[k].parent == NONE { Vec3::X } else { v(stems[k].parent_orient) }));
        let tan_rest = V3::from_lanes(tan);
        let f_rest = frame(tan_rest, V3::from_lanes(o_rest));
        let per =
            |f: &dyn Fn(&RawSkjermoStem) -> Vec3| V3::from_lanes(ks.map(|k| k.map_or(Vec3::ZERO, |k| f(&stems[k]))));
        let local = [0, 1, 2, 3].map(|j| per(&|s| v(s.local[j])));
        let rest = [1, 2, 3].map(|j| per(&|s| v(s.rest[j])));
        let scalar = |f: &dyn Fn(&RawSkjermoStem) -> f32| V::from(ks.map(|k| k.map_or(0.0, |k| f(&stems[k]))));
        lanes.push(StemLanes {
            parent,
            w,
            dw,
            tan_rest,
            f_rest,
            local,
            rest,
            drag: scalar(&|s| s.drag),
            length: scalar(&|s| s.length),
        });
        let orient = V3::from_lanes(ks.map(|k| k.map_or(Vec3::ZERO, |k| v(rest_orient[k]))));
        state.push(StateLanes { delta: [V3::ZERO; 4], orient });
    }
    (lanes, state)
}

/// Sine on eight lanes: reduced to [−π, π] by whole turns, then an odd degree-11 polynomial
/// fitted to sine by least squares on Chebyshev nodes (absolute error < 2e-6 on [−π, π]; the reference's `sin`
/// is correctly rounded, so the two paths differ by that much at most).
#[inline(always)]
fn sin(x: V) -> V {
    let turns = (x * V::splat(std::f32::consts::FRAC_1_PI * 0.5)).round();
    // Two-part 2π so the reduction stays exact for the arguments the wind produces.
    let r = x - turns * V::splat(6.28125) - turns * V::splat(0.001_935_307_2);
    let r2 = r * r;
    let p = V::splat(-2.053_034_2e-8) * r2 + V::splat(2.704_617_4e-6);
    let p = p * r2 + V::splat(-1.981_395_8e-4);
    let p = p * r2 + V::splat(8.332_666e-3);
    let p = p * r2 + V::splat(-1.666_661e-1);
    r + r * r2 * p
}

/// `x^k` for a small integer `k ≥ 0` by repeated squaring.
fn powi(mut x: V, mut k: u32) -> V {
    let mut r = V::ONE;
    while k > 0 {
        if k & 1 == 1 {
            r *= x;
        }
        x *= x;
        k >>= 1;
    }
    r
}

/// The wind scene at eight points (as `cpu::wind_sample::wind_at`).
#[inline(always)]
fn wind_lanes(fields: &[RawField], waves: &[RawWave], p: V3, t: f32) -> V3 {
    let mut v = V3::ZERO;
    for f in fields {
        match f.kind {
            kind::CONSTANT => v = v.add(V3::splat(Vec3::new(f.a[0], f.a[1], f.a[2]))),
            kind::SUM_OF_SINES => {
                let (sharp, mode) = (f.a[0], f.a[1]);
                let int_sharp = (sharp.fract() == 0.0 && (0.0..=16.0).contains(&sharp)).then_some(sharp as u32);
                for w in &waves[f.wave_offset as usize..(f.wave_offset + f.wave_count) as usize] {
                    let th = p.x * w.k[0] + p.y * w.k[1] + p.z * w.k[2] + V::splat(w.k[3] * t);
                    let s = sin(th);
                    let h = if mode < 0.5 {
                        s
                    } else {
                        let base = (s + V::ONE) * V::splat(0.5);
                        match int_sharp {
                            Some(k) => powi(base, k),
                            None => base.pow_f32x8(V::splat(sharp)),
                        }
                    };
                    v = v.add(V3::splat(Vec3::new(w.dir[0], w.dir[1], w.dir[2])).scale(h));
                }
            }
            _ => {
                let per: [Vec3; LANES] = std::array::from_fn(|l| field_at(f, waves, p.lane(l), t));
                v = v.add(V3::from_lanes(per));
            }
        }
    }
    v
}

/// Gathers the parents' previous state for the eight lanes of a group (a trunk or padding
/// lane sees no displacement and the orientation vector `X`, as the reference's trunk frame).
#[inline(always)]
fn gather(parent: &[u32; LANES], prev: &[StateLanes]) -> ([V3; 4], V3) {
    let mut d = [[[0.0f32; LANES]; 3]; 4];
    let mut o = [[1.0f32; LANES], [0.0; LANES], [0.0; LANES]];
    for (l, &p) in parent.iter().enumerate() {
        if p == NONE {
            continue;
        }
        let (g, pl) = (p as usize / LANES, p as usize % LANES);
        let s = &prev[g];
        for (j, dj) in d.iter_mut().enumerate() {
            dj[0][l] = s.delta[j].x.as_array_ref()[pl];
            dj[1][l] = s.delta[j].y.as_array_ref()[pl];
            dj[2][l] = s.delta[j].z.as_array_ref()[pl];
        }
        o[0][l] = s.orient.x.as_array_ref()[pl];
        o[1][l] = s.orient.y.as_array_ref()[pl];
        o[2][l] = s.orient.z.as_array_ref()[pl];
    }
    let v3 = |a: [[f32; LANES]; 3]| V3 { x: V::from(a[0]), y: V::from(a[1]), z: V::from(a[2]) };
    (d.map(v3), v3(o))
}

/// Step constants: time, and the method's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaneStep {
    /// Time, s.
    pub time: f32,
    /// `p2_weight^exponent` (eq. 16).
    pub p2_factor: f32,
    /// Largest static bend, rad.
    pub max_bend: f32,
}

/// One step for every group: re-attach on the parents' previous curves, sample the wind at
/// the tips, bend P2 and P3 (eqs. 15–17). Same step as `cpu::skjermo::skjermo_step`.
pub fn step(
    fields: &[RawField],
    waves: &[RawWave],
    stems: &[StemLanes],
    prev: &[StateLanes],
    step: LaneStep,
    next: &mut [StateLanes],
) {
    next.par_iter_mut().zip(stems.par_iter()).with_min_len(16).for_each(|(out, st)| {
        let (dp, o_now) = gather(&st.parent, prev);
        let mut shift = V3::ZERO;
        for (w, d) in st.w.iter().zip(&dp) {
            shift = shift.add(d.scale(*w));
        }
        let mut tan = st.tan_rest;
        for (j, w) in st.dw.iter().enumerate() {
            tan = tan.add(dp[j + 1].sub(dp[j]).scale(*w));
        }
        let f_now = frame(tan, o_now);
        let df = [0, 1, 2].map(|i| f_now[i].sub(st.f_rest[i]));
        let mut d = st.local.map(|l| shift.add(df[0].scale(l.x)).add(df[1].scale(l.y)).add(df[2].scale(l.z)));
        // Wind at the tip, bend factors (eq. 16), length-keeping update (eq. 17).
        let a = [st.rest[0].add(d[1]), st.rest[1].add(d[2]), st.rest[2].add(d[3])];
        let w = wind_lanes(fields, waves, a[2], step.time);
        let u = w.length();
        let theta = (st.drag * u * u).min(V::splat(step.max_bend));
        let c = st.length * theta;
        let bend = u.cmp_gt(V::ZERO) & c.cmp_gt(V::ZERO);
        let cu = c / bend.blend(u, V::ONE);
        let b3 = w.scale(cu);
        let b2 = w.scale(cu * V::splat(step.p2_factor));
        let d2 = a[1].sub(a[0]);
        let c2 = d2.add(b2).normalize_or_zero().scale(d2.length()).sub(d2);
        let p2 = a[1].add(c2);
        let d3 = a[2].sub(a[1]);
        let p3 = p2.add(d3.add(b3).normalize_or_zero().scale(d3.length()));
        let c3 = p3.sub(a[2].add(c2));
        let c2 = V3::select(bend, c2, V3::ZERO);
        let c3 = V3::select(bend, c3, V3::ZERO);
        d[2] = d[2].add(c2);
        d[3] = d[3].add(c2.add(c3));
        *out = StateLanes { delta: d, orient: f_now[1] };
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lane_sine_is_within_its_stated_error() {
        let mut worst = 0.0f32;
        for i in -200_000..=200_000 {
            let x = i as f32 * 0.05;
            let got = sin(V::splat(x)).as_array_ref()[0];
            worst = worst.max((got - x.sin()).abs());
        }
        // 2e-6 from the polynomial on [−π, π]; the reduction adds the rounding of x itself.
        assert!(worst < 4e-6, "worst error {worst}");
    }

    #[test]
    fn integer_powers_match_powf() {
        for k in 0..=16u32 {
            let x = 0.93f32;
            let got = powi(V::splat(x), k).as_array_ref()[0];
            assert!((got - x.powf(k as f32)).abs() <= 1e-6, "{k}: {got}");
        }
    }
}
