//! CPU twins of `leaf_wind.wgsl` (the wind at every twig) and `leaf_flutter.wgsl` (every
//! leaf's rotation): the same bindings, operations and order.

use super::{RawLeafFrame, RawLeafMotion};
use crate::physics::AIR_DENSITY;
use crate::wind::noise::hash_unit;
use crate::wind::raw::{RawField, RawWave};
use crate::wind::sample::{smoothstep, wind_at};
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// The wind at each twig's sample joint and what follows from its speed alone, two entries
/// per twig: (wind xyz at the twig, m/s; the reconfigured dynamic pressure in the crown
/// `q g(u)`, Pa) and (flutter amplitude, rad; dynamic pressure at the twig, Pa; 0; 0).
/// Bindings: 0 fields, 1 waves, 2 frame, 3 twigs (segment indices), 4 joints, 5 twig wind
/// (write).
pub fn leaf_wind(
    fields: &[RawField],
    waves: &[RawWave],
    frame: &RawLeafFrame,
    twigs: &[u32],
    joint: &[[f32; 4]],
    out: &mut [[f32; 4]],
) {
    out.par_chunks_mut(2).zip(twigs.par_iter()).with_min_len(64).for_each(|(o, &s)| {
        let j = joint[s as usize];
        let u = wind_at(fields, waves, Vec3::new(j[0], j[1], j[2]), frame.time);
        let speed = u.length() * frame.crown_wind;
        let q = 0.5 * AIR_DENSITY * speed * speed;
        let r = speed / frame.reconfiguration_speed;
        let g = (1.0 + r * r).powf(0.5 * frame.vogel_exponent);
        let onset = frame.flutter_onset * frame.flutter_onset;
        let amp = frame.flutter * speed * speed / (speed * speed + onset);
        o[0] = [u.x, u.y, u.z, q * g];
        o[1] = [amp, 0.5 * AIR_DENSITY * u.length_squared(), 0.0, 0.0];
    });
}

/// Unit-RMS narrow-band flutter at `omega` (rad/s) with damping ratio `zeta`: three sines
/// over the half-power band `ω (1 ± ζ)`, phases from `seed`. Twin of `leaf_band`.
#[inline]
pub fn leaf_band(omega: f32, zeta: f32, t: f32, seed: u32) -> f32 {
    let mut sum = 0.0f32;
    for j in 0..3u32 {
        let w = omega * (1.0 + zeta * (j as f32 - 1.0));
        let phase = hash_unit(seed.wrapping_add(j)) * std::f32::consts::TAU;
        sum += (w * t + phase).sin();
    }
    sum * 0.816_496_6
}

/// One leaf's rotation `λ` in its segment's rest frame from its twig's two entries of
/// [`leaf_wind`] and its segment's accumulated rotation `d` (see [`crate::leaves`]). Twin of
/// `leaf_rotation` in `leaves.wgsl`.
#[inline]
pub fn leaf_rotation(frame: &RawLeafFrame, m: &RawLeafMotion, twig: [[f32; 4]; 2], d: Quat, t: f32) -> Quat {
    let [w, s2] = twig;
    let u = d.conjugate() * Vec3::new(w[0], w[1], w[2]);
    let speed = u.length();
    if frame.strength == 0.0 || speed == 0.0 || frame.crown_wind == 0.0 {
        return Quat::IDENTITY;
    }
    let (amp, q_twig) = (s2[0], s2[1]);
    let k = m.compliance * w[3];
    let s = k / (1.0 + k);
    let o = Quat::from_array(m.orientation);
    let b = o * Vec3::Y;
    let c = b.cross(u);
    let cl = c.length();
    let phi = cl.atan2(b.dot(u));
    let axis = if cl > 1e-6 * speed { c / cl } else { o * Vec3::X };
    let omega = m.omega * (1.0 - frame.zeta * frame.zeta).sqrt();
    let omega_twist = m.omega_twist * (1.0 - frame.zeta * frame.zeta).sqrt();
    let pitch = frame.strength * (phi * s + amp * leaf_band(omega, frame.zeta, t, m.seed));
    let tumble = std::f32::consts::FRAC_PI_4 * smoothstep(0.8, 1.25, q_twig / m.flip_pressure);
    let twist = frame.strength * ((amp + tumble) * leaf_band(omega_twist, frame.zeta, t, m.seed.wrapping_add(3)));
    let (sp, cp) = (0.5 * pitch).sin_cos();
    let (st, ct) = (0.5 * twist).sin_cos();
    let swing = Quat::from_xyzw(axis.x * sp, axis.y * sp, axis.z * sp, cp);
    let turn = Quat::from_xyzw(b.x * st, b.y * st, b.z * st, ct);
    swing * turn
}

/// Every leaf's rotation. Bindings: 0 frame, 1 leaf constants, 2 twig wind (two entries per
/// twig, [`leaf_wind`]), 3 acc, 4 leaf rotations (write).
pub fn leaf_flutter(
    frame: &RawLeafFrame,
    leaf: &[RawLeafMotion],
    twig_wind: &[[f32; 4]],
    acc: &[[f32; 4]],
    out: &mut [[f32; 4]],
) {
    out.par_iter_mut().zip(leaf.par_iter()).with_min_len(256).for_each(|(o, m)| {
        let i = 2 * m.twig as usize;
        let d = Quat::from_array(acc[m.segment as usize]);
        *o = leaf_rotation(frame, m, [twig_wind[i], twig_wind[i + 1]], d, frame.time).to_array();
    });
}
