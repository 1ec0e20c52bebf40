// The machine probes of `sylva bench` (`harness.rs`): `copy` moves a buffer through the
// shader cores (read + write bandwidth); `touch` is one workgroup's dependent update, the
// floor that every dispatch of a step pays.

@group(0) @binding(0) var<storage, read> src: array<vec4<u32>>;
@group(0) @binding(1) var<storage, read_write> dst: array<vec4<u32>>;

@compute @workgroup_size(256)
fn copy(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let i = g.x + g.y * n.x * 256u;
    if (i < arrayLength(&dst)) {
        dst[i] = src[i];
    }
}

@compute @workgroup_size(64)
fn touch(@builtin(local_invocation_index) t: u32) {
    dst[t] = dst[t] + vec4<u32>(1u);
}
