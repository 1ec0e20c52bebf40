// akagi_integrate: damped angular springs, implicit in stiffness and damping. CPU twin:
// sylva_core::methods::akagi::kernels::akagi_integrate (bindings 0 segments, 1 akagi segments,
// 2 subtree forces, 3 acc, 4 step, 5 theta, 6 omega, 7 delta).

@group(0) @binding(0) var<storage, read> segments: array<Segment>;
@group(0) @binding(1) var<storage, read> akagi: array<AkagiSegment>;
@group(0) @binding(2) var<storage, read> f_sub: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> acc: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> step: AkagiStep;
@group(0) @binding(5) var<storage, read_write> theta: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> omega: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> delta: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&segments)) {
        return;
    }
    let s = segments[i];
    let a = akagi[i];
    let d = acc[i];
    let axis = quat_rotate(d, quat_rotate(s.orientation, vec3<f32>(0.0, 1.0, 0.0)));
    let tau_world = cross(axis, f_sub[i].xyz) * s.length;
    let own = quat_from_rotation_vector(theta[i].xyz);
    let parent = quat_mul(d, quat_conj(own));
    let tau = quat_rotate(quat_conj(parent), tau_world);
    let t0 = theta[i].xyz;
    let w0 = omega[i].xyz;
    let dt = step.dt;
    let r = length(t0) / step.stiffening_angle;
    let k = a.stiffness * (1.0 + r * r);
    let denom = 1.0 + dt * a.damping / a.inertia + dt * dt * k / a.inertia;
    let w1 = (w0 + (tau - t0 * k) * (dt / a.inertia)) / denom;
    let t1 = t0 + w1 * dt;
    theta[i] = vec4<f32>(t1, 0.0);
    omega[i] = vec4<f32>(w1, 0.0);
    delta[i] = quat_from_rotation_vector(t1);
}
