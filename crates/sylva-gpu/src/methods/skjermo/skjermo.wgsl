// Shared by Skjermo's kernels: structs and Bezier helpers. Twins:
// sylva_core::methods::skjermo::{RawSkjermoStem, RawSkjermoState, RawSkjermoStep, RawSkjermoMode,
// RawSkjermoSway, bezier,
// bezier_d, frame}.

struct SkjermoStem {
    rest: array<vec4<f32>, 4>,
    local: array<vec4<f32>, 4>,
    parent: u32,
    attach: f32,
    drag: f32,
    length: f32,
    parent_orient: vec4<f32>,
}

struct SkjermoState {
    delta: array<vec4<f32>, 4>,
}

struct SkjermoStep {
    time: f32,
    exponent: f32,
    p2_weight: f32,
    max_bend: f32,
    dt: f32,
    dynamics: u32,
    reconfiguration_speed: f32,
    vogel_exponent: f32,
}

struct SkjermoMode {
    w2: f32,
    damping: f32,
    aero: f32,
    _pad: f32,
}

struct SkjermoSway {
    bend: vec4<f32>,
    rate: vec4<f32>,
}

struct Curve {
    p: array<vec3<f32>, 4>,
}

fn bezier(c: Curve, t: f32) -> vec3<f32> {
    let s = 1.0 - t;
    return c.p[0] * (s * s * s) + c.p[1] * (3.0 * s * s * t) + c.p[2] * (3.0 * s * t * t) + c.p[3] * (t * t * t);
}

fn bezier_d(c: Curve, t: f32) -> vec3<f32> {
    let s = 1.0 - t;
    return (c.p[1] - c.p[0]) * (3.0 * s * s) + (c.p[2] - c.p[1]) * (6.0 * s * t) + (c.p[3] - c.p[2]) * (3.0 * t * t);
}

fn unit_or(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    if (l > 1e-6) {
        return v * (1.0 / l);
    }
    return fallback;
}

// glam's Vec3::any_orthogonal_vector.
fn any_orthogonal(v: vec3<f32>) -> vec3<f32> {
    if (abs(v.x) > abs(v.y)) {
        return vec3<f32>(-v.z, 0.0, v.x);
    }
    return vec3<f32>(0.0, v.z, -v.y);
}

struct Frame {
    t: vec3<f32>,
    n: vec3<f32>,
    b: vec3<f32>,
}

fn frame(c: Curve, o: vec3<f32>, t: f32) -> Frame {
    let tan = unit_or(bezier_d(c, t), vec3<f32>(0.0, 1.0, 0.0));
    let n = unit_or(o - tan * dot(o, tan), unit_or(any_orthogonal(tan), vec3<f32>(1.0, 0.0, 0.0)));
    return Frame(tan, n, cross(tan, n));
}

// sylva_core::methods::skjermo::transported_frame: the rest frame turned by the shortest arc
// to the parent curve's tangent now; the rest frame itself where the tangent is the rest one.
fn transported_frame(rest: Frame, tangent: vec3<f32>) -> Frame {
    let t = unit_or(tangent, vec3<f32>(0.0, 1.0, 0.0));
    if (all(t == rest.t)) {
        return rest;
    }
    let k = cross(rest.t, t);
    let c = dot(rest.t, t);
    var m = rest.n;
    if (1.0 + c > 1e-6) {
        m = rest.n * c + cross(k, rest.n) + k * (dot(k, rest.n) / (1.0 + c));
    }
    let n = unit_or(m - t * dot(m, t), unit_or(any_orthogonal(t), vec3<f32>(1.0, 0.0, 0.0)));
    return Frame(t, n, cross(t, n));
}

fn rest_curve(s: SkjermoStem) -> Curve {
    return Curve(array<vec3<f32>, 4>(s.rest[0].xyz, s.rest[1].xyz, s.rest[2].xyz, s.rest[3].xyz));
}

fn now_curve(s: SkjermoStem, st: SkjermoState) -> Curve {
    return Curve(array<vec3<f32>, 4>(
        s.rest[0].xyz + st.delta[0].xyz,
        s.rest[1].xyz + st.delta[1].xyz,
        s.rest[2].xyz + st.delta[2].xyz,
        s.rest[3].xyz + st.delta[3].xyz,
    ));
}
