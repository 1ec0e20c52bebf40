//! CPU twin of `mesh_detail.wgsl`: one midpoint vertex of a subdivided band per work
//! item (Akagi §2.3). See [`crate::mesh`] for the construction.

use super::uv::ring_uv;
use crate::mesh::{RawDetail, RawMeshInfo, RawRing, RawVertex, bark_relief};
use rayon::prelude::*;

/// Writes detail d's vertex `vertex[rings × (sides + 1) + d]` from the two ring vertices of
/// its edge (written by `mesh_tubes` first): the edge's midpoint, the mean normal, and the
/// relief sampled at the midpoint less the mean of what the ends carry.
/// Bindings as in the kernel: 0 info, 1 detail, 2 vertex (read ring vertices, write details),
/// 3 ring.
pub fn mesh_detail(info: &RawMeshInfo, detail: &[RawDetail], vertex: &mut [RawVertex], ring: &[RawRing]) {
    let (ring_vertices, out) = vertex.split_at_mut((info.rings * (info.sides + 1)) as usize);
    out.par_iter_mut().zip(detail.par_iter()).for_each(|(v, d)| {
        let (a, b) = (&ring_vertices[d.a as usize], &ring_vertices[d.b as usize]);
        let normal = (a.normal() + b.normal()).normalize();
        let mut p = (a.pos() + b.pos()) * 0.5;
        if d.scale != 0.0 {
            let (ua, ub) = (ring_uv(info, ring, d.a), ring_uv(info, ring, d.b));
            let (u, vv) = (0.5 * (ua[0] + ub[0]), 0.5 * (ua[1] + ub[1]));
            let ends = 0.5 * (bark_relief(ua[0], ua[1], d.stem_seed) + bark_relief(ub[0], ub[1], d.stem_seed));
            p += normal * (d.scale * (bark_relief(u, vv, d.stem_seed) - ends));
        }
        *v = RawVertex::new(p, normal);
    });
}
