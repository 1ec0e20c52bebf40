// hsm_integrate (Song §5.2 stage 4), per particle (`hsm_advance`): shape-matching pull,
// gravity (balanced when prestressed), semi-implicit drag toward its owner cluster's wind,
// damping, then the displacement. CPU twin: sylva_core::methods::hsm::kernels::hsm_integrate.
// Bindings: 0 owners, 1 cluster state, 2 goals, 3 step, 4 displacements, 5 velocities
// (w = drag factor, negative when fixed).

@group(0) @binding(0) var<storage, read> owner: array<u32>;
@group(0) @binding(1) var<storage, read> state: array<HsmClusterState>;
@group(0) @binding(2) var<storage, read> goal: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> step: HsmStep;
@group(0) @binding(4) var<storage, read_write> displacement: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> velocity: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&velocity)) {
        return;
    }
    hsm_advance(i, goal[i]);
}
