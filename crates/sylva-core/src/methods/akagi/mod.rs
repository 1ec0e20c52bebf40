//! Akagi & Kitajima's sway by force propagation (§2.5), with the dynamics a real tool needs.
//!
//! Each step:
//! 1. **Forces** (`kernels::akagi_forces`): the wind at each segment's current centre
//!    pushes on its bark, `½ ρ C_d (2 r̄ L |sin φ|) U² v̂` (φ between the segment and the
//!    flow: a cylinder's projected area), and on its leaves, `½ ρ C_d A_leaf U² v̂`.
//! 2. **Propagation** (`akagi_subtree`): each segment's force plus the summed forces of its
//!    children, from the tips toward the root — one pass per depth of the hierarchy,
//!    deepest first (the GPU runs one dispatch per depth).
//! 3. **Rotation** (`akagi_integrate`): the component of that force perpendicular to the
//!    segment, at its tip, gives the torque `τ = L (â × F)`; the segment turns about its
//!    base against the rotational stiffness `k = E·I/L` (with the mechanical radius: the
//!    model's, but never thinner than its children together, Leonardo's rule, nor than
//!    `min_radius`) as a damped angular spring,
//!    `I θ̈ = τ − k θ − c θ̇`, with `I` the subtree's moment of inertia about the joint and
//!    `c = 2 ζ √(k I)`. Integration is implicit in the spring and damping terms, so it is
//!    stable for any step. θ is a rotation vector in the parent's rest frame.
//!    Two additions keep strong wind physical: drag grows as `U^1.3` above
//!    `reconfiguration_speed` (leaves streamline, Vogel 1989), and the spring stiffens as
//!    `k (1 + (|θ|/θ_s)²)` so joints do not spin through large angles.
//! 4. **Pose**: rotations `δ = exp(θ)` applied root to tip through the seam.

pub mod kernels;
pub mod raw;

pub use raw::*;

use super::{Animator, Method, MethodError, MethodOptions, Simulation, check};
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
    /// Damping ratio ζ of every joint. Default 0.15: measured damping ratios of tree sway
    /// are 0.05–0.3 (aerodynamic and internal damping together).
    pub damping_ratio: f32,
    /// Drag coefficient of bark (a cylinder in cross-flow ≈ 1.0–1.2).
    pub drag: f32,
    /// Effective drag coefficient per unit (one-sided) leaf area. Default 0.05: leaves in a
    /// crown shelter one another, so the sum over leaves must come to a crown's drag
    /// (C_d ≈ 0.3 on the crown's frontal area, which for a broadleaf crown is 5–10 times
    /// smaller than its leaf area).
    pub leaf_drag: f32,
    /// Substeps per `step` call.
    pub substeps: u32,
    /// Thinnest radius used for a joint's stiffness, m. Default 1.5 mm: generators taper
    /// twigs toward zero for looks, but living twig tips are 2–5 mm thick; without a floor
    /// the stiffness `E·π r⁴/4L` of a tip vanishes and it spins in the wind.
    pub min_radius: f32,
    /// Speed above which bark and leaves streamline, m/s: drag grows as `U^(2 − 0.7)`
    /// beyond it instead of `U²` (Vogel 1989: leaves and crowns reconfigure in strong wind,
    /// with Vogel exponents around −0.7).
    pub reconfiguration_speed: f32,
    /// Angle at which a joint has stiffened to twice its small-angle stiffness, rad: the
    /// spring is `k (1 + (|θ|/θ_s)²)` — wood stiffens and branches stop rotating as rigid
    /// segments well before they turn by a radian.
    pub stiffening_angle: f32,
}

impl Default for AkagiParams {
    fn default() -> Self {
        Self {
            damping_ratio: 0.15,
            drag: 0.8,
            leaf_drag: 0.05,
            substeps: 1,
            min_radius: 0.0015,
            reconfiguration_speed: 5.0,
            stiffening_angle: 0.5,
        }
    }
}

impl AkagiParams {
    /// Checks every field's range.
    pub fn check(&self) -> Result<(), MethodError> {
        let m = "akagi";
        check(m, "damping_ratio", self.damping_ratio, (0.0..=10.0).contains(&self.damping_ratio), "0 to 10")?;
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
    raw: Vec<crate::model::RawSegment>,
    rest: Vec<[f32; 4]>,
}

impl Akagi {
    /// Precomputes areas, subtree inertia, stiffness, damping and the depth buckets.
    pub fn new(tree: &Tree, params: AkagiParams) -> Self {
        let s = &tree.segments;
        let n = s.len();
        let leaf_mass_per_area = tree.wood.leaf_areal_density;
        let mut leaf_area = vec![0.0f32; n];
        for (k, &seg) in tree.leaves.segment.iter().enumerate() {
            leaf_area[seg as usize] += std::f32::consts::FRAC_PI_4 * tree.leaves.width[k] * tree.leaves.length[k];
        }
        // Subtree mass and inertia about each joint, tips first (children have larger indices).
        let mut mass = vec![0.0f32; n];
        let mut inertia = vec![0.0f32; n];
        for i in (0..n).rev() {
            let l = s.length[i];
            let m = s.mass[i] + leaf_area[i] * leaf_mass_per_area;
            let mut m_sub = m;
            let mut inert = m * l * l / 3.0;
            for &c in tree.children.of(i) {
                let c = c as usize;
                let d = (s.start[c] - s.start[i]).length_squared();
                m_sub += mass[c];
                inert += inertia[c] + mass[c] * d;
            }
            mass[i] = m_sub;
            inertia[i] = inert.max(1e-12);
        }
        let r_mech = crate::physics::mechanical_radii(tree, params.min_radius);
        let segments = (0..n)
            .map(|i| {
                let k = tree.wood.segment_stiffness(s.length[i], r_mech[i]);
                RawAkagiSegment {
                    bark_area: (s.radius_base[i] + s.radius_tip[i]) * s.length[i],
                    leaf_area: leaf_area[i] * params.leaf_drag / params.drag.max(1e-6),
                    inertia: inertia[i],
                    stiffness: k,
                    damping: 2.0 * params.damping_ratio * (k * inertia[i]).sqrt(),
                    _pad: [0; 3],
                }
            })
            .collect();
        // Deepest first: forces gather toward the root.
        let mut buckets = crate::pose::fk::depth_buckets(&s.parent);
        buckets.reverse();
        let rest = s.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        Self { params, segments, buckets, raw: tree.raw_segments(), rest }
    }

    /// The per-step values the kernels read.
    pub fn step_params(&self, time: f32, dt: f32) -> RawAkagiStep {
        RawAkagiStep {
            drag: self.params.drag,
            time,
            dt,
            reconfiguration_speed: self.params.reconfiguration_speed,
            stiffening_angle: self.params.stiffening_angle,
            _pad: [0.0; 3],
        }
    }

    /// Natural angular frequency √(k/I) of segment `i`'s joint, rad/s.
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
        let mut f_own = vec![[0.0f32; 4]; n];
        let mut f_sub = vec![[0.0f32; 4]; n];
        let mut delta = vec![[0.0f32; 4]; n];
        let mut joints: Vec<[f32; 4]> = state.pose.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        for _ in 0..self.params.substeps.max(1) {
            let t = state.time + sub;
            let step = self.step_params(t, sub);
            akagi_forces(fields, waves, &self.raw, &self.segments, &joints, &state.acc, step, &mut f_own);
            for bucket in &self.buckets {
                akagi_subtree(
                    bucket,
                    &tree.children.offset,
                    &tree.children.count,
                    &tree.children.index,
                    &f_own,
                    &mut f_sub,
                );
            }
            akagi_integrate(
                &self.raw,
                &self.segments,
                &f_sub,
                &state.acc,
                step,
                &mut state.theta,
                &mut state.omega,
                &mut delta,
            );
            crate::pose::fk::pose_accumulate(&tree.segments.parent, &delta, &mut state.acc);
            crate::pose::fk::pose_positions(&tree.segments.parent, &self.rest, &state.acc, &mut joints);
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

    fn seam(&self, _tree: &Tree, _wind: &PackedWind, state: &AkagiState, out: &mut SeamPose) {
        out.joints.clear();
        out.joints.extend(state.pose.start.iter().map(|p| p.extend(0.0).to_array()));
        out.acc.clone_from(&state.acc);
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
