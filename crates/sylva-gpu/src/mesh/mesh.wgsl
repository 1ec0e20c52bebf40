// Per-frame meshing (Akagi §2.2–2.4): structs shared by mesh_tubes, mesh_detail and
// mesh_leaves, twins of sylva_core::mesh::{RawRing, RawMeshInfo, RawDetail}, and
// the bark relief.

const TAU: f32 = 6.283185307179586;

struct Ring {
    segment: u32,
    prev: u32,
    next: u32,
    t: f32,
    v: f32,
    relief: f32,
    stem_seed: u32,
    radius: f32,
}

struct MeshInfo {
    sides: u32,
    rings: u32,
    leaf_sides: u32,
    leaves: u32,
    details: u32,
    _pad: array<u32, 3>,
}

// A midpoint vertex of a subdivided band (sylva_core::mesh::RawDetail).
struct Detail {
    a: u32,
    b: u32,
    ring: u32,
    t: f32,
    scale: f32,
    stem_seed: u32,
    _pad: array<u32, 2>,
}

// Bark relief in -1..1 (CPU twin: sylva_core::mesh::bark_relief).
fn bark_relief(u: f32, v: f32, seed: u32) -> f32 {
    let wander = value_noise(v * 0.6, seed);
    let ridge = sin(TAU * (u * 7.0 + 0.8 * wander));
    return ridge * ridge * 2.0 - 1.0;
}
