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

/// One stem as produced by a generator; its segments live in [`TreeBuilder::segments`].
#[derive(Debug, Clone, Copy, Default)]
pub struct StemDraft {
    /// Index of the parent stem in the draft list (must be smaller than this stem's index),
    /// with the parent's local segment index and the fraction along that segment where this
    /// stem starts. `None` for a trunk.
    pub parent: Option<(usize, usize, f64)>,
    /// Branching level.
    pub level: u8,
    /// Number of segments pushed so far.
    pub segments: u32,
    /// Draft index of its last segment.
    pub last: u32,
}

/// One segment as produced by a generator.
#[derive(Debug, Clone, Copy)]
pub struct SegmentDraft {
    /// Draft stem it belongs to.
    pub stem: u32,
    /// Start and end joints.
    pub start: DVec3,
    /// End joint.
    pub end: DVec3,
    /// Turtle frame; local +Y should point along the segment. The builder corrects small
    /// mismatches with the shortest rotation, keeping the twist.
    pub frame: DQuat,
    /// Radius at the start.
    pub radius_base: f64,
    /// Radius at the end.
    pub radius_tip: f64,
}

/// One leaf as produced by a generator.
#[derive(Debug, Clone, Copy)]
pub struct LeafDraft {
    /// Draft stem index it hangs on.
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

/// Collects stems, segments and leaves (flat, in creation order), then builds a validated
/// [`Tree`].
#[derive(Debug, Clone, Default)]
pub struct TreeBuilder {
    /// Stems in creation order (parents before children).
    pub stems: Vec<StemDraft>,
    /// Segments in creation order (within a stem: base to tip).
    pub segments: Vec<SegmentDraft>,
    /// Leaves.
    pub leaves: Vec<LeafDraft>,
}

impl TreeBuilder {
    /// Adds an empty stem and returns its draft index.
    pub fn add_stem(&mut self, parent: Option<(usize, usize, f64)>, level: u8) -> usize {
        self.stems.push(StemDraft { parent, level, segments: 0, last: u32::MAX });
        self.stems.len() - 1
    }

    /// Appends a segment to `stem`; returns its local index within the stem.
    pub fn push_segment(
        &mut self,
        stem: usize,
        start: DVec3,
        end: DVec3,
        frame: DQuat,
        radius_base: f64,
        radius_tip: f64,
    ) -> usize {
        let index = self.segments.len() as u32;
        self.segments.push(SegmentDraft { stem: stem as u32, start, end, frame, radius_base, radius_tip });
        let s = &mut self.stems[stem];
        s.segments += 1;
        s.last = index;
        s.segments as usize - 1
    }

    /// Appends another builder (a subtree grown separately); its first stem's parent refers to
    /// a stem of `self` and is kept, every other index is shifted.
    pub fn append_subtree(&mut self, sub: TreeBuilder) {
        let so = self.stems.len();
        let go = self.segments.len() as u32;
        for (k, mut s) in sub.stems.into_iter().enumerate() {
            if k > 0 {
                s.parent = s.parent.map(|(p, seg, f)| (p + so, seg, f));
            }
            s.last = s.last.wrapping_add(go);
            self.stems.push(s);
        }
        self.segments.extend(sub.segments.into_iter().map(|g| SegmentDraft { stem: g.stem + so as u32, ..g }));
        self.leaves.extend(sub.leaves.into_iter().map(|l| LeafDraft { stem: l.stem + so, ..l }));
    }

    /// Scales every height (y) by `factor` — Weber–Penn's ZScale. Orientations are
    /// re-aimed at build time.
    pub fn scale_heights(&mut self, factor: f64) {
        for g in &mut self.segments {
            g.start.y *= factor;
            g.end.y *= factor;
        }
        for l in &mut self.leaves {
            l.position.y *= factor;
        }
    }

    /// Total number of segments so far.
    pub fn segment_count(&self) -> usize {
        self.segments.len()
    }

    /// Builds the tree and checks its invariants.
    pub fn build(self, name: &str, seed: u64, wood: WoodProperties) -> Result<Tree, ModelError> {
        let TreeBuilder { stems: drafts, segments: seg_drafts, leaves: leaf_drafts } = self;
        let total = seg_drafts.len();
        if total >= NONE as usize {
            return Err(ModelError::TooLarge { what: "segments", count: total });
        }
        // Order stems by level, keeping creation order within a level.
        let mut order: Vec<usize> = (0..drafts.len()).filter(|&i| drafts[i].segments > 0).collect();
        order.sort_by_key(|&i| drafts[i].level);
        let mut new_index = vec![u32::MAX; drafts.len()];
        let mut first_seg = vec![0u32; drafts.len()];
        let mut acc = 0u32;
        for (k, &i) in order.iter().enumerate() {
            new_index[i] = k as u32;
            first_seg[i] = acc;
            acc += drafts[i].segments;
        }
        if acc as usize != total {
            return Err(ModelError::Internal(format!("stems count {acc} segments, {total} pushed")));
        }
        // Final position of every draft segment (segments of a stem are in creation order).
        let mut fill = first_seg.clone();
        let mut src = vec![0u32; total];
        for (d, g) in seg_drafts.iter().enumerate() {
            let st = g.stem as usize;
            if st >= drafts.len() {
                return Err(ModelError::Internal(format!("segment {d} on missing stem {st}")));
            }
            src[fill[st] as usize] = d as u32;
            fill[st] += 1;
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
        let nst = order.len();
        let mut stems = Stems {
            parent: Vec::with_capacity(nst),
            level: Vec::with_capacity(nst),
            first_segment: Vec::with_capacity(nst),
            segment_count: Vec::with_capacity(nst),
            attach: Vec::with_capacity(nst),
            length: Vec::with_capacity(nst),
            bezier: Vec::new(),
            bezier_error: Vec::new(),
        };
        let mut arc_start = Vec::with_capacity(total);
        let sanitize = |r: f64| if r.is_finite() { r.max(MIN_RADIUS) } else { MIN_RADIUS };

        for (k, &i) in order.iter().enumerate() {
            let d = &drafts[i];
            let n = d.segments as usize;
            let (parent_stem, attach_seg) = match d.parent {
                None => (NONE, None),
                Some((p, local, frac)) => {
                    let pn = new_index.get(p).copied().unwrap_or(u32::MAX);
                    if pn == u32::MAX || pn as usize >= k || local >= drafts[p].segments as usize {
                        return Err(ModelError::Internal(format!("stem draft {i}: bad parent {p}/{local}")));
                    }
                    (pn, Some((first_seg[p] + local as u32, frac)))
                }
            };
            // Radii: positive and non-increasing along the stem.
            let mut prev = f64::INFINITY;
            let mut arc = 0.0f64;
            let f0 = first_seg[i] as usize;
            for s in 0..n {
                let g = &seg_drafts[src[f0 + s] as usize];
                let dir = g.end - g.start;
                let len = dir.length();
                let frame = g.frame.normalize();
                let q = if len > 0.0 {
                    let fy = frame * DVec3::Y;
                    (DQuat::from_rotation_arc(fy, dir / len) * frame).normalize()
                } else {
                    frame
                };
                let q32 = q.as_quat().normalize();
                let index = seg.parent.len() as u32;
                let parent = if s == 0 { attach_seg.map_or(NONE, |(p, _)| p) } else { index - 1 };
                let local =
                    if parent == NONE { q32 } else { (seg.orientation[parent as usize].inverse() * q32).normalize() };
                let r0 = sanitize(g.radius_base).min(prev);
                let r1 = sanitize(g.radius_tip).min(r0);
                prev = r1;
                let (r0, r1, l) = (r0 as f32, r1 as f32, len as f32);
                seg.parent.push(parent);
                seg.level.push(d.level);
                seg.stem.push(k as u32);
                seg.start.push(g.start.as_vec3());
                seg.orientation.push(q32);
                seg.local_orientation.push(local);
                seg.length.push(l);
                seg.radius_base.push(r0);
                seg.radius_tip.push(r1);
                seg.mass.push(wood.segment_mass(l, r0, r1));
                seg.stiffness.push(wood.segment_stiffness(l, r0));
                arc_start.push(arc);
                arc += len;
            }
            let attach = match attach_seg {
                None => 0.0,
                Some((p, frac)) => {
                    let p = p as usize;
                    let ps = seg.stem[p] as usize;
                    let plen = stems.length[ps] as f64;
                    if plen > 0.0 { ((arc_start[p] + frac * seg.length[p] as f64) / plen).clamp(0.0, 1.0) } else { 0.0 }
                }
            };
            stems.parent.push(parent_stem);
            stems.level.push(d.level);
            stems.first_segment.push(first_seg[i]);
            stems.segment_count.push(n as u32);
            stems.attach.push(attach as f32);
            stems.length.push(arc as f32);
        }

        // One Bézier per stem, fitted in parallel (each fit depends on its stem alone).
        let (bezier, bezier_error): (Vec<[Vec3; 4]>, Vec<f32>) = (0..stems.len())
            .into_par_iter()
            .map(|k| {
                let f = stems.first_segment[k] as usize;
                let n = stems.segment_count[k] as usize;
                if n == 1 {
                    return fit_cubic_bezier(&[seg.start[f], seg.end(f)]);
                }
                let mut pts: Vec<Vec3> = seg.start[f..f + n].to_vec();
                pts.push(seg.end(f + n - 1));
                fit_cubic_bezier(&pts)
            })
            .unzip();
        stems.bezier = bezier;
        stems.bezier_error = bezier_error;

        // Leaves, sorted by segment (stable: creation order within a segment).
        let mut leaf_list: Vec<(u32, &LeafDraft)> = Vec::with_capacity(leaf_drafts.len());
        for l in &leaf_drafts {
            if l.stem >= drafts.len() || l.segment >= drafts[l.stem].segments as usize {
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
        let levels = match seg.level.iter().copied().max() {
            None => 0,
            Some(l) => l.checked_add(1).ok_or(ModelError::TooLarge { what: "branch levels", count: 256 })?,
        };
        let tree = Tree {
            name: name.to_string(),
            seed,
            levels,
            segments: seg,
            stems,
            leaves,
            children,
            wood,
            trunk_shape: Default::default(),
            leaf_shape: Default::default(),
            leaf_motion: Default::default(),
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
