//! CPU twins of `shader/pose_accumulate.wgsl` and `shader/pose_positions.wgsl`: forward
//! kinematics by ancestor walks (see [`crate::animate`]). Every segment walks its own chain,
//! in parallel, exactly as a GPU invocation does.

use crate::model::NONE;
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// `acc[i] = δ_root · … · δ_parent · δ_i`. Bindings: 0 = parents, 1 = δ, 2 = acc.
pub fn pose_accumulate(parent: &[u32], delta: &[[f32; 4]], acc: &mut [[f32; 4]]) {
    acc.par_iter_mut().enumerate().for_each(|(i, out)| {
        let mut d = Quat::from_array(delta[i]);
        let mut a = parent[i];
        while a != NONE {
            d = Quat::from_array(delta[a as usize]) * d;
            a = parent[a as usize];
        }
        *out = d.to_array();
    });
}

/// `p_i = rest_i + Σ over the chain (D_parent(a) · o_a − o_a)`, `o_a = rest_a − rest_parent(a)`.
/// Bindings: 0 = parents, 1 = rest joints, 2 = acc (from [`pose_accumulate`]), 3 = joints.
pub fn pose_positions(parent: &[u32], rest: &[[f32; 4]], acc: &[[f32; 4]], out: &mut [[f32; 4]]) {
    out.par_iter_mut().enumerate().for_each(|(i, o)| {
        let v3 = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
        let mut disp = Vec3::ZERO;
        let mut a = i as u32;
        let mut p = parent[i];
        while p != NONE {
            let off = v3(rest[a as usize]) - v3(rest[p as usize]);
            disp += Quat::from_array(acc[p as usize]) * off - off;
            a = p;
            p = parent[p as usize];
        }
        let r = v3(rest[i]) + disp;
        *o = [r.x, r.y, r.z, 0.0];
    });
}
