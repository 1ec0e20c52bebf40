//! CPU twins of `shader/hsm_clusters.wgsl`, `hsm_goals.wgsl`, `hsm_integrate.wgsl` and
//! `hsm_pose.wgsl`: Song's four stages (see [`crate::animate::hsm`]). Same operations in the
//! same order as the WGSL, except that the GPU sums a cluster's particles as a tree in shared
//! memory where this sums them in slot order.

use crate::animate::hsm::{RawHsmCluster, RawHsmClusterInfo, RawHsmClusterState, RawHsmSlot, RawHsmStep, kind};
use crate::cpu::wind_sample::wind_at;
use crate::model::NONE;
use crate::wind::raw::{RawField, RawWave};
use glam::{Mat3, Quat, Vec3};
use rayon::prelude::*;

#[inline]
fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// The rotation of `a` (Müller, Bender, Chentanez & Macklin 2016), warm-started from `q`:
/// `ω = Σ rᵢ × aᵢ / (|Σ rᵢ · aᵢ| + ε)`, `q ← exp(ω) q`, until |ω| < 2e-6 or `iterations`.
/// ε is 1e-6 of the columns' summed lengths (plus 1e-30), so a zero, flat or inverted `a`
/// leaves a finite rotation, never NaN.
pub fn extract_rotation(a: Mat3, q: Quat, iterations: u32) -> Quat {
    let mut q = q;
    let eps = 1e-6 * (a.x_axis.length() + a.y_axis.length() + a.z_axis.length()) + 1e-30;
    for _ in 0..iterations {
        let r = Mat3::from_quat(q);
        let num = r.x_axis.cross(a.x_axis) + r.y_axis.cross(a.y_axis) + r.z_axis.cross(a.z_axis);
        let den = (r.x_axis.dot(a.x_axis) + r.y_axis.dot(a.y_axis) + r.z_axis.dot(a.z_axis)).abs() + eps;
        let omega = num / den;
        let w = omega.length();
        if w < 2e-6 {
            break;
        }
        q = (Quat::from_axis_angle(omega / w, w) * q).normalize();
    }
    q
}

/// Stage 1, per cluster: centre of mass, Apq, R, the goal transform, α and the wind at the
/// centre. Sums run over displacements from rest `u = x − x⁰`, so a cluster at rest has
/// exactly zero shift and an exactly symmetric Apq (R = I): still air keeps the rest bit
/// for bit. Bindings: 0 fields, 1 waves, 2 cluster info, 3 clusters, 4 slots, 5 positions,
/// 6 rest positions, 7 step, 8 cluster state (read for R's warm start, written).
#[allow(clippy::too_many_arguments)]
pub fn hsm_clusters(
    fields: &[RawField],
    waves: &[RawWave],
    info: &[RawHsmClusterInfo],
    clusters: &[RawHsmCluster],
    slots: &[RawHsmSlot],
    position: &[[f32; 4]],
    rest: &[[f32; 4]],
    step: RawHsmStep,
    state: &mut [RawHsmClusterState],
) {
    state.par_iter_mut().enumerate().with_min_len(64).for_each(|(c, st)| {
        let inf = info[c];
        let cl = &clusters[c];
        let c0 = v3(cl.rest_cm);
        let mut sm = Vec3::ZERO;
        let mut a0 = Vec3::ZERO;
        let mut a1 = Vec3::ZERO;
        let mut a2 = Vec3::ZERO;
        for s in &slots[inf.slot_offset as usize..(inf.slot_offset + inf.slot_count) as usize] {
            let x = position[s.particle as usize];
            let m = x[3];
            let u = v3(x) - v3(rest[s.particle as usize]);
            let q = Vec3::from_array(s.q);
            sm += u * m;
            // d = x − c⁰ = u + q; (d qⱼ) m keeps Apq symmetric when u = 0.
            let d = u + q;
            a0 += (d * q.x) * m;
            a1 += (d * q.y) * m;
            a2 += (d * q.z) * m;
        }
        let shift = sm / cl.mass;
        let cm = c0 + shift;
        // Σ m q = 0, so Σ m (x − c⁰) qᵀ is Apq = Σ m (x − c) qᵀ.
        let apq = Mat3::from_cols(a0, a1, a2);
        let q = extract_rotation(apq, Quat::from_array(st.rotation), step.polar_iterations);
        let r = Mat3::from_quat(q);
        let mut t = r;
        if step.beta > 0.0 {
            let aqq_inv = Mat3::from_cols(v3(cl.aqq_inv[0]), v3(cl.aqq_inv[1]), v3(cl.aqq_inv[2]));
            let a = apq * aqq_inv;
            let det = a.determinant();
            if det > 1e-6 {
                t = a * (step.beta / det.powf(1.0 / 3.0)) + r * (1.0 - step.beta);
            }
        }
        let alpha = (cl.rest_cm[3] * step.dt * step.dt).min(1.0);
        // A leaf feels the wind sampled for its segment (stage 4 reads it there).
        let u = if inf.kind == kind::LEAF { Vec3::ZERO } else { wind_at(fields, waves, cm, step.time) };
        st.cm = [cm.x, cm.y, cm.z, alpha];
        st.rotation = q.to_array();
        st.transform =
            [t.x_axis.extend(shift.x).into(), t.y_axis.extend(shift.y).into(), t.z_axis.extend(shift.z).into()];
        st.wind = [u.x, u.y, u.z, 0.0];
    });
}

/// Stage 3, per particle: the α-weighted mean of its clusters' goals `T_c q + c_c`, and
/// `ᾱ = min(1, Σ α_c)`. Goals are formed as displacements from rest, `x⁰ + (T q − q) + (c − c⁰)`,
/// so a cluster at rest gives exactly `x⁰`. Bindings: 0 slots, 1 member offsets, 2 members,
/// 3 rest positions, 4 cluster state, 5 goals.
pub fn hsm_goals(
    slots: &[RawHsmSlot],
    member_offset: &[u32],
    member: &[[u32; 2]],
    rest: &[[f32; 4]],
    state: &[RawHsmClusterState],
    goal: &mut [[f32; 4]],
) {
    goal.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, g)| {
        let lo = member_offset[i] as usize;
        let hi = member_offset[i + 1] as usize;
        let mut sum = Vec3::ZERO;
        let mut wsum = 0.0f32;
        for m in &member[lo..hi] {
            let st = &state[m[0] as usize];
            let q = slots[m[1] as usize].q;
            let q = Vec3::from_array(q);
            let tq = v3(st.transform[0]) * q.x + v3(st.transform[1]) * q.y + v3(st.transform[2]) * q.z;
            let shift = Vec3::new(st.transform[0][3], st.transform[1][3], st.transform[2][3]);
            let gd = (tq - q) + shift;
            sum += gd * st.cm[3];
            wsum += st.cm[3];
        }
        let x0 = v3(rest[i]);
        *g = if wsum > 0.0 {
            let gg = x0 + sum / wsum;
            [gg.x, gg.y, gg.z, wsum.min(1.0)]
        } else {
            [x0.x, x0.y, x0.z, 0.0]
        };
    });
}

/// Stage 4, per particle: shape-matching pull, gravity (balanced by the support of a
/// prestressed tree), drag toward the wind of its `owner` cluster,
/// damping, then the position. Bindings: 0 rest (w = drag factor), 1 owners, 2 cluster
/// state, 3 goals, 4 step, 5 positions, 6 velocities.
pub fn hsm_integrate(
    rest: &[[f32; 4]],
    owner: &[u32],
    state: &[RawHsmClusterState],
    goal: &[[f32; 4]],
    step: RawHsmStep,
    position: &mut [[f32; 4]],
    velocity: &mut [[f32; 4]],
) {
    let h = step.dt;
    position.par_iter_mut().zip(velocity.par_iter_mut()).enumerate().with_min_len(256).for_each(|(i, (x, v))| {
        if v[3] == 0.0 {
            return; // fixed
        }
        let g = goal[i];
        let p = v3(*x);
        let st = &state[owner[i] as usize];
        let gravity = v3(step.gravity);
        let mut vel = v3(*v) + (v3(g) - p) * (g[3] / h) + gravity * ((1.0 - step.gravity[3]) * h);
        let rel = v3(st.wind) - vel;
        let s = h * rest[i][3] * rel.length();
        vel += rel * (s / (1.0 + s));
        vel *= step.damping;
        let p = p + vel * h;
        *x = [p.x, p.y, p.z, x[3]];
        *v = [vel.x, vel.y, vel.z, v[3]];
    });
}

/// Seam rotations per segment: its cluster's R (identity where it has none). Bindings:
/// 0 segment clusters, 1 cluster state, 2 acc.
pub fn hsm_pose(segment_cluster: &[u32], state: &[RawHsmClusterState], acc: &mut [[f32; 4]]) {
    acc.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, a)| {
        let c = segment_cluster[i];
        *a = if c == NONE { [0.0, 0.0, 0.0, 1.0] } else { state[c as usize].rotation };
    });
}
