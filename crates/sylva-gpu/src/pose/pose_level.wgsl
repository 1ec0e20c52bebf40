// pose_level: one depth of forward kinematics, root first (the alternative to the ancestor
// walks of pose_accumulate and pose_positions): for every segment i of this depth,
// acc[i] = acc[parent] * delta[i] and disp[i] = disp[parent] + (acc[parent] o_i - o_i),
// o_i = rest[i] - rest[parent]; joints[i] = rest[i] + disp[i], so identity rotations give
// the rest pose exactly. CPU twin: sylva_core::pose::fk::pose_level (bindings 0 bucket,
// 1 parents, 2 rest, 3 delta, 4 acc, 5 disp, 6 joints). Buckets are padded with 0xffffffff
// to a multiple of four entries.

@group(0) @binding(0) var<storage, read> bucket: array<u32>;
@group(0) @binding(1) var<storage, read> parents: array<u32>;
@group(0) @binding(2) var<storage, read> rest: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> delta: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> acc: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> disp: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> joints: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = gid.x + gid.y * nwg.x * 64u;
    if (k >= arrayLength(&bucket)) {
        return;
    }
    let i = bucket[k];
    if (i == 0xffffffffu) {
        return;
    }
    let p = parents[i];
    var d = vec3<f32>(0.0);
    if (p == NONE) {
        acc[i] = delta[i];
    } else {
        acc[i] = quat_mul(acc[p], delta[i]);
        let off = rest[i].xyz - rest[p].xyz;
        d = disp[p].xyz + (quat_rotate(acc[p], off) - off);
    }
    disp[i] = vec4<f32>(d, 0.0);
    joints[i] = vec4<f32>(rest[i].xyz + d, 0.0);
}
