// leaf_flutter: every leaf's rotation about its attachment, one leaf per invocation.
// CPU twin: sylva_core::leaves::kernels::leaf_flutter (same bindings).

@group(0) @binding(0) var<storage, read> frame: LeafFrame;
@group(0) @binding(1) var<storage, read> motion: array<LeafMotion>;
@group(0) @binding(2) var<storage, read> twig_wind: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> acc: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> leaf_rotation_out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let l = gid.x + gid.y * nwg.x * 64u;
    if (l >= frame.leaves) {
        return;
    }
    let m = motion[l];
    leaf_rotation_out[l] = leaf_rotation(frame, m, twig_wind[2u * m.twig], twig_wind[2u * m.twig + 1u], acc[m.segment], frame.time);
}
