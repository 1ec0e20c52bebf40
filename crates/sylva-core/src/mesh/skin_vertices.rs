//! CPU twin of `skin_vertices.wgsl`: linear blend skinning with two bones, one output
//! vertex per work item, instance-major (Zioma §6.5; see [`crate::mesh::skin`]).

use crate::mesh::{RawSkin, RawSkinInfo, RawVertex};
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// Bone `b` of instance `base / segments` applied to rest point `x`.
#[inline]
fn bone(rest_joint: &[[f32; 4]], joint: &[[f32; 4]], acc: &[[f32; 4]], base: usize, b: usize) -> (Vec3, Quat, Vec3) {
    let j = joint[base + b];
    let r = rest_joint[b];
    (Vec3::new(j[0], j[1], j[2]), Quat::from_array(acc[base + b]), Vec3::new(r[0], r[1], r[2]))
}

/// Writes `out[instance × vertices + v]` for the dispatch's instances, reading pose
/// `first_instance + instance`. A leaf vertex (`RawSkin::leaf` > 0) is first turned about
/// its leaf's attachment by the leaf's rotation (one past the array, or the identity, leaves
/// it as it is). Bindings as in the kernel: 0 info, 1 rest, 2 skin, 3 rest joints (one
/// instance), 4 joints, 5 rotations (instance-major), 6 out (write), 7 leaf attachments,
/// 8 leaf rotations.
#[allow(clippy::too_many_arguments)]
pub fn skin_vertices(
    info: &RawSkinInfo,
    rest: &[RawVertex],
    skin: &[RawSkin],
    rest_joint: &[[f32; 4]],
    joint: &[[f32; 4]],
    acc: &[[f32; 4]],
    out: &mut [RawVertex],
    [leaf_attach, leaf_rotation]: [&[[f32; 4]]; 2],
) {
    let n = info.vertices as usize;
    out.par_iter_mut().enumerate().for_each(|(id, o)| {
        let (inst, v) = (id / n, id % n);
        let base = (info.first_instance as usize + inst) * info.segments as usize;
        let (mut x, mut nrm) = (rest[v].pos(), rest[v].normal());
        let s = skin[v];
        if s.leaf > 0 {
            let l = (s.leaf - 1) as usize;
            if let (Some(&q), Some(&a)) = (leaf_rotation.get(l), leaf_attach.get(l)) {
                if q != [0.0, 0.0, 0.0, 1.0] {
                    let (q, a) = (Quat::from_array(q), Vec3::new(a[0], a[1], a[2]));
                    x = a + q * (x - a);
                    nrm = q * nrm;
                }
            }
        }
        let (j0, d0, r0) = bone(rest_joint, joint, acc, base, s.bone0 as usize);
        let (j1, d1, r1) = bone(rest_joint, joint, acc, base, s.bone1 as usize);
        let w = s.weight;
        let p = (j0 + d0 * (x - r0)) * (1.0 - w) + (j1 + d1 * (x - r1)) * w;
        let normal = ((d0 * nrm) * (1.0 - w) + (d1 * nrm) * w).normalize();
        *o = RawVertex::new(p, normal);
    });
}
