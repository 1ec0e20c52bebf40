//! CPU references of the GPU kernels, with the same names, binding order and loop shape as
//! their WGSL twins in `sylva-gpu/src/shader/` (`cpu::x` ↔ `shader/x.wgsl`).

pub mod noise;
mod segment_ends;
pub mod trunk_noise;
pub mod wind_sample;

pub use segment_ends::segment_ends;
pub use trunk_noise::trunk_noise;
pub use wind_sample::wind_sample;
