// Shared by the hierarchical shape matching kernels: Song's linearised tree (§5.1) and the
// rotation extraction. Twins: sylva_core::animate::hsm::Raw* and
// sylva_core::cpu::hsm::extract_rotation.

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

// The rotation of `a` (Müller, Bender, Chentanez & Macklin 2016), warm-started from `q0`;
// never NaN (see the CPU twin).
fn extract_rotation(a: mat3x3<f32>, q0: vec4<f32>, iterations: u32) -> vec4<f32> {
    var q = q0;
    let eps = 1e-6 * (length(a[0]) + length(a[1]) + length(a[2])) + 1e-30;
    for (var k = 0u; k < iterations; k++) {
        let r = quat_to_mat3(q);
        let num = cross(r[0], a[0]) + cross(r[1], a[1]) + cross(r[2], a[2]);
        let den = abs(dot(r[0], a[0]) + dot(r[1], a[1]) + dot(r[2], a[2])) + eps;
        let omega = num / den;
        let w = length(omega);
        if (w < 2e-6) {
            break;
        }
        q = normalize(quat_mul(quat_axis_angle(omega / w, w), q));
    }
    return q;
}

// A cluster's goal for rest offset q, as a displacement from rest: (T q − q) + (c − c⁰).
// Twin: goal_displacement in sylva_core::cpu::hsm.
fn hsm_goal_displacement(st: HsmClusterState, q: vec3<f32>) -> vec3<f32> {
    let tq = st.transform[0].xyz * q.x + st.transform[1].xyz * q.y + st.transform[2].xyz * q.z;
    let shift = vec3<f32>(st.transform[0].w, st.transform[1].w, st.transform[2].w);
    return (tq - q) + shift;
}

// A free particle's new velocity: pull toward goal g (w = ᾱ) from u (both displacements
// from rest), gravity, semi-implicit drag toward `wind` with drag factor kd, damping.
// Twin: particle_velocity.
fn hsm_velocity(v: vec3<f32>, g: vec4<f32>, u: vec3<f32>, wind: vec3<f32>, kd: f32, step: HsmStep) -> vec3<f32> {
    let h = step.dt;
    var vel = v + (g.xyz - u) * (g.w * (1.0 / h)) + step.gravity.xyz * ((1.0 - step.gravity.w) * h);
    let rel = wind - vel;
    let s = h * kd * length(rel);
    vel += rel * (s / (1.0 + s));
    return vel * step.damping;
}
