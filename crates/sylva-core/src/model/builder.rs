//! Turns generator output (stems as polylines with frames and radii) into a [`Tree`]:
//! topological order, parent links, relative orientations, mass and stiffness, flat child
//! lists and one fitted Bézier per stem. Both generators go through here, so the invariants
//! are established in one place.

use super::{Children, Leaves, ModelError, NONE, Segments, Stems, Tree, WoodProperties, fit_cubic_bezier};
use glam::{DQuat, DVec3, Vec3};
use rayon::prelude::*;

/// Smallest radius any segment end is given, m (0.01 mm): keeps radii positive at stem tips
/// that taper to a point.
pub const MIN_RADIUS: f64 = 1e-5;

/// One stem as produced by a generator.
#[derive(Debug, Clone, Default)]
pub struct StemDraft {
    /// Index of the parent stem in the draft list (must be smaller than this stem's index),
    /// with the parent's local segment index and the fraction along that segment where this
    /// stem starts. `None` for a trunk.
    pub parent: Option<(usize, usize, f64)>,
    /// Branching level.
    pub level: u8,
    /// Joints: `n + 1` points for `n` segments.
    pub points: Vec<DVec3>,
    /// Turtle frame of each segment (`n` entries); local +Y should point along the segment.
    /// The builder corrects small mismatches with the shortest rotation, keeping the twist.
    pub frames: Vec<DQuat>,
    /// Radius at each joint (`n + 1` entries).
    pub radii: Vec<f64>,
}

impl StemDraft {
    /// Number of segments.
    pub fn segment_count(&self) -> usize {
        self.points.len().saturating_sub(1)
    }
}

/// One leaf as produced by a generator.
#[derive(Debug, Clone, Copy)]
pub struct LeafDraft {
    /// Draft stem index and local segment index it hangs on.
    pub stem: usize,
    /// Local segment index within the stem.
    pub segment: usize,
    /// Attachment point.
    pub position: DVec3,
    /// Orientation (blade along local +Y).
    pub orientation: DQuat,
    /// Blade width, m.
    pub width: f64,
    /// Blade length, m.
    pub length: f64,
}

/// Collects stems and leaves, then builds a validated [`Tree`].
#[derive(Debug, Clone, Default)]
pub struct TreeBuilder {
    /// Stems in creation order (parents before children).
    pub stems: Vec<StemDraft>,
    /// Leaves.
    pub leaves: Vec<LeafDraft>,
}

impl TreeBuilder {
    /// Scales every height (y) by `factor` — Weber–Penn's ZScale. Orientations are
    /// re-aimed at build time.
    pub fn scale_heights(&mut self, factor: f64) {
        for s in &mut self.stems {
            for p in &mut s.points {
                p.y *= factor;
            }
        }
        for l in &mut self.leaves {
            l.position.y *= factor;
        }
    }

    /// Total number of segments so far.
    pub fn segment_count(&self) -> usize {
        self.stems.iter().map(|s| s.segment_count()).sum()
    }

    /// Builds the tree and checks its invariants.
    pub fn build(self, name: &str, seed: u64, wood: WoodProperties) -> Result<Tree, ModelError> {
        let TreeBuilder { stems: drafts, leaves: leaf_drafts } = self;
        // Order stems by level, keeping creation order within a level.
        let mut order: Vec<usize> = (0..drafts.len()).filter(|&i| drafts[i].segment_count() > 0).collect();
        order.sort_by_key(|&i| drafts[i].level);
        let mut new_index = vec![u32::MAX; drafts.len()];
        for (k, &i) in order.iter().enumerate() {
            new_index[i] = k as u32;
        }
        let mut first_seg = vec![0u32; drafts.len()];
        let mut total = 0usize;
        for &i in &order {
            first_seg[i] = total as u32;
            total += drafts[i].segment_count();
        }
        if total >= NONE as usize {
            return Err(ModelError::TooLarge { what: "segments", count: total });
        }

        let mut seg = Segments {
            parent: Vec::with_capacity(total),
            level: Vec::with_capacity(total),
            stem: Vec::with_capacity(total),
            start: Vec::with_capacity(total),
            orientation: Vec::with_capacity(total),
            local_orientation: Vec::with_capacity(total),
            length: Vec::with_capacity(total),
            radius_base: Vec::with_capacity(total),
            radius_tip: Vec::with_capacity(total),
            mass: Vec::with_capacity(total),
            stiffness: Vec::with_capacity(total),
        };
        let mut stems = Stems::default();
        let mut stem_arc: Vec<Vec<f64>> = Vec::with_capacity(order.len());

        for (k, &i) in order.iter().enumerate() {
            let d = &drafts[i];
            let n = d.segment_count();
            if d.frames.len() != n || d.radii.len() != n + 1 {
                return Err(ModelError::Internal(format!(
                    "stem draft {i}: {} points, {} frames, {} radii",
                    d.points.len(),
                    d.frames.len(),
                    d.radii.len()
                )));
            }
            let (parent_stem, attach_seg) = match d.parent {
                None => (NONE, None),
                Some((p, local, frac)) => {
                    let pn = new_index.get(p).copied().unwrap_or(u32::MAX);
                    if pn == u32::MAX || pn as usize >= k || local >= drafts[p].segment_count() {
                        return Err(ModelError::Internal(format!("stem draft {i}: bad parent {p}/{local}")));
                    }
                    (pn, Some((first_seg[p] + local as u32, p, local, frac)))
                }
            };
            // Radii: positive and non-increasing along the stem.
            let mut radii = d.radii.clone();
            let mut prev = f64::INFINITY;
            for r in &mut radii {
                let v = if r.is_finite() { r.max(MIN_RADIUS) } else { MIN_RADIUS };
                *r = v.min(prev);
                prev = *r;
            }
            let mut arc = Vec::with_capacity(n + 1);
            arc.push(0.0);
            for s in 0..n {
                let a = d.points[s];
                let b = d.points[s + 1];
                let dir = b - a;
                let len = dir.length();
                arc.push(arc[s] + len);
                let frame = d.frames[s].normalize();
                let q = if len > 0.0 {
                    let fy = frame * DVec3::Y;
                    (DQuat::from_rotation_arc(fy, dir / len) * frame).normalize()
                } else {
                    frame
                };
                let q32 = q.as_quat().normalize();
                let index = seg.parent.len() as u32;
                let parent = if s == 0 {
                    attach_seg.map_or(NONE, |(p, ..)| p)
                } else {
                    index - 1
                };
                let local = if parent == NONE {
                    q32
                } else {
                    (seg.orientation[parent as usize].inverse() * q32).normalize()
                };
                let (r0, r1) = (radii[s] as f32, radii[s + 1] as f32);
                let l = len as f32;
                seg.parent.push(parent);
                seg.level.push(d.level);
                seg.stem.push(k as u32);
                seg.start.push(a.as_vec3());
                seg.orientation.push(q32);
                seg.local_orientation.push(local);
                seg.length.push(l);
                seg.radius_base.push(r0);
                seg.radius_tip.push(r1);
                seg.mass.push(wood.segment_mass(l, r0, r1));
                seg.stiffness.push(wood.segment_stiffness(l, r0));
            }
            let length = arc[n];
            let attach = match attach_seg {
                None => 0.0,
                Some((_, p, local, frac)) => {
                    let pk = new_index[p] as usize;
                    let parc = &stem_arc[pk];
                    let plen = *parc.last().unwrap_or(&0.0);
                    if plen > 0.0 {
                        ((parc[local] + frac * (parc[local + 1] - parc[local])) / plen).clamp(0.0, 1.0)
                    } else {
                        0.0
                    }
                }
            };
            stems.parent.push(parent_stem);
            stems.level.push(d.level);
            stems.first_segment.push(first_seg[i]);
            stems.segment_count.push(n as u32);
            stems.attach.push(attach as f32);
            stems.length.push(length as f32);
            stem_arc.push(arc);
        }

        // One Bézier per stem, fitted in parallel (each fit depends on its stem alone).
        let fits: Vec<([Vec3; 4], f32)> = order
            .par_iter()
            .map(|&i| {
                let pts: Vec<Vec3> = drafts[i].points.iter().map(|p| p.as_vec3()).collect();
                fit_cubic_bezier(&pts)
            })
            .collect();
        for (b, e) in fits {
            stems.bezier.push(b);
            stems.bezier_error.push(e);
        }

        // Leaves, sorted by segment (stable: creation order within a segment).
        let mut leaf_list: Vec<(u32, &LeafDraft)> = Vec::with_capacity(leaf_drafts.len());
        for l in &leaf_drafts {
            if l.stem >= drafts.len() || l.segment >= drafts[l.stem].segment_count() {
                return Err(ModelError::Internal(format!("leaf on missing segment {}/{}", l.stem, l.segment)));
            }
            leaf_list.push((first_seg[l.stem] + l.segment as u32, l));
        }
        leaf_list.sort_by_key(|(s, _)| *s);
        let mut leaves = Leaves::default();
        for (s, l) in &leaf_list {
            leaves.segment.push(*s);
            leaves.position.push(l.position.as_vec3());
            leaves.orientation.push(l.orientation.normalize().as_quat().normalize());
            leaves.width.push((l.width as f32).max(MIN_RADIUS as f32));
            leaves.length.push((l.length as f32).max(MIN_RADIUS as f32));
        }

        let children = build_children(&seg.parent, &leaves.segment);
        let levels = seg.level.iter().copied().max().map_or(0, |l| l + 1);
        let tree = Tree {
            name: name.to_string(),
            seed,
            levels,
            segments: seg,
            stems,
            leaves,
            children,
            wood,
        };
        tree.validate()?;
        Ok(tree)
    }
}

/// Flat child lists from a parent array (children in increasing index order).
pub(crate) fn build_children(parent: &[u32], leaf_segment: &[u32]) -> Children {
    let n = parent.len();
    let mut count = vec![0u32; n];
    for &p in parent {
        if p != NONE {
            count[p as usize] += 1;
        }
    }
    let mut offset = vec![0u32; n];
    let mut acc = 0u32;
    for i in 0..n {
        offset[i] = acc;
        acc += count[i];
    }
    let mut fill = offset.clone();
    let mut index = vec![0u32; acc as usize];
    for (i, &p) in parent.iter().enumerate() {
        if p != NONE {
            index[fill[p as usize] as usize] = i as u32;
            fill[p as usize] += 1;
        }
    }
    let mut leaf_count = vec![0u32; n];
    for &s in leaf_segment {
        leaf_count[s as usize] += 1;
    }
    let mut leaf_offset = vec![0u32; n];
    let mut acc = 0u32;
    for i in 0..n {
        leaf_offset[i] = acc;
        acc += leaf_count[i];
    }
    let max_children = count.iter().copied().max().unwrap_or(0);
    Children { offset, count, index, leaf_offset, leaf_count, max_children }
}
