// mesh_leaves: one leaf per invocation (Akagi §2.4): the leaf's transform once, then its
// polygon — k = 0 the centre, 1.. the rim (the disc's two half-circles, or a polygon holding
// the leaf's outline: row `shape` of the table `leaf_rim`, made once on the CPU), scaled to
// the blade, turned by the leaf's rotation; the workgroup's leaves written out together
// (vertex_stage.wgsl).
// CPU twin: sylva_core::mesh::mesh_leaves (same bindings, same loop body).

@group(0) @binding(0) var<storage, read> info: MeshInfo;
@group(0) @binding(1) var<storage, read> leaf: array<Leaf>;
@group(0) @binding(2) var<storage, read> segment: array<Segment>;
@group(0) @binding(3) var<storage, read> joint: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> acc: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> vertex_words: array<u32>;
@group(0) @binding(6) var<storage, read> leaf_rotation: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> leaf_rim: array<vec2<f32>>;

@compute @workgroup_size(64)
fn main(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
    @builtin(num_workgroups) nwg: vec3<u32>,
) {
    let first = workgroup_first(wid, nwg);
    let stride = info.leaf_sides + 1u;
    let staged = stage_fits(stride);
    let l = first + lane;
    if (l < info.leaves) {
        leaf_vertices(l, lane, stride, staged);
    }
    flush_runs(staged, first, info.leaves, stride, lane);
}

fn leaf_vertices(l: u32, lane: u32, stride: u32, staged: bool) {
    let lf = leaf[l];
    let s = lf.segment;
    let d = acc[s];
    let base = joint[s].xyz + quat_rotate(d, lf.position - segment[s].start);
    // The leaf's rotation about its attachment (in its segment's rest frame); one past the
    // array, or the identity, leaves it at rest bit for bit.
    var lambda = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    if (lf.index < arrayLength(&leaf_rotation)) {
        lambda = leaf_rotation[lf.index];
    }
    var q = quat_mul(d, lf.orientation);
    if (any(lambda != vec4<f32>(0.0, 0.0, 0.0, 1.0))) {
        q = quat_mul(d, quat_mul(lambda, lf.orientation));
    }
    let qx = quat_rotate(q, vec3<f32>(1.0, 0.0, 0.0));
    let qy = quat_rotate(q, vec3<f32>(0.0, 1.0, 0.0));
    let normal = quat_rotate(q, vec3<f32>(0.0, 0.0, 1.0));
    let sides = max(info.leaf_sides, 1u);
    let row = min(lf.shape, max(arrayLength(&leaf_rim) / sides, 1u) - 1u) * sides;
    for (var k = 0u; k < stride; k++) {
        var uv = vec2<f32>(0.5, 0.5);
        if (k > 0u) {
            uv = leaf_rim[row + k - 1u];
        }
        let p = base + qx * ((uv.x - 0.5) * lf.width) + qy * (uv.y * lf.length);
        put_vertex(staged, lane * stride + k, l * stride + k, vertex_new(p, normal));
    }
}
