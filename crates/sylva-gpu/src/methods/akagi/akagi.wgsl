// Shared by Akagi's kernels: per-segment constants and per-step parameters.
// Twins: sylva_core::methods::akagi::RawAkagiSegment and RawAkagiStep.

struct AkagiSegment {
    bark_area: f32,
    leaf_area: f32,
    inertia: f32,
    stiffness: f32,
    damping: f32,
    air_scale: f32,
    _pad: array<u32, 2>,
}

struct AkagiStep {
    drag: f32,
    time: f32,
    dt: f32,
    reconfiguration_speed: f32,
    stiffening_angle: f32,
    vogel_exponent: f32,
    _pad: array<f32, 2>,
}

const AIR_DENSITY: f32 = 1.225;
