//! One cubic Bézier per stem (Skjermo §2.1): the curve Skjermo's method animates and the
//! deformer bends each branch along.

use glam::{DVec3, Vec3};

/// A cubic Bézier curve `B(t) = Σ bᵢ(t) Pᵢ`, `t ∈ [0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubicBezier(pub [Vec3; 4]);

impl CubicBezier {
    /// Point at parameter `t`.
    pub fn eval(&self, t: f32) -> Vec3 {
        let [p0, p1, p2, p3] = self.0;
        let s = 1.0 - t;
        p0 * (s * s * s) + p1 * (3.0 * s * s * t) + p2 * (3.0 * s * t * t) + p3 * (t * t * t)
    }

    /// Derivative `dB/dt` at `t`.
    pub fn derivative(&self, t: f32) -> Vec3 {
        let [p0, p1, p2, p3] = self.0;
        let s = 1.0 - t;
        (p1 - p0) * (3.0 * s * s) + (p2 - p1) * (6.0 * s * t) + (p3 - p2) * (3.0 * t * t)
    }
}

fn basis(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t]
}

fn eval_d(p: &[DVec3; 4], t: f64) -> DVec3 {
    let b = basis(t);
    p[0] * b[0] + p[1] * b[1] + p[2] * b[2] + p[3] * b[3]
}

fn deriv_d(p: &[DVec3; 4], t: f64) -> (DVec3, DVec3) {
    let s = 1.0 - t;
    let d1 = (p[1] - p[0]) * (3.0 * s * s) + (p[2] - p[1]) * (6.0 * s * t) + (p[3] - p[2]) * (3.0 * t * t);
    let d2 = (p[2] - 2.0 * p[1] + p[0]) * (6.0 * s) + (p[3] - 2.0 * p[2] + p[1]) * (6.0 * t);
    (d1, d2)
}

/// Fits a cubic Bézier to a polyline (a stem's segment joints), with P0 and P3 fixed at the
/// polyline's ends.
///
/// Least squares over the joints at chord-length parameters, regularised lightly toward
/// the Hermite guess from the end tangents (so two- and three-point stems have a unique,
/// natural answer), then refined by two rounds of projecting each joint onto the curve
/// (Newton steps) and solving again. Returns the control points and the largest distance
/// from a joint to its projection on the curve.
pub fn fit_cubic_bezier(points: &[Vec3]) -> ([Vec3; 4], f32) {
    assert!(points.len() >= 2, "a stem has at least one segment");
    if points.len() == 2 {
        // A straight stem: the control polygon is the segment, split in thirds. Exact.
        let (a, b) = (points[0], points[1]);
        return ([a, a + (b - a) / 3.0, a + (b - a) * (2.0 / 3.0), b], 0.0);
    }
    let pts: Vec<DVec3> = points.iter().map(|p| p.as_dvec3()).collect();
    let n = pts.len();
    let p0 = pts[0];
    let p3 = pts[n - 1];
    let mut t: Vec<f64> = Vec::with_capacity(n);
    let mut acc = 0.0;
    t.push(0.0);
    for k in 1..n {
        acc += (pts[k] - pts[k - 1]).length();
        t.push(acc);
    }
    let total = acc;
    if total <= 0.0 {
        return ([points[0]; 4], 0.0);
    }
    for v in &mut t {
        *v /= total;
    }
    let t0 = (pts[1] - pts[0]).normalize_or_zero();
    let t1 = (pts[n - 1] - pts[n - 2]).normalize_or_zero();
    let g1 = p0 + t0 * (total / 3.0);
    let g2 = p3 - t1 * (total / 3.0);
    let lambda = 1e-6;
    let mut ctrl = [p0, g1, g2, p3];
    for round in 0..6 {
        let (mut a11, mut a12, mut a22) = (lambda, 0.0, lambda);
        let mut r1 = g1 * lambda;
        let mut r2 = g2 * lambda;
        for k in 1..n - 1 {
            let b = basis(t[k]);
            let r = pts[k] - p0 * b[0] - p3 * b[3];
            a11 += b[1] * b[1];
            a12 += b[1] * b[2];
            a22 += b[2] * b[2];
            r1 += r * b[1];
            r2 += r * b[2];
        }
        let det = a11 * a22 - a12 * a12;
        if det.abs() > 1e-300 {
            ctrl[1] = (r1 * a22 - r2 * a12) / det;
            ctrl[2] = (r2 * a11 - r1 * a12) / det;
        }
        if round == 5 {
            break;
        }
        // Reparameterise: move each interior t to the closest point on the curve.
        for k in 1..n - 1 {
            let mut tk = t[k];
            for _ in 0..4 {
                let d = eval_d(&ctrl, tk) - pts[k];
                let (d1, d2) = deriv_d(&ctrl, tk);
                let num = d.dot(d1);
                let den = d1.dot(d1) + d.dot(d2);
                if den.abs() < 1e-300 {
                    break;
                }
                tk = (tk - num / den).clamp(0.0, 1.0);
            }
            t[k] = tk;
        }
    }
    // Error: distance from each joint to the curve, by a dense search refined with Newton.
    let mut err = 0.0f64;
    for (k, p) in pts.iter().enumerate() {
        let mut best_t = t[k];
        let mut best = (eval_d(&ctrl, best_t) - *p).length_squared();
        for j in 0..=64 {
            let tj = j as f64 / 64.0;
            let d = (eval_d(&ctrl, tj) - *p).length_squared();
            if d < best {
                best = d;
                best_t = tj;
            }
        }
        let mut tk = best_t;
        for _ in 0..4 {
            let d = eval_d(&ctrl, tk) - *p;
            let (d1, d2) = deriv_d(&ctrl, tk);
            let den = d1.dot(d1) + d.dot(d2);
            if den.abs() < 1e-300 {
                break;
            }
            tk = (tk - d.dot(d1) / den).clamp(0.0, 1.0);
        }
        let d = (eval_d(&ctrl, tk) - *p).length_squared().min(best);
        err = err.max(d.sqrt());
    }
    ([ctrl[0].as_vec3(), ctrl[1].as_vec3(), ctrl[2].as_vec3(), ctrl[3].as_vec3()], err as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_line_fits_exactly() {
        let pts: Vec<Vec3> = (0..6).map(|i| Vec3::new(0.0, i as f32, 0.0)).collect();
        let (c, err) = fit_cubic_bezier(&pts);
        assert!(err < 1e-5, "err {err}");
        assert_eq!(c[0], pts[0]);
        assert_eq!(c[3], pts[5]);
    }

    #[test]
    fn reproduces_points_sampled_from_a_cubic() {
        let truth =
            CubicBezier([Vec3::ZERO, Vec3::new(0.3, 1.0, 0.0), Vec3::new(1.2, 1.8, 0.4), Vec3::new(2.0, 2.0, 1.0)]);
        // Joints at uneven parameters: the fit must still find the curve.
        let pts: Vec<Vec3> = [0.0, 0.1, 0.25, 0.45, 0.6, 0.8, 0.9, 1.0].iter().map(|&t| truth.eval(t)).collect();
        let (c, err) = fit_cubic_bezier(&pts);
        // Alternating least squares and reprojection converges slowly; 0.06 % of the length is ample.
        assert!(err < 2e-3, "err {err}");
        let fitted = CubicBezier(c);
        for j in 0..=20 {
            let t = j as f32 / 20.0;
            let p = fitted.eval(t);
            let d = (0..=400).map(|k| (truth.eval(k as f32 / 400.0) - p).length()).fold(f32::MAX, f32::min);
            assert!(d < 5e-3, "t={t} d={d}");
        }
    }

    #[test]
    fn derivative_matches_finite_difference() {
        let b = CubicBezier([Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 2.0, 1.0)]);
        let h = 1e-3;
        let fd = (b.eval(0.4 + h) - b.eval(0.4 - h)) / (2.0 * h);
        assert!((fd - b.derivative(0.4)).length() < 1e-2);
    }
}
