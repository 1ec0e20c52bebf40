//! Skinning (Zioma §6.5): a static rest mesh whose vertices follow the per-segment pose by
//! linear blend skinning with at most two bones — the cheap path for forests, where one
//! rest mesh serves every instance and only each instance's pose differs.
//!
//! Bones are segments; a bone's transform maps rest to pose rigidly,
//! `x ↦ joint_b + D_b (x − rest_b)` (joint position, accumulated rotation, rest joint), the
//! same transform that carries a leaf in [`crate::mesh::mesh_leaves`]. A bark vertex on a
//! ring at parameter t of segment i blends segment i with its neighbour in the stem toward
//! the nearer joint — weight ½ − t of the previous segment for t < ½, t − ½ of the next for
//! t > ½ — so a joint ring is exactly half each and the skin bends smoothly there. The
//! lower half of a stem's first segment pairs with the branch it grows from, as Zioma pairs
//! a vertex with "the branch one step higher in the hierarchy", weighted by distance from
//! the branch's origin and by stiffness: `(½ − t) · min(1, 2k / (k + k_parent))`, so a
//! twig much more flexible than its parent hinges at its base and one as stiff bends with
//! it. A trunk's base pairs with nothing (the paper's identity). A leaf vertex follows its
//! segment alone, after its leaf's rotation has turned it about the leaf's attachment
//! (every instance takes the same leaf rotations: the first instance's).
//!
//! The CPU reference `mesh::skin_vertices` is the twin of `skin_vertices.wgsl`; both write
//! instance-major output (`instance × vertices + vertex`) from instance-major poses.

use super::{MeshLayout, RawVertex};
use crate::model::NONE;
use bytemuck::{Pod, Zeroable};

/// Two bones and the second's weight, 16 bytes. WGSL: `struct Skin` in `skin_vertices.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawSkin {
    /// First bone (segment), weight `1 − weight`.
    pub bone0: u32,
    /// Second bone (segment), weight `weight`.
    pub bone1: u32,
    /// Weight of the second bone, 0…½.
    pub weight: f32,
    /// 1 + the index of the leaf whose rotation turns this vertex about the leaf's
    /// attachment before the bones carry it ([`crate::pose::SeamPose::leaf`]); 0 for bark.
    pub leaf: u32,
}

/// Sizes for the kernel, 16 bytes. WGSL: `struct SkinInfo`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawSkinInfo {
    /// Vertices of one instance.
    pub vertices: u32,
    /// Segments of one instance (the pose stride).
    pub segments: u32,
    /// Instances skinned by this dispatch.
    pub instances: u32,
    /// The first of them: instance `k` of the dispatch reads pose `first_instance + k` and
    /// writes `out[k × vertices ..]` (batches keep each output under the binding limit).
    pub first_instance: u32,
}

/// How much a stem's base follows the branch it grows from, 0…1: `min(1, 2k / (k + k_p))`
/// for stiffnesses k (the stem's first segment) and k_p (the parent segment).
pub fn base_weight(k: f32, k_parent: f32) -> f32 {
    if k + k_parent > 0.0 && (k + k_parent).is_finite() { (2.0 * k / (k + k_parent)).min(1.0) } else { 0.0 }
}

/// A rest mesh with its bone weights, bark and leaves in separate ranges (as
/// [`super::MeshFrame`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SkinLayout {
    /// Rest bark vertices.
    pub tube_rest: Vec<RawVertex>,
    /// Bark bones.
    pub tube_skin: Vec<RawSkin>,
    /// Rest leaf vertices.
    pub leaf_rest: Vec<RawVertex>,
    /// Leaf bones.
    pub leaf_skin: Vec<RawSkin>,
    /// Rest joint of every segment (w = 0): the bones' rest frames.
    pub rest_joint: Vec<[f32; 4]>,
    /// Rest attachment of every leaf (w = 0), by leaf index: where its rotation turns it.
    pub leaf_attach: Vec<[f32; 4]>,
    /// Segments per instance.
    pub segments: u32,
}

impl SkinLayout {
    /// The rest mesh of `layout` (meshed from the rest pose) and its weights.
    pub fn new(layout: &MeshLayout) -> Self {
        let n = layout.segments.len();
        let joint: Vec<[f32; 4]> = layout.segments.iter().map(|s| [s.start[0], s.start[1], s.start[2], 0.0]).collect();
        let acc = vec![[0.0, 0.0, 0.0, 1.0]; n];
        let rest = layout.mesh_raw(&joint, &acc);
        let stride = layout.params.sides as usize + 1;
        let mut tube_skin = Vec::with_capacity(rest.tubes.len());
        let segments = &layout.segments;
        let bones = |r: &super::RawRing, t: f32| {
            let own = &segments[r.segment as usize];
            let (bone1, weight) = if t < 0.5 && r.prev != NONE {
                (r.prev, 0.5 - t)
            } else if t < 0.5 && own.parent != NONE {
                (own.parent, (0.5 - t) * base_weight(own.stiffness, segments[own.parent as usize].stiffness))
            } else if t > 0.5 && r.next != NONE {
                (r.next, t - 0.5)
            } else {
                (r.segment, 0.0)
            };
            RawSkin { bone0: r.segment, bone1, weight, leaf: 0 }
        };
        for r in &layout.rings {
            tube_skin.extend(std::iter::repeat_n(bones(r, r.t), stride));
        }
        // Midpoints of subdivided bands: on their ring's segment at their own parameter.
        tube_skin.extend(layout.details.iter().map(|d| bones(&layout.rings[d.ring as usize], d.t)));
        let leaf_stride = layout.params.leaf_sides as usize + 1;
        let leaf_skin = layout
            .leaves
            .iter()
            .flat_map(|l| {
                std::iter::repeat_n(
                    RawSkin { bone0: l.segment, bone1: l.segment, weight: 0.0, leaf: l.index + 1 },
                    leaf_stride,
                )
            })
            .collect();
        let mut leaf_attach = vec![[0.0f32; 4]; layout.leaf_slots as usize];
        for l in &layout.leaves {
            if let Some(a) = leaf_attach.get_mut(l.index as usize) {
                *a = [l.position[0], l.position[1], l.position[2], 0.0];
            }
        }
        Self {
            tube_rest: rest.tubes,
            tube_skin,
            leaf_rest: rest.leaves,
            leaf_skin,
            rest_joint: joint,
            leaf_attach,
            segments: n as u32,
        }
    }

    /// Skins `instances` poses (instance-major joints and rotations) on the CPU: bark and
    /// leaves, instance-major, leaves at rest on their segments.
    pub fn skin(&self, joint: &[[f32; 4]], acc: &[[f32; 4]], instances: u32) -> super::MeshFrame {
        self.skin_with_leaves(joint, acc, &[], instances)
    }

    /// As [`Self::skin`], every instance's leaves turned by `leaf_rotation` (one per leaf,
    /// shared by the instances; empty: at rest).
    pub fn skin_with_leaves(
        &self,
        joint: &[[f32; 4]],
        acc: &[[f32; 4]],
        leaf_rotation: &[[f32; 4]],
        instances: u32,
    ) -> super::MeshFrame {
        let run = |rest: &[RawVertex], skin: &[RawSkin]| {
            let info =
                RawSkinInfo { vertices: rest.len() as u32, segments: self.segments, instances, first_instance: 0 };
            let mut out = vec![RawVertex::zeroed(); rest.len() * instances as usize];
            let leaves = [&self.leaf_attach[..], leaf_rotation];
            crate::mesh::skin_vertices(&info, rest, skin, &self.rest_joint, joint, acc, &mut out, leaves);
            out
        };
        super::MeshFrame { tubes: run(&self.tube_rest, &self.tube_skin), leaves: run(&self.leaf_rest, &self.leaf_skin) }
    }
}
