// The tree model's packed structs: twins of sylva_core::model::{RawSegment, RawStem, RawLeaf}.
// A test checks that sizes and member offsets match the Rust structs.

const NONE: u32 = 0xffffffffu;

struct Segment {
    start: vec3<f32>,
    length: f32,
    orientation: vec4<f32>,
    local_orientation: vec4<f32>,
    radius_base: f32,
    radius_tip: f32,
    mass: f32,
    stiffness: f32,
    parent: u32,
    level: u32,
    stem: u32,
    child_offset: u32,
    child_count: u32,
    leaf_offset: u32,
    leaf_count: u32,
    _pad: u32,
}

struct Stem {
    bezier: array<vec4<f32>, 4>,
    parent: u32,
    level: u32,
    first_segment: u32,
    segment_count: u32,
    attach: f32,
    length: f32,
    _pad: vec2<u32>,
}

struct Leaf {
    position: vec3<f32>,
    width: f32,
    orientation: vec4<f32>,
    length: f32,
    segment: u32,
    shape: u32,
    index: u32,
}
