// skjermo_step: re-attach every stem on its parent's previous curve and bend P2, P3
// (eqs. 15-17), the bend following the wind as the stem's damped first mode. CPU twin:
// sylva_core::methods::skjermo::kernels::skjermo_step (bindings 0 fields, 1 waves, 2 stems,
// 3 previous state, 4 step, 5 next state, 6 modes, 7 sway).

@group(0) @binding(2) var<storage, read> stems: array<SkjermoStem>;
@group(0) @binding(3) var<storage, read> prev: array<SkjermoState>;
@group(0) @binding(4) var<storage, read> step: SkjermoStep;
@group(0) @binding(5) var<storage, read_write> next: array<SkjermoState>;
@group(0) @binding(6) var<storage, read> modes: array<SkjermoMode>;
@group(0) @binding(7) var<storage, read_write> sway: array<SkjermoSway>;

fn safe_normalize(v: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    if (l > 0.0) {
        return v / l;
    }
    return vec3<f32>(0.0);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = gid.x + gid.y * nwg.x * 64u;
    if (k >= arrayLength(&stems)) {
        return;
    }
    let st = stems[k];
    let rest = rest_curve(st);
    var shift = vec3<f32>(0.0);
    var f_now: Frame;
    var f_rest: Frame;
    if (st.parent == NONE) {
        f_now = frame(rest, vec3<f32>(1.0, 0.0, 0.0), 0.0);
        f_rest = f_now;
    } else {
        let p = stems[st.parent];
        let prest = rest_curve(p);
        let pnow = now_curve(p, prev[st.parent]);
        shift = bezier(pnow, st.attach) - bezier(prest, st.attach);
        f_rest = frame(prest, st.parent_orient.xyz, st.attach);
        f_now = transported_frame(f_rest, bezier_d(pnow, st.attach));
    }
    var d: array<vec3<f32>, 4>;
    for (var j = 0u; j < 4u; j++) {
        let l = st.local[j].xyz;
        let now = f_now.t * l.x + f_now.n * l.y + f_now.b * l.z;
        let was = f_rest.t * l.x + f_rest.n * l.y + f_rest.b * l.z;
        d[j] = shift + (now - was);
    }
    let a1 = rest.p[1] + d[1];
    let a2 = rest.p[2] + d[2];
    let a3 = rest.p[3] + d[3];
    let w = wind_at(a3, step.time);
    let u = length(w);
    let r = u / step.reconfiguration_speed;
    let g = pow(1.0 + r * r, 0.5 * step.vogel_exponent);
    let theta = min(st.drag * u * u * g, step.max_bend);
    let c = st.length * theta;
    var b3 = vec3<f32>(0.0);
    if (u > 0.0 && c > 0.0) {
        b3 = w * (c / u);
    }
    if (step.dynamics != 0u) {
        let m = modes[k];
        let next_sway = damped_apply(sway[k].bend.xyz, sway[k].rate.xyz, b3, m.w2, m.damping, damped_coefficients(m.w2, m.damping, step.dt));
        let rate = next_sway.v * (1.0 / (1.0 + m.aero * u * g * step.dt));
        sway[k] = SkjermoSway(vec4<f32>(next_sway.x, 0.0), vec4<f32>(rate, 0.0));
        b3 = next_sway.x;
    }
    var c2 = vec3<f32>(0.0);
    var c3 = vec3<f32>(0.0);
    if (dot(b3, b3) > 0.0) {
        let b2 = b3 * pow(step.p2_weight, step.exponent);
        let d2 = a2 - a1;
        c2 = safe_normalize(d2 + b2) * length(d2) - d2;
        let p2 = a2 + c2;
        let d3 = a3 - a2;
        let p3 = p2 + safe_normalize(d3 + b3) * length(d3);
        c3 = p3 - (a3 + c2);
    }
    d[2] += c2;
    d[3] += c2 + c3;
    var out: SkjermoState;
    for (var j = 0u; j < 4u; j++) {
        out.delta[j] = vec4<f32>(d[j], 0.0);
    }
    next[k] = out;
}
