//! Geometry every frame (Akagi & Kitajima §2.2–2.4, §3): tubes around the posed skeleton and
//! a polygon per leaf, regenerated from the pose each frame with a fixed topology.
//!
//! # Tubes (§2.2)
//! Every stem is one tube. Each segment contributes `samples` cross-sections along a cubic
//! **Hermite centreline** between its posed end points; the tangents at a joint are the
//! normalised mean of the two segments' axes there (scaled by the segment length), so the
//! centreline is C¹ through joints. A cross-section is the unit n-gon (`sides`, 8 by
//! default) placed at the centreline point, oriented by the **slerp** of the joint frames at
//! the segment's ends (a joint's frame is the half-way slerp of the two segments meeting
//! there) and sized by the linear interpolation of base and tip radius. The last ring of one
//! segment *is* the first ring of the next (one ring per joint), so the surface is continuous
//! by construction and normals and bark texture coordinates run on along the stem:
//! `u` around (0…1, a duplicated seam column), `v` = rest arc length / (2π × the stem's base
//! radius), so bark texels stay square.
//!
//! # Displacement (§2.3)
//! On segments thicker than [`MeshParams::displace_min_radius`] ring vertices are pushed
//! along their normal by a procedural bark relief (ridges along the stem broken by noise),
//! periodic around the stem so the seam stays closed, and zero at the stem's base and tip
//! rings so joints with parents stay closed. Where such a band of quads between two rings
//! has an edge longer than [`MeshParams::subdivide_min_edge`] (at rest), its triangles are
//! **subdivided at the edge midpoints** (each into four) and every midpoint vertex is
//! displaced along its normal by the relief sampled there, less what the corners already
//! carry: `p = (pₐ + p_b)/2 + n · s · (relief(mid) − (relief(a) + relief(b))/2)` with
//! `s` = depth × radius. A midpoint on a ring edge shared with a band that is not subdivided
//! gets `s = 0` — exactly the edge's midpoint — so the surface has no cracks. The midpoint
//! vertices ([`RawDetail`]) follow the ring vertices in the bark buffer and are computed from
//! them by `mesh::mesh_detail` ↔ `mesh_detail.wgsl`, one per invocation.
//!
//! # Leaves (§2.4)
//! From each leaf point a leaf polygon: the unit n-gon as two half-circles scaled by the
//! blade's width and length (an ellipse from the attachment point to the tip), fanned from
//! its centre, carried by its segment's rotation.
//!
//! # Data
//! The topology (index buffers, the ring table) is built once per tree by [`MeshLayout`];
//! per frame only vertices are computed, from the pose as the GPU pose seam stores it
//! (joint positions and accumulated rotations `D`, see [`crate::pose`]). The CPU
//! references `mesh::mesh_tubes` and `mesh::mesh_leaves` are the twins of
//! `sylva-gpu`'s `mesh_tubes.wgsl` and `mesh_leaves.wgsl` (one invocation per vertex).

pub mod deformer;
mod detail;
mod leaves;
pub mod skin;
mod skin_vertices;
mod skjermo_deform;
mod tubes;
mod uv;
mod vertex;

pub use deformer::{DeformLayout, DeformerParams, RawDeformRing, RawDeformShape, deform_radius};
pub use detail::mesh_detail;
pub use leaves::mesh_leaves;
pub use skin::{RawSkin, RawSkinInfo, SkinLayout};
pub use skin_vertices::skin_vertices;
pub use skjermo_deform::skjermo_deform;
pub use tubes::mesh_tubes;
pub use vertex::{RawVertex, Uv, oct_decode, oct_encode};

use crate::model::{NONE, RawLeaf, RawSegment, Tree};
use crate::pose::Pose;
use bytemuck::{Pod, Zeroable};
use glam::Quat;

/// Meshing parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshParams {
    /// Sides of each tube cross-section. Default 8, Akagi's choice: round enough at a few
    /// pixels across, 16 triangles per ring segment.
    pub sides: u32,
    /// Cross-sections per segment (≥ 1). Default 3: enough for the Hermite curve to read
    /// as a bend at joints without multiplying vertices.
    pub samples: u32,
    /// Sides of the leaf polygon. Default 8 (four per half-circle).
    pub leaf_sides: u32,
    /// Mesh the leaves.
    pub leaves: bool,
    /// Bark relief depth as a fraction of the local radius. Default 0.06: visible ridges on
    /// a trunk without changing its silhouette much. 0 turns displacement off.
    pub bark_depth: f32,
    /// Segments with a base radius below this (m) are not displaced. Default 0.04 m: the
    /// trunk and thick branches.
    pub displace_min_radius: f32,
    /// Displaced bands with an edge longer than this at rest (m) are subdivided at their
    /// edge midpoints. Default 0.08 m: the trunk's and thick branches' long quads get the
    /// relief in between their rings, thin ones stay as they are. Infinity turns it off.
    pub subdivide_min_edge: f32,
    /// Stems whose base radius is below this (m), and every stem on them, get no tube
    /// (their leaves are still meshed). Default 0: every stem. Game assets leave the twigs
    /// to their leaf cards.
    pub min_stem_radius: f32,
}

impl Default for MeshParams {
    fn default() -> Self {
        Self {
            sides: 8,
            samples: 3,
            leaf_sides: 8,
            leaves: true,
            bark_depth: 0.06,
            displace_min_radius: 0.04,
            subdivide_min_edge: 0.08,
            min_stem_radius: 0.0,
        }
    }
}

/// Leaf `index`'s draw in 0…1 for thinning ([`MeshLayout::thin_leaves`]).
fn leaf_draw(key: u64, index: u64) -> f32 {
    crate::rng::hash_unit(crate::rng::child_key(key, index)) as f32
}

/// Which stems get a tube: a stem at least `min_radius` thick at its base, on a stem that
/// gets one (stems are in topological order: parents first).
pub fn meshed_stems(tree: &Tree, min_radius: f32) -> Vec<bool> {
    let st = &tree.stems;
    let mut meshed = vec![false; st.len()];
    for k in 0..st.len() {
        let parent_meshed = st.parent[k] == NONE || meshed[st.parent[k] as usize];
        meshed[k] = parent_meshed && tree.segments.radius_base[st.first_segment[k] as usize] >= min_radius;
    }
    meshed
}

/// Largest sides / samples accepted (bounds memory on user input).
pub const MAX_SIDES: u32 = 64;
/// Smallest ring radius as a fraction of its stem's base radius.
pub const MIN_RADIUS_FRACTION: f32 = 0.1;
/// Largest samples per segment accepted.
pub const MAX_SAMPLES: u32 = 32;

/// One cross-section of a tube, 32 bytes. WGSL: `struct Ring` in `mesh.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawRing {
    /// Segment the ring lies on.
    pub segment: u32,
    /// Previous segment of the same stem ([`NONE`] at the stem's base).
    pub prev: u32,
    /// Next segment of the same stem ([`NONE`] at the stem's tip).
    pub next: u32,
    /// Parameter along the segment, 0…1.
    pub t: f32,
    /// Bark texture coordinate along the stem.
    pub v: f32,
    /// Bark relief depth, fraction of the radius (0 = not displaced).
    pub relief: f32,
    /// Seed of the stem's relief pattern.
    pub stem_seed: u32,
    /// Rest radius of the ring, m: base-to-tip interpolation on the segment, never below
    /// [`MIN_RADIUS_FRACTION`] of the stem's base radius (a stem ending in a point would
    /// give degenerate triangles).
    pub radius: f32,
}

/// Frame constants, 32 bytes. WGSL: `struct MeshInfo` in `mesh.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawMeshInfo {
    /// Tube sides.
    pub sides: u32,
    /// Number of rings.
    pub rings: u32,
    /// Leaf polygon sides.
    pub leaf_sides: u32,
    /// Number of leaves.
    pub leaves: u32,
    /// Number of midpoint vertices of subdivided bands.
    pub details: u32,
    /// Padding.
    pub _pad: [u32; 3],
}

/// A midpoint vertex of a subdivided band (§2.3), 32 bytes. WGSL: `struct Detail` in
/// `mesh.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawDetail {
    /// First end of the edge (a ring vertex).
    pub a: u32,
    /// Second end of the edge (a ring vertex).
    pub b: u32,
    /// Ring whose segment the midpoint lies on (for skinning).
    pub ring: u32,
    /// Parameter along that segment, 0…1 (for skinning).
    pub t: f32,
    /// Relief amplitude at the midpoint, m (depth × radius; 0 on a boundary edge).
    pub scale: f32,
    /// Seed of the stem's relief pattern.
    pub stem_seed: u32,
    /// Padding.
    pub _pad: [u32; 2],
}

/// The fixed topology of one tree's mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshLayout {
    /// Parameters it was built with.
    pub params: MeshParams,
    /// Ring table (per stem, base to tip).
    pub rings: Vec<RawRing>,
    /// Midpoint vertices of subdivided bands; bark vertex `rings × (sides + 1) + d`.
    pub details: Vec<RawDetail>,
    /// Bark triangle indices into the tube vertices.
    pub tube_indices: Vec<u32>,
    /// Leaf triangle indices into the leaf vertices.
    pub leaf_indices: Vec<u32>,
    /// Packed segments (rest data the kernels read).
    pub segments: Vec<RawSegment>,
    /// Packed leaves.
    pub leaves: Vec<RawLeaf>,
    /// Leaves of the tree(s) it was built from: the length of the leaf rotations it reads
    /// ([`crate::pose::SeamPose::leaf`], indexed by [`RawLeaf::index`]).
    pub leaf_slots: u32,
}

/// One frame's vertices.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshFrame {
    /// Bark vertices (`rings × (sides + 1)`, then one per [`RawDetail`]).
    pub tubes: Vec<RawVertex>,
    /// Leaf vertices (`leaves × (leaf_sides + 1)`).
    pub leaves: Vec<RawVertex>,
}

/// Errors building a mesh layout.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// A parameter is out of range.
    #[error("mesh parameter `{field}` = {value}: expected {expected}")]
    Param { field: &'static str, value: String, expected: &'static str },
    /// The mesh would be too large.
    #[error("the mesh would have {vertices} vertices; the limit is {limit} (lower `sides`/`samples` or the tree size)")]
    TooLarge { vertices: u64, limit: u64 },
}

/// Largest number of vertices of one mesh (tubes or leaves): indices are u32 and a GPU
/// storage binding holds 128 MiB on the smallest device Sylva supports (4 Mi × 16 B fits).
pub const MAX_VERTICES: u64 = 4 << 20;

impl MeshLayout {
    /// Builds the topology for `tree`.
    pub fn new(tree: &Tree, params: MeshParams) -> Result<Self, MeshError> {
        let bad = |field, value: String, expected| Err(MeshError::Param { field, value, expected });
        if !(3..=MAX_SIDES).contains(&params.sides) {
            return bad("sides", params.sides.to_string(), "3 to 64");
        }
        if !(1..=MAX_SAMPLES).contains(&params.samples) {
            return bad("samples", params.samples.to_string(), "1 to 32");
        }
        if !(3..=MAX_SIDES).contains(&params.leaf_sides) {
            return bad("leaf_sides", params.leaf_sides.to_string(), "3 to 64");
        }
        if !(params.bark_depth.is_finite() && (0.0..=0.5).contains(&params.bark_depth)) {
            return bad("bark_depth", params.bark_depth.to_string(), "0 to 0.5");
        }
        if params.subdivide_min_edge.is_nan() || params.subdivide_min_edge <= 0.0 {
            return bad("subdivide_min_edge", params.subdivide_min_edge.to_string(), "a positive length in m");
        }
        if !(params.min_stem_radius.is_finite() && params.min_stem_radius >= 0.0) {
            return bad("min_stem_radius", params.min_stem_radius.to_string(), "a length ≥ 0 in m");
        }
        let s = &tree.segments;
        let st = &tree.stems;
        let meshed = meshed_stems(tree, params.min_stem_radius);
        let ring_count: u64 =
            (0..st.len()).filter(|&k| meshed[k]).map(|k| st.segment_count[k] as u64 * params.samples as u64 + 1).sum();
        let tube_vertices = ring_count * (params.sides as u64 + 1);
        let leaf_vertices = if params.leaves { tree.leaves.len() as u64 * (params.leaf_sides as u64 + 1) } else { 0 };
        for v in [tube_vertices, leaf_vertices] {
            if v > MAX_VERTICES {
                return Err(MeshError::TooLarge { vertices: v, limit: MAX_VERTICES });
            }
        }
        let mut rings = Vec::with_capacity(ring_count as usize);
        let mut tube_indices = Vec::new();
        let mut details = Vec::new();
        let sides = params.sides;
        for k in (0..st.len()).filter(|&k| meshed[k]) {
            let first = st.first_segment[k] as usize;
            let n = st.segment_count[k] as usize;
            let base_radius = s.radius_base[first].max(1e-4);
            let v_scale = 1.0 / (std::f32::consts::TAU * base_radius);
            let first_ring = rings.len() as u32;
            let mut arc = 0.0f32;
            for i in first..first + n {
                let prev = if i > first { (i - 1) as u32 } else { NONE };
                let next = if i + 1 < first + n { (i + 1) as u32 } else { NONE };
                let relief = if s.radius_base[i] >= params.displace_min_radius { params.bark_depth } else { 0.0 };
                let last_j = if next == NONE { params.samples } else { params.samples - 1 };
                for j in 0..=last_j {
                    let t = j as f32 / params.samples as f32;
                    // No relief on the stem's first and last rings: they meet the parent
                    // and close the tip.
                    let edge = (i == first && j == 0) || (next == NONE && j == params.samples);
                    rings.push(RawRing {
                        segment: i as u32,
                        prev,
                        next,
                        t,
                        v: (arc + t * s.length[i]) * v_scale,
                        relief: if edge { 0.0 } else { relief },
                        stem_seed: (k as u32).wrapping_mul(0x9e37_79b9) ^ tree.seed as u32,
                        radius: (s.radius_base[i] + (s.radius_tip[i] - s.radius_base[i]) * t)
                            .max(MIN_RADIUS_FRACTION * base_radius),
                    });
                }
                arc += s.length[i];
            }
            let ring_end = rings.len() as u32;
            let stride = sides + 1;
            // §2.3: which bands (ring r → r + 1) are subdivided.
            let split: Vec<bool> = (first_ring..ring_end - 1)
                .map(|r| {
                    let (lo, hi) = (&rings[r as usize], &rings[r as usize + 1]);
                    let around = std::f32::consts::TAU * lo.radius.max(hi.radius) / sides as f32;
                    let along = s.length[lo.segment as usize] / params.samples as f32;
                    lo.relief > 0.0 && hi.relief > 0.0 && around.max(along) > params.subdivide_min_edge
                })
                .collect();
            let detail_base = ring_count as u32 * stride;
            for r in first_ring..ring_end - 1 {
                let band = (r - first_ring) as usize;
                if !split[band] {
                    for j in 0..sides {
                        let a = r * stride + j;
                        let b = a + 1;
                        let c = a + stride;
                        let d = c + 1;
                        tube_indices.extend_from_slice(&[a, c, d, a, d, b]);
                    }
                    continue;
                }
                let (lo, hi) = (rings[r as usize], rings[r as usize + 1]);
                let t_hi = if hi.segment == lo.segment { hi.t } else { 1.0 };
                let inner = lo.relief * 0.5 * (lo.radius + hi.radius);
                // Ring-edge midpoints are displaced only where the band across the ring is
                // subdivided too (else they stay on the straight edge: no crack).
                let below = band > 0 && split[band - 1];
                let above = band + 1 < split.len() && split[band + 1];
                let mut push = |a: u32, b: u32, ring: u32, t: f32, scale: f32| {
                    details.push(RawDetail { a, b, ring, t, scale, stem_seed: lo.stem_seed, _pad: [0; 2] });
                    detail_base + details.len() as u32 - 1
                };
                let ab: Vec<u32> = (0..sides)
                    .map(|j| {
                        let a = r * stride + j;
                        push(a, a + 1, r, lo.t, if below { lo.relief * lo.radius } else { 0.0 })
                    })
                    .collect();
                let cd: Vec<u32> = (0..sides)
                    .map(|j| {
                        let c = (r + 1) * stride + j;
                        push(c, c + 1, r + 1, hi.t, if above { hi.relief * hi.radius } else { 0.0 })
                    })
                    .collect();
                let t_mid = 0.5 * (lo.t + t_hi);
                let ac: Vec<u32> =
                    (0..=sides).map(|k| push(r * stride + k, (r + 1) * stride + k, r, t_mid, inner)).collect();
                let ad: Vec<u32> =
                    (0..sides).map(|j| push(r * stride + j, (r + 1) * stride + j + 1, r, t_mid, inner)).collect();
                for j in 0..sides as usize {
                    let a = r * stride + j as u32;
                    let (b, c) = (a + 1, a + stride);
                    let d = c + 1;
                    let (mab, mcd, mac, mbd, mad) = (ab[j], cd[j], ac[j], ac[j + 1], ad[j]);
                    tube_indices.extend_from_slice(&[
                        // (a, c, d) in four
                        a, mac, mad, mac, c, mcd, mad, mcd, d, mac, mcd, mad, //
                        // (a, d, b) in four
                        a, mad, mab, mad, d, mbd, mab, mbd, b, mad, mbd, mab,
                    ]);
                }
                let vertices = ring_count * stride as u64 + details.len() as u64;
                if vertices > MAX_VERTICES {
                    return Err(MeshError::TooLarge { vertices, limit: MAX_VERTICES });
                }
            }
        }
        let mut leaf_indices = Vec::new();
        if params.leaves {
            let stride = params.leaf_sides + 1;
            for l in 0..tree.leaves.len() as u32 {
                let c = l * stride;
                for j in 0..params.leaf_sides {
                    let a = c + 1 + j;
                    let b = c + 1 + (j + 1) % params.leaf_sides;
                    leaf_indices.extend_from_slice(&[c, a, b]);
                }
            }
        }
        Ok(Self {
            params,
            rings,
            details,
            tube_indices,
            leaf_indices,
            segments: tree.raw_segments(),
            leaves: if params.leaves { tree.raw_leaves() } else { Vec::new() },
            leaf_slots: tree.leaves.len() as u32,
        })
    }

    /// Several trees' layouts as one mesh (a forest in one dispatch): segment, ring and
    /// vertex indices offset; the pose buffers are the trees' concatenated in the same
    /// order. Every layout must have the same sides and leaf sides.
    pub fn concat(layouts: &[&MeshLayout]) -> Result<Self, MeshError> {
        let first = layouts.first().ok_or(MeshError::Param {
            field: "layouts",
            value: "none".into(),
            expected: "at least one layout",
        })?;
        let params = first.params;
        let total_ring_vertices: u32 = layouts.iter().map(|l| l.rings.len() as u32).sum::<u32>() * (params.sides + 1);
        let mut out = MeshLayout {
            params,
            rings: Vec::new(),
            details: Vec::new(),
            tube_indices: Vec::new(),
            leaf_indices: Vec::new(),
            segments: Vec::new(),
            leaves: Vec::new(),
            leaf_slots: 0,
        };
        for l in layouts {
            if (l.params.sides, l.params.leaf_sides) != (params.sides, params.leaf_sides) {
                return Err(MeshError::Param {
                    field: "sides",
                    value: l.params.sides.to_string(),
                    expected: "the same sides and leaf sides in every layout of a forest",
                });
            }
            let seg = out.segments.len() as u32;
            let shift = |i: u32| if i == NONE { NONE } else { i + seg };
            // Bark vertices are [every ring's][every detail]: ring vertices shift by the
            // rings before, midpoints move behind all rings.
            let (rings_before, details_before) = (out.rings.len() as u32, out.details.len() as u32);
            let ring_vertices = l.rings.len() as u32 * (params.sides + 1);
            let ring_shift = rings_before * (params.sides + 1);
            let remap = move |i: u32| {
                if i < ring_vertices {
                    i + ring_shift
                } else {
                    total_ring_vertices + details_before + (i - ring_vertices)
                }
            };
            let lv = out.leaf_vertex_count() as u32;
            out.rings.extend(l.rings.iter().map(|r| RawRing {
                segment: r.segment + seg,
                prev: shift(r.prev),
                next: shift(r.next),
                ..*r
            }));
            out.details.extend(l.details.iter().map(|d| RawDetail {
                a: d.a + ring_shift,
                b: d.b + ring_shift,
                ring: d.ring + rings_before,
                ..*d
            }));
            out.tube_indices.extend(l.tube_indices.iter().map(|&i| remap(i)));
            out.leaf_indices.extend(l.leaf_indices.iter().map(|i| i + lv));
            out.segments.extend(l.segments.iter().map(|s| RawSegment { parent: shift(s.parent), ..*s }));
            let slots = out.leaf_slots;
            out.leaves.extend(l.leaves.iter().map(|f| RawLeaf {
                segment: f.segment + seg,
                index: f.index + slots,
                ..*f
            }));
            out.leaf_slots += l.leaf_slots;
        }
        for v in [out.tube_vertex_count() as u64, out.leaf_vertex_count() as u64] {
            if v > MAX_VERTICES {
                return Err(MeshError::TooLarge { vertices: v, limit: MAX_VERTICES });
            }
        }
        Ok(out)
    }

    /// Keeps about `keep` (0…1] of the leaves — each leaf by a hash of its index and
    /// `seed`, so the choice is stable — and scales the kept blades by `1 / √keep` in width
    /// and length, so the crown's leaf area (its look from afar) stays the same. For
    /// level-of-detail meshes.
    pub fn thin_leaves(&mut self, keep: f32, seed: u64) -> Result<(), MeshError> {
        if !(keep.is_finite() && keep > 0.0 && keep <= 1.0) {
            return Err(MeshError::Param {
                field: "leaf_keep",
                value: keep.to_string(),
                expected: "more than 0, at most 1",
            });
        }
        if keep == 1.0 {
            return Ok(());
        }
        let grow = 1.0 / keep.sqrt();
        let key = crate::rng::mix64(seed ^ 0x1eaf);
        let mut index = 0u64;
        self.leaves.retain(|_| {
            index += 1;
            leaf_draw(key, index) < keep
        });
        for l in &mut self.leaves {
            l.width *= grow;
            l.length *= grow;
        }
        let stride = self.params.leaf_sides + 1;
        let sides = self.params.leaf_sides;
        self.leaf_indices = (0..self.leaves.len() as u32)
            .flat_map(|l| {
                (0..sides).flat_map(move |j| [l * stride, l * stride + 1 + j, l * stride + 1 + (j + 1) % sides])
            })
            .collect();
        Ok(())
    }

    /// The `leaf_keep` at which [`MeshLayout::thin_leaves`] keeps exactly `count` of
    /// `leaves` leaves with `seed` (1 when `count ≥ leaves`; draws that tie keep fewer).
    pub fn leaf_keep_for(count: usize, leaves: usize, seed: u64) -> f32 {
        if count >= leaves {
            return 1.0;
        }
        let key = crate::rng::mix64(seed ^ 0x1eaf);
        let mut draws: Vec<f32> = (1..=leaves as u64).map(|i| leaf_draw(key, i)).collect();
        draws.sort_by(f32::total_cmp);
        // `draw < keep` holds for exactly the `count` smallest; a keep of 0 is refused.
        draws[count].max(f32::MIN_POSITIVE)
    }

    /// Frame constants for the kernels.
    pub fn info(&self) -> RawMeshInfo {
        RawMeshInfo {
            sides: self.params.sides,
            rings: self.rings.len() as u32,
            leaf_sides: self.params.leaf_sides,
            leaves: self.leaves.len() as u32,
            details: self.details.len() as u32,
            _pad: [0; 3],
        }
    }

    /// Number of bark vertices.
    pub fn tube_vertex_count(&self) -> usize {
        self.rings.len() * (self.params.sides as usize + 1) + self.details.len()
    }

    /// Number of leaf vertices.
    pub fn leaf_vertex_count(&self) -> usize {
        self.leaves.len() * (self.params.leaf_sides as usize + 1)
    }

    /// Number of triangles (bark + leaves).
    pub fn triangle_count(&self) -> usize {
        (self.tube_indices.len() + self.leaf_indices.len()) / 3
    }

    /// The mesh of `pose`, on the CPU (rayon).
    pub fn mesh(&self, tree: &Tree, pose: &Pose) -> MeshFrame {
        let (joint, acc) = crate::pose::pose_buffers(tree, pose);
        self.mesh_raw(&joint, &acc)
    }

    /// The mesh from the pose seam's buffers (joint positions, accumulated rotations D),
    /// leaves at rest on their segments.
    pub fn mesh_raw(&self, joint: &[[f32; 4]], acc: &[[f32; 4]]) -> MeshFrame {
        self.mesh_seam(joint, acc, &[])
    }

    /// The mesh from the pose seam's buffers with the leaves' rotations (empty: at rest).
    pub fn mesh_seam(&self, joint: &[[f32; 4]], acc: &[[f32; 4]], leaf_rotation: &[[f32; 4]]) -> MeshFrame {
        let info = self.info();
        let mut tubes = vec![RawVertex::zeroed(); self.tube_vertex_count()];
        let ring_vertices = self.rings.len() * (self.params.sides as usize + 1);
        crate::mesh::mesh_tubes(&info, &self.rings, &self.segments, joint, acc, &mut tubes[..ring_vertices]);
        crate::mesh::mesh_detail(&info, &self.details, &mut tubes, &self.rings);
        let mut leaves = vec![RawVertex::zeroed(); self.leaf_vertex_count()];
        let rim = self.leaf_rim_table();
        crate::mesh::mesh_leaves(&info, &self.leaves, &self.segments, joint, acc, leaf_rotation, &rim, &mut leaves);
        MeshFrame { tubes, leaves }
    }
}

/// Spherical linear interpolation of unit quaternions along the shorter arc; nlerp when
/// they are nearly equal. The WGSL twin is `quat_slerp` in `quat.wgsl`.
pub fn quat_slerp(a: Quat, b: Quat, t: f32) -> Quat {
    let mut d = a.dot(b);
    let mut b = b;
    if d < 0.0 {
        d = -d;
        b = -b;
    }
    if d > 0.9995 {
        return (a * (1.0 - t) + b * t).normalize();
    }
    let theta = d.acos();
    let s = 1.0 / theta.sin();
    (a * (((1.0 - t) * theta).sin() * s) + b * ((t * theta).sin() * s)).normalize()
}

/// Bark relief in −1…1 at angle fraction `u` (periodic) and height `v` along the stem.
/// The WGSL twin is `bark_relief` in `mesh.wgsl`.
pub fn bark_relief(u: f32, v: f32, seed: u32) -> f32 {
    // Seven ridges around the stem (an integer count keeps the relief periodic in u),
    // wandering sideways with height by 1-D noise along v.
    let wander = crate::wind::noise::value_noise(v * 0.6, seed);
    let ridge = (std::f32::consts::TAU * (u * 7.0 + 0.8 * wander)).sin();
    ridge * ridge * 2.0 - 1.0
}
