//! CPU twin of `shader/trunk_noise.wgsl`: Zioma's trunk motion as superposed noise bands.

use super::noise::value_noise;
use crate::wind::trunk::RawBand;
use rayon::prelude::*;

/// (parallel, perpendicular, twist) angles in radians at time `t` for a tree with phase
/// seed `tree_seed`: each band adds `bias + amplitude · noise(frequency · t, seed ^ tree)`
/// to its axis.
pub fn trunk_angles(bands: &[RawBand], t: f32, tree_seed: u32) -> [f32; 3] {
    let mut out = [0.0f32; 3];
    for b in bands {
        let n = value_noise(b.frequency * t, b.seed ^ tree_seed);
        out[(b.axis as usize).min(2)] += b.bias + b.amplitude * n;
    }
    out
}

/// The kernel's CPU twin. Bindings as in `trunk_noise.wgsl`: 0 = bands, 1 = samples
/// (t, tree seed as bits, –, –), 2 = angles (parallel, perpendicular, twist, 0).
pub fn trunk_noise(bands: &[RawBand], samples: &[[f32; 4]], out: &mut [[f32; 4]]) {
    out.par_iter_mut().zip(samples.par_iter()).for_each(|(o, s)| {
        let a = trunk_angles(bands, s[0], s[1].to_bits());
        *o = [a[0], a[1], a[2], 0.0];
    });
}
