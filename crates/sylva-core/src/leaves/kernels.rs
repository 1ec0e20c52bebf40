//! CPU twins of `leaf_wind.wgsl` (the wind at every twig) and `leaf_flutter.wgsl` (every
//! leaf's rotation): the same bindings, operations and order.

use super::{RawLeafFrame, RawLeafMotion};
use crate::physics::AIR_DENSITY;
use crate::wind::noise::hash_unit;
use crate::wind::raw::{RawField, RawWave};
use crate::wind::sample::{smoothstep, wind_at};
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// The wind at each twig's sample joint. Bindings: 0 fields, 1 waves, 2 frame, 3 twigs
/// (segment indices), 4 joints, 5 twig wind (write).
pub fn leaf_wind(
    fields: &[RawField],
    waves: &[RawWave],
    frame: &RawLeafFrame,
    twigs: &[u32],
    joint: &[[f32; 4]],
    out: &mut [[f32; 4]],
) {
    out.par_iter_mut().zip(twigs.par_iter()).with_min_len(64).for_each(|(o, &s)| {
        let j = joint[s as usize];
        *o = wind_at(fields, waves, Vec3::new(j[0], j[1], j[2]), frame.time).extend(0.0).to_array();
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

/// One leaf's rotation `λ` in its segment's rest frame from the wind `u` at its twig (world
/// frame) and its segment's accumulated rotation `d` (see [`crate::leaves`]). Twin of
/// `leaf_rotation` in `leaf_flutter.wgsl`.
#[inline]
pub fn leaf_rotation(frame: &RawLeafFrame, m: &RawLeafMotion, u_world: Vec3, d: Quat, t: f32) -> Quat {
    let twig = d.conjugate() * u_world;
    let u = twig * frame.crown_wind;
    let speed = u.length();
    if frame.strength == 0.0 || speed == 0.0 {
        return Quat::IDENTITY;
    }
    let q = 0.5 * AIR_DENSITY * speed * speed;
    let q_twig = 0.5 * AIR_DENSITY * twig.length_squared();
    let r = speed / frame.reconfiguration_speed;
    let g = (1.0 + r * r).powf(0.5 * frame.vogel_exponent);
    let k = m.compliance * q * g;
    let s = k / (1.0 + k);
    let o = Quat::from_array(m.orientation);
    let b = o * Vec3::Y;
    let c = b.cross(u);
    let cl = c.length();
    let phi = cl.atan2(b.dot(u));
    let axis = if cl > 1e-6 * speed { c / cl } else { o * Vec3::X };
    let omega = m.omega * (1.0 - frame.zeta * frame.zeta).sqrt();
    let omega_twist = m.omega_twist * (1.0 - frame.zeta * frame.zeta).sqrt();
    let onset = frame.flutter_onset * frame.flutter_onset;
    let amp = frame.flutter * speed * speed / (speed * speed + onset);
    let pitch = frame.strength * (phi * s + amp * leaf_band(omega, frame.zeta, t, m.seed));
    let tumble = std::f32::consts::FRAC_PI_4 * smoothstep(0.8, 1.25, q_twig / m.flip_pressure);
    let twist = frame.strength * ((amp + tumble) * leaf_band(omega_twist, frame.zeta, t, m.seed.wrapping_add(3)));
    let hp = 0.5 * pitch;
    let ht = 0.5 * twist;
    let swing = Quat::from_xyzw(axis.x * hp.sin(), axis.y * hp.sin(), axis.z * hp.sin(), hp.cos());
    let turn = Quat::from_xyzw(b.x * ht.sin(), b.y * ht.sin(), b.z * ht.sin(), ht.cos());
    swing * turn
}

/// Every leaf's rotation. Bindings: 0 frame, 1 leaf constants, 2 twig wind, 3 acc, 4 leaf
/// rotations (write).
pub fn leaf_flutter(
    frame: &RawLeafFrame,
    leaf: &[RawLeafMotion],
    twig_wind: &[[f32; 4]],
    acc: &[[f32; 4]],
    out: &mut [[f32; 4]],
) {
    out.par_iter_mut().zip(leaf.par_iter()).with_min_len(256).for_each(|(o, m)| {
        let w = twig_wind[m.twig as usize];
        let d = Quat::from_array(acc[m.segment as usize]);
        *o = leaf_rotation(frame, m, Vec3::new(w[0], w[1], w[2]), d, frame.time).to_array();
    });
}
