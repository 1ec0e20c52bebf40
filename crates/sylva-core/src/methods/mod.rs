//! Animation methods and the seam they all plug into.
//!
//! # The seam
//!
//! A method is built from a tree and its options ([`MethodOptions`]: a seed and a table of
//! the method's own parameters, as a scene's `[tree.params]` sets them). It has a rest state,
//! takes new wind, steps by `dt`, and hands its pose out as the seam's buffers
//! ([`SeamPose`]: per segment, the joint position and the accumulated rotation `D`, which
//! meshers, skinning and exporters read).
//!
//! * [`Method`] is that interface with the state explicit, `step(&self, tree, wind, &mut
//!   state, dt)`: what tests and tools that hold many states use.
//! * [`Simulation`] owns a method, its tree, its wind and one state: the object-safe
//!   [`Animator`] that the runtime and the exporters drive without knowing the method.
//! * The GPU twin of the seam is `sylva_gpu::methods::GpuAnimator`; the runtime's registry
//!   maps a method's name to both constructors.
//!
//! One folder per method holds its parameters, its GPU-layout types (`raw.rs`), the CPU
//! twins of its kernels and its fast CPU forms, and a `animator` constructor for the
//! registry. A method uses the shared modules (`model`, `wind`, `physics`, `pose`, `leaves`), never
//! another method.

pub mod akagi;
pub mod hsm;
pub mod skjermo;
pub mod zioma;

use crate::model::Tree;
use crate::pose::{Curves, Placement, Pose, SeamPose};
use crate::wind::PackedWind;
use glam::Vec3;
use std::fmt::Debug;
use std::sync::Arc;

/// Errors building a method.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MethodError {
    /// A parameter is missing its range or type.
    #[error("method `{method}`: parameter `{field}` = {value}: expected {expected}")]
    Param { method: &'static str, field: String, value: String, expected: String },
    /// The method's layout would exceed a limit.
    #[error("method `{method}`: the tree needs {needed} {what}, more than the limit of {limit}")]
    TooLarge { method: &'static str, what: &'static str, needed: usize, limit: usize },
    /// No method by this name.
    #[error("no animation method `{name}` (known: {known})")]
    Unknown { name: String, known: String },
}

/// What a method is built from besides the tree.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MethodOptions {
    /// Seed of the method's own randomness (Zioma's branch phases).
    pub seed: u64,
    /// The method's parameters by name (its `Params` type's fields); absent ones keep their
    /// defaults. Unknown names and out-of-range values are errors.
    pub params: toml::Table,
}

impl MethodOptions {
    /// Options with a seed and default parameters.
    pub fn seeded(seed: u64) -> Self {
        Self { seed, params: toml::Table::new() }
    }

    /// The method's parameters: the defaults, with the table's entries over them.
    pub fn parse<P: serde::de::DeserializeOwned + Default>(&self, method: &'static str) -> Result<P, MethodError> {
        if self.params.is_empty() {
            return Ok(P::default());
        }
        P::deserialize(toml::Value::Table(self.params.clone())).map_err(|e| {
            let message = e.to_string();
            let field = message.split('`').nth(1).unwrap_or("params").to_string();
            MethodError::Param { method, field, value: "(as written)".into(), expected: message.trim().to_string() }
        })
    }
}

/// A parameter check: `Err` naming the field, its value and what was expected.
pub fn check(method: &'static str, field: &str, value: f32, ok: bool, expected: &str) -> Result<(), MethodError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(MethodError::Param { method, field: field.into(), value: value.to_string(), expected: expected.into() })
    }
}

/// An animation method with its state explicit (see the module docs).
pub trait Method: Debug + Send + Sync + 'static {
    /// The simulation state: structure of arrays in topological order.
    type State: Clone + Debug + Send + Sync;

    /// The name scene files and the registry use.
    fn name(&self) -> &'static str;

    /// The state at rest (still air gives the rest pose bit for bit).
    fn rest_state(&self, tree: &Tree) -> Self::State;

    /// Advances `state` by `dt` seconds in `wind`.
    fn step(&self, tree: &Tree, wind: &PackedWind, state: &mut Self::State, dt: f32);

    /// Simulated time of `state`, s.
    fn time(&self, state: &Self::State) -> f32;

    /// Sets the simulated time of `state` (a simulation started later than time 0).
    fn set_time(&self, state: &mut Self::State, time: f32);

    /// The pose of `state` as the seam's buffers (one instance).
    fn seam(&self, tree: &Tree, wind: &PackedWind, state: &Self::State, out: &mut SeamPose);

    /// The pose of `state` with world orientations (and Béziers where the method has them).
    fn pose(&self, tree: &Tree, wind: &PackedWind, state: &Self::State) -> Pose {
        let mut seam = SeamPose::default();
        self.seam(tree, wind, state, &mut seam);
        seam.pose(tree, 0)
    }

    /// The stems' animated Béziers as the deformer reads them (methods that bend curves).
    fn curves<'a>(&'a self, _state: &'a Self::State) -> Option<Curves<'a>> {
        None
    }

    /// Poses every placed instance on its own (wind sampled at the instance, its own phase)
    /// into `out`, instance-major, with the first instance's leaf rotations (which every
    /// copy takes); false for methods whose copies share a simulation.
    fn seam_instances(
        &self,
        _tree: &Tree,
        _wind: &PackedWind,
        _state: &Self::State,
        _instances: &[Placement],
        _out: &mut SeamPose,
    ) -> bool {
        false
    }

    /// Registers the instances [`Self::seam_instances`] will pose, for methods that keep
    /// state per instance (Zioma's rings); the others ignore it.
    fn set_instances(&self, _tree: &Tree, _state: &mut Self::State, _instances: &[Placement]) {}

    /// Debug data: the centres of the method's clusters, in the tree's frame.
    fn cluster_centres(&self, _state: &Self::State) -> Option<Vec<Vec3>> {
        None
    }

    /// Particles simulated (particle methods).
    fn particles(&self) -> Option<usize> {
        None
    }
}

/// A method, its tree, its wind and its state, driven as one object (see the module docs).
pub trait Animator: Debug + Send + Sync {
    /// The method's name.
    fn name(&self) -> &'static str;
    /// The tree it animates.
    fn tree(&self) -> &Arc<Tree>;
    /// Replaces the wind; the state is kept.
    fn set_wind(&mut self, wind: Arc<PackedWind>);
    /// The wind it reads.
    fn wind(&self) -> &PackedWind;
    /// Returns to the rest state at `time`.
    fn reset(&mut self, time: f32);
    /// Advances by `dt` seconds.
    fn step(&mut self, dt: f32);
    /// Advances `steps` steps of `dt` seconds.
    fn advance(&mut self, dt: f32, steps: usize) {
        for _ in 0..steps {
            self.step(dt);
        }
    }
    /// Simulated time, s.
    fn time(&self) -> f32;
    /// The current pose as the seam's buffers (one instance).
    fn seam(&self, out: &mut SeamPose);
    /// The current pose with world orientations.
    fn pose(&self) -> Pose;
    /// See [`Method::curves`].
    fn curves(&self) -> Option<Curves<'_>>;
    /// See [`Method::seam_instances`].
    fn seam_instances(&self, instances: &[Placement], out: &mut SeamPose) -> bool;
    /// See [`Method::set_instances`].
    fn set_instances(&mut self, instances: &[Placement]);
    /// See [`Method::cluster_centres`].
    fn cluster_centres(&self) -> Option<Vec<Vec3>>;
    /// See [`Method::particles`].
    fn particles(&self) -> Option<usize>;
}

/// A [`Method`] with its tree, wind and state: the [`Animator`] every method becomes.
#[derive(Debug, Clone)]
pub struct Simulation<M: Method> {
    tree: Arc<Tree>,
    method: M,
    state: M::State,
    wind: Arc<PackedWind>,
    /// The instances registered ([`Animator::set_instances`]), kept across a reset.
    instances: Vec<Placement>,
}

impl<M: Method> Simulation<M> {
    /// The method at rest in still air.
    pub fn new(tree: Arc<Tree>, method: M) -> Self {
        let state = method.rest_state(&tree);
        Self { tree, method, state, wind: Arc::new(PackedWind::calm()), instances: Vec::new() }
    }

    /// Boxed as an [`Animator`].
    pub fn boxed(tree: Arc<Tree>, method: M) -> Box<dyn Animator> {
        Box::new(Self::new(tree, method))
    }

    /// The method.
    pub fn method(&self) -> &M {
        &self.method
    }

    /// The state.
    pub fn state(&self) -> &M::State {
        &self.state
    }

    /// The state, to edit.
    pub fn state_mut(&mut self) -> &mut M::State {
        &mut self.state
    }
}

impl<M: Method> Animator for Simulation<M> {
    fn name(&self) -> &'static str {
        self.method.name()
    }
    fn tree(&self) -> &Arc<Tree> {
        &self.tree
    }
    fn set_wind(&mut self, wind: Arc<PackedWind>) {
        self.wind = wind;
    }
    fn wind(&self) -> &PackedWind {
        &self.wind
    }
    fn reset(&mut self, time: f32) {
        self.state = self.method.rest_state(&self.tree);
        self.method.set_time(&mut self.state, time);
        self.method.set_instances(&self.tree, &mut self.state, &self.instances);
    }
    fn step(&mut self, dt: f32) {
        self.method.step(&self.tree, &self.wind, &mut self.state, dt);
    }
    fn time(&self) -> f32 {
        self.method.time(&self.state)
    }
    fn seam(&self, out: &mut SeamPose) {
        self.method.seam(&self.tree, &self.wind, &self.state, out);
    }
    fn pose(&self) -> Pose {
        self.method.pose(&self.tree, &self.wind, &self.state)
    }
    fn curves(&self) -> Option<Curves<'_>> {
        self.method.curves(&self.state)
    }
    fn seam_instances(&self, instances: &[Placement], out: &mut SeamPose) -> bool {
        self.method.seam_instances(&self.tree, &self.wind, &self.state, instances, out)
    }
    fn set_instances(&mut self, instances: &[Placement]) {
        self.instances = instances.to_vec();
        self.method.set_instances(&self.tree, &mut self.state, instances);
    }
    fn cluster_centres(&self) -> Option<Vec<Vec3>> {
        self.method.cluster_centres(&self.state)
    }
    fn particles(&self) -> Option<usize> {
        self.method.particles()
    }
}
