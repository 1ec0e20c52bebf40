//! CPU twins of `hsm_clusters.wgsl`, `hsm_goals.wgsl`, `hsm_integrate.wgsl` and
//! `hsm_pose.wgsl`: Song's four stages (see [`crate::methods::hsm`]). Same operations in the
//! same order as the WGSL: a cluster's sums go through the GPU's [`LANES`] lanes (lane `j mod
//! 64` takes slot `j`) and the same halving tree, so both sides add in the same order (the
//! GPU's subgroup kernel makes the tree's last strides by shuffles, the same additions).

use crate::leaves::kernels::leaf_band;
pub use crate::methods::hsm::rotation::{NEWTON_NEAR, extract_rotation, rotation_step};
use crate::methods::hsm::rotation::{ROTATIONS, extract_rotations_at};
use crate::methods::hsm::{
    RawHsmCluster, RawHsmClusterInfo, RawHsmClusterState, RawHsmMember, RawHsmSlot, RawHsmStep, kind,
};
use crate::model::NONE;
use crate::simd::dispatch;
use crate::wind::lanes::{LANES as WIND_LANES, V3, wind_lanes};
use crate::wind::noise::{hash_unit, pcg_hash};
use crate::wind::raw::{RawField, RawWave};
use glam::{Mat3, Quat, Vec3, Vec3A, Vec4};
use rayon::prelude::*;

/// Invocations per cluster in `hsm_clusters.wgsl` (its workgroup size).
pub const LANES: usize = 64;

#[inline]
fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// Largest weight a cluster brings to the mean of its particles' goals (stage 3).
///
/// A cluster's weight is `w = k h²`, its rate `k` (1/s²) times the substep squared; a
/// particle shared by several clusters goes to the `w`-weighted mean of their goals, the
/// point where their spring forces `m k_c (g_c − x)` balance, and moves `ᾱ = min(Σ w, hold)`
/// of the way there ([`RawHsmStep::hold`], never above 1). That clamp keeps Müller's
/// unconditional stability (a particle never passes its goal). The weights are **not**
/// clamped at the hold:
/// * Clamped (Müller's per-cluster `α = min(1, k h²)`), every cluster stiffer than `1/h²`
///   had an equal say, so a thick stem held the ring it shares with a twig or a leaf no
///   better than the twig did, and a joint resisted only about `m r² / h²` (its ring's mass
///   and lever). The stochastic bush, whose 3 cm stems are ~50× stiffer than that at
///   240 Hz, lay down in gusty wind: segment ends 2.0 m from rest on a 2.3 m bush.
/// * A weight passes the hold only up to `k̂ h²`, `k̂` the smallest rate on the cluster's path to
///   the root ([`crate::methods::hsm::RawHsmCluster::aqq_inv`]'s first w). A cluster pulls
///   the parent's rings it reaches into (`overlap`) at its own rate, and a thin twig's rate
///   can be high only because it is light: unbounded, monopodial's laterals dragged its
///   trunk (tips 3.0 m from rest in `gusty`, 0.24 m clamped). Below 1 nothing changes, so
///   slender trees (every cluster under `1/h²`) move as before, bit for bit.
///
/// `MAX_WEIGHT` only keeps the sums finite: a ratio of 10⁶ between two clusters already
/// leaves the softer one no say. WGSL: `MAX_WEIGHT` in `hsm.wgsl`.
pub const MAX_WEIGHT: f32 = 1e6;

/// One slot's terms of a cluster's sums from the particle's displacement `x` (w = mass) and
/// the cluster's shift at the last substep `sp`: `[m u, m d q.x, m d q.y, m d q.z]` with
/// `u = x − x⁰ − sp` and `d = u + q = x − c⁰ − sp` (so Apq stays exactly symmetric at
/// rest). `Σ m q = 0`, so `sp` drops out of Apq; subtracting it keeps the terms at the size
/// of the cluster instead of its distance from rest (a palm frond's tip travels metres),
/// and with them their rounding: a GPU that rounds differently then agrees with the CPU
/// far better (palm, 1,000 steps on an H100: 4.9e-4 × height apart before, 1.9e-5 after).
/// WGSL: the slot loop of `hsm_lane_sums` in `hsm_cluster_stage.wgsl`.
#[inline(always)]
fn slot_terms(x: [f32; 4], sp: Vec3A, s: &RawHsmSlot) -> [Vec3A; 4] {
    let m = x[3];
    let u = a3(x) - sp;
    let q = Vec3A::from_array(s.q);
    let d = u + q;
    [u * m, (d * q.x) * m, (d * q.y) * m, (d * q.z) * m]
}

/// Stage 1, per cluster: centre of mass, Apq, R, the goal transform, the weight `k h²` and
/// the wind at the centre (where the step samples it, [`RawHsmStep::sample_wind`]; else the
/// cluster keeps the wind it holds). Sums run over the particles' displacements from rest
/// `u = x − x⁰` (the state itself), so a cluster at rest has exactly zero shift and an
/// exactly symmetric Apq (R = I): still air keeps the rest bit for bit. Bindings: 0 fields,
/// 1 waves, 2 cluster info, 3 clusters, 4 slots, 5 displacements (w = mass), 6 step,
/// 7 cluster state (read for R's warm start, written).
#[allow(clippy::too_many_arguments)]
pub fn hsm_clusters(
    fields: &[RawField],
    waves: &[RawWave],
    info: &[RawHsmClusterInfo],
    clusters: &[RawHsmCluster],
    slots: &[RawHsmSlot],
    displacement: &[[f32; 4]],
    step: RawHsmStep,
    state: &mut [RawHsmClusterState],
) {
    hsm_clusters_with(fields, waves, info, clusters, step, state, |c, sp, quarter| {
        let inf = &info[c];
        let run = &slots[inf.slot_offset as usize..(inf.slot_offset + inf.slot_count) as usize];
        cluster_sums(run, displacement, sp, quarter)
    });
}

/// Scratch of one chunk of stage 1: a cluster's quarter lanes (see [`cluster_sums`]).
pub(crate) type Quarter = [[Vec3A; 4]; LANES / 4];

/// The CPU twin of `hsm_clusters_subgroup.wgsl`: the same additions in the same order as
/// [`hsm_clusters`] (the GPU makes the tree's strides below its subgroup size by shuffles).
pub use self::hsm_clusters as hsm_clusters_subgroup;

/// [`hsm_clusters`] with each cluster's sums `[Σ m u, Apq columns]` about the shift `sp`
/// from `sums(cluster, sp, scratch)`, which must add as [`cluster_sums`] does (the CPU's fast
/// form, [`super::slot_groups`], gives the same bits).
#[allow(clippy::too_many_arguments)]
pub(crate) fn hsm_clusters_with<S>(
    fields: &[RawField],
    waves: &[RawWave],
    info: &[RawHsmClusterInfo],
    clusters: &[RawHsmCluster],
    step: RawHsmStep,
    state: &mut [RawHsmClusterState],
    sums: S,
) where
    S: Fn(usize, Vec3A, &mut Quarter) -> [Vec3A; 4] + Sync,
{
    // One parallel pass: each chunk of clusters gets its shape matching, then the wind at
    // the new centres (fixed chunks, so the wind's lane groups do not depend on the threads).
    const CHUNK: usize = 256;
    let level = crate::simd::level();
    state.par_chunks_mut(CHUNK).enumerate().for_each(|(k, chunk)| {
        let base = k * CHUNK;
        let mut quarter = [[Vec3A::ZERO; 4]; LANES / 4];
        // Sixteen clusters at a time, their rotations extracted in SIMD lanes.
        for (g, group) in chunk.chunks_mut(ROTATIONS).enumerate() {
            let at = base + g * ROTATIONS;
            let mut apq = [(Mat3::ZERO, Vec3::ZERO); ROTATIONS];
            for (i, st) in group.iter().enumerate() {
                // Sums about the last substep's shift (see `slot_terms`).
                let t = &st.transform;
                let sp = Vec3A::new(t[0][3], t[1][3], t[2][3]);
                apq[i] = cluster_apq(&clusters[at + i], sums(at + i, sp, &mut quarter), sp);
            }
            // A last, short group is padded with zero matrices (their rotations are unused).
            let mut q: [Quat; ROTATIONS] =
                std::array::from_fn(|i| group.get(i).map_or(Quat::IDENTITY, |st| Quat::from_array(st.rotation)));
            extract_rotations_at(level, &apq.map(|s| s.0), &mut q, step.polar_iterations);
            for (i, st) in group.iter_mut().enumerate() {
                finish_cluster(&clusters[at + i], apq[i], q[i], &step, st);
            }
        }
        if step.sample_wind != 0 && !fields.is_empty() {
            let range = base..base + chunk.len();
            wind_chunk_at(level, fields, waves, &info[range.clone()], &clusters[range], &step, chunk);
        }
    });
}

/// Stage 1 for one cluster (one workgroup of `hsm_clusters.wgsl`) up to R: its Apq and the
/// shift of its centre from rest, from its sums about the last shift `sp`.
#[inline(always)]
fn cluster_apq(cl: &RawHsmCluster, sums: [Vec3A; 4], sp: Vec3A) -> (Mat3, Vec3) {
    let [sm, a0, a1, a2] = sums.map(Vec3::from);
    let shift = Vec3::from(sp) + sm / cl.mass;
    // Σ m q = 0, so Σ m (x − c⁰ − sp) qᵀ is Apq = Σ m (x − c) qᵀ.
    (Mat3::from_cols(a0, a1, a2), shift)
}

/// A cluster's weight at substep `h`: its `k h²`, past the hold only up to its path's `k̂ h²`
/// (see [`MAX_WEIGHT`]). WGSL: `hsm_cluster_stage.wgsl`.
#[inline(always)]
pub(super) fn cluster_weight(cl: &RawHsmCluster, h: f32, hold: f32) -> f32 {
    let bound = (cl.aqq_inv[0][3] * h * h).max(hold);
    (cl.rest_cm[3] * h * h).min(bound).min(MAX_WEIGHT)
}

/// Stage 1 for one cluster after R (`q`): the goal transform, the weight `k h²` and the
/// state, the wind aside.
#[inline(always)]
fn finish_cluster(
    cl: &RawHsmCluster,
    (apq, shift): (Mat3, Vec3),
    q: Quat,
    step: &RawHsmStep,
    st: &mut RawHsmClusterState,
) {
    let cm = v3(cl.rest_cm) + shift;
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
    let weight = cluster_weight(cl, step.dt, step.hold);
    st.cm = [cm.x, cm.y, cm.z, weight];
    st.rotation = q.to_array();
    st.transform = [t.x_axis.extend(shift.x).into(), t.y_axis.extend(shift.y).into(), t.z_axis.extend(shift.z).into()];
    if step.sample_wind != 0 {
        st.wind = [0.0, 0.0, 0.0, 1.0];
    }
}

/// Vogel's reconfiguration of the drag of a cluster's particles in the wind `u` at its
/// centre, the factor `g(|u|)` of [`crate::physics::DragModel::reconfiguration`] with the
/// step's U_r and B: parts that move with the air far slower than it (all but a gust's first
/// instants) streamline with the wind's own speed, so one factor per cluster and substep
/// serves all its particles. 1 in still air. WGSL: `hsm_reconfiguration`.
#[inline(always)]
pub fn reconfiguration(u: Vec3, step: &RawHsmStep) -> f32 {
    let drag = crate::physics::DragModel {
        reconfiguration_speed: step.reconfiguration_speed,
        vogel_exponent: step.vogel_exponent,
    };
    drag.reconfiguration(u.length())
}

/// Lane `t`'s sums as invocation `t` of stage 1 adds them (`hsm_lane_sums`): zero, plus slot `t`,
/// slot `t + 64`, …; zero for a lane past the slot count.
#[inline(always)]
fn lane_sums(run: &[RawHsmSlot], displacement: &[[f32; 4]], sp: Vec3A, t: usize) -> [Vec3A; 4] {
    let mut acc = [Vec3A::ZERO; 4];
    if run.len() <= LANES {
        // At most one slot per lane (most clusters): the same additions without the
        // strided iterator.
        if let Some(s) = run.get(t) {
            for (a, v) in acc.iter_mut().zip(slot_terms(displacement[s.particle as usize], sp, s)) {
                *a += v;
            }
        }
        return acc;
    }
    for s in run.iter().skip(t).step_by(LANES) {
        for (a, v) in acc.iter_mut().zip(slot_terms(displacement[s.particle as usize], sp, s)) {
            *a += v;
        }
    }
    acc
}

#[inline(always)]
fn add4(a: [Vec3A; 4], b: [Vec3A; 4]) -> [Vec3A; 4] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]]
}

/// Stage 1's sums `[Σ m u, Apq columns]` of one cluster's slots `run`, added in the order of
/// the workgroup in `hsm_clusters.wgsl`: its lanes (see [`lane_sums`]; lanes past the slot
/// count are zero, so only the next power of two of them take part) are halved, lane `t`
/// taking lane `t + stride`, down to lane 0. The two widest halvings are done in registers
/// as each quarter's lane is formed, `(v_t + v_{t+W/2}) + (v_{t+W/4} + v_{t+3W/4})`, and only
/// the quarter's lanes go through memory: the same additions in the same order, so the same
/// bits, without writing every slot's terms out and reading them back.
#[inline(always)]
pub(crate) fn cluster_sums(
    run: &[RawHsmSlot],
    displacement: &[[f32; 4]],
    sp: Vec3A,
    quarter: &mut Quarter,
) -> [Vec3A; 4] {
    let width = run.len().clamp(1, LANES).next_power_of_two();
    let lane = |t: usize| lane_sums(run, displacement, sp, t);
    match width {
        1 => lane(0),
        2 => add4(lane(0), lane(1)),
        _ => {
            let q = width / 4;
            for (t, l) in quarter[..q].iter_mut().enumerate() {
                *l = add4(add4(lane(t), lane(t + 2 * q)), add4(lane(t + q), lane(t + 3 * q)));
            }
            let mut stride = q / 2;
            while stride > 0 {
                // Invocation t < stride adds lane t + stride to lane t (one barrier per level).
                for t in 0..stride {
                    quarter[t] = add4(quarter[t], quarter[t + stride]);
                }
                stride /= 2;
            }
            quarter[0]
        }
    }
}

dispatch! {
/// The wind at the centres of one chunk's clusters, with its [`reconfiguration`] in w; a
/// leaf cluster's adds the air's fluctuation in its band ([`leaf_air`]). The WGSL samples it
/// in the cluster's own invocation; here sixteen centres at a time ([`crate::wind::lanes`]).
fn wind_chunk_at(
    fields: &[RawField],
    waves: &[RawWave],
    info: &[RawHsmClusterInfo],
    clusters: &[RawHsmCluster],
    step: &RawHsmStep,
    state: &mut [RawHsmClusterState],
) {
    let time = step.time;
    for (g, group) in state.chunks_mut(WIND_LANES).enumerate() {
        let base = g * WIND_LANES;
        let centre = |l: usize| v3(group[l.min(group.len() - 1)].cm);
        let u = wind_lanes(fields, waves, V3::from_lanes(std::array::from_fn(centre)), time);
        for (l, st) in group.iter_mut().enumerate() {
            let w = u.lane(l);
            let (inf, cl) = (&info[base + l], &clusters[base + l]);
            let air = if inf.kind == kind::LEAF { leaf_air(w, cl.aqq_inv[1][3], inf.source, step) } else { Vec3::ZERO };
            st.wind = [w.x + air.x, w.y + air.y, w.z + air.z, reconfiguration(w, step)];
        }
    }
}
}

/// Key of the leaves' streams of air ([`leaf_air`]).
const LEAF_AIR_KEY: u32 = 0x1eaf_a1e5;

/// The air's fluctuation at a leaf, m/s: the turbulence at the leaf's own scale, which the
/// wind field does not resolve (its smallest eddies are crown-sized) and which makes
/// leaves flutter (Tadrist et al. 2018). A narrow band at the leaf's swing `omega` (rad/s)
/// with the leaves' damping ratio as its half-power width ([`crate::leaves::kernels::leaf_band`],
/// unit RMS, phases from the leaf's index `source`), along a direction of its own, with RMS
/// `σ = s |u| |u|² / (|u|² + u_o²)` (`s` = [`RawHsmStep::leaf_turbulence`], `u_o` =
/// [`RawHsmStep::flutter_onset`]): zero in still air, rising from the onset on as the closed
/// form's flutter does. The leaf cluster's spring and drag make the swing from it, at the
/// cluster's own frequency and damping. WGSL: `hsm_leaf_air` in `hsm_cluster_stage.wgsl`.
#[inline]
pub fn leaf_air(u: Vec3, omega: f32, source: u32, step: &RawHsmStep) -> Vec3 {
    let speed2 = u.length_squared();
    if step.leaf_turbulence == 0.0 || speed2 == 0.0 || omega == 0.0 {
        return Vec3::ZERO;
    }
    let sigma = step.leaf_turbulence * speed2.sqrt() * speed2 / (speed2 + step.flutter_onset * step.flutter_onset);
    let seed = pcg_hash(LEAF_AIR_KEY ^ source.wrapping_mul(0x9e37_79b9));
    let d = Vec3::new(hash_unit(seed ^ 0x0a11), hash_unit(seed ^ 0x0b22), hash_unit(seed ^ 0x0c33)) * 2.0 - 1.0;
    let len = d.length();
    if len == 0.0 {
        return Vec3::ZERO;
    }
    d * (sigma * leaf_band(omega, step.leaf_zeta, step.time, seed) / len)
}

/// A particle's goal as a displacement from rest (xyz) and ᾱ (w): the mean over its
/// clusters weighted by their `k h²` (see [`hsm_goals`], [`MAX_WEIGHT`]). WGSL:
/// `hsm_particle_goal` in `hsm_gather.wgsl`.
#[inline(always)]
fn particle_goal(i: usize, member_offset: &[u32], member: &[RawHsmMember], state: &[RawHsmClusterState]) -> [f32; 4] {
    let lo = member_offset[i] as usize;
    let hi = member_offset[i + 1] as usize;
    let mut sum = Vec3A::ZERO;
    let mut wsum = 0.0f32;
    for m in &member[lo..hi] {
        let st = &state[m.cluster as usize];
        sum += goal_displacement(st, Vec3A::from_array(m.q)) * st.cm[3];
        wsum += st.cm[3];
    }
    if wsum > 0.0 { with_xyz(sum / wsum, wsum) } else { [0.0; 4] }
}

/// A cluster's goal for rest offset `q`, as a displacement from rest: `(T q − q) + (c − c⁰)`.
/// WGSL: `hsm_goal_displacement`.
#[inline(always)]
fn goal_displacement(st: &RawHsmClusterState, q: Vec3A) -> Vec3A {
    let t = &st.transform;
    let tq = a3(t[0]) * q.x + a3(t[1]) * q.y + a3(t[2]) * q.z;
    let shift = Vec3A::new(t[0][3], t[1][3], t[2][3]);
    (tq - q) + shift
}

/// A free particle's new velocity: the pull toward goal `g` (w = Σ w, ᾱ its minimum with
/// the hold) from `u` (both
/// displacements from rest, so `g − u` is the goal minus the position), gravity,
/// semi-implicit drag toward `wind` with drag factor `kd` (its own times its owner's
/// [`reconfiguration`]) on the relative velocity `wind − a v` (`a` = `step.air`, see
/// [`super::HsmParams::air_damping`]), damping. WGSL: `hsm_velocity`.
#[inline(always)]
fn particle_velocity(v: Vec3A, g: [f32; 4], u: Vec3A, wind: Vec3A, kd: f32, step: &RawHsmStep) -> Vec3A {
    let h = step.dt;
    let gravity = Vec3A::from_array([step.gravity[0], step.gravity[1], step.gravity[2]]);
    // ᾱ / h as ᾱ · (1 / h): one division per step, not per particle.
    let mut vel = v + (a3(g) - u) * (g[3].min(step.hold) * (1.0 / h)) + gravity * ((1.0 - step.gravity[3]) * h);
    // Implicit in the new velocity v' for the drag `kd |r| (wind − a v')`, |r| at its start.
    let rel = wind - vel * step.air;
    let s = h * kd * rel.length();
    vel += rel * (s / (1.0 + step.air * s));
    vel * step.damping
}

/// The xyz of a 16-byte record in a 4-wide register.
#[inline(always)]
fn a3(x: [f32; 4]) -> Vec3A {
    Vec3A::from_vec4(Vec4::from_array(x))
}

/// A record's xyz replaced, w kept.
#[inline(always)]
fn with_xyz(v: Vec3A, w: f32) -> [f32; 4] {
    v.extend(w).to_array()
}

/// Stage 3, per particle: the mean of its clusters' goals `T_c q + c_c` weighted by their
/// `w_c = k_c h²`, and `Σ w_c` (stage 4 moves `ᾱ = min(Σ w_c, hold)`, see [`MAX_WEIGHT`]). Goals are kept as
/// displacements from rest, `(T q − q) + (c − c⁰)`, so a cluster at rest gives exactly
/// zero. Bindings: 0 member offsets, 1 members, 2 cluster state, 3 goals.
pub fn hsm_goals(member_offset: &[u32], member: &[RawHsmMember], state: &[RawHsmClusterState], goal: &mut [[f32; 4]]) {
    goal.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, g)| {
        *g = particle_goal(i, member_offset, member, state);
    });
}

/// Stage 4, per particle: shape-matching pull, gravity (balanced by the support of a
/// prestressed tree), drag toward the wind of its `owner` cluster, damping, then the
/// displacement. Bindings: 0 owners, 1 cluster state, 2 goals, 3 step, 4 displacements,
/// 5 velocities (w = drag factor, negative for a fixed particle).
pub fn hsm_integrate(
    owner: &[u32],
    state: &[RawHsmClusterState],
    goal: &[[f32; 4]],
    step: RawHsmStep,
    displacement: &mut [[f32; 4]],
    velocity: &mut [[f32; 4]],
) {
    integrate_free(owner, state, step, displacement, velocity, |i| goal[i]);
}

/// Stages 3 and 4 in one pass per particle: its goal, gathered from its clusters, is read by
/// no other particle, so it goes straight into the integration instead of through the goal
/// buffer (Song needs a synchronisation between the two because his goals are scattered
/// from the clusters). The same operations as [`hsm_goals`] then [`hsm_integrate`], so the
/// result is bit for bit theirs without the goal buffer's write and re-read. Bindings:
/// 0 member offsets, 1 members, 2 cluster state, 3 owners, 4 step, 5 displacements,
/// 6 velocities.
pub fn hsm_particles(
    member_offset: &[u32],
    member: &[RawHsmMember],
    state: &[RawHsmClusterState],
    owner: &[u32],
    step: RawHsmStep,
    displacement: &mut [[f32; 4]],
    velocity: &mut [[f32; 4]],
) {
    integrate_free(owner, state, step, displacement, velocity, |i| particle_goal(i, member_offset, member, state));
}

/// Stage 4 over every free particle, its goal from `goal_of` (read from the goal buffer,
/// or gathered in place by the fused pass).
#[inline(always)]
fn integrate_free(
    owner: &[u32],
    state: &[RawHsmClusterState],
    step: RawHsmStep,
    displacement: &mut [[f32; 4]],
    velocity: &mut [[f32; 4]],
    goal_of: impl Fn(usize) -> [f32; 4] + Sync,
) {
    // Chunks with a plain loop inside: the per-particle work is small, so a call per
    // particle would cost as much as the work.
    const CHUNK: usize = 1024;
    displacement.par_chunks_mut(CHUNK).zip(velocity.par_chunks_mut(CHUNK)).enumerate().for_each(|(k, (xs, vs))| {
        let base = k * CHUNK;
        let owners = &owner[base..base + xs.len()];
        for (i, ((x, v), o)) in xs.iter_mut().zip(vs.iter_mut()).zip(owners).enumerate() {
            let kd = v[3];
            if kd < 0.0 {
                continue; // fixed
            }
            let u = a3(*x);
            let wind = state[*o as usize].wind;
            let vel = particle_velocity(a3(*v), goal_of(base + i), u, a3(wind), kd * wind[3], &step);
            *x = with_xyz(u + vel * step.dt, x[3]);
            *v = with_xyz(vel, kd);
        }
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

pub use super::leaf_pose::hsm_leaf_pose;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::{Level, detected};
    use crate::wind::WindScene;
    use rand::{Rng, SeedableRng};

    /// The workgroup of `hsm_clusters.wgsl`, step by step: 64 lanes, lane `j mod 64` adding
    /// slot `j`, then the halving over all 64 lanes (zeros included).
    fn workgroup_sums(run: &[RawHsmSlot], displacement: &[[f32; 4]], sp: Vec3A) -> [Vec3A; 4] {
        let mut lane = [[Vec3A::ZERO; 4]; LANES];
        for (j, s) in run.iter().enumerate() {
            lane[j % LANES] = add4(lane[j % LANES], slot_terms(displacement[s.particle as usize], sp, s));
        }
        let mut stride = LANES / 2;
        while stride > 0 {
            for t in 0..stride {
                lane[t] = add4(lane[t], lane[t + stride]);
            }
            stride /= 2;
        }
        lane[0]
    }

    /// `cluster_sums` (two halvings in registers, zero lanes skipped) adds exactly as the
    /// full 64-lane workgroup does: the same bits for 0 to 200 slots, signed zeros and
    /// magnitudes from 1e-6 to 1e3 included.
    #[test]
    fn cluster_sums_add_as_the_workgroup_does() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        let value = |rng: &mut rand_chacha::ChaCha8Rng| match rng.random_range(0..8) {
            0 => 0.0,
            1 => -0.0,
            _ => rng.random_range(-1.0f32..1.0) * 10f32.powi(rng.random_range(-6..4)),
        };
        let mut quarter = [[Vec3A::ZERO; 4]; LANES / 4];
        for count in (0..=200).chain([256, 257]) {
            let displacement: Vec<[f32; 4]> = (0..count + 3)
                .map(|_| [value(&mut rng), value(&mut rng), value(&mut rng), rng.random_range(0.01..2.0)])
                .collect();
            let run: Vec<RawHsmSlot> = (0..count)
                .map(|_| RawHsmSlot {
                    q: [value(&mut rng), value(&mut rng), value(&mut rng)],
                    particle: rng.random_range(0..displacement.len() as u32),
                })
                .collect();
            let sp = Vec3A::new(value(&mut rng), value(&mut rng), value(&mut rng));
            let bits = |s: [Vec3A; 4]| s.map(|v| v.to_array().map(f32::to_bits));
            assert_eq!(
                bits(cluster_sums(&run, &displacement, sp, &mut quarter)),
                bits(workgroup_sums(&run, &displacement, sp)),
                "{count} slots"
            );
        }
    }

    /// The cluster wind compiled for AVX2 (where the CPU has it) and for the baseline gives
    /// the same bits, at random centres and times, on every wind preset; w is the drag's
    /// reconfiguration at the wind; a leaf cluster's wind is a segment's at the same centre
    /// plus its band of air ([`leaf_air`]), which moves it wherever the wind blows.
    #[test]
    fn cluster_wind_is_the_same_at_every_level() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let info: Vec<RawHsmClusterInfo> = (0..300)
            .map(|i| RawHsmClusterInfo {
                kind: if i % 7 == 3 { kind::LEAF } else { kind::SEGMENT },
                source: i,
                ..bytemuck::Zeroable::zeroed()
            })
            .collect();
        let as_segments: Vec<RawHsmClusterInfo> =
            info.iter().map(|i| RawHsmClusterInfo { kind: kind::SEGMENT, ..*i }).collect();
        let clusters: Vec<RawHsmCluster> = (0..info.len())
            .map(|_| {
                let mut c: RawHsmCluster = bytemuck::Zeroable::zeroed();
                c.aqq_inv[1][3] = rng.random_range(10.0..60.0);
                c
            })
            .collect();
        for (name, _, _) in crate::wind::PRESETS {
            let (fields, waves) = WindScene::resolve(name).unwrap().pack();
            for _ in 0..5 {
                let time = rng.random_range(0.0..30.0);
                let state: Vec<RawHsmClusterState> = (0..info.len())
                    .map(|_| RawHsmClusterState {
                        cm: [
                            rng.random_range(-30.0..30.0),
                            rng.random_range(0.0..25.0),
                            rng.random_range(-30.0..30.0),
                            0.5,
                        ],
                        ..bytemuck::Zeroable::zeroed()
                    })
                    .collect();
                let drag = crate::physics::DragModel::default();
                let step = RawHsmStep {
                    time,
                    reconfiguration_speed: drag.reconfiguration_speed,
                    vogel_exponent: drag.vogel_exponent,
                    leaf_turbulence: 0.2,
                    flutter_onset: 3.0,
                    leaf_zeta: 0.15,
                    ..bytemuck::Zeroable::zeroed()
                };
                let run = |level: Level, info: &[RawHsmClusterInfo]| {
                    let mut s = state.clone();
                    wind_chunk_at(level, &fields, &waves, info, &clusters, &step, &mut s);
                    s
                };
                let base = run(Level::Baseline, &info);
                let plain = run(Level::Baseline, &as_segments);
                for (i, (s, p)) in base.iter().zip(&plain).enumerate() {
                    let u = Vec3::from_slice(&p.wind[..3]);
                    // w is the reconfiguration at the wind's speed.
                    let g = drag.reconfiguration(u.length());
                    assert!((s.wind[3] - g).abs() <= 1e-6 * g, "{name}: cluster {i} w {} against {g}", s.wind[3]);
                    let air = Vec3::from_slice(&s.wind[..3]) - u;
                    if info[i].kind == kind::LEAF {
                        // The sum's rounding aside (a few ulps of the wind).
                        let want = leaf_air(u, clusters[i].aqq_inv[1][3], i as u32, &step);
                        assert!(
                            (air - want).length() <= 1e-6 * (u.length() + 1.0),
                            "{name}: leaf {i}: {air} against {want}"
                        );
                        assert_eq!(air != Vec3::ZERO, u != Vec3::ZERO, "{name}: leaf {i} in {u}: air {air}");
                    } else {
                        assert_eq!(air, Vec3::ZERO, "{name}: cluster {i}");
                    }
                }
                let bits =
                    |s: &[RawHsmClusterState]| s.iter().flat_map(|c| c.wind.map(f32::to_bits)).collect::<Vec<_>>();
                assert_eq!(bits(&base), bits(&run(detected(), &info)), "{name} at t = {time}");
            }
        }
    }
}
