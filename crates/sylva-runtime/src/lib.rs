//! Sylva as a library: what an application embeds to have moving trees in its own renderer.
//!
//! A scene (TOML, [`sylva_core::scene::Scene`]) becomes a [`World`]: every tree grown
//! (species or grammar), its method built on the CPU or the GPU from the [`MethodRegistry`]
//! (the four built-in methods and any the application registers), its copies dealt among
//! phase groups or posed one by one, and the wind composed with live effects ([`Effect`]).
//! Each frame the application steps the world, records its meshes and draws its items:
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use std::sync::Arc;
//! use sylva_runtime::{World, sylva_core::scene::Scene, sylva_gpu::GpuContext};
//! // An application's own device (here one Sylva makes): adapter, device and queue.
//! let ctx = Arc::new(GpuContext::new(&Default::default())?);
//! let mut world = World::new(ctx.clone(), Scene::default_scene())?;
//! world.step(4)?; // four simulation steps (the scene's `sim_rate`)
//! let mut encoder = ctx.device.create_command_encoder(&Default::default());
//! world.record(&mut encoder); // the meshes of the new poses, on the GPU
//! let items = world.draw_items(); // vertex and index buffers, instance lists
//! # let _ = items; Ok(()) }
//! ```
//!
//! The device may be the application's ([`sylva_gpu::GpuContext::from_wgpu`]), so an
//! engine and Sylva share it. Debug overlays come as data ([`World::skeleton`],
//! [`World::cluster_centres`], [`World::wind_arrows`]). Errors are [`RuntimeError`]s.

mod error;
pub mod registry;
pub mod tree;
pub mod wind;
mod world;

pub use error::RuntimeError;
pub use registry::{BUILTIN, CpuConstructor, MethodEntry, MethodRegistry};
pub use sylva_core;
pub use sylva_gpu;
pub use tree::{MAX_SKINNED_BYTES, Simulation, WorldTree};
pub use wind::{Effect, WorldWind};
pub use world::World;
