//! Zioma's per-stem and per-frame records as the GPU lays them out (`zioma_rotations.wgsl`).

use bytemuck::{Pod, Zeroable};

/// Per-stem constants, 64 bytes. WGSL: `ZiomaStem` in `zioma_rotations.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawZiomaStem {
    /// Stem base (where it samples the wind), m.
    pub base: [f32; 3],
    /// Static bend per (m/s)², rad·s²/m².
    pub drag: f32,
    /// Unit rest direction (base to tip).
    pub dir: [f32; 3],
    /// Sway frequency, Hz.
    pub freq: f32,
    /// Unit axis of the parent segment at the attachment (up for trunks).
    pub parent_axis: [f32; 3],
    /// Phase, cycles.
    pub phase: f32,
    /// Branching level.
    pub level: u32,
    /// Noise stream.
    pub seed: u32,
    /// Arc length, m.
    pub length: f32,
    /// Padding.
    pub _pad: u32,
}

/// Per-frame, per-instance values, 80 bytes. WGSL: `ZiomaFrame`. Directions are in the
/// tree's own frame; `origin` and `heading` place the instance in the world, where the wind
/// is sampled.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawZiomaFrame {
    /// Horizontal unit direction the trunk leans toward (the wind's at the crown, turned by
    /// the oscillator's answer to its swings; zero in calm air).
    pub wind_dir: [f32; 3],
    /// Time, s.
    pub time: f32,
    /// Trunk angles: parallel, perpendicular, twist, rad.
    pub trunk: [f32; 3],
    /// Rate of the parallel angle, rad/s.
    pub trunk_rate: f32,
    /// 0 = trunk only, 1 = full.
    pub lod: u32,
    /// Branch amplitude scale.
    pub amplitude: f32,
    /// Largest static bend, rad.
    pub max_bend: f32,
    /// Inertia gain.
    pub inertia: f32,
    /// Instance position in the world, m.
    pub origin: [f32; 3],
    /// Instance phase offset, cycles (added to every branch's phase).
    pub phase: f32,
    /// Instance heading (cos, sin of the yaw about +Y).
    pub heading: [f32; 2],
    /// Padding.
    pub _pad: [f32; 2],
}

/// One tree's values for a frame, 64 bytes: its trunk ([`super::trunk::TrunkModel`]), the
/// time and the method's parameters. WGSL: `ZiomaTrunk` in `zioma.wgsl`; the frame kernel
/// ([`super::frames`]) reads it once for every instance.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawZiomaTrunk {
    /// Where the trunk's wind is sampled (the crown's centre, tree frame), m.
    pub crown_centre: [f32; 3],
    /// First-mode frequency f₀, Hz.
    pub natural_frequency: f32,
    /// Trunk-top deflection per pascal on the crown, m/Pa.
    pub tip_per_pascal: f32,
    /// Share of the tip's speed at which the drag's point of work moves (the air's damping).
    pub damping_centre: f32,
    /// Trunk-top motion per radian of arc, m.
    pub lever: f32,
    /// Structural damping ratio.
    pub damping_ratio: f32,
    /// Reconfiguration speed U_r, m/s.
    pub reconfiguration_speed: f32,
    /// Vogel exponent B.
    pub vogel_exponent: f32,
    /// Time of the frame, s.
    pub time: f32,
    /// Seed of the tree's trunk noise (an instance's seed is XORed in).
    pub tree_seed: u32,
    /// 0 = trunk only, 1 = full.
    pub lod: u32,
    /// Branch amplitude scale.
    pub amplitude: f32,
    /// Largest static bend, rad.
    pub max_bend: f32,
    /// Inertia gain.
    pub inertia: f32,
}

/// One instance's ring ([`super::Ring`]: the trunk's free ring-down since the wind last
/// changed, taken at the instance's own crown), 32 bytes. WGSL: `ZiomaRing` in `zioma.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawZiomaRing {
    /// Bend at the change, rad (scene frame).
    pub bend: [f32; 3],
    /// Time of the change, s.
    pub since: f32,
    /// Rate of bend at the change, rad/s.
    pub rate: [f32; 3],
    /// Damping ratio in the new wind.
    pub zeta: f32,
}

impl From<&super::Ring> for RawZiomaRing {
    fn from(r: &super::Ring) -> Self {
        Self { bend: r.bend.to_array(), since: r.since, rate: r.rate.to_array(), zeta: r.zeta }
    }
}

/// A placed instance ([`crate::pose::Placement`]) as the frame kernel reads it, 32 bytes.
/// WGSL: `ZiomaInstance` in `zioma.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawZiomaInstance {
    /// Position of the tree's origin in the world, m.
    pub position: [f32; 3],
    /// Rotation about +Y, rad.
    pub yaw: f32,
    /// Phase offset of every branch, cycles.
    pub phase: f32,
    /// Seed of the trunk's noise for this instance.
    pub seed: u32,
    /// Padding.
    pub _pad: [u32; 2],
}

impl From<&crate::pose::Placement> for RawZiomaInstance {
    fn from(p: &crate::pose::Placement) -> Self {
        Self { position: p.position.to_array(), yaw: p.yaw, phase: p.phase, seed: p.seed, _pad: [0; 2] }
    }
}
