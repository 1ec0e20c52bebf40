//! Zioma's procedural wind animation (GPU Gems 3, ch. 6, §6.3–6.5).
//!
//! Stateless: the pose at time t is a function of (tree, wind, t) alone.
//!
//! * **Trunk** (§6.3.3): the trunk noise bands of [`crate::wind::trunk`] for the wind speed
//!   at the crown's centre at time t give angles parallel to the wind (about `up × w`),
//!   perpendicular (about `w`) and a twist (about `up`), spread over the trunk's segments in
//!   proportion to their length.
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
//!   down by the pose seam ([`crate::animate`]); **LOD**: trunk only, or trunk and branches.

use super::Pose;
use crate::cpu::zioma_rotations::zioma_rotations;
use crate::model::{NONE, Tree};
use crate::rng::{child_key, mix64};
use crate::wind::WindScene;
use crate::wind::raw::{RawField, RawWave};
use crate::wind::trunk::TrunkNoise;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// Drag coefficient of bark and leaves together (a cylinder in cross-flow ≈ 1.0–1.2;
/// leaves streamline in wind, lowering it).
pub const BRANCH_DRAG: f32 = 0.8;

/// Simulation level of detail (§6.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Lod {
    /// Trunk only: branches ride along rigidly.
    TrunkOnly,
    /// Trunk and branches.
    #[default]
    Full,
}

/// Parameters of Zioma's method.
#[derive(Debug, Clone, Copy, PartialEq)]
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
    pub seed: u64,
}

impl Default for ZiomaParams {
    fn default() -> Self {
        Self { lod: Lod::Full, amplitude: 1.0, max_bend: 0.6, inertia: 0.5, seed: 0 }
    }
}

/// Per-stem constants, 64 bytes. WGSL: `ZiomaStem` in `zioma_rotations.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawZiomaStem {
    /// Stem base (where it samples the wind), m.
    pub base: [f32; 3],
    /// Static bend per (m/s)², rad·s²/m².
    pub drag: f32,
    /// Unit rest direction (base to tip).
    pub dir: [f32; 3],
    /// Sway frequency, Hz.
    pub freq: f32,
    /// Unit axis of the parent segment at the attachment (up for trunks).
    pub parent_axis: [f32; 3],
    /// Phase, cycles.
    pub phase: f32,
    /// Branching level.
    pub level: u32,
    /// Noise stream.
    pub seed: u32,
    /// Arc length, m.
    pub length: f32,
    /// Padding.
    pub _pad: u32,
}

/// Per-frame, per-instance values, 80 bytes. WGSL: `ZiomaFrame`. Directions are in the
/// tree's own frame; `origin` and `heading` place the instance in the world, where the wind
/// is sampled.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawZiomaFrame {
    /// Horizontal unit wind direction at the crown (zero in calm air).
    pub wind_dir: [f32; 3],
    /// Time, s.
    pub time: f32,
    /// Trunk angles: parallel, perpendicular, twist, rad.
    pub trunk: [f32; 3],
    /// Rate of the parallel angle, rad/s.
    pub trunk_rate: f32,
    /// 0 = trunk only, 1 = full.
    pub lod: u32,
    /// Branch amplitude scale.
    pub amplitude: f32,
    /// Largest static bend, rad.
    pub max_bend: f32,
    /// Inertia gain.
    pub inertia: f32,
    /// Instance position in the world, m.
    pub origin: [f32; 3],
    /// Instance phase offset, cycles (added to every branch's phase).
    pub phase: f32,
    /// Instance heading (cos, sin of the yaw about +Y).
    pub heading: [f32; 2],
    /// Padding.
    pub _pad: [f32; 2],
}

/// Zioma's Table 6-1 (Intel Xeon 2.33 GHz, GeForce 8800 GTX; 4,617 vertices per
/// instance): (instances, branches, DirectX 9 ms, DirectX 10 ms, two-bone skinning without
/// branch simulation ms). The DirectX columns are simulation and skinning per frame.
pub const ZIOMA_TABLE_6_1: [(usize, usize, f64, f64, f64); 4] = [
    (30, 2_400, 1.46, 1.34, 0.86),
    (100, 8_000, 3.90, 3.82, 2.32),
    (256, 20_480, 9.81, 9.68, 5.82),
    (1_000, 80_000, 38.21, 37.61, 22.48),
];

/// One placed copy of a tree (instancing, §6.5): position, yaw, its own phase and seed, so
/// a forest of one species does not sway in lockstep.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ZiomaInstance {
    /// Position of the tree's origin in the world, m.
    pub position: Vec3,
    /// Rotation about +Y, rad.
    pub yaw: f32,
    /// Phase offset of every branch, cycles.
    pub phase: f32,
    /// Seed of the trunk's noise for this instance.
    pub seed: u32,
}

impl ZiomaInstance {
    /// A seeded random placement on a square of side `spacing · ⌈√count⌉` (instance `k` of a
    /// forest).
    pub fn grid(count: usize, spacing: f32, seed: u64) -> Vec<Self> {
        let side = (count as f32).sqrt().ceil().max(1.0) as usize;
        (0..count)
            .map(|k| {
                let h = child_key(mix64(seed ^ 0x1A57), k as u64);
                let u = |shift: u32| ((h >> shift) & 0xFFFF) as f32 / 65_536.0;
                Self {
                    position: Vec3::new(
                        ((k % side) as f32 + 0.5 * u(0)) * spacing,
                        0.0,
                        ((k / side) as f32 + 0.5 * u(16)) * spacing,
                    ),
                    yaw: std::f32::consts::TAU * u(32),
                    phase: u(48),
                    seed: (h >> 8) as u32,
                }
            })
            .collect()
    }

    /// World → tree frame for a horizontal vector (inverse yaw).
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        let (s, c) = self.yaw.sin_cos();
        Vec3::new(c * v.x - s * v.z, v.y, s * v.x + c * v.z)
    }

    /// Tree frame → world for a point.
    pub fn to_world(&self, p: Vec3) -> Vec3 {
        let (s, c) = self.yaw.sin_cos();
        self.position + Vec3::new(c * p.x + s * p.z, p.y, -s * p.x + c * p.z)
    }
}

/// Zioma's method set up for one tree.
#[derive(Debug, Clone)]
pub struct Zioma {
    /// Parameters.
    pub params: ZiomaParams,
    /// Per-stem constants.
    pub stems: Vec<RawZiomaStem>,
    /// Point where the trunk's wind is sampled (crown centre), m.
    pub crown_centre: Vec3,
    tree_seed: u32,
    raw: Vec<crate::model::RawSegment>,
}

impl Zioma {
    /// Precomputes per-stem drag, frequency and phase.
    pub fn new(tree: &Tree, params: ZiomaParams) -> Self {
        let s = &tree.segments;
        let st = &tree.stems;
        let w = tree.wood;
        let key = mix64(params.seed ^ 0x5A10_4D41);
        let mut stems = Vec::with_capacity(st.len());
        for k in 0..st.len() {
            let first = st.first_segment[k] as usize;
            let n = st.segment_count[k] as usize;
            let (mut area, mut mass) = (0.0f32, 0.0f32);
            for i in first..first + n {
                area += (s.radius_base[i] + s.radius_tip[i]) * s.length[i];
                mass += s.mass[i];
                let (o, c) = (tree.children.leaf_offset[i] as usize, tree.children.leaf_count[i] as usize);
                for l in o..o + c {
                    let a = std::f32::consts::FRAC_PI_4 * tree.leaves.width[l] * tree.leaves.length[l];
                    area += a;
                    mass += a * w.leaf_areal_density;
                }
            }
            let len = st.length[k].max(1e-4);
            let stiffness = s.stiffness[first].max(1e-9);
            let torque_per_u2 = 0.5 * crate::wind::trunk::AIR_DENSITY * BRANCH_DRAG * area * 0.5 * len;
            let drag = torque_per_u2 / stiffness;
            let freq =
                ((stiffness / (mass.max(1e-6) * len * len / 3.0)).sqrt() / std::f32::consts::TAU).clamp(0.3, 10.0);
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
        Self { params, stems, crown_centre, tree_seed: mix64(params.seed) as u32, raw: tree.raw_segments() }
    }

    /// The per-frame values at time `t`: wind at the crown, trunk angles and their rate (the
    /// tree at the origin, unturned).
    pub fn frame(&self, tree: &Tree, fields: &[RawField], waves: &[RawWave], t: f32) -> RawZiomaFrame {
        self.frame_for(tree, fields, waves, t, None)
    }

    /// The per-frame values of one instance (`None`: the tree at the origin, unturned).
    pub fn frame_for(
        &self,
        tree: &Tree,
        fields: &[RawField],
        waves: &[RawWave],
        t: f32,
        instance: Option<&ZiomaInstance>,
    ) -> RawZiomaFrame {
        let (centre, seed) = match instance {
            Some(i) => (i.to_world(self.crown_centre), self.tree_seed ^ i.seed),
            None => (self.crown_centre, self.tree_seed),
        };
        let v = crate::cpu::wind_sample::wind_at(fields, waves, centre, t);
        let v = instance.map_or(v, |i| i.to_local(v));
        let h = Vec3::new(v.x, 0.0, v.z);
        let u = h.length();
        let dir = if u > 1e-6 { h / u } else { Vec3::ZERO };
        let noise = TrunkNoise::for_tree(tree, u);
        let a = noise.angles(t, seed);
        let dt = 0.01;
        let rate = (noise.angles(t + dt, seed)[0] - noise.angles(t - dt, seed)[0]) / (2.0 * dt);
        let (sin, cos) = instance.map_or((0.0, 1.0), |i| i.yaw.sin_cos());
        RawZiomaFrame {
            wind_dir: dir.to_array(),
            time: t,
            trunk: a,
            trunk_rate: rate,
            lod: (self.params.lod == Lod::Full) as u32,
            amplitude: self.params.amplitude,
            max_bend: self.params.max_bend,
            inertia: self.params.inertia,
            origin: instance.map_or([0.0; 3], |i| i.position.to_array()),
            phase: instance.map_or(0.0, |i| i.phase),
            heading: [cos, sin],
            _pad: [0.0; 2],
        }
    }

    /// Per-segment rotations δ of every instance at time `t`, instance by instance
    /// (`instances.len() × segments`), all in one parallel pass (CPU reference).
    pub fn rotations_instances(
        &self,
        tree: &Tree,
        fields: &[RawField],
        waves: &[RawWave],
        t: f32,
        instances: &[ZiomaInstance],
    ) -> Vec<[f32; 4]> {
        let frames: Vec<RawZiomaFrame> =
            instances.iter().map(|i| self.frame_for(tree, fields, waves, t, Some(i))).collect();
        let mut out = vec![[0.0; 4]; tree.segments.len() * instances.len()];
        zioma_rotations(fields, waves, &self.raw, &self.stems, &frames, &mut out);
        out
    }

    /// Per-segment rotations δ at time `t` (CPU reference).
    pub fn rotations(&self, tree: &Tree, wind: &WindScene, t: f32) -> Vec<[f32; 4]> {
        let (fields, waves) = wind.pack();
        self.rotations_packed(tree, &fields, &waves, t)
    }

    /// [`Self::rotations`] with a scene packed once by the caller.
    pub fn rotations_packed(&self, tree: &Tree, fields: &[RawField], waves: &[RawWave], t: f32) -> Vec<[f32; 4]> {
        let frame = self.frame(tree, fields, waves, t);
        let mut out = vec![[0.0; 4]; tree.segments.len()];
        zioma_rotations(fields, waves, &self.raw, &self.stems, &[frame], &mut out);
        out
    }

    /// The pose at time `t` (CPU reference).
    pub fn pose(&self, tree: &Tree, wind: &WindScene, t: f32) -> Pose {
        Pose::from_rotations(tree, &self.rotations(tree, wind, t))
    }

    /// [`Self::pose`] with a scene packed once by the caller (per-frame loops).
    pub fn pose_packed(&self, tree: &Tree, fields: &[RawField], waves: &[RawWave], t: f32) -> Pose {
        Pose::from_rotations(tree, &self.rotations_packed(tree, fields, waves, t))
    }
}
