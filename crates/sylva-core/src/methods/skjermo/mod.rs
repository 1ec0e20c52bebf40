//! Skjermo's Bézier bending (§4): every stem is one cubic Bézier whose control points are
//! re-attached to the parent's curve and bent by the wind each step.
//!
//! Each step, for every stem in parallel (`kernels::skjermo_step`):
//! 1. **Re-attach** (§4.2) on the parent's curve *from the previous step*: P0 at the attachment
//!    parameter, and the stem's rest control points carried by the attachment frame. At rest
//!    that frame is built from the parent curve's derivative there and the parent's
//!    orientation vector O (`[T, N, B]` with `N` the part of O normal to T — Sloan's handle
//!    construction, eq. 8). As the parent bends, the rest frame turns by the shortest arc
//!    from the rest tangent to the current one ([`transported_frame`]). Projecting O on the
//!    current tangent instead twists a child about its parent wherever O is far from normal
//!    to that tangent (a curved parent). On the aspen in `gusty` that twist swung the twigs'
//!    tips 12 mm RMS at the gusts' pace, against 3 mm of their own bending. A trunk keeps its
//!    base.
//! 2. **Wind**: the scene's velocity F at the re-attached tip P3.
//! 3. **Bend** (eqs. 15–17): bend factors `b₃ = c F̂·1^e`, `b₂ = c F̂·(1/3)^e` with the
//!    published exponent e = 1.8 (configurable), where `c = L θ` scales by the stem's length
//!    and its static bend `θ = min(max_bend, drag · |F|²)`; then
//!    `P'ᵢ = P'ᵢ₋₁ + |Pᵢ − Pᵢ₋₁| · normalize(Pᵢ − Pᵢ₋₁ + bᵢ)` for i = 2, 3, which keeps the
//!    control polygon's lengths (P0, P1 stay: the branch grows out of its parent).
//!
//! **The bend as a damped oscillator** (`dynamics`, on by default). Published, `b₃` follows
//! the wind at once: a stem has no frequency and stops dead when the wind does. Here `b₃`
//! is each stem's first bending mode driven toward the static push `c F̂`:
//! `b¨ + (2ζω + a_air u) b˙ + ω² (b − c F̂) = 0`, stepped exactly
//! ([`crate::physics::oscillator`]), so the frequency does not depend on the time step.
//! * ω: the stem's first mode from its wood, sections and everything it carries
//!   ([`crate::physics::beam`], Rayleigh's quotient); ζ: wood's structural damping.
//! * The drag factor is set so that the tip's static deflection, `(1 + (1/3)^e) c`, is the
//!   beam's under the drag on the stem and everything growing from it
//!   (`physics::beam::drag_bend`), `½ ρ u²` on each segment's `C_d A` of bark and
//!   leaves.
//! * Aerodynamic damping from drag on a moving stem, `F(w − v)`: linearised about the wind,
//!   the push drops by `2 c/u` per m/s the drag's point of work moves downwind, which moves
//!   at `DragBend::damping_centre` of the tip's speed (each part weighed by how far it moves
//!   with the stem's mode); applied implicitly.
//!
//! Because a stem reads its parent's previous curve, motion reaches level d one step after
//! level d − 1: **level d lags d steps** behind the trunk (§5); at 60 steps/s a four-level
//! tree's twigs answer 50 ms late. Buffers ping-pong between steps (GPU and CPU alike).
//!
//! Control points are kept as displacements from rest so still air reproduces the rest
//! curves exactly. The pose's segments turn with their stem's tangent (rest → current, at
//! the segment's middle) through the pose seam, so lengths are kept and `Pose::bezier`
//! carries the animated curves for the deformer.

pub mod kernels;
pub mod lanes;
pub mod raw;

pub use raw::*;

use self::lanes::{LANES, LaneStep, OscLanes, StateLanes, StemLanes, SwayLanes};
use super::{Animator, Method, MethodError, MethodOptions, Simulation, check};
use crate::leaves::LeafFlutter;
use crate::model::{NONE, Tree};
use crate::pose::{Curves, Pose, SeamPose};
use crate::wind::PackedWind;
use crate::wind::raw::{RawField, RawWave};
use bytemuck::Zeroable;
use glam::{Vec3, Vec4};
use kernels::{skjermo_rotations, skjermo_step};
use rayon::prelude::*;
use std::sync::Arc;

/// Parameters of Skjermo's method.
#[derive(Debug, Clone, Copy, PartialEq, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SkjermoParams {
    /// Exponent e of eq. 16 (published: 1.8).
    pub exponent: f32,
    /// Weight of P2's bend factor before the exponent (printed: 1/3).
    pub p2_weight: f32,
    /// Largest static bend of a stem, rad (0.6: branches past ~35° in wind break or shed).
    pub max_bend: f32,
    /// Drag coefficient C_d of bark ([`crate::physics::BRANCH_DRAG`]).
    pub drag: f32,
    /// Effective drag coefficient per unit leaf area ([`crate::physics::LEAF_DRAG`]; leaves
    /// and twigs of a crown so dense that they would drag more than the crown as a body are
    /// sheltered, [`crate::physics::crown_shelter`]).
    pub leaf_drag: f32,
    /// The bend follows the wind as each stem's damped first mode (true), or at once as
    /// published (false).
    pub dynamics: bool,
    /// Reconfiguration speed U_r, m/s: above it drag grows as `u^(2+B)`
    /// ([`crate::physics::DragModel`]).
    pub reconfiguration_speed: f32,
    /// Vogel exponent B (−0.7, Vogel 1989; 0 keeps drag quadratic).
    pub vogel_exponent: f32,
    /// Structural damping ratio ζ of the wood ([`crate::physics::STRUCTURAL_DAMPING`]); the
    /// air's damping adds to it and grows with the wind.
    pub damping_ratio: f32,
}

impl Default for SkjermoParams {
    fn default() -> Self {
        Self {
            exponent: 1.8,
            p2_weight: 1.0 / 3.0,
            max_bend: 0.6,
            drag: crate::physics::BRANCH_DRAG,
            leaf_drag: crate::physics::LEAF_DRAG,
            dynamics: true,
            reconfiguration_speed: crate::physics::DragModel::default().reconfiguration_speed,
            vogel_exponent: crate::physics::DragModel::default().vogel_exponent,
            damping_ratio: crate::physics::STRUCTURAL_DAMPING,
        }
    }
}

/// Skjermo's method set up for one tree.
#[derive(Debug, Clone)]
pub struct Skjermo {
    /// Parameters.
    pub params: SkjermoParams,
    /// Per-stem constants (after editing them, call [`Skjermo::rebuild_lanes`]).
    pub stems: Vec<RawSkjermoStem>,
    /// Rest orientation vector of each stem.
    pub rest_orient: Vec<[f32; 4]>,
    /// Per-stem oscillator constants (after editing them, call [`Skjermo::rebuild_lanes`]).
    pub modes: Vec<RawSkjermoMode>,
    /// Per-segment (stem, Bézier parameter of the segment's middle).
    pub segment_param: Vec<[f32; 4]>,
    /// The per-stem constants in groups of sixteen for the fast CPU step.
    pub lanes: Vec<StemLanes>,
    /// Its leaves' motion ([`crate::leaves`]).
    pub leaves: LeafFlutter,
    rest_lanes: Vec<StateLanes>,
}

/// State: per-stem displacements (current), time and the current pose.
#[derive(Debug, Clone, PartialEq)]
pub struct SkjermoState {
    /// Per-stem state.
    pub stems: Vec<RawSkjermoState>,
    /// Per-stem bend oscillators.
    pub sway: Vec<RawSkjermoSway>,
    /// Steps taken.
    pub steps: u64,
    /// Simulated time, s.
    pub time: f32,
    /// Current pose (with Béziers).
    pub pose: Pose,
    /// Accumulated rotations D of the current pose (the seam's buffer).
    pub acc: Vec<[f32; 4]>,
    /// The per-stem displacements in groups of sixteen (what the CPU step reads and writes;
    /// `stems` is copied from it after every step).
    pub lanes: Vec<StateLanes>,
    scratch: Vec<StateLanes>,
    /// The bend oscillators in groups of sixteen (the CPU step updates them in place; `sway`
    /// is copied from them after every step).
    pub sway_lanes: Vec<SwayLanes>,
    /// The oscillators' step coefficients per group for the step length `.0`.
    coefficients: (f32, Vec<OscLanes>),
}

/// Bézier point.
pub fn bezier(p: &[Vec3; 4], t: f32) -> Vec3 {
    let s = 1.0 - t;
    p[0] * (s * s * s) + p[1] * (3.0 * s * s * t) + p[2] * (3.0 * s * t * t) + p[3] * (t * t * t)
}

/// Bézier derivative.
pub fn bezier_d(p: &[Vec3; 4], t: f32) -> Vec3 {
    let s = 1.0 - t;
    (p[1] - p[0]) * (3.0 * s * s) + (p[2] - p[1]) * (6.0 * s * t) + (p[3] - p[2]) * (3.0 * t * t)
}

/// `v` normalised (by one reciprocal) where longer than 1e-6, else `fallback`. WGSL:
/// `unit_or` in `skjermo.wgsl`; the lane path (`skjermo_lanes`) rounds the same way, so the
/// rest frames it stores match these bit for bit.
pub fn unit_or(v: Vec3, fallback: Vec3) -> Vec3 {
    let l = v.length();
    if l > 1e-6 { v * (1.0 / l) } else { fallback }
}

/// The attachment frame `[T, N, B]` at `t` with orientation vector `o` (columns as arrays).
pub fn frame(p: &[Vec3; 4], o: Vec3, t: f32) -> [Vec3; 3] {
    frame_from_tangent(bezier_d(p, t), o)
}

/// The attachment frame from a curve tangent (not necessarily unit) and an orientation vector.
pub fn frame_from_tangent(tangent: Vec3, o: Vec3) -> [Vec3; 3] {
    let tan = unit_or(tangent, Vec3::Y);
    let n = unit_or(o - tan * o.dot(tan), unit_or(tan.any_orthogonal_vector(), Vec3::X));
    [tan, n, tan.cross(n)]
}

/// The attachment frame now: the rest frame `rest` turned by the shortest arc from its tangent
/// to the parent curve's `tangent` now (not necessarily unit), so a child turns with its
/// parent's bend and does not twist about it. Where the tangent is the rest one (still air)
/// this is `rest` itself, bit for bit; where it has turned half round, the rest normal. The
/// normal is made normal to the tangent again after the turn. WGSL: `transported_frame` in
/// `skjermo.wgsl`.
pub fn transported_frame(rest: &[Vec3; 3], tangent: Vec3) -> [Vec3; 3] {
    let t = unit_or(tangent, Vec3::Y);
    if t == rest[0] {
        return *rest;
    }
    let (k, c) = (rest[0].cross(t), rest[0].dot(t));
    let x = rest[1];
    let m = if 1.0 + c > 1e-6 { x * c + k.cross(x) + k * (k.dot(x) / (1.0 + c)) } else { x };
    let n = unit_or(m - t * m.dot(t), unit_or(t.any_orthogonal_vector(), Vec3::X));
    [t, n, t.cross(n)]
}

fn closest_param(p: &[Vec3; 4], q: Vec3) -> f32 {
    let mut best = (f32::MAX, 0.0f32);
    for k in 0..=256 {
        let t = k as f32 / 256.0;
        let d = (bezier(p, t) - q).length_squared();
        if d < best.0 {
            best = (d, t);
        }
    }
    best.1
}

impl Skjermo {
    /// Precomputes rest control points, attachment parameters and frames.
    pub fn new(tree: &Tree, params: SkjermoParams) -> Self {
        let st = &tree.stems;
        let s = &tree.segments;
        let ctrl = |k: usize| st.bezier[k];
        let mut stems = Vec::with_capacity(st.len());
        let mut rest_orient = vec![[0.0f32; 4]; st.len()];
        let min_radius = crate::physics::MIN_RADIUS;
        let beam = crate::physics::stem_frequencies(tree, min_radius);
        let shelter = crate::physics::crown_shelter(tree, params.drag, params.leaf_drag);
        let cd_area = crate::physics::beam::drag_areas(tree, params.drag, params.leaf_drag, shelter);
        let bend = crate::physics::beam::drag_bend(tree, min_radius, &cd_area);
        // The tip moves by b₂ + b₃ = (1 + p2_factor) b₃.
        let tip_gain = 1.0 + params.p2_weight.powf(params.exponent);
        let pressure = 0.5 * crate::physics::AIR_DENSITY;
        for k in 0..st.len() {
            let p = ctrl(k);
            let (attach, f) = if st.parent[k] == NONE {
                let f = frame(&p, Vec3::X, 0.0);
                (0.0, f)
            } else {
                let pk = st.parent[k] as usize;
                let pp = ctrl(pk);
                let a = closest_param(&pp, p[0]);
                let o = Vec3::from_slice(&rest_orient[pk][..3]);
                (a, frame(&pp, o, a))
            };
            // This stem's own orientation vector: its frame's normal, carried with the frame.
            rest_orient[k] = f[1].extend(0.0).to_array();
            let base = if st.parent[k] == NONE { p[0] } else { bezier(&ctrl(st.parent[k] as usize), attach) };
            let local = [0, 1, 2, 3].map(|j| {
                let d = p[j] - base;
                Vec4::new(d.dot(f[0]), d.dot(f[1]), d.dot(f[2]), 0.0).to_array()
            });
            stems.push(RawSkjermoStem {
                rest: p.map(|q| q.extend(1.0).to_array()),
                local,
                parent: st.parent[k],
                attach,
                drag: pressure * bend.tip[k] / (st.length[k].max(1e-4) * tip_gain),
                length: st.length[k],
                parent_orient: if st.parent[k] == NONE { [0.0; 4] } else { rest_orient[st.parent[k] as usize] },
            });
        }
        // Each segment's middle as a parameter on its stem's curve.
        let segment_param = (0..s.len())
            .map(|i| {
                let k = s.stem[i] as usize;
                let mid = s.start[i] + s.axis(i) * (0.5 * s.length[i]);
                [f32::from_bits(k as u32), closest_param(&ctrl(k), mid), 0.0, 0.0]
            })
            .collect();
        let modes = stems
            .iter()
            .zip(beam.omega.iter().zip(&bend.damping_centre))
            .map(|(stem, (&w, &centre))| RawSkjermoMode {
                w2: w * w,
                damping: params.damping_ratio * w,
                aero: w * w * 2.0 * centre * tip_gain * stem.length * stem.drag,
                _pad: 0.0,
            })
            .collect::<Vec<_>>();
        let (lanes, rest_lanes) = lanes::build(&stems, &modes);
        Self {
            params,
            stems,
            rest_orient,
            modes,
            segment_param,
            lanes,
            rest_lanes,
            leaves: LeafFlutter::new(tree, tree.seed),
        }
    }

    /// Rebuilds the fast path's lane groups from `stems` (after editing them).
    pub fn rebuild_lanes(&mut self) {
        (self.lanes, self.rest_lanes) = lanes::build(&self.stems, &self.modes);
    }

    /// Per-step values.
    pub fn step_params(&self, time: f32) -> RawSkjermoStep {
        RawSkjermoStep {
            time,
            exponent: self.params.exponent,
            p2_weight: self.params.p2_weight,
            max_bend: self.params.max_bend,
            dt: 0.0,
            dynamics: self.params.dynamics as u32,
            reconfiguration_speed: self.params.reconfiguration_speed,
            vogel_exponent: self.params.vogel_exponent,
        }
    }

    /// Per-step values of the fast CPU step.
    pub fn lane_step(&self, time: f32, dt: f32) -> LaneStep {
        LaneStep {
            time,
            dt,
            p2_factor: self.params.p2_weight.powf(self.params.exponent),
            max_bend: self.params.max_bend,
            dynamics: self.params.dynamics,
            reconfiguration_speed: self.params.reconfiguration_speed,
            vogel_exponent: self.params.vogel_exponent,
        }
    }

    /// Advances only the stems' curves one step of `dt` seconds (no pose): every stem
    /// re-attaches to its parent's previous curve and bends; the two lane buffers ping-pong.
    /// This is the branch update Skjermo's figures count.
    pub fn step_stems(&self, fields: &[RawField], waves: &[RawWave], state: &mut SkjermoState, dt: f32) {
        let t = state.time + dt;
        if state.coefficients.0 != dt || state.coefficients.1.len() != self.lanes.len() {
            state.coefficients = (dt, lanes::coefficients(&self.modes, dt));
        }
        lanes::step(
            crate::simd::level(),
            fields,
            waves,
            &self.lanes,
            &state.coefficients.1,
            &state.lanes,
            &mut state.sway_lanes,
            self.lane_step(t, dt),
            &mut state.scratch,
        );
        std::mem::swap(&mut state.lanes, &mut state.scratch);
        state.time = t;
        state.steps += 1;
    }

    /// The same step through the reference kernel (`kernels::skjermo_step`, the twin of
    /// the WGSL), one stem at a time, on `state.stems` only; kept to check the fast path
    /// against.
    pub fn step_reference(&self, fields: &[RawField], waves: &[RawWave], state: &mut SkjermoState, dt: f32) {
        let t = state.time + dt;
        let mut next = state.stems.clone();
        let step = RawSkjermoStep { dt, ..self.step_params(t) };
        skjermo_step(fields, waves, &self.stems, &state.stems, step, &mut next, &self.modes, &mut state.sway);
        state.stems = next;
        state.time = t;
        state.steps += 1;
    }

    /// The pose (segment transforms and animated Béziers) from `state.stems`.
    pub fn update_pose(&self, tree: &Tree, state: &mut SkjermoState) {
        let mut delta = vec![[0.0f32; 4]; tree.segments.len()];
        skjermo_rotations(&self.segment_param, &self.stems, &state.stems, &tree.segments.parent, &mut delta);
        let (joints, acc) = crate::pose::seam_buffers(tree, &delta);
        let mut pose = Pose::from_seam(tree, &joints, &acc);
        state.acc = acc;
        pose.bezier = Some(
            self.stems
                .iter()
                .zip(&state.stems)
                .map(|(r, s)| {
                    [0, 1, 2, 3].map(|j| Vec3::from_slice(&r.rest[j][..3]) + Vec3::from_slice(&s.delta[j][..3]))
                })
                .collect(),
        );
        state.pose = pose;
    }
}

impl SkjermoParams {
    /// Checks every field's range.
    pub fn check(&self) -> Result<(), MethodError> {
        let m = "skjermo";
        check(m, "exponent", self.exponent, self.exponent > 0.0 && self.exponent <= 16.0, "0 to 16")?;
        check(m, "p2_weight", self.p2_weight, (0.0..=1.0).contains(&self.p2_weight), "0 to 1")?;
        check(m, "max_bend", self.max_bend, self.max_bend > 0.0 && self.max_bend <= 3.2, "0 to π rad")?;
        check(m, "drag", self.drag, self.drag >= 0.0, "a finite number ≥ 0")?;
        check(m, "leaf_drag", self.leaf_drag, self.leaf_drag >= 0.0, "a finite number ≥ 0")?;
        check(
            m,
            "reconfiguration_speed",
            self.reconfiguration_speed,
            self.reconfiguration_speed > 0.0,
            "a number > 0 m/s",
        )?;
        check(m, "vogel_exponent", self.vogel_exponent, (-2.0..=0.0).contains(&self.vogel_exponent), "−2 to 0")?;
        check(m, "damping_ratio", self.damping_ratio, (0.0..=2.0).contains(&self.damping_ratio), "0 to 2")
    }
}

/// The registry's CPU constructor: Skjermo's method on `tree` with `options`.
pub fn animator(tree: Arc<Tree>, options: &MethodOptions) -> Result<Box<dyn Animator>, MethodError> {
    let params = options.parse::<SkjermoParams>("skjermo")?;
    params.check()?;
    let method = Skjermo::new(&tree, params);
    Ok(Simulation::boxed(tree, method))
}

impl Method for Skjermo {
    type State = SkjermoState;

    fn name(&self) -> &'static str {
        "skjermo"
    }

    fn rest_state(&self, tree: &Tree) -> SkjermoState {
        SkjermoState {
            stems: vec![RawSkjermoState { delta: [[0.0; 4]; 4] }; self.stems.len()],
            sway: vec![RawSkjermoSway::zeroed(); self.stems.len()],
            steps: 0,
            time: 0.0,
            pose: Pose { bezier: Some(tree.stems.bezier.clone()), ..Pose::rest(tree) },
            acc: vec![[0.0, 0.0, 0.0, 1.0]; tree.segments.len()],
            lanes: self.rest_lanes.clone(),
            scratch: self.rest_lanes.clone(),
            sway_lanes: vec![SwayLanes::default(); self.rest_lanes.len()],
            coefficients: (0.0, Vec::new()),
        }
    }

    /// One step of `dt` seconds: all stems re-attach to their parents' previous curves and
    /// bend (ping-pong, sixteen stems at a time), then the pose follows.
    fn step(&self, tree: &Tree, wind: &PackedWind, state: &mut SkjermoState, dt: f32) {
        self.step_stems(&wind.fields, &wind.waves, state, dt);
        let (lanes, sway) = (&state.lanes, &state.sway_lanes);
        state.stems.par_iter_mut().zip(state.sway.par_iter_mut()).enumerate().for_each(|(k, (s, sw))| {
            let (g, o) = (&lanes[k / LANES], &sway[k / LANES]);
            let l = k % LANES;
            *s = RawSkjermoState { delta: [0, 1, 2, 3].map(|j| g.delta(l, j).extend(0.0).to_array()) };
            *sw = RawSkjermoSway {
                bend: o.bend.lane(l).extend(0.0).to_array(),
                rate: o.rate.lane(l).extend(0.0).to_array(),
            };
        });
        self.update_pose(tree, state);
    }

    fn time(&self, state: &SkjermoState) -> f32 {
        state.time
    }

    fn set_time(&self, state: &mut SkjermoState, time: f32) {
        state.time = time;
    }

    fn seam(&self, _tree: &Tree, wind: &PackedWind, state: &SkjermoState, out: &mut SeamPose) {
        out.joints.clear();
        out.joints.extend(state.pose.start.iter().map(|p| p.extend(0.0).to_array()));
        out.acc.clone_from(&state.acc);
        self.leaves.seam(wind, self.time(state), out);
    }

    fn pose(&self, _tree: &Tree, _wind: &PackedWind, state: &SkjermoState) -> Pose {
        state.pose.clone()
    }

    fn curves<'a>(&'a self, state: &'a SkjermoState) -> Option<Curves<'a>> {
        Some(Curves { stems: &self.stems, state: &state.stems })
    }
}
