// skjermo_rotations: seam rotations delta_i = R_parent^-1 R_i, R the rotation of a stem's
// tangent (rest -> current) at the segment's middle. CPU twin:
// sylva_core::methods::skjermo::kernels::skjermo_rotations (bindings 0 segment params, 1 stems,
// 2 state, 3 parents, 4 delta).

@group(0) @binding(0) var<storage, read> params: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> stems: array<SkjermoStem>;
@group(0) @binding(2) var<storage, read> state: array<SkjermoState>;
@group(0) @binding(3) var<storage, read> parents: array<u32>;
@group(0) @binding(4) var<storage, read_write> delta: array<vec4<f32>>;

fn segment_rotation(param: vec4<f32>) -> vec4<f32> {
    let k = bitcast<u32>(param.x);
    let s = stems[k];
    let a = bezier_d(rest_curve(s), param.y);
    let b = bezier_d(now_curve(s, state[k]), param.y);
    var an = vec3<f32>(0.0);
    var bn = vec3<f32>(0.0);
    if (length(a) > 0.0) {
        an = normalize(a);
    }
    if (length(b) > 0.0) {
        bn = normalize(b);
    }
    return shortest_arc(an, bn);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&params)) {
        return;
    }
    let r = segment_rotation(params[i]);
    let p = parents[i];
    if (p == NONE) {
        delta[i] = r;
    } else {
        delta[i] = quat_mul(quat_conj(segment_rotation(params[p])), r);
    }
}
