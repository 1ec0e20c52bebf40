//! Akagi & Kitajima's sway by force propagation (§2.5), with the dynamics a real tool needs.
//!
//! Each step:
//! 1. **Forces** (`cpu::akagi::akagi_forces`): the wind at each segment's current centre
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

use super::Pose;
use crate::cpu::akagi::{akagi_forces, akagi_integrate, akagi_subtree};
use crate::model::Tree;
use crate::wind::WindScene;
use crate::wind::raw::{RawField, RawWave};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// Parameters of Akagi's method.
#[derive(Debug, Clone, Copy, PartialEq)]
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

/// Per-segment constants, 32 bytes. WGSL: `AkagiSegment` in `akagi.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawAkagiSegment {
    /// Bark area facing a cross-flow, 2 r̄ L, m².
    pub bark_area: f32,
    /// Leaf area on the segment scaled by `leaf_drag / drag`, so one coefficient serves
    /// both: m².
    pub leaf_area: f32,
    /// Moment of inertia of the subtree about the joint, kg·m².
    pub inertia: f32,
    /// Rotational stiffness, N·m/rad.
    pub stiffness: f32,
    /// Damping, N·m·s/rad.
    pub damping: f32,
    /// Padding.
    pub _pad: [u32; 3],
}

/// Per-step values, 32 bytes. WGSL: `AkagiStep` in `akagi.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawAkagiStep {
    /// Drag coefficient.
    pub drag: f32,
    /// Time at the end of the step, s.
    pub time: f32,
    /// Step, s.
    pub dt: f32,
    /// See [`AkagiParams::reconfiguration_speed`].
    pub reconfiguration_speed: f32,
    /// See [`AkagiParams::stiffening_angle`].
    pub stiffening_angle: f32,
    /// Padding.
    pub _pad: [f32; 3],
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
        let r_mech = super::mechanical_radii(tree, params.min_radius);
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
        let mut buckets = crate::cpu::pose_fk::depth_buckets(&s.parent);
        buckets.reverse();
        let rest = s.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        Self { params, segments, buckets, raw: tree.raw_segments(), rest }
    }

    /// The state at rest.
    pub fn rest_state(&self, tree: &Tree) -> AkagiState {
        let n = tree.segments.len();
        AkagiState {
            theta: vec![[0.0; 4]; n],
            omega: vec![[0.0; 4]; n],
            acc: vec![[0.0, 0.0, 0.0, 1.0]; n],
            pose: Pose::rest(tree),
            time: 0.0,
        }
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

    /// Advances `state` by `dt` seconds (in `params.substeps` substeps) in `wind`.
    pub fn step(&self, tree: &Tree, fields: &[RawField], waves: &[RawWave], state: &mut AkagiState, dt: f32) {
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
            crate::cpu::pose_fk::pose_accumulate(&tree.segments.parent, &delta, &mut state.acc);
            crate::cpu::pose_fk::pose_positions(&tree.segments.parent, &self.rest, &state.acc, &mut joints);
            state.time = t;
        }
        for (i, j) in joints.iter().enumerate() {
            state.pose.start[i] = Vec3::new(j[0], j[1], j[2]);
            state.pose.orientation[i] = glam::Quat::from_array(state.acc[i]) * tree.segments.orientation[i];
        }
    }

    /// Convenience: steps a scene (packs it each call).
    pub fn step_scene(&self, tree: &Tree, wind: &WindScene, state: &mut AkagiState, dt: f32) {
        let (f, w) = wind.pack();
        self.step(tree, &f, &w, state, dt);
    }
}

/// Largest displacement of any segment end from rest, m.
pub fn max_tip_displacement(tree: &Tree, pose: &Pose) -> f32 {
    (0..tree.segments.len()).map(|i| (pose.end(tree, i) - tree.segments.end(i)).length()).fold(0.0, f32::max)
}

/// Mean displacement of segment ends from rest.
pub fn mean_shift(tree: &Tree, pose: &Pose) -> Vec3 {
    super::displacement(tree, pose).crown_mean
}
