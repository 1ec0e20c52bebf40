//! Each stem's first bending mode: the natural frequency of a tapered cantilever from the
//! wood (E, density), its sections and the mass it carries (its own wood and leaves, and
//! every stem growing from it, lumped where it attaches).
//!
//! The frequency is Rayleigh's quotient with the static deflection under the stem's own
//! weight as the mode shape (the "static deflection method"; for a uniform cantilever it
//! gives 3.53 √(EI/ρA)/L² against the exact 1.875² = 3.516, 0.4 % high):
//! `ω² = Σ m y / Σ m y²` over the stem's masses, with `y` the deflection under loads equal
//! to those masses. The stem bends at its joints, each a spring `k = E I / ℓ` of its
//! segment's length ℓ and mechanical radius ([`super::mechanical_radii`]) — a chain of such
//! springs bends as the continuous beam does under the same moments — and each segment
//! turns rigidly between joints, so its own mass enters `Σ m y²` as a rod's,
//! `m (y_c² + (φ ℓ)²/12)`.

use crate::model::Tree;

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

/// The first bending mode of every stem of `tree`, with joints never thinner than
/// `min_radius` (m). Stems with no mass or no compliance get 0 rad/s.
pub fn stem_frequencies(tree: &Tree, min_radius: f32) -> StemModes {
    stem_frequencies_with(tree, &super::bending_radii(tree, min_radius))
}

/// [`stem_frequencies`] with each joint's bending radius given (m).
pub fn stem_frequencies_with(tree: &Tree, r_mech: &[f32]) -> StemModes {
    let s = &tree.segments;
    let st = &tree.stems;
    let n = s.len();
    let own = segment_masses(tree);
    let mut subtree_mass = own.clone();
    for i in (0..n).rev() {
        let carried: f32 = tree.children.of(i).iter().map(|&c| subtree_mass[c as usize]).sum();
        subtree_mass[i] += carried;
    }
    let mut omega = vec![0.0f32; st.len()];
    // Per segment of a stem: own mass at the centre, child stems lumped at the end.
    let mut lumped = Vec::new();
    let mut compliance = Vec::new();
    let mut moment = Vec::new();
    for (k, w) in omega.iter_mut().enumerate() {
        let first = st.first_segment[k] as usize;
        let count = st.segment_count[k] as usize;
        if count == 0 {
            continue;
        }
        let range = first..first + count;
        lumped.clear();
        compliance.clear();
        for i in range.clone() {
            let side: f32 = tree
                .children
                .of(i)
                .iter()
                .filter(|&&c| s.stem[c as usize] as usize != k)
                .map(|&c| subtree_mass[c as usize])
                .sum();
            lumped.push(side as f64);
            let stiff = tree.wood.segment_stiffness(s.length[i], r_mech[i]) as f64;
            compliance.push(if stiff > 0.0 { 1.0 / stiff } else { 0.0 });
        }
        // Bending moment at each joint under loads equal to the masses (g = 1), tip first.
        moment.clear();
        moment.resize(count, 0.0f64);
        let (mut beyond, mut m_next) = (0.0f64, 0.0f64);
        for j in (0..count).rev() {
            let (l, m) = (s.length[first + j] as f64, own[first + j] as f64);
            moment[j] = m_next + (beyond + lumped[j]) * l + m * 0.5 * l;
            beyond += lumped[j] + m;
            m_next = moment[j];
        }
        // Slope and deflection from the base; Rayleigh's sums.
        let (mut slope, mut y, mut work, mut kinetic) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for j in 0..count {
            let (l, m) = (s.length[first + j] as f64, own[first + j] as f64);
            slope += moment[j] * compliance[j];
            let yc = y + slope * 0.5 * l;
            let ye = y + slope * l;
            work += m * yc + lumped[j] * ye;
            kinetic += m * (yc * yc + slope * slope * l * l / 12.0) + lumped[j] * ye * ye;
            y = ye;
        }
        if kinetic > 0.0 && work > 0.0 {
            *w = (work / kinetic).sqrt() as f32;
        }
    }
    StemModes { omega, subtree_mass }
}
