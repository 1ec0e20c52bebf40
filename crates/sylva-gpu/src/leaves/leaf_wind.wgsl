// leaf_wind: the wind at each twig's sample joint and what follows from its speed alone (two
// entries per twig), one twig per invocation.
// CPU twin: sylva_core::leaves::kernels::leaf_wind (same bindings).

@group(0) @binding(2) var<storage, read> frame: LeafFrame;
@group(0) @binding(3) var<storage, read> twigs: array<u32>;
@group(0) @binding(4) var<storage, read> joint: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> twig_wind: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= frame.twigs) {
        return;
    }
    let u = wind_at(joint[twigs[i]].xyz, frame.time);
    let speed = length(u) * frame.crown_wind;
    let q = 0.5 * LEAF_AIR_DENSITY * speed * speed;
    let r = speed / frame.reconfiguration_speed;
    let g = pow(1.0 + r * r, 0.5 * frame.vogel_exponent);
    let onset = frame.flutter_onset * frame.flutter_onset;
    let amp = frame.flutter * speed * speed / (speed * speed + onset);
    twig_wind[2u * i] = vec4<f32>(u, q * g);
    twig_wind[2u * i + 1u] = vec4<f32>(amp, 0.5 * LEAF_AIR_DENSITY * dot(u, u), 0.0, 0.0);
}
