// skin_vertices: linear blend skinning with two bones (Zioma §6.5), one output vertex per
// invocation, instance-major: out[instance * vertices + v], reading pose first_instance + instance;
// leaf vertices turned about their leaf's attachment by its rotation first.
// CPU twin: sylva_core::mesh::skin_vertices (same bindings, same loop body).

struct Skin {
    bone0: u32,
    bone1: u32,
    weight: f32,
    leaf: u32,
}

struct SkinInfo {
    vertices: u32,
    segments: u32,
    instances: u32,
    first_instance: u32,
}

@group(0) @binding(0) var<storage, read> info: SkinInfo;
@group(0) @binding(1) var<storage, read> rest: array<Vertex>;
@group(0) @binding(2) var<storage, read> skin: array<Skin>;
@group(0) @binding(3) var<storage, read> rest_joint: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> joint: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> acc: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> out: array<Vertex>;
@group(0) @binding(7) var<storage, read> leaf_attach: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read> leaf_rotation: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let id = gid.x + gid.y * nwg.x * 64u;
    if (id >= info.vertices * info.instances) {
        return;
    }
    let inst = id / info.vertices;
    let v = id % info.vertices;
    let base = (info.first_instance + inst) * info.segments;
    var x = vertex_pos(rest[v]);
    var nrm = oct_decode(rest[v].normal_oct);
    let s = skin[v];
    // A leaf vertex turns about its leaf's attachment first (the identity leaves it be).
    if (s.leaf > 0u && s.leaf - 1u < arrayLength(&leaf_rotation) && s.leaf - 1u < arrayLength(&leaf_attach)) {
        let q = leaf_rotation[s.leaf - 1u];
        if (any(q != vec4<f32>(0.0, 0.0, 0.0, 1.0))) {
            let a = leaf_attach[s.leaf - 1u].xyz;
            x = a + quat_rotate(q, x - a);
            nrm = quat_rotate(q, nrm);
        }
    }
    let w = s.weight;
    let p0 = joint[base + s.bone0].xyz + quat_rotate(acc[base + s.bone0], x - rest_joint[s.bone0].xyz);
    let p1 = joint[base + s.bone1].xyz + quat_rotate(acc[base + s.bone1], x - rest_joint[s.bone1].xyz);
    let p = p0 * (1.0 - w) + p1 * w;
    let normal = normalize(quat_rotate(acc[base + s.bone0], nrm) * (1.0 - w) + quat_rotate(acc[base + s.bone1], nrm) * w);
    out[id] = vertex_new(p, normal);
}
