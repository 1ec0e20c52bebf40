//! Every instance's per-frame values as a kernel (Zioma §6.3.3, §6.5): the wind at the
//! instance's crown through the trunk's oscillator ([`TrunkModel::bend`]) plus the
//! instance's own ring, turned into the tree's frame, the lean's direction, its noise bands
//! ([`TrunkNoise`]) and the parallel band's rate by a central difference. CPU twin of
//! `zioma_frames.wgsl`; [`super::Zioma::frames_for`] runs it, so the CPU method and the GPU
//! compute the same thing in the same order (to the device's rounding of `sin`, `pow`,
//! `exp` and `atan2`).

use super::raw::{RawZiomaFrame, RawZiomaInstance, RawZiomaRing, RawZiomaTrunk};
use super::trunk::{self, Ring, TrunkModel, TrunkNoise};
use crate::physics::DragModel;
use crate::pose::Placement;
use crate::wind::raw::{RawField, RawWave};
use glam::Vec3;
use rayon::prelude::*;

/// Half-width of the central difference the trunk's rate is taken over, s.
pub const RATE_DT: f32 = 0.01;

impl RawZiomaTrunk {
    /// The trunk model it carries.
    pub fn model(&self) -> TrunkModel {
        TrunkModel {
            natural_frequency: self.natural_frequency,
            tip_per_pascal: self.tip_per_pascal,
            damping_centre: self.damping_centre,
            lever: self.lever,
            damping_ratio: self.damping_ratio,
            drag: DragModel { reconfiguration_speed: self.reconfiguration_speed, vogel_exponent: self.vogel_exponent },
        }
    }
}

impl From<&RawZiomaRing> for Ring {
    fn from(r: &RawZiomaRing) -> Self {
        Ring { bend: Vec3::from_array(r.bend), rate: Vec3::from_array(r.rate), since: r.since, zeta: r.zeta }
    }
}

impl From<&RawZiomaInstance> for Placement {
    fn from(i: &RawZiomaInstance) -> Self {
        Self { position: Vec3::from_array(i.position), yaw: i.yaw, phase: i.phase, seed: i.seed }
    }
}

/// The time the trunk's rate at `t` is differenced back to, and the span to `t + RATE_DT`:
/// `RATE_DT` before `t`, but never past the change a ring starts at (before it the lean was
/// the old wind's, which the ring's closed form does not know; differencing across it read
/// the jump to the new wind's lean as a rate).
fn rate_behind(ring: &Ring, t: f32) -> (f32, f32) {
    if ring.is_ringing() && t >= ring.since && t - RATE_DT < ring.since {
        (ring.since, RATE_DT + (t - ring.since))
    } else {
        (t - RATE_DT, 2.0 * RATE_DT)
    }
}

/// One instance's frame values, ringing by `r`.
pub fn zioma_frame(
    fields: &[RawField],
    waves: &[RawWave],
    k: &RawZiomaTrunk,
    i: &RawZiomaInstance,
    r: &RawZiomaRing,
) -> RawZiomaFrame {
    let (model, ring, place) = (k.model(), Ring::from(r), Placement::from(i));
    let centre = place.to_world(Vec3::from_array(k.crown_centre));
    let seed = k.tree_seed ^ i.seed;
    // The trunk's lean (its oscillator's answer to the wind, horizontal, in the tree's
    // frame) and the bands on it.
    let lean = |t: f32| {
        let b = place.to_local(model.bend(fields, waves, centre, t) + model.ring_at(&ring, t).0);
        let theta = b.length().min(trunk::MAX_TRUNK_BEND);
        (b.try_normalize().unwrap_or(Vec3::ZERO), TrunkNoise::new(model.natural_frequency, theta))
    };
    let t = k.time;
    let (dir, noise) = lean(t);
    let a = noise.angles(t, seed);
    let (tp, (tm, span)) = (t + RATE_DT, rate_behind(&ring, t));
    let rate = (lean(tp).1.angles(tp, seed)[0] - lean(tm).1.angles(tm, seed)[0]) / span;
    let (sin, cos) = i.yaw.sin_cos();
    RawZiomaFrame {
        wind_dir: dir.to_array(),
        time: t,
        trunk: a,
        trunk_rate: rate,
        lod: k.lod,
        amplitude: k.amplitude,
        max_bend: k.max_bend,
        inertia: k.inertia,
        origin: i.position,
        phase: i.phase,
        heading: [cos, sin],
        _pad: [0.0; 2],
    }
}

/// The kernel's CPU twin. Bindings as in `zioma_frames.wgsl`: 0 = fields, 1 = waves,
/// 2 = the tree's values (one), 3 = instances, 4 = their rings, 5 = frames (one per
/// instance).
pub fn zioma_frames(
    fields: &[RawField],
    waves: &[RawWave],
    trunk: &[RawZiomaTrunk],
    instances: &[RawZiomaInstance],
    rings: &[RawZiomaRing],
    out: &mut [RawZiomaFrame],
) {
    let k = &trunk[0];
    out.par_iter_mut()
        .zip(instances.par_iter().zip(rings.par_iter()))
        .for_each(|(o, (i, r))| *o = zioma_frame(fields, waves, k, i, r));
}
