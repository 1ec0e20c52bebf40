// Wind fields, shared by every kernel that samples the wind. Twin:
// sylva_core::wind::sample::{field_at, wind_at} (same operations, same order).
// A kernel that composes this file binds the scene at group 0, bindings 0 and 1.

const TAU: f32 = 6.283185307179586;
const KIND_CONSTANT: u32 = 0u;
const KIND_SUM_OF_SINES: u32 = 1u;
const KIND_GUST_FRONT: u32 = 2u;
const KIND_VORTEX: u32 = 3u;
const KIND_BLAST: u32 = 4u;
const KIND_TURBULENCE: u32 = 5u;
const KIND_GRID: u32 = 6u;

struct Field {
    kind: u32,
    wave_offset: u32,
    wave_count: u32,
    _pad: u32,
    a: vec4<f32>,
    b: vec4<f32>,
    c: vec4<f32>,
}

struct Wave {
    dir: vec4<f32>,
    k: vec4<f32>,
    phase: vec4<f32>,
}

@group(0) @binding(0) var<storage, read> wind_fields: array<Field>;
@group(0) @binding(1) var<storage, read> wind_waves: array<Wave>;

// A wave field's blend in and out (`wave_envelope` in wind/sample.rs): exactly 1 without fades.
fn wave_envelope(b: vec4<f32>, t: f32) -> f32 {
    return smooth_step(0.0, 1.0, (t - b.x) * b.y) * (1.0 - smooth_step(0.0, 1.0, (t - b.z) * b.w));
}

// One axis of a grid lookup (`axis` in wind/grid.rs): the nodes either side of u and the
// fraction between them, over n nodes repeated (wrap) or held at the edge.
struct GridAxis {
    i0: u32,
    i1: u32,
    f: f32,
}

fn grid_axis(u: f32, n: f32, wrap: bool) -> GridAxis {
    var a: GridAxis;
    if (wrap) {
        let fl = floor(u);
        let m = i32(n);
        let i = (i32(fl) % m + m) % m;
        a.i0 = u32(i);
        a.i1 = u32((i + 1) % m);
        a.f = u - fl;
    } else {
        let c = clamp(u, 0.0, n - 1.0);
        let fl = floor(c);
        a.i0 = u32(fl);
        a.i1 = min(a.i0 + 1u, u32(n) - 1u);
        a.f = c - fl;
    }
    return a;
}

// Node i of a grid whose nodes start at record `base`, three to a record.
fn grid_node(base: u32, i: u32) -> vec3<f32> {
    let w = wind_waves[base + i / 3u];
    switch i % 3u {
        case 0u: {
            return w.dir.xyz;
        }
        case 1u: {
            return w.k.xyz;
        }
        default: {
            return w.phase.xyz;
        }
    }
}

fn grid_lerp(a: vec3<f32>, b: vec3<f32>, s: f32) -> vec3<f32> {
    return a + (b - a) * s;
}

fn grid_row(base: u32, at: u32, ax: GridAxis) -> vec3<f32> {
    return grid_lerp(grid_node(base, at + ax.i0), grid_node(base, at + ax.i1), ax.f);
}

fn grid_frame(base: u32, k: u32, n: vec3<u32>, ax: GridAxis, ay: GridAxis, az: GridAxis) -> vec3<f32> {
    let p0 = grid_lerp(
        grid_row(base, ((k * n.z + az.i0) * n.y + ay.i0) * n.x, ax),
        grid_row(base, ((k * n.z + az.i0) * n.y + ay.i1) * n.x, ax),
        ay.f,
    );
    let p1 = grid_lerp(
        grid_row(base, ((k * n.z + az.i1) * n.y + ay.i0) * n.x, ax),
        grid_row(base, ((k * n.z + az.i1) * n.y + ay.i1) * n.x, ax),
        ay.f,
    );
    return grid_lerp(p0, p1, az.f);
}

// A grid field (`grid_at` in wind/grid.rs): trilinear in space, linear between looped frames.
fn grid_at(f: Field, p: vec3<f32>, t: f32) -> vec3<f32> {
    let head = wind_waves[f.wave_offset];
    let wrap = f.b.w >= 0.5;
    let g = ((p - f.a.xyz) - head.k.xyz * t) * f.b.xyz;
    let ax = grid_axis(g.x, head.dir.x, wrap);
    let ay = grid_axis(g.y, head.dir.y, wrap);
    let az = grid_axis(g.z, head.dir.z, wrap);
    let at = grid_axis(t * f.a.w, head.dir.w, true);
    let n = vec3<u32>(head.dir.xyz);
    let base = f.wave_offset + 1u;
    return grid_lerp(grid_frame(base, at.i0, n, ax, ay, az), grid_frame(base, at.i1, n, ax, ay, az), at.f);
}

fn field_at(f: Field, p: vec3<f32>, t: f32) -> vec3<f32> {
    switch f.kind {
        case KIND_CONSTANT: {
            return f.a.xyz;
        }
        case KIND_SUM_OF_SINES: {
            let sharp = f.a.x;
            let mode = f.a.y;
            let e = wave_envelope(f.b, t);
            var v = vec3<f32>(0.0);
            for (var i = f.wave_offset; i < f.wave_offset + f.wave_count; i++) {
                let w = wind_waves[i];
                let th = dot(w.k.xyz, p) + w.k.w * t;
                let s = sin_turns(th);
                var h = s;
                if (mode >= 0.5) {
                    h = pow((s + 1.0) * 0.5, sharp);
                }
                v += w.dir.xyz * (h * e);
            }
            return v;
        }
        case KIND_GUST_FRONT: {
            let rel = vec2<f32>(p.x - f.a.x, p.z - f.a.y);
            let d = f.a.zw;
            let along = dot(rel, d);
            let s = along - f.b.y * (t - f.c.x);
            var g: f32;
            if (s >= 0.0) {
                g = 1.0 - smooth_step(0.0, f.b.z, s);
            } else {
                g = exp(s / f.b.w);
            }
            let lateral = abs(rel.x * -d.y + rel.y * d.x);
            let lat = 1.0 - smooth_step(0.5 * f.c.y, f.c.y, lateral);
            let behind_origin = smooth_step(-f.b.z, 0.0, along);
            let a = f.b.x * g * lat * behind_origin;
            return vec3<f32>(d.x * a, 0.0, d.y * a);
        }
        case KIND_VORTEX: {
            let tau = t - f.b.z;
            if (tau < 0.0 || tau > f.b.w) {
                return vec3<f32>(0.0);
            }
            let env = smooth_step(0.0, f.c.x, tau) * smooth_step(0.0, f.c.x, f.b.w - tau);
            let cx = f.a.x + f.a.z * tau;
            let cz = f.a.y + f.a.w * tau;
            let rx = p.x - cx;
            let rz = p.z - cz;
            let d2 = rx * rx + rz * rz;
            let r2 = f.b.y * f.b.y;
            let up = f.c.y * exp(-d2 / r2);
            let d = sqrt(d2);
            if (d < 1e-6) {
                return vec3<f32>(0.0, env * up, 0.0);
            }
            // 1 - e^(-x), by its series near the axis where the subtraction cancels.
            let x = 1.256 * d2 / r2;
            var one_minus = 1.0 - exp(-x);
            if (x < 1e-2) {
                one_minus = x * (1.0 - 0.5 * x);
            }
            let vt = f.b.x * 1.398 * (f.b.y / d) * one_minus;
            return vec3<f32>(env * vt * rz / d, env * up, env * vt * -rx / d);
        }
        case KIND_BLAST: {
            let tau = t - f.b.x;
            let rel = p - f.a.xyz;
            let d = length(rel);
            if (tau < 0.0 || d < 1e-6) {
                return vec3<f32>(0.0);
            }
            let x = (d - f.b.y * tau) / f.b.z;
            let shell = exp(-(x * x));
            let amp = f.a.w * exp(-tau / f.b.w) * shell * (1.0 - smooth_step(0.8 * f.c.x, f.c.x, d));
            return rel * (amp / d);
        }
        case KIND_TURBULENCE: {
            let e = wave_envelope(f.b, t);
            var v = vec3<f32>(0.0);
            for (var i = f.wave_offset; i < f.wave_offset + f.wave_count; i++) {
                let w = wind_waves[i];
                let c0 = w.k.w * t + w.phase.x;
                let cyc = c0 - floor(c0);
                let th = TAU * cyc - dot(w.k.xyz, p);
                v += w.dir.xyz * (sin_turns(th) * e);
            }
            return v;
        }
        case KIND_GRID: {
            return grid_at(f, p, t);
        }
        default: {
            return vec3<f32>(0.0);
        }
    }
}

// The scene's wind at p and t: the sum of its fields.
fn wind_at(p: vec3<f32>, t: f32) -> vec3<f32> {
    var v = vec3<f32>(0.0);
    let n = arrayLength(&wind_fields);
    for (var i = 0u; i < n; i++) {
        v += field_at(wind_fields[i], p, t);
    }
    return v;
}
