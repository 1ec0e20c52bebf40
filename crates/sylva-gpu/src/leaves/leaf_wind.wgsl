// leaf_wind: the wind at each twig's sample joint, one twig per invocation.
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
    twig_wind[i] = vec4<f32>(wind_at(joint[twigs[i]].xyz, frame.time), 0.0);
}
