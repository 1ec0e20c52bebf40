//! The exact step of a damped oscillator, `x¨ + 2 a x˙ + w² (x − x_eq) = 0`, held over one
//! time step: the frequency and damping it gives do not depend on the step's length. Akagi's
//! joints and Skjermo's stems step with it. WGSL: `wgsl/oscillator.wgsl`.

use glam::Vec3;

/// The step's coefficients `(C, S)` over `dt`: `C = e^(−a dt) cos(ω_d dt)`,
/// `S = e^(−a dt) sin(ω_d dt) / ω_d` with `ω_d = √(w² − a²)` (cosh and sinh when
/// overdamped, written with exponentials that cannot overflow). WGSL: `damped_coefficients`.
#[inline]
pub fn damped_coefficients(w2: f32, a: f32, dt: f32) -> (f32, f32) {
    let disc = w2 - a * a;
    if disc > 0.0 {
        let wd = disc.sqrt();
        let e = (-a * dt).exp();
        let (sn, cs) = (wd * dt).sin_cos();
        (e * cs, e * sn / wd)
    } else {
        let b = (-disc).sqrt();
        let (e1, e2) = (((b - a) * dt).exp(), (-(a + b) * dt).exp());
        (0.5 * (e1 + e2), if b > 1e-6 { 0.5 * (e1 - e2) / b } else { e1 * dt })
    }
}

/// The exact step from `(x0, v0)` with coefficients `(c, s)` of [`damped_coefficients`]:
/// `x = x_eq + C x0' + S (v0 + a x0')`, `v = C v0 − S (a v0 + w² x0')`, `x0' = x0 − x_eq`.
/// WGSL: `damped_apply`.
#[inline]
pub fn damped_apply(x0: Vec3, v0: Vec3, x_eq: Vec3, w2: f32, a: f32, (c, s): (f32, f32)) -> (Vec3, Vec3) {
    let x = x0 - x_eq;
    (x_eq + x * c + (v0 + x * a) * s, v0 * c - (v0 * a + x * w2) * s)
}

/// The exact step of `x¨ + 2 a x˙ + w² (x − x_eq) = 0` over `dt` from `(x0, v0)`:
/// `(x1, v1)`, under- or overdamped.
#[inline]
pub fn damped_step(x0: Vec3, v0: Vec3, x_eq: Vec3, w2: f32, a: f32, dt: f32) -> (Vec3, Vec3) {
    damped_apply(x0, v0, x_eq, w2, a, damped_coefficients(w2, a, dt))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Many short steps equal one long one (the step is the exact solution), under- and
    /// overdamped, and a free oscillator keeps its energy.
    #[test]
    fn steps_compose_exactly() {
        for (w2, a) in [(4.0f32, 0.1f32), (4.0, 3.0), (1.0, 1.0)] {
            let (x0, v0, eq) = (Vec3::new(1.0, -0.5, 0.2), Vec3::new(0.3, 0.0, -1.0), Vec3::new(0.1, 0.2, 0.0));
            let (long, long_v) = damped_step(x0, v0, eq, w2, a, 1.0);
            let (mut x, mut v) = (x0, v0);
            for _ in 0..100 {
                (x, v) = damped_step(x, v, eq, w2, a, 0.01);
            }
            assert!((x - long).length() < 1e-4 && (v - long_v).length() < 1e-4, "{x} {long} {v} {long_v}");
        }
        let (mut x, mut v) = (Vec3::X, Vec3::ZERO);
        for _ in 0..1000 {
            (x, v) = damped_step(x, v, Vec3::ZERO, 9.0, 0.0, 0.013);
        }
        let energy = 9.0 * x.length_squared() + v.length_squared();
        assert!((energy - 9.0).abs() < 1e-3, "energy {energy}");
    }
}
