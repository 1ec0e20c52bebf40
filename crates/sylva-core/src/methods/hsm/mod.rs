//! Song et al.'s hierarchical shape matching (HSM, §4–5; shape matching after Müller et al.
//! 2005): every branch segment and every leaf is a **cluster** of particles that keeps its
//! own shape; clusters overlap head to tail, and force travels through the shared particles.
//!
//! # Clusters (§4, Figs. 3–5)
//! * A **segment cluster** is `rings` rings of `ring_size` particles along the segment
//!   (ring `j` at `j / (rings − 1)` of its length). Its first ring is *shared*: it is the ring
//!   of the parent's cluster nearest to the segment's joint (the parent's tail ring for a
//!   stem's next segment — Song's head-to-tail link). The root's first ring is its own and
//!   **fixed** (the tree stands in the ground).
//! * A **leaf cluster** is the nearest ring of its segment's cluster (shared) plus
//!   `leaf_particles` points on the blade (its tip, then points along an edge). Its rate is
//!   its petiole's swing `ω²`, the closed form's ([`crate::leaves::leaf_constants`]: from
//!   the blade and the species' `[leaf_motion]`, above its twig's mode), over the fraction
//!   of a swing its spring holds ([`layout::swing_fraction`]: the blade drags the cluster's
//!   centre and R along), so a leaf swings near the same frequency in every method. Its
//!   blade feels the wind at the cluster's centre plus the air at the leaf's own scale, a
//!   narrow band about ω ([`kernels::leaf_air`], [`HsmParams::leaf_turbulence`]): that is
//!   what makes it flutter. The pose seam's leaf rotation is where the blade
//!   points: [`kernels::hsm_leaf_pose`] reads the tip and edge particles in the cluster's
//!   frame.
//! * Particles are the simulation's proxies, not the bark: a ring's radius is the segment's
//!   radius but never less than `ring_ratio × length`, because a joint resists bending
//!   through the lever of its shared ring and a 2 mm twig ring would have none. Mass and
//!   drag area come from the tree (wood density × volume, leaf areal density × blade area).
//!
//! # Layout (§5.1, Figs. 6–9)
//! [`HsmLayout`] holds Song's four groups as flat arrays shared by the CPU and the GPU:
//! *tree information* (`RawHsmStep::clusters`, `particles`, `max_children`), *cluster
//! information* ([`RawHsmClusterInfo`]: kind, source, particle (slot) offset and count),
//! *cluster data* ([`RawHsmCluster`]: parent, children, rest centre of mass, Aqq⁻¹; and the
//! per-step [`RawHsmClusterState`]: current centre of mass, R, the goal transform, the
//! wind), and *particle data* (displacement from rest + mass, velocity + drag factor (or
//! [`FIXED`]), rest position, owner). The state is kept as displacements `u = x − x⁰`, not
//! positions: the stages then never read the rest positions (every per-particle byte
//! counts, the large layouts are memory-bound), and a particle at rest is exactly zero. A cluster's particles are its run of [`RawHsmSlot`]s (particle index and rest
//! offset `q = x⁰ − c⁰`); each particle lists the clusters it belongs to with its offset in
//! each ([`RawHsmMember`]), so a particle's goal is a deterministic gather over its
//! clusters, never a float atomic.
//!
//! # The step (Table 1, §5.2's four stages)
//! 1. `hsm_clusters` (one GPU workgroup per cluster, shared-memory reduction): centre of
//!    mass `c`, `Apq = Σ m (x − c⁰) qᵀ`, the rotation `R` of `Apq` (see below), the goal
//!    transform `T = β Â + (1 − β) R` with `Â = Apq Aqq⁻¹ / det^⅓` (Müller's linear blend;
//!    `β = 0` is pure rotation), the cluster's weight `w = k h²` and the wind at `c`.
//! 2. Synchronisation: the end of the dispatch.
//! 3. `hsm_goals` (per particle): over the clusters sharing it, `g_c = T_c q + c_c`; the goal
//!    is the weighted mean `ĝ = Σ w_c g_c / Σ w_c`, kept with `Σ w_c` (Table 1 steps 3–4
//!    take `Σ α / n`; with n, a ring shared by twenty leaves had its segment's hold
//!    diluted twentyfold).
//! 4. `hsm_integrate` (per particle): `v += ᾱ (ĝ − x) / h + h g` with
//!    `ᾱ = min(Σ w_c, hold)` (see "Stiffness" below; Table 1 steps 5–6; a
//!    prestressed tree's support cancels g, see [`HsmParams::prestressed`]),
//!    drag toward the wind `u` sampled at its cluster's centre (a leaf's with its band of air)
//!    `v += (u − v) s / (1 + s)`,
//!    `s = h k_d g(|u|) |u − v|` (semi-implicit, so it never overshoots the air; `g` Vogel's
//!    reconfiguration at the cluster's wind, [`kernels::reconfiguration`], as every method
//!    streamlines), damping `v *= e^{−c h}`, then `x += h v` (step 7).
//!
//! Stages 3 and 4 run as one pass by default (`hsm_particles`, see [`HsmParams::fused`]):
//! the same numbers bit for bit, without the goal buffer.
//!
//! The GPU twins (`sylva_gpu::hsm::GpuHsm`) run the same stages over the same buffers, every
//! substep of a step in one submission.
//!
//! **Stiffness** is a rate, not a per-step fraction: a cluster's weight is `w = k h²` with
//! `k` in 1/s² (from the wood's `E·I/L`, trunk stiffest). Where `Σ w` is under the hold,
//! `v += k h (g − x)` is a spring of angular frequency √k integrated by symplectic Euler and
//! the static sag under gravity (`x − g = g/k`) does not depend on the step. The weights
//! themselves may pass the hold (up to the smallest rate on the cluster's path to the
//! root): a shared particle's goal is where its clusters' spring forces balance, so a thick
//! stem holds the ring it shares with a twig or a leaf (see
//! [`crate::methods::hsm::kernels::MAX_WEIGHT`]).
//!
//! **The hold** is a rate of the tree, not of the step: `ᾱ = min(Σ w, s (r h)²)` with `r`
//! the substep rate ([`HsmParams::substep_rate`]) and `s` the rate scale. Short, thick
//! segments, and rings shared by hundreds of twigs, are stiffer than any affordable
//! explicit step can hold; Müller's clamp `ᾱ ≤ 1` held them at `1/h²`, so a tree's
//! frequency rose with the substeps (the small aspen 0.95 → 5.9 Hz from 240 to 3,840
//! substeps/s). The hold scales such a particle's pull as if its mass were `Σ w / hold`
//! times larger (mass scaling), by the same factor at any step, and substeps rise until
//! `s (r h)² ≤ 1`, so Müller's stability is kept and the same tree sways alike at 30, 60,
//! 120 or 240 frames/s. The scale `s` comes from the wood ([`calibrate`]): the trunk,
//! plucked when the method is built, sways at its first mode from
//! [`crate::physics::stem_frequencies`], and each side stem, plucked with its parent held,
//! at its own (a factor on its clusters' rates besides `s`). Damping is a ratio of the
//! trunk's mode ([`HsmParams::damping_ratio`]); the drag adds the air's, weighed by the
//! inertia the hold gives the trunk's mode ([`HsmLayout::air_scale`]).
//!
//! **Rotation**: `R` is extracted by the iterative method of Müller, Bender, Chentanez &
//! Macklin (2016), warm-started from the last step's R, `R ← rot(ω) R` (the unit
//! quaternion along `(ω/2, 1)`, no trigonometry), with a Newton step: `ω = H⁻¹ g`,
//! `g = Σ rᵢ × aᵢ`, `H = tr(B) I − sym(B)`, `B = Apq Rᵀ` (the gradient and Hessian of
//! `tr(Rᵀ Apq)`), blended toward Müller's `ω = g / (|tr B| + ε)` where `H` is not safely
//! positive definite (see [`crate::methods::hsm::kernels::rotation_step`]). It yields a rotation for any
//! finite `Apq` — flat (leaf), collinear, inverted or zero clusters included — never NaN,
//! and reaches the optimal rotation in 1–2 iterations per step warm, elongated clusters
//! included, where Müller's step alone turns them about their long axis by only
//! `(σ₂ + σ₃) / (σ₁ + σ₂ + σ₃)` of the way per iteration. R is a continuous function of
//! the particles (no threshold switches a step on or off), so rounding differences between
//! the CPU and a GPU stay rounding-sized (see [`crate::methods::hsm::kernels::extract_rotation`]).
//!
//! # Pose
//! Each segment turns by its cluster's R (the pose seam's accumulated rotation D = R), and
//! joints follow by forward kinematics, so lengths are kept and the mesh stays connected.
//! The cluster transform `R (x⁰ − c⁰) + c` of a joint stays within a few millimetres of it
//! (see the tests).

pub mod calibrate;
pub mod kernels;
pub mod layout;
pub mod leaf_pose;
pub mod params;
pub mod raw;
pub mod rotation;
pub mod runs;
pub mod slot_groups;

pub use layout::HsmLayout;
pub use params::*;
pub use raw::*;

use super::{Animator, Method, MethodError, MethodOptions, Simulation};
use crate::model::{NONE, Tree};
use crate::pose::{Pose, SeamPose};
use crate::wind::PackedWind;
use crate::wind::raw::{RawField, RawWave};
use bytemuck::Zeroable;
use glam::Vec3;
use kernels::{hsm_goals, hsm_integrate, hsm_leaf_pose, hsm_pose};
use runs::{HsmRuns, avx2_at, hsm_particles_runs};
use slot_groups::{HsmSlotGroups, hsm_clusters_groups};
use std::sync::Arc;

/// Simulation state: structure of arrays, particles in layout order.
#[derive(Debug, Clone, PartialEq)]
pub struct HsmState {
    /// Displacement from the rest position `x − x⁰` (xyz, m) and mass (w, kg) of each
    /// particle; [`Hsm::positions`] adds the rest back.
    pub displacement: Vec<[f32; 4]>,
    /// Velocity (xyz, m/s) of each particle; w is its drag factor `k_d` (1/m, as in
    /// [`HsmLayout::rest`]), or [`FIXED`] for a fixed particle.
    pub velocity: Vec<[f32; 4]>,
    /// Per-cluster results of the last substep.
    pub clusters: Vec<RawHsmClusterState>,
    /// Goal as a displacement from rest (xyz, m) and Σ w (w) of each particle from the last
    /// substep.
    pub goal: Vec<[f32; 4]>,
    /// Simulated time, s.
    pub time: f32,
}

impl HsmState {
    /// Kinetic energy ½ Σ m v², J.
    pub fn kinetic_energy(&self) -> f64 {
        self.displacement
            .iter()
            .zip(&self.velocity)
            .map(|(p, v)| 0.5 * p[3] as f64 * (Vec3::new(v[0], v[1], v[2]).length_squared() as f64))
            .sum()
    }

    /// Largest distance of any particle from the same particle in `other`, m.
    pub fn max_distance(&self, other: &HsmState) -> f32 {
        self.displacement
            .iter()
            .zip(&other.displacement)
            .map(|(a, b)| (Vec3::new(a[0], a[1], a[2]) - Vec3::new(b[0], b[1], b[2])).length())
            .fold(0.0, f32::max)
    }
}

/// Hierarchical shape matching set up for one tree (or a forest of copies).
#[derive(Debug, Clone)]
pub struct Hsm {
    /// Parameters.
    pub params: HsmParams,
    /// Song's linearised tree.
    pub layout: HsmLayout,
    /// The layout's particles in runs of shared membership, for the CPU's fused pass.
    runs: HsmRuns,
    /// The layout's slots in groups of eight, for the CPU's stage 1.
    groups: HsmSlotGroups,
    rest_joints: Vec<[f32; 4]>,
    /// Cluster of each leaf of the tree (`u32::MAX` where a truncated layout has none).
    pub leaf_cluster: Vec<u32>,
    /// Each leaf's blade in the particles, for [`kernels::hsm_leaf_pose`].
    pub leaves: Vec<RawHsmLeaf>,
    /// The tree's leaf motion: the onset, band width and crown share of the leaves' air.
    pub leaf_motion: crate::leaves::LeafMotion,
}

impl Hsm {
    /// Builds the clusters of every segment and leaf of `tree`, calibrated to its wood when
    /// [`HsmParams::calibrate`] is set.
    pub fn new(tree: &Tree, params: HsmParams) -> Result<Self, HsmError> {
        let layout = HsmLayout::new(tree, &params, None)?;
        let mut hsm = Self::from_layout(tree, params, layout);
        if params.calibrate && params.substep_rate > 0.0 {
            calibrate::calibrate(tree, &mut hsm);
        }
        Ok(hsm)
    }

    /// Substeps for a step of `dt` seconds (see [`HsmParams::substep_rate`]).
    pub fn substeps(&self, dt: f32) -> u32 {
        let p = &self.params;
        let rate = p.substep_rate * self.layout.rate_scale.max(1.0).sqrt();
        let n = (dt * rate - 1e-4).ceil();
        (if n.is_finite() { n.clamp(1.0, MAX_SUBSTEPS as f32) as u32 } else { 1 }).max(p.substeps)
    }

    /// The hold `s (r h)²` of a substep `h` (1 without a substep rate; see [`RawHsmStep::hold`]).
    pub fn hold(&self, h: f32) -> f32 {
        let r = self.params.substep_rate;
        if r > 0.0 { (self.layout.rate_scale * (r * h).powi(2)).min(1.0) } else { 1.0 }
    }

    /// Uses a prepared layout (truncated or a forest).
    pub fn from_layout(tree: &Tree, params: HsmParams, layout: HsmLayout) -> Self {
        let rest_joints = tree.segments.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        let runs = HsmRuns::new(&layout);
        let groups = HsmSlotGroups::new(&layout);
        let mut leaf_cluster = vec![NONE; tree.leaves.len()];
        let mut leaves: Vec<RawHsmLeaf> = tree
            .leaves
            .segment
            .iter()
            .map(|&segment| RawHsmLeaf { segment, strength: tree.leaf_motion.strength, ..RawHsmLeaf::zeroed() })
            .collect();
        let blade = params.leaf_particles;
        for (c, info) in layout.info.iter().enumerate() {
            if info.kind == kind::LEAF && (info.source as usize) < leaf_cluster.len() && info.slot_count > blade {
                leaf_cluster[info.source as usize] = c as u32;
                let ring = info.slot_count - blade;
                let at = |j: u32| {
                    let p = layout.slots[(info.slot_offset + j) as usize].particle as usize;
                    Vec3::from_slice(&layout.rest[p][..3])
                };
                let centre = (0..ring).map(at).sum::<Vec3>() / ring as f32;
                let attach = tree.leaves.position[info.source as usize];
                let lf = &mut leaves[info.source as usize];
                lf.slot_offset = info.slot_offset;
                lf.cluster = c as u32;
                lf.ring = ring;
                lf.blade = blade;
                lf.attach = (attach - centre).to_array();
                lf.tip = (at(ring) - attach).to_array();
                if blade > 1 {
                    lf.edge = (at(ring + 1) - attach).to_array();
                }
            }
        }
        Self { params, layout, runs, groups, rest_joints, leaf_cluster, leaves, leaf_motion: tree.leaf_motion }
    }

    /// The state at rest (without prestress, gravity has yet to sag it: see [`Self::settle`]).
    /// The same as [`Method::rest_state`], for layouts without their tree at hand.
    pub fn state_at_rest(&self) -> HsmState {
        let l = &self.layout;
        HsmState {
            displacement: l.mass.iter().map(|m| [0.0, 0.0, 0.0, *m]).collect(),
            velocity: l
                .rest
                .iter()
                .zip(&l.free)
                .map(|(r, f)| [0.0, 0.0, 0.0, if *f > 0.0 { r[3] } else { FIXED }])
                .collect(),
            clusters: l.clusters.iter().map(RawHsmClusterState::rest).collect(),
            goal: vec![[0.0; 4]; l.rest.len()],
            time: 0.0,
        }
    }

    /// Bytes a CPU substep moves, counted as [`HsmLayout::bytes_per_step`] counts them: the
    /// same where the CPU runs the WGSL's shapes, fewer where it runs its fast forms (stage 1
    /// over groups of slots, [`HsmSlotGroups::bytes_per_pass`], and the fused pass over runs,
    /// [`HsmRuns::bytes_per_pass`]).
    pub fn cpu_bytes_per_step(&self) -> usize {
        let l = &self.layout;
        if !avx2_at(crate::simd::level()) {
            return l.bytes_per_step(self.params.fused);
        }
        let particles =
            if self.params.fused { self.runs.bytes_per_pass() } else { l.bytes_per_step(false) - l.stage1_bytes() };
        self.groups.bytes_per_pass(l) + particles
    }

    /// The per-substep values the kernels read.
    pub fn step_params(&self, time: f32, dt: f32) -> RawHsmStep {
        let p = &self.params;
        RawHsmStep {
            gravity: [0.0, -p.gravity, 0.0, if p.prestressed { 1.0 } else { 0.0 }],
            dt,
            time,
            damping: (-2.0 * p.damping_ratio * std::f32::consts::TAU * self.layout.sway_hz * dt).exp(),
            beta: p.beta,
            polar_iterations: p.polar_iterations,
            clusters: self.layout.info.len() as u32,
            particles: self.layout.rest.len() as u32,
            max_children: self.layout.max_children,
            hold: self.hold(dt),
            reconfiguration_speed: p.reconfiguration_speed,
            vogel_exponent: p.vogel_exponent,
            air: if p.drag_scale > 0.0 {
                p.air_damping * self.layout.air_scale / (p.drag_scale * self.layout.load_scale)
            } else {
                1.0
            },
            sample_wind: 1,
            leaf_turbulence: p.leaf_turbulence * self.leaf_motion.crown_wind,
            flutter_onset: self.leaf_motion.flutter_onset / self.leaf_motion.crown_wind.max(f32::MIN_POSITIVE),
            leaf_zeta: self.leaf_motion.damping_ratio,
        }
    }

    /// One substep: the four stages.
    pub fn substep(&self, fields: &[RawField], waves: &[RawWave], state: &mut HsmState, h: f32) {
        self.substep_with(fields, waves, state, self.step_params(state.time + h, h));
    }

    /// One substep with the given step values.
    pub fn substep_with(&self, fields: &[RawField], waves: &[RawWave], state: &mut HsmState, step: RawHsmStep) {
        let l = &self.layout;
        hsm_clusters_groups(fields, waves, l, &self.groups, &state.displacement, step, &mut state.clusters);
        if self.params.fused {
            hsm_particles_runs(l, &self.runs, &state.clusters, step, &mut state.displacement, &mut state.velocity);
        } else {
            hsm_goals(&l.member_offset, &l.member, &state.clusters, &mut state.goal);
            hsm_integrate(&l.owner, &state.clusters, &state.goal, step, &mut state.displacement, &mut state.velocity);
        }
        state.time = step.time;
    }

    /// Advances `state` by `dt` seconds in [`Self::substeps`] substeps ([`Method::step`] with
    /// the wind's packed arrays). The wind is sampled once per step, at the clusters' centres
    /// after its first substep, and held through the others, as Akagi and Skjermo hold theirs
    /// over a step: the substeps resolve the wood's stiffness, not the wind, whose fastest
    /// eddies (8 Hz in `gusty`) a 60 Hz step already resolves. Sampling it every substep cost
    /// a fifth of the CPU's step on the aspen.
    pub fn step_packed(&self, fields: &[RawField], waves: &[RawWave], state: &mut HsmState, dt: f32) {
        let n = self.substeps(dt);
        let h = dt / n as f32;
        for k in 0..n {
            let step = RawHsmStep { sample_wind: (k == 0) as u32, ..self.step_params(state.time + h, h) };
            self.substep_with(fields, waves, state, step);
        }
    }

    /// Steps in still air until the kinetic energy per kilogram falls below `tolerance`
    /// (J/kg) or `max_steps` pass; returns the steps taken. The settled state is the tree's
    /// rest under gravity, which wind displaces and damping returns to.
    pub fn settle(&self, state: &mut HsmState, dt: f32, max_steps: usize, tolerance: f64) -> usize {
        let total: f64 = self.layout.mass.iter().map(|&m| m as f64).sum();
        for k in 0..max_steps {
            self.step_packed(&[], &[], state, dt);
            if state.kinetic_energy() / total.max(1e-12) < tolerance {
                return k + 1;
            }
        }
        max_steps
    }

    /// Particle positions `x⁰ + u` of `state`, m.
    pub fn positions(&self, state: &HsmState) -> Vec<Vec3> {
        self.layout
            .rest
            .iter()
            .zip(&state.displacement)
            .map(|(r, u)| Vec3::new(r[0] + u[0], r[1] + u[1], r[2] + u[2]))
            .collect()
    }

    /// Accumulated rotations of the pose seam: each segment's cluster R (identity for
    /// segments a truncated layout left out).
    pub fn rotations(&self, state: &HsmState) -> Vec<[f32; 4]> {
        let mut acc = vec![[0.0f32; 4]; self.layout.segment_cluster.len()];
        hsm_pose(&self.layout.segment_cluster, &state.clusters, &mut acc);
        acc
    }

    /// Each leaf's rotation in its segment's rest frame, from its blade's particles (Song
    /// §4: a leaf is a cluster of its own; see [`kernels::hsm_leaf_pose`]). `acc` holds
    /// the segments' rotations.
    pub fn leaf_rotations(&self, state: &HsmState, acc: &[[f32; 4]], out: &mut Vec<[f32; 4]>) {
        out.resize(self.leaves.len(), [0.0, 0.0, 0.0, 1.0]);
        hsm_leaf_pose(&self.leaves, &self.layout.slots, &state.displacement, &state.clusters, acc, out);
    }

    /// Where each segment cluster's own transform puts its segment's joint,
    /// `R (x⁰ − c⁰) + c` (a check on the forward-kinematics pose).
    pub fn cluster_joints(&self, tree: &Tree, state: &HsmState) -> Vec<Vec3> {
        (0..tree.segments.len())
            .map(|i| {
                let c = self.layout.segment_cluster[i];
                if c == NONE {
                    return tree.segments.start[i];
                }
                let st = &state.clusters[c as usize];
                let rest = &self.layout.clusters[c as usize].rest_cm;
                let r = glam::Quat::from_array(st.rotation);
                r * (tree.segments.start[i] - Vec3::new(rest[0], rest[1], rest[2]))
                    + Vec3::new(st.cm[0], st.cm[1], st.cm[2])
            })
            .collect()
    }
}

impl From<HsmError> for MethodError {
    fn from(e: HsmError) -> Self {
        match e {
            HsmError::Param { field, value, expected } => MethodError::Param {
                method: "hsm",
                field: field.into(),
                value: value.to_string(),
                expected: expected.into(),
            },
            HsmError::TooLarge { what, needed, limit } => MethodError::TooLarge { method: "hsm", what, needed, limit },
        }
    }
}

/// The registry's CPU constructor: hierarchical shape matching on `tree` with `options`.
pub fn animator(tree: Arc<Tree>, options: &MethodOptions) -> Result<Box<dyn Animator>, MethodError> {
    let params = options.parse::<HsmParams>("hsm")?;
    let method = Hsm::new(&tree, params)?;
    Ok(Simulation::boxed(tree, method))
}

impl Method for Hsm {
    type State = HsmState;

    fn name(&self) -> &'static str {
        "hsm"
    }

    fn rest_state(&self, _tree: &Tree) -> HsmState {
        self.state_at_rest()
    }

    fn step(&self, _tree: &Tree, wind: &PackedWind, state: &mut HsmState, dt: f32) {
        self.step_packed(&wind.fields, &wind.waves, state, dt);
    }

    fn time(&self, state: &HsmState) -> f32 {
        state.time
    }

    fn set_time(&self, state: &mut HsmState, time: f32) {
        state.time = time;
    }

    fn seam(&self, tree: &Tree, _wind: &PackedWind, state: &HsmState, out: &mut SeamPose) {
        out.acc = self.rotations(state);
        out.joints.resize(out.acc.len(), [0.0; 4]);
        crate::pose::fk::positions_forward(&tree.segments.parent, &self.rest_joints, &out.acc, &mut out.joints);
        self.leaf_rotations(state, &out.acc, &mut out.leaf);
    }

    /// Segments turned by their clusters' rotations, joints by forward kinematics.
    fn pose(&self, tree: &Tree, _wind: &PackedWind, state: &HsmState) -> Pose {
        let acc = self.rotations(state);
        let mut joints = vec![[0.0f32; 4]; acc.len()];
        crate::pose::fk::positions_forward(&tree.segments.parent, &self.rest_joints, &acc, &mut joints);
        Pose {
            start: joints.iter().map(|j| Vec3::new(j[0], j[1], j[2])).collect(),
            orientation: acc
                .iter()
                .zip(&tree.segments.orientation)
                .map(|(d, q)| glam::Quat::from_array(*d) * *q)
                .collect(),
            bezier: None,
        }
    }

    fn cluster_centres(&self, state: &HsmState) -> Option<Vec<Vec3>> {
        Some(state.clusters.iter().map(|c| Vec3::new(c.cm[0], c.cm[1], c.cm[2])).collect())
    }

    fn particles(&self) -> Option<usize> {
        Some(self.layout.particle_count())
    }
}
