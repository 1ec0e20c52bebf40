//! CPU twin of `mesh_leaves.wgsl`: one leaf-polygon vertex per work item (Akagi
//! §2.4). See [`crate::mesh`] for the construction.

use crate::mesh::{RawMeshInfo, RawVertex};
use crate::model::{RawLeaf, RawSegment};
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// Writes leaf l's polygon `vertex[l × (leaf_sides + 1) ..][..leaf_sides + 1]`: k = 0 the
/// centre, 1… the rim; the leaf's transform once, then the unit polygon scaled to the blade.
/// Bindings as in the kernel: 0 info, 1 leaf, 2 segment, 3 joint, 4 acc, 5 vertex (write).
pub fn mesh_leaves(
    info: &RawMeshInfo,
    leaf: &[RawLeaf],
    segment: &[RawSegment],
    joint: &[[f32; 4]],
    acc: &[[f32; 4]],
    vertex: &mut [RawVertex],
) {
    let stride = info.leaf_sides as usize + 1;
    let unit: Vec<(f32, f32)> = (0..info.leaf_sides)
        .map(|k| {
            let a = std::f32::consts::TAU * k as f32 / info.leaf_sides as f32;
            (a.sin(), a.cos())
        })
        .collect();
    vertex.par_chunks_mut(stride).zip(leaf.par_iter()).for_each(|(out, lf)| {
        let s = lf.segment as usize;
        let d = Quat::from_array(acc[s]);
        let base = Vec3::new(joint[s][0], joint[s][1], joint[s][2])
            + d * (Vec3::from_array(lf.position) - Vec3::from_array(segment[s].start));
        let q = d * Quat::from_array(lf.orientation);
        let (qx, qy) = (q * Vec3::X, q * Vec3::Y);
        let normal = (q * Vec3::Z).to_array();
        for (k, v) in out.iter_mut().enumerate() {
            // (u, v) on the blade: the centre, then two half-circles of the unit n-gon from
            // the base (a = 0) to the tip (a = π), scaled to width and length.
            let mut uv = (0.5, 0.5);
            if k > 0 {
                let (sin, cos) = unit[k - 1];
                uv = (0.5 * sin + 0.5, 0.5 - 0.5 * cos);
            }
            let p = base + qx * ((uv.0 - 0.5) * lf.width) + qy * (uv.1 * lf.length);
            *v = RawVertex { position: p.to_array(), u: uv.0, normal, v: uv.1 };
        }
    });
}
