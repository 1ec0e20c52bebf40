//! The static texture-coordinate streams beside the per-frame vertices ([`super::vertex`]):
//! made once from the layout, in the vertex order the kernels write.

use super::{MeshLayout, Uv};
use crate::model::LeafShape;
use crate::model::leaf_shape::leaf_rim;

impl MeshLayout {
    /// Bark texture coordinates, one per bark vertex: `u` around the ring (k / sides, the
    /// seam column at 1), `v` the ring's ([`super::RawRing::v`]); a band midpoint the mean of
    /// its edge's two ends.
    pub fn tube_uv(&self) -> Vec<Uv> {
        let sides = self.params.sides;
        let mut uv: Vec<Uv> = Vec::with_capacity(self.tube_vertex_count());
        for r in &self.rings {
            uv.extend((0..=sides).map(|k| [k as f32 / sides as f32, r.v]));
        }
        for d in &self.details {
            let (a, b) = (uv[d.a as usize], uv[d.b as usize]);
            uv.push([0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]);
        }
        uv
    }

    /// Leaf texture coordinates, one per leaf vertex: the centre (0.5, 0.5), then the rim of
    /// the leaf's outline (`leaf_rim`), as `mesh_leaves` places them.
    pub fn leaf_uv(&self) -> Vec<Uv> {
        let sides = self.params.leaf_sides;
        // One past the last shape: what an unknown index gets (the default radius).
        let rims: Vec<Vec<Uv>> = (0..=LeafShape::ALL.len() as u32)
            .map(|shape| (0..sides).map(|k| leaf_rim(shape, k, sides).into()).collect())
            .collect();
        let mut uv = Vec::with_capacity(self.leaf_vertex_count());
        for l in &self.leaves {
            uv.push([0.5, 0.5]);
            uv.extend_from_slice(&rims[(l.shape as usize).min(rims.len() - 1)]);
        }
        uv
    }
}
