//! CPU twins of `akagi_forces.wgsl`, `akagi_subtree.wgsl` and `akagi_integrate.wgsl`
//! (see [`crate::methods::akagi`]).

use crate::methods::akagi::{RawAkagiSegment, RawAkagiStep};
use crate::model::RawSegment;
use crate::physics::AIR_DENSITY;
use crate::wind::raw::{RawField, RawWave};
use crate::wind::sample::wind_at;
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// Own wind force on each segment at its current centre. Bindings: 0 fields, 1 waves,
/// 2 segments, 3 akagi segments, 4 joints, 5 acc, 6 step, 7 forces.
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
    out.par_iter_mut().enumerate().for_each(|(i, o)| {
        let s = &segments[i];
        let axis = Quat::from_array(acc[i]) * (Quat::from_array(s.orientation) * Vec3::Y);
        let centre = Vec3::new(joints[i][0], joints[i][1], joints[i][2]) + axis * (0.5 * s.length);
        let v = wind_at(fields, waves, centre, step.time);
        let u = v.length();
        if u < 1e-6 {
            *o = [0.0; 4];
            return;
        }
        let vhat = v / u;
        let sin_phi = vhat.cross(axis).length();
        let area = akagi[i].bark_area * sin_phi + akagi[i].leaf_area;
        // Streamlining above the reconfiguration speed: U² → U_r^0.7 · U^1.3.
        let u2 =
            if u > step.reconfiguration_speed { u * u * (step.reconfiguration_speed / u).powf(0.7) } else { u * u };
        let f = vhat * (0.5 * AIR_DENSITY * step.drag * area * u2);
        *o = [f.x, f.y, f.z, 0.0];
    });
}

/// One depth of the propagation: `f_sub[i] = f_own[i] + Σ f_sub[children]` for the segments
/// of `bucket` (their children were summed by the previous, deeper bucket). Bindings:
/// 0 bucket, 1 child offsets, 2 child counts, 3 child indices, 4 own forces, 5 subtree forces.
pub fn akagi_subtree(
    bucket: &[u32],
    offset: &[u32],
    count: &[u32],
    index: &[u32],
    f_own: &[[f32; 4]],
    f_sub: &mut [[f32; 4]],
) {
    let sums: Vec<(usize, [f32; 4])> = bucket
        .par_iter()
        .map(|&i| {
            let i = i as usize;
            let mut f = Vec3::new(f_own[i][0], f_own[i][1], f_own[i][2]);
            let o = offset[i] as usize;
            for &c in &index[o..o + count[i] as usize] {
                let c = c as usize;
                f += Vec3::new(f_sub[c][0], f_sub[c][1], f_sub[c][2]);
            }
            (i, [f.x, f.y, f.z, 0.0])
        })
        .collect();
    for (i, f) in sums {
        f_sub[i] = f;
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

/// Damped angular springs, implicit in stiffness and damping. Bindings: 0 segments,
/// 1 akagi segments, 2 subtree forces, 3 acc, 4 step, 5 θ, 6 ω, 7 δ.
#[allow(clippy::too_many_arguments)]
pub fn akagi_integrate(
    segments: &[RawSegment],
    akagi: &[RawAkagiSegment],
    f_sub: &[[f32; 4]],
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
            let f = Vec3::new(f_sub[i][0], f_sub[i][1], f_sub[i][2]);
            let tau_world = axis.cross(f) * s.length;
            // Into the parent's rest frame: undo the parent's accumulated rotation, which is
            // this segment's accumulated rotation without its own.
            let own = quat_from_rotation_vector(Vec3::new(th[0], th[1], th[2]));
            let parent = d * own.inverse();
            let tau = parent.inverse() * tau_world;
            let t0 = Vec3::new(th[0], th[1], th[2]);
            let w0 = Vec3::new(om[0], om[1], om[2]);
            let dt = step.dt;
            let r = t0.length() / step.stiffening_angle;
            let k = a.stiffness * (1.0 + r * r);
            let denom = 1.0 + dt * a.damping / a.inertia + dt * dt * k / a.inertia;
            let w1 = (w0 + (tau - t0 * k) * (dt / a.inertia)) / denom;
            let t1 = t0 + w1 * dt;
            *th = [t1.x, t1.y, t1.z, 0.0];
            *om = [w1.x, w1.y, w1.z, 0.0];
            *de = quat_from_rotation_vector(t1).to_array();
        },
    );
}
