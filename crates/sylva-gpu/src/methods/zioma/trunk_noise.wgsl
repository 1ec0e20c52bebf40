// trunk_noise: Zioma's trunk noise bands, (parallel, perpendicular, twist) at many
// (t, tree seed) samples. CPU twin: sylva_core::methods::zioma::trunk (bindings 0 bands,
// 1 samples, 2 angles).

struct Band {
    axis: u32,
    seed: u32,
    frequency: f32,
    amplitude: f32,
    bias: f32,
    _pad: array<u32, 3>,
}

@group(0) @binding(0) var<storage, read> bands: array<Band>;
@group(0) @binding(1) var<storage, read> samples: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> angles: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&samples)) {
        return;
    }
    let t = samples[i].x;
    let tree = bitcast<u32>(samples[i].y);
    var out = vec3<f32>(0.0);
    for (var b = 0u; b < arrayLength(&bands); b++) {
        let band = bands[b];
        let n = value_noise(band.frequency * t, band.seed ^ tree);
        out[min(band.axis, 2u)] += band.bias + band.amplitude * n;
    }
    angles[i] = vec4<f32>(out, 0.0);
}
