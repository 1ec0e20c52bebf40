// zioma_rotations: Zioma's per-segment rotations (`ZiomaFrame` from zioma.wgsl). CPU twin:
// sylva_core::methods::zioma::rotations (bindings 0 fields, 1 waves — from wind.wgsl —
// 2 segments, 3 stems, 4 frames (one per instance), 5 delta, instance-major).

struct ZiomaStem {
    base: vec3<f32>,
    drag: f32,
    dir: vec3<f32>,
    freq: f32,
    parent_axis: vec3<f32>,
    phase: f32,
    level: u32,
    seed: u32,
    length: f32,
    _pad: u32,
}

@group(0) @binding(2) var<storage, read> segments: array<Segment>;
@group(0) @binding(3) var<storage, read> stems: array<ZiomaStem>;
@group(0) @binding(4) var<storage, read> frames: array<ZiomaFrame>;
@group(0) @binding(5) var<storage, read_write> delta: array<vec4<f32>>;

fn axis_or(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    if (l > 1e-6) {
        return v / l;
    }
    return fallback;
}

const IDENTITY: vec4<f32> = vec4<f32>(0.0, 0.0, 0.0, 1.0);

fn zioma_rotation(s: Segment, stem: ZiomaStem, f: ZiomaFrame) -> vec4<f32> {
    let frac = s.length / stem.length;
    let up = vec3<f32>(0.0, 1.0, 0.0);
    if (s.level == 0u) {
        let w = f.wind_dir;
        let par_axis = axis_or(cross(up, w), vec3<f32>(1.0, 0.0, 0.0));
        let perp_axis = axis_or(w, vec3<f32>(0.0, 0.0, 1.0));
        return quat_mul(
            quat_mul(quat_axis_angle(par_axis, f.trunk.x * frac), quat_axis_angle(perp_axis, f.trunk.y * frac)),
            quat_axis_angle(up, f.trunk.z * frac),
        );
    }
    if (f.lod == 0u) {
        return IDENTITY;
    }
    // The wind at the stem's base in the world, turned into the tree's frame.
    let b = stem.base;
    let hc = f.heading.x;
    let hs = f.heading.y;
    let world = f.origin + vec3<f32>(hc * b.x + hs * b.z, b.y, -hs * b.x + hc * b.z);
    let vw = wind_at(world, f.time);
    let v = vec3<f32>(hc * vw.x - hs * vw.z, vw.y, hs * vw.x + hc * vw.z);
    let vh = vec3<f32>(v.x, 0.0, v.z);
    let u = length(vh);
    if (u < 1e-6) {
        return IDENTITY;
    }
    let w = vh / u;
    let dir = stem.dir;
    let pa = stem.parent_axis;
    let bh = vec3<f32>(dir.x, 0.0, dir.z);
    var c = 0.0;
    if (length(bh) > 1e-4) {
        c = dot(normalize(bh), w);
    }
    let facing = max(-c, 0.0);
    let back = max(c, 0.0);
    let perp = 1.0 - abs(c);
    let theta = min(stem.drag * u * u, f.max_bend) * f.amplitude;
    let phase = stem.phase + f.phase;
    let osc = value_noise(stem.freq * f.time + phase, stem.seed);
    let osc2 = value_noise(2.7 * stem.freq * f.time + phase, stem.seed ^ 0x55u);
    let inertia = -f.inertia * f.trunk_rate / (TAU * stem.freq);
    let bend = theta * (facing * (0.9 + 0.1 * osc) + back * (0.4 + 0.8 * osc) + perp * (0.6 + 0.3 * osc)) + inertia * f.amplitude;
    // The bend fades with the cross flow where the wind runs along the branch (rotations.rs).
    let across = cross(dir, w);
    let k = axis_or(across, axis_or(cross(up, w), vec3<f32>(1.0, 0.0, 0.0)));
    let bend_across = bend * min(4.0 * length(across), 1.0);
    // Turns over smoothly as the wind crosses the branch's plane (rotations.rs).
    let side = clamp(4.0 * dot(axis_or(cross(pa, dir), vec3<f32>(0.0)), w), -1.0, 1.0);
    let swing = side * perp * theta * (0.5 + 0.5 * osc2);
    let twist = perp * theta * 0.3 * osc2;
    return quat_mul(
        quat_mul(quat_axis_angle(k, bend_across * frac), quat_axis_angle(pa, swing * frac)),
        quat_axis_angle(dir, twist * frac),
    );
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&delta)) {
        return;
    }
    let n = arrayLength(&segments);
    let s = segments[i % n];
    delta[i] = zioma_rotation(s, stems[s.stem], frames[i / n]);
}
