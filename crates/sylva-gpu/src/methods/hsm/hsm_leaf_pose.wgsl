// hsm_leaf_pose: each leaf's rotation in its segment's rest frame from its blade's particles.
// In the frame of the leaf's anchor ring (its cluster's rotation R, centre moved by the ring
// particles' mean displacement): the swing taking the blade's rest direction (attachment ->
// tip) onto its direction now, then the twist about it taking the edge point's rest offset
// onto its offset now (both across the blade); the leaf's rotation is D_s^-1 R twist swing.
// The identity where nothing has moved, for a leaf without a cluster and at strength 0;
// another strength scales the turn's angle about its axis.
// CPU twin: sylva_core::methods::hsm::kernels::hsm_leaf_pose.
// Bindings: 0 leaves, 1 slots, 2 displacements (w = mass), 3 cluster state, 4 acc,
// 5 leaf rotations.

@group(0) @binding(0) var<storage, read> leaves: array<HsmLeaf>;
@group(0) @binding(1) var<storage, read> slots: array<HsmSlot>;
@group(0) @binding(2) var<storage, read> displacement: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> state: array<HsmClusterState>;
@group(0) @binding(4) var<storage, read> acc: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> leaf_rotation: array<vec4<f32>>;

// v / |v|, or zero for a zero vector.
fn unit(v: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    if (l > 0.0) {
        return v / l;
    }
    return vec3<f32>(0.0);
}

fn slot_u(lf: HsmLeaf, j: u32) -> vec3<f32> {
    return displacement[slots[lf.slot_offset + j].particle].xyz;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let l = gid.x + gid.y * nwg.x * 64u;
    if (l >= arrayLength(&leaf_rotation)) {
        return;
    }
    let rest = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    let lf = leaves[l];
    if (lf.ring == 0u || lf.blade == 0u || lf.strength == 0.0) {
        leaf_rotation[l] = rest;
        return;
    }
    let d = acc[lf.segment];
    let r = state[lf.cluster].rotation;
    var moved = any(d != rest) || any(r != rest);
    var mean = vec3<f32>(0.0);
    for (var j = 0u; j < lf.ring; j++) {
        let x = slot_u(lf, j);
        moved = moved || any(x != vec3<f32>(0.0));
        mean += x;
    }
    mean *= 1.0 / f32(lf.ring);
    let tip = slot_u(lf, lf.ring);
    var edge = vec3<f32>(0.0);
    if (lf.blade > 1u) {
        edge = slot_u(lf, lf.ring + 1u);
    }
    if (!(moved || any(tip != vec3<f32>(0.0)) || any(edge != vec3<f32>(0.0)))) {
        leaf_rotation[l] = rest;
        return;
    }
    let back = quat_conj(r);
    let a = quat_rotate(back, lf.attach + lf.tip + tip - mean) - lf.attach;
    let swing = shortest_arc(unit(lf.tip), unit(a));
    var turn = swing;
    if (lf.blade > 1u) {
        let n = unit(a);
        let e0 = quat_rotate(swing, lf.edge);
        let e = quat_rotate(back, lf.attach + lf.edge + edge - mean) - lf.attach;
        turn = quat_mul(shortest_arc(unit(e0 - n * dot(n, e0)), unit(e - n * dot(n, e))), swing);
    }
    let q = normalize(quat_mul(quat_conj(d), quat_mul(r, turn)));
    if (lf.strength == 1.0) {
        leaf_rotation[l] = q;
        return;
    }
    // The turn's angle scaled about its axis (atan2: well conditioned at small angles).
    let sin_half = length(q.xyz);
    if (sin_half == 0.0) {
        leaf_rotation[l] = rest;
        return;
    }
    let half = atan2(sin_half, q.w) * lf.strength;
    leaf_rotation[l] = vec4<f32>(q.xyz * (sin(half) / sin_half), cos(half));
}
