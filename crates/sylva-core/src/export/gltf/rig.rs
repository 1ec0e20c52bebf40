//! The skin's joints (per segment or per stem, and a leaf joint per leaf-bearing joint),
//! the hierarchy attributes of every element, and tangents: what each vertex of an
//! exported mesh is bound to and carries.

use super::*;

/// Joints: which segment drives each and its parent joint, then the leaf joints.
#[derive(Debug)]
pub(super) struct Rig {
    pub(super) mode: JointMode,
    /// Joint of each segment.
    pub(super) joint_of_segment: Vec<u32>,
    /// Segment driving each skeleton joint.
    pub(super) driver: Vec<usize>,
    /// Parent joint of each skeleton joint ([`NONE`] for a root).
    pub(super) parent: Vec<u32>,
    /// Leaf joints: joint `driver.len() + g` is `leaf_groups[g]`.
    pub(super) leaf_groups: Vec<LeafGroup>,
    /// Leaf joint of each skeleton joint ([`NONE`]: none, its leaves are rigid with it).
    pub(super) leaf_joint: Vec<u32>,
}

/// The leaves hanging on one skeleton joint, turned together by one leaf joint.
#[derive(Debug)]
pub(super) struct LeafGroup {
    /// The skeleton joint the leaves hang on: the leaf joint's parent.
    pub(super) parent: u32,
    /// Rest pivot: the mean of the leaves' attachments, m.
    pub(super) pivot: Vec3,
    /// The leaves (indices into the tree's leaves).
    pub(super) leaves: Vec<u32>,
}

impl Rig {
    /// The skeleton in `mode`; with `leaf_joints`, a leaf joint for every joint that
    /// carries leaves.
    pub(super) fn new(tree: &Tree, mode: JointMode, leaf_joints: bool) -> Self {
        let s = &tree.segments;
        let (joint_of_segment, driver, parent) = match mode {
            JointMode::Segment => ((0..s.len() as u32).collect(), (0..s.len()).collect(), s.parent.clone()),
            JointMode::Stem => (
                s.stem.clone(),
                tree.stems.first_segment.iter().map(|&f| f as usize).collect::<Vec<_>>(),
                tree.stems.parent.clone(),
            ),
        };
        let mut leaf_joint = vec![NONE; driver.len()];
        let mut leaf_groups: Vec<LeafGroup> = Vec::new();
        if leaf_joints {
            let l = &tree.leaves;
            for i in 0..l.len() {
                let j = joint_of_segment[l.segment[i] as usize];
                if leaf_joint[j as usize] == NONE {
                    leaf_joint[j as usize] = leaf_groups.len() as u32;
                    leaf_groups.push(LeafGroup { parent: j, pivot: Vec3::ZERO, leaves: Vec::new() });
                }
                leaf_groups[leaf_joint[j as usize] as usize].leaves.push(i as u32);
            }
            for g in &mut leaf_groups {
                let sum: Vec3 = g.leaves.iter().map(|&i| l.position[i as usize]).sum();
                g.pivot = sum / g.leaves.len() as f32;
            }
        }
        Self { mode, joint_of_segment, driver, parent, leaf_groups, leaf_joint }
    }

    /// Joints in all: the skeleton's, then the leaf joints.
    pub(super) fn joints(&self) -> usize {
        self.driver.len() + self.leaf_groups.len()
    }

    pub(super) fn name(&self, j: usize) -> String {
        let what = match self.mode {
            JointMode::Segment => "segment",
            JointMode::Stem => "stem",
        };
        match j.checked_sub(self.driver.len()) {
            None => format!("{what}_{j}"),
            Some(g) => format!("leaves_{what}_{}", self.leaf_groups[g].parent),
        }
    }

    /// Up to two joints and weights for a vertex bound to `skin`; a leaf vertex at blade
    /// coordinate `v` (0 at the attachment, 1 at the tip) blends its segment's joint into
    /// its leaf joint by `v`, so the attachment stays on the twig and the blade turns.
    pub(super) fn bind(&self, skin: &RawSkin, v: f32) -> ([u16; 4], [f32; 4]) {
        let a = self.joint_of_segment[skin.bone0 as usize];
        let b = self.joint_of_segment[skin.bone1 as usize];
        if skin.leaf != 0 && self.leaf_joint[a as usize] != NONE {
            let leaf = (self.driver.len() as u32 + self.leaf_joint[a as usize]) as u16;
            let w = v.clamp(0.0, 1.0);
            return if w == 0.0 {
                ([a as u16, 0, 0, 0], [1.0, 0.0, 0.0, 0.0])
            } else if w == 1.0 {
                ([leaf, 0, 0, 0], [1.0, 0.0, 0.0, 0.0])
            } else {
                ([a as u16, leaf, 0, 0], [1.0 - w, w, 0.0, 0.0])
            };
        }
        if a == b || skin.weight == 0.0 {
            ([a as u16, 0, 0, 0], [1.0, 0.0, 0.0, 0.0])
        } else {
            ([a as u16, b as u16, 0, 0], [1.0 - skin.weight, skin.weight, 0.0, 0.0])
        }
    }
}

/// A leaf group's rotation at one frame: the normalised sum of its leaves' rotations (each
/// in the hemisphere of the identity), relative to the segment they hang on; rest when the
/// frame has none.
pub(super) fn group_rotation(group: &LeafGroup, frame: &[[f32; 4]]) -> Quat {
    if frame.is_empty() {
        return Quat::IDENTITY;
    }
    let mut sum = Vec4::ZERO;
    for &i in &group.leaves {
        let q = frame.get(i as usize).map_or(Vec4::W, |q| Vec4::from_array(*q));
        sum += if q.w < 0.0 { -q } else { q };
    }
    sum.try_normalize().map_or(Quat::IDENTITY, Quat::from_vec4)
}

/// Per-element hierarchy data (see the module documentation).
#[derive(Debug, Clone, Copy)]
pub(super) struct Element {
    pub(super) pivot: Vec3,
    pub(super) axis: Vec3,
    pub(super) depth: f32,
    pub(super) parent_pivot: Vec3,
    pub(super) phase: f32,
}

pub(super) struct Hierarchy {
    pub(super) stems: Vec<Element>,
}

impl Hierarchy {
    pub(super) fn new(tree: &Tree) -> Self {
        let st = &tree.stems;
        let s = &tree.segments;
        let pivot: Vec<Vec3> = st.first_segment.iter().map(|&f| s.start[f as usize]).collect();
        let stems = (0..st.len())
            .map(|k| {
                let first = st.first_segment[k] as usize;
                let last = first + st.segment_count[k] as usize - 1;
                let axis = (s.end(last) - pivot[k]).try_normalize().unwrap_or(s.orientation[first] * Vec3::Y);
                Element {
                    pivot: pivot[k],
                    axis,
                    depth: st.level[k] as f32,
                    parent_pivot: if st.parent[k] == NONE { pivot[k] } else { pivot[st.parent[k] as usize] },
                    phase: crate::rng::hash_unit(crate::rng::child_key(tree.seed ^ 0x9a5e, k as u64)) as f32,
                }
            })
            .collect();
        Self { stems }
    }

    pub(super) fn bark(&self, tree: &Tree, segment: usize) -> Element {
        self.stems[tree.segments.stem[segment] as usize]
    }

    pub(super) fn leaf(&self, tree: &Tree, leaf: &RawLeaf) -> Element {
        let stem = &self.stems[tree.segments.stem[leaf.segment as usize] as usize];
        let p = Vec3::from_array(leaf.position);
        let bits = p.to_array().map(f32::to_bits);
        let key = (bits[0] as u64) << 32 ^ (bits[1] as u64) << 16 ^ bits[2] as u64;
        Element {
            pivot: p,
            axis: (Quat::from_array(leaf.orientation) * Vec3::Y).normalize(),
            depth: stem.depth + 1.0,
            parent_pivot: stem.pivot,
            phase: crate::rng::hash_unit(crate::rng::child_key(tree.seed ^ 0x1eaf, key)) as f32,
        }
    }
}

/// Per leaf of `tree`: its swing and twist frequencies (Hz) and flutter amplitude (rad,
/// [`crate::model::LeafMotion`]'s `flutter_deg × strength`), from [`crate::leaves`].
pub(super) fn leaf_flutter(tree: &Tree) -> Vec<[f32; 3]> {
    let f = crate::leaves::LeafFlutter::new(tree, tree.seed);
    let amplitude = f.params.flutter_deg.to_radians() * f.params.strength;
    let hz = |omega: f32| omega / std::f32::consts::TAU;
    f.leaves.iter().map(|m| [hz(m.omega), hz(m.omega_twist), amplitude]).collect()
}

/// One primitive's vertex streams.
pub(super) struct Geometry<'a> {
    pub(super) vertices: &'a [RawVertex],
    pub(super) skin: &'a [RawSkin],
    pub(super) indices: &'a [u32],
    pub(super) tangents: Vec<[f32; 4]>,
    pub(super) elements: Vec<Element>,
    /// Per vertex of a leaf primitive: swing and twist frequency (Hz) and flutter amplitude
    /// (rad) of its leaf, for an engine's flutter shader; empty for bark.
    pub(super) flutter: Vec<[f32; 3]>,
}

impl<'a> Geometry<'a> {
    pub(super) fn new(
        vertices: &'a [RawVertex],
        skin: &'a [RawSkin],
        indices: &'a [u32],
        element: impl Fn(usize, &RawSkin) -> Element,
    ) -> Self {
        Self {
            vertices,
            skin,
            indices,
            tangents: tangents(vertices, indices),
            elements: skin.iter().enumerate().map(|(v, s)| element(v, s)).collect(),
            flutter: Vec::new(),
        }
    }
}

/// Per-vertex tangents (xyz unit, w the handedness) from the texture coordinates: each
/// triangle's `∂P/∂u` and `∂P/∂v` summed at its corners, `∂P/∂u` made orthogonal to the
/// normal; a vertex without a usable gradient gets any tangent orthogonal to its normal.
pub fn tangents(vertices: &[RawVertex], indices: &[u32]) -> Vec<[f32; 4]> {
    let mut du = vec![Vec3::ZERO; vertices.len()];
    let mut dv = vec![Vec3::ZERO; vertices.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
        let p = |i: usize| Vec3::from_array(vertices[i].position);
        let (e1, e2) = (p(b) - p(a), p(c) - p(a));
        let (u1, v1) = (vertices[b].u - vertices[a].u, vertices[b].v - vertices[a].v);
        let (u2, v2) = (vertices[c].u - vertices[a].u, vertices[c].v - vertices[a].v);
        let det = u1 * v2 - u2 * v1;
        if det.abs() < 1e-12 {
            continue;
        }
        let r = 1.0 / det;
        let s = (e1 * v2 - e2 * v1) * r;
        let w = (e2 * u1 - e1 * u2) * r;
        for i in [a, b, c] {
            du[i] += s;
            dv[i] += w;
        }
    }
    vertices
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let n = Vec3::from_array(v.normal).normalize();
            let t = (du[i] - n * n.dot(du[i])).try_normalize().unwrap_or_else(|| n.any_orthonormal_vector());
            let w = if n.cross(t).dot(dv[i]) < 0.0 { -1.0 } else { 1.0 };
            [t.x, t.y, t.z, w]
        })
        .collect()
}
