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
//!   `leaf_particles` points on the blade (its tip, then points along an edge).
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
//!    is the weighted mean `ĝ = Σ w_c g_c / Σ w_c` with `ᾱ = min(1, Σ w_c)` (Table 1
//!    steps 3–4 take `Σ α / n`; with n, a ring shared by twenty leaves had its segment's
//!    hold diluted twentyfold).
//! 4. `hsm_integrate` (per particle): `v += ᾱ (ĝ − x) / h + h g` (Table 1 steps 5–6; a
//!    prestressed tree's support cancels g, see [`HsmParams::prestressed`]),
//!    drag toward the wind `u` sampled at its cluster's centre (a leaf's segment's)
//!    `v += (u − v) s / (1 + s)`,
//!    `s = h k_d |u − v|` (semi-implicit, so it never overshoots the air), damping
//!    `v *= e^{−c h}`, then `x += h v` (step 7).
//!
//! Stages 3 and 4 run as one pass by default (`hsm_particles`, see [`HsmParams::fused`]):
//! the same numbers bit for bit, without the goal buffer.
//!
//! The GPU twins (`sylva_gpu::hsm::GpuHsm`) run the same stages over the same buffers, every
//! substep of a step in one submission.
//!
//! **Stiffness** is a rate, not a per-step fraction: a cluster's weight is `w = k h²` with
//! `k` in 1/s² (from the wood's `E·I/L`, trunk stiffest). Where `Σ w < 1`,
//! `v += k h (g − x)` is a spring of angular frequency √k integrated by symplectic Euler and
//! the static sag under gravity (`x − g = g/k`) does not depend on the step; the clamp
//! `ᾱ ≤ 1` keeps Müller's unconditional stability. The weights themselves may pass 1 (up
//! to the smallest rate on the cluster's path to the root): a shared particle's goal is
//! where its clusters' spring forces balance, so a thick stem holds the ring it shares
//! with a twig or a leaf (see [`crate::cpu::hsm::MAX_WEIGHT`]). What the clamp still
//! limits: a joint between two clusters that are both stiffer than `1/h²` resists bending
//! by about `m L² / h²` (its shared particles' mass and lever), less than the wood of
//! short, thick segments. Such trees bend more than Akagi's beam model says unless the
//! substeps rise (`docs/PERFORMANCE.md`, "HSM stiffness against the wood's").
//!
//! **Rotation**: `R` is extracted by the iterative method of Müller, Bender, Chentanez &
//! Macklin (2016), warm-started from the last step's R, `R ← rot(ω) R` (the unit
//! quaternion along `(ω/2, 1)`, no trigonometry), with a Newton step: `ω = H⁻¹ g`,
//! `g = Σ rᵢ × aᵢ`, `H = tr(B) I − sym(B)`, `B = Apq Rᵀ` (the gradient and Hessian of
//! `tr(Rᵀ Apq)`), blended toward Müller's `ω = g / (|tr B| + ε)` where `H` is not safely
//! positive definite (see [`crate::cpu::hsm::rotation_step`]). It yields a rotation for any
//! finite `Apq` — flat (leaf), collinear, inverted or zero clusters included — never NaN,
//! and reaches the optimal rotation in 1–2 iterations per step warm, elongated clusters
//! included, where Müller's step alone turns them about their long axis by only
//! `(σ₂ + σ₃) / (σ₁ + σ₂ + σ₃)` of the way per iteration. R is a continuous function of
//! the particles (no threshold switches a step on or off), so rounding differences between
//! the CPU and a GPU stay rounding-sized (see [`crate::cpu::hsm::extract_rotation`]).
//!
//! # Pose
//! Each segment turns by its cluster's R (the pose seam's accumulated rotation D = R), and
//! joints follow by forward kinematics, so lengths are kept and the mesh stays connected.
//! The cluster transform `R (x⁰ − c⁰) + c` of a joint stays within a few millimetres of it
//! (see the tests).

use super::Pose;
use crate::cpu::hsm::{hsm_goals, hsm_integrate, hsm_pose};
use crate::cpu::hsm_runs::{HsmRuns, avx2_at, hsm_particles_runs};
use crate::cpu::hsm_slot_groups::{HsmSlotGroups, hsm_clusters_groups};
use crate::model::{NONE, Tree};
use crate::wind::WindScene;
use crate::wind::raw::{RawField, RawWave};
use crate::wind::trunk::AIR_DENSITY;
use bytemuck::{Pod, Zeroable};
use glam::{DMat3, DVec3, Mat3, Vec3};

/// Cluster kinds ([`RawHsmClusterInfo::kind`]).
pub mod kind {
    /// A branch segment.
    pub const SEGMENT: u32 = 0;
    /// A leaf.
    pub const LEAF: u32 = 1;
    /// A whole stem (the global level of Song's Fig. 4).
    pub const STEM: u32 = 2;
}

/// Largest particles per ring, rings per segment and particles per leaf.
pub const MAX_PER_CLUSTER: u32 = 64;

/// Parameters of hierarchical shape matching.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HsmParams {
    /// Rings per segment cluster, the shared head ring included (≥ 2). Default 2: head and
    /// tail, Song's Fig. 5.
    pub rings: u32,
    /// Particles per ring (≥ 3). Default 4: the fewest that make a ring resist twist as
    /// well as bending, at Song's cost per cluster (Table 2 has 42–60 particles per
    /// cluster; the bench sets rings and ring size to match).
    pub ring_size: u32,
    /// Smallest ring radius as a fraction of the segment's length. Default 0.25 (see the
    /// module notes: a joint's bending resistance is the lever of its shared ring).
    pub ring_ratio: f32,
    /// How far a segment cluster reaches into its parent: 1 = the parent's ring nearest
    /// to the joint (Song's head-to-tail link), 2 = the parent's whole segment (all its
    /// rings). Default 2: a joint then resists bending through the parent's length rather
    /// than a ring's radius, so a trunk holds its crown up under gravity with few substeps
    /// (Müller et al. 2005 widen overlapping regions for the same reason).
    pub overlap: u32,
    /// Add a cluster per stem over all its rings (Song's global shape matching, Fig. 4).
    /// Default true: with segment clusters alone, load travels one segment per substep and
    /// a long stem sags with the square of its segment count.
    pub stem_clusters: bool,
    /// Particles on each leaf blade besides the shared ring (≥ 1). Default 2: its tip and
    /// a point on its edge, enough to give the blade an orientation.
    pub leaf_particles: u32,
    /// Scale on every segment cluster's stiffness. Default 1: the wood's own bending
    /// stiffness (see the module notes on how a cluster's `k` follows from `E·I/L`).
    pub stiffness_scale: f32,
    /// Thinnest radius used for a joint's bending stiffness, m (as
    /// [`super::akagi::AkagiParams::min_radius`]). Default 1.5 mm.
    pub min_radius: f32,
    /// Stiffness of leaf clusters, 1/s². Default 900 (30 rad/s): leaves flutter.
    pub leaf_stiffness: f32,
    /// Velocity damping rate c, 1/s: `v *= e^{−c h}` each substep. Default 2: a branch
    /// released in still air rings down within a few seconds, as wood and air damp it
    /// (damping ratios 0.05–0.3), on top of the aerodynamic damping of the drag.
    pub damping: f32,
    /// Drag coefficient of bark (a cylinder in cross-flow ≈ 1.0–1.2). Default 0.8.
    pub drag: f32,
    /// Drag coefficient per (one-sided) leaf area. Default 0.05: leaves shelter one
    /// another (see [`super::akagi::AkagiParams::leaf_drag`]).
    pub leaf_drag: f32,
    /// Gravity along −Y, m/s². Default 9.81.
    pub gravity: f32,
    /// The tree as generated is its shape *under its own weight*: a support equal and
    /// opposite to gravity holds every particle, so still air keeps the rest shape exactly.
    /// Default true: generators draw trees as they stand, and a particle's step toward its
    /// goal is capped at ᾱ = 1 per substep, which for tall, thin trees is less than wood's —
    /// bare gravity would sag them (a stem of n segments sags roughly as n² h² g). A support
    /// that turned with the wood (`−R g`) was tried and rejected: it is not conservative
    /// and pumps energy into spinning leaves. False applies bare gravity.
    pub prestressed: bool,
    /// Müller's linear blend β ∈ [0, 1]: 0 matches rotations only (rigid clusters);
    /// larger values let clusters shear and stretch. Default 0.
    pub beta: f32,
    /// Iterations of the rotation extraction per step (all of them run, so R is a
    /// continuous function of the particles; see [`crate::cpu::hsm::extract_rotation`]).
    /// Default 2: warm-started from the last substep, one iteration tracks the motion and
    /// the second refines it; a cold start (a cluster rotated far in one step) needs up to
    /// about 20.
    pub polar_iterations: u32,
    /// Run stages 3 and 4 as one pass per particle (`hsm_particles`) instead of two
    /// (`hsm_goals`, then `hsm_integrate` through the goal buffer). Default true: a
    /// particle's gathered goal is read by no other particle, so the fused pass gives the
    /// same numbers bit for bit while moving about a quarter fewer bytes per step (see
    /// `docs/PERFORMANCE.md`). On the CPU the fused pass runs over runs of particles that
    /// share their clusters, eight to an AVX2 register ([`crate::cpu::hsm_runs`]), with
    /// the same bits again. False runs Song's four stages as published and keeps
    /// [`HsmState::goal`] up to date (the fused pass leaves it as it was).
    pub fused: bool,
    /// Substeps per `step` call. Default 4: 240 Hz at 60 frames/s, where the clusters of
    /// long, slender trees (aspen, poplar, fir) have weights `k h²` below 1, so their sag
    /// and sway do not depend on the frame rate. Trees of short, thick segments are stiffer
    /// than 240 Hz can hold and bend less as substeps rise (module notes, "Stiffness").
    pub substeps: u32,
}

impl Default for HsmParams {
    fn default() -> Self {
        Self {
            rings: 2,
            ring_size: 4,
            ring_ratio: 0.25,
            overlap: 2,
            stem_clusters: true,
            leaf_particles: 2,
            stiffness_scale: 1.0,
            min_radius: 0.0015,
            leaf_stiffness: 900.0,
            damping: 2.0,
            drag: 0.8,
            leaf_drag: 0.05,
            gravity: 9.81,
            prestressed: true,
            beta: 0.0,
            polar_iterations: 2,
            fused: true,
            substeps: 4,
        }
    }
}

impl HsmParams {
    /// The cluster sizes of Song's Tables 2 and 3 (42–60 particles per cluster): segment
    /// clusters of 4 rings of 14 (42 particles of their own, 56 at the root), leaves of 42
    /// blade particles, no stem clusters (the paper's counts have none), one substep per step
    /// (the paper's frame is one shape-matching pass).
    pub fn song_tables() -> Self {
        Self { rings: 4, ring_size: 14, leaf_particles: 42, stem_clusters: false, substeps: 1, ..Self::default() }
    }
}

/// Song's Table 2 (one tree on a GTX 580): clusters, particles, frames per second.
pub const SONG_TABLE_2: [(usize, usize, f64); 7] = [
    (5, 300, 2200.0),
    (15, 900, 1800.0),
    (67, 3444, 1400.0),
    (293, 13548, 1000.0),
    (867, 38772, 670.0),
    (2230, 99816, 350.0),
    (4975, 211812, 175.0),
];

/// Song's Table 3 (ten trees on a GTX 580): clusters, particles, frames per second.
pub const SONG_TABLE_3: [(usize, usize, f64); 7] = [
    (50, 3000, 260.0),
    (150, 9000, 210.0),
    (670, 34440, 160.0),
    (2930, 135480, 110.0),
    (8670, 387720, 70.0),
    (22300, 998160, 36.0),
    (49750, 2118120, 17.0),
];

/// An unusable parameter or a layout beyond its limits.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HsmError {
    /// A parameter outside its range.
    #[error("hsm parameter `{field}` = {value}: {expected}")]
    Param { field: &'static str, value: f32, expected: &'static str },
    /// The layout would exceed a limit.
    #[error("hsm layout needs {needed} {what}, more than the limit of {limit}")]
    TooLarge { what: &'static str, needed: usize, limit: usize },
}

/// Largest number of particles (and of slots) in one layout: 64 million (≈ 4 GB of state).
pub const MAX_PARTICLES: usize = 64 << 20;

impl HsmParams {
    /// Checks every field's range.
    pub fn check(&self) -> Result<(), HsmError> {
        let bad = |field, value: f32, expected| Err(HsmError::Param { field, value, expected });
        if !(2..=MAX_PER_CLUSTER).contains(&self.rings) {
            return bad("rings", self.rings as f32, "expected 2 to 64");
        }
        if !(3..=MAX_PER_CLUSTER).contains(&self.ring_size) {
            return bad("ring_size", self.ring_size as f32, "expected 3 to 64");
        }
        if !(1..=2).contains(&self.overlap) {
            return bad("overlap", self.overlap as f32, "expected 1 or 2");
        }
        if !(1..=MAX_PER_CLUSTER).contains(&self.leaf_particles) {
            return bad("leaf_particles", self.leaf_particles as f32, "expected 1 to 64");
        }
        if !(self.ring_ratio >= 0.0 && self.ring_ratio <= 10.0) {
            return bad("ring_ratio", self.ring_ratio, "expected 0 to 10");
        }
        for (field, k) in [("stiffness_scale", self.stiffness_scale), ("leaf_stiffness", self.leaf_stiffness)] {
            if !(k.is_finite() && k > 0.0) {
                return bad(field, k, "expected a positive number");
            }
        }
        if !(self.min_radius.is_finite() && self.min_radius >= 0.0) {
            return bad("min_radius", self.min_radius, "expected a finite number ≥ 0 (m)");
        }
        for (field, v) in [
            ("damping", self.damping),
            ("drag", self.drag),
            ("leaf_drag", self.leaf_drag),
            ("gravity", self.gravity.abs()),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, v, "expected a finite number ≥ 0");
            }
        }
        if !(0.0..=1.0).contains(&self.beta) {
            return bad("beta", self.beta, "expected 0 to 1");
        }
        if !(1..=64).contains(&self.polar_iterations) {
            return bad("polar_iterations", self.polar_iterations as f32, "expected 1 to 64");
        }
        if !(1..=1000).contains(&self.substeps) {
            return bad("substeps", self.substeps as f32, "expected 1 to 1000");
        }
        Ok(())
    }
}

/// Cluster information (Fig. 9), 16 bytes. WGSL: `HsmClusterInfo` in `hsm.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Pod, Zeroable)]
pub struct RawHsmClusterInfo {
    /// [`kind::SEGMENT`] or [`kind::LEAF`].
    pub kind: u32,
    /// Segment or leaf index in the tree.
    pub source: u32,
    /// First slot of the cluster.
    pub slot_offset: u32,
    /// Number of slots (particles) of the cluster.
    pub slot_count: u32,
}

/// Cluster data that does not change (Fig. 9), 80 bytes. WGSL: `HsmCluster`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawHsmCluster {
    /// Rest centre of mass c⁰ (xyz), m; w = stiffness (rate) k, 1/s².
    pub rest_cm: [f32; 4],
    /// Parent cluster (`u32::MAX` for the root).
    pub parent: u32,
    /// First of the cluster's children in [`HsmLayout::children`].
    pub child_offset: u32,
    /// Number of child clusters.
    pub child_count: u32,
    /// Total mass of the cluster's particles, kg.
    pub mass: f32,
    /// Columns of Aqq⁻¹ (xyz; zero where Aqq is singular), 1/(kg·m²). The first column's w
    /// is the rate bound k̂, 1/s²: the smallest k on the path from the root to this cluster
    /// (see [`crate::cpu::hsm::MAX_WEIGHT`]); the other two are zero.
    pub aqq_inv: [[f32; 4]; 3],
}

/// One particle of a cluster, 16 bytes. WGSL: `HsmSlot`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawHsmSlot {
    /// Rest offset from the cluster's rest centre of mass, q = x⁰ − c⁰, m.
    pub q: [f32; 3],
    /// Particle index.
    pub particle: u32,
}

/// One cluster a particle belongs to, with the particle's rest offset in it, 16 bytes
/// (the particle's side of a [`RawHsmSlot`], so stage 3 reads one record per cluster).
/// WGSL: `HsmMember`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawHsmMember {
    /// Rest offset from the cluster's rest centre of mass, q = x⁰ − c⁰, m.
    pub q: [f32; 3],
    /// Cluster index.
    pub cluster: u32,
}

/// Cluster data written each step (Fig. 9's current CM, A), 96 bytes. WGSL: `HsmClusterState`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawHsmClusterState {
    /// Current centre of mass (xyz), m; w = the cluster's weight `k h²` this substep.
    pub cm: [f32; 4],
    /// Rotation R as a unit quaternion (x, y, z, w), the warm start of the next step.
    pub rotation: [f32; 4],
    /// Columns of the goal transform T (xyz); the w components are the centre's shift
    /// from rest `c − c⁰` (x, y, z), which goals are built from.
    pub transform: [[f32; 4]; 3],
    /// Wind velocity at the centre of mass (xyz), m/s.
    pub wind: [f32; 4],
}

impl RawHsmClusterState {
    /// A cluster at rest: at its rest centre of mass, unrotated.
    pub fn rest(c: &RawHsmCluster) -> Self {
        Self {
            cm: [c.rest_cm[0], c.rest_cm[1], c.rest_cm[2], 0.0],
            rotation: [0.0, 0.0, 0.0, 1.0],
            transform: [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]],
            wind: [0.0; 4],
        }
    }
}

/// Per-substep values and tree information, 48 bytes. WGSL: `HsmStep`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawHsmStep {
    /// Gravity (xyz), m/s²; w = 1 when prestressed (see [`HsmParams::prestressed`]).
    pub gravity: [f32; 4],
    /// Substep h, s.
    pub dt: f32,
    /// Time at the end of the substep, s.
    pub time: f32,
    /// `e^{−c h}`.
    pub damping: f32,
    /// Müller's β.
    pub beta: f32,
    /// Most rotation iterations.
    pub polar_iterations: u32,
    /// Number of clusters.
    pub clusters: u32,
    /// Number of particles.
    pub particles: u32,
    /// Largest number of child clusters of any cluster.
    pub max_children: u32,
}

/// Song's linearised tree (§5.1): every array the four stages read, CPU and GPU alike.
#[derive(Debug, Clone, PartialEq)]
pub struct HsmLayout {
    /// Cluster information, parents before children.
    pub info: Vec<RawHsmClusterInfo>,
    /// Constant cluster data.
    pub clusters: Vec<RawHsmCluster>,
    /// Child cluster ids, grouped by parent (Fig. 8's "Children ID").
    pub children: Vec<u32>,
    /// Every cluster's particles, cluster after cluster.
    pub slots: Vec<RawHsmSlot>,
    /// Rest position (xyz) and drag factor `k_d = ½ ρ C_d A / m` (w, 1/m) of each particle.
    pub rest: Vec<[f32; 4]>,
    /// Mass of each particle, kg.
    pub mass: Vec<f32>,
    /// 1 for a free particle, 0 for a fixed one.
    pub free: Vec<f32>,
    /// The cluster whose wind each particle feels: the cluster that made it, or for a leaf
    /// blade its segment's cluster (leaves are too small to sample the air apart).
    pub owner: Vec<u32>,
    /// Start of each particle's run in `member` (one more entry than particles).
    pub member_offset: Vec<u32>,
    /// The clusters of every particle with its rest offset in each, in cluster order.
    pub member: Vec<RawHsmMember>,
    /// Cluster of each segment of the tree (`u32::MAX` where a truncated layout has none).
    pub segment_cluster: Vec<u32>,
    /// Largest number of child clusters of any cluster.
    pub max_children: u32,
}

/// [`HsmState::velocity`]'s w for a fixed particle (free ones carry their drag factor ≥ 0).
pub const FIXED: f32 = -1.0;

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
    /// Goal as a displacement from rest (xyz, m) and ᾱ (w) of each particle from the last
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

struct Builder {
    layout: HsmLayout,
    /// Per cluster: (ring centre, first particle) of each of its rings.
    rings: Vec<Vec<(Vec3, u32)>>,
    /// Per particle: position (before the rest offsets are known).
    pos: Vec<Vec3>,
}

impl Builder {
    fn particle(&mut self, p: Vec3, mass: f32, kd: f32, free: bool, owner: u32) -> u32 {
        let i = self.pos.len() as u32;
        self.pos.push(p);
        self.layout.mass.push(mass);
        self.layout.rest.push([p.x, p.y, p.z, kd]);
        self.layout.free.push(if free { 1.0 } else { 0.0 });
        self.layout.owner.push(owner);
        i
    }

    fn nearest_ring(&self, cluster: u32, p: Vec3) -> (Vec3, u32) {
        *self.rings[cluster as usize]
            .iter()
            .min_by(|a, b| (a.0 - p).length_squared().total_cmp(&(b.0 - p).length_squared()))
            .expect("a cluster has rings")
    }
}

impl HsmLayout {
    /// Clusters for every segment and leaf of `tree` (each segment followed by its leaves, so
    /// parents come before children). `max_clusters` keeps only the first clusters in that
    /// order — still a whole tree, grown from the root — for benchmarks at set sizes.
    pub fn new(tree: &Tree, params: &HsmParams, max_clusters: Option<usize>) -> Result<Self, HsmError> {
        params.check()?;
        let s = &tree.segments;
        let l = &tree.leaves;
        let k = params.ring_size as usize;
        let rings = params.rings as usize;
        let total_clusters = (s.len() + l.len()).min(max_clusters.unwrap_or(usize::MAX));
        let needed = total_clusters.saturating_mul((3 * rings + params.leaf_particles as usize) * k.max(1));
        if needed > MAX_PARTICLES {
            return Err(HsmError::TooLarge { what: "slots", needed, limit: MAX_PARTICLES });
        }
        let mut b = Builder {
            layout: HsmLayout {
                info: Vec::with_capacity(total_clusters),
                clusters: Vec::with_capacity(total_clusters),
                children: Vec::new(),
                slots: Vec::new(),
                rest: Vec::new(),
                mass: Vec::new(),
                free: Vec::new(),
                owner: Vec::new(),
                member_offset: Vec::new(),
                member: Vec::new(),
                segment_cluster: vec![NONE; s.len()],
                max_children: 0,
            },
            rings: Vec::with_capacity(total_clusters),
            pos: Vec::new(),
        };
        let mut slot_particles: Vec<u32> = Vec::new();
        let mut parents: Vec<u32> = Vec::with_capacity(total_clusters);
        // (K, μ) of a segment cluster; (k, 0) of a leaf.
        let mut stiffness: Vec<(f32, f32)> = Vec::with_capacity(total_clusters);
        let pi = std::f32::consts::PI;
        let r_mech = super::mechanical_radii(tree, params.min_radius);
        #[allow(clippy::needless_range_loop)] // i indexes every per-segment array of the tree
        'segments: for i in 0..s.len() {
            if b.layout.info.len() >= total_clusters {
                break;
            }
            let c = b.layout.info.len() as u32;
            let len = s.length[i];
            let q = s.orientation[i];
            let own_rings = if s.parent[i] == NONE { rings } else { rings - 1 };
            let own = (own_rings * k) as f32;
            // Twig tips taper toward zero for looks; a living tip is never thinner than
            // `min_radius`, and a massless particle would simply blow away with the air.
            let floor = tree.wood.segment_mass(len, params.min_radius, params.min_radius);
            let m = s.mass[i].max(floor).max(1e-9) / own;
            let area = (s.radius_base[i].max(params.min_radius) + s.radius_tip[i].max(params.min_radius)) * len / own;
            let kd = 0.5 * AIR_DENSITY * params.drag * area / m;
            let slot_offset = slot_particles.len() as u32;
            let mut my_rings = Vec::with_capacity(rings);
            let parent_cluster =
                if s.parent[i] == NONE { NONE } else { b.layout.segment_cluster[s.parent[i] as usize] };
            if s.parent[i] != NONE {
                if parent_cluster == NONE {
                    continue 'segments; // parent dropped by truncation (cannot happen in order)
                }
                let (centre, first) = b.nearest_ring(parent_cluster, s.start[i]);
                if params.overlap >= 2 {
                    // The parent's whole segment: its head ring and its own rings.
                    for &(_, f) in &b.rings[parent_cluster as usize] {
                        slot_particles.extend(f..f + k as u32);
                    }
                } else {
                    slot_particles.extend(first..first + k as u32);
                }
                my_rings.push((centre, first));
            }
            for j in (rings - own_rings)..rings {
                let u = j as f32 / (rings - 1) as f32;
                let r = (s.radius_base[i] + (s.radius_tip[i] - s.radius_base[i]) * u).max(params.ring_ratio * len);
                let centre = s.start[i] + q * Vec3::new(0.0, u * len, 0.0);
                let twist = if j % 2 == 1 { pi / k as f32 } else { 0.0 };
                let first = b.pos.len() as u32;
                for p in 0..k {
                    let a = std::f32::consts::TAU * p as f32 / k as f32 + twist;
                    let x = centre + q * Vec3::new(r * a.cos(), 0.0, r * a.sin());
                    let fixed = s.parent[i] == NONE && j == 0;
                    b.particle(x, m, kd, !fixed, c);
                }
                slot_particles.extend(first..first + k as u32);
                my_rings.push((centre, first));
            }
            b.layout.segment_cluster[i] = c;
            b.rings.push(my_rings);
            b.layout.info.push(RawHsmClusterInfo {
                kind: kind::SEGMENT,
                source: i as u32,
                slot_offset,
                slot_count: slot_particles.len() as u32 - slot_offset,
            });
            parents.push(parent_cluster);
            // k from the joint's bending stiffness K = E·I/L: bending the cluster by θ
            // against its head ring stores ≈ ½ k μ r² θ² (μ the reduced mass of head ring
            // and the rest, r the tail ring's radius), so k = K / (μ r²).
            let head = if s.parent[i] == NONE {
                m * k as f32
            } else {
                b.layout.mass[b.rings[c as usize][0].1 as usize] * k as f32
            };
            let rest_mass = if s.parent[i] == NONE { m * ((rings - 1) * k) as f32 } else { own * m };
            let mu = head * rest_mass / (head + rest_mass);
            let joint = tree.wood.segment_stiffness(len, r_mech[i]) * params.stiffness_scale;
            stiffness.push((joint, mu));
            // This segment's leaves.
            let lo = tree.children.leaf_offset[i] as usize;
            for leaf in lo..lo + tree.children.leaf_count[i] as usize {
                if b.layout.info.len() >= total_clusters {
                    break 'segments;
                }
                let n = params.leaf_particles as usize;
                let (w, h) = (l.width[leaf], l.length[leaf]);
                let blade = std::f32::consts::FRAC_PI_4 * w * h;
                let m = (blade * tree.wood.leaf_areal_density).max(1e-9) / n as f32;
                let kd = 0.5 * AIR_DENSITY * params.leaf_drag * blade / n as f32 / m;
                let slot_offset = slot_particles.len() as u32;
                let (centre, first) = b.nearest_ring(c, l.position[leaf]);
                slot_particles.extend(first..first + k as u32);
                let lq = l.orientation[leaf];
                let first_own = b.pos.len() as u32;
                for p in 0..n {
                    // The tip, then points along the edge toward the base.
                    let local = if p == 0 {
                        Vec3::new(0.0, h, 0.0)
                    } else {
                        Vec3::new(0.5 * w, h * (1.0 - p as f32 / n as f32), 0.0)
                    };
                    b.particle(l.position[leaf] + lq * local, m, kd, true, c);
                }
                slot_particles.extend(first_own..first_own + n as u32);
                b.rings.push(vec![(centre, first)]);
                b.layout.info.push(RawHsmClusterInfo {
                    kind: kind::LEAF,
                    source: leaf as u32,
                    slot_offset,
                    slot_count: slot_particles.len() as u32 - slot_offset,
                });
                parents.push(c);
                stiffness.push((params.leaf_stiffness, 0.0));
            }
        }
        // Song's global level (Fig. 4): one more cluster per stem over all its segments'
        // rings (and the parent's shared ring), so a stem keeps its shape as a whole and
        // load reaches the root in a few substeps instead of one segment per substep.
        if params.stem_clusters {
            for st in 0..tree.stems.len() {
                let first = tree.stems.first_segment[st] as usize;
                let count = tree.stems.segment_count[st] as usize;
                let segs: Vec<u32> =
                    (first..first + count).map(|i| b.layout.segment_cluster[i]).take_while(|&c| c != NONE).collect();
                if segs.len() < 2 {
                    continue; // a one-segment stem is its segment's cluster already
                }
                let slot_offset = slot_particles.len() as u32;
                let mut kmin = f32::INFINITY;
                let mut mu = 0.0f32;
                for (n, &c) in segs.iter().enumerate() {
                    let rings = &b.rings[c as usize];
                    // The first segment brings its shared head ring too; later ones only
                    // their own rings (their head ring is the previous segment's tail).
                    for &(_, f) in &rings[if n == 0 { 0 } else { 1 }..] {
                        slot_particles.extend(f..f + k as u32);
                    }
                    let (kk, m) = stiffness[c as usize];
                    if kk < kmin {
                        kmin = kk;
                        mu = m;
                    }
                }
                b.layout.info.push(RawHsmClusterInfo {
                    kind: kind::STEM,
                    source: st as u32,
                    slot_offset,
                    slot_count: slot_particles.len() as u32 - slot_offset,
                });
                parents.push(segs[0]);
                stiffness.push((kmin, mu));
            }
        }
        let n_clusters = b.layout.info.len();
        let n_particles = b.pos.len();
        // Children lists (Fig. 8).
        let mut child_count = vec![0u32; n_clusters];
        for &p in &parents {
            if p != NONE {
                child_count[p as usize] += 1;
            }
        }
        let mut child_offset = vec![0u32; n_clusters];
        let mut acc = 0u32;
        for c in 0..n_clusters {
            child_offset[c] = acc;
            acc += child_count[c];
        }
        let mut children = vec![0u32; acc as usize];
        let mut fill = child_offset.clone();
        for (c, &p) in parents.iter().enumerate() {
            if p != NONE {
                children[fill[p as usize] as usize] = c as u32;
                fill[p as usize] += 1;
            }
        }
        // Rest centres of mass, offsets and Aqq⁻¹ (in f64: the inverse of a thin cluster's Aqq
        // is ill-conditioned).
        let mut slots = Vec::with_capacity(slot_particles.len());
        let mut clusters = Vec::with_capacity(n_clusters);
        for c in 0..n_clusters {
            let info = b.layout.info[c];
            let run = &slot_particles[info.slot_offset as usize..(info.slot_offset + info.slot_count) as usize];
            let mut msum = 0.0f64;
            let mut cm = DVec3::ZERO;
            for &p in run {
                let m = b.layout.mass[p as usize] as f64;
                msum += m;
                cm += b.pos[p as usize].as_dvec3() * m;
            }
            let cm = cm / msum;
            let mut aqq = DMat3::ZERO;
            for &p in run {
                let m = b.layout.mass[p as usize] as f64;
                // Aqq of the offsets as stored.
                let qf = (b.pos[p as usize].as_dvec3() - cm).as_vec3();
                let q = qf.as_dvec3();
                aqq += DMat3::from_cols(q * q.x, q * q.y, q * q.z) * m;
                slots.push(RawHsmSlot { q: qf.to_array(), particle: p });
            }
            let det = aqq.determinant();
            let scale = aqq.x_axis.x + aqq.y_axis.y + aqq.z_axis.z;
            let inv = if det.abs() > 1e-9 * scale.powi(3) { aqq.inverse().as_mat3() } else { Mat3::ZERO };
            let cmf = cm.as_vec3();
            // A segment's k = K / (μ ρ²), ρ² = tr(Aqq) / M its squared radius of gyration.
            let (kk, mu) = stiffness[c];
            let kc = if mu > 0.0 { kk / (mu * (scale / msum) as f32).max(1e-30) } else { kk };
            clusters.push(RawHsmCluster {
                rest_cm: [cmf.x, cmf.y, cmf.z, kc],
                parent: parents[c],
                child_offset: child_offset[c],
                child_count: child_count[c],
                mass: msum as f32,
                aqq_inv: [inv.x_axis.extend(0.0).into(), inv.y_axis.extend(0.0).into(), inv.z_axis.extend(0.0).into()],
            });
        }
        // Each cluster's rate bound k̂: the smallest rate on its path to the root, itself
        // included (clusters come after their parents, so one pass carries it down). Stage 1
        // lets a cluster's weight pass 1 only up to k̂ h² (see `cpu::hsm::MAX_WEIGHT`).
        for c in 0..n_clusters {
            let p = parents[c];
            let own = clusters[c].rest_cm[3];
            clusters[c].aqq_inv[0][3] = if p == NONE { own } else { own.min(clusters[p as usize].aqq_inv[0][3]) };
        }
        // Each particle's (cluster, slot) pairs, in cluster order.
        let mut count = vec![0u32; n_particles + 1];
        for s in &slots {
            count[s.particle as usize + 1] += 1;
        }
        for i in 0..n_particles {
            count[i + 1] += count[i];
        }
        let mut member = vec![RawHsmMember { q: [0.0; 3], cluster: 0 }; slots.len()];
        let mut fill = count.clone();
        for (c, info) in b.layout.info.iter().enumerate() {
            for sl in info.slot_offset..info.slot_offset + info.slot_count {
                let p = slots[sl as usize].particle as usize;
                member[fill[p] as usize] = RawHsmMember { q: slots[sl as usize].q, cluster: c as u32 };
                fill[p] += 1;
            }
        }
        let mut layout = b.layout;
        layout.max_children = child_count.iter().copied().max().unwrap_or(0);
        layout.children = children;
        layout.slots = slots;
        layout.clusters = clusters;
        layout.member_offset = count;
        layout.member = member;
        Ok(layout)
    }

    /// `copies` copies of this layout side by side, `spacing` metres apart along x (Song's
    /// Table 3: ten trees). Segment clusters refer to the first copy's tree.
    pub fn forest(&self, copies: usize, spacing: f32) -> Result<Self, HsmError> {
        let copies = copies.max(1);
        let needed = self.slots.len().saturating_mul(copies);
        if needed > MAX_PARTICLES {
            return Err(HsmError::TooLarge { what: "slots", needed, limit: MAX_PARTICLES });
        }
        let (nc, np, ns, nch) =
            (self.info.len() as u32, self.rest.len() as u32, self.slots.len() as u32, self.children.len() as u32);
        let mut out = self.clone();
        for k in 1..copies as u32 {
            let dx = spacing * k as f32;
            out.info.extend(self.info.iter().map(|i| RawHsmClusterInfo { slot_offset: i.slot_offset + k * ns, ..*i }));
            out.clusters.extend(self.clusters.iter().map(|c| {
                let mut c = *c;
                c.rest_cm[0] += dx;
                c.parent = if c.parent == NONE { NONE } else { c.parent + k * nc };
                c.child_offset += k * nch;
                c
            }));
            out.children.extend(self.children.iter().map(|c| c + k * nc));
            out.slots.extend(self.slots.iter().map(|s| RawHsmSlot { particle: s.particle + k * np, ..*s }));
            out.rest.extend(self.rest.iter().map(|r| [r[0] + dx, r[1], r[2], r[3]]));
            out.mass.extend_from_slice(&self.mass);
            out.free.extend_from_slice(&self.free);
            out.owner.extend(self.owner.iter().map(|o| o + k * nc));
            let base = *out.member_offset.last().expect("offsets");
            out.member_offset.extend(self.member_offset[1..].iter().map(|o| o + base));
            out.member.extend(self.member.iter().map(|m| RawHsmMember { cluster: m.cluster + k * nc, ..*m }));
        }
        Ok(out)
    }

    /// Number of clusters.
    pub fn cluster_count(&self) -> usize {
        self.info.len()
    }

    /// Number of (distinct) particles.
    pub fn particle_count(&self) -> usize {
        self.rest.len()
    }

    /// Stage 1's share of [`Self::bytes_per_step`]: info, clusters, cluster state (r/w);
    /// per slot the record and the particle's displacement + mass.
    pub fn stage1_bytes(&self) -> usize {
        self.info.len() * (16 + 80 + 2 * 96) + self.slots.len() * (16 + 16)
    }

    /// Bytes the stages must read and write per substep, each array counted once per
    /// stage that touches it (a lower bound on the traffic: gathered values are counted at
    /// their size, not their cache lines), for bandwidth figures. `fused`: stages 3 and 4
    /// in one pass.
    pub fn bytes_per_step(&self, fused: bool) -> usize {
        let (p, m) = (self.rest.len(), self.member.len());
        let stage1 = self.stage1_bytes();
        // Stage 3: offsets, goal written; per member: the record (q, cluster), the
        // cluster's transform and α.
        let members = m * (16 + 52);
        let stage3 = p * (4 + 16) + members;
        // Stage 4: displacement, velocity (r/w), owner, goal, owner's wind.
        let stage4 = p * (2 * 16 + 2 * 16 + 4 + 16 + 16);
        if fused {
            // One pass: no goal written or read.
            p * (4 + 2 * 16 + 2 * 16 + 4 + 16) + members + stage1
        } else {
            stage1 + stage3 + stage4
        }
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
}

impl Hsm {
    /// Builds the clusters of every segment and leaf of `tree`.
    pub fn new(tree: &Tree, params: HsmParams) -> Result<Self, HsmError> {
        let layout = HsmLayout::new(tree, &params, None)?;
        Ok(Self::from_layout(tree, params, layout))
    }

    /// Uses a prepared layout (truncated or a forest).
    pub fn from_layout(tree: &Tree, params: HsmParams, layout: HsmLayout) -> Self {
        let rest_joints = tree.segments.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        let runs = HsmRuns::new(&layout);
        let groups = HsmSlotGroups::new(&layout);
        Self { params, layout, runs, groups, rest_joints }
    }

    /// The state at rest (without prestress, gravity has yet to sag it: see [`Self::settle`]).
    pub fn rest_state(&self) -> HsmState {
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
            damping: (-p.damping * dt).exp(),
            beta: p.beta,
            polar_iterations: p.polar_iterations,
            clusters: self.layout.info.len() as u32,
            particles: self.layout.rest.len() as u32,
            max_children: self.layout.max_children,
        }
    }

    /// One substep: the four stages.
    pub fn substep(&self, fields: &[RawField], waves: &[RawWave], state: &mut HsmState, h: f32) {
        let l = &self.layout;
        let step = self.step_params(state.time + h, h);
        hsm_clusters_groups(fields, waves, l, &self.groups, &state.displacement, step, &mut state.clusters);
        if self.params.fused {
            hsm_particles_runs(l, &self.runs, &state.clusters, step, &mut state.displacement, &mut state.velocity);
        } else {
            hsm_goals(&l.member_offset, &l.member, &state.clusters, &mut state.goal);
            hsm_integrate(&l.owner, &state.clusters, &state.goal, step, &mut state.displacement, &mut state.velocity);
        }
        state.time = step.time;
    }

    /// Advances `state` by `dt` seconds in `params.substeps` substeps.
    pub fn step(&self, fields: &[RawField], waves: &[RawWave], state: &mut HsmState, dt: f32) {
        let n = self.params.substeps.max(1);
        let h = dt / n as f32;
        for _ in 0..n {
            self.substep(fields, waves, state, h);
        }
    }

    /// Convenience: steps a scene (packs it each call).
    pub fn step_scene(&self, wind: &WindScene, state: &mut HsmState, dt: f32) {
        let (f, w) = wind.pack();
        self.step(&f, &w, state, dt);
    }

    /// Steps in still air until the kinetic energy per kilogram falls below `tolerance`
    /// (J/kg) or `max_steps` pass; returns the steps taken. The settled state is the tree's
    /// rest under gravity, which wind displaces and damping returns to.
    pub fn settle(&self, state: &mut HsmState, dt: f32, max_steps: usize, tolerance: f64) -> usize {
        let total: f64 = self.layout.mass.iter().map(|&m| m as f64).sum();
        for k in 0..max_steps {
            self.step(&[], &[], state, dt);
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

    /// The pose: segments turned by their clusters' rotations, joints by forward kinematics.
    pub fn pose(&self, tree: &Tree, state: &HsmState) -> Pose {
        let acc = self.rotations(state);
        let mut joints = vec![[0.0f32; 4]; acc.len()];
        crate::cpu::pose_fk::pose_positions(&tree.segments.parent, &self.rest_joints, &acc, &mut joints);
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
