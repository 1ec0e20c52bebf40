//! Exporters (CPU): static OBJ, and glTF 2.0 with a skin and wind baked from any method.
//! Every file is written atomically: completely or not at all.

pub mod bake;
pub mod gltf;
pub mod obj;
pub mod textures;

pub use bake::{BakeError, BakeParams, Clip, bake};
pub use gltf::{
    DEFAULT_LODS, ExportReport, GltfDocument, GltfError, GltfOptions, JointMode, Lod, LodReport, build_gltf, write_gltf,
};
pub use obj::{ObjOptions, write_obj};
