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

// Spherical linear interpolation along the shorter arc; nlerp when nearly equal.
// CPU twin: sylva_core::mesh::quat_slerp.
fn quat_slerp(a: vec4<f32>, b_in: vec4<f32>, t: f32) -> vec4<f32> {
    var d = dot(a, b_in);
    var b = b_in;
    if (d < 0.0) {
        d = -d;
        b = -b;
    }
    if (d > 0.9995) {
        return normalize(a * (1.0 - t) + b * t);
    }
    let theta = acos(d);
    let s = 1.0 / sin(theta);
    return normalize(a * (sin((1.0 - t) * theta) * s) + b * (sin(t * theta) * s));
}

// Rotation taking unit a onto unit b: normalize(a x b, 1 + a.b); exactly the identity when
// a == b (tested: with fused multiply-adds a x a is a product's rounding error, not zero).
fn shortest_arc(a: vec3<f32>, b: vec3<f32>) -> vec4<f32> {
    let w = 1.0 + dot(a, b);
    if (all(a == b) || all(a == vec3<f32>(0.0)) || all(b == vec3<f32>(0.0)) || w < 1e-6) {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    return normalize(vec4<f32>(cross(a, b), w));
}
