// HSM stage 1 (Song §5.2), shared by its two kernels: one workgroup per cluster, its
// particles as invocations; each invocation sums its lane's terms (`hsm_lane_sums`: it
// strides over the slots), the kernel adds the 64 lanes by a tree (`hsm_clusters`: in shared
// memory; `hsm_clusters_subgroup`: in shared memory down to the subgroup, then by shuffles,
// the same additions in the same order), then one invocation extracts R, forms the goal
// transform, α and the wind, a leaf's with its band of air (`hsm_finish_cluster`). CPU twin:
// sylva_core::methods::hsm::kernels::hsm_clusters (same lanes, same reduction tree).
// Bindings: 0 fields, 1 waves, 2 cluster info, 3 clusters, 4 slots, 5 displacements from
// rest (w = mass), 6 step, 7 cluster state.

@group(0) @binding(2) var<storage, read> info: array<HsmClusterInfo>;
@group(0) @binding(3) var<storage, read> clusters: array<HsmCluster>;
@group(0) @binding(4) var<storage, read> slots: array<HsmSlot>;
@group(0) @binding(5) var<storage, read> displacement: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> step: HsmStep;
@group(0) @binding(7) var<storage, read_write> state: array<HsmClusterState>;

const LANES: u32 = 64u;

var<workgroup> red_m: array<vec3<f32>, 64>;
var<workgroup> red_a0: array<vec3<f32>, 64>;
var<workgroup> red_a1: array<vec3<f32>, 64>;
var<workgroup> red_a2: array<vec3<f32>, 64>;

// A lane's (or a reduction's) sums: Σ m u and the three columns of Σ m (u + q) qᵀ.
struct HsmSums {
    m: vec3<f32>,
    a0: vec3<f32>,
    a1: vec3<f32>,
    a2: vec3<f32>,
}

// The shift at the last substep, subtracted from every displacement (see the CPU twin's
// slot_terms: Σ m q = 0, so Apq is unchanged, and the terms keep the cluster's size).
fn hsm_last_shift(c: u32) -> vec3<f32> {
    let st0 = state[c].transform;
    return vec3<f32>(st0[0].w, st0[1].w, st0[2].w);
}

// Lane t's sums: slots t, t + 64, … of cluster c.
fn hsm_lane_sums(c: u32, t: u32, sp: vec3<f32>) -> HsmSums {
    let inf = info[c];
    var sm = vec3<f32>(0.0);
    var a0 = vec3<f32>(0.0);
    var a1 = vec3<f32>(0.0);
    var a2 = vec3<f32>(0.0);
    for (var j = t; j < inf.slot_count; j += LANES) {
        let s = slots[inf.slot_offset + j];
        let x = displacement[s.particle];
        let m = x.w;
        let u = x.xyz - sp;
        let q = s.q;
        sm += u * m;
        let d = u + q;
        a0 += (d * q.x) * m;
        a1 += (d * q.y) * m;
        a2 += (d * q.z) * m;
    }
    return HsmSums(sm, a0, a1, a2);
}

// Lane t's sums into the shared arrays, then the tree's strides s = 32, 16, … down to
// `until` (exclusive) in shared memory.
fn hsm_reduce_shared(t: u32, sums: HsmSums, until: u32) {
    red_m[t] = sums.m;
    red_a0[t] = sums.a0;
    red_a1[t] = sums.a1;
    red_a2[t] = sums.a2;
    workgroupBarrier();
    for (var s = LANES / 2u; s > until; s >>= 1u) {
        if (t < s) {
            red_m[t] = red_m[t] + red_m[t + s];
            red_a0[t] = red_a0[t] + red_a0[t + s];
            red_a1[t] = red_a1[t] + red_a1[t + s];
            red_a2[t] = red_a2[t] + red_a2[t + s];
        }
        workgroupBarrier();
    }
}

// Invocation 0's work once the sums are in: R, the goal transform, α and the wind.
fn hsm_finish_cluster(c: u32, sp: vec3<f32>, sums: HsmSums) {
    let inf = info[c];
    let cl = clusters[c];
    let c0 = cl.rest_cm.xyz;
    let shift = sp + sums.m / cl.mass;
    let cm = c0 + shift;
    let apq = mat3x3<f32>(sums.a0, sums.a1, sums.a2);
    let q = extract_rotation(apq, state[c].rotation, step.polar_iterations);
    let r = quat_to_mat3(q);
    var tr = r;
    if (step.beta > 0.0) {
        let aqq_inv = mat3x3<f32>(cl.aqq_inv[0].xyz, cl.aqq_inv[1].xyz, cl.aqq_inv[2].xyz);
        let a = apq * aqq_inv;
        let det = determinant(a);
        if (det > 1e-6) {
            tr = a * (step.beta / pow(det, 1.0 / 3.0)) + r * (1.0 - step.beta);
        }
    }
    // The cluster's weight k h², past the hold only up to its path's k̂ h² (see MAX_WEIGHT;
    // the CPU twin is cluster_weight in kernels.rs).
    let bound = max(cl.aqq_inv[0].w * step.dt * step.dt, step.hold);
    let weight = min(min(cl.rest_cm.w * step.dt * step.dt, bound), MAX_WEIGHT);
    state[c].cm = vec4<f32>(cm, weight);
    state[c].rotation = q;
    state[c].transform = array<vec4<f32>, 3>(
        vec4<f32>(tr[0], shift.x),
        vec4<f32>(tr[1], shift.y),
        vec4<f32>(tr[2], shift.z),
    );
    // The wind is sampled on a step's first substep and held through the others.
    if (step.sample_wind != 0u) {
        let u = wind_at(cm, step.time);
        var air = vec3<f32>(0.0);
        if (inf.kind == HSM_LEAF) {
            air = hsm_leaf_air(u, cl.aqq_inv[1].w, inf.source);
        }
        state[c].wind = vec4<f32>(u + air, hsm_reconfiguration(u, step));
    }
}

// The air's fluctuation at a leaf in its band (see the CPU twin, kernels::leaf_air).
fn hsm_leaf_air(u: vec3<f32>, omega: f32, source: u32) -> vec3<f32> {
    let speed2 = dot(u, u);
    if (step.leaf_turbulence == 0.0 || speed2 == 0.0 || omega == 0.0) {
        return vec3<f32>(0.0);
    }
    let sigma = step.leaf_turbulence * sqrt(speed2) * speed2 / (speed2 + step.flutter_onset * step.flutter_onset);
    let seed = pcg_hash(HSM_LEAF_AIR_KEY ^ (source * 0x9e3779b9u));
    let d = vec3<f32>(hash_unit(seed ^ 0x0a11u), hash_unit(seed ^ 0x0b22u), hash_unit(seed ^ 0x0c33u)) * 2.0 - 1.0;
    let len = length(d);
    if (len == 0.0) {
        return vec3<f32>(0.0);
    }
    return d * (sigma * leaf_band(omega, step.leaf_zeta, step.time, seed) / len);
}

const HSM_LEAF_AIR_KEY: u32 = 0x1eafa1e5u;
