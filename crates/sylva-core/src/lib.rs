//! Sylva core: the tree model, its generators, wind fields, the animation methods and their
//! CPU kernels, meshing and export.
//!
//! This crate never depends on a GPU API. Every stage here is the CPU reference that the
//! `sylva-gpu` crate's WGSL kernels are held to.
//!
//! Pipeline: species or grammar → [`Tree`] (skeleton + leaves) → wind → method → pose → mesh.
//!
//! * [`model`]: the one tree representation all methods and meshers consume
//!   (structure of arrays, topological order, flat child lists, `Pod` raw twins for upload).
//! * [`generate`]: parametric L-systems (Song §3, ABOP ch. 1–2) and Weber–Penn trees
//!   (Weber & Penn 1995; Skjermo §2.1); [`species`]: the presets shipped in `presets/` and
//!   loading of user files.
//! * [`wind`]: wind fields, packed for the kernels, sampled one point or sixteen at a time.
//! * [`physics`]: the tree as a mechanical body (air, drag, a joint's radius, a stem's load).
//! * [`methods`]: the method seam ([`methods::Method`], [`methods::Animator`]) and one folder
//!   per method (Zioma, Akagi, Skjermo, HSM) with its parameters, GPU-layout types, CPU
//!   kernels and fast forms.
//! * [`leaves`]: leaves that move about their petioles (one rotation per leaf in the seam).
//! * [`pose`]: the seam's output (joints and accumulated rotations), forward kinematics,
//!   placements of instances, curves for the deformer.
//! * [`mesh`]: per-frame meshing, skinning and Skjermo's deformer, with their CPU kernels.
//! * [`export`]: OBJ and glTF, baked clips; [`io`]: files read with limits and written
//!   completely or not at all; [`scene`]: scene files.
//! * [`simd`]: sixteen-lane vectors for the CPU fast paths, run with AVX2 where the CPU has it.

pub mod export;
pub mod generate;
pub mod io;
pub mod leaves;
pub mod limits;
pub mod mesh;
pub mod methods;
pub mod model;
pub mod physics;
pub mod pose;
pub mod rng;
pub mod scene;
pub mod simd;
pub mod species;
pub mod wind;

/// Fewest items a CPU kernel hands to rayon's pool; smaller batches run on the calling thread.
/// A parallel call from outside the pool waits for a worker, and when the pool is shared (an
/// application's other work, several simulations at once) it waits behind everything already
/// queued there: a few hundred segments' worth of work is cheaper than that hand-off.
pub const PARALLEL_FROM: usize = 4096;

pub use generate::lsystem::{Grammar, GrammarError, LSystemOptions};
pub use generate::weber_penn::{WeberPennError, WeberPennParams};
pub use limits::{LimitExceeded, Limits};
pub use model::{Children, Leaves, ModelError, NONE, Segments, Stems, Tree, TreeBuilder, TreeStats, WoodProperties};
pub use species::{Preset, PresetKind, SpeciesError, SpeciesSource};
