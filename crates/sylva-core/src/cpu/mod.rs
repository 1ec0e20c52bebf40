//! CPU references of the GPU kernels, with the same names, binding order and loop shape as
//! their WGSL twins in `sylva-gpu/src/shader/` (`cpu::x` ↔ `shader/x.wgsl`).

pub mod akagi;
pub mod hsm;
pub mod hsm_runs;
pub mod hsm_slot_groups;
mod mesh_detail;
mod mesh_leaves;
mod mesh_tubes;
pub mod noise;
pub mod pose_fk;
mod segment_ends;
mod skin_vertices;
pub mod skjermo;
mod skjermo_deform;
pub mod trunk_noise;
pub mod wind_sample;
pub mod zioma_rotations;

pub use mesh_detail::mesh_detail;
pub use mesh_leaves::mesh_leaves;
pub use mesh_tubes::mesh_tubes;
pub use segment_ends::segment_ends;
pub use skin_vertices::skin_vertices;
pub use skjermo_deform::skjermo_deform;
pub use trunk_noise::trunk_noise;
pub use wind_sample::wind_sample;
pub use zioma_rotations::zioma_rotations;
