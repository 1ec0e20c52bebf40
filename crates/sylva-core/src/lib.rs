//! Sylva core: the tree model, its generators, and (as they land) wind fields,
//! animation methods and CPU meshing.
//!
//! This crate never depends on a GPU API. Every stage here is the CPU reference that the
//! `sylva-gpu` crate's WGSL kernels are held to.
//!
//! Pipeline: species or grammar → [`Tree`] (skeleton + leaves) → wind → method → pose → mesh.
//!
//! * [`model`]: the one tree representation all methods and meshers consume
//!   (structure of arrays, topological order, flat child lists, `Pod` raw twins for upload).
//! * [`generate`]: parametric L-systems (Song §3, ABOP ch. 1–2) and Weber–Penn trees
//!   (Weber & Penn 1995; Skjermo §2.1).
//! * [`species`]: the presets shipped in `presets/` and loading of user files.
//! * [`export`]: static OBJ output, written atomically.
//! * [`simd`]: eight-lane vectors for the CPU fast paths, with AVX2 where the CPU has it.

pub mod export;
pub mod generate;
pub mod io;
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

pub use generate::lsystem::{Grammar, GrammarError, LSystemOptions};
pub use generate::weber_penn::{WeberPennError, WeberPennParams};
pub use limits::{LimitExceeded, Limits};
pub use model::{Children, Leaves, ModelError, NONE, Segments, Stems, Tree, TreeBuilder, TreeStats, WoodProperties};
pub use species::{Preset, PresetKind, SpeciesError, SpeciesSource};
