// hsm_particles: stages 3 and 4 in one pass per particle (its goal is read by no other
// particle, so it skips the goal buffer). The same operations as hsm_goals then
// hsm_integrate. CPU twin: sylva_core::methods::hsm::kernels::hsm_particles. Bindings: 0 member offsets,
// 1 members, 2 cluster state (from hsm_gather.wgsl), 3 owners, 4 step, 5 displacements,
// 6 velocities (w = drag factor, negative when fixed).

@group(0) @binding(3) var<storage, read> owner: array<u32>;
@group(0) @binding(4) var<storage, read> step: HsmStep;
@group(0) @binding(5) var<storage, read_write> displacement: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> velocity: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&velocity)) {
        return;
    }
    hsm_advance(i, hsm_particle_goal(i));
}
