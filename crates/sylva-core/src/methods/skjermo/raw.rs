//! Skjermo's per-stem constants, state and per-step values as the GPU lays them out
//! (`skjermo.wgsl`).

use bytemuck::{Pod, Zeroable};

/// Per-stem constants, 160 bytes (the curve seam's [`crate::pose::RawCurveStem`]). WGSL:
/// `SkjermoStem` in `skjermo.wgsl`.
pub type RawSkjermoStem = crate::pose::RawCurveStem;

/// Per-stem state (what ping-pongs): the stem's curve as displacements from rest and its
/// orientation vector, 80 bytes. WGSL: `SkjermoState`.
pub type RawSkjermoState = crate::pose::RawStemCurve;

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
    /// Padding.
    pub _pad: [f32; 4],
}
