// skjermo_deform: Skjermo's deformer (§3), one grid ring per invocation: the unbent branch
// (eqs. 1-6), the generalised de Casteljau deformation along the stem's current Bézier with
// Sloan's handles (eqs. 7-9), normals through the Jacobian (eq. 10); the workgroup's rings
// written out together (vertex_stage.wgsl).
// CPU twin: sylva_core::mesh::skjermo_deform (same bindings, same loop body).

struct DeformShape {
    radius: f32,
    taper: f32,
    flare: f32,
    bulges: f32,
    bulge_depth: f32,
    lobes: f32,
    lobe_depth: f32,
    lobe_fade: f32,
    v_floor: f32,
    _pad: array<f32, 3>,
}

struct DeformRing {
    stem: u32,
    v: f32,
    tex_v: f32,
    _pad: u32,
}

const MIN_RADIUS_FRACTION: f32 = 0.1;

@group(0) @binding(0) var<storage, read> info: MeshInfo;
@group(0) @binding(1) var<storage, read> ring: array<DeformRing>;
@group(0) @binding(2) var<storage, read> shape: array<DeformShape>;
@group(0) @binding(3) var<storage, read> stems: array<SkjermoStem>;
@group(0) @binding(4) var<storage, read> state: array<SkjermoState>;
@group(0) @binding(5) var<storage, read_write> vertex_words: array<u32>;

// Radius of the unbent branch and its derivatives in v and theta (eqs. 2-5; CPU twin:
// sylva_core::mesh::deform_radius).
fn deform_radius(s: DeformShape, v: f32, theta: f32) -> vec3<f32> {
    var taper = MIN_RADIUS_FRACTION * s.radius;
    var taper_d = 0.0;
    if (v < s.v_floor) {
        var vt = 0.0;
        if (v > 0.0) {
            vt = pow(v, s.taper);
        }
        taper = s.radius * (1.0 - vt);
        taper_d = -s.radius * s.taper * pow(max(v, 1e-4), s.taper - 1.0);
    }
    let ln100 = 2.302585092994046 * 2.0;
    let e = exp(ln100 * (1.0 - 8.0 * v));
    let flare = s.flare / 100.0 * e + 1.0;
    let flare_d = s.flare / 100.0 * e * (-8.0 * ln100);
    let w = TAU * s.bulges;
    let bulge = 1.0 + s.bulge_depth * sin(w * v);
    let bulge_d = s.bulge_depth * w * cos(w * v);
    let fade = 1.0 - v * s.lobe_fade;
    let lobe = 1.0 + s.lobe_depth * sin(s.lobes * theta) * fade;
    let lobe_v = -s.lobe_depth * sin(s.lobes * theta) * s.lobe_fade;
    let lobe_t = s.lobe_depth * s.lobes * cos(s.lobes * theta) * fade;
    let r = taper * flare * bulge * lobe;
    let r_v = taper_d * flare * bulge * lobe + taper * flare_d * bulge * lobe + taper * flare * bulge_d * lobe
        + taper * flare * bulge * lobe_v;
    let r_t = taper * flare * bulge * lobe_t;
    return vec3<f32>(r, r_v, r_t);
}

@compute @workgroup_size(64)
fn main(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
    @builtin(num_workgroups) nwg: vec3<u32>,
) {
    let first = workgroup_first(wid, nwg);
    let stride = info.sides + 1u;
    let staged = stage_fits(stride);
    let r_index = first + lane;
    if (r_index < info.rings) {
        ring_vertices(r_index, lane, stride, staged);
    }
    flush_runs(staged, first, info.rings, stride, lane);
}

fn ring_vertices(r_index: u32, lane: u32, stride: u32, staged: bool) {
    let rg = ring[r_index];
    let k = rg.stem;
    let st = stems[k];
    let c = now_curve(st, state[k]);
    let p = c.p;
    var o = vec3<f32>(1.0, 0.0, 0.0);
    if (st.parent != NONE) {
        o = unit_or(bezier_d(now_curve(stems[st.parent], state[st.parent]), st.attach), vec3<f32>(1.0, 0.0, 0.0));
    }
    let l0 = unit_or(p[1] - p[0], unit_or(p[3] - p[0], vec3<f32>(0.0, 1.0, 0.0)));
    let l1 = unit_or(p[2] - p[1], l0);
    let l2 = unit_or(p[3] - p[2], l1);
    let s0 = unit_or(cross(l0, o), unit_or(any_orthogonal(l0), vec3<f32>(1.0, 0.0, 0.0)));
    let t0 = unit_or(cross(s0, l0), vec3<f32>(0.0, 0.0, 1.0));
    let t1 = unit_or(cross(s0, l1), t0);
    let s1 = unit_or(cross(l1, t1), s0);
    let t2 = unit_or(cross(s1, l2), t1);
    let s2 = unit_or(cross(l2, t2), s1);
    let s = array<vec3<f32>, 3>(s0, s1, s2);
    let t = array<vec3<f32>, 3>(t0, t1, t2);
    let u = rg.v;
    let w = array<f32, 3>((1.0 - u) * (1.0 - u), 2.0 * u * (1.0 - u), u * u);
    let dw = array<f32, 3>(-2.0 * (1.0 - u), 2.0 - 4.0 * u, 2.0 * u);
    let d = array<vec3<f32>, 3>(p[1] - p[0], p[2] - p[1], p[3] - p[2]);
    let lerps = array<vec3<f32>, 3>(p[0] + d[0] * u, p[1] + d[1] * u, p[2] + d[2] * u);
    let shp = shape[k];
    for (var ci = 0u; ci < stride; ci++) {
        let theta = TAU * (f32(ci % info.sides) / f32(info.sides));
        let sn = sin(theta);
        let cs = cos(theta);
        let rr = deform_radius(shp, u, theta);
        let fv = sn * rr.x;
        let fw = cs * rr.x;
        let fv_t = cs * rr.x + sn * rr.z;
        let fw_t = -sn * rr.x + cs * rr.z;
        let fv_u = sn * rr.y;
        let fw_u = cs * rr.y;
        var pos = vec3<f32>(0.0);
        var d_theta = vec3<f32>(0.0);
        var d_u = vec3<f32>(0.0);
        for (var i = 0u; i < 3u; i++) {
            let q = lerps[i] + s[i] * fv + t[i] * fw;
            pos += q * w[i];
            d_theta += (s[i] * fv_t + t[i] * fw_t) * w[i];
            // Sum of dw is 0: differences at the handles' scale (CPU twin likewise).
            let q_rel = (p[i] - p[0]) + (d[i] - d[0]) * u + (s[i] - s0) * fv + (t[i] - t0) * fw;
            d_u += q_rel * dw[i] + (d[i] + s[i] * fv_u + t[i] * fw_u) * w[i];
        }
        let a = d_theta * (1.0 / max(length(d_theta), 1e-30));
        let b = d_u * (1.0 / max(length(d_u), 1e-30));
        let normal = unit_or(cross(a, b), s0);
        let x = vertex_new(pos, normal);
        put_vertex(staged, lane * stride + ci, r_index * stride + ci, x);
    }
}
