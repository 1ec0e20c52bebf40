//! Zioma's procedural wind animation (GPU Gems 3, ch. 6, §6.3–6.5).
//!
//! Stateless but for one ring: the pose at time t is a function of (tree, wind, t) and, once
//! the wind has changed, of the trunk's ring-down since ([`trunk::Ring`], a closed form in
//! t too). The stateless entry points ([`Zioma::pose_at`], [`Zioma::rotations_packed`],
//! [`Zioma::rotations_instances`]) take the wind as blowing since t = 0 from still air: the
//! tree starts upright and swings into its lean. Each instance rings by its own ring, taken
//! at its own crown (the wind differs from one to the next), so a forest's trunks stay
//! continuous when the wind changes; the state keeps them for the instances registered with
//! [`Method::set_instances`].
//!
//! * **Trunk** (§6.3.3, Ota 2003): the wind at the crown's centre passed wave by wave through
//!   a damped oscillator at the trunk's own frequency ([`trunk`]); the trunk leans by that
//!   wind's static bend along it (about `up × w`), with small-branch chaos bands parallel,
//!   perpendicular (about `w`) and as a twist (about `up`), spread over the trunk's segments
//!   in proportion to their length.
//! * **Branches** (§6.3.3, Listing 6-1): each stem samples the wind at its base. Its
//!   horizontal direction `b` against the wind direction `w` weighs three cases,
//!   `facing = max(0, −b·w)`, `back = max(0, b·w)`, `perpendicular = 1 − |b·w|`:
//!   facing the wind the branch is pressed downwind, toward the trunk, and barely sways;
//!   on the back side it sways with high amplitude; perpendicular to the wind it bends about
//!   its parent's axis and twists about its own.
//! * **Amplitude and stiffness** (Ota 2003): the static bend `θ = τ / k` from the drag torque
//!   `τ = ½ ρ C_d A U² · L/2` on the stem's bark and leaves against the stiffness of its base
//!   joint `k = E·I/L`, capped at `max_bend`; sway frequency `f = √(k / (m L²/3)) / 2π`
//!   (a rod turning about its end), clamped to 0.3–10 Hz.
//! * **Phase** (§6.3.3): a random phase per stem, from the seed; **inertia**: branches lag
//!   the trunk by `−inertia · trunk rate / (2π f)`.
//! * **Hierarchy** (§6.4): per-branch angles become quaternions, concatenated from the root
//!   down by the pose seam ([`crate::pose`]); **LOD**: trunk only, or trunk and branches.

pub mod frames;
pub mod raw;
pub mod rotations;
pub mod trunk;

pub use raw::*;

use super::{Animator, Method, MethodError, MethodOptions, Simulation, check};
use crate::leaves::LeafFlutter;
use crate::model::{NONE, Tree};
use crate::physics::StemLoad;
use crate::pose::{Placement, Pose, SeamPose};
use crate::rng::{child_key, mix64};
use crate::wind::PackedWind;
use crate::wind::WindScene;
use crate::wind::raw::{RawField, RawWave};
use bytemuck::Zeroable;
use glam::Vec3;
use rayon::prelude::*;
use rotations::zioma_rotations;
use std::sync::Arc;
pub use trunk::Ring;
use trunk::TrunkModel;

/// Simulation level of detail (§6.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Lod {
    /// Trunk only: branches ride along rigidly.
    TrunkOnly,
    /// Trunk and branches.
    #[default]
    Full,
}

/// Parameters of Zioma's method (a scene's `[tree.params]` sets any of them but `seed`,
/// which is the tree's).
#[derive(Debug, Clone, Copy, PartialEq, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ZiomaParams {
    /// Simulation LOD.
    pub lod: Lod,
    /// Scales every branch angle (1 = physical estimate).
    pub amplitude: f32,
    /// Largest static bend of a branch, rad (0.6 ≈ 35°: beyond it a rigid-rotation model
    /// of a bending branch looks wrong).
    pub max_bend: f32,
    /// How strongly branches lag the trunk's motion (0 = not at all).
    pub inertia: f32,
    /// Seed of the per-branch phases.
    #[serde(skip)]
    pub seed: u64,
}

impl Default for ZiomaParams {
    fn default() -> Self {
        Self { lod: Lod::Full, amplitude: 1.0, max_bend: 0.6, inertia: 0.5, seed: 0 }
    }
}

impl ZiomaParams {
    /// Checks every field's range.
    pub fn check(&self) -> Result<(), MethodError> {
        check("zioma", "amplitude", self.amplitude, self.amplitude >= 0.0, "a finite number ≥ 0")?;
        check("zioma", "max_bend", self.max_bend, self.max_bend > 0.0 && self.max_bend <= 3.2, "0 to π rad")?;
        check("zioma", "inertia", self.inertia, self.inertia >= 0.0, "a finite number ≥ 0")
    }
}

/// Zioma's state: the time, and the trunk's ring-down since the wind last changed (the pose
/// is a closed form in t), the tree's and each registered instance's.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ZiomaState {
    /// Time, s.
    pub time: f32,
    /// The trunk's ring-down since the wind last changed (the tree at the origin).
    pub ring: Ring,
    /// The wind the last step took (`None`: still air, not yet stepped).
    pub wind: Option<PackedWind>,
    /// The instances registered with [`Method::set_instances`].
    pub instances: Vec<Placement>,
    /// Each registered instance's ring, taken at its own crown.
    pub rings: Vec<Ring>,
}

/// The registry's CPU constructor: Zioma's method on `tree` with `options`.
pub fn animator(tree: Arc<Tree>, options: &MethodOptions) -> Result<Box<dyn Animator>, MethodError> {
    let params = ZiomaParams { seed: options.seed, ..options.parse::<ZiomaParams>("zioma")? };
    params.check()?;
    let method = Zioma::new(&tree, params);
    Ok(Simulation::boxed(tree, method))
}

/// A placed copy of a tree (§6.5 instancing); see [`Placement`].
pub type ZiomaInstance = Placement;

/// Zioma's method set up for one tree.
#[derive(Debug, Clone)]
pub struct Zioma {
    /// Parameters.
    pub params: ZiomaParams,
    /// Per-stem constants.
    pub stems: Vec<RawZiomaStem>,
    /// Point where the trunk's wind is sampled (crown centre), m.
    pub crown_centre: Vec3,
    /// The trunk's frequency, static bend and damping (the shared physical description).
    pub trunk: TrunkModel,
    /// Its leaves' motion ([`crate::leaves`]: a closed form in t, as its branches).
    pub leaves: LeafFlutter,
    tree_seed: u32,
    raw: Vec<crate::model::RawSegment>,
}

impl Zioma {
    /// Precomputes per-stem drag, frequency and phase.
    pub fn new(tree: &Tree, params: ZiomaParams) -> Self {
        let s = &tree.segments;
        let st = &tree.stems;
        let key = mix64(params.seed ^ 0x5A10_4D41);
        let mut stems = Vec::with_capacity(st.len());
        for k in 0..st.len() {
            let first = st.first_segment[k] as usize;
            let load = StemLoad::of(tree, k);
            let (len, drag) = (load.length, load.bend_per_u2());
            let freq = load.frequency().clamp(0.3, 10.0);
            let b = st.bezier[k];
            let dir = (b[3] - b[0]).try_normalize().unwrap_or(s.axis(first));
            let parent_axis = if s.parent[first] == NONE { Vec3::Y } else { s.axis(s.parent[first] as usize) };
            let h = child_key(key, k as u64);
            stems.push(RawZiomaStem {
                base: s.start[first].to_array(),
                drag,
                dir: dir.to_array(),
                freq,
                parent_axis: parent_axis.to_array(),
                phase: (h >> 40) as f32 / (1u64 << 24) as f32,
                level: st.level[k] as u32,
                seed: h as u32,
                length: len,
                _pad: 0,
            });
        }
        let (lo, hi) = tree.bounds();
        let crown_centre = Vec3::new(
            tree.segments.start.first().map_or(0.0, |p| p.x),
            0.5 * (lo.y + hi.y) + 0.25 * (hi.y - lo.y),
            tree.segments.start.first().map_or(0.0, |p| p.z),
        );
        let trunk = TrunkModel::for_tree(tree, crate::physics::BRANCH_DRAG, crate::physics::LEAF_DRAG);
        Self {
            params,
            stems,
            crown_centre,
            trunk,
            leaves: LeafFlutter::new(tree, tree.seed),
            tree_seed: mix64(params.seed) as u32,
            raw: tree.raw_segments(),
        }
    }

    /// The ring that keeps the trunk continuous when the wind changes from `old` (ringing by
    /// `ring`) to `new` at time `t`, taken at the tree's crown.
    pub fn ring_after(&self, old: &PackedWind, new: &PackedWind, ring: &Ring, t: f32) -> Ring {
        self.trunk.ring_after((&old.fields, &old.waves), (&new.fields, &new.waves), ring, self.crown_centre, t)
    }

    /// [`Self::ring_after`] for `instance`, taken at its own crown.
    pub fn instance_ring_after(
        &self,
        old: &PackedWind,
        new: &PackedWind,
        ring: &Ring,
        instance: &ZiomaInstance,
        t: f32,
    ) -> Ring {
        let crown = instance.to_world(self.crown_centre);
        self.trunk.ring_after((&old.fields, &old.waves), (&new.fields, &new.waves), ring, crown, t)
    }

    /// [`Self::instance_ring_after`] for every instance, each from its own ring in `rings`
    /// (in parallel).
    pub fn instance_rings_after(
        &self,
        old: &PackedWind,
        new: &PackedWind,
        rings: &[Ring],
        instances: &[ZiomaInstance],
        t: f32,
    ) -> Vec<Ring> {
        instances.par_iter().zip(rings).map(|(i, r)| self.instance_ring_after(old, new, r, i, t)).collect()
    }

    /// The ring of a wind blowing since t = 0 from still air.
    pub fn start_ring(&self, fields: &[RawField], waves: &[RawWave]) -> Ring {
        self.trunk.ring_after((&[], &[]), (fields, waves), &Ring::default(), self.crown_centre, 0.0)
    }

    /// Every instance's ring of a wind blowing since `t` from still air.
    pub fn start_rings(
        &self,
        fields: &[RawField],
        waves: &[RawWave],
        instances: &[ZiomaInstance],
        t: f32,
    ) -> Vec<Ring> {
        instances
            .par_iter()
            .map(|i| {
                let crown = i.to_world(self.crown_centre);
                self.trunk.ring_after((&[], &[]), (fields, waves), &Ring::default(), crown, t)
            })
            .collect()
    }

    /// The per-frame values at time `t`: wind at the crown, trunk angles and their rate (the
    /// tree at the origin, unturned), ringing by `ring`.
    pub fn frame(&self, fields: &[RawField], waves: &[RawWave], t: f32, ring: &Ring) -> RawZiomaFrame {
        self.frame_for(fields, waves, t, None, ring)
    }

    /// The tree's values for a frame at time `t` (what the frame kernel reads beside each
    /// instance and its ring).
    pub fn raw_trunk(&self, t: f32) -> RawZiomaTrunk {
        let m = &self.trunk;
        RawZiomaTrunk {
            crown_centre: self.crown_centre.to_array(),
            natural_frequency: m.natural_frequency,
            tip_per_pascal: m.tip_per_pascal,
            damping_centre: m.damping_centre,
            lever: m.lever,
            damping_ratio: m.damping_ratio,
            reconfiguration_speed: m.drag.reconfiguration_speed,
            vogel_exponent: m.drag.vogel_exponent,
            time: t,
            tree_seed: self.tree_seed,
            lod: (self.params.lod == Lod::Full) as u32,
            amplitude: self.params.amplitude,
            max_bend: self.params.max_bend,
            inertia: self.params.inertia,
        }
    }

    /// The per-frame values of one instance (`None`: the tree at the origin, unturned).
    pub fn frame_for(
        &self,
        fields: &[RawField],
        waves: &[RawWave],
        t: f32,
        instance: Option<&ZiomaInstance>,
        ring: &Ring,
    ) -> RawZiomaFrame {
        let instance = instance.map_or(RawZiomaInstance::zeroed(), RawZiomaInstance::from);
        frames::zioma_frame(fields, waves, &self.raw_trunk(t), &instance, &ring.into())
    }

    /// The per-frame values of every instance, each ringing by its own ring in `rings` (in
    /// parallel; each on its own), by the frame kernel's CPU twin ([`frames::zioma_frames`]).
    pub fn frames_for(
        &self,
        fields: &[RawField],
        waves: &[RawWave],
        t: f32,
        instances: &[ZiomaInstance],
        rings: &[Ring],
    ) -> Vec<RawZiomaFrame> {
        assert_eq!(instances.len(), rings.len(), "one ring per instance");
        let raw: Vec<RawZiomaInstance> = instances.iter().map(RawZiomaInstance::from).collect();
        let rings: Vec<RawZiomaRing> = rings.iter().map(RawZiomaRing::from).collect();
        let mut out = vec![RawZiomaFrame::zeroed(); raw.len()];
        frames::zioma_frames(fields, waves, &[self.raw_trunk(t)], &raw, &rings, &mut out);
        out
    }

    /// Per-segment rotations δ of every instance at time `t`, instance by instance
    /// (`instances.len() × segments`), all in one parallel pass (CPU reference), the wind
    /// blowing since t = 0.
    pub fn rotations_instances(
        &self,
        tree: &Tree,
        fields: &[RawField],
        waves: &[RawWave],
        t: f32,
        instances: &[ZiomaInstance],
    ) -> Vec<[f32; 4]> {
        self.rotations_instances_ringing(
            tree,
            fields,
            waves,
            t,
            instances,
            &self.start_rings(fields, waves, instances, 0.0),
        )
    }

    /// [`Self::rotations_instances`], each instance ringing by its own ring in `rings`.
    pub fn rotations_instances_ringing(
        &self,
        tree: &Tree,
        fields: &[RawField],
        waves: &[RawWave],
        t: f32,
        instances: &[ZiomaInstance],
        rings: &[Ring],
    ) -> Vec<[f32; 4]> {
        let frames = self.frames_for(fields, waves, t, instances, rings);
        let mut out = vec![[0.0; 4]; tree.segments.len() * instances.len()];
        zioma_rotations(fields, waves, &self.raw, &self.stems, &frames, &mut out);
        out
    }

    /// Per-segment rotations δ at time `t` (CPU reference).
    pub fn rotations(&self, tree: &Tree, wind: &WindScene, t: f32) -> Vec<[f32; 4]> {
        let (fields, waves) = wind.pack();
        self.rotations_packed(tree, &fields, &waves, t)
    }

    /// [`Self::rotations`] with a scene packed once by the caller (blowing since t = 0).
    pub fn rotations_packed(&self, tree: &Tree, fields: &[RawField], waves: &[RawWave], t: f32) -> Vec<[f32; 4]> {
        self.rotations_ringing(tree, fields, waves, t, &self.start_ring(fields, waves))
    }

    /// Per-segment rotations δ at time `t` ringing by `ring`.
    pub fn rotations_ringing(
        &self,
        tree: &Tree,
        fields: &[RawField],
        waves: &[RawWave],
        t: f32,
        ring: &Ring,
    ) -> Vec<[f32; 4]> {
        let frame = self.frame(fields, waves, t, ring);
        let mut out = vec![[0.0; 4]; tree.segments.len()];
        zioma_rotations(fields, waves, &self.raw, &self.stems, &[frame], &mut out);
        out
    }

    /// Each of `instances`' rings in `wind`: a registered instance's own (an unregistered one
    /// takes the tree's), or, if the last step took another wind, the ring of a change to
    /// `wind` now, at the instance's crown.
    fn current_rings(&self, state: &ZiomaState, wind: &PackedWind, instances: &[Placement]) -> Vec<Ring> {
        let rings: Vec<Ring> = (0..instances.len())
            .map(|k| match (state.instances.get(k), state.rings.get(k)) {
                (Some(p), Some(ring)) if *p == instances[k] => *ring,
                _ => state.ring,
            })
            .collect();
        match &state.wind {
            Some(w) if w == wind => rings,
            Some(w) => self.instance_rings_after(w, wind, &rings, instances, state.time),
            None => self.instance_rings_after(&PackedWind::calm(), wind, &rings, instances, state.time),
        }
    }

    /// The state's ring in `wind`: its own if the last step took that wind, else the ring of a
    /// change to it now.
    fn current_ring(&self, state: &ZiomaState, wind: &PackedWind) -> Ring {
        match &state.wind {
            Some(w) if w == wind => state.ring,
            Some(w) => self.ring_after(w, wind, &state.ring, state.time),
            None => self.ring_after(&PackedWind::calm(), wind, &state.ring, state.time),
        }
    }

    /// The pose at time `t` (CPU reference, the wind blowing since t = 0).
    pub fn pose_at(&self, tree: &Tree, wind: &PackedWind, t: f32) -> Pose {
        Pose::from_rotations(tree, &self.rotations_packed(tree, &wind.fields, &wind.waves, t))
    }
}

impl Method for Zioma {
    type State = ZiomaState;

    fn name(&self) -> &'static str {
        "zioma"
    }

    fn rest_state(&self, _tree: &Tree) -> ZiomaState {
        ZiomaState::default()
    }

    /// Advances the time; a wind unlike the last step's starts a ring at the current time,
    /// the tree's and each registered instance's.
    fn step(&self, _tree: &Tree, wind: &PackedWind, state: &mut ZiomaState, dt: f32) {
        if state.wind.as_ref() != Some(wind) {
            state.rings = self.current_rings(state, wind, &state.instances);
            state.ring = self.current_ring(state, wind);
            state.wind = Some(wind.clone());
        }
        state.time += dt;
    }

    /// Registers the instances [`Method::seam_instances`] will pose, so each keeps its own
    /// ring from the next wind change on; one registered before the first step is exact
    /// from the start. An instance new to the state takes the tree's ring until then.
    fn set_instances(&self, _tree: &Tree, state: &mut ZiomaState, instances: &[Placement]) {
        let rings = (0..instances.len())
            .map(|k| match (state.instances.get(k), state.rings.get(k)) {
                (Some(old), Some(ring)) if *old == instances[k] => *ring,
                _ => state.ring,
            })
            .collect();
        state.instances = instances.to_vec();
        state.rings = rings;
    }

    fn time(&self, state: &ZiomaState) -> f32 {
        state.time
    }

    fn set_time(&self, state: &mut ZiomaState, time: f32) {
        state.time = time;
    }

    fn seam(&self, tree: &Tree, wind: &PackedWind, state: &ZiomaState, out: &mut SeamPose) {
        let ring = self.current_ring(state, wind);
        *out =
            SeamPose::from_rotations(tree, &self.rotations_ringing(tree, &wind.fields, &wind.waves, state.time, &ring));
        self.leaves.seam(wind, state.time, out);
    }

    fn pose(&self, tree: &Tree, wind: &PackedWind, state: &ZiomaState) -> Pose {
        let ring = self.current_ring(state, wind);
        Pose::from_rotations(tree, &self.rotations_ringing(tree, &wind.fields, &wind.waves, state.time, &ring))
    }

    fn seam_instances(
        &self,
        tree: &Tree,
        wind: &PackedWind,
        state: &ZiomaState,
        instances: &[Placement],
        out: &mut SeamPose,
    ) -> bool {
        let rings = self.current_rings(state, wind, instances);
        let delta = self.rotations_instances_ringing(tree, &wind.fields, &wind.waves, state.time, instances, &rings);
        *out = SeamPose::from_rotations(tree, &delta);
        // The first instance's leaves (every copy's, as skinning shares them).
        let n = tree.segments.len().min(out.joints.len());
        let mut leaf = std::mem::take(&mut out.leaf);
        self.leaves.write(wind, state.time, &out.joints[..n], &out.acc[..n], &mut leaf);
        out.leaf = leaf;
        true
    }
}
