//! `#[repr(C)]` `Pod` twins of the model, padded as WGSL lays out the matching structs
//! (`sylva-gpu/src/wgsl/tree.wgsl`; a test there checks sizes and offsets with naga).

use super::Tree;
use bytemuck::{Pod, Zeroable};

/// One segment, 96 bytes. WGSL: `struct Segment` in `tree.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawSegment {
    /// Rest start position, m.
    pub start: [f32; 3],
    /// Length, m.
    pub length: f32,
    /// World rest orientation (x, y, z, w).
    pub orientation: [f32; 4],
    /// Orientation relative to the parent (x, y, z, w).
    pub local_orientation: [f32; 4],
    /// Radius at the start, m.
    pub radius_base: f32,
    /// Radius at the end, m.
    pub radius_tip: f32,
    /// Mass, kg.
    pub mass: f32,
    /// Rotational stiffness at the base joint, N·m/rad.
    pub stiffness: f32,
    /// Parent segment (`u32::MAX` for none).
    pub parent: u32,
    /// Branching level.
    pub level: u32,
    /// Stem index.
    pub stem: u32,
    /// Offset of the children run.
    pub child_offset: u32,
    /// Number of children.
    pub child_count: u32,
    /// Offset of the leaves run.
    pub leaf_offset: u32,
    /// Number of leaves.
    pub leaf_count: u32,
    /// Padding to a 16-byte multiple.
    pub _pad: u32,
}

impl RawSegment {
    pub(crate) fn from_tree(t: &Tree, i: usize) -> Self {
        let s = &t.segments;
        let c = &t.children;
        Self {
            start: s.start[i].to_array(),
            length: s.length[i],
            orientation: s.orientation[i].to_array(),
            local_orientation: s.local_orientation[i].to_array(),
            radius_base: s.radius_base[i],
            radius_tip: s.radius_tip[i],
            mass: s.mass[i],
            stiffness: s.stiffness[i],
            parent: s.parent[i],
            level: s.level[i] as u32,
            stem: s.stem[i],
            child_offset: c.offset[i],
            child_count: c.count[i],
            leaf_offset: c.leaf_offset[i],
            leaf_count: c.leaf_count[i],
            _pad: 0,
        }
    }
}

/// One stem with its Bézier, 96 bytes. WGSL: `struct Stem` in `tree.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawStem {
    /// Control points P0..P3 (xyz; w = 1).
    pub bezier: [[f32; 4]; 4],
    /// Parent stem (`u32::MAX` for none).
    pub parent: u32,
    /// Branching level.
    pub level: u32,
    /// First segment.
    pub first_segment: u32,
    /// Number of segments.
    pub segment_count: u32,
    /// Attachment parameter along the parent (arc-length fraction).
    pub attach: f32,
    /// Arc length, m.
    pub length: f32,
    /// Padding.
    pub _pad: [u32; 2],
}

impl RawStem {
    pub(crate) fn from_tree(t: &Tree, i: usize) -> Self {
        let st = &t.stems;
        let b = st.bezier[i];
        Self {
            bezier: [
                b[0].extend(1.0).to_array(),
                b[1].extend(1.0).to_array(),
                b[2].extend(1.0).to_array(),
                b[3].extend(1.0).to_array(),
            ],
            parent: st.parent[i],
            level: st.level[i] as u32,
            first_segment: st.first_segment[i],
            segment_count: st.segment_count[i],
            attach: st.attach[i],
            length: st.length[i],
            _pad: [0; 2],
        }
    }
}

/// One leaf, 48 bytes. WGSL: `struct Leaf` in `tree.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawLeaf {
    /// Attachment point, m.
    pub position: [f32; 3],
    /// Blade width, m.
    pub width: f32,
    /// Orientation (x, y, z, w).
    pub orientation: [f32; 4],
    /// Blade length, m.
    pub length: f32,
    /// Segment it hangs on.
    pub segment: u32,
    /// Outline, a [`crate::model::LeafShape`] index.
    pub shape: u32,
    /// Its index in the tree's leaves: where its rotation is in
    /// [`crate::pose::SeamPose::leaf`].
    pub index: u32,
}

impl RawLeaf {
    pub(crate) fn from_tree(t: &Tree, i: usize) -> Self {
        let l = &t.leaves;
        Self {
            position: l.position[i].to_array(),
            width: l.width[i],
            orientation: l.orientation[i].to_array(),
            length: l.length[i],
            segment: l.segment[i],
            shape: t.leaf_shape.index(),
            index: i as u32,
        }
    }
}
