// Leaf motion's structs and closed form, shared by leaf_wind and leaf_flutter. Twins:
// sylva_core::leaves::{RawLeafFrame, RawLeafMotion} and kernels::{leaf_band, leaf_rotation}.

const LEAF_AIR_DENSITY: f32 = 1.225;

struct LeafFrame {
    time: f32,
    strength: f32,
    flutter: f32,
    zeta: f32,
    reconfiguration_speed: f32,
    vogel_exponent: f32,
    leaves: u32,
    twigs: u32,
    flutter_onset: f32,
    crown_wind: f32,
    _pad: vec2<u32>,
}

struct LeafMotion {
    orientation: vec4<f32>,
    omega: f32,
    omega_twist: f32,
    compliance: f32,
    flip_pressure: f32,
    seed: u32,
    twig: u32,
    segment: u32,
    _pad: u32,
}

// Unit-RMS narrow-band flutter: three sines over the half-power band omega (1 ± zeta).
fn leaf_band(omega: f32, zeta: f32, t: f32, seed: u32) -> f32 {
    var sum = 0.0;
    for (var j = 0u; j < 3u; j++) {
        let w = omega * (1.0 + zeta * (f32(j) - 1.0));
        let phase = hash_unit(seed + j) * 6.283185307179586;
        sum += sin_turns(w * t + phase);
    }
    return sum * 0.8164966;
}

// One leaf's rotation in its segment's rest frame from its twig's two entries of leaf_wind
// (wind xyz, q g; flutter amplitude, dynamic pressure at the twig) and its segment's
// accumulated rotation d.
fn leaf_rotation(frame: LeafFrame, m: LeafMotion, w: vec4<f32>, s2: vec4<f32>, d: vec4<f32>, t: f32) -> vec4<f32> {
    let u = quat_rotate(quat_conj(d), w.xyz);
    let speed = length(u);
    if (frame.strength == 0.0 || speed == 0.0 || frame.crown_wind == 0.0) {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    let amp = s2.x;
    let q_twig = s2.y;
    let k = m.compliance * w.w;
    let s = k / (1.0 + k);
    let b = quat_rotate(m.orientation, vec3<f32>(0.0, 1.0, 0.0));
    let c = cross(b, u);
    let cl = length(c);
    let phi = atan2(cl, dot(b, u));
    var axis = quat_rotate(m.orientation, vec3<f32>(1.0, 0.0, 0.0));
    if (cl > 1e-6 * speed) {
        axis = c / cl;
    }
    let damped = sqrt(1.0 - frame.zeta * frame.zeta);
    let omega = m.omega * damped;
    let omega_twist = m.omega_twist * damped;
    let pitch = frame.strength * (phi * s + amp * leaf_band(omega, frame.zeta, t, m.seed));
    let tumble = 0.7853981633974483 * smooth_step(0.8, 1.25, q_twig / m.flip_pressure);
    let twist = frame.strength * ((amp + tumble) * leaf_band(omega_twist, frame.zeta, t, m.seed + 3u));
    let hp = 0.5 * pitch;
    let ht = 0.5 * twist;
    let swing = vec4<f32>(axis * sin(hp), cos(hp));
    let turn = vec4<f32>(b * sin(ht), cos(ht));
    return quat_mul(swing, turn);
}
