// pose_jump_rotations: one round of pointer jumping over rotations, out[i] = in[anc[i]] * in[i]
// (in[i] where anc[i] is NONE). Started from delta, after every round of
// sylva_core::pose::fk::jump_ancestors out = acc. anc holds one instance's segments; in and
// out are instance-major. CPU twin: sylva_core::pose::fk::pose_jump_rotations (bindings 0 anc,
// 1 in, 2 out).

@group(0) @binding(0) var<storage, read> anc: array<u32>;
@group(0) @binding(1) var<storage, read> input: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&out)) {
        return;
    }
    let n = arrayLength(&anc);
    let base = (i / n) * n;
    let a = anc[i - base];
    if (a == NONE) {
        out[i] = input[i];
    } else {
        out[i] = quat_mul(input[base + a], input[i]);
    }
}
