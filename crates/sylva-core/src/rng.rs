//! Deterministic random streams.
//!
//! Every random decision is drawn from a stream keyed by the seed and by *what* is being
//! decided (a stem's path in the tree, a module's index in an L-system string), never by
//! the order in which threads happen to run. That makes trees bit-identical whatever the
//! thread count.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// SplitMix64 finaliser: a bijective 64-bit mix with good avalanche.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Key of a child derived from its parent's key and its index among siblings.
#[inline]
pub fn child_key(parent: u64, index: u64) -> u64 {
    mix64(parent ^ mix64(index.wrapping_add(0x5851_F42D_4C95_7F2D)))
}

/// A seeded random stream (ChaCha8), with the few draws the generators need.
#[derive(Debug, Clone)]
pub struct Stream(ChaCha8Rng);

impl Stream {
    /// A stream for the decision identified by `key`.
    pub fn new(key: u64) -> Self {
        Self(ChaCha8Rng::seed_from_u64(key))
    }

    /// Uniform in [0, 1).
    #[inline]
    pub fn unit(&mut self) -> f64 {
        self.0.random::<f64>()
    }

    /// Weber–Penn's variation: uniform in [-v, v] (0 when `v` is 0, without consuming a draw
    /// differently: a draw is always taken so streams stay aligned).
    #[inline]
    pub fn var(&mut self, v: f64) -> f64 {
        let u = self.unit();
        (2.0 * u - 1.0) * v
    }
}

/// Uniform in [0, 1) from a stateless hash of `key` (counter-based, for parallel loops).
#[inline]
pub fn hash_unit(key: u64) -> f64 {
    (mix64(key) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}
