//! Baking: any animation method run on the CPU and sampled at a fixed frame rate into a
//! [`Clip`] — per frame the pose seam's buffers (joint positions and accumulated
//! rotations `D` per segment; per segment the sum of its leaves' rotations, and on request
//! each leaf's), which skinning and the glTF exporter consume.
//!
//! # Looping clips
//!
//! The wind is not periodic, and stateful methods never return exactly to an earlier
//! state, so a loop is made by **cross-fading the ends**: the method runs for `T + B`
//! seconds (`T` the clip, `B` the blend window) and frame `t` of the clip is
//!
//! * `p(t)` for `B ≤ t ≤ T`,
//! * `blend(p(t + T), p(t), w(t / B))` for `0 ≤ t < B`, with `w(x) = 3x² − 2x³`.
//!
//! So the clip starts at `p(T)`, exactly where it ends, and because `w′(0) = 0` its velocity
//! at the start is `p′(T)`, the velocity at its end: no jump in pose or speed across the
//! seam. Blending is done on each segment's *local* transform (rotation and offset relative
//! to its parent: slerp and lerp), and the pose is rebuilt root to tip, so the skeleton
//! stays connected while blending; a leaf's rotation, already relative to its segment, is
//! slerped, and a segment's sum of them lerped in one hemisphere. The last frame is a copy of the first (glTF clips play
//! from the first key to the last).

use crate::mesh::quat_slerp;
use crate::methods::{Animator, MethodError};
use crate::model::{NONE, Tree};
use crate::pose::SeamPose;
use crate::wind::WindScene;
use glam::{Quat, Vec3};

/// Largest `frames × values per frame` a clip may hold (three per segment, one per leaf
/// with [`BakeParams::per_leaf`]; 16 bytes each: 512 MiB, a 10 s loop of the largest
/// shipped species at 30 fps with room to spare).
pub const MAX_CLIP_VALUES: u64 = 32 << 20;

/// How to bake (the method is the caller's: any [`Animator`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BakeParams {
    /// Clip length, s.
    pub seconds: f32,
    /// Frames per second of the clip.
    pub fps: f32,
    /// Make the clip loop seamlessly (see the module documentation).
    pub looped: bool,
    /// Cross-fade window of a looping clip, s. Default 1 s: long against a frame, short
    /// against the clip, and about one period of a branch's sway.
    pub blend: f32,
    /// Simulated time before the clip starts, s. Default 2 s, so stateful methods have left
    /// their rest pose and settled into the wind before frame 0.
    pub preroll: f32,
    /// Simulation steps per second of stateful methods. Default 120 Hz: every method is
    /// stable there, and it is a whole multiple of 24, 30 and 60 fps.
    pub sim_rate: f32,
    /// Keep every leaf's rotation per frame ([`Clip::leaves`]); off, only each segment's sum
    /// of them ([`Clip::leaf_sums`], all an export needs), so trees with 10⁵ leaves fit.
    pub per_leaf: bool,
}

impl Default for BakeParams {
    fn default() -> Self {
        Self { seconds: 10.0, fps: 30.0, looped: false, blend: 1.0, preroll: 2.0, sim_rate: 120.0, per_leaf: false }
    }
}

/// Errors baking a clip.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BakeError {
    /// A parameter is out of range.
    #[error("bake parameter `{field}` = {value}: expected {expected}")]
    Param { field: &'static str, value: String, expected: String },
    /// The clip would be too large.
    #[error(
        "the clip would hold {frames} frames × {segments} values (three per segment, one per leaf when kept); the limit is {limit} (shorten it, lower the fps or use a smaller tree)"
    )]
    TooLarge { frames: u64, segments: u64, limit: u64 },
    /// The method could not be built.
    #[error(transparent)]
    Method(#[from] MethodError),
}

/// A baked animation: the pose seam's buffers per frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Clip {
    /// Frames per second.
    pub fps: f32,
    /// The last frame equals the first and the clip plays seamlessly in a loop.
    pub looped: bool,
    /// Joint position of every segment (w = 0), per frame.
    pub joints: Vec<Vec<[f32; 4]>>,
    /// Accumulated rotation `D` of every segment, per frame.
    pub acc: Vec<Vec<[f32; 4]>>,
    /// Rotation of every leaf relative to its segment ([`SeamPose::leaf`]), per frame, with
    /// [`BakeParams::per_leaf`]; an empty frame has every leaf at rest.
    pub leaves: Vec<Vec<[f32; 4]>>,
    /// Per frame and segment, the sum of its leaves' rotations relative to it, each taken in
    /// the identity's hemisphere (`(0, 0, 0, n)` for `n` leaves at rest; zero with none):
    /// normalised, the least-squares single turn of the leaves, and summed over segments,
    /// that of any group of them.
    pub leaf_sums: Vec<Vec<[f32; 4]>>,
}

impl Clip {
    /// Number of frames (keys), the first at t = 0 and the last at [`Clip::duration`].
    pub fn frames(&self) -> usize {
        self.joints.len()
    }

    /// Clip length, s.
    pub fn duration(&self) -> f32 {
        (self.frames().saturating_sub(1)) as f32 / self.fps
    }
}

impl BakeParams {
    /// Checks every field; returns (clip frames N, blend frames, steps per frame).
    fn check(&self, segments: usize) -> Result<(usize, usize, usize), BakeError> {
        let bad = |field, value: f32, expected: &str| {
            Err(BakeError::Param { field, value: value.to_string(), expected: expected.to_string() })
        };
        if !(self.fps.is_finite() && self.fps > 0.0 && self.fps <= 240.0) {
            return bad("fps", self.fps, "more than 0 and at most 240 frames per second");
        }
        if !(self.seconds.is_finite() && self.seconds > 0.0 && self.seconds <= 3600.0) {
            return bad("seconds", self.seconds, "more than 0 and at most 3600 seconds");
        }
        let n = (self.seconds * self.fps).round() as usize;
        if n < 1 {
            return bad("seconds", self.seconds, "at least one frame interval (1 / fps)");
        }
        if !(self.preroll.is_finite() && (0.0..=600.0).contains(&self.preroll)) {
            return bad("preroll", self.preroll, "0 to 600 seconds");
        }
        if !(self.sim_rate.is_finite() && self.sim_rate >= self.fps && self.sim_rate <= 2000.0) {
            return bad("sim_rate", self.sim_rate, "at least fps and at most 2000 steps per second");
        }
        let blend_frames = if self.looped {
            if !(self.blend.is_finite() && self.blend >= 0.0) {
                return bad("blend", self.blend, "a non-negative number of seconds");
            }
            let b = (self.blend * self.fps).round() as usize;
            if b < 2 || b > n / 2 {
                return Err(BakeError::Param {
                    field: "blend",
                    value: self.blend.to_string(),
                    expected: format!(
                        "a loop's cross-fade of at least 2 frames and at most half the clip: {} to {} s at {} fps",
                        2.0 / self.fps,
                        (n / 2) as f32 / self.fps,
                        self.fps
                    ),
                });
            }
            b
        } else {
            0
        };
        let frames = (n + 1 + blend_frames) as u64;
        if frames * segments as u64 > MAX_CLIP_VALUES {
            return Err(BakeError::TooLarge { frames, segments: segments as u64, limit: MAX_CLIP_VALUES });
        }
        let steps = (self.sim_rate / self.fps).ceil().max(1.0) as usize;
        Ok((n, blend_frames, steps))
    }
}

/// Bakes `anim` (from its current state, in `wind`) into a clip: `params.preroll` of
/// simulated time first, then a key every `1 / fps` s. `progress(done, total)` is called
/// after each simulated frame.
pub fn bake(
    anim: &mut dyn Animator,
    wind: &WindScene,
    params: &BakeParams,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Clip, BakeError> {
    let tree = anim.tree().clone();
    let tree = &*tree;
    let values = 3 * tree.segments.len() + if params.per_leaf { tree.leaves.len() } else { 0 };
    let (n, blend, steps) = params.check(values)?;
    anim.set_wind(std::sync::Arc::new(wind.packed()));
    let dt = 1.0 / (params.fps * steps as f32);
    // Preroll: whole frames of simulated time before frame 0.
    let pre_frames = (params.preroll * params.fps).round() as usize;
    anim.advance(dt, pre_frames * steps);
    let total = n + 1 + blend;
    let mut joints = Vec::with_capacity(total);
    let mut acc = Vec::with_capacity(total);
    let mut leaves = Vec::with_capacity(total);
    let mut sums = Vec::with_capacity(total);
    let mut seam = SeamPose::default();
    for k in 0..total {
        anim.advance(dt, if k == 0 { 0 } else { steps });
        anim.seam(&mut seam);
        joints.push(seam.joints.clone());
        acc.push(seam.acc.clone());
        sums.push(leaf_sums(tree, &seam.leaf));
        leaves.push(if params.per_leaf { seam.leaf.clone() } else { Vec::new() });
        progress(k + 1, total);
    }
    if params.looped {
        let mut out_j = Vec::with_capacity(n + 1);
        let mut out_a = Vec::with_capacity(n + 1);
        let mut out_l = Vec::with_capacity(n + 1);
        let mut out_s = Vec::with_capacity(n + 1);
        for k in 0..n {
            if k < blend {
                let x = k as f32 / blend as f32;
                let w = x * x * (3.0 - 2.0 * x);
                let (j, a) = blend_poses(tree, (&joints[k + n], &acc[k + n]), (&joints[k], &acc[k]), w);
                out_j.push(j);
                out_a.push(a);
                out_l.push(blend_leaves(&leaves[k + n], &leaves[k], w));
                out_s.push(blend_sums(&sums[k + n], &sums[k], w));
            } else {
                out_j.push(std::mem::take(&mut joints[k]));
                out_a.push(std::mem::take(&mut acc[k]));
                out_l.push(std::mem::take(&mut leaves[k]));
                out_s.push(std::mem::take(&mut sums[k]));
            }
        }
        out_j.push(out_j[0].clone());
        out_a.push(out_a[0].clone());
        out_l.push(out_l[0].clone());
        out_s.push(out_s[0].clone());
        joints = out_j;
        acc = out_a;
        leaves = out_l;
        sums = out_s;
    }
    Ok(Clip { fps: params.fps, looped: params.looped, joints, acc, leaves, leaf_sums: sums })
}

/// Per segment, the sum of its leaves' rotations `leaf` (by leaf index; a missing one at
/// rest), each in the identity's hemisphere.
pub fn leaf_sums(tree: &Tree, leaf: &[[f32; 4]]) -> Vec<[f32; 4]> {
    let mut sum = vec![glam::Vec4::ZERO; tree.segments.len()];
    for (i, &s) in tree.leaves.segment.iter().enumerate() {
        let q = leaf.get(i).map_or(glam::Vec4::W, |q| glam::Vec4::from_array(*q));
        sum[s as usize] += if q.w < 0.0 { -q } else { q };
    }
    sum.iter().map(|v| v.to_array()).collect()
}

/// Leaf sums `a` blended toward `b` by `w`, each pair lerped in one hemisphere.
fn blend_sums(a: &[[f32; 4]], b: &[[f32; 4]], w: f32) -> Vec<[f32; 4]> {
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            let (x, y) = (glam::Vec4::from_array(*x), glam::Vec4::from_array(*y));
            x.lerp(if x.dot(y) < 0.0 { -y } else { y }, w).to_array()
        })
        .collect()
}

/// Each segment's transform relative to its parent's: rotation `D_p⁻¹ D` and offset
/// `D_p⁻¹ (j − j_p)` (the root's relative to the world).
pub fn local_transforms(tree: &Tree, joints: &[[f32; 4]], acc: &[[f32; 4]]) -> (Vec<Quat>, Vec<Vec3>) {
    let s = &tree.segments;
    (0..s.len())
        .map(|i| {
            let d = Quat::from_array(acc[i]);
            let j = Vec3::from_slice(&joints[i][..3]);
            match s.parent[i] {
                NONE => (d, j),
                p => {
                    let dp_inv = Quat::from_array(acc[p as usize]).conjugate();
                    ((dp_inv * d).normalize(), dp_inv * (j - Vec3::from_slice(&joints[p as usize][..3])))
                }
            }
        })
        .unzip()
}

/// Rebuilds joints and accumulated rotations from local transforms, root to tip (segments
/// are in topological order).
pub fn from_local_transforms(tree: &Tree, rot: &[Quat], offset: &[Vec3]) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let s = &tree.segments;
    let mut d = vec![Quat::IDENTITY; s.len()];
    let mut j = vec![Vec3::ZERO; s.len()];
    for i in 0..s.len() {
        match s.parent[i] {
            NONE => {
                d[i] = rot[i];
                j[i] = offset[i];
            }
            p => {
                let p = p as usize;
                d[i] = (d[p] * rot[i]).normalize();
                j[i] = j[p] + d[p] * offset[i];
            }
        }
    }
    (j.iter().map(|p| p.extend(0.0).to_array()).collect(), d.iter().map(|q| q.to_array()).collect())
}

/// Leaf rotations `a` blended toward `b` by `w` (0 = a, 1 = b); an empty side is at rest.
fn blend_leaves(a: &[[f32; 4]], b: &[[f32; 4]], w: f32) -> Vec<[f32; 4]> {
    let at = |x: &[[f32; 4]], i: usize| x.get(i).map_or(Quat::IDENTITY, |q| Quat::from_array(*q));
    (0..a.len().max(b.len())).map(|i| quat_slerp(at(a, i), at(b, i), w).to_array()).collect()
}

/// `a` blended toward `b` by `w` (0 = a, 1 = b), per segment in local terms.
fn blend_poses(
    tree: &Tree,
    a: (&[[f32; 4]], &[[f32; 4]]),
    b: (&[[f32; 4]], &[[f32; 4]]),
    w: f32,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let (ra, oa) = local_transforms(tree, a.0, a.1);
    let (rb, ob) = local_transforms(tree, b.0, b.1);
    let rot: Vec<Quat> = ra.iter().zip(&rb).map(|(x, y)| quat_slerp(*x, *y, w)).collect();
    let off: Vec<Vec3> = oa.iter().zip(&ob).map(|(x, y)| x.lerp(*y, w)).collect();
    from_local_transforms(tree, &rot, &off)
}
