// hsm_goals (Song §5.2 stage 3), per particle: its goal (a displacement from rest) and Σw
// from `hsm_particle_goal` (hsm_gather.wgsl). CPU twin: sylva_core::methods::hsm::kernels::hsm_goals.
// Bindings: 0 member offsets, 1 members, 2 cluster state (from hsm_gather.wgsl), 3 goals.

@group(0) @binding(3) var<storage, read_write> goal: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&goal)) {
        return;
    }
    goal[i] = hsm_particle_goal(i);
}
