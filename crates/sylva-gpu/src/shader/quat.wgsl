// Quaternion helpers shared by every kernel. A unit quaternion is vec4<f32>(x, y, z, w),
// the layout of glam::Quat and of the Raw* structs.

// Rotates v by q: v + 2 q.xyz × (q.xyz × v + q.w v) (the same formula as glam's Quat * Vec3).
fn quat_rotate(q: vec4<f32>, v: vec3<f32>) -> vec3<f32> {
    let u = q.xyz;
    let t = 2.0 * cross(u, v);
    return v + q.w * t + cross(u, t);
}

// Hamilton product a * b (apply b, then a).
fn quat_mul(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(
        a.w * b.xyz + b.w * a.xyz + cross(a.xyz, b.xyz),
        a.w * b.w - dot(a.xyz, b.xyz),
    );
}

// Rotation of `angle` radians about the unit `axis` (as glam's Quat::from_axis_angle).
fn quat_axis_angle(axis: vec3<f32>, angle: f32) -> vec4<f32> {
    let h = angle * 0.5;
    return vec4<f32>(axis * sin(h), cos(h));
}

// Inverse of a unit quaternion (its conjugate).
fn quat_conj(q: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(-q.xyz, q.w);
}

// Rotation of |t| radians about t / |t|; exactly the identity at t = 0.
fn quat_from_rotation_vector(t: vec3<f32>) -> vec4<f32> {
    let a = length(t);
    if (a == 0.0) {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    return quat_axis_angle(t / a, a);
}
