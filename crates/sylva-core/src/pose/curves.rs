//! The curve seam: methods that bend one Bézier per stem (Skjermo §4) hand their curves
//! to the deformer (§3) in these layouts, beside the per-segment pose.

use bytemuck::{Pod, Zeroable};

/// A curve-bending method's per-stem constants, 160 bytes: the stem's rest Bézier, its rest
/// shape in its attachment frame, where it hangs on its parent, and the method's bend
/// factor. WGSL: `SkjermoStem` in `skjermo.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawCurveStem {
    /// Rest control points (xyz, w = 1).
    pub rest: [[f32; 4]; 4],
    /// Rest control points P0..P3 relative to the attachment point in the rest attachment
    /// frame (xyz).
    pub local: [[f32; 4]; 4],
    /// Parent stem (`u32::MAX` for a trunk).
    pub parent: u32,
    /// Bézier parameter of the attachment on the parent.
    pub attach: f32,
    /// Static bend per (m/s)², rad·s²/m².
    pub drag: f32,
    /// Arc length, m.
    pub length: f32,
    /// The parent's rest orientation vector (xyz; zero for a trunk).
    pub parent_orient: [f32; 4],
}

/// A stem's animated Bézier as the deformer reads it (Skjermo §3), 64 bytes: the
/// displacement of each control point from rest. Children re-attach by the parent's rest
/// orientation vector (`RawCurveStem::parent_orient`) turned with its curve's tangent, so
/// none is carried here. WGSL: `SkjermoState` in `skjermo.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawStemCurve {
    /// Displacements of P0..P3 (xyz).
    pub delta: [[f32; 4]; 4],
}

/// A method's stems and their current curves, as the deformer reads them.
#[derive(Debug, Clone, Copy)]
pub struct Curves<'a> {
    /// Per-stem constants (rest control points, attachment).
    pub stems: &'a [RawCurveStem],
    /// Each stem's current curve.
    pub state: &'a [RawStemCurve],
}
