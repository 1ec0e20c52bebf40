//! Animation: a method turns (tree, wind, time, its own state) into a [`Pose`].
//!
//! # The seam every method plugs into
//!
//! A method produces one rotation `δᵢ` per segment, a world-frame rotation about the
//! segment's joint, expressed in the *rest* frame. The pose follows by forward kinematics:
//!
//! * accumulated rotation `Dᵢ = D_parent · δᵢ` (root: `Dᵢ = δᵢ`);
//! * orientation `Qᵢ = Dᵢ · Q_restᵢ`;
//! * joint position `pᵢ = restᵢ + (p_parent − rest_parent) + (D_parent · oᵢ − oᵢ)` with
//!   `oᵢ = restᵢ − rest_parent`, the rest offset from the parent's joint.
//!
//! Written as displacements, the rest pose is reproduced bit for bit when every `δ` is the
//! identity (zero wind). Zioma's rule "per-branch angles → quaternions concatenated from the
//! root down" is exactly `D`. The CPU (`cpu::pose_fk`) and GPU (`pose_accumulate.wgsl`,
//! `pose_positions.wgsl`) both let each segment walk its ancestor chain, so no pass waits on
//! another level.
//!
//! A [`Pose`] is what meshers, renderers and exporters consume: per-segment world joint
//! position and orientation, plus animated Bézier control points for methods that have them.

pub mod akagi;
pub mod driver;
pub mod hsm;
pub mod skjermo;
pub mod skjermo_lanes;
pub mod zioma;

pub use driver::CpuAnimator;

use crate::model::Tree;
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

/// The pose seam's buffers from rotations `δ`, instance-major: joint positions (w = 0) and
/// accumulated rotations `D`, by forward kinematics (ancestor walks, rayon). What meshers and
/// skinning read; [`Pose`] is the same data with world orientations.
pub fn seam_buffers(tree: &Tree, delta: &[[f32; 4]]) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let mut acc = vec![[0.0f32; 4]; delta.len()];
    crate::cpu::pose_fk::pose_accumulate(&tree.segments.parent, delta, &mut acc);
    let mut joints = vec![[0.0f32; 4]; delta.len()];
    let rest: Vec<[f32; 4]> = tree.segments.start.iter().map(|p| p.extend(0.0).to_array()).collect();
    crate::cpu::pose_fk::pose_positions(&tree.segments.parent, &rest, &acc, &mut joints);
    (joints, acc)
}

/// Mechanical radius of each segment, m: its own base radius, but never thinner than
/// `min_radius` nor than the radius whose section equals its children's together
/// (Leonardo's rule — a joint carries what grows beyond it). Generators taper radii for
/// looks; the mechanics of Akagi's joints and HSM's clusters need this.
pub fn mechanical_radii(tree: &Tree, min_radius: f32) -> Vec<f32> {
    let s = &tree.segments;
    let mut r = vec![0.0f32; s.len()];
    for i in (0..s.len()).rev() {
        let carried: f32 = tree.children.of(i).iter().map(|&c| r[c as usize].powi(2)).sum();
        r[i] = s.radius_base[i].max(min_radius).max(carried.sqrt());
    }
    r
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
