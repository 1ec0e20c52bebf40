//! Akagi's per-segment and per-step records as the GPU lays them out (`akagi.wgsl`).

use bytemuck::{Pod, Zeroable};

/// Per-segment constants, 32 bytes. WGSL: `AkagiSegment` in `akagi.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawAkagiSegment {
    /// Bark area facing a cross-flow, 2 r̄ L, m².
    pub bark_area: f32,
    /// Leaf area on the segment scaled by `leaf_drag / drag`, so one coefficient serves
    /// both: m².
    pub leaf_area: f32,
    /// Modal inertia of the joint `J = k / ω²`, with ω its stem's first-mode frequency,
    /// kg·m².
    pub inertia: f32,
    /// Rotational stiffness, N·m/rad.
    pub stiffness: f32,
    /// Structural damping `c = 2 ζ √(k J)`, N·m·s/rad.
    pub damping: f32,
    /// Factor on the air's damping Γ of turning about the joint, `J / J_rigid`: the modal
    /// inertia over the inertia of everything beyond the joint swinging about it, so the air
    /// damps the joint's ring as it damps that swing, `Γ / (2 J_rigid ω)`.
    pub air_scale: f32,
    /// Padding.
    pub _pad: [u32; 2],
}

/// Per-step values, 32 bytes. WGSL: `AkagiStep` in `akagi.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawAkagiStep {
    /// Drag coefficient.
    pub drag: f32,
    /// Time at the end of the step, s.
    pub time: f32,
    /// Step, s.
    pub dt: f32,
    /// See [`super::AkagiParams::reconfiguration_speed`].
    pub reconfiguration_speed: f32,
    /// See [`super::AkagiParams::stiffening_angle`].
    pub stiffening_angle: f32,
    /// See [`super::AkagiParams::vogel_exponent`].
    pub vogel_exponent: f32,
    /// Padding.
    pub _pad: [f32; 2],
}
