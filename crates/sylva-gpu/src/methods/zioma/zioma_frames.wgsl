// zioma_frames: every instance's per-frame values (Zioma §6.3.3, §6.5): the wind at its
// crown through the trunk's damped oscillator plus its own ring, turned into the tree's frame,
// the lean's direction, its noise bands and the parallel band's rate. CPU twin:
// sylva_core::methods::zioma::frames (bindings 0 fields, 1 waves — from wind.wgsl —
// 2 the tree's values, 3 instances, 4 their rings, 5 frames). The trunk's functions are
// sylva_core::methods::zioma::trunk::TrunkModel's, written out in the same order.

@group(0) @binding(2) var<storage, read> trunk: ZiomaTrunk;
@group(0) @binding(3) var<storage, read> instances: array<ZiomaInstance>;
@group(0) @binding(4) var<storage, read> rings: array<ZiomaRing>;
@group(0) @binding(5) var<storage, read_write> frames: array<ZiomaFrame>;

const AIR_DENSITY: f32 = 1.225;
const MAX_TRUNK_BEND: f32 = 0.35;
const RATE_DT: f32 = 0.01;

// Vogel reconfiguration's factor on u² (DragModel::reconfiguration).
fn reconfiguration(u: f32) -> f32 {
    let r = u / trunk.reconfiguration_speed;
    return pow(1.0 + r * r, 0.5 * trunk.vogel_exponent);
}

// The arc angle under a steady wind of u m/s, capped (TrunkModel::static_bend).
fn static_bend(u: f32) -> f32 {
    let q = 0.5 * AIR_DENSITY * u * u * reconfiguration(u);
    return min(trunk.tip_per_pascal * q / trunk.lever, MAX_TRUNK_BEND);
}

// The damping ratio in a wind of u m/s, the wood's plus the air's (TrunkModel::damping).
fn trunk_damping(u: f32) -> f32 {
    let w = TAU * trunk.natural_frequency;
    return trunk.damping_ratio
        + 0.5 * w * trunk.damping_centre * AIR_DENSITY * trunk.tip_per_pascal * u * reconfiguration(u);
}

// The oscillator's gain and phase lag at f Hz (TrunkModel::response).
fn trunk_response(f: f32, zeta: f32) -> vec2<f32> {
    let r = abs(f) / max(trunk.natural_frequency, 1e-6);
    let re = 1.0 - r * r;
    let im = 2.0 * zeta * r;
    return vec2<f32>(1.0 / max(sqrt(re * re + im * im), 1e-6), atan2(im, re));
}

// d θ / d u at a steady wind of u m/s (TrunkModel::static_bend_slope).
fn static_bend_slope(u: f32) -> f32 {
    if (static_bend(u) >= MAX_TRUNK_BEND) {
        return 0.0;
    }
    let ur2 = trunk.reconfiguration_speed * trunk.reconfiguration_speed;
    let slope = u * reconfiguration(u) * (2.0 + trunk.vogel_exponent * u * u / (ur2 + u * u));
    return trunk.tip_per_pascal * 0.5 * AIR_DENSITY * slope / trunk.lever;
}

// The wind at p and t with every wave passed through the trunk's oscillator at damping
// ratio zeta (sylva_core::wind::sample::wind_through with TrunkModel::response).
fn wind_through_trunk(p: vec3<f32>, t: f32, zeta: f32) -> vec3<f32> {
    var v = vec3<f32>(0.0);
    let n = arrayLength(&wind_fields);
    for (var i = 0u; i < n; i++) {
        let f = wind_fields[i];
        switch f.kind {
            case KIND_SUM_OF_SINES: {
                let sharp = f.a.x;
                let mode = f.a.y;
                // Mean of ((sin + 1) / 2)^sharp over a period (midpoint rule).
                var mean = 0.0;
                if (mode >= 0.5) {
                    var s = 0.0;
                    for (var j = 0u; j < 64u; j++) {
                        s += pow((sin((f32(j) + 0.5) * TAU / 64.0) + 1.0) * 0.5, sharp);
                    }
                    mean = s / 64.0;
                }
                let e = wave_envelope(f.b, t);
                var sum = vec3<f32>(0.0);
                for (var k = f.wave_offset; k < f.wave_offset + f.wave_count; k++) {
                    let w = wind_waves[k];
                    let h = trunk_response(abs(w.k.w) / TAU, zeta);
                    var turn = 1.0;
                    if (w.k.w < 0.0) {
                        turn = -1.0;
                    }
                    let s = sin_turns(dot(w.k.xyz, p) + w.k.w * t - h.y * turn);
                    var swing = s;
                    if (mode >= 0.5) {
                        swing = pow((s + 1.0) * 0.5, sharp) - mean;
                    }
                    sum += w.dir.xyz * ((mean + h.x * swing) * e);
                }
                v += sum;
            }
            case KIND_TURBULENCE: {
                let e = wave_envelope(f.b, t);
                var sum = vec3<f32>(0.0);
                for (var k = f.wave_offset; k < f.wave_offset + f.wave_count; k++) {
                    let w = wind_waves[k];
                    let h = trunk_response(w.k.w, zeta);
                    let c0 = w.k.w * t + w.phase.x;
                    let cyc = c0 - floor(c0);
                    sum += w.dir.xyz * (h.x * sin_turns(TAU * cyc - dot(w.k.xyz, p) - h.y) * e);
                }
                v += sum;
            }
            default: {
                v += field_at(f, p, t);
            }
        }
    }
    return v;
}

// The trunk's bend at p and t, a horizontal vector (TrunkModel::bend).
fn trunk_bend(p: vec3<f32>, t: f32) -> vec3<f32> {
    let w = wind_at(p, t);
    let raw = vec3<f32>(w.x, 0.0, w.z);
    let u = length(raw);
    if (u < 1e-6) {
        return vec3<f32>(0.0);
    }
    let zeta = trunk_damping(u);
    let wt = wind_through_trunk(p, t, zeta);
    let swing = vec3<f32>(wt.x, 0.0, wt.z) - raw;
    let along = raw / u;
    let across = cross(vec3<f32>(0.0, 1.0, 0.0), along);
    let theta = static_bend(u);
    return along * (theta + static_bend_slope(u) * dot(swing, along)) + across * (theta * dot(swing, across) / u);
}

// The ring's bend at t (TrunkModel::ring_at).
fn ring_bend(ring: ZiomaRing, t: f32) -> vec3<f32> {
    let tau = t - ring.since;
    if (tau < 0.0 || (all(ring.bend == vec3<f32>(0.0)) && all(ring.rate == vec3<f32>(0.0)))) {
        return vec3<f32>(0.0);
    }
    let w = TAU * trunk.natural_frequency;
    let z = clamp(ring.zeta, 0.0, 0.95);
    let a = z * w;
    let wd = w * sqrt(1.0 - z * z);
    let b = (ring.rate + ring.bend * a) / wd;
    return exp(-a * tau) * (ring.bend * cos(wd * tau) + b * sin(wd * tau));
}

// The trunk's noise bands at lean theta (TrunkNoise::new's table, trunk::TRUNK_BANDS):
// (parallel, perpendicular, twist).
fn trunk_noise_angles(theta: f32, t: f32, seed: u32) -> vec3<f32> {
    let f0 = trunk.natural_frequency;
    var out = vec3<f32>(0.0);
    out.x += 1.0 * theta + 0.12 * theta * value_noise(2.3 * f0 * t, 0x13u ^ seed);
    out.x += 0.0 * theta + 0.05 * theta * value_noise(5.1 * f0 * t, 0x14u ^ seed);
    out.y += 0.0 * theta + 0.06 * theta * value_noise(3.1 * f0 * t, 0x22u ^ seed);
    out.z += 0.0 * theta + 0.08 * theta * value_noise(1.3 * f0 * t, 0x31u ^ seed);
    return out;
}

// The lean at t as (unit direction in the tree's frame, or zero; angle θ): sc is the
// instance's (sin, cos) of yaw.
fn lean(centre: vec3<f32>, ring: ZiomaRing, t: f32, sc: vec2<f32>) -> vec4<f32> {
    let w = trunk_bend(centre, t) + ring_bend(ring, t);
    let b = vec3<f32>(sc.y * w.x - sc.x * w.z, w.y, sc.x * w.x + sc.y * w.z);
    let l = length(b);
    var dir = vec3<f32>(0.0);
    if (l > 1e-30) {
        dir = b * (1.0 / l);
    }
    return vec4<f32>(dir, min(l, MAX_TRUNK_BEND));
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&instances)) {
        return;
    }
    let inst = instances[i];
    let ring = rings[i];
    let sc = vec2<f32>(sin(inst.yaw), cos(inst.yaw));
    let c = trunk.crown_centre;
    let centre = inst.position + vec3<f32>(sc.y * c.x + sc.x * c.z, c.y, -sc.x * c.x + sc.y * c.z);
    let seed = trunk.tree_seed ^ inst.seed;
    let t = trunk.time;
    let now = lean(centre, ring, t, sc);
    let tp = t + RATE_DT;
    // Never differenced back past the change a ring starts at (frames.rs, rate_behind).
    var tm = t - RATE_DT;
    var span = 2.0 * RATE_DT;
    let ringing = any(ring.bend != vec3<f32>(0.0)) || any(ring.rate != vec3<f32>(0.0));
    if (ringing && t >= ring.since && tm < ring.since) {
        tm = ring.since;
        span = RATE_DT + (t - ring.since);
    }
    let ahead = trunk_noise_angles(lean(centre, ring, tp, sc).w, tp, seed).x;
    let behind = trunk_noise_angles(lean(centre, ring, tm, sc).w, tm, seed).x;
    var f: ZiomaFrame;
    f.wind_dir = now.xyz;
    f.time = t;
    f.trunk = trunk_noise_angles(now.w, t, seed);
    f.trunk_rate = (ahead - behind) / span;
    f.lod = trunk.lod;
    f.amplitude = trunk.amplitude;
    f.max_bend = trunk.max_bend;
    f.inertia = trunk.inertia;
    f.origin = inst.position;
    f.phase = inst.phase;
    f.heading = sc.yx;
    f._pad = vec2<f32>(0.0);
    frames[i] = f;
}
