// mesh_detail: one midpoint vertex of a subdivided band per invocation (Akagi §2.3): the
// midpoint of its edge's two ring vertices (written by mesh_tubes before), the mean normal,
// and the bark relief sampled at the midpoint less the mean of what the ends carry (the ends'
// texture coordinates from their rings). CPU twin: sylva_core::mesh::mesh_detail (same
// bindings, same loop body).

@group(0) @binding(0) var<storage, read> info: MeshInfo;
@group(0) @binding(1) var<storage, read> detail: array<Detail>;
@group(0) @binding(2) var<storage, read_write> vertex: array<Vertex>;
@group(0) @binding(3) var<storage, read> ring: array<Ring>;

// Texture coordinates of ring vertex a (sylva_core::mesh::MeshLayout::tube_uv).
fn ring_uv(a: u32) -> vec2<f32> {
    let stride = info.sides + 1u;
    return vec2<f32>(f32(a % stride) / f32(info.sides), ring[a / stride].v);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= info.details) {
        return;
    }
    let d = detail[i];
    let a = vertex[d.a];
    let b = vertex[d.b];
    let normal = normalize(oct_decode(a.normal_oct) + oct_decode(b.normal_oct));
    var p = (vertex_pos(a) + vertex_pos(b)) * 0.5;
    if (d.scale != 0.0) {
        let ua = ring_uv(d.a);
        let ub = ring_uv(d.b);
        let u = 0.5 * (ua.x + ub.x);
        let v = 0.5 * (ua.y + ub.y);
        let ends = 0.5 * (bark_relief(ua.x, ua.y, d.stem_seed) + bark_relief(ub.x, ub.y, d.stem_seed));
        p += normal * (d.scale * (bark_relief(u, v, d.stem_seed) - ends));
    }
    vertex[info.rings * (info.sides + 1u) + i] = vertex_new(p, normal);
}
