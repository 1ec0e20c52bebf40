//! CPU twin of `mesh_tubes.wgsl`: one bark vertex per work item (Akagi §2.2–2.3).
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

/// Writes ring r's vertices `vertex[r × (sides + 1) ..][..sides + 1]`: the centreline
/// point and frame once per ring, then the unit polygon placed around it.
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
    // The unit polygon (Akagi: a precomputed octagon), one angle per side.
    let unit: Vec<(f32, f32)> = (0..info.sides)
        .map(|k| {
            let angle = std::f32::consts::TAU * (k as f32 / info.sides as f32);
            (angle.cos(), angle.sin())
        })
        .collect();
    vertex.par_chunks_mut(stride).zip(ring.par_iter()).for_each(|(out, rg)| {
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
        let (fx, fy, fz) = (frame * Vec3::X, frame * Vec3::Y, frame * Vec3::Z);
        // The normal leans along the axis by the taper; |radial + fy·slope| is the same for
        // every vertex of the ring.
        let slope = (seg.radius_base - seg.radius_tip) / seg.length.max(1e-6);
        let lean = 1.0 / (1.0 + slope * slope).sqrt();
        for (k, v) in out.iter_mut().enumerate() {
            let kk = k % info.sides as usize;
            let (c, s) = unit[kk];
            let radial = fx * c + fz * s;
            let normal = (radial + fy * slope) * lean;
            let mut p = centre + radial * radius;
            if rg.relief != 0.0 {
                let around = kk as f32 / info.sides as f32;
                p += normal * (rg.relief * radius * bark_relief(around, rg.v, rg.stem_seed));
            }
            *v = RawVertex::new(p, normal);
        }
    });
}
