//! The pose seam's leaf rotations from HSM's leaf clusters: where each leaf's blade points
//! relative to its segment ([`hsm_leaf_pose`], the twin of `hsm_leaf_pose.wgsl`).

use super::{RawHsmClusterState, RawHsmLeaf, RawHsmSlot};
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// Leaf rotations from HSM's leaf blades, in their segments' rest frames. In the frame of
/// the leaf's cluster (its rotation `R`; the ring it shares with its segment moved by its
/// particles' mean displacement, the attachment carried with it): the swing taking the
/// blade's rest direction (attachment → tip) onto its direction now, then the twist about it
/// taking the edge point's rest offset onto its offset now (both across the blade); the
/// leaf's rotation is then `D_s⁻¹ R · twist · swing`, so it shows where the blade points,
/// however much of that `R` shares. Exactly the identity where nothing has moved (every
/// displacement zero, `R` and `D_s` the identity), for a leaf without a cluster and at
/// `strength` 0; another strength scales the turn's angle about its axis. Bindings: 0 leaves, 1 slots, 2 displacements, 3 cluster state, 4 acc, 5 leaf rotations
/// (write).
pub fn hsm_leaf_pose(
    leaves: &[RawHsmLeaf],
    slots: &[RawHsmSlot],
    displacement: &[[f32; 4]],
    state: &[RawHsmClusterState],
    acc: &[[f32; 4]],
    out: &mut [[f32; 4]],
) {
    out.par_iter_mut()
        .zip(leaves)
        .with_min_len(256)
        .for_each(|(o, lf)| *o = leaf_turn(lf, slots, displacement, state, acc));
}

/// One leaf of [`hsm_leaf_pose`].
fn leaf_turn(
    lf: &RawHsmLeaf,
    slots: &[RawHsmSlot],
    displacement: &[[f32; 4]],
    state: &[RawHsmClusterState],
    acc: &[[f32; 4]],
) -> [f32; 4] {
    const REST: [f32; 4] = [0.0, 0.0, 0.0, 1.0];
    if lf.ring == 0 || lf.blade == 0 || lf.strength == 0.0 {
        return REST;
    }
    let u = |j: u32| Vec3::from_slice(&displacement[slots[(lf.slot_offset + j) as usize].particle as usize][..3]);
    let (d, r) = (acc[lf.segment as usize], state[lf.cluster as usize].rotation);
    let mut moved = d != REST || r != REST;
    let mut mean = Vec3::ZERO;
    for j in 0..lf.ring {
        let x = u(j);
        moved |= x != Vec3::ZERO;
        mean += x;
    }
    mean *= 1.0 / lf.ring as f32;
    let tip = u(lf.ring);
    let edge = if lf.blade > 1 { u(lf.ring + 1) } else { Vec3::ZERO };
    if !(moved || tip != Vec3::ZERO || edge != Vec3::ZERO) {
        return REST;
    }
    let (r, back) = (Quat::from_array(r), Quat::from_array(r).conjugate());
    let (tip0, edge0, attach) = (Vec3::from_array(lf.tip), Vec3::from_array(lf.edge), Vec3::from_array(lf.attach));
    let a = back * (attach + tip0 + tip - mean) - attach;
    let swing = crate::pose::shortest_arc(unit(tip0), unit(a));
    let turn = if lf.blade < 2 {
        swing
    } else {
        let n = unit(a);
        let e0 = swing * edge0;
        let e = back * (attach + edge0 + edge - mean) - attach;
        crate::pose::shortest_arc(unit(e0 - n * n.dot(e0)), unit(e - n * n.dot(e))) * swing
    };
    let q = (Quat::from_array(d).conjugate() * (r * turn)).normalize();
    if lf.strength == 1.0 {
        return q.to_array();
    }
    // The turn's angle scaled about its axis (atan2: well conditioned at small angles).
    let (axis, sin_half) = (Vec3::new(q.x, q.y, q.z), Vec3::new(q.x, q.y, q.z).length());
    if sin_half == 0.0 {
        return REST;
    }
    let half = sin_half.atan2(q.w) * lf.strength;
    let k = axis * (half.sin() / sin_half);
    [k.x, k.y, k.z, half.cos()]
}

/// `v / |v|`, or zero for a zero vector (WGSL: `unit` in `hsm_leaf_pose.wgsl`).
#[inline]
fn unit(v: Vec3) -> Vec3 {
    let l = v.length();
    if l > 0.0 { v / l } else { Vec3::ZERO }
}
