// hsm_clusters (Song §5.2 stage 1, `hsm_cluster_stage.wgsl`): the 64 lanes added by a
// tree in shared memory.

@compute @workgroup_size(64)
fn main(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) t: u32,
) {
    let c = wg.x + wg.y * nwg.x;
    if (c >= arrayLength(&info)) {
        return;
    }
    let sp = hsm_last_shift(c);
    hsm_reduce_shared(t, hsm_lane_sums(c, t, sp), 0u);
    if (t == 0u) {
        hsm_finish_cluster(c, sp, HsmSums(red_m[0], red_a0[0], red_a1[0], red_a2[0]));
    }
}
