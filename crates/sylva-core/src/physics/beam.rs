//! Each stem's first bending mode and static bend, as a continuous tapered cantilever: the
//! natural frequency from the wood (E, density), its sections and the mass it carries (its
//! own wood and leaves, and every stem growing from it, lumped where it starts), and the
//! tip's deflection under the drag on all of that ([`drag_bend`]; [`drag_bend_with`] can carry
//! each side stem as a rigid body instead, its load's couple too, as Akagi does).
//!
//! The beam is integrated in [`PIECES`] pieces per segment, each with the section at its
//! middle (radii tapering from the segment's base to its tip, never under the section that
//! carries its leaves, [`super::section_floor`]): the moment from every load beyond a point,
//! curvature `M / E I`, slope and deflection. The frequency is Rayleigh's quotient with the
//! static deflection under the stem's own weight as the mode shape (the "static deflection
//! method"; for a uniform cantilever it gives 3.53 √(EI/ρA)/L² against the exact
//! 1.875² = 3.516, 0.4 % high):
//! `ω² = Σ m y / Σ m y²` over the stem's masses, with `y` the deflection under loads equal
//! to those masses.

use crate::model::Tree;
use glam::DVec3;

/// Pieces each segment is integrated in.
pub const PIECES: usize = 8;

/// Per-stem natural frequencies of one tree.
#[derive(Debug, Clone, PartialEq)]
pub struct StemModes {
    /// First-mode angular frequency of each stem, rad/s (tree order).
    pub omega: Vec<f32>,
    /// Mass carried by each segment's joint: its segment and everything beyond, kg.
    pub subtree_mass: Vec<f32>,
}

impl StemModes {
    /// First-mode frequency of stem `k`, Hz.
    pub fn hz(&self, k: usize) -> f32 {
        self.omega[k] / std::f32::consts::TAU
    }
}

/// Mass of each segment with its leaves, kg.
pub fn segment_masses(tree: &Tree) -> Vec<f32> {
    let s = &tree.segments;
    let mut m = s.mass.clone();
    for (k, &seg) in tree.leaves.segment.iter().enumerate() {
        let area = std::f32::consts::FRAC_PI_4 * tree.leaves.width[k] * tree.leaves.length[k];
        m[seg as usize] += area * tree.wood.leaf_areal_density;
    }
    m
}

/// Drag area `C_d A` of each segment, m²: its bark (`(r_base + r_tip) ℓ`) with `bark_drag`
/// and its leaf blades (π/4 · w · l) with `leaf_drag`, both times `shelter` except the
/// trunk's bark ([`super::crown_shelter`]).
pub fn drag_areas(tree: &Tree, bark_drag: f32, leaf_drag: f32, shelter: f32) -> Vec<f32> {
    let s = &tree.segments;
    let mut a: Vec<f32> = (0..s.len())
        .map(|i| {
            let crown = if tree.stems.level[s.stem[i] as usize] == 0 { 1.0 } else { shelter };
            crown * bark_drag * (s.radius_base[i] + s.radius_tip[i]) * s.length[i]
        })
        .collect();
    for (k, &seg) in tree.leaves.segment.iter().enumerate() {
        a[seg as usize] +=
            shelter * leaf_drag * std::f32::consts::FRAC_PI_4 * tree.leaves.width[k] * tree.leaves.length[k];
    }
    a
}

/// How each stem bends under the wind's drag.
#[derive(Debug, Clone, PartialEq)]
pub struct DragBend {
    /// Static tip deflection per pascal of dynamic pressure `½ ρ u²`, m/Pa (tree order).
    pub tip: Vec<f32>,
    /// How fast the drag's point of work moves, as a share of the tip's speed: with the bend
    /// as the stem's mode shape `φ = y / y_tip`, a part moving at `φ` times the tip's speed
    /// loses `ρ C_d A u g φ` of its drag, which the mode feels times `φ` again, so the mode's
    /// aerodynamic damping is the tip's `ρ u g Σ a φ²` against the stiffness that gives the
    /// tip `Σ a φ` per pascal: the weight `Σ F y² / (y_tip Σ F y)` (52/81 ≈ 0.642 for a
    /// uniform load on a uniform cantilever; more where the load sits near the tip, as a crown
    /// does). Loads where a stem barely moves (its side stems lumped near its base, a forked
    /// trunk's other leaders) neither push its mode nor damp it. Side stems count where they
    /// start (their couples' own motion is left out).
    pub damping_centre: Vec<f32>,
}

/// [`DragBend::damping_centre`] of a uniform load on a uniform cantilever, `∫φ² / ∫φ` with
/// `φ(ξ) = (ξ⁴ − 4ξ³ + 6ξ²) / 3`: the weight given to a stem with no load or no bend.
pub const UNIFORM_CENTRE: f32 = 52.0 / 81.0;

/// How a stem's beam carries the stems that grow from it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SideStems {
    /// Each as its whole load where it starts: the description every method takes its
    /// frequencies and bends from.
    AtBase,
    /// Each as a rigid body on the point it starts from: its whole load there and that load's
    /// couple about the point, every load beyond times its reach along the stem's axis, as
    /// Akagi's propagation carries them (children's forces times their whole lever arms). A
    /// side stem that rises from a thin stem turns it more than its load alone would.
    Rigid,
}

/// Each stem's static bend under the drag of the stem and of everything growing from it
/// (`cd_area`: each segment's `C_d A`, [`drag_areas`]): each segment's own drag spread along
/// it, every side stem's whole subtree where it starts; sections never thinner than their
/// [`super::section_floor`] over `min_radius` (m).
pub fn drag_bend(tree: &Tree, min_radius: f32, cd_area: &[f32]) -> DragBend {
    drag_bend_with(tree, min_radius, cd_area, SideStems::AtBase)
}

/// [`drag_bend`] with the side stems carried as `side`.
pub fn drag_bend_with(tree: &Tree, min_radius: f32, cd_area: &[f32], side: SideStems) -> DragBend {
    let subtree = subtree_sums(tree, cd_area);
    let reach = match side {
        SideStems::AtBase => None,
        SideStems::Rigid => Some(first_moments(tree, cd_area)),
    };
    let floor = super::section_floor(tree, min_radius);
    let mut beam = Beam::default();
    let (mut tip, mut damping_centre) = (Vec::new(), Vec::new());
    for k in 0..tree.stems.len() {
        beam.bend(tree, k, cd_area, &subtree, &floor, reach.as_deref());
        let y_tip = beam.tip();
        let (mut work, mut squares) = (0.0f64, 0.0f64);
        for &(f, y) in &beam.loads {
            work += f * y;
            squares += f * y * y;
        }
        tip.push(y_tip as f32);
        damping_centre.push(if work > 0.0 && y_tip > 0.0 { (squares / (work * y_tip)) as f32 } else { UNIFORM_CENTRE });
    }
    DragBend { tip, damping_centre }
}

/// The first bending mode of every stem of `tree`, with sections never thinner than their
/// [`super::section_floor`] over `min_radius` (m). Stems with no mass or no compliance get
/// 0 rad/s.
pub fn stem_frequencies(tree: &Tree, min_radius: f32) -> StemModes {
    let own = segment_masses(tree);
    let subtree_mass = subtree_sums(tree, &own);
    let floor = super::section_floor(tree, min_radius);
    let mut beam = Beam::default();
    let omega = (0..tree.stems.len())
        .map(|k| {
            // Loads equal to the masses (g = 1); Rayleigh's sums over the deflections.
            beam.bend(tree, k, &own, &subtree_mass, &floor, None);
            let (mut work, mut kinetic) = (0.0f64, 0.0f64);
            for &(m, y) in &beam.loads {
                work += m * y;
                kinetic += m * y * y;
            }
            if kinetic > 0.0 && work > 0.0 { (work / kinetic).sqrt() as f32 } else { 0.0 }
        })
        .collect();
    StemModes { omega, subtree_mass }
}

/// Each segment's value summed with everything beyond it.
pub(crate) fn subtree_sums(tree: &Tree, own: &[f32]) -> Vec<f32> {
    let mut sum = own.to_vec();
    for i in (0..sum.len()).rev() {
        let carried: f32 = tree.children.of(i).iter().map(|&c| sum[c as usize]).sum();
        sum[i] += carried;
    }
    sum
}

/// Each segment's first moment of `own` about the origin with everything beyond it,
/// `Σ own_j c_j` over its subtree (`c_j` each segment's middle, where its own load acts on
/// average), m·(unit of `own`).
pub(super) fn first_moments(tree: &Tree, own: &[f32]) -> Vec<DVec3> {
    let s = &tree.segments;
    let mut sum: Vec<DVec3> = (0..own.len())
        .map(|i| (s.start[i].as_dvec3() + 0.5 * s.length[i] as f64 * s.axis(i).as_dvec3()) * own[i] as f64)
        .collect();
    for i in (0..sum.len()).rev() {
        let carried: DVec3 = tree.children.of(i).iter().map(|&c| sum[c as usize]).sum();
        sum[i] += carried;
    }
    sum
}

/// Flexural rigidity `E I` of piece `p` of segment `i`, N·m²: the section at the piece's
/// middle, tapering from the segment's base to its tip, never under `floor[i]` (m).
pub(super) fn piece_rigidity(tree: &Tree, i: usize, p: usize, floor: &[f32]) -> f64 {
    let s = &tree.segments;
    let t = (p as f32 + 0.5) / PIECES as f32;
    let r = (s.radius_base[i] + (s.radius_tip[i] - s.radius_base[i]) * t).max(floor[i]) as f64;
    tree.wood.young_modulus as f64 * std::f64::consts::FRAC_PI_4 * r.powi(4)
}

/// One piece of a stem: where it starts along the stem, its length and flexural rigidity,
/// and (after bending) its curvature, and the slope and deflection at its start.
#[derive(Debug, Clone, Copy, Default)]
struct Piece {
    x: f64,
    h: f64,
    ei: f64,
    curvature: f64,
    slope: f64,
    y: f64,
}

impl Piece {
    /// Deflection `o` along the piece (constant curvature within it).
    fn y_at(&self, o: f64) -> f64 {
        self.y + self.slope * o + 0.5 * self.curvature * o * o
    }
}

/// A stem bent as a continuous tapered cantilever under lateral point loads.
#[derive(Debug, Default)]
struct Beam {
    pieces: Vec<Piece>,
    /// Each load's piece, offset within it (m), size and couple (the size times m).
    at: Vec<(usize, f64, f64, f64)>,
    /// Each load's size and deflection, after [`Beam::bend`].
    loads: Vec<(f64, f64)>,
    events: Vec<(f64, usize)>,
}

impl Beam {
    /// Bends stem `k` under `own[i]` spread along each of its segments and `subtree[c]` where
    /// each side stem starts (unit loads give deflections per load), and, given each
    /// segment's subtree first moment `reach` ([`first_moments`]), each side stem's couple
    /// about where it starts ([`SideStems::Rigid`]). Sections are never thinner than `floor`
    /// (per segment, m).
    fn bend(&mut self, tree: &Tree, k: usize, own: &[f32], subtree: &[f32], floor: &[f32], reach: Option<&[DVec3]>) {
        let s = &tree.segments;
        let first = tree.stems.first_segment[k] as usize;
        let count = tree.stems.segment_count[k] as usize;
        self.pieces.clear();
        self.at.clear();
        let mut x = 0.0f64;
        for (i, &load) in own.iter().enumerate().skip(first).take(count) {
            let l = s.length[i] as f64;
            let h = l / PIECES as f64;
            let base = self.pieces.len();
            for p in 0..PIECES {
                let ei = piece_rigidity(tree, i, p, floor);
                self.pieces.push(Piece { x: x + p as f64 * h, h, ei, ..Default::default() });
                self.at.push((base + p, 0.5 * h, load as f64 / PIECES as f64, 0.0));
            }
            for &c in tree.children.of(i) {
                let c = c as usize;
                if s.stem[c] as usize != k {
                    let along = ((s.start[c] - s.start[i]).dot(s.axis(i)) as f64).clamp(0.0, l);
                    let p = ((along / h) as usize).min(PIECES - 1);
                    // Σ F (x − x_c)·a over the side stem: its first moment less its load
                    // times where it starts, along the stem's axis.
                    let couple = reach.map_or(0.0, |m| {
                        let a = s.axis(i).as_dvec3();
                        (m[c] - s.start[c].as_dvec3() * subtree[c] as f64).dot(a)
                    });
                    self.at.push((base + p, along - p as f64 * h, subtree[c] as f64, couple));
                }
            }
            x += l;
        }
        // Moments at the pieces' middles: sweep from the tip down over loads and middles,
        // carrying the force beyond and its moment.
        self.events.clear();
        self.events.extend(self.at.iter().enumerate().map(|(n, &(p, o, ..))| (self.pieces[p].x + o, n)));
        self.events.extend(self.pieces.iter().enumerate().map(|(p, q)| (q.x + 0.5 * q.h, usize::MAX - p)));
        self.events.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let (mut force, mut moment, mut here) = (0.0f64, 0.0f64, x);
        for &(pos, e) in &self.events {
            moment += force * (here - pos);
            here = pos;
            if e >= self.at.len() {
                let q = &mut self.pieces[usize::MAX - e];
                q.curvature = if q.ei > 0.0 { moment / q.ei } else { 0.0 };
            } else {
                force += self.at[e].2;
                moment += self.at[e].3;
            }
        }
        // Slopes and deflections from the base.
        let (mut slope, mut y) = (0.0f64, 0.0f64);
        for q in &mut self.pieces {
            q.slope = slope;
            q.y = y;
            y += slope * q.h + 0.5 * q.curvature * q.h * q.h;
            slope += q.curvature * q.h;
        }
        self.loads.clear();
        self.loads.extend(self.at.iter().map(|&(p, o, f, _)| (f, self.pieces[p].y_at(o))));
    }

    /// Deflection of the stem's tip.
    fn tip(&self) -> f64 {
        self.pieces.last().map_or(0.0, |q| q.y_at(q.h))
    }
}
