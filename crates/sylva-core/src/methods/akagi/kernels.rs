//! CPU twins of `akagi_forces.wgsl`, `akagi_subtree.wgsl` and `akagi_integrate.wgsl`
//! (see [`crate::methods::akagi`]).

use crate::methods::akagi::{RawAkagiSegment, RawAkagiStep};
use crate::model::RawSegment;
use crate::physics::DragModel;
use crate::physics::oscillator::damped_step;
use crate::simd::dispatch;
use crate::wind::lanes::{LANES, V3, wind_lanes};
use crate::wind::raw::{RawField, RawWave};
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// Own drag on each segment at its current centre, with its aerodynamic damping. `out`
/// holds two entries per segment: `2i` the force (N) and, in w, the drag's rate of change
/// with the segment's own velocity `γ = ρ C_d A |u| g(|u|)` (N·s/m: a part moving with the
/// wind at v feels `F − γ v`); `2i + 1` the centre. Bindings: 0 fields, 1 waves,
/// 2 segments, 3 akagi segments, 4 joints, 5 acc, 6 step, 7 forces.
///
/// The WGSL samples the wind in each segment's invocation; here sixteen centres at a time
/// ([`crate::wind::lanes`], whose polynomial sine agrees with `wind_at` to its error), in
/// fixed groups, so the result does not depend on the thread count or the instruction set.
#[allow(clippy::too_many_arguments)]
pub fn akagi_forces(
    fields: &[RawField],
    waves: &[RawWave],
    segments: &[RawSegment],
    akagi: &[RawAkagiSegment],
    joints: &[[f32; 4]],
    acc: &[[f32; 4]],
    step: RawAkagiStep,
    out: &mut [[f32; 4]],
) {
    let level = crate::simd::level();
    out.par_chunks_mut(2 * LANES).enumerate().for_each(|(k, o)| {
        let base = k * LANES;
        forces_group(level, fields, waves, &segments[base..], &akagi[base..], &joints[base..], &acc[base..], &step, o);
    });
}

dispatch! {
/// [`akagi_forces`] for one group of up to sixteen segments (`out` two entries each).
#[allow(clippy::too_many_arguments)]
fn forces_group(
    fields: &[RawField],
    waves: &[RawWave],
    segments: &[RawSegment],
    akagi: &[RawAkagiSegment],
    joints: &[[f32; 4]],
    acc: &[[f32; 4]],
    step: &RawAkagiStep,
    out: &mut [[f32; 4]],
) {
    let n = out.len() / 2;
    let drag = DragModel { reconfiguration_speed: step.reconfiguration_speed, vogel_exponent: step.vogel_exponent };
    let mut axis = [Vec3::ZERO; LANES];
    let mut centre = [Vec3::ZERO; LANES];
    for i in 0..n {
        let s = &segments[i];
        axis[i] = Quat::from_array(acc[i]) * (Quat::from_array(s.orientation) * Vec3::Y);
        centre[i] = Vec3::new(joints[i][0], joints[i][1], joints[i][2]) + axis[i] * (0.5 * s.length);
    }
    // A short last group repeats its last centre in the unused lanes.
    for i in n..LANES {
        centre[i] = centre[n - 1];
    }
    let wind = if fields.is_empty() { V3::ZERO } else { wind_lanes(fields, waves, V3::from_lanes(centre), step.time) };
    for (i, o) in out.chunks_mut(2).enumerate() {
        let w = wind.lane(i);
        let u = w.length();
        o[0] = if u < 1e-6 {
            [0.0; 4]
        } else {
            let sin_phi = (w / u).cross(axis[i]).length();
            let cd_area = step.drag * (akagi[i].bark_area * sin_phi + akagi[i].leaf_area);
            let f = drag.force(cd_area, w);
            [f.x, f.y, f.z, drag.damping(cd_area, u)]
        };
        o[1] = [centre[i].x, centre[i].y, centre[i].z, 0.0];
    }
}
}

/// One depth of the propagation toward the root, for the segments of `bucket` (their
/// children were summed by the previous, deeper bucket). With `f_j`, `γ_j` a segment's own
/// drag and damping at its centre `x_j`, and `p` the joints, per joint i over everything
/// beyond it, at `3i`, `3i + 1`, `3i + 2`:
/// - the force `F = Σ f_j` and `S₀ = Σ γ_j`;
/// - the moment about the joint `M = Σ (x_j − p_i) × f_j` and the aerodynamic damping of
///   turning about it `Γ = Σ γ_j |x_j − p_i|²` (N·m·s/rad);
/// - `S₁ = Σ γ_j (x_j − p_i)`, which carries Γ to the parent without cancellation.
///
/// Bindings: 0 bucket, 1 child offsets, 2 child counts, 3 child indices, 4 own forces,
/// 5 joints, 6 sums.
pub fn akagi_subtree(
    bucket: &[u32],
    offset: &[u32],
    count: &[u32],
    index: &[u32],
    f_own: &[[f32; 4]],
    joints: &[[f32; 4]],
    sub: &mut [[f32; 4]],
) {
    let v = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
    // Joint i's sums from its own drag and its children's sums (a deeper bucket's).
    let joint = |i: usize, sub: &[[f32; 4]]| {
        let p = v(joints[i]);
        let (mut f, mut s0) = (v(f_own[2 * i]), f_own[2 * i][3]);
        let r = v(f_own[2 * i + 1]) - p;
        let (mut m, mut s1, mut gamma) = (r.cross(f), r * s0, s0 * r.length_squared());
        let o = offset[i] as usize;
        for &c in &index[o..o + count[i] as usize] {
            let c = c as usize;
            let d = v(joints[c]) - p;
            let (fc, s0c, s1c) = (v(sub[3 * c]), sub[3 * c][3], v(sub[3 * c + 2]));
            f += fc;
            m += v(sub[3 * c + 1]) + d.cross(fc);
            gamma += sub[3 * c + 1][3] + 2.0 * d.dot(s1c) + d.length_squared() * s0c;
            s1 += s1c + d * s0c;
            s0 += s0c;
        }
        [[f.x, f.y, f.z, s0], [m.x, m.y, m.z, gamma], [s1.x, s1.y, s1.z, 0.0]]
    };
    if bucket.len() < crate::PARALLEL_FROM {
        // A bucket's children lie in a deeper bucket, so writing as we go reads nothing
        // this bucket writes.
        for &i in bucket {
            let i = i as usize;
            let e = joint(i, sub);
            sub[3 * i..3 * i + 3].copy_from_slice(&e);
        }
        return;
    }
    let sums: Vec<(usize, [[f32; 4]; 3])> = bucket.par_iter().map(|&i| (i as usize, joint(i as usize, sub))).collect();
    for (i, e) in sums {
        sub[3 * i..3 * i + 3].copy_from_slice(&e);
    }
}

/// Quaternion of a rotation vector (angle |θ| about θ/|θ|); exactly the identity at 0.
#[inline]
pub fn quat_from_rotation_vector(t: Vec3) -> Quat {
    let a = t.length();
    if a == 0.0 {
        return Quat::IDENTITY;
    }
    Quat::from_axis_angle(t / a, a)
}

/// Damped angular springs advanced by the exact solution of `J θ̈ + (c + s Γ) θ̇ + k θ = τ`
/// (`s` the joint's [`RawAkagiSegment::air_scale`])
/// over the step with the moment, stiffness and damping held (so frequency and damping do
/// not depend on the step, and the air's damping Γ is stable at any wind). The spring
/// stiffens with the bend the moment holds it at ([`stiffening`]); its damping ratio stays. τ is the moment of
/// everything beyond the joint about it, less its twist about the segment's axis, in the
/// parent's rest frame. Bindings: 0 segments, 1 akagi segments, 2 the propagated sums
/// ([`akagi_subtree`]), 3 acc, 4 step, 5 θ, 6 ω, 7 δ.
#[allow(clippy::too_many_arguments)]
pub fn akagi_integrate(
    segments: &[RawSegment],
    akagi: &[RawAkagiSegment],
    sub: &[[f32; 4]],
    acc: &[[f32; 4]],
    step: RawAkagiStep,
    theta: &mut [[f32; 4]],
    omega: &mut [[f32; 4]],
    delta: &mut [[f32; 4]],
) {
    theta.par_iter_mut().zip(omega.par_iter_mut()).zip(delta.par_iter_mut()).enumerate().for_each(
        |(i, ((th, om), de))| {
            let s = &segments[i];
            let a = &akagi[i];
            let d = Quat::from_array(acc[i]);
            let axis = d * (Quat::from_array(s.orientation) * Vec3::Y);
            let m = Vec3::new(sub[3 * i + 1][0], sub[3 * i + 1][1], sub[3 * i + 1][2]);
            let gamma = sub[3 * i + 1][3];
            let tau_world = m - axis * axis.dot(m);
            // Into the parent's rest frame: undo the parent's accumulated rotation, which is
            // this segment's accumulated rotation without its own.
            let own = quat_from_rotation_vector(Vec3::new(th[0], th[1], th[2]));
            let parent = d * own.inverse();
            let tau = parent.inverse() * tau_world;
            let t0 = Vec3::new(th[0], th[1], th[2]);
            let w0 = Vec3::new(om[0], om[1], om[2]);
            let stiffen = stiffening(tau.length() / a.stiffness, step.stiffening_angle);
            let k = a.stiffness * stiffen;
            let c = a.damping * stiffen.sqrt() + gamma * a.air_scale;
            let (mut t1, mut w1) = damped_step(t0, w0, tau / k, k / a.inertia, c / (2.0 * a.inertia), step.dt);
            // A hard stop at three stiffening angles: the bend goes no further and stops
            // moving outward.
            let (bend, stop) = (t1.length(), 3.0 * step.stiffening_angle);
            if bend > stop {
                let n = t1 / bend;
                t1 = n * stop;
                w1 -= n * w1.dot(n).max(0.0);
            }
            *th = [t1.x, t1.y, t1.z, 0.0];
            *om = [w1.x, w1.y, w1.z, 0.0];
            *de = quat_from_rotation_vector(t1).to_array();
        },
    );
}

/// How much a joint has stiffened at the bend the moment τ holds it at: the spring is
/// `k (1 + (θ/θ_s)²)`, and its equilibrium under τ solves `θ + θ³/θ_s² = τ/k = b` (one real
/// root: `θ = 2 θ_s/√3 · sinh(⅓ asinh(3√3 b / (2 θ_s)))`); returns `1 + (θ/θ_s)²`, the
/// secant stiffness over `k`. Holding it over the step keeps the step exact and stable in
/// any wind. WGSL: `stiffening` in `akagi_integrate.wgsl`.
#[inline]
pub fn stiffening(b: f32, theta_s: f32) -> f32 {
    // θ / θ_s.
    let u = 2.0 / 3f32.sqrt() * ((3.0 * 3f32.sqrt() * b / (2.0 * theta_s)).asinh() / 3.0).sinh();
    1.0 + u * u
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Stream;
    use glam::DVec3;

    /// Every joint's sums are those of everything beyond it taken one load at a time: the
    /// force, the moment of each load about the joint with its whole lever arm (a stem rising
    /// from its parent turns the joint below by its height above it, not only by where it
    /// grows), and the air's damping of turning, `Σ γ |x − p|²`. A random hierarchy of
    /// 12,211 joints in five levels (the last two, of 5,000 and 7,000, take the parallel
    /// path), loads and joints in a 10 m box. Tolerance 2·10⁻⁵ of the sum of the terms'
    /// magnitudes (f32 sums of up to 12,211 terms).
    #[test]
    fn a_joints_moment_is_every_load_beyond_it_times_its_whole_lever_arm() {
        let levels = [1usize, 10, 200, 5000, 7000];
        let mut rng = Stream::new(26);
        let (mut parent, mut buckets) = (Vec::new(), Vec::new());
        let mut start = 0usize;
        for (d, &n) in levels.iter().enumerate() {
            for _ in 0..n {
                let p = if d == 0 {
                    usize::MAX
                } else {
                    start - levels[d - 1] + (rng.unit() * levels[d - 1] as f64) as usize
                };
                parent.push(p);
            }
            buckets.push((start as u32..(start + n) as u32).collect::<Vec<u32>>());
            start += n;
        }
        let n = parent.len();
        let mut kids = vec![Vec::new(); n];
        for (c, &p) in parent.iter().enumerate().skip(1) {
            kids[p].push(c as u32);
        }
        let count: Vec<u32> = kids.iter().map(|k| k.len() as u32).collect();
        let offset: Vec<u32> = kids.iter().scan(0u32, |o, k| Some(std::mem::replace(o, *o + k.len() as u32))).collect();
        let index: Vec<u32> = kids.concat();
        let mut r = |a: f64| rng.var(a) as f32;
        let joints: Vec<[f32; 4]> = (0..n).map(|_| [r(5.0), r(5.0), r(5.0), 0.0]).collect();
        let mut f_own = Vec::with_capacity(2 * n);
        for _ in 0..n {
            f_own.push([r(10.0), r(10.0), r(10.0), 0.5 + r(0.5)]);
            f_own.push([r(5.0), r(5.0), r(5.0), 0.0]);
        }
        let mut sub = vec![[0.0f32; 4]; 3 * n];
        for bucket in buckets.iter().rev() {
            akagi_subtree(bucket, &offset, &count, &index, &f_own, &joints, &mut sub);
        }
        // One load at a time, to every joint it lies beyond (its own and its ancestors').
        let v = |a: [f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
        let mut want = vec![(DVec3::ZERO, DVec3::ZERO, 0.0f64); n];
        let mut scale = vec![(0.0f64, 0.0f64, 0.0f64); n];
        for j in 0..n {
            let (f, g, x) = (v(f_own[2 * j]), f_own[2 * j][3] as f64, v(f_own[2 * j + 1]));
            let mut i = j;
            while i != usize::MAX {
                let arm = x - v(joints[i]);
                want[i].0 += f;
                want[i].1 += arm.cross(f);
                want[i].2 += g * arm.length_squared();
                scale[i].0 += f.length();
                scale[i].1 += arm.length() * f.length();
                scale[i].2 += g * arm.length_squared();
                i = parent[i];
            }
        }
        for (i, (&(f, m, g), &(sf, sm, sg))) in want.iter().zip(&scale).enumerate() {
            let got = (v(sub[3 * i]), v(sub[3 * i + 1]), sub[3 * i + 1][3] as f64);
            assert!((got.0 - f).length() <= 2e-5 * sf, "joint {i}: force {} against {f}", got.0);
            assert!((got.1 - m).length() <= 2e-5 * sm, "joint {i}: moment {} against {m}", got.1);
            assert!((got.2 - g).abs() <= 2e-5 * sg, "joint {i}: Γ {} against {g}", got.2);
        }
    }
}
