// Zioma's per-frame records, shared by the frame kernel that writes them and the rotation
// kernel that reads them. Twins: sylva_core::methods::zioma::{RawZiomaFrame, RawZiomaTrunk,
// RawZiomaRing, RawZiomaInstance}.

// One instance's values for a frame (directions in the tree's frame).
struct ZiomaFrame {
    wind_dir: vec3<f32>,
    time: f32,
    trunk: vec3<f32>,
    trunk_rate: f32,
    lod: u32,
    amplitude: f32,
    max_bend: f32,
    inertia: f32,
    origin: vec3<f32>,
    phase: f32,
    heading: vec2<f32>,
    _pad: vec2<f32>,
}

// One tree's values for a frame: its trunk model, the time and the method's parameters.
struct ZiomaTrunk {
    crown_centre: vec3<f32>,
    natural_frequency: f32,
    tip_per_pascal: f32,
    damping_centre: f32,
    lever: f32,
    damping_ratio: f32,
    reconfiguration_speed: f32,
    vogel_exponent: f32,
    time: f32,
    tree_seed: u32,
    lod: u32,
    amplitude: f32,
    max_bend: f32,
    inertia: f32,
}

// One instance's ring: the trunk's free ring-down since the wind last changed, taken at the
// instance's crown.
struct ZiomaRing {
    bend: vec3<f32>,
    since: f32,
    rate: vec3<f32>,
    zeta: f32,
}

// A placed instance.
struct ZiomaInstance {
    position: vec3<f32>,
    yaw: f32,
    phase: f32,
    seed: u32,
    _pad: vec2<u32>,
}
