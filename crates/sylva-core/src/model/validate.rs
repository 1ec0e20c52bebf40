//! The model's invariants, checked after every build (and available to tools via
//! [`Tree::validate`](super::Tree::validate)).

use super::{NONE, Tree};
use glam::Vec3;

/// A broken invariant of the tree model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// Arrays that must have one entry per element disagree in length.
    #[error("array `{array}` has {found} entries, expected {expected}")]
    Length { array: &'static str, found: usize, expected: usize },
    /// A parent index is not smaller than its child's.
    #[error("segment {index}: parent {parent} does not precede it (topological order)")]
    Order { index: usize, parent: u32 },
    /// A child's base is not on its parent.
    #[error("segment {index}: base is {distance} m from its parent segment {parent} (tolerance {tolerance} m)")]
    Detached { index: usize, parent: u32, distance: f32, tolerance: f32 },
    /// A value is not finite or out of its range.
    #[error("{what} {index}: {field} = {value} ({expected})")]
    Value { what: &'static str, index: usize, field: &'static str, value: f32, expected: &'static str },
    /// A quaternion is not of unit length.
    #[error("{what} {index}: quaternion length {norm} is not 1")]
    NotUnit { what: &'static str, index: usize, norm: f32 },
    /// Stem, child or leaf bookkeeping disagrees with the segments.
    #[error("inconsistent structure: {0}")]
    Structure(String),
    /// Too many elements for 32-bit indices.
    #[error("too many {what}: {count}")]
    TooLarge { what: &'static str, count: usize },
    /// A generator handed the builder malformed drafts.
    #[error("internal error: {0}")]
    Internal(String),
}

fn dist_to_segment(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let l2 = ab.length_squared();
    let t = if l2 > 0.0 { ((p - a).dot(ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (a + ab * t - p).length()
}

fn check_len(array: &'static str, found: usize, expected: usize) -> Result<(), ModelError> {
    if found != expected {
        return Err(ModelError::Length { array, found, expected });
    }
    Ok(())
}

/// Relative tolerance for geometric invariants: 1e-4 × tree height.
pub const GEOMETRY_TOLERANCE: f32 = 1e-4;

pub(super) fn validate(t: &Tree) -> Result<(), ModelError> {
    let s = &t.segments;
    let n = s.len();
    for (name, len) in [
        ("segments.level", s.level.len()),
        ("segments.stem", s.stem.len()),
        ("segments.start", s.start.len()),
        ("segments.orientation", s.orientation.len()),
        ("segments.local_orientation", s.local_orientation.len()),
        ("segments.length", s.length.len()),
        ("segments.radius_base", s.radius_base.len()),
        ("segments.radius_tip", s.radius_tip.len()),
        ("segments.mass", s.mass.len()),
        ("segments.stiffness", s.stiffness.len()),
        ("children.offset", t.children.offset.len()),
        ("children.count", t.children.count.len()),
        ("children.leaf_offset", t.children.leaf_offset.len()),
        ("children.leaf_count", t.children.leaf_count.len()),
    ] {
        check_len(name, len, n)?;
    }
    let height = t.height().max(1e-3);
    let tol = GEOMETRY_TOLERANCE * height;

    let unit = |what, index, q: glam::Quat| -> Result<(), ModelError> {
        let norm = q.length();
        if !norm.is_finite() || (norm - 1.0).abs() > 1e-4 {
            return Err(ModelError::NotUnit { what, index, norm });
        }
        Ok(())
    };
    let positive = |what, index, field, value: f32| -> Result<(), ModelError> {
        if !value.is_finite() || value <= 0.0 {
            return Err(ModelError::Value { what, index, field, value, expected: "finite and > 0" });
        }
        Ok(())
    };

    for i in 0..n {
        let p = s.parent[i];
        if p != NONE && p as usize >= i {
            return Err(ModelError::Order { index: i, parent: p });
        }
        if !s.start[i].is_finite() {
            return Err(ModelError::Value {
                what: "segment",
                index: i,
                field: "start",
                value: f32::NAN,
                expected: "finite",
            });
        }
        unit("segment", i, s.orientation[i])?;
        unit("segment", i, s.local_orientation[i])?;
        positive("segment", i, "length", s.length[i])?;
        positive("segment", i, "radius_base", s.radius_base[i])?;
        positive("segment", i, "radius_tip", s.radius_tip[i])?;
        positive("segment", i, "mass", s.mass[i])?;
        positive("segment", i, "stiffness", s.stiffness[i])?;
        if s.radius_tip[i] > s.radius_base[i] {
            return Err(ModelError::Value {
                what: "segment",
                index: i,
                field: "radius_tip",
                value: s.radius_tip[i],
                expected: "≤ radius_base (radii never increase along a stem)",
            });
        }
        if p != NONE {
            let pi = p as usize;
            let d = if s.stem[pi] == s.stem[i] {
                (s.end(pi) - s.start[i]).length()
            } else {
                dist_to_segment(s.start[i], s.start[pi], s.end(pi))
            };
            if d > tol {
                return Err(ModelError::Detached { index: i, parent: p, distance: d, tolerance: tol });
            }
            let composed = s.orientation[pi] * s.local_orientation[i];
            if composed.dot(s.orientation[i]).abs() < 1.0 - 1e-5 {
                return Err(ModelError::Structure(format!(
                    "segment {i}: parent orientation × local orientation ≠ orientation"
                )));
            }
            if s.stem[pi] == s.stem[i] && s.radius_base[i] > s.radius_tip[pi] {
                return Err(ModelError::Value {
                    what: "segment",
                    index: i,
                    field: "radius_base",
                    value: s.radius_base[i],
                    expected: "≤ the previous segment's radius_tip (radii never increase along a stem)",
                });
            }
        }
    }

    // Stems: contiguous ranges covering every segment, in order.
    let st = &t.stems;
    let m = st.len();
    for (name, len) in [
        ("stems.level", st.level.len()),
        ("stems.first_segment", st.first_segment.len()),
        ("stems.segment_count", st.segment_count.len()),
        ("stems.attach", st.attach.len()),
        ("stems.length", st.length.len()),
        ("stems.bezier", st.bezier.len()),
        ("stems.bezier_error", st.bezier_error.len()),
    ] {
        check_len(name, len, m)?;
    }
    let mut next = 0u32;
    for k in 0..m {
        if st.first_segment[k] != next || st.segment_count[k] == 0 {
            return Err(ModelError::Structure(format!(
                "stem {k} does not start where stem {} ended",
                k.wrapping_sub(1)
            )));
        }
        let first = st.first_segment[k] as usize;
        let last = first + st.segment_count[k] as usize - 1;
        for i in first..=last {
            if s.stem[i] as usize != k || s.level[i] != st.level[k] {
                return Err(ModelError::Structure(format!(
                    "segment {i} is in stem {k}'s range but says stem {}",
                    s.stem[i]
                )));
            }
            if i > first && s.parent[i] as usize != i - 1 {
                return Err(ModelError::Structure(format!(
                    "segment {i}: parent is not the previous segment of its stem"
                )));
            }
        }
        let parent_stem = st.parent[k];
        let first_parent = s.parent[first];
        if (parent_stem == NONE) != (first_parent == NONE) {
            return Err(ModelError::Structure(format!("stem {k}: parent stem and first segment's parent disagree")));
        }
        if parent_stem != NONE && (parent_stem as usize >= k || s.stem[first_parent as usize] != parent_stem) {
            return Err(ModelError::Structure(format!(
                "stem {k}: parent stem {parent_stem} does not hold segment {first_parent}"
            )));
        }
        if !(0.0..=1.0).contains(&st.attach[k]) {
            return Err(ModelError::Value {
                what: "stem",
                index: k,
                field: "attach",
                value: st.attach[k],
                expected: "in [0, 1]",
            });
        }
        let b = st.bezier[k];
        if (b[0] - s.start[first]).length() > tol || (b[3] - s.end(last)).length() > tol {
            return Err(ModelError::Structure(format!("stem {k}: Bézier end points are not the stem's ends")));
        }
        next += st.segment_count[k];
    }
    if next as usize != n {
        return Err(ModelError::Structure(format!("stems cover {next} of {n} segments")));
    }

    // Children lists agree with the parent array.
    let c = &t.children;
    let mut seen = 0usize;
    for i in 0..n {
        for &ch in c.of(i) {
            if s.parent[ch as usize] as usize != i {
                return Err(ModelError::Structure(format!("segment {ch} listed as child of {i}")));
            }
            seen += 1;
        }
    }
    let roots = s.parent.iter().filter(|&&p| p == NONE).count();
    if seen + roots != n || c.index.len() != seen {
        return Err(ModelError::Structure("child lists do not cover every non-root segment exactly once".into()));
    }

    // Leaves.
    let l = &t.leaves;
    let nl = l.len();
    for (name, len) in [
        ("leaves.position", l.position.len()),
        ("leaves.orientation", l.orientation.len()),
        ("leaves.width", l.width.len()),
        ("leaves.length", l.length.len()),
    ] {
        check_len(name, len, nl)?;
    }
    for k in 0..nl {
        let sg = l.segment[k] as usize;
        if sg >= n || (k > 0 && l.segment[k] < l.segment[k - 1]) {
            return Err(ModelError::Structure(format!(
                "leaf {k}: segment {sg} missing or leaves not sorted by segment"
            )));
        }
        unit("leaf", k, l.orientation[k])?;
        positive("leaf", k, "width", l.width[k])?;
        positive("leaf", k, "length", l.length[k])?;
        let d = dist_to_segment(l.position[k], s.start[sg], s.end(sg));
        if d > tol {
            return Err(ModelError::Detached { index: k, parent: sg as u32, distance: d, tolerance: tol });
        }
        let o = c.leaf_offset[sg] as usize;
        if !(o..o + c.leaf_count[sg] as usize).contains(&k) {
            return Err(ModelError::Structure(format!("leaf {k} outside its segment's leaf run")));
        }
    }
    Ok(())
}
