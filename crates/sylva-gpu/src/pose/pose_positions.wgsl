// pose_positions: joint[i] = rest[i] + sum over the chain of (acc[parent(a)] o_a - o_a),
// o_a = rest[a] - rest[parent(a)]: displacements, so identity rotations give the rest pose
// exactly. Instances: acc and joints instance-major, as in pose_accumulate. CPU twin: sylva_core::pose::fk::pose_positions (bindings 0 parents, 1 rest,
// 2 acc, 3 joints).

@group(0) @binding(0) var<storage, read> parents: array<u32>;
@group(0) @binding(1) var<storage, read> rest: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> acc: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> joints: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&joints)) {
        return;
    }
    let n = arrayLength(&parents);
    let base = (i / n) * n;
    let l = i - base;
    var disp = vec3<f32>(0.0);
    var a = l;
    var p = parents[l];
    for (var step = 0u; step <= l && p != NONE; step++) {
        let off = rest[a].xyz - rest[p].xyz;
        disp += quat_rotate(acc[base + p], off) - off;
        a = p;
        p = parents[p];
    }
    joints[i] = vec4<f32>(rest[l].xyz + disp, 0.0);
}
