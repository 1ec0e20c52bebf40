// mesh_tubes: one ring per invocation (Akagi §2.2–2.3): the Hermite centreline point and
// the slerped frame once, then the unit polygon placed around it with the interpolated
// radius and the bark relief along the normal (sides + 1 vertices, the last the seam),
// written out by the workgroup together (vertex_stage.wgsl).
// CPU twin: sylva_core::mesh::mesh_tubes (same bindings, same loop body).

@group(0) @binding(0) var<storage, read> info: MeshInfo;
@group(0) @binding(1) var<storage, read> ring: array<Ring>;
@group(0) @binding(2) var<storage, read> segment: array<Segment>;
@group(0) @binding(3) var<storage, read> joint: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> acc: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> vertex_words: array<u32>;

fn world_orientation(i: u32) -> vec4<f32> {
    return quat_mul(acc[i], segment[i].orientation);
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
    let r = first + lane;
    if (r < info.rings) {
        ring_vertices(r, lane, stride, staged);
    }
    flush_runs(staged, first, info.rings, stride, lane);
}

fn ring_vertices(r: u32, lane: u32, stride: u32, staged: bool) {
    let rg = ring[r];
    let i = rg.segment;
    let seg = segment[i];
    let q = world_orientation(i);
    let axis = quat_rotate(q, vec3<f32>(0.0, 1.0, 0.0));
    let p0 = joint[i].xyz;
    let p1 = p0 + axis * seg.length;
    var f0 = q;
    var m0 = axis * seg.length;
    if (rg.prev != NONE) {
        let qp = world_orientation(rg.prev);
        f0 = quat_slerp(qp, q, 0.5);
        m0 = normalize(quat_rotate(qp, vec3<f32>(0.0, 1.0, 0.0)) + axis) * seg.length;
    }
    var f1 = q;
    var m1 = axis * seg.length;
    if (rg.next != NONE) {
        let qn = world_orientation(rg.next);
        f1 = quat_slerp(q, qn, 0.5);
        m1 = normalize(axis + quat_rotate(qn, vec3<f32>(0.0, 1.0, 0.0))) * seg.length;
    }
    let t = rg.t;
    let t2 = t * t;
    let t3 = t2 * t;
    let centre = p0 * (2.0 * t3 - 3.0 * t2 + 1.0)
        + m0 * (t3 - 2.0 * t2 + t)
        + p1 * (-2.0 * t3 + 3.0 * t2)
        + m1 * (t3 - t2);
    let frame = quat_slerp(f0, f1, t);
    let radius = rg.radius;
    let fx = quat_rotate(frame, vec3<f32>(1.0, 0.0, 0.0));
    let fy = quat_rotate(frame, vec3<f32>(0.0, 1.0, 0.0));
    let fz = quat_rotate(frame, vec3<f32>(0.0, 0.0, 1.0));
    let slope = (seg.radius_base - seg.radius_tip) / max(seg.length, 1e-6);
    let lean = 1.0 / sqrt(1.0 + slope * slope);
    for (var k = 0u; k < stride; k++) {
        let kk = k % info.sides;
        let around = f32(kk) / f32(info.sides);
        let angle = TAU * around;
        let radial = fx * cos(angle) + fz * sin(angle);
        let normal = (radial + fy * slope) * lean;
        var p = centre + radial * radius;
        if (rg.relief != 0.0) {
            p += normal * (rg.relief * radius * bark_relief(around, rg.v, rg.stem_seed));
        }
        put_vertex(staged, lane * stride + k, r * stride + k, vertex_new(p, normal));
    }
}
