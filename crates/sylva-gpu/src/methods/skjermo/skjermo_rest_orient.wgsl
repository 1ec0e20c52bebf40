// skjermo_rest_orient: one level of the rest orientation vectors, each stem's the normal of
// its rest attachment frame on its parent's rest curve, turned by the parent's orientation
// (a trunk's from +X at its base). Run once per stem depth (ping-pong), it gives the rest
// orientations as this device rounds them, so that a step in still air reproduces the rest
// bit for bit. CPU twin: sylva_core::methods::skjermo::kernels::skjermo_rest_orient (bindings 0 stems,
// 1 orientations in, 2 orientations out).

@group(0) @binding(0) var<storage, read> stems: array<SkjermoStem>;
@group(0) @binding(1) var<storage, read> orient_in: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> orient_out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = gid.x + gid.y * nwg.x * 64u;
    if (k >= arrayLength(&stems)) {
        return;
    }
    let st = stems[k];
    var f: Frame;
    if (st.parent == NONE) {
        f = frame(rest_curve(st), vec3<f32>(1.0, 0.0, 0.0), 0.0);
    } else {
        f = frame(rest_curve(stems[st.parent]), orient_in[st.parent].xyz, st.attach);
    }
    orient_out[k] = vec4<f32>(f.n, 0.0);
}
