// wind_sample: velocity of the bound scene at many (x, y, z, t) samples.
// CPU twin: sylva_core::wind::sample (bindings 0 fields, 1 waves, 2 samples, 3 out).

@group(0) @binding(2) var<storage, read> samples: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> velocities: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&samples)) {
        return;
    }
    let s = samples[i];
    velocities[i] = vec4<f32>(wind_at(s.xyz, s.w), 0.0);
}
