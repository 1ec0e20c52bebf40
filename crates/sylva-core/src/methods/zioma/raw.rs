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
