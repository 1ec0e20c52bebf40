// segment_ends: end[i] = start[i] + rotate(orientation[i], (0, length[i], 0)).
// CPU twin: sylva_core::pose::segment_ends (same bindings, same loop body).

@group(0) @binding(0) var<storage, read> segments: array<Segment>;
@group(0) @binding(1) var<storage, read_write> ends: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&segments)) {
        return;
    }
    let s = segments[i];
    ends[i] = vec4<f32>(s.start + quat_rotate(s.orientation, vec3<f32>(0.0, s.length, 0.0)), 1.0);
}
