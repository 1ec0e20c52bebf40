// The vertex every mesh kernel writes each frame and the renderer draws, 16 bytes (CPU
// twin: sylva_core::mesh::RawVertex): position as three f32, the unit normal octahedral in
// two snorm16 (oct_encode, oct_decode). Texture coordinates are a static second stream.

struct Vertex {
    position: array<f32, 3>,
    normal_oct: u32,
}

fn vertex_new(p: vec3<f32>, n: vec3<f32>) -> Vertex {
    return Vertex(array<f32, 3>(p.x, p.y, p.z), oct_encode(n));
}

fn vertex_pos(x: Vertex) -> vec3<f32> {
    return vec3<f32>(x.position[0], x.position[1], x.position[2]);
}

fn sign_not_zero(p: vec2<f32>) -> vec2<f32> {
    return select(vec2<f32>(-1.0), vec2<f32>(1.0), p >= vec2<f32>(0.0));
}

// pack2x16snorm's rule, spelled out so that the CPU twin rounds alike: floor(0.5 + 32767 x).
fn snorm16(x: f32) -> u32 {
    return bitcast<u32>(i32(floor(0.5 + 32767.0 * clamp(x, -1.0, 1.0)))) & 0xffffu;
}

fn unsnorm16(bits: u32) -> f32 {
    // Sign-extend the low 16 bits.
    return max(f32((bitcast<i32>(bits << 16u)) >> 16u) / 32767.0, -1.0);
}

// A unit vector folded onto the octahedron's square (a zero vector gives +z).
fn oct_encode(n: vec3<f32>) -> u32 {
    let p = n.xy / max(abs(n.x) + abs(n.y) + abs(n.z), 1e-30);
    var q = p;
    if (n.z < 0.0) {
        q = (vec2<f32>(1.0) - abs(p.yx)) * sign_not_zero(p);
    }
    return snorm16(q.x) | (snorm16(q.y) << 16u);
}

// The unit vector of oct_encode's bits, from the two components as a Snorm16x2 attribute
// reads them.
fn oct_unfold(p: vec2<f32>) -> vec3<f32> {
    let z = 1.0 - abs(p.x) - abs(p.y);
    var q = p;
    if (z < 0.0) {
        q = (vec2<f32>(1.0) - abs(p.yx)) * sign_not_zero(p);
    }
    return normalize(vec3<f32>(q, z));
}

fn oct_decode(bits: u32) -> vec3<f32> {
    return oct_unfold(vec2<f32>(unsnorm16(bits & 0xffffu), unsnorm16(bits >> 16u)));
}
