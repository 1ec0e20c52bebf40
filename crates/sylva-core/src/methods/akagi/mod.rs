//! Akagi & Kitajima's sway by force propagation (§2.5), with the dynamics of the wood.
//!
//! Each step:
//! 1. **Forces** (`kernels::akagi_forces`): the wind at each segment's centre pushes on its
//!    bark, `C_d (2 r̄ L |sin φ|)` (φ between the segment and the flow: a cylinder's
//!    projected area), and on its leaves, `C_d,leaf A_leaf`, with drag that reconfigures in
//!    strong wind, and damps the segment's own motion through the air
//!    ([`crate::physics::DragModel`]).
//! 2. **Propagation** (`akagi_subtree`): from the tips toward the root, one pass per depth
//!    of the hierarchy (the GPU runs one dispatch per depth), the force on everything beyond
//!    each joint, its moment about the joint — children's forces times their lever arms —
//!    and the air's damping of turning about it, `Γ = Σ γ r²`.
//! 3. **Rotation** (`akagi_integrate`): each joint is a spring `k = E·I/ℓ` of its segment's
//!    section (never thinner than what carries its leaves, [`crate::physics::section_floor`])
//!    and length — in a chain, these bend under the propagated moments as a beam stepped at
//!    each segment's base section, stiffer than the tapered beam where a segment tapers. Its
//!    inertia is modal, `J = k/ω²` with ω its stem's first-mode
//!    frequency from the wood, sections and carried mass
//!    ([`crate::physics::stem_frequencies`]), so a stem sways at the tapered cantilever's
//!    frequency and branches at their own, higher ones. `J θ̈ + (c + s Γ) θ̇ + k θ = τ` with
//!    `c = 2 ζ √(k J)` (structural damping) is advanced by its exact solution over the step,
//!    so frequency and damping do not depend on the step. The air damps the joint as it
//!    would damp everything beyond it swinging about it, `Γ / (2 J_rigid ω)`: `s = J /
//!    J_rigid`, the modal inertia over that swing's. `J` gives a short, stiff joint its
//!    stem's frequency and is not that swing's inertia (at the base of a uniform cantilever
//!    in 20 segments, five times it; met with `J`, Γ damped that cantilever about a ninth as
//!    much as the air does, and less the finer it was cut). θ is a rotation vector in the
//!    parent's rest frame; the spring stiffens as `k (1 + (|θ|/θ_s)²)` at the bend the
//!    moment holds it at, and stops at `3 θ_s`, so joints do not spin through large angles.
//! 4. **Pose**: rotations `δ = exp(θ)` applied root to tip through the seam.

pub mod kernels;
pub mod raw;

pub use raw::*;

use super::{Animator, Method, MethodError, MethodOptions, Simulation, check};
use crate::leaves::LeafFlutter;
use crate::model::Tree;
use crate::pose::{Pose, SeamPose};
use crate::wind::PackedWind;
use kernels::{akagi_forces, akagi_integrate, akagi_subtree};
use std::sync::Arc;

use glam::Vec3;

/// Parameters of Akagi's method.
#[derive(Debug, Clone, Copy, PartialEq, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AkagiParams {
    /// Structural damping ratio ζ of every joint (≤ 0.9). Default
    /// [`crate::physics::STRUCTURAL_DAMPING`]; the air adds its own damping Γ, which rises
    /// with the wind.
    pub damping_ratio: f32,
    /// Drag coefficient of bark (a cylinder in cross-flow ≈ 1.0–1.2).
    pub drag: f32,
    /// Effective drag coefficient per unit (one-sided) leaf area
    /// ([`crate::physics::LEAF_DRAG`]; leaves and twigs of a crown so dense that they would
    /// drag more than the crown as a body are sheltered, [`crate::physics::crown_shelter`]).
    pub leaf_drag: f32,
    /// Substeps per `step` call.
    pub substeps: u32,
    /// Thinnest radius used for a joint's stiffness, m. Default 1.5 mm: generators taper
    /// twigs toward zero for looks, but living twig tips are 2–5 mm thick; without a floor
    /// the stiffness `E·π r⁴/4L` of a tip vanishes and it spins in the wind.
    pub min_radius: f32,
    /// Speed around which bark and leaves streamline, m/s (see
    /// [`crate::physics::DragModel`]; default 5).
    pub reconfiguration_speed: f32,
    /// Vogel exponent B: drag grows as `U^(2+B)` well above the reconfiguration speed
    /// (default −0.7, Vogel 1989).
    pub vogel_exponent: f32,
    /// Angle at which a joint has stiffened to twice its small-angle stiffness, rad: the
    /// spring is `k (1 + (|θ|/θ_s)²)` — wood stiffens and branches stop rotating as rigid
    /// segments well before they turn by a radian — and a joint bends at most `3 θ_s`.
    pub stiffening_angle: f32,
}

impl Default for AkagiParams {
    fn default() -> Self {
        Self {
            damping_ratio: crate::physics::STRUCTURAL_DAMPING,
            drag: 0.8,
            leaf_drag: crate::physics::LEAF_DRAG,
            substeps: 1,
            min_radius: crate::physics::MIN_RADIUS,
            reconfiguration_speed: 5.0,
            vogel_exponent: -0.7,
            stiffening_angle: 0.5,
        }
    }
}

impl AkagiParams {
    /// Checks every field's range.
    pub fn check(&self) -> Result<(), MethodError> {
        let m = "akagi";
        check(m, "damping_ratio", self.damping_ratio, (0.0..=0.9).contains(&self.damping_ratio), "0 to 0.9")?;
        check(m, "vogel_exponent", self.vogel_exponent, (-2.0..=0.0).contains(&self.vogel_exponent), "−2 to 0")?;
        check(m, "drag", self.drag, self.drag >= 0.0, "a finite number ≥ 0")?;
        check(m, "leaf_drag", self.leaf_drag, self.leaf_drag >= 0.0, "a finite number ≥ 0")?;
        check(m, "substeps", self.substeps as f32, (1..=1000).contains(&self.substeps), "1 to 1000")?;
        check(m, "min_radius", self.min_radius, self.min_radius >= 0.0, "a finite number ≥ 0 (m)")?;
        check(
            m,
            "reconfiguration_speed",
            self.reconfiguration_speed,
            self.reconfiguration_speed > 0.0,
            "a positive speed (m/s)",
        )?;
        check(m, "stiffening_angle", self.stiffening_angle, self.stiffening_angle > 0.0, "a positive angle (rad)")
    }
}

/// The registry's CPU constructor: Akagi's method on `tree` with `options`.
pub fn animator(tree: Arc<Tree>, options: &MethodOptions) -> Result<Box<dyn Animator>, MethodError> {
    let params = options.parse::<AkagiParams>("akagi")?;
    params.check()?;
    let method = Akagi::new(&tree, params);
    Ok(Simulation::boxed(tree, method))
}

/// Simulation state: structure of arrays in topological order.
#[derive(Debug, Clone, PartialEq)]
pub struct AkagiState {
    /// Rotation vector θ per segment (xyz, w unused), rad.
    pub theta: Vec<[f32; 4]>,
    /// Angular velocity per segment, rad/s.
    pub omega: Vec<[f32; 4]>,
    /// Accumulated rotations D of the current pose.
    pub acc: Vec<[f32; 4]>,
    /// Current pose.
    pub pose: Pose,
    /// Simulated time, s.
    pub time: f32,
}

/// Akagi's method set up for one tree.
#[derive(Debug, Clone)]
pub struct Akagi {
    /// Parameters.
    pub params: AkagiParams,
    /// Per-segment constants.
    pub segments: Vec<RawAkagiSegment>,
    /// Segment indices grouped by depth in the hierarchy, deepest first.
    pub buckets: Vec<Vec<u32>>,
    /// Its leaves' motion ([`crate::leaves`]).
    pub leaves: LeafFlutter,
    raw: Vec<crate::model::RawSegment>,
    rest: Vec<[f32; 4]>,
}

/// Inertia of everything beyond each joint (its segment and all it carries, wood and leaves)
/// swinging rigidly about it, `Σ m_j |x_j − p_i|²` with each segment's mass at its middle,
/// where the air's damping `Γ = Σ γ_j |x_j − p_i|²` takes its drag, kg·m². From the subtree's
/// sums of `m`, `m x` and `m |x|²` about the root, in f64.
fn swing_inertia(tree: &Tree) -> Vec<f64> {
    let s = &tree.segments;
    let origin = s.start.first().map_or(glam::DVec3::ZERO, |p| p.as_dvec3());
    let mass = crate::physics::beam::segment_masses(tree);
    let mut sums: Vec<(f64, glam::DVec3, f64)> = (0..s.len())
        .map(|i| {
            let x = s.start[i].as_dvec3() + s.axis(i).as_dvec3() * (0.5 * s.length[i] as f64) - origin;
            let m = mass[i] as f64;
            (m, x * m, m * x.length_squared())
        })
        .collect();
    for i in (0..s.len()).rev() {
        let (m, mx, mxx) = tree.children.of(i).iter().fold((0.0, glam::DVec3::ZERO, 0.0), |(a, b, c), &k| {
            let (m, mx, mxx) = sums[k as usize];
            (a + m, b + mx, c + mxx)
        });
        sums[i].0 += m;
        sums[i].1 += mx;
        sums[i].2 += mxx;
    }
    sums.iter()
        .enumerate()
        .map(|(i, &(m, mx, mxx))| {
            let p = s.start[i].as_dvec3() - origin;
            (mxx - 2.0 * p.dot(mx) + p.length_squared() * m).max(0.0)
        })
        .collect()
}

impl Akagi {
    /// Precomputes areas, stiffness, modal inertia, damping and the depth buckets.
    pub fn new(tree: &Tree, params: AkagiParams) -> Self {
        let s = &tree.segments;
        let n = s.len();
        let mut leaf_area = vec![0.0f32; n];
        for (k, &seg) in tree.leaves.segment.iter().enumerate() {
            leaf_area[seg as usize] += std::f32::consts::FRAC_PI_4 * tree.leaves.width[k] * tree.leaves.length[k];
        }
        let r_mech = crate::physics::bending_radii(tree, params.min_radius);
        let modes = crate::physics::stem_frequencies(tree, params.min_radius);
        let shelter = crate::physics::crown_shelter(tree, params.drag, params.leaf_drag);
        let swing = swing_inertia(tree);
        let segments = (0..n)
            .map(|i| {
                let k = tree.wood.segment_stiffness(s.length[i], r_mech[i]).max(1e-12);
                let mut w = modes.omega[s.stem[i] as usize];
                if !(w.is_finite() && w > 0.0) {
                    // A stem with no mass or compliance: a rod of its subtree's mass.
                    w = (3.0 * k / (modes.subtree_mass[i] * s.length[i] * s.length[i]).max(1e-12)).sqrt();
                }
                let inertia = (k / (w * w)).max(1e-12);
                RawAkagiSegment {
                    bark_area: if tree.stems.level[s.stem[i] as usize] == 0 { 1.0 } else { shelter }
                        * (s.radius_base[i] + s.radius_tip[i])
                        * s.length[i],
                    leaf_area: shelter * leaf_area[i] * params.leaf_drag / params.drag.max(1e-6),
                    inertia,
                    stiffness: k,
                    damping: 2.0 * params.damping_ratio * (k * inertia).sqrt(),
                    air_scale: if swing[i] > 0.0 { (inertia as f64 / swing[i]) as f32 } else { 1.0 },
                    _pad: [0; 2],
                }
            })
            .collect();
        // Deepest first: forces gather toward the root.
        let mut buckets = crate::pose::fk::depth_buckets(&s.parent);
        buckets.reverse();
        let rest = s.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        Self { params, segments, buckets, leaves: LeafFlutter::new(tree, tree.seed), raw: tree.raw_segments(), rest }
    }

    /// The per-step values the kernels read.
    pub fn step_params(&self, time: f32, dt: f32) -> RawAkagiStep {
        RawAkagiStep {
            drag: self.params.drag,
            time,
            dt,
            reconfiguration_speed: self.params.reconfiguration_speed,
            stiffening_angle: self.params.stiffening_angle,
            vogel_exponent: self.params.vogel_exponent,
            _pad: [0.0; 2],
        }
    }

    /// Natural angular frequency √(k/J) of segment `i`'s joint (its stem's first mode), rad/s.
    pub fn natural_frequency(&self, i: usize) -> f32 {
        (self.segments[i].stiffness / self.segments[i].inertia).sqrt()
    }
}

impl Method for Akagi {
    type State = AkagiState;

    fn name(&self) -> &'static str {
        "akagi"
    }

    fn rest_state(&self, tree: &Tree) -> AkagiState {
        let n = tree.segments.len();
        AkagiState {
            theta: vec![[0.0; 4]; n],
            omega: vec![[0.0; 4]; n],
            acc: vec![[0.0, 0.0, 0.0, 1.0]; n],
            pose: Pose::rest(tree),
            time: 0.0,
        }
    }

    fn step(&self, tree: &Tree, wind: &PackedWind, state: &mut AkagiState, dt: f32) {
        let (fields, waves) = (&wind.fields[..], &wind.waves[..]);
        let n = tree.segments.len();
        let sub = dt / self.params.substeps.max(1) as f32;
        let mut forces = vec![[0.0f32; 4]; 2 * n];
        let mut sums = vec![[0.0f32; 4]; 3 * n];
        let mut delta = vec![[0.0f32; 4]; n];
        let mut joints: Vec<[f32; 4]> = state.pose.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        for _ in 0..self.params.substeps.max(1) {
            let t = state.time + sub;
            let step = self.step_params(t, sub);
            akagi_forces(fields, waves, &self.raw, &self.segments, &joints, &state.acc, step, &mut forces);
            for bucket in &self.buckets {
                akagi_subtree(
                    bucket,
                    &tree.children.offset,
                    &tree.children.count,
                    &tree.children.index,
                    &forces,
                    &joints,
                    &mut sums,
                );
            }
            akagi_integrate(
                &self.raw,
                &self.segments,
                &sums,
                &state.acc,
                step,
                &mut state.theta,
                &mut state.omega,
                &mut delta,
            );
            crate::pose::fk::pose_forward(&tree.segments.parent, &self.rest, &delta, &mut state.acc, &mut joints);
            state.time = t;
        }
        for (i, j) in joints.iter().enumerate() {
            state.pose.start[i] = Vec3::new(j[0], j[1], j[2]);
            state.pose.orientation[i] = glam::Quat::from_array(state.acc[i]) * tree.segments.orientation[i];
        }
    }

    fn time(&self, state: &AkagiState) -> f32 {
        state.time
    }

    fn set_time(&self, state: &mut AkagiState, time: f32) {
        state.time = time;
    }

    fn seam(&self, _tree: &Tree, wind: &PackedWind, state: &AkagiState, out: &mut SeamPose) {
        out.joints.clear();
        out.joints.extend(state.pose.start.iter().map(|p| p.extend(0.0).to_array()));
        out.acc.clone_from(&state.acc);
        self.leaves.seam(wind, self.time(state), out);
    }

    fn pose(&self, _tree: &Tree, _wind: &PackedWind, state: &AkagiState) -> Pose {
        state.pose.clone()
    }
}

/// Largest displacement of any segment end from rest, m.
pub fn max_tip_displacement(tree: &Tree, pose: &Pose) -> f32 {
    (0..tree.segments.len()).map(|i| (pose.end(tree, i) - tree.segments.end(i)).length()).fold(0.0, f32::max)
}

/// Mean displacement of segment ends from rest.
pub fn mean_shift(tree: &Tree, pose: &Pose) -> Vec3 {
    crate::pose::displacement(tree, pose).crown_mean
}
