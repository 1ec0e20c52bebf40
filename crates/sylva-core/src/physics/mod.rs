//! The tree as a mechanical body, shared by every method: air, drag coefficients, the
//! mechanical radius of a joint, the loads a stem carries, each stem's natural frequency
//! ([`beam`]), the whole tree's static bend ([`frame`]) and drag with reconfiguration and
//! damping ([`drag`]). Methods keep their papers' mechanisms and take their constants from
//! here.

pub mod beam;
pub mod drag;
pub mod frame;
pub mod measure;
pub mod oscillator;

pub use beam::{StemModes, stem_frequencies};
pub use drag::{DragModel, STRUCTURAL_DAMPING};

use crate::model::Tree;

/// Air density at sea level, kg/m³.
pub const AIR_DENSITY: f32 = 1.225;

/// Thinnest radius a joint bends at, m. 1.5 mm: generators taper twigs toward zero for
/// looks, but living twig tips are 2–5 mm thick.
pub const MIN_RADIUS: f32 = 0.0015;

/// Drag coefficient of bark and leaves together (a cylinder in cross-flow ≈ 1.0–1.2;
/// leaves streamline in wind, lowering it).
pub const BRANCH_DRAG: f32 = 0.8;

/// Effective drag coefficient per unit (one-sided) leaf area. 0.03: leaves in a crown
/// shelter one another, so the sum over leaves must come to a crown's drag (C_d ≈ 0.2–0.3 on
/// the crown's frontal area, which for a broadleaf crown is 5–10 times smaller than its leaf
/// area).
pub const LEAF_DRAG: f32 = 0.03;

/// Drag coefficient of a whole crown on its frontal area (0.25: crowns measured in wind
/// tunnels give 0.2–0.3 at moderate speeds before they streamline, Mayhead 1973; Vollsinger
/// et al. 2005).
pub const CROWN_DRAG: f32 = 0.25;

/// How much the crown of `tree` shelters itself, 0–1: the factor on the drag of its leaves
/// (`leaf_drag` per unit area) and of the bark of every stem but the trunk (`bark_drag`) so
/// that together they drag no more than the crown would as a body, [`CROWN_DRAG`] on its
/// frontal area (in a dense crown, leaves and twigs sit in one another's wake). The frontal
/// area is the ellipse spanned by the leaves' height and horizontal spread; a tree without
/// leaves is not sheltered.
pub fn crown_shelter(tree: &Tree, bark_drag: f32, leaf_drag: f32) -> f32 {
    let l = &tree.leaves;
    if l.is_empty() {
        return 1.0;
    }
    let (mut lo, mut hi) = (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN));
    let mut drag = 0.0f32;
    for k in 0..l.len() {
        lo = lo.min(l.position[k]);
        hi = hi.max(l.position[k]);
        drag += leaf_drag * std::f32::consts::FRAC_PI_4 * l.width[k] * l.length[k];
    }
    let s = &tree.segments;
    for i in 0..s.len() {
        if tree.stems.level[s.stem[i] as usize] > 0 {
            drag += bark_drag * (s.radius_base[i] + s.radius_tip[i]) * s.length[i];
        }
    }
    let size = hi - lo;
    let frontal = std::f32::consts::FRAC_PI_4 * size.y * 0.5 * (size.x + size.z);
    if drag > 0.0 { (CROWN_DRAG * frontal / drag).clamp(0.0, 1.0) } else { 1.0 }
}

/// Thinnest radius each segment bends at, m: `min_radius`, and, on side stems, never
/// thinner for the leaf area it carries (its own and everything beyond) than the tree's
/// main branches are drawn. The pipe model (Shinozaki et al. 1964: a stem's section is
/// proportional to the leaf area beyond it) with its constant read from the tree itself,
/// the median over first-order branches of leaf area per section, so presets whose leaves
/// are drawn large for looks are not stiffened. Generators taper a child by its parent's
/// radius where it grows, so twigs near a branch's tip come out hair-thin under a metre of
/// leafy shoot, and would sway slower than the trunk. The trunk keeps its drawn section,
/// which the presets' field frequencies rest on.
pub fn section_floor(tree: &Tree, min_radius: f32) -> Vec<f32> {
    let s = &tree.segments;
    let mut own = vec![0.0f32; s.len()];
    for (k, &seg) in tree.leaves.segment.iter().enumerate() {
        own[seg as usize] += std::f32::consts::FRAC_PI_4 * tree.leaves.width[k] * tree.leaves.length[k];
    }
    let leaf_area = beam::subtree_sums(tree, &own);
    let st = &tree.stems;
    let mut per_section: Vec<f32> = (0..st.len())
        .filter(|&k| st.level[k] == 1 && st.segment_count[k] > 0)
        .map(|k| st.first_segment[k] as usize)
        .filter(|&i| leaf_area[i] > 0.0 && s.radius_base[i] > 0.0)
        .map(|i| leaf_area[i] / (std::f32::consts::PI * s.radius_base[i] * s.radius_base[i]))
        .collect();
    per_section.sort_by(f32::total_cmp);
    let Some(&ratio) = per_section.get(per_section.len() / 2) else {
        return vec![min_radius; s.len()];
    };
    let per_area = 1.0 / (std::f32::consts::PI * ratio);
    let trunk = |i: usize| st.level[s.stem[i] as usize] == 0;
    leaf_area
        .iter()
        .enumerate()
        .map(|(i, &a)| if trunk(i) { min_radius } else { (a * per_area).sqrt().max(min_radius) })
        .collect()
}

/// Mechanical radius of each segment, m: its own base radius, but never thinner than its
/// [`section_floor`] nor than the radius whose section equals its children's together
/// (Leonardo's rule — a joint carries what grows beyond it). Generators taper radii for
/// looks; the mechanics of Akagi's joints and HSM's clusters need this.
pub fn mechanical_radii(tree: &Tree, min_radius: f32) -> Vec<f32> {
    let s = &tree.segments;
    let floor = section_floor(tree, min_radius);
    let mut r = vec![0.0f32; s.len()];
    for i in (0..s.len()).rev() {
        let carried: f32 = tree.children.of(i).iter().map(|&c| r[c as usize].powi(2)).sum();
        r[i] = s.radius_base[i].max(floor[i]).max(carried.sqrt());
    }
    r
}

/// Radius at which each segment bends, m: its own base radius (the section the tree is
/// drawn with), never under its [`section_floor`].
pub fn bending_radii(tree: &Tree, min_radius: f32) -> Vec<f32> {
    let floor = section_floor(tree, min_radius);
    tree.segments.radius_base.iter().zip(&floor).map(|(r, f)| r.max(*f)).collect()
}

/// What one stem carries, as a rod turning about its base joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StemLoad {
    /// Area facing the wind: bark (2 r̄ L per segment) and leaf blades (π/4 · w · l), m².
    pub area: f32,
    /// Wood and leaf mass of the stem's own segments, kg.
    pub mass: f32,
    /// Arc length (never under 0.1 mm), m.
    pub length: f32,
    /// Rotational stiffness of the base joint `E·I/L` (never under 1e-9), N·m/rad.
    pub stiffness: f32,
}

impl StemLoad {
    /// The load of stem `k` of `tree`.
    pub fn of(tree: &Tree, k: usize) -> Self {
        let s = &tree.segments;
        let st = &tree.stems;
        let first = st.first_segment[k] as usize;
        let n = st.segment_count[k] as usize;
        let (mut area, mut mass) = (0.0f32, 0.0f32);
        for i in first..first + n {
            area += (s.radius_base[i] + s.radius_tip[i]) * s.length[i];
            mass += s.mass[i];
            let (o, c) = (tree.children.leaf_offset[i] as usize, tree.children.leaf_count[i] as usize);
            for l in o..o + c {
                let a = std::f32::consts::FRAC_PI_4 * tree.leaves.width[l] * tree.leaves.length[l];
                area += a;
                mass += a * tree.wood.leaf_areal_density;
            }
        }
        Self { area, mass, length: st.length[k].max(1e-4), stiffness: s.stiffness[first].max(1e-9) }
    }

    /// Static bend per (m/s)² of wind, rad·s²/m²: the drag torque `½ ρ C_d A U² · L/2` with
    /// [`BRANCH_DRAG`] over the stiffness (Ota 2003's `θ = τ / k`).
    pub fn bend_per_u2(&self) -> f32 {
        let torque_per_u2 = 0.5 * AIR_DENSITY * BRANCH_DRAG * self.area * 0.5 * self.length;
        torque_per_u2 / self.stiffness
    }

    /// Sway frequency of the stem as a rod turning about its end, `√(k / (m L²/3)) / 2π`,
    /// Hz (unclamped).
    pub fn frequency(&self) -> f32 {
        (self.stiffness / (self.mass.max(1e-6) * self.length * self.length / 3.0)).sqrt() / std::f32::consts::TAU
    }
}
