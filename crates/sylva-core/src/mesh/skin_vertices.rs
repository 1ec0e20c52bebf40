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
/// `first_instance + instance`. Bindings as in the kernel: 0 info, 1 rest, 2 skin,
/// 3 rest joints (one instance), 4 joints, 5 rotations (instance-major), 6 out (write).
pub fn skin_vertices(
    info: &RawSkinInfo,
    rest: &[RawVertex],
    skin: &[RawSkin],
    rest_joint: &[[f32; 4]],
    joint: &[[f32; 4]],
    acc: &[[f32; 4]],
    out: &mut [RawVertex],
) {
    let n = info.vertices as usize;
    out.par_iter_mut().enumerate().for_each(|(id, o)| {
        let (inst, v) = (id / n, id % n);
        let base = (info.first_instance as usize + inst) * info.segments as usize;
        let (x, nrm) = (Vec3::from_array(rest[v].position), Vec3::from_array(rest[v].normal));
        let s = skin[v];
        let (j0, d0, r0) = bone(rest_joint, joint, acc, base, s.bone0 as usize);
        let (j1, d1, r1) = bone(rest_joint, joint, acc, base, s.bone1 as usize);
        let w = s.weight;
        let p = (j0 + d0 * (x - r0)) * (1.0 - w) + (j1 + d1 * (x - r1)) * w;
        let normal = ((d0 * nrm) * (1.0 - w) + (d1 * nrm) * w).normalize();
        *o = RawVertex { position: p.to_array(), u: rest[v].u, normal: normal.to_array(), v: rest[v].v };
    });
}
