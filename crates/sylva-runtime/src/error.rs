//! What can go wrong building or running a world.

use sylva_core::methods::MethodError;
use sylva_core::scene::SceneError;

/// Errors of the runtime.
#[derive(Debug, thiserror::Error)]
pub enum RuntimeError {
    /// The scene file.
    #[error(transparent)]
    Scene(Box<SceneError>),
    /// A tree's species or grammar.
    #[error("{file}: field `tree[{index}].species`: {source}")]
    Species {
        /// The scene file.
        file: String,
        /// The tree's index.
        index: usize,
        /// Why the species did not load or grow.
        source: Box<sylva_core::species::SpeciesError>,
    },
    /// A tree's method and its parameters.
    #[error("{file}:{line}: tree[{index}]: {source}")]
    Method {
        /// The scene file.
        file: String,
        /// The line of the tree's method or parameters.
        line: usize,
        /// The tree's index.
        index: usize,
        /// What the method refused.
        source: Box<MethodError>,
    },
    /// The scene's wind.
    #[error("{file}: field `wind`: {source}")]
    SceneWind {
        /// The scene file.
        file: String,
        /// Why the wind did not load.
        source: Box<sylva_core::wind::WindError>,
    },
    /// Meshing.
    #[error(transparent)]
    Mesh(#[from] sylva_core::mesh::MeshError),
    /// The device.
    #[error(transparent)]
    Gpu(#[from] sylva_gpu::GpuError),
    /// A scene beyond a limit (the message names the limit and what to change).
    #[error("{0}")]
    Limit(String),
    /// Registering a method.
    #[error("{0}")]
    Registry(String),
    /// A tree index out of range.
    #[error("tree {index}: the world has {trees} trees")]
    NoTree {
        /// The index asked for.
        index: usize,
        /// Trees in the world.
        trees: usize,
    },
    /// A method asked for on the GPU has no GPU twin.
    #[error("tree[{index}]: method `{method}` has no GPU twin; set `backend = \"cpu\"`")]
    NoGpuTwin {
        /// The tree's index.
        index: usize,
        /// The method.
        method: String,
    },
}

impl From<SceneError> for RuntimeError {
    fn from(e: SceneError) -> Self {
        Self::Scene(Box::new(e))
    }
}
