// hsm_leaf_pose: each leaf's rotation in its segment's rest frame, its leaf cluster's R turned
// back by its segment's (the identity where it has no cluster or has not turned from it).
// CPU twin: sylva_core::methods::hsm::kernels::hsm_leaf_pose.
// Bindings: 0 leaf segments, 1 leaf clusters, 2 cluster state, 3 acc, 4 leaf rotations.

@group(0) @binding(0) var<storage, read> leaf_segment: array<u32>;
@group(0) @binding(1) var<storage, read> leaf_cluster: array<u32>;
@group(0) @binding(2) var<storage, read> state: array<HsmClusterState>;
@group(0) @binding(3) var<storage, read> acc: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> leaf_rotation: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let l = gid.x + gid.y * nwg.x * 64u;
    if (l >= arrayLength(&leaf_rotation)) {
        return;
    }
    let c = leaf_cluster[l];
    if (c == NONE) {
        leaf_rotation[l] = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        return;
    }
    let r = state[c].rotation;
    let d = acc[leaf_segment[l]];
    if (all(r == d)) {
        leaf_rotation[l] = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    } else {
        leaf_rotation[l] = quat_mul(quat_conj(d), r);
    }
}
