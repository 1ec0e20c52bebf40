//! The tree model: one representation consumed by every animation method and mesher.
//!
//! A [`Tree`] is a skeleton of straight **segments** (Akagi §2.1: position, orientation
//! quaternion, radius, length; Zioma §6.3.2/§6.4: a hierarchy whose rotations are
//! concatenated from the root), grouped into **stems** (a branch = a chain of segments,
//! Weber & Penn; each with one cubic Bézier, Skjermo §2.1), plus **leaves** attached to
//! segments. Everything is stored as structure-of-arrays in topological order: a segment's
//! parent always has a smaller index (Song §5.1, the linearised layout the GPU needs), and
//! every segment's children are a contiguous run of a flat index array (offset + count).
//!
//! Conventions: SI units (metres, kilograms, pascals), right-handed, **+Y up**. A segment's
//! local frame has its axis along local **+Y**; a leaf's blade extends along local +Y from
//! its attachment point, its width along local X and its face normal along local +Z.

mod bezier;
mod builder;
mod digest;
pub mod leaf_motion;
pub mod leaf_shape;
mod raw;
mod validate;

pub use bezier::{CubicBezier, fit_cubic_bezier};
pub use builder::{LeafDraft, SegmentDraft, StemDraft, TreeBuilder};
pub use leaf_motion::LeafMotion;
pub use leaf_shape::LeafShape;
pub use raw::{RawLeaf, RawSegment, RawStem};
pub use validate::ModelError;

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};

/// Index value meaning "none" (the root segment's parent, a trunk's parent stem).
pub const NONE: u32 = u32::MAX;

/// Material properties of wood and leaves, used to derive per-segment mass and stiffness.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WoodProperties {
    /// Young's modulus of green (living) wood along the grain, Pa. Default 8 GPa: the USDA
    /// Wood Handbook lists 6–12 GPa for green hardwoods and softwoods; living branches are
    /// green, so green values apply.
    pub young_modulus: f32,
    /// Density of green wood, kg/m³. Default 800: green wood with its water is typically
    /// 700–1,000 kg/m³.
    pub density: f32,
    /// Mass of leaf blade per area, kg/m². Default 0.2: fresh leaves are 0.1–0.3 kg/m².
    pub leaf_areal_density: f32,
}

impl Default for WoodProperties {
    fn default() -> Self {
        Self { young_modulus: 8.0e9, density: 800.0, leaf_areal_density: 0.2 }
    }
}

impl WoodProperties {
    /// Mass of a truncated cone of length `l` between radii `r0` and `r1`, kg.
    pub fn segment_mass(&self, l: f32, r0: f32, r1: f32) -> f32 {
        self.density * std::f32::consts::PI * l * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0
    }

    /// Rotational stiffness of the joint at a segment's base, N·m/rad: `k = E·I/L` with the
    /// second moment of area of a round section `I = π r⁴ / 4` at the base radius — the
    /// moment that turns the end of a cantilever of length `L` by one radian.
    pub fn segment_stiffness(&self, l: f32, r_base: f32) -> f32 {
        let i = std::f32::consts::FRAC_PI_4 * r_base.powi(4);
        self.young_modulus * i / l.max(1e-6)
    }
}

/// Breast height, where forestry measures a trunk's diameter (DBH), m.
pub const BREAST_HEIGHT: f32 = 1.3;

/// Per-segment arrays (structure of arrays), in topological order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Segments {
    /// Parent segment index, [`NONE`] for a root. Always smaller than the segment's index.
    pub parent: Vec<u32>,
    /// Branching level: 0 = trunk, 1 = branches on the trunk, …
    pub level: Vec<u8>,
    /// Stem this segment belongs to.
    pub stem: Vec<u32>,
    /// Rest position of the segment's start (its joint with the parent), m.
    pub start: Vec<Vec3>,
    /// Rest orientation in world space (unit quaternion; local +Y is the segment's axis).
    pub orientation: Vec<Quat>,
    /// Rest orientation relative to the parent segment:
    /// `orientation[i] = orientation[parent[i]] * local_orientation[i]`.
    pub local_orientation: Vec<Quat>,
    /// Length along the axis, m.
    pub length: Vec<f32>,
    /// Radius at the start, m.
    pub radius_base: Vec<f32>,
    /// Radius at the end, m.
    pub radius_tip: Vec<f32>,
    /// Mass of the wood of this segment, kg ([`WoodProperties::segment_mass`]).
    pub mass: Vec<f32>,
    /// Rotational stiffness at the base joint, N·m/rad ([`WoodProperties::segment_stiffness`]).
    pub stiffness: Vec<f32>,
}

impl Segments {
    /// Number of segments.
    pub fn len(&self) -> usize {
        self.parent.len()
    }
    /// True when there are no segments.
    pub fn is_empty(&self) -> bool {
        self.parent.is_empty()
    }
    /// Rest position of segment `i`'s end.
    pub fn end(&self, i: usize) -> Vec3 {
        self.start[i] + self.orientation[i] * Vec3::new(0.0, self.length[i], 0.0)
    }
    /// Unit axis direction of segment `i` in world space.
    pub fn axis(&self, i: usize) -> Vec3 {
        self.orientation[i] * Vec3::Y
    }
}

/// Per-stem arrays. A stem is a chain of consecutive segments `first_segment ..
/// first_segment + segment_count`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stems {
    /// Parent stem, [`NONE`] for a trunk.
    pub parent: Vec<u32>,
    /// Branching level (same as its segments').
    pub level: Vec<u8>,
    /// Index of the first segment.
    pub first_segment: Vec<u32>,
    /// Number of segments.
    pub segment_count: Vec<u32>,
    /// Where the stem attaches along its parent, as a fraction of the parent's arc length
    /// (0 = parent's base, 1 = parent's tip). 0 for trunks.
    pub attach: Vec<f32>,
    /// Arc length of the centreline, m.
    pub length: Vec<f32>,
    /// Cubic Bézier control points fitted to the centreline (P0 = base, P3 = tip).
    pub bezier: Vec<[Vec3; 4]>,
    /// Largest distance from a segment joint to the fitted Bézier, m.
    pub bezier_error: Vec<f32>,
}

impl Stems {
    /// Number of stems.
    pub fn len(&self) -> usize {
        self.parent.len()
    }
    /// True when there are no stems.
    pub fn is_empty(&self) -> bool {
        self.parent.is_empty()
    }
}

/// Per-leaf arrays, sorted by the segment they are attached to.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Leaves {
    /// Segment the leaf is attached to.
    pub segment: Vec<u32>,
    /// Attachment point (base of the blade), m.
    pub position: Vec<Vec3>,
    /// Orientation (unit quaternion): blade along local +Y, width along X, normal along +Z.
    pub orientation: Vec<Quat>,
    /// Blade width, m.
    pub width: Vec<f32>,
    /// Blade length, m.
    pub length: Vec<f32>,
}

impl Leaves {
    /// Number of leaves.
    pub fn len(&self) -> usize {
        self.segment.len()
    }
    /// True when there are no leaves.
    pub fn is_empty(&self) -> bool {
        self.segment.is_empty()
    }
}

/// Children as flat arrays (Song §5.1, Fig. 8): the children of segment `i` are
/// `index[offset[i] .. offset[i] + count[i]]`, in increasing order. Leaves likewise:
/// the leaves of segment `i` are `leaf_offset[i] .. leaf_offset[i] + leaf_count[i]`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Children {
    /// Start of each segment's run in `index`.
    pub offset: Vec<u32>,
    /// Number of children of each segment.
    pub count: Vec<u32>,
    /// Child segment indices, grouped by parent.
    pub index: Vec<u32>,
    /// Start of each segment's run of leaves.
    pub leaf_offset: Vec<u32>,
    /// Number of leaves on each segment.
    pub leaf_count: Vec<u32>,
    /// Largest child count of any segment (Song's "maximum number of child clusters").
    pub max_children: u32,
}

impl Children {
    /// The children of segment `i`.
    pub fn of(&self, i: usize) -> &[u32] {
        let o = self.offset[i] as usize;
        &self.index[o..o + self.count[i] as usize]
    }
}

/// A generated tree: skeleton, stems, leaves and flat child lists.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tree {
    /// Name of the species or grammar it came from.
    pub name: String,
    /// Seed it was generated with.
    pub seed: u64,
    /// Number of stem levels (trunk = level 0).
    pub levels: u8,
    /// Segment arrays.
    pub segments: Segments,
    /// Stem arrays.
    pub stems: Stems,
    /// Leaf arrays.
    pub leaves: Leaves,
    /// Flat child lists.
    pub children: Children,
    /// Wood properties used for mass and stiffness.
    pub wood: WoodProperties,
    /// The trunk's cross-section as the species describes it (flare, lobes, bulges): what
    /// the segment radii already hold (flare) and what only a mesher adds (lobes, bulges).
    pub trunk_shape: TrunkShape,
    /// The outline of every leaf (Weber–Penn `LeafShape`).
    pub leaf_shape: LeafShape,
    /// How its leaves move about their petioles.
    pub leaf_motion: LeafMotion,
}

/// The trunk's shape beyond its segments' radii (Weber–Penn `Flare`, `Lobes`, `LobeDepth`;
/// Skjermo's bulges, eq. 4). Zero for L-system trees: a round, unflared trunk.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TrunkShape {
    /// Weber–Penn `Flare`: the base radius is `1 + 0.99 flare` times the unflared radius,
    /// fading out over the lowest eighth of the trunk. Already in the segments' radii.
    pub flare: f32,
    /// Weber–Penn `Lobes` of the trunk's cross-section.
    pub lobes: u32,
    /// Weber–Penn `LobeDepth`: `1 + d sin(lobes θ)`.
    pub lobe_depth: f32,
    /// Skjermo's bulges along each stem (eq. 4, `b_n`).
    pub bulges: f32,
    /// Bulge depth (eq. 4, `b_d`).
    pub bulge_depth: f32,
}

impl TrunkShape {
    /// Weber–Penn's flare factor at height fraction `z` of the trunk:
    /// `flare (100^y − 1) / 100 + 1`, `y = max(1 − 8z, 0)`.
    pub fn flare_factor(&self, z: f32) -> f32 {
        let y = (1.0 - 8.0 * z).max(0.0);
        self.flare * (100f32.powf(y) - 1.0) / 100.0 + 1.0
    }
}

/// Summary figures of a tree.
#[derive(Debug, Clone, PartialEq)]
pub struct TreeStats {
    /// Segments per level.
    pub segments_per_level: Vec<usize>,
    /// Stems per level.
    pub stems_per_level: Vec<usize>,
    /// Leaves per level of the segment they hang on.
    pub leaves_per_level: Vec<usize>,
    /// Height of the highest point above the lowest, m.
    pub height: f32,
    /// Largest horizontal extent (x or z) of segments and leaves, m.
    pub crown_width: f32,
    /// Total wood mass, kg.
    pub mass: f32,
    /// Bytes held by the model's arrays.
    pub memory_bytes: usize,
}

impl Tree {
    /// Summary statistics.
    pub fn stats(&self) -> TreeStats {
        let levels = self.segments.level.iter().map(|&l| l as usize + 1).max().unwrap_or(0);
        let mut segments_per_level = vec![0; levels];
        for &l in &self.segments.level {
            segments_per_level[l as usize] += 1;
        }
        let mut stems_per_level = vec![0; levels];
        for &l in &self.stems.level {
            stems_per_level[l as usize] += 1;
        }
        let mut leaves_per_level = vec![0; levels];
        for &s in &self.leaves.segment {
            leaves_per_level[self.segments.level[s as usize] as usize] += 1;
        }
        let (lo, hi) = self.bounds();
        let memory_bytes = self.segments.len() * std::mem::size_of::<RawSegment>()
            + self.stems.len() * std::mem::size_of::<RawStem>()
            + self.leaves.len() * std::mem::size_of::<RawLeaf>()
            + (self.children.index.len() + 4 * self.segments.len()) * 4;
        TreeStats {
            segments_per_level,
            stems_per_level,
            leaves_per_level,
            height: hi.y - lo.y,
            crown_width: (hi.x - lo.x).max(hi.z - lo.z),
            mass: self.segments.mass.iter().sum(),
            memory_bytes,
        }
    }

    /// The same tree moved by `offset` (m): a neighbour standing elsewhere in the same wind.
    pub fn translated(&self, offset: Vec3) -> Tree {
        let mut t = self.clone();
        t.segments.start.iter_mut().for_each(|p| *p += offset);
        t.stems.bezier.iter_mut().flatten().for_each(|p| *p += offset);
        t.leaves.position.iter_mut().for_each(|p| *p += offset);
        t
    }

    /// Axis-aligned bounds of segment joints and leaf tips.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for i in 0..self.segments.len() {
            for p in [self.segments.start[i], self.segments.end(i)] {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        for i in 0..self.leaves.len() {
            let tip = self.leaves.position[i] + self.leaves.orientation[i] * Vec3::new(0.0, self.leaves.length[i], 0.0);
            for p in [self.leaves.position[i], tip] {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        if lo.x > hi.x {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        (lo, hi)
    }

    /// Height of the tree (highest minus lowest point), m.
    pub fn height(&self) -> f32 {
        let (lo, hi) = self.bounds();
        hi.y - lo.y
    }

    /// Trunk diameter at breast height (1.3 m above the trunk's base, along its axis), m; for
    /// a trunk shorter than that, its diameter at mid-length. Where the trunk has forked
    /// below that height, the diameter of the section of its stems there together, `√Σd²`
    /// (as multi-stemmed trees are measured). `None` without stems.
    pub fn dbh(&self) -> Option<f32> {
        let st = &self.stems;
        if st.is_empty() || st.segment_count[0] == 0 {
            return None;
        }
        let target = BREAST_HEIGHT.min(0.5 * st.length[0]);
        // Arc length from the trunk's base to where each of its stems (clones) starts.
        let mut base = vec![f32::NAN; st.len()];
        base[0] = 0.0;
        let mut section = 0.0f32;
        for k in 0..st.len() {
            if k > 0 {
                let p = st.parent[k] as usize;
                if st.level[k] != 0 || p >= k || base[p].is_nan() {
                    continue;
                }
                base[k] = base[p] + st.attach[k] * st.length[p];
            }
            if let Some(d) = self.diameter_along(k, target - base[k]) {
                section += d * d;
            }
        }
        Some(section.sqrt())
    }

    /// Diameter of stem `k` at arc length `at` from its base, m; `None` where `at` is off the
    /// stem (stem 0 reads its tip's beyond its length).
    fn diameter_along(&self, k: usize, at: f32) -> Option<f32> {
        let (st, s) = (&self.stems, &self.segments);
        let (first, n) = (st.first_segment[k] as usize, st.segment_count[k] as usize);
        if n == 0 || at < 0.0 || (k > 0 && at >= st.length[k]) {
            return None;
        }
        let mut along = 0.0;
        for i in first..first + n {
            if along + s.length[i] >= at || i + 1 == first + n {
                let f = ((at - along) / s.length[i].max(1e-9)).clamp(0.0, 1.0);
                return Some(2.0 * (s.radius_base[i] + (s.radius_tip[i] - s.radius_base[i]) * f));
            }
            along += s.length[i];
        }
        None
    }

    /// Packed segments for GPU upload (see [`RawSegment`]).
    pub fn raw_segments(&self) -> Vec<RawSegment> {
        (0..self.segments.len()).map(|i| RawSegment::from_tree(self, i)).collect()
    }

    /// Packed stems for GPU upload (see [`RawStem`]).
    pub fn raw_stems(&self) -> Vec<RawStem> {
        (0..self.stems.len()).map(|i| RawStem::from_tree(self, i)).collect()
    }

    /// Packed leaves for GPU upload (see [`RawLeaf`]).
    pub fn raw_leaves(&self) -> Vec<RawLeaf> {
        (0..self.leaves.len()).map(|i| RawLeaf::from_tree(self, i)).collect()
    }

    /// SHA-256 of every array of the tree, as hex: equal digests mean bit-identical trees.
    pub fn digest(&self) -> String {
        digest::digest(self)
    }

    /// Checks every invariant of the model (see [`ModelError`]).
    pub fn validate(&self) -> Result<(), ModelError> {
        validate::validate(self)
    }
}
