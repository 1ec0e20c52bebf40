// Stage 4's particle update, shared by hsm_integrate and hsm_particles: shape-matching pull
// toward `goal`, gravity (balanced when prestressed), semi-implicit drag toward the owner
// cluster's wind (the drag factor times its reconfiguration, the wind's w), damping, then the displacement. The velocity's w is the drag factor;
// fixed particles (w < 0) stay. Reads the kernel's `owner`, `state`, `step`; writes
// `displacement`, `velocity`. CPU twin: sylva_core::methods::hsm::kernels (the integration loop shared
// by both passes).

fn hsm_advance(i: u32, goal: vec4<f32>) {
    let v0 = velocity[i];
    let kd = v0.w;
    if (kd < 0.0) {
        return;
    }
    let x = displacement[i];
    let wind = state[owner[i]].wind;
    let vel = hsm_velocity(v0.xyz, goal, x.xyz, wind.xyz, kd * wind.w, step);
    displacement[i] = vec4<f32>(x.xyz + vel * step.dt, x.w);
    velocity[i] = vec4<f32>(vel, kd);
}
