//! The CPU's fast form of the fused particle pass ([`super::kernels::hsm_particles`], stages 3
//! and 4): particles that belong to the same clusters go through it eight at a time.
//!
//! A ring's particles are members of the same clusters, in the same order, and feel the same
//! cluster's wind; so are a leaf blade's. [`HsmRuns`] groups such consecutive particles into
//! *runs*. Within a run each cluster's transform, weight and wind is the same for every
//! particle, so it is read once per eight particles instead of gathered per particle through
//! `member_offset`, `member` and `owner`, and the goal and the integration run on 256-bit
//! AVX2 registers, one particle per lane (records transposed in and out with eight shuffles
//! per four registers). The rest offsets are kept as three compact arrays, 12 bytes per
//! membership instead of the member record's 16 plus the offsets and owners, already in the
//! lanes' order.
//!
//! The operations are those of `hsm_particles`, in the same order (no fused multiply-add),
//! so the results are the same bit for bit, and with them the GPU twin's parity; a test
//! holds the two passes to identical bits on every preset. A CPU without AVX2 (or
//! `SYLVA_SIMD=baseline`) runs `hsm_particles` itself.

use crate::methods::hsm::{HsmLayout, RawHsmClusterState, RawHsmStep};
use crate::simd::Level;
use rayon::prelude::*;

/// Particles per register.
pub(crate) const WIDTH: usize = 8;

/// The lane of the `i`-th particle of a group of eight once its records are transposed
/// (see `avx2::transpose`): even particles in the low half, odd in the high.
pub(crate) const LANE_OF: [usize; WIDTH] = [0, 4, 1, 5, 2, 6, 3, 7];

/// Particles grouped into runs of shared membership (see the module notes). Built once per
/// layout; the layout's own arrays stay what the GPU and the four-stage path read.
#[derive(Debug, Clone, PartialEq)]
pub struct HsmRuns {
    runs: Vec<Run>,
    /// Member clusters of every run, in the particles' member order, run after run.
    cluster: Vec<u32>,
    /// Rest offsets q (x, y, z) of every run's particles in each of its clusters: cluster
    /// after cluster; within one, groups of eight particles (the last padded with zeros),
    /// each in the order of [`LANE_OF`].
    q: [Vec<f32>; 3],
    /// Runs `[start, end)` of each parallel chunk, about [`CHUNK`] particles each.
    chunks: Vec<(usize, usize)>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Run {
    /// First particle.
    first: u32,
    /// Number of particles.
    len: u32,
    /// First of its clusters in [`HsmRuns::cluster`].
    cluster_offset: u32,
    /// Number of clusters each particle belongs to.
    cluster_count: u32,
    /// First rest offset in [`HsmRuns::q`]; each cluster's take `len` rounded up to eight.
    q_offset: u32,
    /// The cluster whose wind the particles feel.
    owner: u32,
}

/// Particles per parallel chunk: enough work to outweigh a task's cost, small enough to
/// share the particles evenly between threads.
const CHUNK: usize = 2048;

impl HsmRuns {
    /// The runs of `layout`: maximal ranges of consecutive particles with the same member
    /// clusters (in the same order) and the same owner.
    pub fn new(layout: &HsmLayout) -> Self {
        let n = layout.owner.len();
        let members = |i: usize| &layout.member[layout.member_offset[i] as usize..layout.member_offset[i + 1] as usize];
        let same = |i: usize, j: usize| {
            layout.owner[i] == layout.owner[j]
                && members(i).len() == members(j).len()
                && members(i).iter().zip(members(j)).all(|(a, b)| a.cluster == b.cluster)
        };
        let mut runs = Vec::new();
        let mut cluster = Vec::new();
        let mut q: [Vec<f32>; 3] = std::array::from_fn(|_| Vec::with_capacity(layout.member.len() * 9 / 8));
        let mut i = 0;
        while i < n {
            let mut j = i + 1;
            while j < n && same(i, j) {
                j += 1;
            }
            let m = members(i);
            runs.push(Run {
                first: i as u32,
                len: (j - i) as u32,
                cluster_offset: cluster.len() as u32,
                cluster_count: m.len() as u32,
                q_offset: q[0].len() as u32,
                owner: layout.owner[i],
            });
            cluster.extend(m.iter().map(|m| m.cluster));
            for k in 0..m.len() {
                for group in (i..j).step_by(WIDTH) {
                    let mut lanes = [[0.0f32; WIDTH]; 3];
                    for (g, p) in (group..j.min(group + WIDTH)).enumerate() {
                        for (axis, v) in lanes.iter_mut().zip(members(p)[k].q) {
                            axis[LANE_OF[g]] = v;
                        }
                    }
                    for (axis, l) in q.iter_mut().zip(lanes) {
                        axis.extend(l);
                    }
                }
            }
            i = j;
        }
        let mut chunks = Vec::new();
        let (mut start, mut count) = (0, 0);
        for (k, r) in runs.iter().enumerate() {
            count += r.len as usize;
            if count >= CHUNK {
                chunks.push((start, k + 1));
                (start, count) = (k + 1, 0);
            }
        }
        if start < runs.len() {
            chunks.push((start, runs.len()));
        }
        Self { runs, cluster, q, chunks }
    }

    /// Bytes [`hsm_particles_runs`] reads and writes per pass, counted as
    /// [`HsmLayout::bytes_per_step`] counts them: per run its record (24 B) and its owner's
    /// wind (16 B); per run and cluster the cluster index (4 B), transform and weight (52 B);
    /// the rest offsets as stored (12 B per membership, groups padded to eight); each
    /// particle's displacement and velocity read and written (64 B).
    pub fn bytes_per_pass(&self) -> usize {
        let particles: usize = self.runs.iter().map(|r| r.len as usize).sum();
        self.runs.len() * (24 + 16) + self.cluster.len() * (4 + 52) + self.q[0].len() * 12 + particles * 64
    }

    /// Number of runs.
    pub fn len(&self) -> usize {
        self.runs.len()
    }

    /// Whether there are no runs (no particles).
    pub fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }
}

/// Whether the CPU's fast forms run at `level` (AVX2 on this CPU): [`hsm_particles_runs_at`]
/// the runs rather than [`super::kernels::hsm_particles`], and
/// [`super::slot_groups::hsm_clusters_groups_at`] the groups rather than
/// [`super::kernels::hsm_clusters`].
pub fn avx2_at(level: Level) -> bool {
    cfg!(target_arch = "x86_64") && level.min(crate::simd::detected()) == Level::Avx2
}

/// [`super::kernels::hsm_particles`] over `runs` (made from `layout`) at the CPU's best
/// [`Level`]: the same bits.
pub fn hsm_particles_runs(
    layout: &HsmLayout,
    runs: &HsmRuns,
    state: &[RawHsmClusterState],
    step: RawHsmStep,
    displacement: &mut [[f32; 4]],
    velocity: &mut [[f32; 4]],
) {
    hsm_particles_runs_at(crate::simd::level(), layout, runs, state, step, displacement, velocity);
}

/// [`hsm_particles_runs`] at `level`: AVX2 runs the runs; the baseline runs
/// [`super::kernels::hsm_particles`] itself.
pub fn hsm_particles_runs_at(
    level: Level,
    layout: &HsmLayout,
    runs: &HsmRuns,
    state: &[RawHsmClusterState],
    step: RawHsmStep,
    displacement: &mut [[f32; 4]],
    velocity: &mut [[f32; 4]],
) {
    #[cfg(target_arch = "x86_64")]
    if avx2_at(level) {
        // Each chunk's particles as its own slices.
        let mut parts = Vec::with_capacity(runs.chunks.len());
        let (mut d, mut v) = (displacement, velocity);
        for &(a, b) in &runs.chunks {
            let first = runs.runs[a].first as usize;
            let last = &runs.runs[b - 1];
            let n = (last.first + last.len) as usize - first;
            let (dh, dt) = std::mem::take(&mut d).split_at_mut(n);
            let (vh, vt) = std::mem::take(&mut v).split_at_mut(n);
            (d, v) = (dt, vt);
            parts.push((&runs.runs[a..b], first, dh, vh));
        }
        parts.into_par_iter().for_each(|(chunk, base, d, v)| {
            // SAFETY: the CPU has AVX2 (`detected`).
            #[allow(unsafe_code)]
            unsafe {
                avx2::run_chunk(runs, chunk, base, state, &step, d, v)
            }
        });
        return;
    }
    let _ = (level, runs);
    let l = layout;
    super::kernels::hsm_particles(&l.member_offset, &l.member, state, &l.owner, step, displacement, velocity);
}

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
pub(crate) mod avx2 {
    use super::{HsmRuns, Run, WIDTH};
    use crate::methods::hsm::{RawHsmClusterState, RawHsmStep};
    use std::arch::x86_64::*;

    /// Eight records' (x, y, z, w) from four registers of two records each (register `k`
    /// holding records `2k` and `2k + 1`) as four registers of one component each, particles
    /// in the order of [`super::LANE_OF`]; and back: the 4×4 transpose within each 128-bit
    /// half is its own inverse.
    #[inline(always)]
    pub(crate) fn transpose(r: [__m256; 4]) -> [__m256; 4] {
        // SAFETY (all intrinsics here): the caller runs with AVX2.
        unsafe {
            let t0 = _mm256_unpacklo_ps(r[0], r[1]);
            let t1 = _mm256_unpackhi_ps(r[0], r[1]);
            let t2 = _mm256_unpacklo_ps(r[2], r[3]);
            let t3 = _mm256_unpackhi_ps(r[2], r[3]);
            [
                _mm256_shuffle_ps::<0x44>(t0, t2),
                _mm256_shuffle_ps::<0xEE>(t0, t2),
                _mm256_shuffle_ps::<0x44>(t1, t3),
                _mm256_shuffle_ps::<0xEE>(t1, t3),
            ]
        }
    }

    /// Masks of the four two-record registers from the first of `n` valid particles.
    #[inline(always)]
    fn masks(n: usize) -> [__m256i; 4] {
        let m = |r: usize| if r < n { -1 } else { 0 };
        std::array::from_fn(|k| unsafe {
            let (a, b) = (m(2 * k), m(2 * k + 1));
            _mm256_setr_epi32(a, a, a, a, b, b, b, b)
        })
    }

    /// Eight (or the first `n`) records from `src` as components.
    #[inline(always)]
    unsafe fn load(src: *const [f32; 4], n: usize) -> [__m256; 4] {
        let p = src as *const f32;
        let r: [__m256; 4] = if n == WIDTH {
            std::array::from_fn(|k| unsafe { _mm256_loadu_ps(p.add(8 * k)) })
        } else {
            let m = masks(n);
            // Masked-off records are not read (`wrapping_add`: they may lie past the slice).
            std::array::from_fn(|k| unsafe { _mm256_maskload_ps(p.wrapping_add(8 * k), m[k]) })
        };
        transpose(r)
    }

    /// Components back as eight (or the first `n`) records at `dst`.
    #[inline(always)]
    unsafe fn store(dst: *mut [f32; 4], n: usize, c: [__m256; 4]) {
        let p = dst as *mut f32;
        let r = transpose(c);
        if n == WIDTH {
            for (k, r) in r.into_iter().enumerate() {
                unsafe { _mm256_storeu_ps(p.add(8 * k), r) };
            }
        } else {
            let m = masks(n);
            for (k, r) in r.into_iter().enumerate() {
                unsafe { _mm256_maskstore_ps(p.wrapping_add(8 * k), m[k], r) };
            }
        }
    }

    /// One chunk of runs, its particles `displacement` and `velocity` starting at particle
    /// `base`. Per run: the weight sum and wind, then eight particles at a time the weighted
    /// goal over the run's clusters (`particle_goal`, `goal_displacement`) and
    /// `particle_velocity`'s update, operation for operation.
    #[target_feature(enable = "avx2")]
    #[allow(clippy::too_many_arguments)]
    pub(super) unsafe fn run_chunk(
        runs: &HsmRuns,
        chunk: &[Run],
        base: usize,
        state: &[RawHsmClusterState],
        step: &RawHsmStep,
        displacement: &mut [[f32; 4]],
        velocity: &mut [[f32; 4]],
    ) {
        let h = step.dt;
        let inv_h = 1.0 / h;
        let gs = (1.0 - step.gravity[3]) * h;
        let gravity: [__m256; 3] = std::array::from_fn(|c| _mm256_set1_ps(step.gravity[c] * gs));
        let hs = _mm256_set1_ps(h);
        let damping = _mm256_set1_ps(step.damping);
        let zero = _mm256_setzero_ps();
        let one = _mm256_set1_ps(1.0);
        let air = _mm256_set1_ps(step.air);
        let [qx, qy, qz] = &runs.q;
        for run in chunk {
            let clusters =
                &runs.cluster[run.cluster_offset as usize..(run.cluster_offset + run.cluster_count) as usize];
            let mut wsum = 0.0f32;
            for &c in clusters {
                wsum += state[c as usize].cm[3];
            }
            // `particle_goal`: sum / wsum, or zero without weight; `particle_velocity`:
            // ᾱ = min(wsum, hold).
            let weighted = wsum > 0.0;
            let wsum_v = _mm256_set1_ps(wsum);
            let scale = _mm256_set1_ps(if weighted { wsum.min(step.hold) * inv_h } else { 0.0 });
            let wind: [__m256; 3] = std::array::from_fn(|c| _mm256_set1_ps(state[run.owner as usize].wind[c]));
            let reconfigured = _mm256_set1_ps(state[run.owner as usize].wind[3]);
            let len = run.len as usize;
            let padded = len.next_multiple_of(WIDTH);
            let first = run.first as usize - base;
            assert!(first + len <= displacement.len() && first + len <= velocity.len());
            assert!(run.q_offset as usize + clusters.len() * padded <= qx.len());
            for off in (0..len).step_by(WIDTH) {
                let n = (len - off).min(WIDTH);
                let p = first + off;
                // SAFETY: records p..p + n lie in both slices (asserted above), and masked
                // loads and stores touch only those.
                let u = unsafe { load(displacement.as_ptr().add(p), n) };
                let v = unsafe { load(velocity.as_ptr().add(p), n) };
                let mut sum = [zero; 3];
                for (k, &c) in clusters.iter().enumerate() {
                    let st = &state[c as usize];
                    let t = &st.transform;
                    let w = _mm256_set1_ps(st.cm[3]);
                    let at = run.q_offset as usize + k * padded + off;
                    // SAFETY: at + 8 ≤ the arrays' length (asserted above).
                    let q = unsafe {
                        [
                            _mm256_loadu_ps(qx.as_ptr().add(at)),
                            _mm256_loadu_ps(qy.as_ptr().add(at)),
                            _mm256_loadu_ps(qz.as_ptr().add(at)),
                        ]
                    };
                    for (a, s) in sum.iter_mut().enumerate() {
                        let tq = _mm256_add_ps(
                            _mm256_add_ps(
                                _mm256_mul_ps(_mm256_set1_ps(t[0][a]), q[0]),
                                _mm256_mul_ps(_mm256_set1_ps(t[1][a]), q[1]),
                            ),
                            _mm256_mul_ps(_mm256_set1_ps(t[2][a]), q[2]),
                        );
                        let g = _mm256_add_ps(_mm256_sub_ps(tq, q[a]), _mm256_set1_ps(t[a][3]));
                        *s = _mm256_add_ps(*s, _mm256_mul_ps(g, w));
                    }
                }
                let goal = if weighted { sum.map(|s| _mm256_div_ps(s, wsum_v)) } else { [zero; 3] };
                // `particle_velocity`.
                let kd = v[3];
                let mut vel: [__m256; 3] = std::array::from_fn(|a| {
                    _mm256_add_ps(_mm256_add_ps(v[a], _mm256_mul_ps(_mm256_sub_ps(goal[a], u[a]), scale)), gravity[a])
                });
                let rel: [__m256; 3] = std::array::from_fn(|a| _mm256_sub_ps(wind[a], _mm256_mul_ps(vel[a], air)));
                let dot = _mm256_add_ps(
                    _mm256_add_ps(_mm256_mul_ps(rel[0], rel[0]), _mm256_mul_ps(rel[1], rel[1])),
                    _mm256_mul_ps(rel[2], rel[2]),
                );
                let s = _mm256_mul_ps(_mm256_mul_ps(hs, _mm256_mul_ps(kd, reconfigured)), _mm256_sqrt_ps(dot));
                let f = _mm256_div_ps(s, _mm256_add_ps(one, _mm256_mul_ps(air, s)));
                for a in 0..3 {
                    vel[a] = _mm256_mul_ps(_mm256_add_ps(vel[a], _mm256_mul_ps(rel[a], f)), damping);
                }
                // Fixed particles (`kd < 0`) keep their records.
                let fixed = _mm256_cmp_ps::<_CMP_LT_OQ>(kd, zero);
                let nu: [__m256; 4] = std::array::from_fn(|a| {
                    if a == 3 {
                        u[3]
                    } else {
                        _mm256_blendv_ps(_mm256_add_ps(u[a], _mm256_mul_ps(vel[a], hs)), u[a], fixed)
                    }
                });
                let nv: [__m256; 4] =
                    std::array::from_fn(|a| if a == 3 { kd } else { _mm256_blendv_ps(vel[a], v[a], fixed) });
                // SAFETY: as for the loads.
                unsafe {
                    store(displacement.as_mut_ptr().add(p), n, nu);
                    store(velocity.as_mut_ptr().add(p), n, nv);
                }
            }
        }
    }
}
