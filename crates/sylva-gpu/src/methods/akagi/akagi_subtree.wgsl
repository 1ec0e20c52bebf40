// akagi_subtree: one depth of the propagation toward the root, deepest first. Per joint i over
// everything beyond it, at 3i, 3i + 1, 3i + 2 of `sub`: (F = sum f_j, S0 = sum gamma_j),
// (M = sum (x_j - p_i) x f_j, Gamma = sum gamma_j |x_j - p_i|^2), (S1 = sum gamma_j (x_j - p_i)).
// CPU twin: sylva_core::methods::akagi::kernels::akagi_subtree (bindings 0 bucket, 1 child
// offsets, 2 child counts, 3 child indices, 4 own forces, 5 joints, 6 sums). Buckets are
// padded with 0xffffffff to a multiple of four entries (storage bindings are at least 16
// bytes).

@group(0) @binding(0) var<storage, read> bucket: array<u32>;
@group(0) @binding(1) var<storage, read> child_offset: array<u32>;
@group(0) @binding(2) var<storage, read> child_count: array<u32>;
@group(0) @binding(3) var<storage, read> child_index: array<u32>;
@group(0) @binding(4) var<storage, read> f_own: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> joints: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> sub: array<vec4<f32>>;

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
    let p = joints[i].xyz;
    var f = f_own[2u * i].xyz;
    var s0 = f_own[2u * i].w;
    let r = f_own[2u * i + 1u].xyz - p;
    var m = cross(r, f);
    var s1 = r * s0;
    var gamma = s0 * dot(r, r);
    let o = child_offset[i];
    for (var c = 0u; c < child_count[i]; c++) {
        let j = child_index[o + c];
        let d = joints[j].xyz - p;
        let fc = sub[3u * j].xyz;
        let s0c = sub[3u * j].w;
        let s1c = sub[3u * j + 2u].xyz;
        f += fc;
        m += sub[3u * j + 1u].xyz + cross(d, fc);
        gamma += sub[3u * j + 1u].w + 2.0 * dot(d, s1c) + dot(d, d) * s0c;
        s1 += s1c + d * s0c;
        s0 += s0c;
    }
    sub[3u * i] = vec4<f32>(f, s0);
    sub[3u * i + 1u] = vec4<f32>(m, gamma);
    sub[3u * i + 2u] = vec4<f32>(s1, 0.0);
}
