// akagi_forces: own wind force on each segment at its current centre. CPU twin:
// sylva_core::methods::akagi::kernels::akagi_forces (bindings 0 fields, 1 waves, 2 segments,
// 3 akagi segments, 4 joints, 5 acc, 6 step, 7 forces).

@group(0) @binding(2) var<storage, read> segments: array<Segment>;
@group(0) @binding(3) var<storage, read> akagi: array<AkagiSegment>;
@group(0) @binding(4) var<storage, read> joints: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> acc: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> step: AkagiStep;
@group(0) @binding(7) var<storage, read_write> forces: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&segments)) {
        return;
    }
    let s = segments[i];
    let axis = quat_rotate(acc[i], quat_rotate(s.orientation, vec3<f32>(0.0, 1.0, 0.0)));
    let centre = joints[i].xyz + axis * (0.5 * s.length);
    let v = wind_at(centre, step.time);
    let u = length(v);
    if (u < 1e-6) {
        forces[i] = vec4<f32>(0.0);
        return;
    }
    let vhat = v / u;
    let sin_phi = length(cross(vhat, axis));
    let area = akagi[i].bark_area * sin_phi + akagi[i].leaf_area;
    // Streamlining above the reconfiguration speed: U^2 -> U_r^0.7 U^1.3.
    var u2 = u * u;
    if (u > step.reconfiguration_speed) {
        u2 = u * u * pow(step.reconfiguration_speed / u, 0.7);
    }
    forces[i] = vec4<f32>(vhat * (0.5 * AIR_DENSITY * step.drag * area * u2), 0.0);
}
