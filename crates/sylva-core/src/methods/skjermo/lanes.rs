//! Skjermo's step sixteen stems at a time: the fast CPU path.
//!
//! `kernels::skjermo_step` is the reference (the twin of `skjermo_step.wgsl`, one stem per
//! invocation). This module computes the same step on groups of sixteen stems held as
//! structure-of-arrays lanes ([`crate::simd::F32x16`]). At the larger sizes the step is bound
//! by memory traffic, so a group keeps only what cannot be recomputed cheaply (124 bytes of
//! constants per stem, 20 of them the bend oscillator's, against the reference's 160 + 16)
//! and derives the rest:
//!
//! * the parent's curve enters only through its displacement from rest, because a Bézier is
//!   linear in its control points: `B(P_rest + Δ, a) = B(P_rest, a) + B(Δ, a)`, so the shift of
//!   the attachment point is `Σ Bⱼ(a) Δⱼ` and the tangent is the rest tangent plus `B'(Δ, a)`,
//!   both with weights computed from the stored attachment parameter `a` (the tangent's in
//!   units of the rest tangent's length, so that the unit rest tangent is stored rather than
//!   recomputed);
//! * every control point moves by `shift + (F_now − F_rest) · local`, which is exactly zero
//!   when nothing moved, so still air still reproduces the rest curves bit for bit. Of the
//!   rest frame the tangent and normal are stored, the binormal recomputed by the same
//!   instructions that built it; the frame now is the rest frame turned by the shortest arc,
//!   without the reference's re-orthonormalisation (exact in exact arithmetic; every step
//!   turns the rest frame afresh, so rounding does not build up);
//! * the legs P1→P2 and P2→P3 are the local legs turned by the current frame, so of the rest
//!   control points only the tip (where the wind is sampled) is stored;
//! * `p2_weight^exponent` is computed once per step, not once per stem, and the bend
//!   oscillators' step coefficients, folded with their ω² and ζω, once per step length
//!   ([`coefficients`]);
//! * reconfiguration's power `(1 + (u/U_r)²)^(B/2)` by polynomials ([`pow_ge1`]), not a library
//!   call per lane, from `u²` (no division by `U_r`);
//! * each leg is kept at its length by one square root of the ratio of squared lengths
//!   (`turned`), not two;
//! * the parents' state is fetched with AVX2's gather instruction where the CPU has it.
//!
//! The wind is sampled on all sixteen lanes at once ([`crate::wind::lanes`]: a polynomial sine,
//! integer sharpness by repeated multiplication). Results agree with the
//! reference to rounding (tested), and are identical whatever the thread count (every group is
//! computed by the same instructions whichever thread runs it) and whatever the instruction
//! set (`simd.rs`: AVX2 where the CPU has it, tested against the baseline).

use super::{RawSkjermoMode, RawSkjermoStem, bezier_d};
use crate::model::NONE;
use crate::simd::{Level, dispatch};
pub use crate::wind::lanes::LANES;
pub use crate::wind::lanes::pow_ge1;
use crate::wind::lanes::{V, V3, wind_lanes};
use crate::wind::raw::{RawField, RawWave};
use bytemuck::Zeroable;
use glam::Vec3;
use rayon::prelude::*;
use std::ops::{Add, Sub};

/// The attachment frame `[T, N, B]` from a curve tangent and an orientation vector, as
/// `methods::skjermo::frame`.
#[inline(always)]
fn frame(tangent: V3, o: V3) -> [V3; 3] {
    let tan = unit_tangent(tangent);
    let n = unit_normal(o.sub(tan.scale(o.dot(tan))), tan);
    [tan, n, tan.cross(n)]
}

/// `n` (normal to the unit `tan`) made unit: one reciprocal where every lane is longer than
/// 1e-6; else, as `methods::skjermo::unit_or`, each lane's own, with `tan`'s orthogonal (then
/// X) where it is too short (O along the tangent).
#[inline(always)]
fn unit_normal(n: V3, tan: V3) -> V3 {
    let nl = n.length();
    if nl.cmp_gt(V::splat(1e-6)).all() {
        n.scale(V::ONE / nl)
    } else {
        n.axis_or(tan.any_orthogonal().axis_or(V3::splat(Vec3::X)))
    }
}

/// The attachment frame now, as `methods::skjermo::transported_frame`: the rest frame
/// (`t_rest`, `n_rest`, `b_rest`) turned by the shortest arc to the parent curve's `tangent`
/// (in units of the rest tangent's length); the rest frame itself, bit for bit, in lanes whose
/// tangent is the rest one. Where every lane turns by less than half a turn the turned normal
/// is used as it is: it is unit and normal to the tangent but for rounding, which does not
/// build up (every step turns the rest frame afresh), so the reference's re-orthonormalisation
/// is left out.
#[inline(always)]
fn transported_frame(t_rest: V3, n_rest: V3, b_rest: V3, tangent: V3) -> [V3; 3] {
    let same = tangent.x.cmp_eq(t_rest.x) & tangent.y.cmp_eq(t_rest.y) & tangent.z.cmp_eq(t_rest.z);
    if same.all() {
        return [t_rest, n_rest, b_rest];
    }
    let t = unit_tangent(tangent);
    let (k, c) = (t_rest.cross(t), t_rest.dot(t));
    let one_c = V::ONE + c;
    let turning = one_c.cmp_gt(V::splat(1e-6));
    let turned = n_rest.scale(c).add(k.cross(n_rest)).add(k.scale(k.dot(n_rest) / turning.blend(one_c, V::ONE)));
    let n = if turning.all() {
        turned
    } else {
        let m = V3::select(turning, turned, n_rest);
        unit_normal(m.sub(t.scale(m.dot(t))), t)
    };
    let n = V3::select(same, n_rest, n);
    let t = V3::select(same, t_rest, t);
    [t, n, t.cross(n)]
}

/// The frame's unit tangent: `axis_or(Y)`, which where every lane is long enough (all but
/// degenerate groups) is a plain scale by the reciprocal, bit for bit.
#[inline(always)]
fn unit_tangent(tangent: V3) -> V3 {
    let tl = tangent.length();
    if tl.cmp_gt(V::splat(1e-6)).all() { tangent.scale(V::ONE / tl) } else { tangent.axis_or(V3::splat(Vec3::Y)) }
}

/// Per-group constants of sixteen stems (padding lanes have no parent and zero sizes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StemLanes {
    /// Parent stem of each lane (`NONE` for a trunk or a padding lane).
    pub parent: [u32; LANES],
    /// Attachment parameter `a` on the parent's curve (0 for a trunk or padding lane, whose
    /// gathered parent displacements are zero).
    pub attach: V,
    /// Rest attachment frame's tangent: the unit rest tangent of the parent's curve at the
    /// attachment (a trunk: its own at 0).
    pub t_rest: V3,
    /// The reciprocal of that tangent's length before it was made unit, 1/m: the parent's
    /// curve's tangent now, in these units, is `t_rest` plus the derivative of its
    /// displacement times this.
    pub tan_scale: V,
    /// Rest attachment frame's normal (its binormal, `t_rest × n_rest`, is recomputed).
    pub n_rest: V3,
    /// Control points relative to the attachment in the attachment frame.
    pub local: [V3; 4],
    /// Rest tip P3 (where the wind is sampled).
    pub rest_tip: V3,
    /// Static bend per (m/s)², rad·s²/m².
    pub drag: V,
    /// Arc length, m.
    pub length: V,
    /// The bend oscillator's aerodynamic damping per m/s of wind, 1/m (its other constants
    /// are folded into [`OscLanes`]).
    pub aero: V,
}

/// The bend oscillators' step over one step length for sixteen stems:
/// [`crate::physics::oscillator::damped_coefficients`]' `(C, S)` folded with the oscillator's
/// ω² and ζω, so that the step is `b' = p + A (b − p) + S ḃ`, `ḃ' = D ḃ − E (b − p)` (`p` the
/// push): `damped_apply`'s step, rounded differently.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OscLanes {
    /// A = C + ζω S.
    pub a: V,
    /// S, s.
    pub s: V,
    /// D = C − ζω S.
    pub d: V,
    /// E = ω² S, 1/s.
    pub e: V,
}

/// Each group's oscillator coefficients for steps of `dt` seconds, from the per-stem modes
/// (a padding lane's: a rest oscillator's).
pub fn coefficients(modes: &[RawSkjermoMode], dt: f32) -> Vec<OscLanes> {
    modes
        .chunks(LANES)
        .map(|g| {
            let k: [[f32; 4]; LANES] = std::array::from_fn(|l| {
                let m = g.get(l).copied().unwrap_or_else(RawSkjermoMode::zeroed);
                let (c, s) = crate::physics::oscillator::damped_coefficients(m.w2, m.damping, dt);
                [c + m.damping * s, s, c - m.damping * s, m.w2 * s]
            });
            let lane = |i: usize| V::from(k.map(|x| x[i]));
            OscLanes { a: lane(0), s: lane(1), d: lane(2), e: lane(3) }
        })
        .collect()
}

/// Per-group displacements of sixteen stems' control points from rest, in memory twelve
/// lanes-of-sixteen, component after component (`delta[0].x` … `delta[3].z`), which the AVX2
/// gather relies on. Children read their parents' from the previous step, so the step
/// writes them to a second buffer.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C)]
pub struct StateLanes {
    /// Displacements of P0..P3 from rest.
    pub delta: [V3; 4],
}

impl StateLanes {
    /// One stem's displacement of control point `j`.
    pub fn delta(&self, lane: usize, j: usize) -> Vec3 {
        self.delta[j].lane(lane)
    }
}

/// Per-group bend oscillators of sixteen stems. Only a stem's own step reads its oscillator,
/// so the step updates them in place: a second buffer would cost their cache lines' reads
/// for ownership on every step (the step is bound by memory traffic at the larger sizes).
/// The published form leaves them at rest.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SwayLanes {
    /// The tip's bend vector b₃, m.
    pub bend: V3,
    /// Its rate of change, m/s.
    pub rate: V3,
}

/// Builds the lane groups from the reference's per-stem constants. Returns the groups and
/// the rest state.
pub fn build(stems: &[RawSkjermoStem], modes: &[RawSkjermoMode]) -> (Vec<StemLanes>, Vec<StateLanes>) {
    let v = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
    let groups = stems.len().div_ceil(LANES);
    let mut lanes = Vec::with_capacity(groups);
    let mut state = Vec::with_capacity(groups);
    for g in 0..groups {
        let ks: [Option<usize>; LANES] = std::array::from_fn(|l| Some(g * LANES + l).filter(|&k| k < stems.len()));
        let parent = ks.map(|k| k.map_or(NONE, |k| stems[k].parent));
        let attach = ks.map(|k| k.map_or(0.0, |k| if stems[k].parent == NONE { 0.0 } else { stems[k].attach }));
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
        let tan_length = tan_rest.length();
        let tan_scale = tan_length.cmp_gt(V::splat(1e-6)).blend(V::ONE / tan_length, V::ONE);
        let per =
            |f: &dyn Fn(&RawSkjermoStem) -> Vec3| V3::from_lanes(ks.map(|k| k.map_or(Vec3::ZERO, |k| f(&stems[k]))));
        let local = [0, 1, 2, 3].map(|j| per(&|s| v(s.local[j])));
        let rest_tip = per(&|s| v(s.rest[3]));
        let scalar = |f: &dyn Fn(&RawSkjermoStem) -> f32| V::from(ks.map(|k| k.map_or(0.0, |k| f(&stems[k]))));
        lanes.push(StemLanes {
            parent,
            attach: V::from(attach),
            t_rest: f_rest[0],
            tan_scale,
            n_rest: f_rest[1],
            local,
            rest_tip,
            drag: scalar(&|s| s.drag),
            length: scalar(&|s| s.length),
            aero: V::from(ks.map(|k| k.map_or(0.0, |k| modes[k].aero))),
        });
        state.push(StateLanes { delta: [V3::ZERO; 4] });
    }
    (lanes, state)
}

/// Floats in one [`StateLanes`].
const STATE_FLOATS: usize = 12 * LANES;
const _: () = assert!(std::mem::size_of::<StateLanes>() == STATE_FLOATS * 4);

/// Gathers the parents' previous displacements for the sixteen lanes of a group (a trunk or
/// padding lane sees none; nor does a lane whose parent lies outside `prev`, as in
/// [`gather_avx2`]).
#[inline(always)]
fn gather(parent: &[u32; LANES], prev: &[StateLanes]) -> [V3; 4] {
    let mut d = [[[0.0f32; LANES]; 3]; 4];
    for (l, &p) in parent.iter().enumerate() {
        let (g, pl) = (p as usize / LANES, p as usize % LANES);
        let Some(s) = prev.get(g) else {
            continue;
        };
        for (j, dj) in d.iter_mut().enumerate() {
            dj[0][l] = s.delta[j].x.as_array_ref()[pl];
            dj[1][l] = s.delta[j].y.as_array_ref()[pl];
            dj[2][l] = s.delta[j].z.as_array_ref()[pl];
        }
    }
    let v3 = |a: [[f32; LANES]; 3]| V3 { x: V::from(a[0]), y: V::from(a[1]), z: V::from(a[2]) };
    [v3(d[0]), v3(d[1]), v3(d[2]), v3(d[3])]
}

/// [`gather`] with AVX2's gather instruction: twelve component loads of eight lanes each,
/// twice, instead of 192 scalar copies (the same values: a gather only moves bits). A parent
/// at or beyond the end of `prev` is read as none, so no lane reads out of bounds.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(unsafe_code)]
fn gather_avx2(parent: &[u32; LANES], prev: &[StateLanes]) -> [V3; 4] {
    use std::arch::x86_64::*;
    // `step` checks that every float index fits an i32.
    let last = (prev.len() * LANES).saturating_sub(1) as i32;
    let base = prev.as_ptr().cast::<f32>();
    let mut c = [V::ZERO; 12];
    for h in 0..2 {
        // SAFETY: AVX2 is enabled for this function. `parent` holds sixteen u32, read as two
        // unaligned halves of eight. A lane is gathered only where its parent is at most
        // `last`, so its index `(p / 16) · 192 + p % 16 + 16 · component` lies inside `prev`
        // (`prev` is `repr(C)`, twelve lanes-of-sixteen per group); other lanes keep `c`'s
        // defaults. Stores go to `c`'s arrays, eight floats at offset 0 or 8.
        unsafe {
            let p = _mm256_loadu_si256(parent.as_ptr().add(8 * h).cast());
            let inside = _mm256_cmpeq_epi32(_mm256_min_epu32(p, _mm256_set1_epi32(last)), p);
            let idx = _mm256_add_epi32(
                _mm256_mullo_epi32(_mm256_srli_epi32::<4>(p), _mm256_set1_epi32(STATE_FLOATS as i32)),
                _mm256_and_si256(p, _mm256_set1_epi32(LANES as i32 - 1)),
            );
            let mask = _mm256_castsi256_ps(inside);
            for (k, ck) in c.iter_mut().enumerate() {
                let dst = ck.0.as_mut_ptr().add(8 * h);
                let v = _mm256_mask_i32gather_ps::<4>(_mm256_loadu_ps(dst), base.add(k * LANES), idx, mask);
                _mm256_storeu_ps(dst, v);
            }
        }
    }
    let v3 = |k: usize| V3 { x: c[k], y: c[k + 1], z: c[k + 2] };
    [v3(0), v3(3), v3(6), v3(9)]
}

/// A control point's displacement: the attachment's shift plus the frame's change applied to
/// its local coordinates.
#[inline(always)]
fn moved(shift: V3, df: &[V3; 3], l: V3) -> V3 {
    shift.add(df[0].scale(l.x)).add(df[1].scale(l.y)).add(df[2].scale(l.z))
}

/// How far the end of `leg` moves when the leg is turned toward `push` and kept at its length
/// (eq. 17): `(leg + push)` scaled to `|leg|`, less `leg`; by one square root of the squared
/// lengths' ratio, rather than `V3::with_length`'s two (a lane whose turned leg is zero, or too
/// short or long to square, is not turned: `-leg`, as `with_length` gives).
#[inline(always)]
fn turned(leg: V3, push: V3) -> V3 {
    let v = leg.add(push);
    let vv = v.dot(v);
    let positive = vv.cmp_gt(V::ZERO);
    let ratio = (leg.dot(leg) / positive.blend(vv, V::ONE)).sqrt();
    let ok = positive & vv.is_finite() & ratio.is_finite();
    V3::select(ok, v.scale(ratio), V3::ZERO).sub(leg)
}

/// Frame coordinates `l` as a world vector: `F · l`.
#[inline(always)]
fn in_frame(f: &[V3; 3], l: V3) -> V3 {
    f[0].scale(l.x).add(f[1].scale(l.y)).add(f[2].scale(l.z))
}

/// Step constants: time, and the method's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaneStep {
    /// Time, s.
    pub time: f32,
    /// Step length, s (the coefficients handed to [`step`] must be for it).
    pub dt: f32,
    /// The bend follows the wind as a damped oscillator (else at once).
    pub dynamics: bool,
    /// `p2_weight^exponent` (eq. 16).
    pub p2_factor: f32,
    /// Largest static bend, rad.
    pub max_bend: f32,
    /// Reconfiguration speed U_r, m/s.
    pub reconfiguration_speed: f32,
    /// Vogel exponent B.
    pub vogel_exponent: f32,
}

/// One step for every group: re-attach on the parents' previous curves, sample the wind at
/// the tips, advance the bend oscillators `sway` in place (`coefficients`: [`coefficients`]
/// for `step.dt`; untouched in the published form), bend P2 and P3 (eqs. 15–17). Same step
/// as `kernels::skjermo_step`.
/// `level`: the instruction set to run on, [`crate::simd::level`] for the CPU's best (every
/// level gives the same bits).
#[allow(clippy::too_many_arguments)]
pub fn step(
    level: Level,
    fields: &[RawField],
    waves: &[RawWave],
    stems: &[StemLanes],
    coefficients: &[OscLanes],
    prev: &[StateLanes],
    sway: &mut [SwayLanes],
    step: LaneStep,
    next: &mut [StateLanes],
) {
    assert_eq!(coefficients.len(), stems.len(), "skjermo_lanes::step: oscillator coefficients per group");
    assert!(
        prev.len() == stems.len() && next.len() == stems.len() && sway.len() == stems.len(),
        "skjermo_lanes::step: {} stem groups, {} and {} state groups, {} oscillator groups",
        stems.len(),
        prev.len(),
        next.len(),
        sway.len()
    );
    // The AVX2 gather indexes `prev` in floats with i32.
    let fast_gather =
        level.min(crate::simd::detected()) == Level::Avx2 && prev.len() * STATE_FLOATS <= i32::MAX as usize;
    next.par_chunks_mut(16).zip(sway.par_chunks_mut(16)).zip(stems.par_chunks(16)).enumerate().for_each(
        |(c, ((out, sw), st))| {
            let cs = &coefficients[16 * c..16 * c + out.len()];
            groups_at(level, fields, waves, st, cs, prev, sw, step, fast_gather, out);
        },
    );
}

dispatch! {
/// The step for a run of groups; `fast_gather`: fetch the parents with [`gather_avx2`] (set
/// only where the CPU has AVX2 and the AVX2 level was asked for).
#[allow(clippy::too_many_arguments)]
fn groups_at(
    fields: &[RawField],
    waves: &[RawWave],
    stems: &[StemLanes],
    coefficients: &[OscLanes],
    prev: &[StateLanes],
    sway: &mut [SwayLanes],
    step: LaneStep,
    fast_gather: bool,
    next: &mut [StateLanes],
) {
    for (((out, st), cs), osc) in next.iter_mut().zip(stems).zip(coefficients).zip(sway) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `fast_gather` is set only at the AVX2 level, which `step` runs only where
        // the CPU has AVX2.
        #[allow(unsafe_code)]
        let dp = if fast_gather { unsafe { gather_avx2(&st.parent, prev) } } else { gather(&st.parent, prev) };
        #[cfg(not(target_arch = "x86_64"))]
        let dp = {
            let _ = fast_gather;
            gather(&st.parent, prev)
        };
        // The attachment point's shift `Σ wⱼ Δⱼ` (Bernstein weights of `a`) and the parent
        // curve's tangent there, `tan_rest + B'(Δ, a)` with `B'(Δ, a) = Σ eⱼ Δⱼ`,
        // `e = (−3s², 3s² − 6st, 6st − 3t², 3t²)`, in units of the rest tangent's length (the
        // frame only needs its direction). Computed here rather than stored: the step is bound
        // by memory traffic at the larger sizes.
        let (t, s) = (st.attach, V::ONE - st.attach);
        let (ss, st_, tt) = (s * s, s * t, t * t);
        let w = [ss * s, V::splat(3.0) * ss * t, V::splat(3.0) * s * tt, tt * t];
        let dw = [V::splat(3.0) * ss * st.tan_scale, V::splat(6.0) * st_ * st.tan_scale, V::splat(3.0) * tt * st.tan_scale];
        let e = [-dw[0], dw[0] - dw[1], dw[1] - dw[2], dw[2]];
        let (mut shift, mut tan) = (V3::ZERO, st.t_rest);
        for (j, dj) in dp.iter().enumerate() {
            shift = shift.add(dj.scale(w[j]));
            tan = tan.add(dj.scale(e[j]));
        }
        // Written out, not with `array::map` or a closure: neither is inlined into the AVX2
        // body, and they would run as baseline code.
        let b_rest = st.t_rest.cross(st.n_rest);
        let f_now = transported_frame(st.t_rest, st.n_rest, b_rest, tan);
        let df = [f_now[0].sub(st.t_rest), f_now[1].sub(st.n_rest), f_now[2].sub(b_rest)];
        // P0 and P1 only follow the attachment: written at once, so that fewer values stay
        // live across the wind.
        out.delta[0] = moved(shift, &df, st.local[0]);
        let d1 = moved(shift, &df, st.local[1]);
        out.delta[1] = d1;
        let d2 = moved(shift, &df, st.local[2]);
        let d3 = moved(shift, &df, st.local[3]);
        // Wind at the tip and the static push b₃ = c ŵ (eq. 16), which the bend follows as
        // the stem's damped first mode (or at once).
        let w = wind_lanes(fields, waves, st.rest_tip.add(d3), step.time);
        let uu = w.dot(w);
        let u = uu.sqrt();
        let g = if step.vogel_exponent == 0.0 {
            V::ONE
        } else {
            let ur = step.reconfiguration_speed;
            pow_ge1(V::ONE + uu * V::splat(1.0 / (ur * ur)), 0.5 * step.vogel_exponent)
        };
        let theta = (st.drag * uu * g).min(V::splat(step.max_bend));
        let c = st.length * theta;
        let pushed = u.cmp_gt(V::ZERO) & c.cmp_gt(V::ZERO);
        let cu = c / pushed.blend(u, V::ONE);
        let push = V3::select(pushed, w.scale(cu), V3::ZERO);
        let b3 = if step.dynamics {
            // `physics::oscillator::damped_apply` ([`OscLanes`]), then the air's damping.
            let x = osc.bend.sub(push);
            let bend = push.add(x.scale(cs.a)).add(osc.rate.scale(cs.s));
            let rate = osc.rate.scale(cs.d).sub(x.scale(cs.e));
            osc.bend = bend;
            osc.rate = rate.scale(V::ONE / (V::ONE + st.aero * u * g * V::splat(step.dt)));
            bend
        } else {
            push
        };
        let bend = b3.dot(b3).cmp_gt(V::ZERO);
        let b2 = b3.scale(V::splat(step.p2_factor));
        // The legs P1→P2 and P2→P3 as they are now: the rest legs turned with the frame (the
        // same vectors as the differences of the moved points, without storing the rest
        // points; the step is bound by memory traffic at the larger sizes).
        let l2 = in_frame(&f_now, st.local[2].sub(st.local[1]));
        let l3 = in_frame(&f_now, st.local[3].sub(st.local[2]));
        // Each leg turned toward its push and kept at its length: P2 moves by c2, P3 by
        // c2 + c3.
        let c2 = turned(l2, b2);
        let c3 = turned(l3, b3);
        out.delta[2] = d2.add(V3::select(bend, c2, V3::ZERO));
        out.delta[3] = d3.add(V3::select(bend, c2.add(c3), V3::ZERO));
    }
}
}
