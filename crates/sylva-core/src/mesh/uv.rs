//! The static texture-coordinate streams beside the per-frame vertices ([`super::vertex`]):
//! made once from the layout, in the vertex order the kernels write.

use super::{MeshLayout, RawMeshInfo, RawRing, Uv};
use crate::model::LeafShape;
use crate::model::leaf_shape::leaf_rim;

/// Texture coordinates of ring vertex `a` of the bark: `u` around the ring (k / sides, the
/// seam column at 1), `v` the ring's ([`RawRing::v`]).
#[inline]
pub(super) fn ring_uv(info: &RawMeshInfo, ring: &[RawRing], a: u32) -> Uv {
    let stride = info.sides + 1;
    [(a % stride) as f32 / info.sides as f32, ring[(a / stride) as usize].v]
}

/// Every shape's rim of `sides` points once (the disc's two half-circles, or a polygon
/// holding the outline), then one past the last shape: what an unknown index gets (the
/// default radius). A leaf's is `rims[shape.min(rims.len() - 1)]`.
pub(super) fn leaf_rims(sides: u32) -> Vec<Vec<Uv>> {
    (0..=LeafShape::ALL.len() as u32)
        .map(|shape| (0..sides).map(|k| leaf_rim(shape, k, sides).into()).collect())
        .collect()
}

impl MeshLayout {
    /// Bark texture coordinates, one per bark vertex: the rings' (`ring_uv`), then each band
    /// midpoint the mean of its edge's two ends.
    pub fn tube_uv(&self) -> Vec<Uv> {
        let info = self.info();
        let ring_vertices = self.rings.len() as u32 * (info.sides + 1);
        let mut uv: Vec<Uv> = Vec::with_capacity(self.tube_vertex_count());
        uv.extend((0..ring_vertices).map(|a| ring_uv(&info, &self.rings, a)));
        for d in &self.details {
            let (a, b) = (uv[d.a as usize], uv[d.b as usize]);
            uv.push([0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]);
        }
        uv
    }

    /// Every leaf shape's rim of `leaf_sides` points, shape after shape, then the row an
    /// unknown shape index gets (`leaf_rims`): the `leaf_rim` binding of `mesh_leaves`,
    /// made once so that no kernel evaluates an outline per vertex and frame.
    pub fn leaf_rim_table(&self) -> Vec<Uv> {
        leaf_rims(self.params.leaf_sides).concat()
    }

    /// Leaf texture coordinates, one per leaf vertex: the centre (0.5, 0.5), then the rim of
    /// the leaf's outline (`leaf_rim`), as `mesh_leaves` places them.
    pub fn leaf_uv(&self) -> Vec<Uv> {
        let rims = leaf_rims(self.params.leaf_sides);
        let mut uv = Vec::with_capacity(self.leaf_vertex_count());
        for l in &self.leaves {
            uv.push([0.5, 0.5]);
            uv.extend_from_slice(&rims[(l.shape as usize).min(rims.len() - 1)]);
        }
        uv
    }
}
