//! CPU twin of `mesh_leaves.wgsl`: one leaf-polygon vertex per work item (Akagi
//! §2.4). See [`crate::mesh`] for the construction.

use crate::mesh::{RawMeshInfo, RawVertex, Uv};
use crate::model::{RawLeaf, RawSegment};
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// Writes leaf l's polygon `vertex[l × (leaf_sides + 1) ..][..leaf_sides + 1]`: k = 0 the
/// centre, 1… the rim; the leaf's transform once, then the unit polygon scaled to the blade.
/// The leaf turns by its rotation `λ` (`leaf_rotation[index]`, in its segment's rest frame)
/// about its attachment; one missing from the array, or the identity, leaves it at rest.
/// The rim comes from `leaf_rim` ([`super::MeshLayout::leaf_rim_table`]: every shape's
/// `leaf_sides` points, made once; an index past the table takes its last row).
/// Bindings as in the kernel: 0 info, 1 leaf, 2 segment, 3 joint, 4 acc, 5 vertex (write),
/// 6 leaf rotation, 7 leaf rim.
#[allow(clippy::too_many_arguments)]
pub fn mesh_leaves(
    info: &RawMeshInfo,
    leaf: &[RawLeaf],
    segment: &[RawSegment],
    joint: &[[f32; 4]],
    acc: &[[f32; 4]],
    leaf_rotation: &[[f32; 4]],
    leaf_rim: &[Uv],
    vertex: &mut [RawVertex],
) {
    let stride = info.leaf_sides as usize + 1;
    let sides = (info.leaf_sides as usize).max(1);
    let rows = (leaf_rim.len() / sides).max(1);
    vertex.par_chunks_mut(stride).zip(leaf.par_iter()).for_each(|(out, lf)| {
        let s = lf.segment as usize;
        let d = Quat::from_array(acc[s]);
        let base = Vec3::new(joint[s][0], joint[s][1], joint[s][2])
            + d * (Vec3::from_array(lf.position) - Vec3::from_array(segment[s].start));
        let rest = Quat::from_array(lf.orientation);
        let lambda = leaf_rotation.get(lf.index as usize).copied().unwrap_or([0.0, 0.0, 0.0, 1.0]);
        let q = if lambda == [0.0, 0.0, 0.0, 1.0] { d * rest } else { d * (Quat::from_array(lambda) * rest) };
        let (qx, qy) = (q * Vec3::X, q * Vec3::Y);
        let normal = q * Vec3::Z;
        let row = (lf.shape as usize).min(rows - 1) * sides;
        for (k, v) in out.iter_mut().enumerate() {
            // (u, v) on the blade: the centre, then the rim from the base through +u to the
            // tip and back, scaled to width and length.
            let uv = if k > 0 { leaf_rim[row + k - 1] } else { [0.5, 0.5] };
            let p = base + qx * ((uv[0] - 0.5) * lf.width) + qy * (uv[1] * lf.length);
            *v = RawVertex::new(p, normal);
        }
    });
}
