// Integer hashing, 1-D value noise and the scalar helpers shared by kernels. Twin:
// sylva_core::wind::noise (same integer operations, so both sides hash identically).

fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn hash_unit(v: u32) -> f32 {
    return f32(pcg_hash(v) >> 8u) * (1.0 / 16777216.0);
}

// Smooth value noise in [-1, 1]: random values at integers, quintic fade.
fn value_noise(x: f32, seed: u32) -> f32 {
    let i = floor(x);
    let f = x - i;
    let i0 = u32(i32(i));
    let a = hash_unit(i0 ^ pcg_hash(seed)) * 2.0 - 1.0;
    let b = hash_unit((i0 + 1u) ^ pcg_hash(seed)) * 2.0 - 1.0;
    let u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    return a + (b - a) * u;
}

// sin of a wave's phase, reduced to [-pi, pi] by whole turns first (2pi in two parts, so
// the reduction is exact for the phases the wind produces). A GPU's own sin of a large
// argument reduces it in single precision (NVIDIA's: an error that grows with |x|, ~6e-5 at
// 1,500 rad, and the same at the next step, so a simulation drifts by it); reduced, it is
// within ~1e-6 of the CPU's correctly rounded sine. The CPU's sixteen-lane twin
// (sylva_core::wind::lanes::sin) reduces the same way.
fn sin_turns(x: f32) -> f32 {
    let turns = round(x * (0.5 / 3.141592653589793));
    return sin(x - turns * 6.28125 - turns * 0.0019353072);
}

fn smooth_step(e0: f32, e1: f32, x: f32) -> f32 {
    let t = clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}
