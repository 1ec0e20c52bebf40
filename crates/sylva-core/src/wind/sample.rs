//! CPU twin of `wind.wgsl` (`wind_at`) and `wind_sample.wgsl` (the kernel):
//! the wind velocity of a packed scene at (x, t). Same operations in the same order as the
//! WGSL, in f32.

use crate::wind::raw::{RawField, RawWave, kind};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::f32::consts::TAU;

/// `smoothstep` as WGSL defines it, written out so both sides do the same operations.
#[inline]
pub fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The envelope of a wave field at `t` from its packed [`crate::wind::Fade`]s (`RawField::b`):
/// a smoothstep in times one minus a smoothstep out; exactly 1 without fades. As
/// `wave_envelope` in `wind.wgsl`.
#[inline]
pub fn wave_envelope(b: [f32; 4], t: f32) -> f32 {
    smoothstep(0.0, 1.0, (t - b[0]) * b[1]) * (1.0 - smoothstep(0.0, 1.0, (t - b[2]) * b[3]))
}

#[inline]
fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// Velocity (m/s) of one field at position `p` (m) and time `t` (s).
pub fn field_at(f: &RawField, waves: &[RawWave], p: Vec3, t: f32) -> Vec3 {
    match f.kind {
        kind::CONSTANT => v3(f.a),
        kind::SUM_OF_SINES => {
            let sharp = f.a[0];
            let mode = f.a[1];
            let e = wave_envelope(f.b, t);
            let mut v = Vec3::ZERO;
            for w in &waves[f.wave_offset as usize..(f.wave_offset + f.wave_count) as usize] {
                let th = v3(w.k).dot(p) + w.k[3] * t;
                let s = th.sin();
                let h = if mode < 0.5 { s } else { ((s + 1.0) * 0.5).powf(sharp) };
                v += v3(w.dir) * (h * e);
            }
            v
        }
        kind::GUST_FRONT => {
            let rel = Vec2::new(p.x - f.a[0], p.z - f.a[1]);
            let d = Vec2::new(f.a[2], f.a[3]);
            let along = rel.dot(d);
            let s = along - f.b[1] * (t - f.c[0]);
            let g = if s >= 0.0 { 1.0 - smoothstep(0.0, f.b[2], s) } else { (s / f.b[3]).exp() };
            let lateral = (rel.x * -d.y + rel.y * d.x).abs();
            let lat = 1.0 - smoothstep(0.5 * f.c[1], f.c[1], lateral);
            let behind_origin = smoothstep(-f.b[2], 0.0, along);
            let a = f.b[0] * g * lat * behind_origin;
            Vec3::new(d.x * a, 0.0, d.y * a)
        }
        kind::VORTEX => {
            let tau = t - f.b[2];
            if tau < 0.0 || tau > f.b[3] {
                return Vec3::ZERO;
            }
            let env = smoothstep(0.0, f.c[0], tau) * smoothstep(0.0, f.c[0], f.b[3] - tau);
            let cx = f.a[0] + f.a[2] * tau;
            let cz = f.a[1] + f.a[3] * tau;
            let rx = p.x - cx;
            let rz = p.z - cz;
            let d2 = rx * rx + rz * rz;
            let r2 = f.b[1] * f.b[1];
            let up = f.c[1] * (-d2 / r2).exp();
            let d = d2.sqrt();
            if d < 1e-6 {
                return Vec3::new(0.0, env * up, 0.0);
            }
            // 1 − e^(−x), by its series near the axis where the subtraction cancels.
            let x = 1.256 * d2 / r2;
            let one_minus = if x < 1e-2 { x * (1.0 - 0.5 * x) } else { 1.0 - (-x).exp() };
            let vt = f.b[0] * 1.398 * (f.b[1] / d) * one_minus;
            Vec3::new(env * vt * rz / d, env * up, env * vt * -rx / d)
        }
        kind::BLAST => {
            let tau = t - f.b[0];
            let rel = p - v3(f.a);
            let d = rel.length();
            if tau < 0.0 || d < 1e-6 {
                return Vec3::ZERO;
            }
            let x = (d - f.b[1] * tau) / f.b[2];
            let shell = (-(x * x)).exp();
            let amp = f.a[3] * (-tau / f.b[3]).exp() * shell * (1.0 - smoothstep(0.8 * f.c[0], f.c[0], d));
            rel * (amp / d)
        }
        kind::TURBULENCE => {
            let e = wave_envelope(f.b, t);
            let mut v = Vec3::ZERO;
            for w in &waves[f.wave_offset as usize..(f.wave_offset + f.wave_count) as usize] {
                let cyc = w.k[3] * t + w.phase[0];
                let cyc = cyc - cyc.floor();
                let th = TAU * cyc - v3(w.k).dot(p);
                v += v3(w.dir) * (th.sin() * e);
            }
            v
        }
        kind::GRID => crate::wind::grid::grid_at(f, waves, p, t),
        _ => Vec3::ZERO,
    }
}

/// Velocity of a whole scene (the sum of its fields), as `wind_at` in `wind.wgsl`.
pub fn wind_at(fields: &[RawField], waves: &[RawWave], p: Vec3, t: f32) -> Vec3 {
    let mut v = Vec3::ZERO;
    for f in fields {
        v += field_at(f, waves, p, t);
    }
    v
}

/// The wind at `p` and `t` with each wave (sum of sines, turbulence) passed through a linear
/// filter: `response(f)` gives the gain and the phase lag (rad) at `f` Hz. A sharpened sum of
/// sines keeps its mean and filters what swings about it. Fields without waves pass through
/// as they are. With `response` = (1, 0) it is [`wind_at`] (to rounding). A field's
/// [`wave_envelope`] scales its filtered waves at `t`: a blend as slow as the filter's memory
/// (a fade of a second or more against a tree's damping) passes through nearly unchanged.
pub fn wind_through(
    fields: &[RawField],
    waves: &[RawWave],
    p: Vec3,
    t: f32,
    response: impl Fn(f32) -> (f32, f32),
) -> Vec3 {
    let mut v = Vec3::ZERO;
    for f in fields {
        let run = || &waves[f.wave_offset as usize..(f.wave_offset + f.wave_count) as usize];
        v += match f.kind {
            kind::SUM_OF_SINES => {
                let (sharp, mode) = (f.a[0], f.a[1]);
                // Mean of ((sin + 1) / 2)^sharp over a period (midpoint rule, exact to ~1e-6).
                let mean = if mode < 0.5 {
                    0.0
                } else {
                    (0..64).map(|j| ((((j as f32 + 0.5) * TAU / 64.0).sin() + 1.0) * 0.5).powf(sharp)).sum::<f32>()
                        / 64.0
                };
                let e = wave_envelope(f.b, t);
                let mut sum = Vec3::ZERO;
                for w in run() {
                    let (gain, lag) = response(w.k[3].abs() / TAU);
                    let th = v3(w.k).dot(p) + w.k[3] * t - lag * w.k[3].signum();
                    let s = th.sin();
                    let h = if mode < 0.5 { s } else { ((s + 1.0) * 0.5).powf(sharp) - mean };
                    sum += v3(w.dir) * ((mean + gain * h) * e);
                }
                sum
            }
            kind::TURBULENCE => {
                let e = wave_envelope(f.b, t);
                let mut sum = Vec3::ZERO;
                for w in run() {
                    let (gain, lag) = response(w.k[3]);
                    let cyc = w.k[3] * t + w.phase[0];
                    let cyc = cyc - cyc.floor();
                    let th = TAU * cyc - v3(w.k).dot(p) - lag;
                    sum += v3(w.dir) * (gain * th.sin() * e);
                }
                sum
            }
            _ => field_at(f, waves, p, t),
        };
    }
    v
}

/// The kernel's CPU twin. Bindings as in `wind_sample.wgsl`: 0 = fields, 1 = waves,
/// 2 = samples (x, y, z, t), 3 = velocities (x, y, z, 0).
pub fn wind_sample(fields: &[RawField], waves: &[RawWave], samples: &[[f32; 4]], out: &mut [[f32; 4]]) {
    out.par_iter_mut().zip(samples.par_iter()).for_each(|(o, s)| {
        let v = wind_at(fields, waves, Vec3::new(s[0], s[1], s[2]), s[3]);
        *o = [v.x, v.y, v.z, 0.0];
    });
}
