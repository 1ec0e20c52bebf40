//! The 3-D turtle (ABOP §1.5) that interprets a derived string into stems and leaves.
//!
//! The turtle's frame is a unit quaternion mapping local axes to world: heading H = +Y,
//! left L = −X, up U = +Z (so H × L = U). ABOP's rotation matrices become rotations about
//! those local axes: `+`/`−` R_U(±δ), `&`/`^` R_L(±δ), `\`/`/` R_H(±δ), `|` R_U(180°).

use super::derive::LString;
use super::{Grammar, LSystemError};
use crate::limits::{LimitExceeded, Limits};
use crate::model::{LeafDraft, TreeBuilder};
use glam::{DMat3, DQuat, DVec3};

#[derive(Debug, Clone, Copy)]
struct State {
    pos: DVec3,
    q: DQuat,
    /// Width (diameter), grammar units.
    width: f64,
    /// Stem the next `F` extends, if the turtle stands at its tip.
    stem: Option<usize>,
    /// Last segment drawn on this path (stem, local segment): where a child attaches.
    attach: Option<(usize, usize)>,
}

pub(super) fn interpret(g: &Grammar, s: &LString, limits: &Limits) -> Result<TreeBuilder, LSystemError> {
    let deg = std::f64::consts::PI / 180.0;
    let default_angle = g.angle * deg;
    let mut b = TreeBuilder::default();
    let draws = s.count(b'F').min(limits.max_segments);
    b.segments.reserve_exact(draws);
    b.stems.reserve(draws / 2);
    let mut st = State { pos: DVec3::ZERO, q: DQuat::IDENTITY, width: g.width, stem: None, attach: None };
    let mut stack: Vec<(usize, State)> = Vec::new();
    let mut segments = 0usize;
    let err = |i: usize, sym: u8, message: String| LSystemError::Turtle {
        file: g.file.clone(),
        module: i,
        symbol: sym as char,
        message,
    };
    let limit = |limit: &'static str, value: usize| LSystemError::Limit {
        file: g.file.clone(),
        source: LimitExceeded { limit, value },
    };
    for (i, (sym, a)) in s.iter().enumerate() {
        let arg = |d: f64| a.first().copied().unwrap_or(d);
        let angle = a.first().map_or(default_angle, |v| v * deg);
        match sym {
            b'F' | b'f' => {
                let len = arg(g.step) * g.scale;
                if !len.is_finite() || len < 0.0 {
                    return Err(err(i, sym, format!("length {len} must be finite and ≥ 0")));
                }
                let h = st.q * DVec3::Y;
                let end = st.pos + h * len;
                if sym == b'f' {
                    st.pos = end;
                    st.stem = None;
                    st.attach = None;
                    continue;
                }
                if len == 0.0 {
                    continue;
                }
                segments += 1;
                if segments > limits.max_segments {
                    return Err(limit("max_segments", limits.max_segments));
                }
                let radius = 0.5 * st.width * g.width_scale;
                if !radius.is_finite() || radius <= 0.0 {
                    return Err(err(i, sym, format!("width {} gives a radius that is not > 0", st.width)));
                }
                let stem = match st.stem {
                    Some(k) => {
                        // The previous segment's tip takes this segment's base radius.
                        let last = b.stems[k].last as usize;
                        b.segments[last].radius_tip = radius;
                        k
                    }
                    None => {
                        let (parent, level) = match st.attach {
                            Some((ps, pseg)) => match b.stems[ps].level.checked_add(1).filter(|&l| l < u8::MAX) {
                                Some(level) => (Some((ps, pseg, 1.0)), level),
                                None => {
                                    return Err(err(
                                        i,
                                        sym,
                                        format!(
                                            "a branch {} levels deep; a tree holds at most {} levels of branches",
                                            u16::from(b.stems[ps].level) + 2,
                                            u8::MAX
                                        ),
                                    ));
                                }
                            },
                            None => (None, 0),
                        };
                        b.add_stem(parent, level)
                    }
                };
                let local = b.push_segment(stem, st.pos, end, st.q, radius, radius);
                st.attach = Some((stem, local));
                st.stem = Some(stem);
                st.pos = end;
                if let Some((t, e)) = g.tropism {
                    // ABOP eq. (2.?): rotate H toward T by α = e |H × T|.
                    let axis = h.cross(t);
                    let l = axis.length();
                    if l > 1e-12 {
                        st.q = (DQuat::from_axis_angle(axis / l, e * l) * st.q).normalize();
                    }
                }
            }
            b'+' => st.q = (st.q * DQuat::from_rotation_z(angle)).normalize(),
            b'-' => st.q = (st.q * DQuat::from_rotation_z(-angle)).normalize(),
            b'&' => st.q = (st.q * DQuat::from_rotation_x(angle)).normalize(),
            b'^' => st.q = (st.q * DQuat::from_rotation_x(-angle)).normalize(),
            b'\\' => st.q = (st.q * DQuat::from_rotation_y(angle)).normalize(),
            b'/' => st.q = (st.q * DQuat::from_rotation_y(-angle)).normalize(),
            b'|' => st.q = (st.q * DQuat::from_rotation_z(std::f64::consts::PI)).normalize(),
            b'$' => {
                let h = st.q * DVec3::Y;
                let l = DVec3::Y.cross(h);
                if l.length() > 1e-9 {
                    let l = l.normalize();
                    let u = h.cross(l);
                    st.q = DQuat::from_mat3(&DMat3::from_cols(-l, h, u)).normalize();
                }
            }
            b'!' => {
                let w = arg(st.width);
                if !w.is_finite() || w <= 0.0 {
                    return Err(err(i, sym, format!("width {w} must be finite and > 0")));
                }
                st.width = w;
            }
            b'[' => {
                if stack.len() >= limits.max_branch_depth {
                    return Err(limit("max_branch_depth", limits.max_branch_depth));
                }
                stack.push((i, st));
                st.stem = None;
            }
            b']' => match stack.pop() {
                Some((_, prev)) => st = prev,
                None => return Err(err(i, sym, "`]` without a matching `[`".into())),
            },
            b'~' => {
                let length = a.first().map_or(g.leaf.0, |v| v * g.scale);
                let width = a.get(1).map_or(if a.is_empty() { g.leaf.1 } else { length * 0.5 }, |v| v * g.scale);
                if !(length.is_finite() && width.is_finite() && length > 0.0 && width > 0.0) {
                    return Err(err(i, sym, format!("leaf length {length} and width {width} must be finite and > 0")));
                }
                let Some((stem, segment)) = st.attach else {
                    return Err(err(i, sym, "a leaf needs a segment to hang on: draw an F before it".into()));
                };
                if b.leaves.len() >= limits.max_leaves {
                    return Err(limit("max_leaves", limits.max_leaves));
                }
                b.leaves.push(LeafDraft { stem, segment, position: st.pos, orientation: st.q, width, length });
            }
            _ => {}
        }
    }
    if let Some(&(i, _)) = stack.last() {
        let n = stack.len();
        return Err(err(i, b'[', format!("{n} `[` left without a matching `]` at the end of the string")));
    }
    Ok(b)
}
