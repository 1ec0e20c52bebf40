// mesh_leaves: one leaf-polygon vertex per invocation (Akagi §2.4): k = 0 the centre, 1..
// the rim, two half-circles of the unit n-gon scaled to the blade.
// CPU twin: sylva_core::cpu::mesh_leaves (same bindings, same loop body).

@group(0) @binding(0) var<storage, read> info: MeshInfo;
@group(0) @binding(1) var<storage, read> leaf: array<Leaf>;
@group(0) @binding(2) var<storage, read> segment: array<Segment>;
@group(0) @binding(3) var<storage, read> joint: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> acc: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> vertex: array<Vertex>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let vid = gid.x + gid.y * nwg.x * 64u;
    let stride = info.leaf_sides + 1u;
    if (vid >= info.leaves * stride) {
        return;
    }
    let lf = leaf[vid / stride];
    let k = vid % stride;
    let s = lf.segment;
    let d = acc[s];
    let base = joint[s].xyz + quat_rotate(d, lf.position - segment[s].start);
    let q = quat_mul(d, lf.orientation);
    var local = vec3<f32>(0.0, 0.5 * lf.length, 0.0);
    if (k > 0u) {
        let a = TAU * f32(k - 1u) / f32(info.leaf_sides);
        local = vec3<f32>(sin(a) * 0.5 * lf.width, (1.0 - cos(a)) * 0.5 * lf.length, 0.0);
    }
    let p = base + quat_rotate(q, local);
    let normal = quat_rotate(q, vec3<f32>(0.0, 0.0, 1.0));
    vertex[vid] = Vertex(p, local.x / max(lf.width, 1e-9) + 0.5, normal, local.y / max(lf.length, 1e-9));
}
