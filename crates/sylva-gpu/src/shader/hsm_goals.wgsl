// hsm_goals (Song §5.2 stage 3), per particle: the α-weighted mean of the goals of the
// clusters sharing it, as displacements from rest, and ᾱ = min(1, Σα). A gather over the
// particle's clusters, in cluster order. CPU twin: sylva_core::cpu::hsm::hsm_goals.
// Bindings: 0 member offsets, 1 members, 2 rest positions, 3 cluster state, 4 goals.

@group(0) @binding(0) var<storage, read> member_offset: array<u32>;
@group(0) @binding(1) var<storage, read> member: array<HsmMember>;
@group(0) @binding(2) var<storage, read> rest: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> state: array<HsmClusterState>;
@group(0) @binding(4) var<storage, read_write> goal: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&rest)) {
        return;
    }
    var sum = vec3<f32>(0.0);
    var wsum = 0.0;
    for (var k = member_offset[i]; k < member_offset[i + 1u]; k++) {
        let m = member[k];
        let st = state[m.cluster];
        sum += hsm_goal_displacement(st, m.q) * st.cm.w;
        wsum += st.cm.w;
    }
    let x0 = rest[i].xyz;
    if (wsum > 0.0) {
        goal[i] = vec4<f32>(x0 + sum / wsum, min(wsum, 1.0));
    } else {
        goal[i] = vec4<f32>(x0, 0.0);
    }
}
