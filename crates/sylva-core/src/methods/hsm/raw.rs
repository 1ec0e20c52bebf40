//! Song's linearised tree as the GPU lays it out (§5.1, Figs. 6–9): `#[repr(C)]` twins of
//! the structs in `hsm.wgsl`, checked against naga's layout by the GPU crate's tests.

use bytemuck::{Pod, Zeroable};

/// Cluster kinds ([`RawHsmClusterInfo::kind`]).
pub mod kind {
    /// A branch segment.
    pub const SEGMENT: u32 = 0;
    /// A leaf.
    pub const LEAF: u32 = 1;
    /// A whole stem (the global level of Song's Fig. 4).
    pub const STEM: u32 = 2;
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
    /// First of the cluster's children in [`super::HsmLayout::children`].
    pub child_offset: u32,
    /// Number of child clusters.
    pub child_count: u32,
    /// Total mass of the cluster's particles, kg.
    pub mass: f32,
    /// Columns of Aqq⁻¹ (xyz; zero where Aqq is singular), 1/(kg·m²). The first column's w
    /// is the rate bound k̂, 1/s²: the smallest k on the path from the root to this cluster
    /// (see [`crate::methods::hsm::kernels::MAX_WEIGHT`]). The second's is a leaf cluster's
    /// swing ω, rad/s, the centre of the band of air it feels (see
    /// [`crate::methods::hsm::kernels::leaf_air`]); zero for other clusters. The third's is zero.
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
    /// Wind velocity at the centre of mass (xyz), m/s, plus for a leaf cluster the air's
    /// fluctuation in its band ([`super::kernels::leaf_air`]); w = the drag's
    /// reconfiguration factor at the wind ([`super::kernels::reconfiguration`]).
    pub wind: [f32; 4],
}

impl RawHsmClusterState {
    /// A cluster at rest: at its rest centre of mass, unrotated.
    pub fn rest(c: &RawHsmCluster) -> Self {
        Self {
            cm: [c.rest_cm[0], c.rest_cm[1], c.rest_cm[2], 0.0],
            rotation: [0.0, 0.0, 0.0, 1.0],
            transform: [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]],
            wind: [0.0, 0.0, 0.0, 1.0],
        }
    }
}

/// Per-substep values and tree information, 80 bytes. WGSL: `HsmStep`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawHsmStep {
    /// Gravity (xyz), m/s²; w = 1 when prestressed (see [`super::HsmParams::prestressed`]).
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
    /// The most a particle moves toward its goal in one substep, `ᾱ = min(Σ w, hold)`,
    /// and the least bound on a cluster's weight: `s (r h)²` for substep rate `r` and rate
    /// scale `s` (see [`super::HsmParams::substep_rate`]), never above 1.
    pub hold: f32,
    /// [`super::HsmParams::reconfiguration_speed`], m/s.
    pub reconfiguration_speed: f32,
    /// [`super::HsmParams::vogel_exponent`].
    pub vogel_exponent: f32,
    /// The drag's relative velocity is `wind − air · v`: [`super::HsmParams::air_damping`]
    /// times the calibration's [`super::HsmLayout::air_scale`] over the drag's scales,
    /// [`super::HsmParams::drag_scale`] times the calibration's
    /// [`super::HsmLayout::load_scale`] (1 when the drag scale is 0).
    pub air: f32,
    /// 1: stage 1 samples the wind at the clusters' centres (the first substep of a step);
    /// 0: the clusters keep the wind they hold (see [`super::Hsm::step_packed`]).
    pub sample_wind: u32,
    /// RMS of the air's velocity in a leaf's band, as a fraction of the wind at the leaf's
    /// centre well above the onset: [`super::HsmParams::leaf_turbulence`] times the crown's
    /// share of the wind ([`crate::leaves::LeafMotion::crown_wind`]).
    pub leaf_turbulence: f32,
    /// Wind at a leaf's centre at which that air reaches half its RMS, m/s:
    /// [`crate::leaves::LeafMotion::flutter_onset`] over the crown's share.
    pub flutter_onset: f32,
    /// Half-power width of the leaves' band, the damping ratio of their swing
    /// ([`crate::leaves::LeafMotion::damping_ratio`]).
    pub leaf_zeta: f32,
}

/// [`super::HsmState::velocity`]'s w for a fixed particle (free ones carry their drag factor ≥ 0).
pub const FIXED: f32 = -1.0;

/// One leaf's blade in the particles, 64 bytes: what [`super::kernels::hsm_leaf_pose`] turns
/// into the leaf's rotation. WGSL: `HsmLeaf`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawHsmLeaf {
    /// Rest offset of the blade's tip from the leaf's attachment, m.
    pub tip: [f32; 3],
    /// The segment it hangs on.
    pub segment: u32,
    /// Rest offset of the blade's edge point from the attachment, m (zero with one blade
    /// particle).
    pub edge: [f32; 3],
    /// First slot of its leaf cluster: the ring's slots, then the blade's (tip, edge, …).
    pub slot_offset: u32,
    /// Rest offset of the attachment from the centre of the leaf cluster's ring, m.
    pub attach: [f32; 3],
    /// Its leaf cluster.
    pub cluster: u32,
    /// Ring slots (0: the leaf has no cluster and stays at rest).
    pub ring: u32,
    /// Blade slots.
    pub blade: u32,
    /// Scale of the leaf's turn, the tree's `leaf_motion.strength` (0: rigid on its segment).
    pub strength: f32,
    /// Padding.
    pub _pad: u32,
}
