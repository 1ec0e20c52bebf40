//! Sylva's GPU crate: wgpu device setup, compute kernels and the renderer.
//!
//! Every kernel here is the WGSL twin of a CPU reference in `sylva-core` with the same name,
//! binding order and loop shape (`shader/x.wgsl` ↔ `sylva_core::cpu::x`), and tests hold the
//! two to the same numbers on random inputs.
//!
//! * [`GpuContext`]: instance from the environment (`WGPU_BACKEND`, …), adapter report,
//!   device with the adapter's limits, typed errors, a process-wide shared device.
//! * [`kernel`]: a small uniform way to build a compute pipeline from WGSL sources, upload
//!   structure-of-arrays buffers, dispatch and read back.
//! * [`shader`]: the WGSL sources; shared pieces (quaternions, the tree structs) are
//!   composed into each kernel, never copied.
//! * [`timer`]: GPU time of a stretch of work from timestamp queries.

mod context;
pub mod deform;
pub mod hsm;
pub mod kernel;
pub mod mesh;
pub mod pose;
pub mod render;
pub mod segment_ends;
pub mod shader;
pub mod skin;
pub mod timer;
pub mod trunk_noise;
pub mod wind_sample;

pub use context::{AdapterSummary, GpuContext, GpuError, GpuOptions};
pub use sylva_core;
