//! Sixteen `f32` lanes for the CPU's lane paths, and running a kernel with the CPU's wider
//! vector unit when it has one.
//!
//! [`F32x16`] is a plain `[f32; 16]` whose operations are lane-by-lane loops: the compiler
//! turns each into four 128-bit instructions on a baseline x86-64 build, and into two 256-bit
//! instructions inside a `dispatch!`ed kernel on a CPU with AVX2. Sixteen lanes rather than
//! eight because the lane kernels are long chains of dependent operations (square roots,
//! divisions, polynomials): two independent halves per operation keep the pipelines busy.
//! Every operation is an IEEE single-precision add, subtract, multiply, divide, square root,
//! compare or bit select — never a fused multiply-add — so a result is the same bit for bit
//! on either path, on any machine (tested).
//!
//! `dispatch!` is runtime dispatch, as SIMD libraries do it: the binary stays a baseline
//! x86-64 build that runs everywhere, and the hot loops use AVX2 where the CPU reports it.

use std::ops::{Add, AddAssign, BitAnd, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// Lanes per vector.
pub const LANES: usize = 16;

/// Sixteen `f32` lanes. A mask (from a comparison) holds all-one bits in the lanes where it is
/// true and zero bits elsewhere.
#[derive(Clone, Copy, PartialEq, Default)]
#[repr(C, align(32))]
pub struct F32x16(pub [f32; LANES]);

impl std::fmt::Debug for F32x16 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl F32x16 {
    /// Every lane zero.
    pub const ZERO: Self = Self([0.0; LANES]);
    /// Every lane one.
    pub const ONE: Self = Self([1.0; LANES]);

    /// Every lane `x`.
    #[inline(always)]
    pub const fn splat(x: f32) -> Self {
        Self([x; LANES])
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f32) -> f32) -> Self {
        let mut r = [0.0; LANES];
        for (r, a) in r.iter_mut().zip(self.0) {
            *r = f(a);
        }
        Self(r)
    }
    #[inline(always)]
    fn zip(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        let mut r = [0.0; LANES];
        for ((r, a), b) in r.iter_mut().zip(self.0).zip(o.0) {
            *r = f(a, b);
        }
        Self(r)
    }
    #[inline(always)]
    fn mask(self, o: Self, f: impl Fn(f32, f32) -> bool) -> Self {
        self.zip(o, |a, b| f32::from_bits(if f(a, b) { u32::MAX } else { 0 }))
    }
    /// The lanes as an array.
    #[inline(always)]
    pub fn as_array_ref(&self) -> &[f32; LANES] {
        &self.0
    }
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f32; LANES] {
        self.0
    }
    /// Square root per lane.
    #[inline(always)]
    pub fn sqrt(self) -> Self {
        self.map(f32::sqrt)
    }
    /// Absolute value per lane.
    #[inline(always)]
    pub fn abs(self) -> Self {
        self.map(f32::abs)
    }
    /// Nearest integer per lane, ties to even: `f32::round_ties_even` bit for bit, by adding
    /// and subtracting 2²³ (baseline x86-64 has no rounding instruction, and a library call
    /// per lane would cost more than the rest of a sine).
    #[inline(always)]
    pub fn round(self) -> Self {
        const BIG: f32 = 8_388_608.0;
        self.map(|a| {
            let m = a.abs();
            // Already an integer (or NaN) at 2²³ and above.
            let r = if m < BIG { (m + BIG) - BIG } else { m };
            f32::from_bits(r.to_bits() | (a.to_bits() & 0x8000_0000))
        })
    }
    /// `self^e` per lane (`f32::powf`).
    pub fn powf(self, e: f32) -> Self {
        self.map(|a| a.powf(e))
    }
    /// The smaller of two lanes; `o` where either is NaN (the `minps` rule).
    #[inline(always)]
    pub fn min(self, o: Self) -> Self {
        self.zip(o, |a, b| if a < b { a } else { b })
    }
    /// The larger of two lanes; `o` where either is NaN (the `maxps` rule).
    #[inline(always)]
    pub fn max(self, o: Self) -> Self {
        self.zip(o, |a, b| if a > b { a } else { b })
    }
    /// Mask of `self > o`.
    #[inline(always)]
    pub fn cmp_gt(self, o: Self) -> Self {
        self.mask(o, |a, b| a > b)
    }
    /// Mask of `self == o`.
    #[inline(always)]
    pub fn cmp_eq(self, o: Self) -> Self {
        self.mask(o, |a, b| a == b)
    }
    /// Mask of the finite lanes.
    #[inline(always)]
    pub fn is_finite(self) -> Self {
        self.mask(self, |a, _| a.is_finite())
    }
    /// Per lane, `t` where this mask is set, else `f`.
    #[inline(always)]
    pub fn blend(self, t: Self, f: Self) -> Self {
        let mut r = [0.0; LANES];
        for (((r, m), t), f) in r.iter_mut().zip(self.0).zip(t.0).zip(f.0) {
            let m = m.to_bits();
            *r = f32::from_bits((m & t.to_bits()) | (!m & f.to_bits()));
        }
        Self(r)
    }
    /// Whether every lane of this mask is set.
    #[inline(always)]
    pub fn all(self) -> bool {
        self.0.iter().fold(u32::MAX, |acc, m| acc & m.to_bits()) >> 31 == 1
    }
}

impl From<[f32; LANES]> for F32x16 {
    #[inline(always)]
    fn from(a: [f32; LANES]) -> Self {
        Self(a)
    }
}

macro_rules! lane_op {
    ($tr:ident, $f:ident, $tra:ident, $fa:ident, $op:tt) => {
        impl $tr for F32x16 {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                self.zip(o, |a, b| a $op b)
            }
        }
        impl $tra for F32x16 {
            #[inline(always)]
            fn $fa(&mut self, o: Self) {
                *self = *self $op o;
            }
        }
    };
}
lane_op!(Add, add, AddAssign, add_assign, +);
lane_op!(Sub, sub, SubAssign, sub_assign, -);
lane_op!(Mul, mul, MulAssign, mul_assign, *);

impl Mul<f32> for F32x16 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: f32) -> Self {
        self * Self::splat(o)
    }
}

impl Div for F32x16 {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        self.zip(o, |a, b| a / b)
    }
}

impl Neg for F32x16 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.map(|a| -a)
    }
}

impl BitAnd for F32x16 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, o: Self) -> Self {
        self.zip(o, |a, b| f32::from_bits(a.to_bits() & b.to_bits()))
    }
}

/// Instruction sets the dispatched kernels are compiled for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// The build's own target (SSE2 on a default x86-64 build).
    Baseline,
    /// AVX2 (sixteen lanes in two 256-bit registers: two independent halves keep the
    /// pipelines fuller than one AVX-512 register did on the benchmark machine).
    Avx2,
}

/// The level the dispatched kernels run at: the best the CPU reports, capped by
/// `SYLVA_SIMD=baseline` (to time or test the baseline).
pub fn level() -> Level {
    static LEVEL: std::sync::OnceLock<Level> = std::sync::OnceLock::new();
    *LEVEL.get_or_init(|| {
        let cap = match std::env::var("SYLVA_SIMD").as_deref() {
            Ok("baseline") => Level::Baseline,
            _ => Level::Avx2,
        };
        detected().min(cap)
    })
}

/// The best level the CPU reports.
pub fn detected() -> Level {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        return Level::Avx2;
    }
    Level::Baseline
}

/// Defines `$at(level, args)`, which runs the body compiled for `level`: pass [`level`] for
/// the CPU's best, a lower one to test that every level gives the same bits (a level above
/// [`detected`] runs at [`detected`], so no call can reach an instruction the CPU lacks). The body is
/// compiled once per level; everything it calls in its loop must be `#[inline(always)]` so
/// that it is compiled inside each copy.
macro_rules! dispatch {
    ($(#[$m:meta])* $vis:vis fn $at:ident($($a:ident: $t:ty),* $(,)?) $body:block) => {
        $(#[$m])*
        $vis fn $at(level: $crate::simd::Level, $($a: $t),*) {
            #[inline(always)]
            fn kernel($($a: $t),*) $body
            let level = level.min($crate::simd::detected());
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2")]
                fn avx2($($a: $t),*) {
                    kernel($($a),*)
                }
                match level {
                    // SAFETY: the CPU has AVX2 (`level` is capped by `detected` above).
                    #[allow(unsafe_code)]
                    $crate::simd::Level::Avx2 => return unsafe { avx2($($a),*) },
                    $crate::simd::Level::Baseline => {}
                }
            }
            kernel($($a),*)
        }
    };
}
pub(crate) use dispatch;

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    dispatch! {
        /// Every lane operation applied to `a` and `b`, one output row per operation.
        fn ops_at(a: &[F32x16], b: &[F32x16], out: &mut [[F32x16; 12]]) {
            for ((a, b), o) in a.iter().zip(b).zip(out) {
                let (a, b) = (*a, *b);
                let m = a.cmp_gt(b);
                *o = [
                    a + b,
                    a - b,
                    a * b,
                    a / b,
                    a.abs().sqrt(),
                    a.abs(),
                    a.round(),
                    a.min(b),
                    a.max(b),
                    m,
                    m.blend(a, b),
                    -a,
                ];
            }
        }
    }

    /// Scalar f32 operations, the same rules as the lanes claim.
    fn scalar(a: f32, b: f32) -> [f32; 12] {
        let m = f32::from_bits(if a > b { u32::MAX } else { 0 });
        [
            a + b,
            a - b,
            a * b,
            a / b,
            a.abs().sqrt(),
            a.abs(),
            a.round_ties_even(),
            if a < b { a } else { b },
            if a > b { a } else { b },
            m,
            if a > b { a } else { b },
            -a,
        ]
    }

    fn random_lanes(rng: &mut impl Rng) -> F32x16 {
        let special = [0.0, -0.0, 0.5, -0.5, 1.5, 2.5, -2.5, 8_388_607.5, 8_388_608.0, -1e30, f32::INFINITY, f32::NAN];
        F32x16(std::array::from_fn(|_| match rng.random_range(0..4) {
            0 => special[rng.random_range(0..special.len())],
            1 => f32::from_bits(rng.random()),
            _ => rng.random_range(-1e4..1e4f32),
        }))
    }

    /// Every operation, at every level the CPU has, equals the scalar operation bit for bit
    /// on random lanes (specials included: ±0, halves, 2²³, infinities, NaN).
    #[test]
    fn every_level_matches_scalar_f32_bit_for_bit() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let a: Vec<F32x16> = (0..4000).map(|_| random_lanes(&mut rng)).collect();
        let b: Vec<F32x16> = (0..4000).map(|_| random_lanes(&mut rng)).collect();
        let levels: Vec<Level> = [Level::Baseline, Level::Avx2].into_iter().filter(|&l| l <= detected()).collect();
        if levels.len() == 1 {
            println!("this CPU has no AVX2: only the baseline level is checked");
        }
        for level in levels {
            let mut out = vec![[F32x16::ZERO; 12]; a.len()];
            ops_at(level, &a, &b, &mut out);
            for ((a, b), o) in a.iter().zip(&b).zip(&out) {
                for l in 0..LANES {
                    let want = scalar(a.0[l], b.0[l]);
                    for (k, w) in want.iter().enumerate() {
                        let got = o[k].0[l];
                        let same = got.to_bits() == w.to_bits() || (got.is_nan() && w.is_nan() && k != 9);
                        assert!(same, "{level:?} op {k} on ({}, {}): {got} vs {w}", a.0[l], b.0[l]);
                    }
                }
            }
        }
    }

    #[test]
    fn masks_reduce_as_stated() {
        let t = F32x16::splat(2.0).cmp_gt(F32x16::ONE);
        assert!(t.all());
        let mut partly = t;
        partly.0[7] = 0.0;
        assert!(!partly.all());
        assert!(!F32x16::ONE.cmp_gt(F32x16::ONE).all());
        let finite =
            F32x16([1.0, f32::INFINITY, f32::NAN, -0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]);
        let f = finite.is_finite();
        assert_eq!(f.0.map(|m| m.to_bits() == u32::MAX), std::array::from_fn(|l| !(l == 1 || l == 2)));
        assert_eq!((t & f).0.map(|m| m.to_bits()), f.0.map(|m| m.to_bits()));
    }
}
