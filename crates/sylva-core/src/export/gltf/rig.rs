//! The skin's joints (per segment or per stem), the hierarchy attributes of every
//! element, and tangents: what each vertex of an exported mesh is bound to and carries.

use super::*;

/// Joints: which segment drives each and its parent joint.
#[derive(Debug)]
pub(super) struct Rig {
    pub(super) mode: JointMode,
    /// Joint of each segment.
    pub(super) joint_of_segment: Vec<u32>,
    /// Segment driving each joint.
    pub(super) driver: Vec<usize>,
    /// Parent joint ([`NONE`] for a root).
    pub(super) parent: Vec<u32>,
}

impl Rig {
    pub(super) fn new(tree: &Tree, mode: JointMode) -> Self {
        let s = &tree.segments;
        match mode {
            JointMode::Segment => Self {
                mode,
                joint_of_segment: (0..s.len() as u32).collect(),
                driver: (0..s.len()).collect(),
                parent: s.parent.clone(),
            },
            JointMode::Stem => Self {
                mode,
                joint_of_segment: s.stem.clone(),
                driver: tree.stems.first_segment.iter().map(|&f| f as usize).collect(),
                parent: tree.stems.parent.clone(),
            },
        }
    }

    pub(super) fn name(&self, j: usize) -> String {
        match self.mode {
            JointMode::Segment => format!("segment_{j}"),
            JointMode::Stem => format!("stem_{j}"),
        }
    }

    /// Up to two joints and weights for a vertex bound to `skin`.
    pub(super) fn bind(&self, skin: &RawSkin) -> ([u16; 4], [f32; 4]) {
        let a = self.joint_of_segment[skin.bone0 as usize] as u16;
        let b = self.joint_of_segment[skin.bone1 as usize] as u16;
        if a == b || skin.weight == 0.0 {
            ([a, 0, 0, 0], [1.0, 0.0, 0.0, 0.0])
        } else {
            ([a, b, 0, 0], [1.0 - skin.weight, skin.weight, 0.0, 0.0])
        }
    }
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

/// One primitive's vertex streams.
pub(super) struct Geometry<'a> {
    pub(super) vertices: &'a [RawVertex],
    pub(super) skin: &'a [RawSkin],
    pub(super) indices: &'a [u32],
    pub(super) tangents: Vec<[f32; 4]>,
    pub(super) elements: Vec<Element>,
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
