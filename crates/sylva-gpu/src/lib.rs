//! Sylva's GPU crate: wgpu device setup, compute kernels, the methods' GPU twins and the
//! renderer.
//!
//! Every kernel here is the WGSL twin of a CPU reference in `sylva-core`, with the same
//! name, binding order and loop shape; [`shaders::KERNELS`] lists each with its sources and
//! its twin, and tests hold the two to the same numbers on random inputs.
//!
//! * [`GpuContext`]: instance from the environment (`WGPU_BACKEND`, …), or an application's
//!   own device; adapter report, typed errors, a process-wide shared device.
//! * [`kernel`]: build a compute pipeline from the registry, upload structure-of-arrays
//!   buffers, dispatch and read back.
//! * [`shaders`]: the kernel registry and the shared WGSL pieces.
//! * [`wind`]: a scene's wind on the device, shared by every method.
//! * [`pose`]: the pose seam's buffers and forward kinematics.
//! * [`methods`]: the GPU seam ([`methods::GpuAnimator`]) and one folder per method.
//! * [`mesh`]: per-frame meshing, skinning and Skjermo's deformer.
//! * [`render`]: the offscreen renderer.
//! * [`timer`]: GPU time of a stretch of work from timestamp queries.

mod context;
pub mod kernel;
pub mod leaves;
pub mod mesh;
pub mod methods;
pub mod pose;
pub mod render;
pub mod shaders;
pub mod step_slots;
pub mod timer;
pub mod wind;

pub use context::{AdapterSummary, GpuContext, GpuCounts, GpuError, GpuOptions};
pub use sylva_core;
