//! Leaves that move: one rotation per leaf about its attachment, beside the per-segment pose
//! of the seam ([`crate::pose::SeamPose::leaf`]).
//!
//! A leaf's rotation `λ` is expressed in its segment's rest frame: the leaf's orientation is
//! `D_s · λ · Q_leaf` and its attachment follows the segment (`D_s` the segment's
//! accumulated rotation). The identity is the rest pose, bit for bit, and still air gives it.
//!
//! Zioma's, Akagi's and Skjermo's leaves move by the closed form here ([`LeafFlutter`]; CPU
//! twins in [`kernels`], WGSL in `sylva-gpu/src/leaves/`): stateless, so the same in t on
//! every method and backend. HSM's leaves are its own leaf clusters (Song §4).
//!
//! Per leaf, from its blade and an implied petiole ([`LeafMotion`]):
//! * **Stiffness and frequency.** The petiole is a cantilever of length `l_p`, diameter
//!   `d_p` and modulus `E_p` turned at its tip by the blade: `k = E_p I_p / l_p`,
//!   `I_p = π d_p⁴ / 64`. The blade (mass `ρ_a A`, `A = π w L / 4`) swings about the
//!   petiole's base: `J = m ((l_p + L/2)² + L²/12)`, `ω_b = √(k / J)`. Twisting about the
//!   midrib, `k_t = (GJ/EI) k` against `m w² / 12`. A leaf rings at least [`ABOVE_TWIG`]
//!   times its twig's first mode ([`crate::physics::stem_frequencies`]): a blade whose
//!   petiole alone would ring slower (a long blade or frond on a stiff short twig) would move
//!   with its twig rather than about it, and its stiffness is raised to match. Swing and
//!   twist stay under [`MAX_LEAF_HZ`], so a 60 Hz step (and a 30 fps render) resolves both.
//! * **Lean (lift and drag).** The normal force `C_N A q g(u)` (dynamic pressure q of the
//!   wind inside the crown, `crown_wind` of the wind at the twig; reconfiguration g of
//!   [`crate::physics::drag`]) at the blade's centre against `k`: the
//!   Cauchy number `K = C_N A r q g / k`. The blade swings toward the flow by
//!   `φ K / (1 + K)` of the angle φ between blade and wind (the small-angle equilibrium of
//!   `k θ = F r sin(φ − θ)`): never past the flow, saturating in strong wind as leaves
//!   reconfigure (Vogel 1989).
//! * **Flutter.** About that lean, in pitch and twist, the narrow-band response of a damped
//!   oscillator to the turbulence at the leaf's scale: three sines spread over the half-power
//!   band `ω (1 ± ζ)` with the leaf's own phases (unit RMS). Its amplitude is
//!   `flutter · u² / (u² + u_onset²)` (u the wind at the leaf): leaves flutter from a
//!   threshold on and depend weakly on the speed beyond it (Tadrist et al. 2018, "Foliage
//!   motion under wind", J. R. Soc. Interface).
//! * **Flip (tumble).** Above the leaf's flip speed (`flip_speed` at the twig, ±25 % per
//!   leaf) the twist grows by up to an eighth of a turn RMS (peaks past a quarter turn) (torsional galloping, Tadrist et al.
//!   2015): the blade flips its underside to the wind and back at its twist frequency.
//!
//! The local wind at a leaf is the wind at the tip of its twig (the stem it grows on) turned
//! into the segment's rest frame: the wind's smallest scales (the crown band of `gusty`,
//! ≥ 0.75 m) are longer than a twig's run of leaves, and one sample per twig keeps the cost
//! a fraction of the methods' own.

pub mod kernels;

pub use crate::model::LeafMotion;
use crate::model::{NONE, Tree};
use crate::physics::AIR_DENSITY;
use crate::physics::drag::DragModel;
use crate::pose::SeamPose;
use crate::wind::PackedWind;
use bytemuck::{Pod, Zeroable};

/// Per-frame values of the leaf kernels (`leaf_wind.wgsl`, `leaf_flutter.wgsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawLeafFrame {
    /// Time, s.
    pub time: f32,
    /// [`LeafMotion::strength`].
    pub strength: f32,
    /// Flutter amplitude, rad.
    pub flutter: f32,
    /// Damping ratio.
    pub zeta: f32,
    /// Reconfiguration speed U_r, m/s.
    pub reconfiguration_speed: f32,
    /// Vogel exponent B.
    pub vogel_exponent: f32,
    /// Number of leaves.
    pub leaves: u32,
    /// Number of twigs sampled.
    pub twigs: u32,
    /// [`LeafMotion::flutter_onset`], m/s.
    pub flutter_onset: f32,
    /// [`LeafMotion::crown_wind`].
    pub crown_wind: f32,
    /// Padding.
    pub _pad: [u32; 2],
}

/// One leaf's constants (GPU layout).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawLeafMotion {
    /// Rest orientation of the blade (x, y, z, w): blade along +Y, width along +X.
    pub orientation: [f32; 4],
    /// Natural angular frequency of the swing, rad/s.
    pub omega: f32,
    /// Natural angular frequency of the twist about the midrib, rad/s.
    pub omega_twist: f32,
    /// Cauchy number per pascal, `C_N A r / k`, 1/Pa.
    pub compliance: f32,
    /// Dynamic pressure at which this leaf flips, Pa.
    pub flip_pressure: f32,
    /// Seed of the leaf's phases.
    pub seed: u32,
    /// Its twig's index in the twig samples.
    pub twig: u32,
    /// The segment it hangs on.
    pub segment: u32,
    /// Padding.
    pub _pad: u32,
}

/// The leaf motion of one tree: per-leaf constants and the twigs whose wind they feel.
#[derive(Debug, Clone, PartialEq)]
pub struct LeafFlutter {
    /// Parameters.
    pub params: LeafMotion,
    /// Per-leaf constants, in the tree's leaf order.
    pub leaves: Vec<RawLeafMotion>,
    /// The segment whose joint each twig's wind is sampled at (its stem's last segment).
    pub twigs: Vec<u32>,
    drag: DragModel,
}

impl LeafFlutter {
    /// The constants of every leaf of `tree` from `tree.leaf_motion`, phases from `seed`.
    pub fn new(tree: &Tree, seed: u64) -> Self {
        let params = tree.leaf_motion;
        let l = &tree.leaves;
        let s = &tree.segments;
        let mut twig_of_stem = vec![NONE; tree.stems.len()];
        let mut twigs = Vec::new();
        let key = crate::rng::mix64(seed ^ 0x1eaf_f1a7) as u32;
        let twig_modes =
            if l.is_empty() { None } else { Some(crate::physics::stem_frequencies(tree, crate::physics::MIN_RADIUS)) };
        let leaves = (0..l.len())
            .map(|i| {
                let seg = l.segment[i] as usize;
                let stem = s.stem[seg] as usize;
                if twig_of_stem[stem] == NONE {
                    twig_of_stem[stem] = twigs.len() as u32;
                    let last = tree.stems.first_segment[stem] + tree.stems.segment_count[stem].max(1) - 1;
                    twigs.push(last);
                }
                let twig_omega = twig_modes.as_ref().map_or(0.0, |m| m.omega[stem]);
                let c = leaf_constants(&params, l.width[i], l.length[i], tree.wood.leaf_areal_density, twig_omega);
                let seed = crate::wind::noise::pcg_hash(key ^ (i as u32).wrapping_mul(0x9e37_79b9));
                let flip_speed = params.flip_speed * (0.75 + 0.5 * crate::wind::noise::hash_unit(seed ^ 0x00f1_1b00));
                RawLeafMotion {
                    orientation: l.orientation[i].to_array(),
                    omega: c.omega,
                    omega_twist: c.omega_twist,
                    compliance: c.compliance,
                    flip_pressure: 0.5 * AIR_DENSITY * flip_speed * flip_speed,
                    seed,
                    twig: twig_of_stem[stem],
                    segment: seg as u32,
                    _pad: 0,
                }
            })
            .collect();
        Self { params, leaves, twigs, drag: DragModel::default() }
    }

    /// The frame constants at time `t`.
    pub fn frame(&self, t: f32) -> RawLeafFrame {
        RawLeafFrame {
            time: t,
            strength: self.params.strength,
            flutter: self.params.flutter_deg.to_radians(),
            zeta: self.params.damping_ratio,
            reconfiguration_speed: self.drag.reconfiguration_speed,
            vogel_exponent: self.drag.vogel_exponent,
            leaves: self.leaves.len() as u32,
            twigs: self.twigs.len() as u32,
            flutter_onset: self.params.flutter_onset,
            crown_wind: self.params.crown_wind,
            _pad: [0; 2],
        }
    }

    /// Writes `seam.leaf` (one instance) from the seam's joints and rotations, the wind and
    /// the time: both kernels' CPU twins in turn. With [`LeafMotion::strength`] 0 the leaves
    /// stay at rest and nothing is computed (`seam.leaf` left empty).
    pub fn seam(&self, wind: &PackedWind, t: f32, seam: &mut SeamPose) {
        self.write(wind, t, &seam.joints, &seam.acc, &mut seam.leaf);
    }

    /// Writes the leaf rotations of the instance whose seam buffers are `joints` and `acc`
    /// (the first instance's, of instance-major buffers) into `out` (see [`Self::seam`]).
    pub fn write(&self, wind: &PackedWind, t: f32, joints: &[[f32; 4]], acc: &[[f32; 4]], out: &mut Vec<[f32; 4]>) {
        if self.params.strength == 0.0 {
            out.clear();
            return;
        }
        let frame = self.frame(t);
        let mut twig_wind = vec![[0.0f32; 4]; 2 * self.twigs.len()];
        kernels::leaf_wind(&wind.fields, &wind.waves, &frame, &self.twigs, joints, &mut twig_wind);
        out.resize(self.leaves.len(), [0.0, 0.0, 0.0, 1.0]);
        kernels::leaf_flutter(&frame, &self.leaves, &twig_wind, acc, out);
    }
}

/// A leaf's natural frequencies and compliance (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeafConstants {
    /// Swing, rad/s.
    pub omega: f32,
    /// Twist, rad/s.
    pub omega_twist: f32,
    /// `C_N A r / k`, 1/Pa.
    pub compliance: f32,
    /// The petiole's swing stiffness `k = J ω²`, N·m/rad (`J` the blade's moment of inertia
    /// about the attachment): the torque a leaf turned by one radian puts on its twig.
    pub stiffness: f32,
}

/// Highest swing or twist frequency a leaf is given, Hz: a 60 Hz step samples the band's top
/// (12 Hz × 1.15) four times a cycle.
pub const MAX_LEAF_HZ: f32 = 12.0;

/// How far above its twig's first mode a leaf rings at least.
pub const ABOVE_TWIG: f32 = 1.25;

/// The constants of a blade `width` × `length` (m) of areal density `rho_a` (kg/m²) on a twig
/// whose first mode is `twig_omega` rad/s (see the module docs).
pub fn leaf_constants(p: &LeafMotion, width: f32, length: f32, rho_a: f32, twig_omega: f32) -> LeafConstants {
    let (w, len) = (width.max(1e-4), length.max(1e-4));
    let area = std::f32::consts::FRAC_PI_4 * w * len;
    let m = (rho_a * area).max(1e-9);
    let lp = p.petiole_ratio * len;
    let dp = p.petiole_diameter_ratio * w;
    let ei = p.petiole_modulus * std::f32::consts::PI * dp.powi(4) / 64.0;
    let r = lp + 0.5 * len;
    let j = m * (r * r + len * len / 12.0);
    let j_twist = m * w * w / 12.0;
    let omega_max = std::f32::consts::TAU * MAX_LEAF_HZ;
    let floor = (ABOVE_TWIG * twig_omega).min(omega_max);
    let omega = (ei / lp / j).sqrt().clamp(floor.max(1e-3), omega_max.max(floor));
    let k = j * omega * omega;
    LeafConstants {
        omega,
        omega_twist: (p.petiole_torsion * k / j_twist).sqrt().min(omega_max),
        compliance: p.normal_force * area * r / k,
        stiffness: k,
    }
}
