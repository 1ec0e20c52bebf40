//! Skjermo's step sixteen stems at a time: the fast CPU path.
//!
//! `cpu::skjermo::skjermo_step` is the reference (the twin of `skjermo_step.wgsl`, one stem per
//! invocation). This module computes the same step on groups of sixteen stems held as
//! structure-of-arrays lanes ([`crate::simd::F32x16`]), with the per-stem constants that do not change
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
//! The wind is sampled on all sixteen lanes at once ([`crate::wind::lanes`]: a polynomial sine,
//! integer sharpness by repeated multiplication). Results agree with the
//! reference to rounding (tested), and are identical whatever the thread count (every group is
//! computed by the same instructions whichever thread runs it) and whatever the instruction
//! set (`simd.rs`: AVX2 where the CPU has it, tested against the baseline).

use super::skjermo::{RawSkjermoStem, bezier_d};
use crate::model::NONE;
use crate::simd::{Level, dispatch};
pub use crate::wind::lanes::LANES;
use crate::wind::lanes::{V, V3, wind_lanes};
use crate::wind::raw::{RawField, RawWave};
use glam::Vec3;
use rayon::prelude::*;
use std::ops::{Add, Sub};

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

/// Per-group constants of sixteen stems (padding lanes have no parent and zero sizes).
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

/// Per-group state of sixteen stems: control-point displacements and orientation vectors.
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

/// Gathers the parents' previous state for the sixteen lanes of a group (a trunk or padding
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
/// `level`: the instruction set to run on, [`crate::simd::level`] for the CPU's best (every
/// level gives the same bits).
pub fn step(
    level: Level,
    fields: &[RawField],
    waves: &[RawWave],
    stems: &[StemLanes],
    prev: &[StateLanes],
    step: LaneStep,
    next: &mut [StateLanes],
) {
    next.par_chunks_mut(16).zip(stems.par_chunks(16)).for_each(|(out, st)| {
        groups_at(level, fields, waves, st, prev, step, out);
    });
}

dispatch! {
/// The step for a run of groups.
fn groups_at(
    fields: &[RawField],
    waves: &[RawWave],
    stems: &[StemLanes],
    prev: &[StateLanes],
    step: LaneStep,
    next: &mut [StateLanes],
) {
    for (out, st) in next.iter_mut().zip(stems) {
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
    }
}
}
