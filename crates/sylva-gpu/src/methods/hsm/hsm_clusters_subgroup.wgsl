// hsm_clusters_subgroup (Song §5.2 stage 1, `hsm_cluster_stage.wgsl`): the tree's strides
// from 32 down to the subgroup size in shared memory, the rest by shuffles within a
// subgroup: lane l adds lane l + s's value, as the tree's invocation t adds t + s, so the
// additions and their order are the shared-memory kernel's and the CPU twin's. Every
// subgroup reduces lanes 0 … SUBGROUP_SIZE − 1 of the shared arrays by its own lane index
// (whatever subgroup invocation 0 falls in), and lane 0's result is broadcast to the
// subgroup. Needs the device's subgroup feature (wgpu's naga takes the subgroup builtins
// without WGSL's `enable subgroups`) and a fixed subgroup size.

// The device's subgroup size (its minimum and maximum agree), set when the pipeline is made.
override SUBGROUP_SIZE: u32 = 32u;

@compute @workgroup_size(64)
fn main(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) t: u32,
    @builtin(subgroup_invocation_id) lane: u32,
) {
    let c = wg.x + wg.y * nwg.x;
    if (c >= arrayLength(&info)) {
        return;
    }
    let sp = hsm_last_shift(c);
    hsm_reduce_shared(t, hsm_lane_sums(c, t, sp), SUBGROUP_SIZE / 2u);
    var m = red_m[lane];
    var a0 = red_a0[lane];
    var a1 = red_a1[lane];
    var a2 = red_a2[lane];
    for (var s = SUBGROUP_SIZE / 2u; s > 0u; s >>= 1u) {
        m = m + subgroupShuffleDown(m, s);
        a0 = a0 + subgroupShuffleDown(a0, s);
        a1 = a1 + subgroupShuffleDown(a1, s);
        a2 = a2 + subgroupShuffleDown(a2, s);
    }
    let sums = HsmSums(subgroupBroadcast(m, 0u), subgroupBroadcast(a0, 0u), subgroupBroadcast(a1, 0u), subgroupBroadcast(a2, 0u));
    if (t == 0u) {
        hsm_finish_cluster(c, sp, sums);
    }
}
