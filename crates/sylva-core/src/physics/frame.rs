//! The whole tree as a linear frame: every stem flexible, every load carried toward the root
//! with its whole lever arm, each side stem starting where its parent has moved and turned to.
//! The static counterpart of Akagi's propagation, and the reference for how far any point of
//! the tree (a leader's top, the crown) leans in a steady wind, where [`super::beam`] bends
//! each stem on its own.
//!
//! Each segment is integrated in [`PIECES`] pieces, as the beam is, with the same sections
//! (the drawn taper, never under [`super::section_floor`]): at each piece's middle the moment
//! of every load beyond it, `M = Σ (p − x) × F`, its bending part (across the segment's axis)
//! over `E I` is the piece's curvature vector, and turn and displacement are integrated from
//! the root outward. Loads act along one direction; small deflections; stems do not twist
//! (the moment along a segment's axis is dropped) and axial strain is neglected.

use super::beam::PIECES;
use crate::model::{NONE, Tree};
use glam::{DVec3, Vec3};

/// Displacement of every segment's end under `load[i]` on each segment (spread along it, as
/// [`super::beam::drag_bend`] spreads it) acting along `direction` (a unit vector), per unit of
/// load (m per N with forces, m/Pa with drag areas `C_d A`); sections never thinner than
/// [`super::section_floor`] over `min_radius` (m).
pub fn static_bend(tree: &Tree, min_radius: f32, load: &[f32], direction: Vec3) -> Vec<Vec3> {
    let s = &tree.segments;
    let n = s.len();
    let dir = direction.as_dvec3();
    let floor = super::section_floor(tree, min_radius);
    let axis: Vec<DVec3> = (0..n).map(|i| s.axis(i).as_dvec3()).collect();
    let start: Vec<DVec3> = (0..n).map(|i| s.start[i].as_dvec3()).collect();
    // Each segment's load with everything beyond it, and its first moment Σ F p.
    let force = super::beam::subtree_sums(tree, load);
    let moment = super::beam::first_moments(tree, load);
    // Per piece: the turn and displacement at its start and its curvature vector.
    let mut theta = vec![DVec3::ZERO; n * PIECES];
    let mut shift = vec![DVec3::ZERO; n * PIECES];
    let mut kappa = vec![DVec3::ZERO; n * PIECES];
    let mut end = Vec::with_capacity(n);
    let mut kids: Vec<(f64, usize)> = Vec::new();
    for i in 0..n {
        let (a, l) = (axis[i], s.length[i] as f64);
        let h = l / PIECES as f64;
        kids.clear();
        kids.extend(
            tree.children.of(i).iter().map(|&c| (((start[c as usize] - start[i]).dot(a)).clamp(0.0, l), c as usize)),
        );
        let own = load[i] as f64 / PIECES as f64;
        for p in 0..PIECES {
            let along = (p as f64 + 0.5) * h;
            let x = start[i] + a * along;
            // Own pieces above this one, at their middles, and every child starting beyond.
            let (mut f, mut m) = (0.0f64, DVec3::ZERO);
            for q in p + 1..PIECES {
                f += own;
                m += (start[i] + a * ((q as f64 + 0.5) * h)) * own;
            }
            for &(o, c) in &kids {
                if o > along {
                    f += force[c] as f64;
                    m += moment[c];
                }
            }
            let bending = (m - x * f).cross(dir);
            let bending = bending - a * bending.dot(a);
            let ei = super::beam::piece_rigidity(tree, i, p, &floor);
            kappa[i * PIECES + p] = if ei > 0.0 { bending / ei } else { DVec3::ZERO };
        }
        // Where the parent has moved and turned to at this segment's start.
        let parent = s.parent[i];
        let (mut th, mut u) = if parent == NONE {
            (DVec3::ZERO, DVec3::ZERO)
        } else {
            let q = parent as usize;
            let hq = s.length[q] as f64 / PIECES as f64;
            let o = ((start[i] - start[q]).dot(axis[q])).clamp(0.0, s.length[q] as f64);
            let p = ((o / hq) as usize).min(PIECES - 1);
            along_piece(theta[q * PIECES + p], shift[q * PIECES + p], kappa[q * PIECES + p], axis[q], o - p as f64 * hq)
        };
        for p in 0..PIECES {
            theta[i * PIECES + p] = th;
            shift[i * PIECES + p] = u;
            (th, u) = along_piece(th, u, kappa[i * PIECES + p], a, h);
        }
        end.push(u.as_vec3());
    }
    end
}

/// Turn and displacement `o` along a piece of constant curvature `k` on axis `a` from `th`, `u`.
fn along_piece(th: DVec3, u: DVec3, k: DVec3, a: DVec3, o: f64) -> (DVec3, DVec3) {
    (th + k * o, u + th.cross(a) * o + k.cross(a) * (0.5 * o * o))
}
