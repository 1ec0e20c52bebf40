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
    /// The segments they hang on, each once.
    pub(super) segments: Vec<u32>,
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
            JointMode::Budget(limit) => {
                let order = thickest_first(tree);
                // Fewest heads dropped so that heads + leaf joints fit the budget.
                let mut k = order.len().min(limit.max(1));
                loop {
                    let heads = merged(tree, &order[..k]);
                    let groups = if leaf_joints { leaf_bearing(tree, &heads.0) } else { 0 };
                    if k + groups <= limit || k == 1 {
                        break heads;
                    }
                    k -= ((k + groups - limit) / 2).max(1).min(k - 1);
                }
            }
        };
        let mut leaf_joint = vec![NONE; driver.len()];
        let mut leaf_groups: Vec<LeafGroup> = Vec::new();
        if leaf_joints {
            let l = &tree.leaves;
            for i in 0..l.len() {
                let j = joint_of_segment[l.segment[i] as usize];
                if leaf_joint[j as usize] == NONE {
                    leaf_joint[j as usize] = leaf_groups.len() as u32;
                    leaf_groups.push(LeafGroup {
                        parent: j,
                        pivot: Vec3::ZERO,
                        leaves: Vec::new(),
                        segments: Vec::new(),
                    });
                }
                leaf_groups[leaf_joint[j as usize] as usize].leaves.push(i as u32);
            }
            for g in &mut leaf_groups {
                let sum: Vec3 = g.leaves.iter().map(|&i| l.position[i as usize]).sum();
                g.pivot = sum / g.leaves.len() as f32;
                g.segments = g.leaves.iter().map(|&i| l.segment[i as usize]).collect();
                g.segments.sort_unstable();
                g.segments.dedup();
            }
        }
        Self { mode, joint_of_segment, driver, parent, leaf_groups, leaf_joint }
    }

    /// Joints in all: the skeleton's, then the leaf joints.
    pub(super) fn joints(&self) -> usize {
        self.driver.len() + self.leaf_groups.len()
    }

    pub(super) fn name(&self, j: usize) -> String {
        // Joints per segment or budget are named by their head segment, per stem by the stem.
        let (what, number) = match self.mode {
            JointMode::Stem => ("stem", j),
            _ => ("segment", self.driver[j.min(self.driver.len() - 1)]),
        };
        match j.checked_sub(self.driver.len()) {
            None => format!("{what}_{number}"),
            Some(g) => {
                let p = self.leaf_groups[g].parent as usize;
                let number = if self.mode == JointMode::Stem { p } else { self.driver[p] };
                format!("leaves_{what}_{number}")
            }
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

/// Segments that may head a joint, thickest base first (ties by index): a stem's first
/// segment always may; a later one only after its stem's first (else it rides with it).
fn thickest_first(tree: &Tree) -> Vec<usize> {
    let s = &tree.segments;
    let mut order: Vec<usize> = (0..s.len()).collect();
    order.sort_by(|&a, &b| s.radius_base[b].total_cmp(&s.radius_base[a]).then(a.cmp(&b)));
    let mut stem_in = vec![false; tree.stems.len()];
    order.retain(|&i| {
        let k = s.stem[i] as usize;
        let first = tree.stems.first_segment[k] as usize == i;
        stem_in[k] |= first;
        first || stem_in[k]
    });
    order
}

/// The skeleton whose joints are headed by `heads`: every other segment rides with the
/// joint of the segment it hangs on (the root always heads one).
fn merged(tree: &Tree, heads: &[usize]) -> (Vec<u32>, Vec<usize>, Vec<u32>) {
    let s = &tree.segments;
    let mut head = vec![false; s.len()];
    for &h in heads {
        head[h] = true;
    }
    let (mut joint_of_segment, mut driver, mut parent) = (vec![0u32; s.len()], Vec::new(), Vec::new());
    for i in 0..s.len() {
        let p = s.parent[i];
        if head[i] || p == NONE {
            joint_of_segment[i] = driver.len() as u32;
            driver.push(i);
            parent.push(if p == NONE { NONE } else { joint_of_segment[p as usize] });
        } else {
            joint_of_segment[i] = joint_of_segment[p as usize];
        }
    }
    (joint_of_segment, driver, parent)
}

/// How many joints carry leaves.
fn leaf_bearing(tree: &Tree, joint_of_segment: &[u32]) -> usize {
    let mut seen = std::collections::HashSet::new();
    tree.leaves.segment.iter().filter(|&&s| seen.insert(joint_of_segment[s as usize])).count()
}

/// A leaf group's rotation at one frame: the normalised sum of its leaves' rotations (each
/// in the hemisphere of the identity) relative to the segment they hang on, from the frame's
/// per-segment sums ([`Clip::leaf_sums`]); rest when the frame has none.
pub(super) fn group_rotation(group: &LeafGroup, sums: &[[f32; 4]]) -> Quat {
    let sum: Vec4 = group.segments.iter().filter_map(|&s| sums.get(s as usize)).map(|q| Vec4::from_array(*q)).sum();
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
    pub(super) uv: &'a [Uv],
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
        uv: &'a [Uv],
        skin: &'a [RawSkin],
        indices: &'a [u32],
        element: impl Fn(usize, &RawSkin) -> Element,
    ) -> Self {
        Self {
            vertices,
            uv,
            skin,
            indices,
            tangents: tangents(vertices, uv, indices),
            elements: skin.iter().enumerate().map(|(v, s)| element(v, s)).collect(),
            flutter: Vec::new(),
        }
    }
}

/// Per-vertex tangents (xyz unit, w the handedness) by MikkTSpace (`bevy_mikktspace`, the
/// algorithm Blender, Unity, Unreal and glTF's sample viewer bake normal maps with), so a
/// normal map reads the same in every engine. A vertex shared by faces keeps the last face's
/// tangent (MikkTSpace would split it only where the faces disagree); one MikkTSpace leaves
/// without a value gets any tangent orthogonal to its normal.
pub fn tangents(vertices: &[RawVertex], uv: &[Uv], indices: &[u32]) -> Vec<[f32; 4]> {
    struct Mesh<'a> {
        vertices: &'a [RawVertex],
        uv: &'a [Uv],
        indices: &'a [u32],
        out: Vec<Option<[f32; 4]>>,
    }
    impl Mesh<'_> {
        fn at(&self, face: usize, vert: usize) -> &RawVertex {
            &self.vertices[self.indices[face * 3 + vert] as usize]
        }
    }
    impl bevy_mikktspace::Geometry for Mesh<'_> {
        fn num_faces(&self) -> usize {
            self.indices.len() / 3
        }
        fn num_vertices_of_face(&self, _: usize) -> usize {
            3
        }
        fn position(&self, face: usize, vert: usize) -> [f32; 3] {
            self.at(face, vert).position
        }
        fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
            self.at(face, vert).normal().to_array()
        }
        fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
            self.uv[self.indices[face * 3 + vert] as usize]
        }
        fn set_tangent(&mut self, t: Option<bevy_mikktspace::TangentSpace>, face: usize, vert: usize) {
            if let Some(t) = t {
                self.out[self.indices[face * 3 + vert] as usize] = Some(t.tangent_encoded());
            }
        }
    }
    let mut mesh = Mesh { vertices, uv, indices, out: vec![None; vertices.len()] };
    // An error only means no face could be processed: every vertex takes the fallback.
    let _ = bevy_mikktspace::generate_tangents(&mut mesh);
    vertices
        .iter()
        .zip(mesh.out)
        .map(|(v, t)| {
            let n = v.normal();
            match t {
                Some([x, y, z, w]) => match Vec3::new(x, y, z).try_normalize() {
                    Some(t) => [t.x, t.y, t.z, if w < 0.0 { -1.0 } else { 1.0 }],
                    None => fallback(n),
                },
                None => fallback(n),
            }
        })
        .collect()
}

fn fallback(n: Vec3) -> [f32; 4] {
    let t = n.any_orthonormal_vector();
    [t.x, t.y, t.z, 1.0]
}
