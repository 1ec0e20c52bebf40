//! The wind scene at sixteen points at once, for the CPU's lane paths (Skjermo's stems, the
//! centres of HSM's clusters): [`crate::simd::F32x16`] lanes, a polynomial sine, and every field
//! kind of `wind::sample::field_at` — constant, sum of sines and turbulence on the
//! lanes, the localised events (gust front, vortex, blast) per lane through `field_at`.
//! Agrees with `wind_at` to the sine's error (tested).

use crate::wind::raw::{RawField, RawWave, kind};
use crate::wind::sample::{field_at, wave_envelope};
use glam::Vec3;
use std::f32::consts::TAU;
use std::ops::{Add, Sub};

pub use crate::simd::LANES;

/// Sixteen `f32` lanes.
pub type V = crate::simd::F32x16;

/// Three lanes of sixteen: x, y and z of sixteen vectors (in that order in memory).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C)]
pub struct V3 {
    /// x of each lane.
    pub x: V,
    /// y of each lane.
    pub y: V,
    /// z of each lane.
    pub z: V,
}

impl V3 {
    pub const ZERO: Self = Self { x: V::ZERO, y: V::ZERO, z: V::ZERO };
    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        Self { x: V::splat(v.x), y: V::splat(v.y), z: V::splat(v.z) }
    }
    #[inline(always)]
    pub fn scale(self, s: V) -> Self {
        Self { x: self.x * s, y: self.y * s, z: self.z * s }
    }
    #[inline(always)]
    pub fn dot(self, o: Self) -> V {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        Self { x: self.y * o.z - o.y * self.z, y: self.z * o.x - o.z * self.x, z: self.x * o.y - o.x * self.y }
    }
    #[inline(always)]
    pub fn length(self) -> V {
        self.dot(self).sqrt()
    }
    #[inline(always)]
    pub fn select(mask: V, a: Self, b: Self) -> Self {
        Self { x: mask.blend(a.x, b.x), y: mask.blend(a.y, b.y), z: mask.blend(a.z, b.z) }
    }
    /// `axis_or`: normalised where longer than 1e-6, else `fallback`.
    #[inline(always)]
    pub fn axis_or(self, fallback: Self) -> Self {
        let l = self.length();
        let ok = l.cmp_gt(V::splat(1e-6));
        let safe = ok.blend(l, V::ONE);
        // One reciprocal, as `methods::skjermo::unit_or`: the same rounding as the reference,
        // so the rest frames it builds are reproduced bit for bit.
        Self::select(ok, self.scale(V::ONE / safe), fallback)
    }
    /// glam's `normalize_or_zero() * len` with one division, `self · (len / |self|)`: zero
    /// where `|self|` is zero or not finite, or the ratio is not (a vector so short that
    /// `len / |self|` overflows), so a finite `len` always gives a finite vector.
    #[inline(always)]
    pub fn with_length(self, len: V) -> Self {
        let l = self.length();
        let positive = l.cmp_gt(V::ZERO);
        let ratio = len / positive.blend(l, V::ONE);
        let ok = positive & l.is_finite() & ratio.is_finite();
        Self::select(ok, self.scale(ratio), Self::ZERO)
    }
    /// glam's `any_orthogonal_vector`.
    #[inline(always)]
    pub fn any_orthogonal(self) -> Self {
        let m = self.x.abs().cmp_gt(self.y.abs());
        Self { x: m.blend(-self.z, V::ZERO), y: m.blend(V::ZERO, self.z), z: m.blend(self.x, -self.y) }
    }
    pub fn lane(&self, l: usize) -> Vec3 {
        Vec3::new(self.x.as_array_ref()[l], self.y.as_array_ref()[l], self.z.as_array_ref()[l])
    }
    pub fn from_lanes(v: [Vec3; LANES]) -> Self {
        Self { x: V::from(v.map(|a| a.x)), y: V::from(v.map(|a| a.y)), z: V::from(v.map(|a| a.z)) }
    }
}

impl Add for V3 {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self { x: self.x + o.x, y: self.y + o.y, z: self.z + o.z }
    }
}

impl Sub for V3 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self { x: self.x - o.x, y: self.y - o.y, z: self.z - o.z }
    }
}

/// Sine on sixteen lanes: reduced to [−π, π] by whole turns, then an odd degree-11 polynomial
/// fitted to sine by least squares on Chebyshev nodes (absolute error < 2e-6 on [−π, π]; the reference's `sin`
/// is correctly rounded, so the two paths differ by that much at most).
#[inline(always)]
pub fn sin(x: V) -> V {
    let turns = (x * V::splat(std::f32::consts::FRAC_1_PI * 0.5)).round();
    // Two-part 2π so the reduction stays exact for the arguments the wind produces.
    let r = x - turns * V::splat(6.28125) - turns * V::splat(0.001_935_307_2);
    let r2 = r * r;
    let p = V::splat(-2.053_034_2e-8) * r2 + V::splat(2.704_617_4e-6);
    let p = p * r2 + V::splat(-1.981_395_8e-4);
    let p = p * r2 + V::splat(8.332_666e-3);
    let p = p * r2 + V::splat(-1.666_661e-1);
    r + r * r2 * p
}

/// `x^k` for a small integer `k ≥ 0` by repeated squaring (the squares `k` of 2 and 3, the
/// sharpness of most scenes, written out: the same products, without the loop).
#[inline(always)]
pub fn powi(mut x: V, mut k: u32) -> V {
    match k {
        2 => return x * x,
        3 => return x * (x * x),
        _ => {}
    }
    let mut r = V::ONE;
    while k > 0 {
        if k & 1 == 1 {
            r *= x;
        }
        x *= x;
        k >>= 1;
    }
    r
}

/// `x^e` on sixteen lanes for finite `x ≥ 1`, as `2^(e log₂ x)` with polynomials (the
/// logarithm by `atanh` of the mantissa taken in [√½, √2), the power of two by a degree-6 fit
/// on [−½, ½] and the exponent's bits): relative error under `3e-7 + 1e-7 · |e log₂ x|` (a few
/// units in the last place, and the rounding of the exponent `e log₂ x` to `f32`, which grows
/// with it) while `|e log₂ x| < 126`, where `f32::powf` costs a library call per lane.
#[inline(always)]
pub fn pow_ge1(x: V, e: f32) -> V {
    // log₂ m = (2 / ln 2) atanh(t), t = (m − 1)/(m + 1), |t| < 0.172 for m in [√½, √2): four
    // terms of the series (truncated at 4e-8).
    const LOG2: [f32; 4] = [
        2.0 * std::f32::consts::LOG2_E,
        2.0 * std::f32::consts::LOG2_E / 3.0,
        2.0 * std::f32::consts::LOG2_E / 5.0,
        2.0 * std::f32::consts::LOG2_E / 7.0,
    ];
    // 2^f on [−½, ½]: a Chebyshev fit of degree 6 (relative error 1.1e-7 in f32).
    const EXP2: [f32; 7] =
        [1.0, std::f32::consts::LN_2, 0.240_226_5, 0.055_503_27, 0.009_618_025, 0.001_340_043_3, 0.000_154_697_32];
    let mut r = [0.0f32; LANES];
    for (r, &a) in r.iter_mut().zip(x.as_array_ref()) {
        let bits = a.to_bits();
        // a = 2^k m: mantissas above √2's take the exponent of ½, so m lies in [√½, √2).
        let high = (bits & 0x007f_ffff) > 0x0035_04f3;
        let k = ((bits >> 23) as i32 - 127 + high as i32) as f32;
        let m = f32::from_bits((bits & 0x007f_ffff) | if high { 0x3f00_0000 } else { 0x3f80_0000 });
        let t = (m - 1.0) / (m + 1.0);
        let t2 = t * t;
        let l = t * (((t2 * LOG2[3] + LOG2[2]) * t2 + LOG2[1]) * t2 + LOG2[0]);
        let y = (e * (k + l)).clamp(-126.0, 126.0);
        let n = (y + 0.5).floor();
        let f = y - n;
        let q = (((((f * EXP2[6] + EXP2[5]) * f + EXP2[4]) * f + EXP2[3]) * f + EXP2[2]) * f + EXP2[1]) * f + EXP2[0];
        *r = q * exp2_whole(n);
    }
    V::from(r)
}

/// `2ⁿ` for a whole `n` in −126..=126, from its exponent bits: `n + 127` added to `2²³` sits
/// in the mantissa's low bits, which the shift moves into the exponent (the bits of `2²³`
/// shift out). The bits of `(n as i32 + 127) << 23`, whose saturating `as` stays scalar code
/// on every lane.
#[inline(always)]
fn exp2_whole(n: f32) -> f32 {
    f32::from_bits((n + (127.0 + 8_388_608.0)).to_bits() << 23)
}

/// The wind scene at sixteen points (as `wind::sample::wind_at`).
#[inline(always)]
pub fn wind_lanes(fields: &[RawField], waves: &[RawWave], p: V3, t: f32) -> V3 {
    let mut v = V3::ZERO;
    for f in fields {
        match f.kind {
            kind::CONSTANT => v = v.add(V3::splat(Vec3::new(f.a[0], f.a[1], f.a[2]))),
            kind::SUM_OF_SINES => {
                let (sharp, mode) = (f.a[0], f.a[1]);
                let int_sharp = (sharp.fract() == 0.0 && (0.0..=16.0).contains(&sharp)).then_some(sharp as u32);
                let e = V::splat(wave_envelope(f.b, t));
                for w in &waves[f.wave_offset as usize..(f.wave_offset + f.wave_count) as usize] {
                    let th = p.x * w.k[0] + p.y * w.k[1] + p.z * w.k[2] + V::splat(w.k[3] * t);
                    let s = sin(th);
                    let h = if mode < 0.5 {
                        s
                    } else {
                        let base = (s + V::ONE) * V::splat(0.5);
                        match int_sharp {
                            Some(k) => powi(base, k),
                            None => base.powf(sharp),
                        }
                    };
                    v = v.add(V3::splat(Vec3::new(w.dir[0], w.dir[1], w.dir[2])).scale(h * e));
                }
            }
            kind::TURBULENCE => {
                let e = V::splat(wave_envelope(f.b, t));
                for w in &waves[f.wave_offset as usize..(f.wave_offset + f.wave_count) as usize] {
                    // The wave's phase in cycles depends on time only: once for all lanes.
                    let cyc = w.k[3] * t + w.phase[0];
                    let cyc = cyc - cyc.floor();
                    let th = V::splat(TAU * cyc) - (p.x * w.k[0] + p.y * w.k[1] + p.z * w.k[2]);
                    v = v.add(V3::splat(Vec3::new(w.dir[0], w.dir[1], w.dir[2])).scale(sin(th) * e));
                }
            }
            _ => {
                let per: [Vec3; LANES] = std::array::from_fn(|l| field_at(f, waves, p.lane(l), t));
                v = v.add(V3::from_lanes(per));
            }
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wind::WindScene;
    use crate::wind::sample::wind_at;

    #[test]
    fn lane_sine_is_within_its_stated_error() {
        let mut worst = 0.0f32;
        for i in -200_000..=200_000 {
            let x = i as f32 * 0.05;
            let got = sin(V::splat(x)).as_array_ref()[0];
            worst = worst.max((got - x.sin()).abs());
        }
        // 2e-6 from the polynomial on [−π, π]; the reduction adds the rounding of x itself.
        assert!(worst < 4e-6, "worst error {worst}");
    }

    /// Regression: `with_length` of a vector so short that `len / |v|` overflows gave
    /// infinities and NaN (0 · ∞); it gives zero there, as glam's `normalize_or_zero`.
    #[test]
    fn with_length_stays_finite_for_tiny_zero_and_infinite_vectors() {
        let tiny = f32::from_bits(1); // the smallest subnormal
        let cases = [
            (Vec3::new(3.0, 4.0, 0.0), 10.0, Some(Vec3::new(6.0, 8.0, 0.0))),
            (Vec3::new(tiny, 0.0, 0.0), 5.0, None),
            (Vec3::new(1e-20, 0.0, -1e-20), 1e30, None),
            (Vec3::ZERO, 2.0, Some(Vec3::ZERO)),
            (Vec3::new(f32::INFINITY, 0.0, 0.0), 1.0, Some(Vec3::ZERO)),
            (Vec3::new(f32::NAN, 1.0, 0.0), 1.0, Some(Vec3::ZERO)),
            (Vec3::new(1.0, 0.0, 0.0), f32::NAN, Some(Vec3::ZERO)),
        ];
        for (v, len, want) in cases {
            let got = V3::splat(v).with_length(V::splat(len)).lane(0);
            assert!(got.is_finite(), "{v} · {len}: {got}");
            if let Some(w) = want {
                assert!((got - w).length() <= 1e-6 * (1.0 + w.length()), "{v} · {len}: {got} vs {w}");
            } else {
                assert!(got.length() <= len * (1.0 + 1e-6), "{v} · {len}: {got}");
            }
        }
    }

    #[test]
    fn exp2_whole_is_the_power_of_two() {
        for n in -126..=126 {
            assert_eq!(exp2_whole(n as f32), 2f32.powi(n), "2^{n}");
            assert_eq!(exp2_whole(n as f32).to_bits(), ((n + 127) as u32) << 23, "2^{n}");
        }
    }

    #[test]
    fn pow_ge1_matches_powf() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for _ in 0..2000 {
            let x: [f32; LANES] = std::array::from_fn(|_| 1.0 + rng.random::<f32>().powi(3) * 1e4);
            let e = -2.0 * rng.random::<f32>();
            let got = pow_ge1(V::from(x), e);
            for (l, &a) in x.iter().enumerate() {
                let want = a.powf(e);
                let g = got.as_array_ref()[l];
                let tol = 3e-7 + 1e-7 * (e * a.log2()).abs();
                assert!((g / want - 1.0).abs() < tol, "{a}^{e}: {g} vs {want}");
            }
        }
    }

    #[test]
    fn integer_powers_match_powf() {
        for k in 0..=16u32 {
            let x = 0.93f32;
            let got = powi(V::splat(x), k).as_array_ref()[0];
            assert!((got - x.powf(k as f32)).abs() <= 1e-6, "{k}: {got}");
        }
    }

    /// Every preset's scene at random points and times, sixteen at a time: within the
    /// polynomial sine's error (scaled by the summed wave amplitudes) of `wind_at`.
    #[test]
    fn lanes_match_wind_at_on_every_preset() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for (name, _, _) in crate::wind::PRESETS {
            let (fields, waves) = WindScene::resolve(name).unwrap().pack();
            let amplitude: f32 = waves.iter().map(|w| Vec3::new(w.dir[0], w.dir[1], w.dir[2]).length()).sum();
            for _ in 0..200 {
                let t = rng.random_range(0.0..30.0);
                let pts: [Vec3; LANES] = std::array::from_fn(|_| {
                    Vec3::new(rng.random_range(-40.0..40.0), rng.random_range(0.0..30.0), rng.random_range(-40.0..40.0))
                });
                let got = wind_lanes(&fields, &waves, V3::from_lanes(pts), t);
                for (l, p) in pts.iter().enumerate() {
                    let want = wind_at(&fields, &waves, *p, t);
                    let err = (got.lane(l) - want).length();
                    assert!(
                        err <= 1e-5 * (1.0 + amplitude + want.length()),
                        "{name}: {p} t {t}: {} vs {want}",
                        got.lane(l)
                    );
                }
            }
        }
    }
}
