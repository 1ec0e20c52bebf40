//! CPU twin of `shader/mesh_leaves.wgsl`: one leaf-polygon vertex per work item (Akagi
//! §2.4). See [`crate::mesh`] for the construction.

use crate::mesh::{RawMeshInfo, RawVertex};
use crate::model::{RawLeaf, RawSegment};
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// Writes `vertex[l × (leaf_sides + 1) + k]`: k = 0 the polygon's centre, 1… its rim.
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
    vertex.par_iter_mut().enumerate().for_each(|(vid, out)| {
        let lf = &leaf[vid / stride];
        let k = (vid % stride) as u32;
        let s = lf.segment as usize;
        let d = Quat::from_array(acc[s]);
        let base = Vec3::new(joint[s][0], joint[s][1], joint[s][2])
            + d * (Vec3::from_array(lf.position) - Vec3::from_array(segment[s].start));
        let q = d * Quat::from_array(lf.orientation);
        let mut local = Vec3::new(0.0, 0.5 * lf.length, 0.0);
        if k > 0 {
            // Two half-circles of the unit n-gon, scaled to the blade: base at a = 0, tip
            // at a = π.
            let a = std::f32::consts::TAU * (k - 1) as f32 / info.leaf_sides as f32;
            local = Vec3::new(a.sin() * 0.5 * lf.width, (1.0 - a.cos()) * 0.5 * lf.length, 0.0);
        }
        let p = base + q * local;
        let normal = q * Vec3::Z;
        *out = RawVertex {
            position: p.to_array(),
            u: local.x / lf.width.max(1e-9) + 0.5,
            normal: normal.to_array(),
            v: local.y / lf.length.max(1e-9),
        };
    });
}
