//! CPU references of the GPU kernels, with the same names, binding order and loop shape as
//! their WGSL twins in `sylva-gpu/src/shader/` (`cpu::x` ↔ `shader/x.wgsl`).

mod segment_ends;

pub use segment_ends::segment_ends;
