// hsm_pose: the pose seam's accumulated rotation of each segment, its cluster's R (the
// identity where a truncated layout has no cluster). CPU twin: sylva_core::methods::hsm::kernels::hsm_pose.
// Bindings: 0 segment clusters, 1 cluster state, 2 acc.

@group(0) @binding(0) var<storage, read> segment_cluster: array<u32>;
@group(0) @binding(1) var<storage, read> state: array<HsmClusterState>;
@group(0) @binding(2) var<storage, read_write> acc: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&acc)) {
        return;
    }
    let c = segment_cluster[i];
    if (c == NONE) {
        acc[i] = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    } else {
        acc[i] = state[c].rotation;
    }
}
