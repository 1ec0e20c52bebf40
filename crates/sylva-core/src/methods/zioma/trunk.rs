//! Trunk motion (Zioma §6.3.3, Figs. 6-2 and 6-3) as the response of a damped oscillator
//! (Ota 2003's `m a + c v + k x = f`, which the chapter cites) at the trunk's own frequency,
//! without state: the wind at the crown is passed through the oscillator's transfer function
//! wave by wave, each of its waves (sum of sines, turbulence) scaled by
//! `|H(f)| = 1 / √((1 − r²)² + (2ζr)²)`, `r = f / f₀`, and delayed by its phase
//! `atan2(2ζr, 1 − r²)`: the steady response of `ẍ + 2ζω₀ẋ + ω₀²x = ω₀² u` to a sum of sines,
//! exactly. The trunk leans by the static bend of the wind as it is (drag is quadratic in
//! it) plus the oscillator's answer to the waves' swings, linearised about that bend
//! ([`TrunkModel::bend`]). Its constants come from the shared physical description
//! ([`TrunkModel`], [`crate::physics`]):
//!
//! * the **natural frequency** f₀ of the trunk's first mode, the continuous tapered
//!   cantilever's ([`crate::physics::stem_frequencies`]);
//! * the **static bend** under the sheltered crown's drag, the same beam's tip deflection
//!   per pascal ([`crate::physics::beam::drag_bend`]) times `½ ρ U² g(U)` (Vogel
//!   reconfiguration, [`DragModel`]), spread over the trunk as an arc whose top moves by
//!   that deflection δ ([`TrunkModel::lever`]);
//! * the **damping ratio**: the wood's ([`STRUCTURAL_DAMPING`]) plus the air's, from the
//!   drag on the moving crown, each part weighed by how far it moves with the trunk's mode
//!   ([`crate::physics::beam::DragBend::damping_centre`]), so it rises with the wind.
//!
//! Fields without waves (constant, gust front, vortex, blast) pass through unfiltered
//! (quasi-statically). When the wind itself changes (it starts, stops, is swapped or
//! edited), the one piece of state, a [`Ring`], takes over: the trunk's bend and rate are
//! kept continuous across the change, and the difference between the old wind's answer
//! and the new one's rings down as the free oscillator, `e^{−ζω₀τ}(X cos ω_d τ + …)`, still
//! a closed form in t. Small-branch chaos rides on top as noise bands (multiples of f₀, scaled
//! by θ): parallel (2.3 f₀, 0.12 θ; 5.1 f₀, 0.05 θ), perpendicular (3.1 f₀, 0.06 θ) and a
//! twist (1.3 f₀, 0.08 θ). A heavier, stiffer tree gets a lower f₀ and a smaller θ: lower
//! amplitude and frequency, as in Fig. 6-3.

use crate::model::Tree;
use crate::physics::{AIR_DENSITY, DragModel, STRUCTURAL_DAMPING};
use crate::wind::noise::value_noise;
use crate::wind::raw::{RawField, RawWave};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use rayon::prelude::*;

/// Largest trunk bend, rad (≈ 20°: beyond it an arc is a poor picture of a bent trunk).
pub const MAX_TRUNK_BEND: f32 = 0.35;

/// Axis a band moves: 0 parallel to the wind, 1 perpendicular, 2 twist.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawBand {
    /// 0 = parallel, 1 = perpendicular, 2 = twist.
    pub axis: u32,
    /// Noise stream.
    pub seed: u32,
    /// Frequency, Hz.
    pub frequency: f32,
    /// Amplitude, rad.
    pub amplitude: f32,
    /// Constant offset, rad.
    pub bias: f32,
    /// Padding.
    pub _pad: [u32; 3],
}

/// A tree's trunk as the shared physical description sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrunkModel {
    /// First-mode frequency f₀, Hz.
    pub natural_frequency: f32,
    /// Trunk-top deflection per pascal of dynamic pressure on the crown, m/Pa.
    pub tip_per_pascal: f32,
    /// Share of the tip's speed at which the drag's point of work moves, which weighs the
    /// air's damping ([`crate::physics::beam::DragBend::damping_centre`]).
    pub damping_centre: f32,
    /// How far the trunk top moves per radian of arc, m: `Σ Lᵢ cᵢ` over the trunk's
    /// segments, `cᵢ` the share of the trunk's length up to segment i's end (each segment
    /// turns by its share of the arc; L/2 for a smooth arc).
    pub lever: f32,
    /// Structural damping ratio.
    pub damping_ratio: f32,
    /// Drag and reconfiguration.
    pub drag: DragModel,
}

impl TrunkModel {
    /// The model of `tree`'s first stem, with bark drag `bark_drag` and leaf drag
    /// `leaf_drag` (per one-sided area) sheltered as [`crate::physics::crown_shelter`] says.
    pub fn for_tree(tree: &Tree, bark_drag: f32, leaf_drag: f32) -> Self {
        if tree.stems.is_empty() || tree.stems.segment_count[0] == 0 {
            let drag = DragModel::default();
            return Self {
                natural_frequency: 1.0,
                tip_per_pascal: 0.0,
                damping_centre: crate::physics::beam::UNIFORM_CENTRE,
                lever: 1.0,
                damping_ratio: STRUCTURAL_DAMPING,
                drag,
            };
        }
        let min_radius = crate::physics::MIN_RADIUS;
        let modes = crate::physics::stem_frequencies(tree, min_radius);
        let shelter = crate::physics::crown_shelter(tree, bark_drag, leaf_drag);
        let cd_area = crate::physics::beam::drag_areas(tree, bark_drag, leaf_drag, shelter);
        let bend = crate::physics::beam::drag_bend(tree, min_radius, &cd_area);
        let (first, n) = (tree.stems.first_segment[0] as usize, tree.stems.segment_count[0] as usize);
        let lengths = &tree.segments.length[first..first + n];
        let total: f32 = lengths.iter().sum::<f32>().max(1e-6);
        let mut along = 0.0;
        let lever = lengths
            .iter()
            .map(|l| {
                along += l;
                l * along / total
            })
            .sum::<f32>()
            .max(1e-6);
        Self {
            natural_frequency: modes.hz(0),
            tip_per_pascal: bend.tip[0],
            damping_centre: bend.damping_centre[0],
            lever,
            damping_ratio: STRUCTURAL_DAMPING,
            drag: DragModel::default(),
        }
    }

    /// Arc angle θ of the trunk under a steady wind of `u` m/s, rad (capped at
    /// [`MAX_TRUNK_BEND`]).
    pub fn static_bend(&self, u: f32) -> f32 {
        let q = 0.5 * AIR_DENSITY * u * u * self.drag.reconfiguration(u);
        (self.tip_per_pascal * q / self.lever).min(MAX_TRUNK_BEND)
    }

    /// Damping ratio in a wind of `u` m/s: the wood's plus the air's, `ω₀ c ρ δ' u g(u) / 2`
    /// (δ' the tip's deflection per pascal, c the damping centre), as Skjermo's stems.
    pub fn damping(&self, u: f32) -> f32 {
        let w = std::f32::consts::TAU * self.natural_frequency;
        self.damping_ratio
            + 0.5 * w * self.damping_centre * AIR_DENSITY * self.tip_per_pascal * u * self.drag.reconfiguration(u)
    }

    /// The oscillator's response to a wave of `f` Hz at damping ratio `zeta`: gain and
    /// phase lag (rad).
    pub fn response(&self, f: f32, zeta: f32) -> (f32, f32) {
        let r = f.abs() / self.natural_frequency.max(1e-6);
        let (re, im) = (1.0 - r * r, 2.0 * zeta * r);
        (1.0 / (re * re + im * im).sqrt().max(1e-6), im.atan2(re))
    }

    /// d θ / d u at a steady wind of `u` m/s (0 where the bend is capped).
    pub fn static_bend_slope(&self, u: f32) -> f32 {
        if self.static_bend(u) >= MAX_TRUNK_BEND {
            return 0.0;
        }
        let d = &self.drag;
        let ur2 = d.reconfiguration_speed * d.reconfiguration_speed;
        let slope = u * d.reconfiguration(u) * (2.0 + d.vogel_exponent * u * u / (ur2 + u * u));
        self.tip_per_pascal * 0.5 * AIR_DENSITY * slope / self.lever
    }

    /// The trunk's bend at `p` and `t` as a horizontal vector, rad along the direction it
    /// leans: the static bend of the wind as it is (drag is quadratic), plus the oscillator's
    /// answer to its swings, linearised about it. The waves' swings `δ = u_H − u` (`u_H` the
    /// wind through [`Self::response`] at the damping of the wind's speed) push along the
    /// wind by `θ'(u) δ∥` and turn the push by `θ(u) δ⊥ / u`.
    pub fn bend(&self, fields: &[RawField], waves: &[RawWave], p: Vec3, t: f32) -> Vec3 {
        let horizontal = |v: Vec3| Vec3::new(v.x, 0.0, v.z);
        let raw = horizontal(crate::wind::sample::wind_at(fields, waves, p, t));
        let u = raw.length();
        if u < 1e-6 {
            return Vec3::ZERO;
        }
        let zeta = self.damping(u);
        let through = horizontal(crate::wind::sample::wind_through(fields, waves, p, t, |f| self.response(f, zeta)));
        let (along, across) = (raw / u, Vec3::Y.cross(raw / u));
        let swing = through - raw;
        let theta = self.static_bend(u);
        along * (theta + self.static_bend_slope(u) * swing.dot(along)) + across * (theta * swing.dot(across) / u)
    }
}

/// The trunk's free ring-down since the wind last changed: the bend (a horizontal lean
/// vector in the scene's frame, rad, as [`TrunkModel::bend`]) and its rate the closed form
/// lacked at the change, which then decay as the free oscillator at f₀ with the damping
/// ratio of the new wind. Zero (the default): no ring.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Ring {
    /// Bend at the change, rad.
    pub bend: Vec3,
    /// Rate of bend at the change, rad/s.
    pub rate: Vec3,
    /// Time of the change, s.
    pub since: f32,
    /// Damping ratio in the new wind.
    pub zeta: f32,
}

impl Ring {
    /// True when there is a ring (a bend or a rate to ring down), false for the default.
    pub fn is_ringing(&self) -> bool {
        self.bend != Vec3::ZERO || self.rate != Vec3::ZERO
    }
}

/// Half-width of the central difference a bend's rate is taken over, s.
const RATE_DT: f32 = 0.01;

impl TrunkModel {
    /// The ring's bend and rate at time `t` (none before its change).
    pub fn ring_at(&self, ring: &Ring, t: f32) -> (Vec3, Vec3) {
        let tau = t - ring.since;
        if tau < 0.0 || !ring.is_ringing() {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        let w = std::f32::consts::TAU * self.natural_frequency;
        let z = ring.zeta.clamp(0.0, 0.95);
        let (a, wd) = (z * w, w * (1.0 - z * z).sqrt());
        let (sin, cos) = (wd * tau).sin_cos();
        let decay = (-a * tau).exp();
        let b = (ring.rate + ring.bend * a) / wd;
        (decay * (ring.bend * cos + b * sin), decay * (ring.rate * cos - (ring.bend * wd + b * a) * sin))
    }

    /// The trunk's bend at `p` and time `t` in a wind (the closed form) with `ring` on top,
    /// and its rate.
    fn bend_and_rate(&self, wind: (&[RawField], &[RawWave]), ring: &Ring, p: Vec3, t: f32) -> (Vec3, Vec3) {
        let bend = |t| self.bend(wind.0, wind.1, p, t);
        let (x, v) = self.ring_at(ring, t);
        (bend(t) + x, (bend(t + RATE_DT) - bend(t - RATE_DT)) / (2.0 * RATE_DT) + v)
    }

    /// The ring that keeps the trunk's bend at `p` and its rate continuous when the wind
    /// changes from `old` (ringing by `ring`) to `new` at time `t`.
    pub fn ring_after(
        &self,
        old: (&[RawField], &[RawWave]),
        new: (&[RawField], &[RawWave]),
        ring: &Ring,
        p: Vec3,
        t: f32,
    ) -> Ring {
        let (x0, v0) = self.bend_and_rate(old, ring, p, t);
        let (x1, v1) = self.bend_and_rate(new, &Ring::default(), p, t);
        let u = crate::wind::sample::wind_at(new.0, new.1, p, t);
        Ring { bend: x0 - x1, rate: v0 - v1, since: t, zeta: self.damping(Vec3::new(u.x, 0.0, u.z).length()) }
    }
}

/// The trunk's noise bands: axis (0 parallel, 1 perpendicular, 2 twist), noise stream,
/// frequency (× f₀), amplitude and bias (× θ). `zioma_frames.wgsl` writes the same table
/// out (`trunk_noise_angles`); the parity test holds them together.
pub const TRUNK_BANDS: [(u32, u32, f32, f32, f32); 4] =
    [(0, 0x13, 2.3, 0.12, 1.0), (0, 0x14, 5.1, 0.05, 0.0), (1, 0x22, 3.1, 0.06, 0.0), (2, 0x31, 1.3, 0.08, 0.0)];

/// The noise bands of one tree in one wind.
#[derive(Debug, Clone, PartialEq)]
pub struct TrunkNoise {
    /// Natural frequency f₀, Hz.
    pub natural_frequency: f32,
    /// Static bend θ, rad.
    pub static_bend: f32,
    /// The bands.
    pub bands: Vec<RawBand>,
}

impl TrunkNoise {
    /// Small-branch chaos about a trunk of frequency `natural_frequency` (Hz) bent by
    /// `static_bend` (rad): the lean itself as the first band's bias.
    pub fn new(natural_frequency: f32, static_bend: f32) -> Self {
        let (f0, theta) = (natural_frequency, static_bend);
        let band = |axis: u32, seed: u32, fr: f32, amp: f32, bias: f32| RawBand {
            axis,
            seed,
            frequency: fr * f0,
            amplitude: amp * theta,
            bias: bias * theta,
            _pad: [0; 3],
        };
        let bands = TRUNK_BANDS.iter().map(|&(axis, seed, fr, amp, bias)| band(axis, seed, fr, amp, bias)).collect();
        Self { natural_frequency: f0, static_bend: theta, bands }
    }

    /// (parallel, perpendicular, twist) at time `t` for a tree with phase seed `tree_seed`.
    pub fn angles(&self, t: f32, tree_seed: u32) -> [f32; 3] {
        trunk_angles(&self.bands, t, tree_seed)
    }
}

/// (parallel, perpendicular, twist) angles in radians at time `t` for a tree with phase
/// seed `tree_seed`: each band adds `bias + amplitude · noise(frequency · t, seed ^ tree)`
/// to its axis.
pub fn trunk_angles(bands: &[RawBand], t: f32, tree_seed: u32) -> [f32; 3] {
    let mut out = [0.0f32; 3];
    for b in bands {
        let n = value_noise(b.frequency * t, b.seed ^ tree_seed);
        out[(b.axis as usize).min(2)] += b.bias + b.amplitude * n;
    }
    out
}

/// The kernel's CPU twin. Bindings as in `trunk_noise.wgsl`: 0 = bands, 1 = samples
/// (t, tree seed as bits, –, –), 2 = angles (parallel, perpendicular, twist, 0).
pub fn trunk_noise(bands: &[RawBand], samples: &[[f32; 4]], out: &mut [[f32; 4]]) {
    out.par_iter_mut().zip(samples.par_iter()).for_each(|(o, s)| {
        let a = trunk_angles(bands, s[0], s[1].to_bits());
        *o = [a[0], a[1], a[2], 0.0];
    });
}
