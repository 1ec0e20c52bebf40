//! Trunk motion as superposed noise bands (Zioma §6.3.3, Figs. 6-2 and 6-3).
//!
//! Instead of integrating `m a + c v + k x = f`, the trunk's bend is synthesised from
//! frequency bands whose amplitudes and frequencies come from the tree itself:
//!
//! * the **natural frequency** of the trunk as a tapered cantilever,
//!   `f₀ = 0.7 · (1.875² / 2π) · √(E I / (ρ A)) / H²` with the trunk's base radius
//!   (`I/A = r²/4`), height H, the wood's E and ρ; the factor 0.7 accounts for taper and
//!   the crown's mass, bringing typical trees to the 0.2–0.6 Hz that field measurements report;
//! * the **static bend** under the crown's drag, `θ = F h² / (2 E I)` with
//!   `F = ½ ρ_air C_d A_crown U²` acting at the crown's mid-height h (a cantilever's end
//!   rotation under a point load), capped at 0.35 rad.
//!
//! Bands (multiples of f₀ and of θ): *parallel* to the wind — a lean of 0.8 θ plus slow gust
//! response (0.15 f₀, 0.3 θ), sway at the natural frequency (f₀, 0.4 θ), and small-branch
//! chaos (2.3 f₀, 0.12 θ; 5.1 f₀, 0.05 θ); *perpendicular* — (0.9 f₀, 0.2 θ),
//! (3.1 f₀, 0.06 θ); *twist* about the trunk axis — (1.3 f₀, 0.08 θ). A heavier, stiffer
//! tree gets a lower f₀ and a smaller θ: lower amplitude and frequency, as in Fig. 6-3.

use crate::model::Tree;
use crate::physics::AIR_DENSITY;
use crate::wind::noise::value_noise;
use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;

/// Drag coefficient of a tree crown (porous: 0.2–0.4 in wind-tunnel studies).
pub const CROWN_DRAG: f32 = 0.3;

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

/// The noise bands of one tree in one wind.
#[derive(Debug, Clone, PartialEq)]
pub struct TrunkNoise {
    /// Natural frequency f₀, Hz.
    pub natural_frequency: f32,
    /// Static bend θ under the mean wind, rad.
    pub static_bend: f32,
    /// The bands.
    pub bands: Vec<RawBand>,
}

impl TrunkNoise {
    /// Bands for a tree with trunk base radius `radius` (m), height `height` (m), crown area
    /// `crown_area` (m²) centred at `crown_height` (m), wood E (Pa) and ρ (kg/m³), in a mean
    /// wind of `wind_speed` (m/s).
    pub fn new(
        radius: f32,
        height: f32,
        crown_area: f32,
        crown_height: f32,
        young: f32,
        density: f32,
        wind_speed: f32,
    ) -> Self {
        let r = radius.max(1e-4);
        let h = height.max(0.1);
        let ei = young * std::f32::consts::FRAC_PI_4 * r.powi(4);
        let f0 = 0.7 * (1.875f32 * 1.875 / std::f32::consts::TAU) * (young * r * r / (4.0 * density)).sqrt() / (h * h);
        let force = 0.5 * AIR_DENSITY * CROWN_DRAG * crown_area * wind_speed * wind_speed;
        let theta = (force * crown_height * crown_height / (2.0 * ei)).min(0.35);
        let band = |axis: u32, seed: u32, fr: f32, amp: f32, bias: f32| RawBand {
            axis,
            seed,
            frequency: fr * f0,
            amplitude: amp * theta,
            bias: bias * theta,
            _pad: [0; 3],
        };
        let bands = vec![
            band(0, 0x11, 0.15, 0.3, 0.8),
            band(0, 0x12, 1.0, 0.4, 0.0),
            band(0, 0x13, 2.3, 0.12, 0.0),
            band(0, 0x14, 5.1, 0.05, 0.0),
            band(1, 0x21, 0.9, 0.2, 0.0),
            band(1, 0x22, 3.1, 0.06, 0.0),
            band(2, 0x31, 1.3, 0.08, 0.0),
        ];
        Self { natural_frequency: f0, static_bend: theta, bands }
    }

    /// Bands for a generated tree: the trunk radius at 40 % of the first stem's length (above
    /// the flare, where a tapered trunk bends), height and crown from its bounds (the crown
    /// spans from the lowest branch to the top).
    pub fn for_tree(tree: &Tree, wind_speed: f32) -> Self {
        let s = &tree.segments;
        let mut radius = s.radius_base.first().copied().unwrap_or(0.05);
        if !tree.stems.is_empty() {
            let (first, n) = (tree.stems.first_segment[0] as usize, tree.stems.segment_count[0] as usize);
            let target = 0.4 * tree.stems.length[0];
            let mut acc = 0.0;
            for i in first..first + n {
                if acc + s.length[i] >= target {
                    let f = ((target - acc) / s.length[i]).clamp(0.0, 1.0);
                    radius = s.radius_base[i] + (s.radius_tip[i] - s.radius_base[i]) * f;
                    break;
                }
                acc += s.length[i];
            }
        }
        let (lo, hi) = tree.bounds();
        let height = hi.y - lo.y;
        let crown_base = (0..s.len()).filter(|&i| s.level[i] > 0).map(|i| s.start[i].y).fold(f32::INFINITY, f32::min);
        let crown_base = if crown_base.is_finite() { crown_base } else { lo.y + 0.5 * height };
        let crown_h = (hi.y - crown_base).max(0.1);
        let width = (hi.x - lo.x).max(hi.z - lo.z).max(0.1);
        Self::new(
            radius,
            height,
            crown_h * width,
            0.5 * (crown_base + hi.y) - lo.y,
            tree.wood.young_modulus,
            tree.wood.density,
            wind_speed,
        )
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
