// pose_jump_terms: the displacement each segment adds to its subtree's joints,
// out[i] = acc[parent] o_i - o_i with o_i = rest[i] - rest[parent] (zero at a root).
// Instance-major acc and out. CPU twin: sylva_core::pose::fk::pose_jump_terms (bindings
// 0 parents, 1 rest, 2 acc, 3 out).

@group(0) @binding(0) var<storage, read> parents: array<u32>;
@group(0) @binding(1) var<storage, read> rest: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> acc: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&out)) {
        return;
    }
    let n = arrayLength(&parents);
    let base = (i / n) * n;
    let l = i - base;
    let p = parents[l];
    if (p == NONE) {
        out[i] = vec4<f32>(0.0);
    } else {
        let off = rest[l].xyz - rest[p].xyz;
        out[i] = vec4<f32>(quat_rotate(acc[base + p], off) - off, 0.0);
    }
}
