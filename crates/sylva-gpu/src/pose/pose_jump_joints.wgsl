// pose_jump_joints: joints[i] = rest[i] + disp[i], so identity rotations give the rest pose
// exactly. Instance-major disp and joints. CPU twin: sylva_core::pose::fk::pose_jump_joints
// (bindings 0 rest, 1 disp, 2 joints).

@group(0) @binding(0) var<storage, read> rest: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> disp: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> joints: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&joints)) {
        return;
    }
    let n = arrayLength(&rest);
    joints[i] = vec4<f32>(rest[i % n].xyz + disp[i].xyz, 0.0);
}
