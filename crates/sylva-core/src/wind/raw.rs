//! Packed wind fields: one `#[repr(C)]` record per field plus a shared table of waves, the
//! layout the GPU reads (`wind.wgsl` structs `Field`, `Wave`; a test checks offsets).
//!
//! The meaning of the parameter slots depends on `kind`:
//!
//! | kind | `a` | `b` | `c` | waves |
//! | --- | --- | --- | --- | --- |
//! | constant | velocity xyz | – | – | – |
//! | sum of sines | (k, mode, –, –) | fades (in start, 1/in duration, out start, 1/out duration) | – | `dir` = D (xz) · A, `k` = D w, `freq` = φ |
//! | gust front | origin xz, direction xz | strength, speed, width, length | start, radius, –, – | – |
//! | vortex | centre xz, drift xz | strength, radius, start, duration | fade, updraft, –, – | – |
//! | blast | centre xyz, strength | start, speed, width, decay | radius, –, –, – | – |
//! | turbulence | – | fades, as sum of sines | – | `dir` = u · a, `k` = wave vector, `freq` = f, `phase` |
//! | grid | origin xyz, frames/s | 1/cell xyz, wrap | – | header (`dir` = nx ny nz frames, `k` = scroll), then 3 nodes a record |

use bytemuck::{Pod, Zeroable};

/// Field kinds.
pub mod kind {
    /// Constant wind.
    pub const CONSTANT: u32 = 0;
    /// Sum of sines (Skjermo eqs. 11–14).
    pub const SUM_OF_SINES: u32 = 1;
    /// Travelling gust front (Zioma §6.3.1 primitive).
    pub const GUST_FRONT: u32 = 2;
    /// Vortex about a vertical axis.
    pub const VORTEX: u32 = 3;
    /// Blast: expanding, decaying shell.
    pub const BLAST: u32 = 4;
    /// 1/f^β turbulence by spectral synthesis.
    pub const TURBULENCE: u32 = 5;
    /// Velocities on a grid (Zioma §6.3.1's wind texture; `wind::grid`).
    pub const GRID: u32 = 6;
}

/// One packed field, 64 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawField {
    /// One of [`kind`].
    pub kind: u32,
    /// First wave in the wave table.
    pub wave_offset: u32,
    /// Number of waves.
    pub wave_count: u32,
    /// Padding.
    pub _pad: u32,
    /// Parameters (see the module table).
    pub a: [f32; 4],
    /// Parameters.
    pub b: [f32; 4],
    /// Parameters.
    pub c: [f32; 4],
}

/// One wave of a sum of sines or of turbulence, 48 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawWave {
    /// Velocity direction times amplitude (xyz), w unused.
    pub dir: [f32; 4],
    /// Wave vector (xyz, rad/m); w = temporal frequency (Hz for turbulence, φ in rad/s for
    /// a sum of sines).
    pub k: [f32; 4],
    /// x = phase in cycles (turbulence); others unused.
    pub phase: [f32; 4],
}
