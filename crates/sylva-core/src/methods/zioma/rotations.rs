//! CPU twin of `zioma_rotations.wgsl`: Zioma's per-segment rotations
//! (see [`crate::methods::zioma`]). Bindings: 0 fields, 1 waves, 2 segments, 3 stems,
//! 4 frames (one per instance), 5 δ (instance-major: `instance × segments + segment`).

use crate::methods::zioma::{RawZiomaFrame, RawZiomaStem};
use crate::model::RawSegment;
use crate::simd::dispatch;
use crate::wind::lanes::{LANES, V3, wind_lanes};
use crate::wind::noise::value_noise;
use crate::wind::raw::{RawField, RawWave};
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// Unit axis or a fallback when the vector vanishes.
#[inline]
pub fn axis_or(v: Vec3, fallback: Vec3) -> Vec3 {
    let l = v.length();
    if l > 1e-6 { v / l } else { fallback }
}

dispatch! {
/// The wind at the bases of `stems` (where every segment of a stem samples it) for instance
/// `f`, turned into the tree's frame: sixteen stems at a time ([`crate::wind::lanes`]).
fn stem_winds_at(fields: &[RawField], waves: &[RawWave], stems: &[RawZiomaStem], f: &RawZiomaFrame, out: &mut [Vec3]) {
    let (hc, hs) = (f.heading[0], f.heading[1]);
    let origin = Vec3::from_array(f.origin);
    for (group, winds) in stems.chunks(LANES).zip(out.chunks_mut(LANES)) {
        let world = |l: usize| {
            let b = Vec3::from_array(group[l.min(group.len() - 1)].base);
            origin + Vec3::new(hc * b.x + hs * b.z, b.y, -hs * b.x + hc * b.z)
        };
        let u = wind_lanes(fields, waves, V3::from_lanes(std::array::from_fn(world)), f.time);
        for (l, w) in winds.iter_mut().enumerate() {
            let vw = u.lane(l);
            *w = Vec3::new(hc * vw.x - hs * vw.z, vw.y, hs * vw.x + hc * vw.z);
        }
    }
}
}

/// Rotation of segment `s` in its stem's wind `v` (in the tree's frame; unread for the trunk
/// and at LOD 0).
#[inline]
pub fn zioma_rotation(s: &RawSegment, stem: &RawZiomaStem, f: &RawZiomaFrame, v: Vec3) -> Quat {
    let frac = s.length / stem.length;
    let up = Vec3::Y;
    if s.level == 0 {
        let w = Vec3::from_array(f.wind_dir);
        let par_axis = axis_or(up.cross(w), Vec3::X);
        let perp_axis = axis_or(w, Vec3::Z);
        return Quat::from_axis_angle(par_axis, f.trunk[0] * frac)
            * Quat::from_axis_angle(perp_axis, f.trunk[1] * frac)
            * Quat::from_axis_angle(up, f.trunk[2] * frac);
    }
    if f.lod == 0 {
        return Quat::IDENTITY;
    }
    let vh = Vec3::new(v.x, 0.0, v.z);
    let u = vh.length();
    if u < 1e-6 {
        return Quat::IDENTITY;
    }
    let w = vh / u;
    let dir = Vec3::from_array(stem.dir);
    let pa = Vec3::from_array(stem.parent_axis);
    let bh = Vec3::new(dir.x, 0.0, dir.z);
    let c = if bh.length() > 1e-4 { bh.normalize().dot(w) } else { 0.0 };
    let facing = (-c).max(0.0);
    let back = c.max(0.0);
    let perp = 1.0 - c.abs();
    let theta = (stem.drag * u * u).min(f.max_bend) * f.amplitude;
    let phase = stem.phase + f.phase;
    let osc = value_noise(stem.freq * f.time + phase, stem.seed);
    let osc2 = value_noise(2.7 * stem.freq * f.time + phase, stem.seed ^ 0x55);
    let inertia = -f.inertia * f.trunk_rate / (std::f32::consts::TAU * stem.freq);
    let bend = theta * (facing * (0.9 + 0.1 * osc) + back * (0.4 + 0.8 * osc) + perp * (0.6 + 0.3 * osc))
        + inertia * f.amplitude;
    // The wind across the branch bends it (about dir × w); a branch along the wind has no
    // cross flow, and its bend axis turns over as the wind passes its line: the bend fades
    // with the cross flow there (within ±14°) instead of flipping sides at once.
    let across = dir.cross(w);
    let k = axis_or(across, axis_or(up.cross(w), Vec3::X));
    let bend = bend * (4.0 * across.length()).min(1.0);
    // Which way the wind swings the branch about its parent: a sign that turns over smoothly
    // (within ±14° of the branch's plane) as the wind crosses the plane, not at once.
    let side = (4.0 * axis_or(pa.cross(dir), Vec3::ZERO).dot(w)).clamp(-1.0, 1.0);
    let swing = side * perp * theta * (0.5 + 0.5 * osc2);
    let twist = perp * theta * 0.3 * osc2;
    Quat::from_axis_angle(k, bend * frac)
        * Quat::from_axis_angle(pa, swing * frac)
        * Quat::from_axis_angle(dir, twist * frac)
}

/// The kernel's CPU twin: each stem's wind sampled once per instance, sixteen stems at a time
/// (the WGSL samples it in every segment's invocation; the same wind to the sine's error).
pub fn zioma_rotations(
    fields: &[RawField],
    waves: &[RawWave],
    segments: &[RawSegment],
    stems: &[RawZiomaStem],
    frames: &[RawZiomaFrame],
    out: &mut [[f32; 4]],
) {
    let (n, m) = (segments.len(), stems.len());
    let level = crate::simd::level();
    // Fixed groups of stems, so the lanes (and the bits) do not depend on the threads.
    const GROUP: usize = 256;
    let mut winds = vec![Vec3::ZERO; frames.len() * m];
    winds.par_chunks_mut(m.max(1)).zip(frames).for_each(|(w, f)| {
        // An instance at LOD 0 reads no stem wind.
        if f.lod != 0 {
            w.par_chunks_mut(GROUP).zip(stems.par_chunks(GROUP)).for_each(|(w, st)| {
                stem_winds_at(level, fields, waves, st, f, w);
            });
        }
    });
    out.par_iter_mut().enumerate().with_min_len(64).for_each(|(i, o)| {
        let s = &segments[i % n];
        let k = s.stem as usize;
        *o = zioma_rotation(s, &stems[k], &frames[i / n], winds[(i / n) * m + k]).to_array();
    });
}
