//! CPU twin of `skjermo_deform.wgsl`: Skjermo's deformer, one grid ring per work
//! item (see [`crate::mesh::deformer`]).

use crate::mesh::{RawDeformRing, RawDeformShape, RawMeshInfo, RawVertex, deform_radius};
use crate::methods::skjermo::{RawSkjermoState, RawSkjermoStem, bezier_d, unit_or};
use crate::model::NONE;
use glam::Vec3;
use rayon::prelude::*;

#[inline]
fn now(stems: &[RawSkjermoStem], state: &[RawSkjermoState], k: usize) -> [Vec3; 4] {
    [0, 1, 2, 3].map(|j| Vec3::from_slice(&stems[k].rest[j][..3]) + Vec3::from_slice(&state[k].delta[j][..3]))
}

/// Writes ring r's vertices `vertex[r × (sides + 1) ..][..sides + 1]`.
/// Bindings as in the kernel: 0 info, 1 ring, 2 shape, 3 stems, 4 state, 5 vertex (write).
pub fn skjermo_deform(
    info: &RawMeshInfo,
    ring: &[RawDeformRing],
    shape: &[RawDeformShape],
    stems: &[RawSkjermoStem],
    state: &[RawSkjermoState],
    vertex: &mut [RawVertex],
) {
    let stride = info.sides as usize + 1;
    vertex.par_chunks_mut(stride).zip(ring.par_iter()).for_each(|(out, rg)| {
        let k = rg.stem as usize;
        let st = &stems[k];
        let p = now(stems, state, k);
        // O: the parent's tangent at the branching point (eq. 8).
        let o = if st.parent != NONE {
            unit_or(bezier_d(&now(stems, state, st.parent as usize), st.attach), Vec3::X)
        } else {
            Vec3::X
        };
        let l0 = unit_or(p[1] - p[0], unit_or(p[3] - p[0], Vec3::Y));
        let l1 = unit_or(p[2] - p[1], l0);
        let l2 = unit_or(p[3] - p[2], l1);
        let s0 = unit_or(l0.cross(o), unit_or(l0.any_orthogonal_vector(), Vec3::X));
        let t0 = unit_or(s0.cross(l0), Vec3::Z);
        let t1 = unit_or(s0.cross(l1), t0);
        let s1 = unit_or(l1.cross(t1), s0);
        let t2 = unit_or(s1.cross(l2), t1);
        let s2 = unit_or(l2.cross(t2), s1);
        let (s, t) = ([s0, s1, s2], [t0, t1, t2]);
        let u = rg.v;
        let w = [(1.0 - u) * (1.0 - u), 2.0 * u * (1.0 - u), u * u];
        let dw = [-2.0 * (1.0 - u), 2.0 - 4.0 * u, 2.0 * u];
        let d = [p[1] - p[0], p[2] - p[1], p[3] - p[2]];
        let lerp = [0, 1, 2].map(|i| p[i] + d[i] * u);
        let shp = &shape[k];
        for (c, v) in out.iter_mut().enumerate() {
            let theta = std::f32::consts::TAU * ((c % info.sides as usize) as f32 / info.sides as f32);
            let (sin, cos) = theta.sin_cos();
            let (r, r_v, r_t) = deform_radius(shp, u, theta);
            let (fv, fw) = (sin * r, cos * r);
            let (fv_t, fw_t) = (cos * r + sin * r_t, -sin * r + cos * r_t);
            let (fv_u, fw_u) = (sin * r_v, cos * r_v);
            let (mut pos, mut d_theta, mut d_u) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
            for i in 0..3 {
                let q = lerp[i] + s[i] * fv + t[i] * fw;
                pos += q * w[i];
                d_theta += (s[i] * fv_t + t[i] * fw_t) * w[i];
                // Σ dwᵢ = 0, so Σ dwᵢ Qᵢ = Σ dwᵢ (Qᵢ − Q₀): differences at the handles' scale,
                // not of positions metres from the origin.
                let q_rel = (p[i] - p[0]) + (d[i] - d[0]) * u + (s[i] - s0) * fv + (t[i] - t0) * fw;
                d_u += q_rel * dw[i] + (d[i] + s[i] * fv_u + t[i] * fw_u) * w[i];
            }
            // Scale-free: a twig tens of micrometres thick still has a well-defined normal.
            let (a, b) = (d_theta * (1.0 / d_theta.length().max(1e-30)), d_u * (1.0 / d_u.length().max(1e-30)));
            let normal = unit_or(a.cross(b), s0);
            *v = RawVertex::new(pos, normal);
        }
    });
}
