// pose_accumulate: acc[i] = delta[root] * ... * delta[parent] * delta[i], by walking the
// ancestor chain (parents have smaller indices, so the walk takes at most i + 1 steps).
// Instances: delta and acc hold instance-major copies (instance × segments + segment) of
// one tree's hierarchy. CPU twin: sylva_core::pose::fk::pose_accumulate (bindings
// 0 parents, 1 delta, 2 acc).

@group(0) @binding(0) var<storage, read> parents: array<u32>;
@group(0) @binding(1) var<storage, read> delta: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> acc: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&delta)) {
        return;
    }
    let n = arrayLength(&parents);
    let base = (i / n) * n;
    let l = i - base;
    var d = delta[i];
    var a = parents[l];
    for (var step = 0u; step <= l && a != NONE; step++) {
        d = quat_mul(delta[base + a], d);
        a = parents[a];
    }
    acc[i] = d;
}
