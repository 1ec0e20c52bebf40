//! WGSL sources. Shared pieces are separate files composed in front of each kernel
//! ([`compose`]), so no WGSL is copied between kernels.

/// Quaternion helpers (`quat_rotate`, `quat_mul`), unit quaternions as `vec4<f32>(x, y, z, w)`.
pub const QUAT: &str = include_str!("quat.wgsl");
/// The tree model's structs (`Segment`, `Stem`, `Leaf`), twins of `sylva_core::model::Raw*`.
pub const TREE: &str = include_str!("tree.wgsl");
/// Kernel: segment end points from start, orientation and length.
pub const SEGMENT_ENDS: &str = include_str!("segment_ends.wgsl");

/// Every kernel, as (name, the sources composed in order). Tests validate each with naga.
pub const KERNELS: &[(&str, &[&str])] = &[("segment_ends", &[QUAT, TREE, SEGMENT_ENDS])];

/// Concatenates WGSL sources into one module.
pub fn compose(parts: &[&str]) -> String {
    parts.join("\n")
}
