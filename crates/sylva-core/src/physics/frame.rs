//! The whole tree as a linear frame: every stem flexible, every load carried toward the root
//! with its whole lever arm, each side stem starting where its parent has moved and turned to.
//! The static counterpart of Akagi's propagation, and the reference for how far any point of
//! the tree (a leader's top, the crown) leans in a steady wind, where [`super::beam`] bends
//! each stem on its own. [`modes`] gives the frame's natural modes, side stems swinging on
//! their parents, where [`super::stem_frequencies`] lumps each side stem's mass where it starts.
//!
//! Each segment is integrated in [`PIECES`] pieces, as the beam is, with the same sections
//! (the drawn taper, never under [`super::section_floor`]): at each piece's middle the moment
//! of every load beyond it, `M = Σ (p − x) × F`, its bending part (across the segment's axis)
//! over `E I` is the piece's curvature vector, and turn and displacement are integrated from
//! the root outward. Small deflections; stems do not twist (the moment along a segment's axis
//! is dropped) and axial strain is neglected.
//!
//! The modes come from subspace iteration (Bathe & Wilson 1972) on the frame's flexibility:
//! each segment's mass (wood and leaves, [`super::beam::segment_masses`]) moves in parts of at
//! most [`PART_OF_HEIGHT`] of the tree's height, spread along them as the loads are; each
//! block of trial shapes is bent under its inertial loads and the block's Rayleigh–Ritz
//! problem solved, until the lowest frequencies settle. Segments carry no rotational inertia
//! of their own.

use super::beam::PIECES;
use crate::model::{NONE, Tree};
use glam::{DVec3, Vec3};
use nalgebra::{DMatrix, SymmetricEigen};
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

/// Displacement of every segment's end under `load[i]` on each segment (spread along it, as
/// [`super::beam::drag_bend`] spreads it) acting along `direction` (a unit vector), per unit of
/// load (m per N with forces, m/Pa with drag areas `C_d A`); sections never thinner than
/// [`super::section_floor`] over `min_radius` (m).
pub fn static_bend(tree: &Tree, min_radius: f32, load: &[f32], direction: Vec3) -> Vec<Vec3> {
    let dir = direction.as_dvec3();
    let pieces: Vec<DVec3> = load.iter().flat_map(|&f| [dir * (f as f64 / PIECES as f64); PIECES]).collect();
    Frame::new(tree, min_radius).bend(&pieces).end.iter().map(|u| u.as_vec3()).collect()
}

/// One natural mode of the whole tree's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameMode {
    /// Frequency, Hz.
    pub hz: f32,
    /// Each segment's displacement (its mean along the segment); the parts [`modes`] moves are
    /// scaled so that `Σ m u² = 1` (kg·m²).
    pub shape: Vec<Vec3>,
    /// Effective mass along x, y and z as a share of the tree's mass, `(Σ m u·e)² / Σ m`: how
    /// much of the tree a uniform push along each axis sets swinging in this mode (the shares
    /// of all modes add up to 1 along each axis).
    pub mass_share: Vec3,
}

impl FrameMode {
    /// Share of the tree's mass the mode swings horizontally (along x and z; y is up).
    pub fn horizontal_share(&self) -> f32 {
        self.mass_share.x + self.mass_share.z
    }
}

/// Largest tree whose modes [`modes`] finds, in segments. Every block iteration bends the
/// whole frame under each of its trial loads (several at once, each bend holding every
/// piece's turn, shift and curvature) and keeps three blocks of shapes: the 30,197-segment
/// weeping willow peaks at 180 MB on two threads, about 6 KB a segment.
pub const MAX_SEGMENTS: usize = 100_000;

/// [`modes`] asked of a tree over [`MAX_SEGMENTS`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "the tree has {segments} segments; the whole tree's modes are found for at most {limit} \
     (physics::frame::MAX_SEGMENTS, about 6 KB a segment)"
)]
pub struct TooLarge {
    /// Segments of the tree.
    pub segments: usize,
    /// [`MAX_SEGMENTS`].
    pub limit: usize,
}

/// The `count` lowest natural modes of `tree` as a frame (fewer where it has fewer parts),
/// lowest first, with sections never thinner than their [`super::section_floor`] over
/// `min_radius` (m). Each segment's mass moves in as many parts (1, 2, 4 or [`PIECES`]) as
/// keep each part within [`PART_OF_HEIGHT`] of the tree's height. Deterministic: the trial
/// shapes come from a fixed seed and are bent in parallel but summed in order. A tree over
/// [`MAX_SEGMENTS`] is refused before anything is allocated.
pub fn modes(tree: &Tree, min_radius: f32, count: usize) -> Result<Vec<FrameMode>, TooLarge> {
    let s = &tree.segments;
    let n = s.len();
    if n > MAX_SEGMENTS {
        return Err(TooLarge { segments: n, limit: MAX_SEGMENTS });
    }
    let span = PART_OF_HEIGHT * tree.height().max(f32::MIN_POSITIVE);
    // The parts: segment, first piece, pieces; and each part's mass.
    let mut parts: Vec<(usize, usize, usize)> = Vec::new();
    let mut mass: Vec<f64> = Vec::new();
    for (i, &m) in super::beam::segment_masses(tree).iter().enumerate() {
        let split = [1, 2, 4, PIECES].into_iter().find(|&k| s.length[i] / k as f32 <= span).unwrap_or(PIECES);
        let w = PIECES / split;
        for g in 0..split {
            parts.push((i, g * w, w));
            mass.push(m as f64 / split as f64);
        }
    }
    let dofs = parts.len();
    let count = count.min(dofs);
    if count == 0 {
        return Ok(Vec::new());
    }
    let frame = Frame::new(tree, min_radius);
    let total: f64 = mass.iter().sum();
    let q = (2 * count).max(count + 8).min(dofs);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x5e1f_f4a3);
    let mut random = || -> Vec<DVec3> {
        let mut r = || rng.random_range(-1.0..1.0);
        (0..dofs).map(|_| DVec3::new(r(), r(), r())).collect()
    };
    // Bent under the inertial loads of `shape` (`F M X`), read part by part.
    let bend = |shape: &[DVec3]| -> Vec<DVec3> {
        let mut load = vec![DVec3::ZERO; n * PIECES];
        for ((&(i, first, w), u), m) in parts.iter().zip(shape).zip(&mass) {
            let f = *u * (m / w as f64);
            load[i * PIECES + first..i * PIECES + first + w].fill(f);
        }
        let piece = frame.bend(&load).piece;
        parts
            .iter()
            .map(|&(i, first, w)| piece[i * PIECES + first..i * PIECES + first + w].iter().sum::<DVec3>() / w as f64)
            .collect()
    };
    let dot = |a: &[DVec3], b: &[DVec3]| -> f64 { a.iter().zip(b).zip(&mass).map(|((u, v), m)| m * u.dot(*v)).sum() };
    // Trial shapes: the tree pushed along x and along z, then random ones.
    let mut x: Vec<Vec<DVec3>> = vec![vec![DVec3::X; dofs], vec![DVec3::Z; dofs]];
    x.truncate(q);
    while x.len() < q {
        x.push(random());
    }
    // The block's Ritz values, ω², lowest first (its shapes are `x`).
    let mut lambda: Vec<f64> = Vec::new();
    for _ in 0..MAX_ITERATIONS {
        let bent: Vec<Vec<DVec3>> = x.par_iter().map(|shape| bend(shape)).collect();
        let norm: Vec<f64> = bent.iter().map(|b| dot(b, b).sqrt().max(f64::MIN_POSITIVE)).collect();
        let m = bent.len();
        // The block's stiffness X̄ᵀ K X̄ = X̄ᵀ M X and mass X̄ᵀ M X̄, each shape scaled to 1.
        let mut k_r = DMatrix::<f64>::zeros(m, m);
        let mut m_r = DMatrix::<f64>::zeros(m, m);
        for a in 0..m {
            for b in 0..m {
                k_r[(a, b)] = dot(&bent[a], &x[b]) / (norm[a] * norm[b]);
                m_r[(a, b)] = if b < a { m_r[(b, a)] } else { dot(&bent[a], &bent[b]) / (norm[a] * norm[b]) };
            }
        }
        let k_r = (&k_r + k_r.transpose()) * 0.5;
        // An orthonormal basis of the block (shapes that have become one are dropped), then
        // its eigenproblem.
        let me = SymmetricEigen::new(m_r);
        let keep: Vec<usize> = (0..m).filter(|&j| me.eigenvalues[j] > 1e-11 * me.eigenvalues.max()).collect();
        let mut w = DMatrix::<f64>::zeros(m, keep.len());
        for (c, &j) in keep.iter().enumerate() {
            w.set_column(c, &(me.eigenvectors.column(j) / me.eigenvalues[j].sqrt()));
        }
        let ke = SymmetricEigen::new(w.transpose() * &k_r * &w);
        let mut order: Vec<usize> = (0..keep.len()).collect();
        order.sort_by(|&a, &b| ke.eigenvalues[a].total_cmp(&ke.eigenvalues[b]));
        let qm = &w * &ke.eigenvectors;
        let next: Vec<f64> = order.iter().map(|&j| ke.eigenvalues[j]).collect();
        x = order
            .iter()
            .map(|&j| {
                let mut shape = vec![DVec3::ZERO; dofs];
                for (a, b) in bent.iter().enumerate() {
                    let c = qm[(a, j)] / norm[a];
                    for (s, u) in shape.iter_mut().zip(b) {
                        *s += *u * c;
                    }
                }
                shape
            })
            .collect();
        let settled = lambda.len() >= count
            && next.len() >= count
            && (0..count).all(|j| (next[j] - lambda[j]).abs() <= TOLERANCE * next[j].abs());
        lambda = next;
        if settled {
            break;
        }
        while x.len() < q {
            x.push(random());
        }
    }
    Ok(x.iter()
        .zip(&lambda)
        .take(count)
        .map(|(shape, &l)| {
            let share = |e: DVec3| {
                let g: f64 = shape.iter().zip(&mass).map(|(u, m)| m * u.dot(e)).sum();
                (g * g / total) as f32
            };
            // Each segment's mean over its parts.
            let mut mean = vec![DVec3::ZERO; n];
            for (&(i, _, w), u) in parts.iter().zip(shape) {
                mean[i] += *u * (w as f64 / PIECES as f64);
            }
            FrameMode {
                hz: (l.max(0.0).sqrt() / std::f64::consts::TAU) as f32,
                mass_share: Vec3::new(share(DVec3::X), share(DVec3::Y), share(DVec3::Z)),
                shape: mean.iter().map(|u| u.as_vec3()).collect(),
            }
        })
        .collect())
}

/// The mode a tree sways in: of `modes`, the one that swings the most of its mass horizontally
/// (the mode a push on the whole crown sets going, and a strain gauge at the base reads).
pub fn sway_mode(modes: &[FrameMode]) -> Option<&FrameMode> {
    modes.iter().max_by(|a, b| a.horizontal_share().total_cmp(&b.horizontal_share()))
}

/// Longest part of a segment that [`modes`] moves as one, as a share of the tree's height.
pub const PART_OF_HEIGHT: f32 = 1.0 / 32.0;

/// Most block iterations of [`modes`].
const MAX_ITERATIONS: usize = 100;

/// Relative change of each of the lowest frequencies² between iterations at which [`modes`]
/// stops (a frequency then moves by under 5 × 10⁻⁷ of itself).
const TOLERANCE: f64 = 1e-6;

/// The frame's geometry and sections, ready to bend under any loads.
struct Frame<'a> {
    tree: &'a Tree,
    axis: Vec<DVec3>,
    start: Vec<DVec3>,
    /// `E I` of each piece, N·m².
    rigidity: Vec<f64>,
}

/// Displacements of a bent frame.
struct Bent {
    /// At each segment's end.
    end: Vec<DVec3>,
    /// At each piece's middle, where its load acts (segment by segment).
    piece: Vec<DVec3>,
}

impl<'a> Frame<'a> {
    fn new(tree: &'a Tree, min_radius: f32) -> Self {
        let s = &tree.segments;
        let n = s.len();
        let floor = super::section_floor(tree, min_radius);
        Self {
            tree,
            axis: (0..n).map(|i| s.axis(i).as_dvec3()).collect(),
            start: (0..n).map(|i| s.start[i].as_dvec3()).collect(),
            rigidity: (0..n * PIECES)
                .map(|j| super::beam::piece_rigidity(tree, j / PIECES, j % PIECES, &floor))
                .collect(),
        }
    }

    /// Bends the frame under `load[i · PIECES + p]`, a force at the middle of piece `p` of
    /// segment `i`.
    fn bend(&self, load: &[DVec3]) -> Bent {
        let (tree, axis, start) = (self.tree, &self.axis, &self.start);
        let s = &tree.segments;
        let n = s.len();
        let middle = |i: usize, p: usize| start[i] + axis[i] * ((p as f64 + 0.5) * s.length[i] as f64 / PIECES as f64);
        // Each segment's load with everything beyond it, and its moment about the origin Σ p × F.
        let mut force: Vec<DVec3> = (0..n).map(|i| load[i * PIECES..(i + 1) * PIECES].iter().sum()).collect();
        let mut moment: Vec<DVec3> =
            (0..n).map(|i| (0..PIECES).map(|p| middle(i, p).cross(load[i * PIECES + p])).sum()).collect();
        for i in (0..n).rev() {
            let (f, m) = tree
                .children
                .of(i)
                .iter()
                .fold((DVec3::ZERO, DVec3::ZERO), |(f, m), &c| (f + force[c as usize], m + moment[c as usize]));
            force[i] += f;
            moment[i] += m;
        }
        // Per piece: the turn and displacement at its start and its curvature vector.
        let mut theta = vec![DVec3::ZERO; n * PIECES];
        let mut shift = vec![DVec3::ZERO; n * PIECES];
        let mut kappa = vec![DVec3::ZERO; n * PIECES];
        let (mut end, mut piece) = (Vec::with_capacity(n), Vec::with_capacity(n * PIECES));
        let mut kids: Vec<(f64, usize)> = Vec::new();
        for i in 0..n {
            let (a, l) = (axis[i], s.length[i] as f64);
            let h = l / PIECES as f64;
            kids.clear();
            kids.extend(
                tree.children
                    .of(i)
                    .iter()
                    .map(|&c| (((start[c as usize] - start[i]).dot(a)).clamp(0.0, l), c as usize)),
            );
            for p in 0..PIECES {
                let along = (p as f64 + 0.5) * h;
                let x = start[i] + a * along;
                // Own pieces above this one, at their middles, and every child starting beyond.
                let (mut f, mut m) = (DVec3::ZERO, DVec3::ZERO);
                for q in p + 1..PIECES {
                    f += load[i * PIECES + q];
                    m += middle(i, q).cross(load[i * PIECES + q]);
                }
                for &(o, c) in &kids {
                    if o > along {
                        f += force[c];
                        m += moment[c];
                    }
                }
                // About x: Σ (p − x) × F.
                let bending = m - x.cross(f);
                let bending = bending - a * bending.dot(a);
                let ei = self.rigidity[i * PIECES + p];
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
                along_piece(
                    theta[q * PIECES + p],
                    shift[q * PIECES + p],
                    kappa[q * PIECES + p],
                    axis[q],
                    o - p as f64 * hq,
                )
            };
            for p in 0..PIECES {
                let j = i * PIECES + p;
                theta[j] = th;
                shift[j] = u;
                piece.push(along_piece(th, u, kappa[j], a, 0.5 * h).1);
                (th, u) = along_piece(th, u, kappa[j], a, h);
            }
            end.push(u);
        }
        Bent { end, piece }
    }
}

/// Turn and displacement `o` along a piece of constant curvature `k` on axis `a` from `th`, `u`.
fn along_piece(th: DVec3, u: DVec3, k: DVec3, a: DVec3, o: f64) -> (DVec3, DVec3) {
    (th + k * o, u + th.cross(a) * o + k.cross(a) * (0.5 * o * o))
}
