//! The CPU's fast form of stage 1's sums ([`super::kernels::hsm_clusters`]): a cluster's slots
//! go through them eight at a time, one per lane of a 256-bit AVX2 register.
//!
//! A cluster's sums `[Σ m u, Apq columns]` are twelve numbers, and each slot adds twelve
//! terms: on SSE that is four three-lane registers per slot, with a broadcast for each of
//! `q`'s components and for the mass, and a quarter of every register idle. Here each of the
//! twelve is one register of eight slots, so eight slots share every operation and nothing
//! is broadcast. [`HsmSlotGroups`] keeps each cluster's slots in groups of eight: their
//! particle indices, and their rest offsets `q` already as three lanes-of-eight arrays (16
//! bytes a slot, as the slot record); the particles' records are loaded two to a register
//! and transposed as the run pass transposes them ([`super::runs`]). Clusters of fewer
//! than 16 slots (the default clusters' rings and blades) gain nothing from a register of
//! eight and are added on SSE as before.
//!
//! The additions are those of the workgroup in `hsm_clusters.wgsl` (as
//! [`super::kernels::hsm_clusters`] does them): lane `t` of the 64 takes slot `t`, `t + 64`, …
//! from zero, so group `k` of eight slots adds into lane block `k mod 8`; the blocks are
//! combined as the quarter lanes are, and the last three halvings run inside the register.
//! The results are the same bit for bit (a test holds them to it on every preset, Song's
//! sizes and clusters of over 64 slots). A CPU without AVX2 (or `SYLVA_SIMD=baseline`) runs
//! `hsm_clusters` itself.

use super::kernels::{LANES, cluster_sums, hsm_clusters, hsm_clusters_with};
use super::runs::{LANE_OF, WIDTH, avx2_at};
use crate::methods::hsm::{HsmLayout, RawHsmClusterState, RawHsmSlot, RawHsmStep};
use crate::simd::Level;
use crate::wind::raw::{RawField, RawWave};

/// The slots of every cluster of a layout in groups of eight (see the module notes). Built
/// once per layout; the layout's own slots stay what the GPU reads.
#[derive(Debug, Clone, PartialEq)]
pub struct HsmSlotGroups {
    /// First group of each cluster, and one past the last cluster's.
    offset: Vec<u32>,
    /// Number of slots of each cluster.
    count: Vec<u32>,
    /// Particle index of each group's slots in slot order; a short last group repeats its
    /// first (those lanes are masked off).
    particle: Vec<[u32; WIDTH]>,
    /// Rest offsets q (x, y, z) of each group's slots, in the order of [`LANE_OF`] (zero past
    /// the last slot).
    q: Vec<[[f32; WIDTH]; 3]>,
    /// One past the largest particle index (0 without slots).
    particles: usize,
}

impl HsmSlotGroups {
    /// The slots of `layout`'s clusters in groups of eight.
    pub fn new(layout: &HsmLayout) -> Self {
        let groups = layout.info.iter().map(|i| (i.slot_count as usize).div_ceil(WIDTH)).sum();
        let mut offset = Vec::with_capacity(layout.info.len() + 1);
        let mut particle = Vec::with_capacity(groups);
        let mut q = Vec::with_capacity(groups);
        for inf in &layout.info {
            offset.push(particle.len() as u32);
            let run = &layout.slots[inf.slot_offset as usize..(inf.slot_offset + inf.slot_count) as usize];
            for group in run.chunks(WIDTH) {
                let mut index = [group[0].particle; WIDTH];
                let mut lanes = [[0.0f32; WIDTH]; 3];
                for (i, s) in group.iter().enumerate() {
                    index[i] = s.particle;
                    for (axis, v) in lanes.iter_mut().zip(s.q) {
                        axis[LANE_OF[i]] = v;
                    }
                }
                particle.push(index);
                q.push(lanes);
            }
        }
        offset.push(particle.len() as u32);
        let count = layout.info.iter().map(|i| i.slot_count).collect();
        let particles = layout.slots.iter().map(|s| s.particle as usize + 1).max().unwrap_or(0);
        Self { offset, count, particle, q, particles }
    }

    /// Bytes [`hsm_clusters_groups`] reads and writes per pass over `layout` (the layout the
    /// groups were made from): [`HsmLayout::stage1_bytes`] with the groups (128 B per eight
    /// slots, padding included) in place of the slot records (16 B each).
    pub fn bytes_per_pass(&self, layout: &HsmLayout) -> usize {
        layout.stage1_bytes() - layout.slots.len() * size_of::<RawHsmSlot>()
            + self.particle.len() * (size_of::<[u32; WIDTH]>() + size_of::<[[f32; WIDTH]; 3]>())
    }

    /// Number of groups.
    pub fn len(&self) -> usize {
        self.particle.len()
    }

    /// Whether there are no groups (no slots).
    pub fn is_empty(&self) -> bool {
        self.particle.is_empty()
    }
}

/// Clusters of fewer slots than this are added as [`hsm_clusters`] adds them: a group's
/// twelve sums halved in the register cost more than a few slots' terms on SSE (the default
/// clusters, eight-slot rings and two-slot blades, ran 5 % slower in groups).
const SMALL: usize = 16;

/// [`hsm_clusters`] over `layout` with its slots as `groups` (made from `layout`) at the CPU's
/// best [`Level`]: the same bits.
pub fn hsm_clusters_groups(
    fields: &[RawField],
    waves: &[RawWave],
    layout: &HsmLayout,
    groups: &HsmSlotGroups,
    displacement: &[[f32; 4]],
    step: RawHsmStep,
    state: &mut [RawHsmClusterState],
) {
    hsm_clusters_groups_at(crate::simd::level(), fields, waves, layout, groups, displacement, step, state);
}

/// [`hsm_clusters_groups`] at `level`: AVX2 adds the slots in groups; the baseline runs
/// [`hsm_clusters`] itself.
#[allow(clippy::too_many_arguments)]
pub fn hsm_clusters_groups_at(
    level: Level,
    fields: &[RawField],
    waves: &[RawWave],
    layout: &HsmLayout,
    groups: &HsmSlotGroups,
    displacement: &[[f32; 4]],
    step: RawHsmStep,
    state: &mut [RawHsmClusterState],
) {
    let l = layout;
    #[cfg(target_arch = "x86_64")]
    if avx2_at(level) {
        assert!(groups.particles <= displacement.len(), "a slot's particle lies past the displacements");
        assert_eq!(groups.count.len(), l.info.len(), "groups made from another layout");
        hsm_clusters_with(fields, waves, &l.info, &l.clusters, step, state, |c, sp, quarter| {
            let inf = &l.info[c];
            if (inf.slot_count as usize) < SMALL {
                let run = &l.slots[inf.slot_offset as usize..(inf.slot_offset + inf.slot_count) as usize];
                return cluster_sums(run, displacement, sp, quarter);
            }
            // SAFETY: the CPU has AVX2 (`avx2_at`), and every group's particles lie in
            // `displacement` (asserted above).
            #[allow(unsafe_code)]
            unsafe {
                avx2::cluster_sums(groups, c, displacement, sp)
            }
        });
        return;
    }
    let _ = (level, groups);
    hsm_clusters(fields, waves, &l.info, &l.clusters, &l.slots, displacement, step, state);
}

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx2 {
    use super::{HsmSlotGroups, LANES, WIDTH};
    use crate::methods::hsm::runs::avx2::transpose;
    use glam::Vec3A;
    use std::arch::x86_64::*;
    use std::mem::MaybeUninit;

    /// Twelve registers of sums.
    type Sums = [__m256; 12];

    #[inline(always)]
    fn add12(a: Sums, b: Sums) -> Sums {
        // SAFETY: the caller runs with AVX2.
        std::array::from_fn(|i| unsafe { _mm256_add_ps(a[i], b[i]) })
    }

    /// The twelve terms of one group's slots (`slot_terms`: u = x − sp, d = u + q;
    /// `[u m, (d q.x) m, (d q.y) m, (d q.z) m]`), lanes from the `last`-th slot on +0.
    #[inline(always)]
    fn group_terms(groups: &HsmSlotGroups, rec: *const f32, spv: [__m256; 3], g: usize, last: usize) -> Sums {
        // SAFETY (all intrinsics and reads here): the caller runs with AVX2, and every
        // particle index is below the displacements' length (`cluster_sums`' promise).
        unsafe {
            let index = &groups.particle[g];
            let ld = |j: usize| _mm_loadu_ps(rec.add(4 * index[j] as usize));
            let r = [
                _mm256_set_m128(ld(1), ld(0)),
                _mm256_set_m128(ld(3), ld(2)),
                _mm256_set_m128(ld(5), ld(4)),
                _mm256_set_m128(ld(7), ld(6)),
            ];
            let [x0, x1, x2, m] = transpose(r);
            let ql = &groups.q[g];
            let q = [_mm256_loadu_ps(ql[0].as_ptr()), _mm256_loadu_ps(ql[1].as_ptr()), _mm256_loadu_ps(ql[2].as_ptr())];
            let u = [_mm256_sub_ps(x0, spv[0]), _mm256_sub_ps(x1, spv[1]), _mm256_sub_ps(x2, spv[2])];
            let d = [_mm256_add_ps(u[0], q[0]), _mm256_add_ps(u[1], q[1]), _mm256_add_ps(u[2], q[2])];
            let dq = |i: usize, a: usize| _mm256_mul_ps(_mm256_mul_ps(d[i], q[a]), m);
            let mut t = [
                _mm256_mul_ps(u[0], m),
                _mm256_mul_ps(u[1], m),
                _mm256_mul_ps(u[2], m),
                dq(0, 0),
                dq(1, 0),
                dq(2, 0),
                dq(0, 1),
                dq(1, 1),
                dq(2, 1),
                dq(0, 2),
                dq(1, 2),
                dq(2, 2),
            ];
            if last != 0 {
                // Lanes past the last slot add exactly +0, as the workgroup's idle lanes do.
                let slot = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
                let valid = _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(last as i32), slot));
                for v in &mut t {
                    *v = _mm256_and_ps(*v, valid);
                }
            }
            t
        }
    }

    /// Cluster `c`'s sums `[Σ m u, Apq columns]` about the shift `sp`, added as
    /// `cluster_sums` adds them (see the module notes).
    ///
    /// # Safety
    /// The CPU has AVX2 and every particle index of `groups` is below `displacement.len()`.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn cluster_sums(
        groups: &HsmSlotGroups,
        c: usize,
        displacement: &[[f32; 4]],
        sp: Vec3A,
    ) -> [Vec3A; 4] {
        let (first, end) = (groups.offset[c] as usize, groups.offset[c + 1] as usize);
        let count = groups.count[c] as usize;
        let spv = [_mm256_set1_ps(sp.x), _mm256_set1_ps(sp.y), _mm256_set1_ps(sp.z)];
        let rec = displacement.as_ptr() as *const f32;
        // The 64 lanes are eight blocks of eight: lane block `b` takes groups `b`, `b + 8`, …,
        // from zero. Only the blocks within the lanes that take part (the next power of two
        // of the slot count) are used.
        let width = count.clamp(1, LANES).next_power_of_two();
        let used = (width / WIDTH).max(1);
        let mut block = [MaybeUninit::<Sums>::uninit(); LANES / WIDTH];
        for b in &mut block[..used] {
            b.write([_mm256_setzero_ps(); 12]);
        }
        let groups_n = end - first;
        debug_assert!(groups_n <= used || used == LANES / WIDTH);
        for k in 0..groups_n {
            let last = if k + 1 == groups_n { count % WIDTH } else { 0 };
            let t = group_terms(groups, rec, spv, first + k, last);
            // SAFETY: block k mod 8 < used (a cluster of more than eight groups uses all eight).
            let acc = unsafe { block[k % (LANES / WIDTH)].assume_init_mut() };
            for (s, v) in acc.iter_mut().zip(t) {
                *s = _mm256_add_ps(*s, v);
            }
        }
        // SAFETY: blocks below `used` are written above.
        let bl = |j: usize| unsafe { block[j].assume_init() };
        // `cluster_sums`: the lanes added into the quarter lanes,
        // `(v_t + v_{t+W/2}) + (v_{t+W/4} + v_{t+3W/4})`, and halved down to the register's eight.
        let v = match used {
            8 => {
                add12(add12(add12(bl(0), bl(4)), add12(bl(2), bl(6))), add12(add12(bl(1), bl(5)), add12(bl(3), bl(7))))
            }
            4 => add12(add12(bl(0), bl(2)), add12(bl(1), bl(3))),
            2 => add12(bl(0), bl(1)),
            _ => bl(0),
        };
        // Slot t is in lane `LANE_OF[t]`: t + 4 sits two lanes on in the same half, t + 2 one
        // lane on, and t + 1 in the other half. Lanes past a short cluster's width are +0,
        // and adding +0 leaves a sum (never −0: each began as 0 + term) unchanged.
        let mut sums = [0.0f32; 12];
        for (s, v) in sums.iter_mut().zip(v) {
            let v = _mm256_add_ps(v, _mm256_shuffle_ps::<0xEE>(v, v));
            let v = _mm256_add_ps(v, _mm256_shuffle_ps::<0x55>(v, v));
            *s = _mm_cvtss_f32(_mm_add_ss(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v)));
        }
        std::array::from_fn(|k| Vec3A::new(sums[3 * k], sums[3 * k + 1], sums[3 * k + 2]))
    }
}
