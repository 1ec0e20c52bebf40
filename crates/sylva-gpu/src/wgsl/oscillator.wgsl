// The exact step of a damped oscillator x'' + 2 a x' + w2 (x - x_eq) = 0 over dt. Twins:
// sylva_core::physics::oscillator::{damped_coefficients, damped_apply}.

// (C, S): C = e^(-a dt) cos(wd dt), S = e^(-a dt) sin(wd dt) / wd (cosh, sinh when overdamped).
fn damped_coefficients(w2: f32, a: f32, dt: f32) -> vec2<f32> {
    let disc = w2 - a * a;
    if (disc > 0.0) {
        let wd = sqrt(disc);
        let e = exp(-a * dt);
        return vec2<f32>(e * cos(wd * dt), e * sin(wd * dt) / wd);
    }
    let b = sqrt(-disc);
    let e1 = exp((b - a) * dt);
    let e2 = exp(-(a + b) * dt);
    var s = e1 * dt;
    if (b > 1e-6) {
        s = 0.5 * (e1 - e2) / b;
    }
    return vec2<f32>(0.5 * (e1 + e2), s);
}

struct Damped {
    x: vec3<f32>,
    v: vec3<f32>,
}

// The step from (x0, v0) with coefficients cs = damped_coefficients(w2, a, dt).
fn damped_apply(x0: vec3<f32>, v0: vec3<f32>, x_eq: vec3<f32>, w2: f32, a: f32, cs: vec2<f32>) -> Damped {
    let x = x0 - x_eq;
    return Damped(x_eq + x * cs.x + (v0 + x * a) * cs.y, v0 * cs.x - (v0 * a + x * w2) * cs.y);
}
