// akagi_forces: own drag on each segment at its current centre, with its aerodynamic damping.
// Two entries per segment: 2i the force (w: the damping gamma = rho Cd A |u| g(|u|), N s/m),
// 2i + 1 the centre. CPU twin: sylva_core::methods::akagi::kernels::akagi_forces (bindings
// 0 fields, 1 waves, 2 segments, 3 akagi segments, 4 joints, 5 acc, 6 step, 7 forces).

@group(0) @binding(2) var<storage, read> segments: array<Segment>;
@group(0) @binding(3) var<storage, read> akagi: array<AkagiSegment>;
@group(0) @binding(4) var<storage, read> joints: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> acc: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> step: AkagiStep;
@group(0) @binding(7) var<storage, read_write> forces: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&segments)) {
        return;
    }
    let s = segments[i];
    let axis = quat_rotate(acc[i], quat_rotate(s.orientation, vec3<f32>(0.0, 1.0, 0.0)));
    let centre = joints[i].xyz + axis * (0.5 * s.length);
    let w = wind_at(centre, step.time);
    let u = length(w);
    var f = vec4<f32>(0.0);
    if (u >= 1e-6) {
        let sin_phi = length(cross(w / u, axis));
        let cd_area = step.drag * (akagi[i].bark_area * sin_phi + akagi[i].leaf_area);
        // Drag with reconfiguration, (1 + (u/U_r)^2)^(B/2) on u^2 (physics::DragModel).
        let r = u / step.reconfiguration_speed;
        let g = pow(1.0 + r * r, 0.5 * step.vogel_exponent);
        f = vec4<f32>(w * (0.5 * AIR_DENSITY * cd_area * u * g), AIR_DENSITY * cd_area * u * g);
    }
    forces[2u * i] = f;
    forces[2u * i + 1u] = vec4<f32>(centre, 0.0);
}
