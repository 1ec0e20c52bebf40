//! The pose seam: what every method hands out, and forward kinematics.
//!
//! A method ([`crate::methods`]) produces one rotation `δᵢ` per segment, a world-frame rotation about the
//! segment's joint, expressed in the *rest* frame. The pose follows by forward kinematics:
//!
//! * accumulated rotation `Dᵢ = D_parent · δᵢ` (root: `Dᵢ = δᵢ`);
//! * orientation `Qᵢ = Dᵢ · Q_restᵢ`;
//! * joint position `pᵢ = restᵢ + (p_parent − rest_parent) + (D_parent · oᵢ − oᵢ)` with
//!   `oᵢ = restᵢ − rest_parent`, the rest offset from the parent's joint.
//!
//! Written as displacements, the rest pose is reproduced bit for bit when every `δ` is the
//! identity (zero wind). Zioma's rule "per-branch angles → quaternions concatenated from the
//! root down" is exactly `D`. The CPU ([`fk::pose_forward`]) makes one pass in topological
//! order, linear in the segments at any depth; the GPU (`pose_accumulate.wgsl`,
//! `pose_positions.wgsl`) lets each segment walk its ancestor chain, so no pass waits on
//! another level, and jumps pointers (`pose_jump_*.wgsl`, [`fk::pose_jump`]) for
//! hierarchies too deep to walk; level by level (`pose_level.wgsl`) is the third way.
//!
//! The seam's buffers ([`SeamPose`]: joints and `D`, instance-major) are what meshers and
//! skinning read; a [`Pose`] is the same with world orientations, plus animated Bézier
//! control points for methods that have them. [`Placement`] places instances posed one by
//! one; [`curves`] carries a curve-bending method's stems to the deformer.

pub mod curves;
pub mod fk;
pub mod segment_ends;

pub use curves::{Curves, RawCurveStem, RawStemCurve};

use crate::model::Tree;
use crate::rng::{child_key, mix64};
use glam::{Quat, Vec3};

/// Per-segment world transforms (and Béziers where the method has them).
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Joint (start) position of each segment, m.
    pub start: Vec<Vec3>,
    /// World orientation of each segment (local +Y along the segment).
    pub orientation: Vec<Quat>,
    /// Animated Bézier control points per stem, if the method has them.
    pub bezier: Option<Vec<[Vec3; 4]>>,
}

impl Pose {
    /// The tree at rest.
    pub fn rest(tree: &Tree) -> Self {
        Self { start: tree.segments.start.clone(), orientation: tree.segments.orientation.clone(), bezier: None }
    }

    /// End point of segment `i` in this pose.
    pub fn end(&self, tree: &Tree, i: usize) -> Vec3 {
        self.start[i] + self.orientation[i] * Vec3::new(0.0, tree.segments.length[i], 0.0)
    }

    /// Checks that the pose is a sound skeleton: finite joints, unit orientations, and every
    /// segment's length (distance to the next joint of its stem) within 1e-4 relative of its
    /// rest length — never finer than f32 resolves at the joint's distance from the origin
    /// (4 ulps: a 1 cm twig 10 m up is good to ≈ 4e-6 m). Returns the first violation.
    pub fn check_sound(&self, tree: &Tree) -> Result<(), String> {
        let s = &tree.segments;
        for i in 0..s.len() {
            if !self.start[i].is_finite() || !self.orientation[i].is_finite() {
                return Err(format!("segment {i}: non-finite joint or orientation"));
            }
            if (self.orientation[i].length() - 1.0).abs() >= 1e-4 {
                return Err(format!("segment {i}: orientation not unit"));
            }
            let p = s.parent[i];
            if p != crate::model::NONE && s.stem[p as usize] == s.stem[i] {
                let p = p as usize;
                let len = (self.start[i] - self.start[p]).length();
                let tol = (1e-4 * s.length[p]).max(4.0 * f32::EPSILON * self.start[i].length());
                let err = (len - s.length[p]).abs();
                if err > tol {
                    return Err(format!("segment {p}: length off by {err} m (tolerance {tol} m)"));
                }
            }
        }
        Ok(())
    }

    /// Poses of many instances of one tree from their rotations, instance-major
    /// (`instance × segments + segment`), in one parallel forward-kinematics pass.
    pub fn from_rotations_instances(tree: &Tree, delta: &[[f32; 4]]) -> Vec<Self> {
        let n = tree.segments.len().max(1);
        let (joints, acc) = seam_buffers(tree, delta);
        joints.chunks(n).zip(acc.chunks(n)).map(|(j, a)| Self::from_seam(tree, j, a)).collect()
    }

    /// Pose from per-segment rotations `δ` (x, y, z, w), by forward kinematics.
    pub fn from_rotations(tree: &Tree, delta: &[[f32; 4]]) -> Self {
        let (joints, acc) = seam_buffers(tree, delta);
        Self::from_seam(tree, &joints, &acc)
    }

    /// Pose from the seam's buffers of one instance: joints (w ignored) and accumulated
    /// rotations `D` (orientation `D · Q_rest`).
    pub fn from_seam(tree: &Tree, joints: &[[f32; 4]], acc: &[[f32; 4]]) -> Self {
        Self {
            start: joints.iter().map(|p| Vec3::new(p[0], p[1], p[2])).collect(),
            orientation: acc.iter().zip(&tree.segments.orientation).map(|(d, q)| Quat::from_array(*d) * *q).collect(),
            bezier: None,
        }
    }
}

/// The pose seam's buffers, instance-major (`instance × segments + segment`): what meshers,
/// skinning and exporters read. The GPU twin keeps the same two arrays on the device.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SeamPose {
    /// Joint (start) position of every segment, m (w = 0).
    pub joints: Vec<[f32; 4]>,
    /// Accumulated rotation `D` of every segment (x, y, z, w): orientation `D · Q_rest`.
    pub acc: Vec<[f32; 4]>,
    /// Rotation `λ` of every leaf about its attachment, in its segment's rest frame (x, y,
    /// z, w): the leaf's orientation is `D_s · λ · Q_leaf` ([`crate::leaves`]). Empty: every
    /// leaf at rest on its segment.
    pub leaf: Vec<[f32; 4]>,
}

impl SeamPose {
    /// The tree at rest, one instance.
    pub fn rest(tree: &Tree) -> Self {
        Self {
            joints: tree.segments.start.iter().map(|p| p.extend(0.0).to_array()).collect(),
            acc: vec![[0.0, 0.0, 0.0, 1.0]; tree.segments.len()],
            leaf: Vec::new(),
        }
    }

    /// From per-segment rotations `δ` by forward kinematics ([`seam_buffers`]).
    pub fn from_rotations(tree: &Tree, delta: &[[f32; 4]]) -> Self {
        let (joints, acc) = seam_buffers(tree, delta);
        Self { joints, acc, leaf: Vec::new() }
    }

    /// Instance `k`'s pose (world orientations).
    pub fn pose(&self, tree: &Tree, k: usize) -> Pose {
        let n = tree.segments.len();
        Pose::from_seam(tree, &self.joints[k * n..(k + 1) * n], &self.acc[k * n..(k + 1) * n])
    }

    /// Number of instances held.
    pub fn instances(&self, tree: &Tree) -> usize {
        self.joints.len() / tree.segments.len().max(1)
    }
}

/// The pose seam's buffers from rotations `δ`, instance-major: joint positions (w = 0) and
/// accumulated rotations `D`, by forward kinematics ([`fk::pose_forward`]: one pass in
/// topological order per instance, instances in parallel). What meshers and skinning read;
/// [`Pose`] is the same data with world orientations.
pub fn seam_buffers(tree: &Tree, delta: &[[f32; 4]]) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let mut acc = vec![[0.0f32; 4]; delta.len()];
    let mut joints = vec![[0.0f32; 4]; delta.len()];
    let rest: Vec<[f32; 4]> = tree.segments.start.iter().map(|p| p.extend(0.0).to_array()).collect();
    fk::pose_forward(&tree.segments.parent, &rest, delta, &mut acc, &mut joints);
    (joints, acc)
}

/// Tip displacement statistics of a pose against rest, per level.
#[derive(Debug, Clone, PartialEq)]
pub struct Displacement {
    /// Mean displacement of segment ends, per level, m.
    pub mean: Vec<f32>,
    /// Largest displacement, per level, m.
    pub max: Vec<f32>,
    /// Mean displacement vector of all segment ends above the trunk's base (the crown), m.
    pub crown_mean: Vec3,
}

/// Displacement of every segment end between `rest` and `pose`.
pub fn displacement(tree: &Tree, pose: &Pose) -> Displacement {
    let levels = tree.levels as usize;
    let mut sum = vec![0.0f64; levels];
    let mut count = vec![0usize; levels];
    let mut max = vec![0.0f32; levels];
    let mut crown = glam::DVec3::ZERO;
    for i in 0..tree.segments.len() {
        let d = pose.end(tree, i) - tree.segments.end(i);
        let l = tree.segments.level[i] as usize;
        sum[l] += d.length() as f64;
        count[l] += 1;
        max[l] = max[l].max(d.length());
        crown += d.as_dvec3();
    }
    Displacement {
        mean: sum.iter().zip(&count).map(|(s, c)| if *c > 0 { (*s / *c as f64) as f32 } else { 0.0 }).collect(),
        max,
        crown_mean: (crown / tree.segments.len().max(1) as f64).as_vec3(),
    }
}

/// A pose as the GPU pose seam stores it: joint positions (w = 0) and accumulated
/// rotations `D = Q · Q_rest⁻¹`.
pub fn pose_buffers(tree: &Tree, pose: &Pose) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let joint = pose.start.iter().map(|p| p.extend(0.0).to_array()).collect();
    let acc = pose
        .orientation
        .iter()
        .zip(&tree.segments.orientation)
        .map(|(q, r)| (*q * r.conjugate()).normalize().to_array())
        .collect();
    (joint, acc)
}

/// One placed copy of a tree (Zioma §6.5 instancing): position, yaw, its own phase and
/// seed, so a forest of one species does not sway in lockstep. Methods that pose every
/// instance on its own ([`crate::methods::Method::seam_instances`]) sample the wind there.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Placement {
    /// Position of the tree's origin in the world, m.
    pub position: Vec3,
    /// Rotation about +Y, rad.
    pub yaw: f32,
    /// Phase offset of every branch, cycles.
    pub phase: f32,
    /// Seed of the trunk's noise for this instance.
    pub seed: u32,
}

impl Placement {
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

/// The rotation taking unit `a` onto unit `b`, `normalize(a × b, 1 + a·b)`: exactly the
/// identity when `a == b` (tested, not left to `a × a`, which a fused multiply-add leaves at
/// the rounding error of a product instead of zero), and faithful for tiny angles (no
/// snapping to the identity). Falls back to the identity for a zero vector or opposite
/// directions. The WGSL twin is `shortest_arc` in `quat.wgsl`.
pub fn shortest_arc(a: Vec3, b: Vec3) -> Quat {
    let w = 1.0 + a.dot(b);
    if a == b || a == Vec3::ZERO || b == Vec3::ZERO || w < 1e-6 {
        return Quat::IDENTITY;
    }
    let c = a.cross(b);
    Quat::from_xyzw(c.x, c.y, c.z, w).normalize()
}
