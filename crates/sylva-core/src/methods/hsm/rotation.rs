//! A cluster's rotation R from its Apq (Müller, Bender, Chentanez & Macklin 2016, with a
//! Newton step): [`extract_rotation`], the scalar reference and the twin of
//! `extract_rotation` in `hsm.wgsl`, and `extract_rotations_at`, sixteen clusters at a time
//! in SIMD lanes with the same bits, which stage 1 runs on the CPU.

use crate::simd::dispatch;
use crate::wind::lanes::{V, V3};
use glam::{Mat3, Quat, Vec3};

/// The rotation of `a` (Müller, Bender, Chentanez & Macklin 2016), warm-started from `q`,
/// with a Newton step. Each of the `iterations` turns `R ← rot(ω) R` by the solution of
/// `H ω = g`, where `g = Σ rᵢ × aᵢ` is the gradient of `tr(Rᵀ A)` and
/// `H = tr(B) I − sym(B)`, `B = A Rᵀ`, its Hessian (see [`rotation_step`]). Where `H` is not
/// safely positive definite (far from the optimum, inverted, collinear or zero clusters)
/// the step is Müller's `g / (|tr B| + ε)`, with ε 1e-6 of the columns' summed lengths (plus
/// 1e-30), so every finite `a` leaves a finite rotation, never NaN.
///
/// Müller's step alone divides every component of the gradient by `tr B ≈ σ₁ + σ₂ + σ₃`,
/// while the curvature about a cluster's long axis is only `σ₂ + σ₃`: an elongated cluster
/// (a leaf blade, a long thin segment) then needs hundreds of iterations to turn about its
/// axis, and two warm iterations per step left palm fronds up to 1.8 rad from their optimal
/// rotation. The Newton step converges in one or two.
///
/// `rot(ω)` is the unit quaternion along `(ω/2, 1)`: a turn by `2 atan(|ω|/2)` about `ω`,
/// which is `exp(ω)` to third order (the steps near the optimum are tiny) and shorter far
/// away, where the iteration only needs to head the right way. It needs no `sin` or `cos`:
/// Vulkan allows a GPU's `sin` an absolute error of 2⁻¹¹, which is most of a small turn,
/// and a GPU turning each cluster by a slightly different amount every step drifted from
/// the CPU by far more than rounding.
///
/// The result is a **continuous** function of `a` and `q`: every iteration runs (no early
/// stop at a threshold) and the two steps are blended, not switched (see
/// [`rotation_step`]). A threshold turns a rounding difference into a jump of the size of
/// the threshold, and in a simulation such jumps add up step after step: with them, two
/// runs started 1e-10 m/s apart ended 1e-5 × the tree's height apart after 1,000 steps,
/// however small the start's difference (and a GPU, rounding differently, 5e-3).
pub fn extract_rotation(a: Mat3, q: Quat, iterations: u32) -> Quat {
    let mut q = q;
    let eps = 1e-6 * (a.x_axis.length() + a.y_axis.length() + a.z_axis.length()) + 1e-30;
    for _ in 0..iterations {
        let r = Mat3::from_quat(q);
        let half = rotation_step(r, a, eps) * 0.5;
        q = (Quat::from_xyzw(half.x, half.y, half.z, 1.0) * q).normalize();
    }
    q
}

/// One step `ω` of [`extract_rotation`] from rotation `r` toward the rotation of `a`.
///
/// `tr(Rᵀ exp(ω̂)ᵀ A) = tr B + ω · g − ½ ωᵀ H ω + O(|ω|³)` with `B = A Rᵀ`,
/// `g = Σ rᵢ × aᵢ` and `H = tr(B) I − sym(B)`, so the maximum of the quadratic model is at
/// `ω = H⁻¹ g`. Near the optimum `B` is symmetric with the singular values σ of `A` as
/// eigenvalues and `H`'s are `σⱼ + σₖ`. The step is `μ + s (H⁻¹ g − μ)` with Müller's
/// `μ = g / (|tr B| + ε)` and a weight `s = s_near · s_pd ∈ [0, 1]`:
/// * `s_near` is 1 where `|μ|` is under [`NEWTON_NEAR`] and falls linearly in `|μ|²` to 0 at
///   twice that (far away the quadratic model can lead Newton to another stationary point;
///   Müller's step is robust there);
/// * `s_pd` needs `H` positive definite (Sylvester: `h₀₀ > 0`, the leading 2×2 minor `> 0`,
///   `det H > 0`) and is `det H / (10⁻⁴ (tr B)³) − 1` clamped to [0, 1], so it is 0 for
///   clusters thinner than about 1% of their length, whose turn about the long axis is not
///   determined, and 1 from 2% up. It is continuous: leaving the positive definite set
///   takes `det H` through 0, where `s_pd` is already 0.
///
/// So `ω` is a continuous function of `r` and `a` (see [`extract_rotation`] for why that
/// matters). WGSL: `rotation_step` in `hsm.wgsl`, the same operations in the same order.
#[inline(always)]
pub fn rotation_step(r: Mat3, a: Mat3, eps: f32) -> Vec3 {
    let g = r.x_axis.cross(a.x_axis) + r.y_axis.cross(a.y_axis) + r.z_axis.cross(a.z_axis);
    let tr = r.x_axis.dot(a.x_axis) + r.y_axis.dot(a.y_axis) + r.z_axis.dot(a.z_axis);
    let muller = g / (tr.abs() + eps);
    let near = NEWTON_NEAR * NEWTON_NEAR;
    let s_near = ((4.0 * near - muller.length_squared()) / (3.0 * near)).min(1.0);
    if !(tr > 0.0 && s_near > 0.0) {
        return muller;
    }
    // Columns of B = A Rᵀ: bₖ = Σᵢ aᵢ rᵢ[k].
    let b0 = a.x_axis * r.x_axis.x + a.y_axis * r.y_axis.x + a.z_axis * r.z_axis.x;
    let b1 = a.x_axis * r.x_axis.y + a.y_axis * r.y_axis.y + a.z_axis * r.z_axis.y;
    let b2 = a.x_axis * r.x_axis.z + a.y_axis * r.y_axis.z + a.z_axis * r.z_axis.z;
    let h00 = tr - b0.x;
    let h11 = tr - b1.y;
    let h22 = tr - b2.z;
    let h01 = -0.5 * (b1.x + b0.y);
    let h02 = -0.5 * (b2.x + b0.z);
    let h12 = -0.5 * (b2.y + b1.z);
    // The adjugate of the symmetric H and its determinant.
    let c00 = h11 * h22 - h12 * h12;
    let c01 = h02 * h12 - h01 * h22;
    let c02 = h01 * h12 - h02 * h11;
    let c11 = h00 * h22 - h02 * h02;
    let c12 = h01 * h02 - h00 * h12;
    let c22 = h00 * h11 - h01 * h01;
    let det = h00 * c00 + h01 * c01 + h02 * c02;
    let thin = 1e-4 * (tr * tr * tr);
    if !(h00 > 0.0 && c22 > 0.0 && det > thin) {
        return muller;
    }
    // (tr B)³ can underflow to zero for a vanishing cluster; det H > 0 then decides alone.
    let s_pd = if thin > 0.0 { (det / thin - 1.0).min(1.0) } else { 1.0 };
    let newton = Vec3::new(
        c00 * g.x + c01 * g.y + c02 * g.z,
        c01 * g.x + c11 * g.y + c12 * g.z,
        c02 * g.x + c12 * g.y + c22 * g.z,
    ) / det;
    muller + (newton - muller) * (s_near * s_pd)
}

/// Length of Müller's step below which [`rotation_step`] takes Newton's whole, rad (it
/// blends the two up to twice this).
pub const NEWTON_NEAR: f32 = 0.05;

/// Clusters whose rotations stage 1 extracts together (see [`extract_rotations_at`]).
pub(crate) const ROTATIONS: usize = crate::simd::LANES;

dispatch! {
/// [`extract_rotation`] of sixteen matrices at once, one per [`crate::simd::F32x16`] lane
/// (the CPU's vector unit, AVX2 where it has it): every lane takes the same IEEE operations in
/// the same order as the scalar path (glam's `Vec3` and `Mat3` arithmetic, its SSE2 `Quat`
/// product and normalisation), so the same bits (tested). The branches of [`rotation_step`]
/// become selects.
pub(crate) fn extract_rotations_at(a: &[Mat3; ROTATIONS], q: &mut [Quat; ROTATIONS], iterations: u32) {
    let col = |c: usize| V3::from_lanes(std::array::from_fn(|l| a[l].col(c)));
    let a = [col(0), col(1), col(2)];
    let comp = |k: usize| V::from(std::array::from_fn(|l| q[l].to_array()[k]));
    let out = extract_rotation_lanes(a, [comp(0), comp(1), comp(2), comp(3)], iterations);
    for (l, q) in q.iter_mut().enumerate() {
        *q = Quat::from_array(out.map(|c| c.as_array_ref()[l]));
    }
}
}

/// [`extract_rotation`] on lanes: `a` by columns, `q` as x, y, z, w.
#[inline(always)]
fn extract_rotation_lanes(a: [V3; 3], q: [V; 4], iterations: u32) -> [V; 4] {
    let eps = V::splat(1e-6) * (a[0].length() + a[1].length() + a[2].length()) + V::splat(1e-30);
    let [mut x, mut y, mut z, mut w] = q;
    for _ in 0..iterations {
        // Mat3::from_quat.
        let (x2, y2, z2) = (x + x, y + y, z + z);
        let (xx, xy, xz) = (x * x2, x * y2, x * z2);
        let (yy, yz, zz) = (y * y2, y * z2, z * z2);
        let (wx, wy, wz) = (w * x2, w * y2, w * z2);
        let one = V::ONE;
        let r = [
            V3 { x: one - (yy + zz), y: xy + wz, z: xz - wy },
            V3 { x: xy - wz, y: one - (xx + zz), z: yz + wx },
            V3 { x: xz + wy, y: yz - wx, z: one - (xx + yy) },
        ];
        let s = rotation_step_lanes(r, a, eps);
        let (hx, hy, hz) = (s.x * 0.5, s.y * 0.5, s.z * 0.5);
        // (h, 1) · q as glam's SSE2 product adds it: (w₀q + x₀·wzyx·±) + (y₀·zwxy·± + z₀·yxwz·±),
        // w₀ = 1.
        let px = (x + hx * w) + (hy * z - hz * y);
        let py = (y - hx * z) + (hy * w + hz * x);
        let pz = (z + hx * y) + (hz * w - hy * x);
        let pw = (w - hx * x) + (-(hy * y) - hz * z);
        // Vec4::normalize: divided by √((x² + z²) + (y² + w²)).
        let len = ((px * px + pz * pz) + (py * py + pw * pw)).sqrt();
        (x, y, z, w) = (px / len, py / len, pz / len, pw / len);
    }
    [x, y, z, w]
}

/// [`rotation_step`] on lanes, its two early returns as selects.
#[inline(always)]
fn rotation_step_lanes(r: [V3; 3], a: [V3; 3], eps: V) -> V3 {
    let g = r[0].cross(a[0]) + r[1].cross(a[1]) + r[2].cross(a[2]);
    let tr = r[0].dot(a[0]) + r[1].dot(a[1]) + r[2].dot(a[2]);
    let d = tr.abs() + eps;
    let muller = V3 { x: g.x / d, y: g.y / d, z: g.z / d };
    let near = NEWTON_NEAR * NEWTON_NEAR;
    let s_near = ((V::splat(4.0 * near) - muller.dot(muller)) / V::splat(3.0 * near)).min(V::ONE);
    let zero = V::ZERO;
    // Columns of B = A Rᵀ: bₖ = Σᵢ aᵢ rᵢ[k].
    let b0 = a[0].scale(r[0].x) + a[1].scale(r[1].x) + a[2].scale(r[2].x);
    let b1 = a[0].scale(r[0].y) + a[1].scale(r[1].y) + a[2].scale(r[2].y);
    let b2 = a[0].scale(r[0].z) + a[1].scale(r[1].z) + a[2].scale(r[2].z);
    let h00 = tr - b0.x;
    let h11 = tr - b1.y;
    let h22 = tr - b2.z;
    let h01 = V::splat(-0.5) * (b1.x + b0.y);
    let h02 = V::splat(-0.5) * (b2.x + b0.z);
    let h12 = V::splat(-0.5) * (b2.y + b1.z);
    let c00 = h11 * h22 - h12 * h12;
    let c01 = h02 * h12 - h01 * h22;
    let c02 = h01 * h12 - h02 * h11;
    let c11 = h00 * h22 - h02 * h02;
    let c12 = h01 * h02 - h00 * h12;
    let c22 = h00 * h11 - h01 * h01;
    let det = h00 * c00 + h01 * c01 + h02 * c02;
    let thin = V::splat(1e-4) * (tr * tr * tr);
    let newton_ok = tr.cmp_gt(zero) & s_near.cmp_gt(zero) & h00.cmp_gt(zero) & c22.cmp_gt(zero) & det.cmp_gt(thin);
    let s_pd = thin.cmp_gt(zero).blend((det / thin - V::ONE).min(V::ONE), V::ONE);
    let newton = V3 {
        x: (c00 * g.x + c01 * g.y + c02 * g.z) / det,
        y: (c01 * g.x + c11 * g.y + c12 * g.z) / det,
        z: (c02 * g.x + c12 * g.y + c22 * g.z) / det,
    };
    let blended = muller + (newton - muller).scale(s_near * s_pd);
    V3::select(newton_ok, blended, muller)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::{Level, detected};
    use rand::{Rng, SeedableRng};

    /// Stage 1's rotations on lanes ([`extract_rotations_at`], at every level the CPU has) are
    /// [`extract_rotation`]'s bit for bit: random matrices (rotations times stretches, shears,
    /// reflections), warm starts near and far, and the degenerate cases the steps guard
    /// (zero, rank one, inverted, vanishing, huge, non-finite).
    #[test]
    fn rotations_on_lanes_are_the_scalar_rotations() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
        let unit = |rng: &mut rand_chacha::ChaCha8Rng| {
            Quat::from_xyzw(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .normalize()
        };
        let levels: Vec<Level> = [Level::Baseline, Level::Avx2].into_iter().filter(|&l| l <= detected()).collect();
        if levels.len() == 1 {
            println!("this CPU has no AVX2: only the baseline level is checked");
        }
        for round in 0..400 {
            let a: [Mat3; ROTATIONS] = std::array::from_fn(|l| {
                let r = Mat3::from_quat(unit(&mut rng));
                let s = Mat3::from_cols_array(&std::array::from_fn(|_| rng.random_range(-1.0f32..1.0)));
                let stretch = Mat3::from_diagonal(Vec3::new(
                    rng.random_range(0.0..2.0),
                    rng.random_range(0.0..2.0),
                    rng.random_range(-0.2..2.0),
                ));
                let m = match (round + l) % 9 {
                    0 => Mat3::ZERO,
                    1 => Mat3::from_cols(Vec3::X, Vec3::X * 2.0, Vec3::X * -0.5),
                    2 => -r,
                    3 => r * 1e-20,
                    4 => r * 1e18,
                    5 if round % 2 == 0 => Mat3::from_cols(Vec3::NAN, Vec3::Y, Vec3::Z),
                    5 => Mat3::from_cols(Vec3::INFINITY, Vec3::Y, Vec3::Z),
                    6 => r * s,
                    _ => r * stretch + s * 0.05,
                };
                m * 10f32.powi(rng.random_range(-4..4))
            });
            let start: [Quat; ROTATIONS] =
                std::array::from_fn(|l| if l % 3 == 0 { Quat::IDENTITY } else { unit(&mut rng) });
            let iterations = 1 + round as u32 % 4;
            let want = std::array::from_fn::<_, ROTATIONS, _>(|l| extract_rotation(a[l], start[l], iterations));
            for &level in &levels {
                let mut got = start;
                extract_rotations_at(level, &a, &mut got, iterations);
                for l in 0..ROTATIONS {
                    let same = got[l].to_array().map(f32::to_bits) == want[l].to_array().map(f32::to_bits)
                        || (got[l].is_nan() && want[l].is_nan());
                    assert!(same, "{level:?}, {iterations} iterations, {}: {} vs {}", a[l], got[l], want[l]);
                }
            }
        }
    }
}
