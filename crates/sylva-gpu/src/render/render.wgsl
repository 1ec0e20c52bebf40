// Sylva's offscreen renderer: sky, ground, bark and leaves lit by a sun with a shadow map.
// Driven by render/mod.rs; `Globals` is the twin of `RawGlobals` there.

struct Globals {
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    sun_view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    // xyz: unit direction towards the sun; w: sun intensity.
    sun_dir: vec4<f32>,
    sun_colour: vec4<f32>,
    sky_zenith: vec4<f32>,
    sky_horizon: vec4<f32>,
    // rgb: ground albedo; w: half the ground's size, m.
    ground: vec4<f32>,
    // x: shadow map texel size (1 / resolution); y: fog distance, m.
    params: vec4<f32>,
}

@group(0) @binding(0) var<uniform> g: Globals;
@group(1) @binding(0) var shadow_map: texture_depth_2d;
@group(1) @binding(1) var shadow_sampler: sampler_comparison;

const PI: f32 = 3.141592653589793;

fn hash2(p: vec2<f32>) -> f32 {
    let q = fract(p * vec2<f32>(0.1031, 0.1030));
    let r = q + dot(q, q.yx + 33.33);
    return fract((r.x + r.y) * r.x);
}

fn noise2(p: vec2<f32>) -> f32 {
    let i = floor(p);
    let f = fract(p);
    let u = f * f * (3.0 - 2.0 * f);
    let a = hash2(i);
    let b = hash2(i + vec2<f32>(1.0, 0.0));
    let c = hash2(i + vec2<f32>(0.0, 1.0));
    let d = hash2(i + vec2<f32>(1.0, 1.0));
    return mix(mix(a, b, u.x), mix(c, d, u.x), u.y);
}

// Fraction of sunlight reaching `world` (3×3 percentage-closer filtering).
fn sun_visibility(world: vec3<f32>, normal: vec3<f32>) -> f32 {
    let offset = world + normal * 0.02;
    let clip = g.sun_view_proj * vec4<f32>(offset, 1.0);
    let ndc = clip.xyz / clip.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    if (uv.x < 0.0 || uv.x > 1.0 || uv.y < 0.0 || uv.y > 1.0 || ndc.z > 1.0) {
        return 1.0;
    }
    var lit = 0.0;
    for (var y = -1; y <= 1; y++) {
        for (var x = -1; x <= 1; x++) {
            let o = vec2<f32>(f32(x), f32(y)) * g.params.x;
            lit += textureSampleCompareLevel(shadow_map, shadow_sampler, uv + o, ndc.z - 0.0015);
        }
    }
    return lit / 9.0;
}

fn sky(dir: vec3<f32>) -> vec3<f32> {
    let up = clamp(dir.y, 0.0, 1.0);
    var c = mix(g.sky_horizon.rgb, g.sky_zenith.rgb, pow(up, 0.6));
    let s = max(dot(dir, g.sun_dir.xyz), 0.0);
    c += g.sun_colour.rgb * (pow(s, 800.0) * 8.0 + pow(s, 12.0) * 0.25);
    return c;
}

fn fog(c: vec3<f32>, world: vec3<f32>) -> vec3<f32> {
    let d = length(world - g.eye.xyz);
    let f = 1.0 - exp(-d / g.params.y);
    return mix(c, g.sky_horizon.rgb, f);
}

// Direct sun (Lambert, shadowed) plus a hemisphere sky term.
fn shade(albedo: vec3<f32>, n: vec3<f32>, world: vec3<f32>, wrap: f32) -> vec3<f32> {
    let ndl = dot(n, g.sun_dir.xyz);
    let diffuse = max((ndl + wrap) / (1.0 + wrap), 0.0);
    let vis = sun_visibility(world, n);
    let hemi = mix(g.ground.rgb * 0.5, g.sky_zenith.rgb, n.y * 0.5 + 0.5);
    return albedo * (g.sun_colour.rgb * g.sun_dir.w * diffuse * vis + hemi * 0.55);
}

// ---- sky: one full-screen triangle --------------------------------------------------------

struct SkyOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) ndc: vec2<f32>,
}

@vertex
fn vs_sky(@builtin(vertex_index) i: u32) -> SkyOut {
    let p = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u)) * 2.0 - 1.0;
    return SkyOut(vec4<f32>(p, 1.0, 1.0), p);
}

@fragment
fn fs_sky(v: SkyOut) -> @location(0) vec4<f32> {
    let far = g.inv_view_proj * vec4<f32>(v.ndc, 1.0, 1.0);
    let dir = normalize(far.xyz / far.w - g.eye.xyz);
    return vec4<f32>(sky(dir), 1.0);
}

// ---- ground: one quad at y = 0 ------------------------------------------------------------

struct GroundOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
}

fn ground_corner(i: u32) -> vec3<f32> {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(-1.0, 1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(1.0, -1.0),
    );
    let c = corners[i] * g.ground.w;
    return vec3<f32>(c.x, 0.0, c.y);
}

@vertex
fn vs_ground(@builtin(vertex_index) i: u32) -> GroundOut {
    let w = ground_corner(i);
    return GroundOut(g.view_proj * vec4<f32>(w, 1.0), w);
}

@fragment
fn fs_ground(v: GroundOut) -> @location(0) vec4<f32> {
    let n = noise2(v.world.xz * 0.35) * 0.6 + noise2(v.world.xz * 2.1) * 0.4;
    let albedo = g.ground.rgb * (0.75 + 0.5 * n);
    let c = shade(albedo, vec3<f32>(0.0, 1.0, 0.0), v.world, 0.0);
    return vec4<f32>(fog(c, v.world), 1.0);
}

// ---- trees: bark and leaves from the mesh kernels' vertex buffers, instanced ----------------

// sylva_core::mesh::RawVertex (vertex.wgsl, composed before this file), the static uv
// stream, then the instance.
struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal_oct: vec2<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) m0: vec4<f32>,
    @location(4) m1: vec4<f32>,
    @location(5) m2: vec4<f32>,
    @location(6) m3: vec4<f32>,
    @location(7) tint: vec4<f32>,
}

struct TreeOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) tint: vec4<f32>,
}

fn to_world(v: VertexIn) -> TreeOut {
    let model = mat4x4<f32>(v.m0, v.m1, v.m2, v.m3);
    let w = model * vec4<f32>(v.position, 1.0);
    let n = normalize((model * vec4<f32>(oct_unfold(v.normal_oct), 0.0)).xyz);
    return TreeOut(g.view_proj * w, w.xyz, n, v.uv, v.tint);
}

@vertex
fn vs_tree(v: VertexIn) -> TreeOut {
    return to_world(v);
}

@fragment
fn fs_bark(v: TreeOut) -> @location(0) vec4<f32> {
    // Furrowed bark: stripes along the stem broken by noise, in the tree's bark colour.
    let n = normalize(v.normal);
    let furrow = noise2(vec2<f32>(v.uv.x * 14.0, v.uv.y * 3.0));
    let fine = noise2(v.uv * vec2<f32>(40.0, 25.0));
    let base = vec3<f32>(0.23, 0.19, 0.15) * (0.55 + 0.6 * furrow + 0.2 * fine);
    let albedo = mix(base, base * v.tint.rgb * 2.0, 0.35);
    let c = shade(albedo, n, v.world, 0.1);
    return vec4<f32>(fog(c, v.world), 1.0);
}

// The blade's outline (leaf_shape.wgsl, composed before this file): the instance's leaf
// shape rides in its tint's w. The same outline cuts the exported leaf texture's alpha
// (CPU twin: sylva_core::model::LeafShape::contains).
fn inside_leaf(shape: f32, uv: vec2<f32>) -> bool {
    return inside_leaf_shape(u32(shape + 0.5), uv);
}

@fragment
fn fs_leaf(v: TreeOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    if (!inside_leaf(v.tint.w, v.uv)) {
        discard;
    }
    var n = normalize(v.normal);
    if (!front) {
        n = -n;
    }
    let vein = 1.0 - 0.25 * smoothstep(0.03, 0.0, abs(v.uv.x - 0.5));
    let albedo = v.tint.rgb * vein * (0.85 + 0.3 * hash2(floor(v.world.xz * 40.0)));
    var c = shade(albedo, n, v.world, 0.35);
    // Light through the blade when the sun is behind it.
    let back = max(-dot(n, g.sun_dir.xyz), 0.0);
    c += albedo * g.sun_colour.rgb * back * 0.35 * sun_visibility(v.world, -n);
    return vec4<f32>(fog(c, v.world), 1.0);
}

// ---- shadow pass: depth only, from the sun --------------------------------------------------

@vertex
fn vs_shadow(v: VertexIn) -> @builtin(position) vec4<f32> {
    let model = mat4x4<f32>(v.m0, v.m1, v.m2, v.m3);
    return g.sun_view_proj * (model * vec4<f32>(v.position, 1.0));
}

struct ShadowLeafOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) shape: f32,
}

@vertex
fn vs_shadow_leaf(v: VertexIn) -> ShadowLeafOut {
    let model = mat4x4<f32>(v.m0, v.m1, v.m2, v.m3);
    let clip = g.sun_view_proj * (model * vec4<f32>(v.position, 1.0));
    return ShadowLeafOut(clip, v.uv, v.tint.w);
}

// Leaves cast the shadow of their outline, not of the polygon around it.
@fragment
fn fs_shadow_leaf(v: ShadowLeafOut) {
    if (!inside_leaf(v.shape, v.uv)) {
        discard;
    }
}
