// Integer hashing and 1-D value noise shared by kernels. Twin: sylva_core::wind::noise
// (same integer operations, so both sides hash identically).

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
