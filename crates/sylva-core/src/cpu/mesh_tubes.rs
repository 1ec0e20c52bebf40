//! CPU twin of `shader/mesh_tubes.wgsl`: one bark vertex per work item (Akagi §2.2–2.3).
//! See [`crate::mesh`] for the construction.

use crate::mesh::{RawMeshInfo, RawRing, RawVertex, bark_relief, quat_slerp};
use crate::model::{NONE, RawSegment};
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// World orientation of segment `i`: `D · Q_rest`.
#[inline]
fn world_orientation(segment: &[RawSegment], acc: &[[f32; 4]], i: usize) -> Quat {
    Quat::from_array(acc[i]) * Quat::from_array(segment[i].orientation)
}

/// Writes `vertex[r × (sides + 1) + k]`, the k-th vertex of ring r.
/// Bindings as in the kernel: 0 info, 1 ring, 2 segment, 3 joint, 4 acc, 5 vertex (write).
pub fn mesh_tubes(
    info: &RawMeshInfo,
    ring: &[RawRing],
    segment: &[RawSegment],
    joint: &[[f32; 4]],
    acc: &[[f32; 4]],
    vertex: &mut [RawVertex],
) {
    let stride = info.sides as usize + 1;
    vertex.par_iter_mut().enumerate().for_each(|(vid, out)| {
        let rg = ring[vid / stride];
        let k = (vid % stride) as u32;
        let i = rg.segment as usize;
        let seg = &segment[i];
        let q = world_orientation(segment, acc, i);
        let axis = q * Vec3::Y;
        let p0 = Vec3::new(joint[i][0], joint[i][1], joint[i][2]);
        let p1 = p0 + axis * seg.length;
        let (mut f0, mut m0) = (q, axis * seg.length);
        if rg.prev != NONE {
            let qp = world_orientation(segment, acc, rg.prev as usize);
            f0 = quat_slerp(qp, q, 0.5);
            m0 = (qp * Vec3::Y + axis).normalize() * seg.length;
        }
        let (mut f1, mut m1) = (q, axis * seg.length);
        if rg.next != NONE {
            let qn = world_orientation(segment, acc, rg.next as usize);
            f1 = quat_slerp(q, qn, 0.5);
            m1 = (axis + qn * Vec3::Y).normalize() * seg.length;
        }
        let t = rg.t;
        let (t2, t3) = (t * t, t * t * t);
        let centre =
            p0 * (2.0 * t3 - 3.0 * t2 + 1.0) + m0 * (t3 - 2.0 * t2 + t) + p1 * (-2.0 * t3 + 3.0 * t2) + m1 * (t3 - t2);
        let frame = quat_slerp(f0, f1, t);
        let radius = rg.radius;
        let kk = k % info.sides;
        let around = kk as f32 / info.sides as f32;
        let angle = std::f32::consts::TAU * around;
        let radial = frame * Vec3::new(angle.cos(), 0.0, angle.sin());
        let slope = (seg.radius_base - seg.radius_tip) / seg.length.max(1e-6);
        let normal = (radial + frame * Vec3::Y * slope).normalize();
        let relief = rg.relief * radius * bark_relief(around, rg.v, rg.stem_seed);
        let p = centre + radial * radius + normal * relief;
        *out =
            RawVertex { position: p.to_array(), u: k as f32 / info.sides as f32, normal: normal.to_array(), v: rg.v };
    });
}
