//! Skjermo's per-stem constants, state and per-step values as the GPU lays them out
//! (`skjermo.wgsl`).

use bytemuck::{Pod, Zeroable};

/// Per-stem constants, 160 bytes (the curve seam's [`crate::pose::RawCurveStem`]). WGSL:
/// `SkjermoStem` in `skjermo.wgsl`.
pub type RawSkjermoStem = crate::pose::RawCurveStem;

/// Per-stem state (what ping-pongs): the stem's curve as displacements from rest, 64 bytes.
/// WGSL: `SkjermoState`.
pub type RawSkjermoState = crate::pose::RawStemCurve;

/// Per-stem oscillator constants of the second-order bend, 16 bytes. WGSL: `SkjermoMode`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawSkjermoMode {
    /// Squared natural frequency of the stem's first mode ω², rad²/s².
    pub w2: f32,
    /// Structural damping rate ζω, 1/s.
    pub damping: f32,
    /// Aerodynamic damping per m/s of wind, 1/m: the bend's velocity is damped at `aero · u`
    /// (1/s).
    pub aero: f32,
    /// Padding.
    pub _pad: f32,
}

/// Per-stem bend of the second-order response (updated in place; each stem reads only its
/// own), 32 bytes. WGSL: `SkjermoSway`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawSkjermoSway {
    /// The tip's bend vector b₃ (eq. 16's push, xyz), m.
    pub bend: [f32; 4],
    /// Its rate of change (xyz), m/s.
    pub rate: [f32; 4],
}

/// Per-step values, 32 bytes. WGSL: `SkjermoStep`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawSkjermoStep {
    /// Time, s.
    pub time: f32,
    /// Exponent e.
    pub exponent: f32,
    /// P2 weight.
    pub p2_weight: f32,
    /// Largest static bend, rad.
    pub max_bend: f32,
    /// Step length, s.
    pub dt: f32,
    /// 1: the bend follows the wind as a damped oscillator; 0: at once, as published.
    pub dynamics: u32,
    /// Reconfiguration speed U_r, m/s.
    pub reconfiguration_speed: f32,
    /// Vogel exponent B.
    pub vogel_exponent: f32,
}
