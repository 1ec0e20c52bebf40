//! CPU twin of `noise.wgsl`: integer hashing and smooth 1-D value noise, with
//! exactly the same integer operations as the WGSL so both sides hash identically.

/// PCG-style 32-bit hash (O'Neill's PCG output permutation on an LCG step).
#[inline]
pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// Uniform in [0, 1) from a hash (24 bits of mantissa, exact in f32).
#[inline]
pub fn hash_unit(v: u32) -> f32 {
    (pcg_hash(v) >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Smooth 1-D value noise in [−1, 1]: random values at integers (stream `seed`), blended
/// with the quintic fade 6t⁵ − 15t⁴ + 10t³ (C² continuous).
#[inline]
pub fn value_noise(x: f32, seed: u32) -> f32 {
    let i = x.floor();
    let f = x - i;
    let i0 = i as i32 as u32;
    let a = hash_unit(i0 ^ pcg_hash(seed)) * 2.0 - 1.0;
    let b = hash_unit(i0.wrapping_add(1) ^ pcg_hash(seed)) * 2.0 - 1.0;
    let u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    a + (b - a) * u
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_is_continuous_bounded_and_hits_lattice_values() {
        let mut prev = value_noise(-10.0, 3);
        for k in 1..20_000 {
            let x = -10.0 + k as f32 * 1e-3;
            let v = value_noise(x, 3);
            assert!((-1.0..=1.0).contains(&v));
            assert!((v - prev).abs() < 0.01, "jump at {x}");
            prev = v;
        }
        assert_eq!(value_noise(5.0, 3), hash_unit(5 ^ pcg_hash(3)) * 2.0 - 1.0);
        assert_ne!(value_noise(0.5, 1), value_noise(0.5, 2));
    }

    #[test]
    fn hash_is_well_spread() {
        let mean: f64 = (0..100_000u32).map(|i| hash_unit(i) as f64).sum::<f64>() / 1e5;
        assert!((mean - 0.5).abs() < 0.01);
    }
}
