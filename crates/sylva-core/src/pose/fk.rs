//! Forward kinematics (see [`crate::pose`]). The CPU runs [`pose_forward`] and
//! [`positions_forward`]: one pass in topological order, linear in the segment count at any
//! depth. The GPU kernels' twins: `pose_accumulate.wgsl` and `pose_positions.wgsl` (every
//! segment walks its own ancestor chain, in parallel, as a GPU invocation does) and
//! `pose_level.wgsl`'s [`pose_level`] (one dispatch per depth).

use crate::model::NONE;
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// `acc[i] = δ_root · … · δ_parent · δ_i`. Bindings: 0 = parents, 1 = δ, 2 = acc. With
/// instances, δ and acc hold instance-major copies (`instance × segments + segment`).
pub fn pose_accumulate(parent: &[u32], delta: &[[f32; 4]], acc: &mut [[f32; 4]]) {
    let n = parent.len();
    acc.par_iter_mut().enumerate().with_min_len(64).for_each(|(i, out)| {
        let base = i / n * n;
        let mut d = Quat::from_array(delta[i]);
        let mut a = parent[i - base];
        while a != NONE {
            d = Quat::from_array(delta[base + a as usize]) * d;
            a = parent[a as usize];
        }
        *out = d.to_array();
    });
}

/// `p_i = rest_i + Σ over the chain (D_parent(a) · o_a − o_a)`, `o_a = rest_a − rest_parent(a)`.
/// Bindings: 0 = parents, 1 = rest joints, 2 = acc (from [`pose_accumulate`]), 3 = joints
/// (instance-major with instances, as acc).
pub fn pose_positions(parent: &[u32], rest: &[[f32; 4]], acc: &[[f32; 4]], out: &mut [[f32; 4]]) {
    let n = parent.len();
    out.par_iter_mut().enumerate().with_min_len(64).for_each(|(i, o)| {
        let v3 = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
        let base = i / n * n;
        let l = i - base;
        let mut disp = Vec3::ZERO;
        let mut a = l as u32;
        let mut p = parent[l];
        while p != NONE {
            let off = v3(rest[a as usize]) - v3(rest[p as usize]);
            disp += Quat::from_array(acc[base + p as usize]) * off - off;
            a = p;
            p = parent[p as usize];
        }
        let r = v3(rest[l]) + disp;
        *o = [r.x, r.y, r.z, 0.0];
    });
}

/// One depth of forward kinematics, root first: for each `i` in `bucket` (all of one depth),
/// `acc[i] = acc[parent] · δ_i`, `disp[i] = disp[parent] + (acc[parent] · o_i − o_i)`,
/// `joints[i] = rest[i] + disp[i]`. Bindings: 0 bucket, 1 parents, 2 rest, 3 δ, 4 acc,
/// 5 disp, 6 joints. The entries of a bucket are independent; run sequentially here.
pub fn pose_level(
    bucket: &[u32],
    parent: &[u32],
    rest: &[[f32; 4]],
    delta: &[[f32; 4]],
    acc: &mut [[f32; 4]],
    disp: &mut [[f32; 4]],
    joints: &mut [[f32; 4]],
) {
    let v3 = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
    for &i in bucket {
        if i == u32::MAX {
            continue;
        }
        let i = i as usize;
        let p = parent[i];
        let mut d = Vec3::ZERO;
        if p == NONE {
            acc[i] = delta[i];
        } else {
            let p = p as usize;
            let ap = Quat::from_array(acc[p]);
            acc[i] = (ap * Quat::from_array(delta[i])).to_array();
            let off = v3(rest[i]) - v3(rest[p]);
            d = v3(disp[p]) + (ap * off - off);
        }
        disp[i] = d.extend(0.0).to_array();
        joints[i] = (v3(rest[i]) + d).extend(0.0).to_array();
    }
}

/// Forward kinematics in one pass in topological order (every parent before its
/// children, as a [`crate::model::Tree`] stores its segments): linear in the segment count
/// whatever the depth, where the ancestor walks cost segments × depth. The same numbers as
/// [`pose_level`] over the depth buckets, bit for bit. Instance-major buffers (`instance ×
/// segments + segment`); instances run in parallel. What the CPU methods and the pose seam
/// use; the ancestor walks stay as the twins of the GPU kernels.
pub fn pose_forward(
    parent: &[u32],
    rest: &[[f32; 4]],
    delta: &[[f32; 4]],
    acc: &mut [[f32; 4]],
    joints: &mut [[f32; 4]],
) {
    let n = parent.len();
    if n == 0 {
        return;
    }
    // Every segment in index order is a single bucket that respects parents first.
    let order: Vec<u32> = (0..n as u32).collect();
    acc.par_chunks_mut(n).zip(joints.par_chunks_mut(n)).zip(delta.par_chunks(n)).for_each(|((acc, joints), delta)| {
        let mut disp = vec![[0.0f32; 4]; n];
        pose_level(&order, parent, rest, delta, acc, &mut disp, joints);
    });
}

/// Joint positions from accumulated rotations `D` in one pass in topological order (as
/// [`pose_forward`]; the same numbers as [`pose_positions`] up to the order of the sum):
/// `disp_i = disp_parent + (D_parent · o_i − o_i)`. Instance-major, instances in parallel.
pub fn positions_forward(parent: &[u32], rest: &[[f32; 4]], acc: &[[f32; 4]], joints: &mut [[f32; 4]]) {
    let n = parent.len();
    if n == 0 {
        return;
    }
    joints.par_chunks_mut(n).zip(acc.par_chunks(n)).for_each(|(joints, acc)| {
        let mut disp = vec![Vec3::ZERO; n];
        for i in 0..n {
            let p = parent[i];
            if p != NONE {
                let p = p as usize;
                let off = v3(rest[i]) - v3(rest[p]);
                disp[i] = disp[p] + (Quat::from_array(acc[p]) * off - off);
            }
            joints[i] = (v3(rest[i]) + disp[i]).extend(0.0).to_array();
        }
    });
}

fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// Segments grouped by depth, root first (the buckets of [`pose_level`]).
pub fn depth_buckets(parent: &[u32]) -> Vec<Vec<u32>> {
    let mut depth = vec![0usize; parent.len()];
    let mut buckets: Vec<Vec<u32>> = Vec::new();
    for i in 0..parent.len() {
        if parent[i] != NONE {
            depth[i] = depth[parent[i] as usize] + 1;
        }
        if buckets.len() <= depth[i] {
            buckets.resize(depth[i] + 1, Vec::new());
        }
        buckets[depth[i]].push(i as u32);
    }
    buckets
}
