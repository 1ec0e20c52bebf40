// akagi_subtree: one depth of the force propagation, deepest first:
// f_sub[i] = f_own[i] + sum of f_sub over i's children. CPU twin:
// sylva_core::methods::akagi::kernels::akagi_subtree (bindings 0 bucket, 1 child offsets, 2 child counts,
// 3 child indices, 4 own forces, 5 subtree forces). Buckets are padded with 0xffffffff to
// a multiple of four entries (storage bindings are at least 16 bytes).

@group(0) @binding(0) var<storage, read> bucket: array<u32>;
@group(0) @binding(1) var<storage, read> child_offset: array<u32>;
@group(0) @binding(2) var<storage, read> child_count: array<u32>;
@group(0) @binding(3) var<storage, read> child_index: array<u32>;
@group(0) @binding(4) var<storage, read> f_own: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> f_sub: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = gid.x + gid.y * nwg.x * 64u;
    if (k >= arrayLength(&bucket)) {
        return;
    }
    let i = bucket[k];
    if (i == 0xffffffffu) {
        return; // padding of a short bucket
    }
    var f = f_own[i].xyz;
    let o = child_offset[i];
    for (var c = 0u; c < child_count[i]; c++) {
        f += f_sub[child_index[o + c]].xyz;
    }
    f_sub[i] = vec4<f32>(f, 0.0);
}
