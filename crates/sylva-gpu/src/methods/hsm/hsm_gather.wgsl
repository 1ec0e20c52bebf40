// Stage 3's gather, shared by hsm_goals and hsm_particles: a particle's goal as a
// displacement from rest (xyz) and Σw (w; ᾱ = min(Σw, hold) in hsm_velocity), the mean of its clusters' goals
// weighted by their w = k h² (not clamped at 1, see MAX_WEIGHT), in cluster order. Binds
// group 0, bindings 0 member offsets, 1 members, 2 cluster state. Twin: particle_goal in
// sylva_core::methods::hsm::kernels.

@group(0) @binding(0) var<storage, read> member_offset: array<u32>;
@group(0) @binding(1) var<storage, read> member: array<HsmMember>;
@group(0) @binding(2) var<storage, read> state: array<HsmClusterState>;

fn hsm_particle_goal(i: u32) -> vec4<f32> {
    var sum = vec3<f32>(0.0);
    var wsum = 0.0;
    for (var k = member_offset[i]; k < member_offset[i + 1u]; k++) {
        let m = member[k];
        let st = state[m.cluster];
        sum += hsm_goal_displacement(st, m.q) * st.cm.w;
        wsum += st.cm.w;
    }
    if (wsum > 0.0) {
        return vec4<f32>(sum / wsum, wsum);
    }
    return vec4<f32>(0.0);
}
