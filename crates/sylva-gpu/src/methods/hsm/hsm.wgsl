// Shared by the hierarchical shape matching kernels: Song's linearised tree (§5.1) and the
// rotation extraction. Twins: sylva_core::methods::hsm::Raw* and
// sylva_core::methods::hsm::kernels::extract_rotation.

const HSM_SEGMENT: u32 = 0u;
const HSM_LEAF: u32 = 1u;
const HSM_STEM: u32 = 2u;

struct HsmClusterInfo {
    kind: u32,
    source: u32,
    slot_offset: u32,
    slot_count: u32,
}

struct HsmCluster {
    rest_cm: vec4<f32>,
    parent: u32,
    child_offset: u32,
    child_count: u32,
    mass: f32,
    aqq_inv: array<vec4<f32>, 3>,
}

struct HsmSlot {
    q: vec3<f32>,
    particle: u32,
}

// CPU twin: sylva_core::methods::hsm::RawHsmLeaf.
struct HsmLeaf {
    tip: vec3<f32>,
    segment: u32,
    edge: vec3<f32>,
    slot_offset: u32,
    attach: vec3<f32>,
    cluster: u32,
    ring: u32,
    blade: u32,
    strength: f32,
    _pad: u32,
}

struct HsmMember {
    q: vec3<f32>,
    cluster: u32,
}

struct HsmClusterState {
    cm: vec4<f32>,
    rotation: vec4<f32>,
    transform: array<vec4<f32>, 3>,
    wind: vec4<f32>,
}

struct HsmStep {
    gravity: vec4<f32>,
    dt: f32,
    time: f32,
    damping: f32,
    beta: f32,
    polar_iterations: u32,
    clusters: u32,
    particles: u32,
    max_children: u32,
    hold: f32,
    reconfiguration_speed: f32,
    vogel_exponent: f32,
    air: f32,
    sample_wind: u32,
    leaf_turbulence: f32,
    flutter_onset: f32,
    leaf_zeta: f32,
}

// Vogel's reconfiguration of a cluster's drag in the wind `u` at its centre, (1 + r²)^(B/2)
// with r = |u| / U_r; 1 in still air. CPU twin: kernels::reconfiguration.
fn hsm_reconfiguration(u: vec3<f32>, step: HsmStep) -> f32 {
    let r = length(u) / step.reconfiguration_speed;
    if (r > 0.0) {
        return pow(1.0 + r * r, 0.5 * step.vogel_exponent);
    }
    return 1.0;
}

// Rotation matrix of a unit quaternion (as glam's Mat3::from_quat).
fn quat_to_mat3(q: vec4<f32>) -> mat3x3<f32> {
    let x2 = q.x + q.x;
    let y2 = q.y + q.y;
    let z2 = q.z + q.z;
    let xx = q.x * x2;
    let xy = q.x * y2;
    let xz = q.x * z2;
    let yy = q.y * y2;
    let yz = q.y * z2;
    let zz = q.z * z2;
    let wx = q.w * x2;
    let wy = q.w * y2;
    let wz = q.w * z2;
    return mat3x3<f32>(
        vec3<f32>(1.0 - (yy + zz), xy + wz, xz - wy),
        vec3<f32>(xy - wz, 1.0 - (xx + zz), yz + wx),
        vec3<f32>(xz + wy, yz - wx, 1.0 - (xx + yy)),
    );
}

// The rotation of `a` (Müller, Bender, Chentanez & Macklin 2016) with a Newton step,
// warm-started from `q0`; never NaN, and continuous in `a` and `q0`: every iteration runs
// and the steps are blended, not switched (see the CPU twin `extract_rotation`).
fn extract_rotation(a: mat3x3<f32>, q0: vec4<f32>, iterations: u32) -> vec4<f32> {
    var q = q0;
    let eps = 1e-6 * (length(a[0]) + length(a[1]) + length(a[2])) + 1e-30;
    for (var k = 0u; k < iterations; k++) {
        let r = quat_to_mat3(q);
        // rot(ω): the unit quaternion along (ω/2, 1), no sin or cos (see the CPU twin).
        let half = rotation_step(r, a, eps) * 0.5;
        q = normalize(quat_mul(vec4<f32>(half, 1.0), q));
    }
    return q;
}

// One step: Müller's μ = g / (|tr B| + ε) blended toward Newton's H⁻¹ g, H = tr(B) I − sym(B),
// B = A Rᵀ, g = Σ rᵢ × aᵢ, by s = s_near · s_pd (near the optimum, H safely positive definite).
// Twin: rotation_step in sylva_core::methods::hsm::kernels.
fn rotation_step(r: mat3x3<f32>, a: mat3x3<f32>, eps: f32) -> vec3<f32> {
    let g = cross(r[0], a[0]) + cross(r[1], a[1]) + cross(r[2], a[2]);
    let tr = dot(r[0], a[0]) + dot(r[1], a[1]) + dot(r[2], a[2]);
    let muller = g / (abs(tr) + eps);
    let near = NEWTON_NEAR * NEWTON_NEAR;
    let s_near = min((4.0 * near - dot(muller, muller)) / (3.0 * near), 1.0);
    if (!(tr > 0.0 && s_near > 0.0)) {
        return muller;
    }
    let b0 = a[0] * r[0].x + a[1] * r[1].x + a[2] * r[2].x;
    let b1 = a[0] * r[0].y + a[1] * r[1].y + a[2] * r[2].y;
    let b2 = a[0] * r[0].z + a[1] * r[1].z + a[2] * r[2].z;
    let h00 = tr - b0.x;
    let h11 = tr - b1.y;
    let h22 = tr - b2.z;
    let h01 = -0.5 * (b1.x + b0.y);
    let h02 = -0.5 * (b2.x + b0.z);
    let h12 = -0.5 * (b2.y + b1.z);
    let c00 = h11 * h22 - h12 * h12;
    let c01 = h02 * h12 - h01 * h22;
    let c02 = h01 * h12 - h02 * h11;
    let c11 = h00 * h22 - h02 * h02;
    let c12 = h01 * h02 - h00 * h12;
    let c22 = h00 * h11 - h01 * h01;
    let det = h00 * c00 + h01 * c01 + h02 * c02;
    let thin = 1e-4 * (tr * tr * tr);
    if (!(h00 > 0.0 && c22 > 0.0 && det > thin)) {
        return muller;
    }
    var s_pd = 1.0;
    if (thin > 0.0) {
        s_pd = min(det / thin - 1.0, 1.0);
    }
    let newton = vec3<f32>(
        c00 * g.x + c01 * g.y + c02 * g.z,
        c01 * g.x + c11 * g.y + c12 * g.z,
        c02 * g.x + c12 * g.y + c22 * g.z,
    ) / det;
    return muller + (newton - muller) * (s_near * s_pd);
}

// Length of Müller's step below which rotation_step takes Newton's whole, rad (blended up
// to twice this; NEWTON_NEAR on the CPU).
const NEWTON_NEAR: f32 = 0.05;

// Largest weight a cluster brings to the mean of its particles' goals: k h², past the hold only up
// to the path's k̂ h² (aqq_inv[0].w); a particle's step min(Σ w, hold) is clamped, the weights
// are not (MAX_WEIGHT on the CPU).
const MAX_WEIGHT: f32 = 1e6;

// A cluster's goal for rest offset q, as a displacement from rest: (T q − q) + (c − c⁰).
// Twin: goal_displacement in sylva_core::methods::hsm::kernels.
fn hsm_goal_displacement(st: HsmClusterState, q: vec3<f32>) -> vec3<f32> {
    let tq = st.transform[0].xyz * q.x + st.transform[1].xyz * q.y + st.transform[2].xyz * q.z;
    let shift = vec3<f32>(st.transform[0].w, st.transform[1].w, st.transform[2].w);
    return (tq - q) + shift;
}

// A free particle's new velocity: pull toward goal g (w = Σw, ᾱ = min(Σw, hold)) from u (both displacements
// from rest), gravity, semi-implicit drag toward `wind` with drag factor kd, damping.
// Twin: particle_velocity.
fn hsm_velocity(v: vec3<f32>, g: vec4<f32>, u: vec3<f32>, wind: vec3<f32>, kd: f32, step: HsmStep) -> vec3<f32> {
    let h = step.dt;
    var vel = v + (g.xyz - u) * (min(g.w, step.hold) * (1.0 / h)) + step.gravity.xyz * ((1.0 - step.gravity.w) * h);
    let rel = wind - vel * step.air;
    let s = h * kd * length(rel);
    vel += rel * (s / (1.0 + step.air * s));
    return vel * step.damping;
}
