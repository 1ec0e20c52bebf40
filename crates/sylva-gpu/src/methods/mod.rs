//! The GPU twins of the animation methods and the seam they plug into: the GPU side of
//! [`sylva_core::methods`].
//!
//! A [`GpuAnimator`] is built from a tree, the method's options and the scene's wind on the
//! device ([`GpuWind`], shared by every method of a scene). It advances by whole steps, all
//! its work submitted to the queue, and keeps its pose on the device as the seam's buffers
//! ([`GpuPose`]: joint positions and accumulated rotations), which the mesher and skinning
//! read with no round trip. Its numbers are those of the CPU twin within the tolerances its
//! parity tests state.
//!
//! One folder per method holds its driver and its WGSL; the runtime's registry names the
//! `animator` constructor of each beside the CPU one.

pub mod akagi;
pub mod hsm;
pub mod skjermo;
pub mod zioma;

use crate::pose::GpuPose;
use crate::wind::GpuWind;
use crate::{GpuContext, GpuError};
use glam::Vec3;
use std::fmt::Debug;
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::methods::{MethodError, MethodOptions};
use sylva_core::pose::{Placement, Pose};

/// Errors building a method on the GPU.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// The method's parameters or layout.
    #[error(transparent)]
    Method(#[from] MethodError),
    /// The device.
    #[error(transparent)]
    Gpu(#[from] GpuError),
}

/// A method's constructor on the GPU: tree, options, the scene's wind on the device and the
/// placed instances (used by methods that pose every instance; the others ignore them).
pub type GpuConstructor =
    fn(&GpuContext, Arc<Tree>, &MethodOptions, &GpuWind, &[Placement]) -> Result<Box<dyn GpuAnimator>, BuildError>;

/// The buffers of a method that bends Bézier curves, as the deformer reads them (Skjermo
/// §3): the per-stem constants (`RawSkjermoStem`) and the current curves (`RawStemCurve`).
#[derive(Debug, Clone, Copy)]
pub struct GpuCurves<'a> {
    /// Per-stem constants.
    pub stems: &'a wgpu::Buffer,
    /// The stems' current curves.
    pub state: &'a wgpu::Buffer,
}

/// A method running on the GPU (see the module docs).
pub trait GpuAnimator: Debug + Send + Sync {
    /// The method's name.
    fn name(&self) -> &'static str;
    /// The tree it animates.
    fn tree(&self) -> &Arc<Tree>;
    /// Binds the scene's wind from now on; the state is kept.
    fn set_wind(&mut self, wind: &GpuWind);
    /// Returns to the rest state at `time`.
    fn reset(&mut self, ctx: &GpuContext, time: f32);
    /// Advances `steps` steps of `dt` seconds and writes the pose (submitted, not waited
    /// for). Zero steps writes the pose of the current state.
    fn advance(&mut self, ctx: &GpuContext, dt: f32, steps: usize);
    /// Simulated time, s.
    fn time(&self) -> f32;
    /// The seam's buffers on the device (instance-major for methods that pose instances).
    fn pose_buffers(&self) -> &GpuPose;
    /// The current pose read back (the first instance; waits for the GPU).
    fn read_pose(&self, ctx: &GpuContext) -> Result<Pose, GpuError> {
        self.pose_buffers().read(ctx)
    }
    /// See [`GpuCurves`].
    fn curves(&self) -> Option<GpuCurves<'_>> {
        None
    }
    /// Debug data: the centres of the method's clusters, in the tree's frame (waits).
    fn cluster_centres(&self, _ctx: &GpuContext) -> Result<Option<Vec<Vec3>>, GpuError> {
        Ok(None)
    }
    /// Particles simulated (particle methods).
    fn particles(&self) -> Option<usize> {
        None
    }
}
