//! Forward kinematics (see [`crate::pose`]). The CPU runs [`pose_forward`] and
//! [`positions_forward`]: one pass in topological order, linear in the segment count at any
//! depth. The GPU kernels' twins: `pose_accumulate.wgsl` and `pose_positions.wgsl` (every
//! segment walks its own ancestor chain, in parallel, as a GPU invocation does) and
//! `pose_level.wgsl`'s [`pose_level`] (one dispatch per depth), and for deep hierarchies
//! pointer jumping ([`pose_jump`]: `pose_jump_*.wgsl`, ⌈log₂(depth + 1)⌉ dispatches for the
//! rotations and as many for the joints).

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
    let one = |acc: &mut [[f32; 4]], joints: &mut [[f32; 4]], delta: &[[f32; 4]]| {
        let mut disp = vec![[0.0f32; 4]; n];
        pose_level(&order, parent, rest, delta, acc, &mut disp, joints);
    };
    // One instance (every CPU method's step) runs here, without a hand-off to the pool.
    if acc.len() == n {
        return one(acc, joints, delta);
    }
    acc.par_chunks_mut(n).zip(joints.par_chunks_mut(n)).zip(delta.par_chunks(n)).for_each(|((a, j), d)| one(a, j, d));
}

/// Joint positions from accumulated rotations `D` in one pass in topological order (as
/// [`pose_forward`]; the same numbers as [`pose_positions`] up to the order of the sum):
/// `disp_i = disp_parent + (D_parent · o_i − o_i)`. Instance-major, instances in parallel.
pub fn positions_forward(parent: &[u32], rest: &[[f32; 4]], acc: &[[f32; 4]], joints: &mut [[f32; 4]]) {
    let n = parent.len();
    if n == 0 {
        return;
    }
    let one = |(joints, acc): (&mut [[f32; 4]], &[[f32; 4]])| {
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
    };
    if joints.len() == n {
        return one((joints, acc));
    }
    joints.par_chunks_mut(n).zip(acc.par_chunks(n)).for_each(one);
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

/// The ancestors pointer jumping reads, one list per round: round 0 reads the parents, round
/// `k + 1` reads `anc_k[anc_k[i]]` (the ancestor 2^(k+1) levels up), and the rounds stop when
/// every entry is [`NONE`]: ⌈log₂(depth + 1)⌉ rounds for a hierarchy `depth` levels deep.
/// They depend on the hierarchy alone, so they are made once, beside the tree.
pub fn jump_ancestors(parent: &[u32]) -> Vec<Vec<u32>> {
    let mut rounds = Vec::new();
    let mut anc = parent.to_vec();
    while anc.iter().any(|&a| a != NONE) {
        let next = anc.iter().map(|&a| if a == NONE { NONE } else { anc[a as usize] }).collect();
        rounds.push(std::mem::replace(&mut anc, next));
    }
    rounds
}

/// One round of pointer jumping over rotations: `out[i] = in[anc[i]] · in[i]` (or `in[i]`
/// where `anc[i]` is [`NONE`]). Starting from δ, after every round of [`jump_ancestors`]
/// `out = acc` (as [`pose_accumulate`], multiplied in a tree of pairs rather than a chain).
/// Bindings: 0 anc, 1 in, 2 out; instance-major `in`/`out` (`anc` holds one instance).
pub fn pose_jump_rotations(anc: &[u32], input: &[[f32; 4]], out: &mut [[f32; 4]]) {
    let n = anc.len();
    out.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, o)| {
        let base = i / n * n;
        let a = anc[i - base];
        *o = if a == NONE {
            input[i]
        } else {
            (Quat::from_array(input[base + a as usize]) * Quat::from_array(input[i])).to_array()
        };
    });
}

/// The displacement each segment adds to its subtree's joints: `out[i] = D_parent · o_i − o_i`,
/// `o_i = rest_i − rest_parent`, zero at a root (the terms [`pose_positions`] sums).
/// Bindings: 0 parents, 1 rest, 2 acc, 3 out; instance-major `acc`/`out`.
pub fn pose_jump_terms(parent: &[u32], rest: &[[f32; 4]], acc: &[[f32; 4]], out: &mut [[f32; 4]]) {
    let n = parent.len();
    out.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, o)| {
        let base = i / n * n;
        let l = i - base;
        let p = parent[l];
        *o = if p == NONE {
            [0.0; 4]
        } else {
            let off = v3(rest[l]) - v3(rest[p as usize]);
            (Quat::from_array(acc[base + p as usize]) * off - off).extend(0.0).to_array()
        };
    });
}

/// One round of pointer jumping over displacements: `out[i] = in[anc[i]] + in[i]` (or
/// `in[i]` at [`NONE`]). Bindings: 0 anc, 1 in, 2 out; instance-major `in`/`out`.
pub fn pose_jump_sums(anc: &[u32], input: &[[f32; 4]], out: &mut [[f32; 4]]) {
    let n = anc.len();
    out.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, o)| {
        let base = i / n * n;
        let a = anc[i - base];
        *o = if a == NONE { input[i] } else { (v3(input[base + a as usize]) + v3(input[i])).extend(0.0).to_array() };
    });
}

/// Joints from summed displacements: `joints[i] = rest[i] + disp[i]`, so identity rotations
/// give the rest pose exactly. Bindings: 0 rest, 1 disp, 2 joints; instance-major
/// `disp`/`joints`.
pub fn pose_jump_joints(rest: &[[f32; 4]], disp: &[[f32; 4]], joints: &mut [[f32; 4]]) {
    let n = rest.len();
    joints.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, o)| {
        *o = (v3(rest[i % n]) + v3(disp[i])).extend(0.0).to_array();
    });
}

/// Forward kinematics by pointer jumping, as the GPU runs it for deep hierarchies
/// (`sylva_gpu::pose::FkStrategy::PointerJump`): ⌈log₂(depth + 1)⌉ rounds of [`pose_jump_rotations`], [`pose_jump_terms`], as
/// many rounds of [`pose_jump_sums`], then [`pose_jump_joints`]. Work n·log depth in
/// 2⌈log₂(depth + 1)⌉ + 2 passes, where ancestor walks do n·depth and level by level makes
/// `depth` passes. `rounds` from [`jump_ancestors`]; instance-major `delta`, `acc`, `joints`.
pub fn pose_jump(
    rounds: &[Vec<u32>],
    parent: &[u32],
    rest: &[[f32; 4]],
    delta: &[[f32; 4]],
    acc: &mut [[f32; 4]],
    joints: &mut [[f32; 4]],
) {
    let mut a = delta.to_vec();
    let mut b = vec![[0.0f32; 4]; delta.len()];
    for anc in rounds {
        pose_jump_rotations(anc, &a, &mut b);
        std::mem::swap(&mut a, &mut b);
    }
    acc.copy_from_slice(&a);
    pose_jump_terms(parent, rest, acc, &mut a);
    for anc in rounds {
        pose_jump_sums(anc, &a, &mut b);
        std::mem::swap(&mut a, &mut b);
    }
    pose_jump_joints(rest, &a, joints);
}
