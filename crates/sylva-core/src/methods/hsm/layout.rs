//! Building Song's linearised tree (§4, §5.1): rings, shared rings, leaf blades and stem
//! clusters laid out as the flat arrays every stage reads.

use super::raw::*;
use super::{HsmError, HsmParams, MAX_PARTICLES};
use crate::model::{NONE, Tree};
use crate::physics::AIR_DENSITY;
use glam::{DMat3, DVec3, Mat3, Vec3};

/// Song's linearised tree (§5.1): every array the four stages read, CPU and GPU alike.
#[derive(Debug, Clone, PartialEq)]
pub struct HsmLayout {
    /// Cluster information, parents before children.
    pub info: Vec<RawHsmClusterInfo>,
    /// Constant cluster data.
    pub clusters: Vec<RawHsmCluster>,
    /// Child cluster ids, grouped by parent (Fig. 8's "Children ID").
    pub children: Vec<u32>,
    /// Every cluster's particles, cluster after cluster.
    pub slots: Vec<RawHsmSlot>,
    /// Rest position (xyz) and drag factor `k_d = ½ ρ C_d A / m` (w, 1/m) of each particle.
    pub rest: Vec<[f32; 4]>,
    /// Mass of each particle, kg.
    pub mass: Vec<f32>,
    /// 1 for a free particle, 0 for a fixed one.
    pub free: Vec<f32>,
    /// The cluster whose wind each particle feels: the cluster that made it (a leaf blade's
    /// is its leaf cluster, whose wind adds the air at the leaf's scale).
    pub owner: Vec<u32>,
    /// Start of each particle's run in `member` (one more entry than particles).
    pub member_offset: Vec<u32>,
    /// The clusters of every particle with its rest offset in each, in cluster order.
    pub member: Vec<RawHsmMember>,
    /// Cluster of each segment of the tree (`u32::MAX` where a truncated layout has none).
    pub segment_cluster: Vec<u32>,
    /// Largest number of child clusters of any cluster.
    pub max_children: u32,
    /// Factor on every segment and stem cluster's rate since they were derived from the
    /// wood (see [`super::HsmParams::calibrate`]); 1 as built.
    pub rate_scale: f32,
    /// Factor on every particle's drag since it was derived from the air: the calibrated
    /// trunk's static compliance over the beam's ([`super::calibrate`]); 1 as built.
    pub load_scale: f32,
    /// Factor on the air's damping so that the trunk's mode meets it as the tree's would:
    /// the hold moves a held particle as if its mass were `Σ w / hold` times its own, so the
    /// mode's inertia lies where the rings are held, while the drag's damping lies where its
    /// area is. The factor is the mode's inertia so inflated over the drag's damping so
    /// weighed, each over its sum with the particles' own masses, in the shape of the trunk's
    /// static lean ([`super::calibrate`], step 6); 1 as built.
    pub air_scale: f32,
    /// The trunk's first-mode frequency from the wood, Hz ([`crate::physics::stem_frequencies`]).
    pub sway_hz: f32,
    /// Factor on the drag of the leaves and side stems, 0–1, so that the crown drags no more
    /// than as a body ([`crate::physics::crown_shelter`]); the trunk's bark is not sheltered.
    pub shelter: f32,
}

struct Builder {
    layout: HsmLayout,
    /// Per cluster: (ring centre, first particle) of each of its rings.
    rings: Vec<Vec<(Vec3, u32)>>,
    /// Per particle: position (before the rest offsets are known).
    pos: Vec<Vec3>,
}

impl Builder {
    fn particle(&mut self, p: Vec3, mass: f32, kd: f32, free: bool, owner: u32) -> u32 {
        let i = self.pos.len() as u32;
        self.pos.push(p);
        self.layout.mass.push(mass);
        self.layout.rest.push([p.x, p.y, p.z, kd]);
        self.layout.free.push(if free { 1.0 } else { 0.0 });
        self.layout.owner.push(owner);
        i
    }

    fn nearest_ring(&self, cluster: u32, p: Vec3) -> (Vec3, u32) {
        *self.rings[cluster as usize]
            .iter()
            .min_by(|a, b| (a.0 - p).length_squared().total_cmp(&(b.0 - p).length_squared()))
            .expect("a cluster has rings")
    }
}

impl HsmLayout {
    /// Clusters for every segment and leaf of `tree` (each segment followed by its leaves, so
    /// parents come before children). `max_clusters` keeps only the first clusters in that
    /// order — still a whole tree, grown from the root — for benchmarks at set sizes.
    pub fn new(tree: &Tree, params: &HsmParams, max_clusters: Option<usize>) -> Result<Self, HsmError> {
        params.check()?;
        let s = &tree.segments;
        let l = &tree.leaves;
        let k = params.ring_size as usize;
        let rings = params.rings as usize;
        let total_clusters = (s.len() + l.len()).min(max_clusters.unwrap_or(usize::MAX));
        let needed = total_clusters.saturating_mul((3 * rings + params.leaf_particles as usize) * k.max(1));
        if needed > MAX_PARTICLES {
            return Err(HsmError::TooLarge { what: "slots", needed, limit: MAX_PARTICLES });
        }
        let mut b = Builder {
            layout: HsmLayout {
                info: Vec::with_capacity(total_clusters),
                clusters: Vec::with_capacity(total_clusters),
                children: Vec::new(),
                slots: Vec::new(),
                rest: Vec::new(),
                mass: Vec::new(),
                free: Vec::new(),
                owner: Vec::new(),
                member_offset: Vec::new(),
                member: Vec::new(),
                segment_cluster: vec![NONE; s.len()],
                max_children: 0,
                rate_scale: 1.0,
                load_scale: 1.0,
                air_scale: 1.0,
                sway_hz: crate::physics::stem_frequencies(tree, params.min_radius).hz(0),
                shelter: crate::physics::crown_shelter(tree, params.drag, params.leaf_drag),
            },
            rings: Vec::with_capacity(total_clusters),
            pos: Vec::new(),
        };
        let mut slot_particles: Vec<u32> = Vec::new();
        let mut parents: Vec<u32> = Vec::with_capacity(total_clusters);
        // (K, μ) of a segment cluster; (k, 0) of a leaf.
        let mut stiffness: Vec<(f32, f32)> = Vec::with_capacity(total_clusters);
        let pi = std::f32::consts::PI;
        let r_mech = crate::physics::mechanical_radii(tree, params.min_radius);
        // Each leaf's petiole swing, as the closed form's (phases unused).
        let petioles = crate::leaves::LeafFlutter::new(tree, 0);
        // Leaves and side stems drag no more together than the crown as a body, as in the
        // other methods; the trunk's bark is not sheltered.
        let shelter = b.layout.shelter;
        #[allow(clippy::needless_range_loop)] // i indexes every per-segment array of the tree
        'segments: for i in 0..s.len() {
            if b.layout.info.len() >= total_clusters {
                break;
            }
            let c = b.layout.info.len() as u32;
            let len = s.length[i];
            let q = s.orientation[i];
            let own_rings = if s.parent[i] == NONE { rings } else { rings - 1 };
            let own = (own_rings * k) as f32;
            // Twig tips taper toward zero for looks; a living tip is never thinner than
            // `min_radius`, and a massless particle would simply blow away with the air.
            let floor = tree.wood.segment_mass(len, params.min_radius, params.min_radius);
            let m = s.mass[i].max(floor).max(1e-9) / own;
            let area = (s.radius_base[i].max(params.min_radius) + s.radius_tip[i].max(params.min_radius)) * len / own;
            let sheltered = if tree.stems.level[s.stem[i] as usize] == 0 { 1.0 } else { shelter };
            let kd = 0.5 * AIR_DENSITY * params.drag * params.drag_scale * sheltered * area / m;
            let slot_offset = slot_particles.len() as u32;
            let mut my_rings = Vec::with_capacity(rings);
            let parent_cluster =
                if s.parent[i] == NONE { NONE } else { b.layout.segment_cluster[s.parent[i] as usize] };
            if s.parent[i] != NONE {
                if parent_cluster == NONE {
                    continue 'segments; // parent dropped by truncation (cannot happen in order)
                }
                let (centre, first) = b.nearest_ring(parent_cluster, s.start[i]);
                if params.overlap >= 2 {
                    // The parent's whole segment: its head ring and its own rings.
                    for &(_, f) in &b.rings[parent_cluster as usize] {
                        slot_particles.extend(f..f + k as u32);
                    }
                } else {
                    slot_particles.extend(first..first + k as u32);
                }
                my_rings.push((centre, first));
            }
            for j in (rings - own_rings)..rings {
                let u = j as f32 / (rings - 1) as f32;
                let r = (s.radius_base[i] + (s.radius_tip[i] - s.radius_base[i]) * u).max(params.ring_ratio * len);
                let centre = s.start[i] + q * Vec3::new(0.0, u * len, 0.0);
                let twist = if j % 2 == 1 { pi / k as f32 } else { 0.0 };
                let first = b.pos.len() as u32;
                for p in 0..k {
                    let a = std::f32::consts::TAU * p as f32 / k as f32 + twist;
                    let x = centre + q * Vec3::new(r * a.cos(), 0.0, r * a.sin());
                    let fixed = s.parent[i] == NONE && j == 0;
                    b.particle(x, m, kd, !fixed, c);
                }
                slot_particles.extend(first..first + k as u32);
                my_rings.push((centre, first));
            }
            b.layout.segment_cluster[i] = c;
            b.rings.push(my_rings);
            b.layout.info.push(RawHsmClusterInfo {
                kind: kind::SEGMENT,
                source: i as u32,
                slot_offset,
                slot_count: slot_particles.len() as u32 - slot_offset,
            });
            parents.push(parent_cluster);
            // k from the joint's bending stiffness K = E·I/L: bending the cluster by θ
            // against its head ring stores ≈ ½ k μ r² θ² (μ the reduced mass of head ring
            // and the rest, r the tail ring's radius), so k = K / (μ r²).
            let head = if s.parent[i] == NONE {
                m * k as f32
            } else {
                b.layout.mass[b.rings[c as usize][0].1 as usize] * k as f32
            };
            let rest_mass = if s.parent[i] == NONE { m * ((rings - 1) * k) as f32 } else { own * m };
            let mu = head * rest_mass / (head + rest_mass);
            let joint = tree.wood.segment_stiffness(len, r_mech[i]) * params.stiffness_scale;
            stiffness.push((joint, mu));
            // This segment's leaves.
            let lo = tree.children.leaf_offset[i] as usize;
            for leaf in lo..lo + tree.children.leaf_count[i] as usize {
                if b.layout.info.len() >= total_clusters {
                    break 'segments;
                }
                let n = params.leaf_particles as usize;
                let (w, h) = (l.width[leaf], l.length[leaf]);
                let blade = std::f32::consts::FRAC_PI_4 * w * h;
                let m = (blade * tree.wood.leaf_areal_density).max(1e-9) / n as f32;
                let kd = 0.5 * AIR_DENSITY * params.leaf_drag * params.drag_scale * shelter * blade / n as f32 / m;
                let slot_offset = slot_particles.len() as u32;
                let (centre, first) = b.nearest_ring(c, l.position[leaf]);
                slot_particles.extend(first..first + k as u32);
                let lq = l.orientation[leaf];
                let first_own = b.pos.len() as u32;
                let leaf_cluster = b.layout.info.len() as u32;
                for p in 0..n {
                    // The tip, then points along the edge toward the base.
                    let local = if p == 0 {
                        Vec3::new(0.0, h, 0.0)
                    } else {
                        Vec3::new(0.5 * w, h * (1.0 - p as f32 / n as f32), 0.0)
                    };
                    b.particle(l.position[leaf] + lq * local, m, kd, true, leaf_cluster);
                }
                slot_particles.extend(first_own..first_own + n as u32);
                if !params.leaf_reaction {
                    // The ring carries the blade's mass and drag (its particles share them).
                    let (add, drag) = (m * n as f32 / k as f32, kd * m * n as f32 / k as f32);
                    for p in first as usize..first as usize + k {
                        let (m0, kd0) = (b.layout.mass[p], b.layout.rest[p][3]);
                        b.layout.mass[p] = m0 + add;
                        b.layout.rest[p][3] = (kd0 * m0 + drag) / (m0 + add);
                    }
                }
                b.rings.push(vec![(centre, first)]);
                b.layout.info.push(RawHsmClusterInfo {
                    kind: kind::LEAF,
                    source: leaf as u32,
                    slot_offset,
                    slot_count: slot_particles.len() as u32 - slot_offset,
                });
                parents.push(c);
                let omega = petioles.leaves.get(leaf).map_or(0.0, |m| m.omega);
                stiffness.push((omega * omega * params.leaf_stiffness, 0.0));
            }
        }
        if !params.leaf_reaction {
            // Rings that carry leaves weigh more: each segment's μ from the final masses.
            for (c, (_, mu)) in stiffness.iter_mut().enumerate() {
                if b.layout.info[c].kind == kind::SEGMENT {
                    let ring = |f: u32| b.layout.mass[f as usize] * k as f32;
                    let rings = &b.rings[c];
                    let head = ring(rings[0].1);
                    let rest: f32 = rings[1..].iter().map(|r| ring(r.1)).sum();
                    *mu = head * rest / (head + rest);
                }
            }
        }
        // Song's global level (Fig. 4): one more cluster per stem over all its segments'
        // rings (and the parent's shared ring), so a stem keeps its shape as a whole and
        // load reaches the root in a few substeps instead of one segment per substep.
        if params.stem_clusters {
            for st in 0..tree.stems.len() {
                let first = tree.stems.first_segment[st] as usize;
                let count = tree.stems.segment_count[st] as usize;
                let segs: Vec<u32> =
                    (first..first + count).map(|i| b.layout.segment_cluster[i]).take_while(|&c| c != NONE).collect();
                if segs.len() < 2 {
                    continue; // a one-segment stem is its segment's cluster already
                }
                let slot_offset = slot_particles.len() as u32;
                let mut kmin = f32::INFINITY;
                let mut mu = 0.0f32;
                for (n, &c) in segs.iter().enumerate() {
                    let rings = &b.rings[c as usize];
                    // The first segment brings its shared head ring too; later ones only
                    // their own rings (their head ring is the previous segment's tail).
                    for &(_, f) in &rings[if n == 0 { 0 } else { 1 }..] {
                        slot_particles.extend(f..f + k as u32);
                    }
                    let (kk, m) = stiffness[c as usize];
                    if kk < kmin {
                        kmin = kk;
                        mu = m;
                    }
                }
                b.layout.info.push(RawHsmClusterInfo {
                    kind: kind::STEM,
                    source: st as u32,
                    slot_offset,
                    slot_count: slot_particles.len() as u32 - slot_offset,
                });
                parents.push(segs[0]);
                stiffness.push((kmin, mu));
            }
        }
        let n_clusters = b.layout.info.len();
        let n_particles = b.pos.len();
        // Children lists (Fig. 8).
        let mut child_count = vec![0u32; n_clusters];
        for &p in &parents {
            if p != NONE {
                child_count[p as usize] += 1;
            }
        }
        let mut child_offset = vec![0u32; n_clusters];
        let mut acc = 0u32;
        for c in 0..n_clusters {
            child_offset[c] = acc;
            acc += child_count[c];
        }
        let mut children = vec![0u32; acc as usize];
        let mut fill = child_offset.clone();
        for (c, &p) in parents.iter().enumerate() {
            if p != NONE {
                children[fill[p as usize] as usize] = c as u32;
                fill[p as usize] += 1;
            }
        }
        // Rest centres of mass, offsets and Aqq⁻¹ (in f64: the inverse of a thin cluster's Aqq
        // is ill-conditioned).
        let mut slots = Vec::with_capacity(slot_particles.len());
        let mut clusters = Vec::with_capacity(n_clusters);
        for c in 0..n_clusters {
            let info = b.layout.info[c];
            let run = &slot_particles[info.slot_offset as usize..(info.slot_offset + info.slot_count) as usize];
            let mut msum = 0.0f64;
            let mut cm = DVec3::ZERO;
            for &p in run {
                let m = b.layout.mass[p as usize] as f64;
                msum += m;
                cm += b.pos[p as usize].as_dvec3() * m;
            }
            let cm = cm / msum;
            let mut aqq = DMat3::ZERO;
            for &p in run {
                let m = b.layout.mass[p as usize] as f64;
                // Aqq of the offsets as stored.
                let qf = (b.pos[p as usize].as_dvec3() - cm).as_vec3();
                let q = qf.as_dvec3();
                aqq += DMat3::from_cols(q * q.x, q * q.y, q * q.z) * m;
                slots.push(RawHsmSlot { q: qf.to_array(), particle: p });
            }
            let det = aqq.determinant();
            let scale = aqq.x_axis.x + aqq.y_axis.y + aqq.z_axis.z;
            let inv = if det.abs() > 1e-9 * scale.powi(3) { aqq.inverse().as_mat3() } else { Mat3::ZERO };
            let cmf = cm.as_vec3();
            // A segment's k = K / (μ ρ²), ρ² = tr(Aqq) / M its squared radius of gyration.
            let (kk, mu) = stiffness[c];
            let mut kc = if mu > 0.0 { kk / (mu * (scale / msum) as f32).max(1e-30) } else { kk };
            if info.kind == kind::LEAF {
                // The blade pulls its cluster's centre and R along as it swings, so its
                // spring holds only a fraction ρ of the swing: the rate ω² / ρ swings it at
                // the petiole's ω (ρ at least 0.02; see `swing_fraction`).
                let ring = (info.slot_count - params.leaf_particles) as usize;
                let leaf = info.source as usize;
                let pitch = (l.orientation[leaf] * Vec3::X).as_dvec3();
                let at = |p: u32| (b.pos[p as usize].as_dvec3(), b.layout.mass[p as usize] as f64);
                let rho = swing_fraction(run.iter().map(|&p| at(p)), ring, l.position[leaf].as_dvec3(), pitch, aqq);
                kc /= (rho as f32).max(0.02);
            }
            // A leaf's swing ω (its rate before the share above), the centre of its band of air.
            let omega = if info.kind == kind::LEAF { kk.max(0.0).sqrt() } else { 0.0 };
            clusters.push(RawHsmCluster {
                rest_cm: [cmf.x, cmf.y, cmf.z, kc],
                parent: parents[c],
                child_offset: child_offset[c],
                child_count: child_count[c],
                mass: msum as f32,
                aqq_inv: [
                    inv.x_axis.extend(0.0).into(),
                    inv.y_axis.extend(omega).into(),
                    inv.z_axis.extend(0.0).into(),
                ],
            });
        }
        path_bounds(&mut clusters);
        // Each particle's (cluster, slot) pairs, in cluster order; without the leaves'
        // reaction a ring takes no pull from its leaves' clusters.
        let info = &b.layout.info;
        let owner = &b.layout.owner;
        let pulls = |c: usize, p: usize| params.leaf_reaction || info[c].kind != kind::LEAF || owner[p] == c as u32;
        let mut count = vec![0u32; n_particles + 1];
        for (c, i) in info.iter().enumerate() {
            for s in &slots[i.slot_offset as usize..(i.slot_offset + i.slot_count) as usize] {
                count[s.particle as usize + 1] += u32::from(pulls(c, s.particle as usize));
            }
        }
        for i in 0..n_particles {
            count[i + 1] += count[i];
        }
        let mut member = vec![RawHsmMember { q: [0.0; 3], cluster: 0 }; count[n_particles] as usize];
        let mut fill = count.clone();
        for (c, info) in info.iter().enumerate() {
            for sl in info.slot_offset..info.slot_offset + info.slot_count {
                let p = slots[sl as usize].particle as usize;
                if !pulls(c, p) {
                    continue;
                }
                member[fill[p] as usize] = RawHsmMember { q: slots[sl as usize].q, cluster: c as u32 };
                fill[p] += 1;
            }
        }
        let mut layout = b.layout;
        layout.max_children = child_count.iter().copied().max().unwrap_or(0);
        layout.children = children;
        layout.slots = slots;
        layout.clusters = clusters;
        layout.member_offset = count;
        layout.member = member;
        Ok(layout)
    }

    /// `copies` copies of this layout side by side, `spacing` metres apart along x (Song's
    /// Table 3: ten trees). Segment clusters refer to the first copy's tree.
    pub fn forest(&self, copies: usize, spacing: f32) -> Result<Self, HsmError> {
        let copies = copies.max(1);
        let needed = self.slots.len().saturating_mul(copies);
        if needed > MAX_PARTICLES {
            return Err(HsmError::TooLarge { what: "slots", needed, limit: MAX_PARTICLES });
        }
        let (nc, np, ns, nch) =
            (self.info.len() as u32, self.rest.len() as u32, self.slots.len() as u32, self.children.len() as u32);
        let mut out = self.clone();
        for k in 1..copies as u32 {
            let dx = spacing * k as f32;
            out.info.extend(self.info.iter().map(|i| RawHsmClusterInfo { slot_offset: i.slot_offset + k * ns, ..*i }));
            out.clusters.extend(self.clusters.iter().map(|c| {
                let mut c = *c;
                c.rest_cm[0] += dx;
                c.parent = if c.parent == NONE { NONE } else { c.parent + k * nc };
                c.child_offset += k * nch;
                c
            }));
            out.children.extend(self.children.iter().map(|c| c + k * nc));
            out.slots.extend(self.slots.iter().map(|s| RawHsmSlot { particle: s.particle + k * np, ..*s }));
            out.rest.extend(self.rest.iter().map(|r| [r[0] + dx, r[1], r[2], r[3]]));
            out.mass.extend_from_slice(&self.mass);
            out.free.extend_from_slice(&self.free);
            out.owner.extend(self.owner.iter().map(|o| o + k * nc));
            let base = *out.member_offset.last().expect("offsets");
            out.member_offset.extend(self.member_offset[1..].iter().map(|o| o + base));
            out.member.extend(self.member.iter().map(|m| RawHsmMember { cluster: m.cluster + k * nc, ..*m }));
        }
        Ok(out)
    }

    /// Multiplies every segment and stem cluster's rate by `s` (leaves keep theirs) and
    /// recomputes the path bounds; [`Self::rate_scale`] keeps the product.
    pub fn scale_rates(&mut self, s: f32) {
        for (c, info) in self.clusters.iter_mut().zip(&self.info) {
            if info.kind != kind::LEAF {
                c.rest_cm[3] *= s;
            }
        }
        path_bounds(&mut self.clusters);
        self.rate_scale *= s;
    }

    /// Multiplies every particle's drag factor by `s`.
    pub fn scale_loads(&mut self, s: f32) {
        for r in &mut self.rest {
            r[3] *= s;
        }
        self.load_scale *= s;
    }

    /// Multiplies the rates of each stem's segment clusters and stem cluster by its entry of
    /// `factors` (one per stem of the tree; leaves keep theirs) and recomputes the path bounds.
    pub fn scale_stem_rates(&mut self, tree: &Tree, factors: &[f32]) {
        for (c, info) in self.clusters.iter_mut().zip(&self.info) {
            let stem = match info.kind {
                kind::SEGMENT => tree.segments.stem[info.source as usize],
                kind::STEM => info.source,
                _ => continue,
            };
            c.rest_cm[3] *= factors.get(stem as usize).copied().unwrap_or(1.0);
        }
        path_bounds(&mut self.clusters);
    }

    /// Number of clusters.
    pub fn cluster_count(&self) -> usize {
        self.info.len()
    }

    /// Number of (distinct) particles.
    pub fn particle_count(&self) -> usize {
        self.rest.len()
    }

    /// Stage 1's share of [`Self::bytes_per_step`]: info, clusters, cluster state (r/w);
    /// per slot the record and the particle's displacement + mass.
    pub fn stage1_bytes(&self) -> usize {
        self.info.len() * (16 + 80 + 2 * 96) + self.slots.len() * (16 + 16)
    }

    /// Bytes the stages must read and write per substep, each array counted once per
    /// stage that touches it (a lower bound on the traffic: gathered values are counted at
    /// their size, not their cache lines), for bandwidth figures. `fused`: stages 3 and 4
    /// in one pass.
    pub fn bytes_per_step(&self, fused: bool) -> usize {
        let (p, m) = (self.rest.len(), self.member.len());
        let stage1 = self.stage1_bytes();
        // Stage 3: offsets, goal written; per member: the record (q, cluster), the
        // cluster's transform and α.
        let members = m * (16 + 52);
        let stage3 = p * (4 + 16) + members;
        // Stage 4: displacement, velocity (r/w), owner, goal, owner's wind.
        let stage4 = p * (2 * 16 + 2 * 16 + 4 + 16 + 16);
        if fused {
            // One pass: no goal written or read.
            p * (4 + 2 * 16 + 2 * 16 + 4 + 16) + members + stage1
        } else {
            stage1 + stage3 + stage4
        }
    }
}

/// Each cluster's rate bound k̂: the smallest rate on its path to the root, itself included
/// (clusters come after their parents, so one pass carries it down). Stage 1 lets a
/// cluster's weight pass the hold only up to k̂ h² (see `kernels::MAX_WEIGHT`).
fn path_bounds(clusters: &mut [RawHsmCluster]) {
    for c in 0..clusters.len() {
        let p = clusters[c].parent;
        let own = clusters[c].rest_cm[3];
        clusters[c].aqq_inv[0][3] = if p == NONE { own } else { own.min(clusters[p as usize].aqq_inv[0][3]) };
    }
}

/// The fraction of a leaf blade's swing that its cluster's spring holds: shape matching
/// linearised about rest. The blade's particles (after the first `ring` of `particles`,
/// position and mass) turn by a small angle about `axis` through the attachment `attach`;
/// the ring stays (its segment holds it). The cluster's centre moves by the blade's share of
/// the mass, `Δc`, and its R by the Newton step of the optimal rotation at rest,
/// `θ = (tr(A) I − A)⁻¹ Σ m q × (u − Δc)` (`A` = `aqq`, Σ m q qᵀ), so each particle's goal
/// moves by `θ × q + Δc`. The spring's pull on the blade, `Σ m (u − g)·s`, over its inertia
/// in the swing, `Σ m |s|²` (`s = axis × (x − attach)`, `u = s` per unit angle), is the
/// fraction ρ: the blade swings at `√(k ρ)` under rate `k`. 1 when the ring is rigid and
/// heavy; small when the blade carries most of the cluster's mass.
pub fn swing_fraction(
    particles: impl Iterator<Item = (DVec3, f64)>,
    ring: usize,
    attach: DVec3,
    axis: DVec3,
    aqq: DMat3,
) -> f64 {
    let parts: Vec<(DVec3, f64)> = particles.collect();
    let mass: f64 = parts.iter().map(|p| p.1).sum();
    let cm = parts.iter().map(|p| p.0 * p.1).sum::<DVec3>() / mass.max(1e-300);
    let swing = |i: usize, x: DVec3| if i < ring { DVec3::ZERO } else { axis.cross(x - attach) };
    let shift = parts.iter().enumerate().map(|(i, p)| swing(i, p.0) * p.1).sum::<DVec3>() / mass.max(1e-300);
    let torque: DVec3 = parts.iter().enumerate().map(|(i, p)| (p.0 - cm).cross(swing(i, p.0) - shift) * p.1).sum();
    let h = DMat3::from_diagonal(DVec3::splat(aqq.x_axis.x + aqq.y_axis.y + aqq.z_axis.z)) - aqq;
    let theta = if h.determinant().abs() > 1e-300 { h.inverse() * torque } else { DVec3::ZERO };
    let (mut pull, mut inertia) = (0.0, 0.0);
    for (i, p) in parts.iter().enumerate().skip(ring) {
        let s = swing(i, p.0);
        let goal = theta.cross(p.0 - cm) + shift;
        pull += (s - goal).dot(s) * p.1;
        inertia += s.length_squared() * p.1;
    }
    if inertia > 0.0 { (pull / inertia).clamp(0.0, 1.0) } else { 1.0 }
}
