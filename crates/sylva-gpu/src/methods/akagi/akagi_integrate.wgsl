// akagi_integrate: damped angular springs advanced by the exact solution of
// J theta'' + (c + Gamma) theta' + k theta = tau over the step, with the moment, the stiffness
// (stiffened at the bend the moment holds) and the damping held. CPU twin:
// sylva_core::methods::akagi::kernels::akagi_integrate (bindings 0 segments, 1 akagi segments,
// 2 propagated sums, 3 acc, 4 step, 5 theta, 6 omega, 7 delta).

@group(0) @binding(0) var<storage, read> segments: array<Segment>;
@group(0) @binding(1) var<storage, read> akagi: array<AkagiSegment>;
@group(0) @binding(2) var<storage, read> sub: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> acc: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> step: AkagiStep;
@group(0) @binding(5) var<storage, read_write> theta: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> omega: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> delta: array<vec4<f32>>;

// 1 + (theta/theta_s)^2 at the equilibrium of theta + theta^3/theta_s^2 = b (kernels::stiffening).
fn stiffening(b: f32, theta_s: f32) -> f32 {
    let u = 2.0 / sqrt(3.0) * sinh(asinh(3.0 * sqrt(3.0) * b / (2.0 * theta_s)) / 3.0);
    return 1.0 + u * u;
}

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
    let m = sub[3u * i + 1u].xyz;
    let gamma = sub[3u * i + 1u].w;
    let tau_world = m - axis * dot(axis, m);
    let own = quat_from_rotation_vector(theta[i].xyz);
    let parent = quat_mul(d, quat_conj(own));
    let tau = quat_rotate(quat_conj(parent), tau_world);
    let t0 = theta[i].xyz;
    let w0 = omega[i].xyz;
    let stiffen = stiffening(length(tau) / a.stiffness, step.stiffening_angle);
    let k = a.stiffness * stiffen;
    let c = a.damping * sqrt(stiffen) + gamma * a.air_scale;
    // The exact step of x'' + 2 a x' + w2 (x - x_eq) = 0 (physics::oscillator::damped_step).
    let w2 = k / a.inertia;
    let damp = c / (2.0 * a.inertia);
    let next = damped_apply(t0, w0, tau / k, w2, damp, damped_coefficients(w2, damp, step.dt));
    var t1 = next.x;
    var w1 = next.v;
    // The hard stop at three stiffening angles.
    let bend = length(t1);
    let stop = 3.0 * step.stiffening_angle;
    if (bend > stop) {
        let n = t1 / bend;
        t1 = n * stop;
        w1 -= n * max(dot(w1, n), 0.0);
    }
    theta[i] = vec4<f32>(t1, 0.0);
    omega[i] = vec4<f32>(w1, 0.0);
    delta[i] = quat_from_rotation_vector(t1);
}
