//! CPU twins of `skjermo_step.wgsl`, `skjermo_rotations.wgsl` and
//! `skjermo_rest_orient.wgsl` (see [`crate::methods::skjermo`]).

use crate::methods::skjermo::{
    RawSkjermoMode, RawSkjermoState, RawSkjermoStem, RawSkjermoStep, RawSkjermoSway, bezier, bezier_d, frame,
    transported_frame,
};
use crate::model::NONE;
use crate::physics::oscillator::{damped_apply, damped_coefficients};
use crate::wind::raw::{RawField, RawWave};
use crate::wind::sample::wind_at;
use glam::{Quat, Vec3};
use rayon::prelude::*;

#[inline]
fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// One step for every stem, reading the previous state (`prev`) and writing `next`; each
/// stem's bend oscillator (`sway`) is updated in place.
/// Bindings: 0 fields, 1 waves, 2 stems, 3 previous state, 4 step, 5 next state, 6 modes,
/// 7 sway.
#[allow(clippy::too_many_arguments)]
pub fn skjermo_step(
    fields: &[RawField],
    waves: &[RawWave],
    stems: &[RawSkjermoStem],
    prev: &[RawSkjermoState],
    step: RawSkjermoStep,
    next: &mut [RawSkjermoState],
    modes: &[RawSkjermoMode],
    sway: &mut [RawSkjermoSway],
) {
    next.par_iter_mut().zip(sway.par_iter_mut()).enumerate().for_each(|(k, (out, sw))| {
        let st = &stems[k];
        let rest = st.rest.map(v3);
        let (shift, f_now, f_rest) = if st.parent == NONE {
            let f = frame(&rest, Vec3::X, 0.0);
            (Vec3::ZERO, f, f)
        } else {
            let p = st.parent as usize;
            let prest = stems[p].rest.map(v3);
            let pnow = [0, 1, 2, 3].map(|j| prest[j] + v3(prev[p].delta[j]));
            let shift = bezier(&pnow, st.attach) - bezier(&prest, st.attach);
            let f_rest = frame(&prest, v3(st.parent_orient), st.attach);
            (shift, transported_frame(&f_rest, bezier_d(&pnow, st.attach)), f_rest)
        };
        // Unbent control points re-attached, as displacements from rest.
        let mut d = [shift; 4];
        for (dj, lj) in d.iter_mut().zip(&st.local) {
            let l = v3(*lj);
            let now = f_now[0] * l.x + f_now[1] * l.y + f_now[2] * l.z;
            let was = f_rest[0] * l.x + f_rest[1] * l.y + f_rest[2] * l.z;
            *dj = shift + (now - was);
        }
        // Wind at the tip and the static push b₃ = c ŵ (eq. 16), with reconfiguration ...
        let a = [0, 1, 2, 3].map(|j| rest[j] + d[j]);
        let w = wind_at(fields, waves, a[3], step.time);
        let u = w.length();
        let r = u / step.reconfiguration_speed;
        let g = (1.0 + r * r).powf(0.5 * step.vogel_exponent);
        let theta = (st.drag * u * u * g).min(step.max_bend);
        let c = st.length * theta;
        let push = if u > 0.0 && c > 0.0 { w * (c / u) } else { Vec3::ZERO };
        // ... which the bend follows as the stem's damped first mode (or at once).
        let b3 = if step.dynamics != 0 {
            let m = modes[k];
            let cs = damped_coefficients(m.w2, m.damping, step.dt);
            let (x, v) = damped_apply(v3(sw.bend), v3(sw.rate), push, m.w2, m.damping, cs);
            let v = v * (1.0 / (1.0 + m.aero * u * g * step.dt));
            sw.bend = x.extend(0.0).to_array();
            sw.rate = v.extend(0.0).to_array();
            x
        } else {
            push
        };
        // The length-keeping update (eq. 17).
        let (mut c2, mut c3) = (Vec3::ZERO, Vec3::ZERO);
        if b3.length_squared() > 0.0 {
            let b2 = b3 * step.p2_weight.powf(step.exponent);
            let d2 = a[2] - a[1];
            c2 = (d2 + b2).normalize_or_zero() * d2.length() - d2;
            let p2 = a[2] + c2;
            let d3 = a[3] - a[2];
            let p3 = p2 + (d3 + b3).normalize_or_zero() * d3.length();
            c3 = p3 - (a[3] + c2);
        }
        d[2] += c2;
        d[3] += c2 + c3;
        out.delta = d.map(|v| v.extend(0.0).to_array());
    });
}

/// One level of the rest orientation vectors: each stem's is the normal of its rest
/// attachment frame on its parent's rest curve, turned by the parent's orientation in
/// `orient_in` (a trunk's from +X at its base). Applied once per stem depth, starting from
/// anything, it gives [`crate::methods::skjermo::Skjermo::rest_orient`]; the GPU runs its
/// twin so that its rest orientations are rounded as its own steps round them, and a step in
/// still air keeps the rest exactly. Bindings: 0 stems, 1 orientations in, 2 out.
pub fn skjermo_rest_orient(stems: &[RawSkjermoStem], orient_in: &[[f32; 4]], orient_out: &mut [[f32; 4]]) {
    orient_out.par_iter_mut().enumerate().for_each(|(k, out)| {
        let st = &stems[k];
        let f = if st.parent == NONE {
            frame(&st.rest.map(v3), Vec3::X, 0.0)
        } else {
            let p = st.parent as usize;
            frame(&stems[p].rest.map(v3), v3(orient_in[p]), st.attach)
        };
        *out = f[1].extend(0.0).to_array();
    });
}

/// Depth of the deepest stem (0 for a trunk alone): how many times
/// [`skjermo_rest_orient`] must run, less one. Stems are in topological order.
pub fn stem_depth(stems: &[RawSkjermoStem]) -> usize {
    let mut depth = vec![0usize; stems.len()];
    for (k, st) in stems.iter().enumerate() {
        if st.parent != NONE {
            depth[k] = depth[st.parent as usize] + 1;
        }
    }
    depth.into_iter().max().unwrap_or(0)
}

/// Absolute rotation of a segment: its stem's rest tangent at the segment's middle turned
/// onto the current tangent.
fn segment_rotation(param: [f32; 4], stems: &[RawSkjermoStem], state: &[RawSkjermoState]) -> Quat {
    let k = param[0].to_bits() as usize;
    let rest = stems[k].rest.map(v3);
    let now = [0, 1, 2, 3].map(|j| rest[j] + v3(state[k].delta[j]));
    let a = bezier_d(&rest, param[1]).normalize_or_zero();
    let b = bezier_d(&now, param[1]).normalize_or_zero();
    shortest_arc(a, b)
}

pub use crate::pose::shortest_arc;

/// Per-segment seam rotations δᵢ = R_parent⁻¹ Rᵢ, so that the seam's accumulated rotation of
/// every segment is its own Rᵢ. Bindings: 0 segment params, 1 stems, 2 state, 3 parents,
/// 4 δ.
pub fn skjermo_rotations(
    params: &[[f32; 4]],
    stems: &[RawSkjermoStem],
    state: &[RawSkjermoState],
    parents: &[u32],
    out: &mut [[f32; 4]],
) {
    out.par_iter_mut().enumerate().for_each(|(i, o)| {
        let r = segment_rotation(params[i], stems, state);
        let p = parents[i];
        let d = if p == NONE { r } else { segment_rotation(params[p as usize], stems, state).inverse() * r };
        *o = d.to_array();
    });
}
