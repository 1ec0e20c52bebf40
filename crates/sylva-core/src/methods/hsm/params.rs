//! Parameters of hierarchical shape matching: units, defaults and their sources, the
//! limits a layout may reach, and the checks that name a field and what it expected.

/// Largest particles per ring, rings per segment and particles per leaf.
pub const MAX_PER_CLUSTER: u32 = 64;

/// Parameters of hierarchical shape matching.
#[derive(Debug, Clone, Copy, PartialEq, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HsmParams {
    /// Rings per segment cluster, the shared head ring included (≥ 2). Default 2: head and
    /// tail, Song's Fig. 5.
    pub rings: u32,
    /// Particles per ring (≥ 3). Default 4: the fewest that make a ring resist twist as
    /// well as bending, at Song's cost per cluster (Table 2 has 42–60 particles per
    /// cluster; the bench sets rings and ring size to match).
    pub ring_size: u32,
    /// Smallest ring radius as a fraction of the segment's length. Default 0.25 (see the
    /// module notes: a joint's bending resistance is the lever of its shared ring).
    pub ring_ratio: f32,
    /// How far a segment cluster reaches into its parent: 1 = the parent's ring nearest
    /// to the joint (Song's head-to-tail link), 2 = the parent's whole segment (all its
    /// rings). Default 2: a joint then resists bending through the parent's length rather
    /// than a ring's radius, so a trunk holds its crown up under gravity with few substeps
    /// (Müller et al. 2005 widen overlapping regions for the same reason).
    pub overlap: u32,
    /// Add a cluster per stem over all its rings (Song's global shape matching, Fig. 4).
    /// Default true: with segment clusters alone, load travels one segment per substep and
    /// a long stem sags with the square of its segment count.
    pub stem_clusters: bool,
    /// Particles on each leaf blade besides the shared ring (≥ 1). Default 2: its tip and
    /// a point on its edge, enough to give the blade an orientation.
    pub leaf_particles: u32,
    /// Scale on every segment cluster's stiffness. Default 1: the wood's own bending
    /// stiffness (see the module notes on how a cluster's `k` follows from `E·I/L`).
    pub stiffness_scale: f32,
    /// Thinnest radius used for a joint's bending stiffness, m (as
    /// [`crate::methods::akagi::AkagiParams::min_radius`]). Default 1.5 mm.
    pub min_radius: f32,
    /// Scale of the leaf clusters' rates: a leaf's rate is its petiole's swing `ω²` (the
    /// closed form's [`crate::leaves::leaf_constants`], from the blade and the species'
    /// `[leaf_motion]`, above its twig's mode) times this. Default 1.
    pub leaf_stiffness: f32,
    /// RMS of the air's velocity at a leaf's scale and in its band, as a fraction of the
    /// wind the leaf feels inside the crown ([`crate::leaves::LeafMotion::crown_wind`] of the
    /// wind at its centre), well above the flutter onset
    /// ([`crate::leaves::LeafMotion::flutter_onset`]); see [`super::kernels::leaf_air`].
    /// Default 0.3: canopy turbulence intensities are 0.3–0.6 (Finnigan 2000), and 0.3 makes
    /// HSM's leaves flutter about as much as the closed form's in `gusty` (`leaf_motion`
    /// tests). 0: leaves move only with the resolved wind.
    pub leaf_turbulence: f32,
    /// Whether a leaf's swing pulls back on its twig. Default false: the ring moves its
    /// leaves and carries their mass and drag, as the closed-form methods' segments do, but
    /// takes none of their swing, so every leaf flutters above its twig (`leaf_motion`'s
    /// gusty test: 48 of 48 probed leaves of the half-size aspen). True: Song's linked
    /// clusters carry force both ways, a leaf cluster sharing its ring with its segment, so
    /// a leaf turned by θ turns its segment by about `k_p / K` θ (its petiole's swing
    /// stiffness over the segment's `E I / L`), and a twig tip lighter than its leaf swings
    /// with it at one coupled frequency (13 of the half-size aspen's 48 probed leaves).
    pub leaf_reaction: bool,
    /// Structural damping ratio ζ of the trunk's first mode: velocities are damped at the
    /// rate `c = 2 ζ ω₀` (`v *= e^{−c h}` each substep), ω₀ the trunk's frequency from the
    /// wood ([`crate::physics::stem_frequencies`]), so the ratio holds at any step. The
    /// drag adds the air's damping, which rises with the wind. Default
    /// [`crate::physics::STRUCTURAL_DAMPING`] (0.04), as Akagi and Skjermo.
    pub damping_ratio: f32,
    /// Drag coefficient of bark (a cylinder in cross-flow ≈ 1.0–1.2). Default 0.8.
    pub drag: f32,
    /// Drag coefficient per (one-sided) leaf area. Default 0.05: leaves shelter one
    /// another (see [`crate::methods::akagi::AkagiParams::leaf_drag`]). Leaves and the bark
    /// of side stems are sheltered by the crown as in the other methods
    /// ([`crate::physics::crown_shelter`]); the trunk's bark is not.
    pub leaf_drag: f32,
    /// Factor on every particle's drag, bark and leaves, on top of the calibration's (see
    /// [`Self::calibrate`]: with it the trunk top leans in steady wind as the beam does).
    /// Default 0.85: at the beam's lean HSM's trunk answers gusts more than the others' do
    /// (the aspen sways 2.6–2.7 % of its height in `gusty` with 1, 2.0× Akagi's 1.34 %),
    /// and with 0.85 the aspen's size series (7–21 m) sways 2.05–2.20 %, among the others'
    /// 1.26–2.41 % and at most 1.71× Akagi's (`sylva fidelity --quick --species
    /// quaking_aspen`). It scales the drag's load, not the air's damping (see
    /// [`Self::air_damping`]).
    pub drag_scale: f32,
    /// Factor on the air's damping: a particle's drag is `kd |r| r` on the relative
    /// velocity `r = wind − a v`, `a` this factor times the calibration's
    /// [`super::HsmLayout::air_scale`] over the drag's scales ([`Self::drag_scale`] and the
    /// calibration's), so the load in still parts is the scaled drag's and the drag's change
    /// with the particle's own velocity (`∂F/∂v`, the aerodynamic damping) is the sheltered
    /// drag's, weighed so the trunk's mode meets it as the wood and leaves would. Default 1:
    /// a uniform cantilever rings at the continuous beam's air damping `c / (2 m ω)` (as
    /// Akagi, Skjermo and Zioma do); the small aspen's trunk at ζ 0.087 at 15 m/s against the
    /// beam's 0.095.
    pub air_damping: f32,
    /// Speed around which bark and leaves streamline, m/s (see
    /// [`crate::physics::DragModel`]; default 5, as the other methods).
    pub reconfiguration_speed: f32,
    /// Vogel exponent B: drag grows as `U^(2+B)` well above the reconfiguration speed
    /// (default −0.7, Vogel 1989; 0 for bare quadratic drag).
    pub vogel_exponent: f32,
    /// Gravity along −Y, m/s². Default 9.81.
    pub gravity: f32,
    /// The tree as generated is its shape *under its own weight*: a support equal and
    /// opposite to gravity holds every particle, so still air keeps the rest shape exactly.
    /// Default true: generators draw trees as they stand, and a particle's step toward its
    /// goal is capped at ᾱ = 1 per substep, which for tall, thin trees is less than wood's —
    /// bare gravity would sag them (a stem of n segments sags roughly as n² h² g). A support
    /// that turned with the wood (`−R g`) was tried and rejected: it is not conservative
    /// and pumps energy into spinning leaves. False applies bare gravity.
    pub prestressed: bool,
    /// Müller's linear blend β ∈ [0, 1]: 0 matches rotations only (rigid clusters);
    /// larger values let clusters shear and stretch. Default 0.
    pub beta: f32,
    /// Iterations of the rotation extraction per step (all of them run, so R is a
    /// continuous function of the particles; see [`crate::methods::hsm::kernels::extract_rotation`]).
    /// Default 2: warm-started from the last substep, one iteration tracks the motion and
    /// the second refines it; a cold start (a cluster rotated far in one step) needs up to
    /// about 20.
    pub polar_iterations: u32,
    /// Run stages 3 and 4 as one pass per particle (`hsm_particles`) instead of two
    /// (`hsm_goals`, then `hsm_integrate` through the goal buffer). Default true: a
    /// particle's gathered goal is read by no other particle, so the fused pass gives the
    /// same numbers bit for bit while moving about a quarter fewer bytes per step (see
    /// `docs/PERFORMANCE.md`). On the CPU the fused pass runs over runs of particles that
    /// share their clusters, eight to an AVX2 register ([`crate::methods::hsm::runs`]), with
    /// the same bits again. False runs Song's four stages as published and keeps
    /// [`super::HsmState::goal`] up to date (the fused pass leaves it as it was).
    pub fused: bool,
    /// Fewest substeps per `step` call. Default 1: [`Self::substep_rate`] sets how many.
    pub substeps: u32,
    /// Substep rate r, Hz: a step of `dt` runs at least `⌈dt · r √max(s, 1)⌉` substeps (s
    /// the rate scale, see [`Self::calibrate`]), and a particle is held at no more than the
    /// rate `s r²` (1/s²) whatever the substep, `ᾱ = min(Σ w, s (r h)²)`. The wood of short,
    /// thick segments is stiffer than any affordable explicit step can hold; with the hold
    /// a rate of the tree, not of the step, the same tree sways at the same frequency at 30,
    /// 60, 120 or 240 frames/s. Default 480 (eight substeps at 60 frames/s). 0: exactly
    /// `substeps` substeps with Müller's clamp `ᾱ ≤ 1` (Song's tables), so the stiffness
    /// then follows the step.
    pub substep_rate: f32,
    /// Scale the segment and stem clusters' rates (and the hold) so that the trunk and every
    /// side stem sway at their first modes from the wood, [`crate::physics::stem_frequencies`]
    /// (times `√stiffness_scale`): HSM plucks its stems when the method is built and measures
    /// them (see [`super::calibrate`]). Default true: shape matching's clusters have a rate
    /// each but no modulus, and their ring levers make a chain of them stiffer than the beam
    /// it stands for. Leaves keep their petioles' rates. Needs `substep_rate > 0`.
    pub calibrate: bool,
}

impl Default for HsmParams {
    fn default() -> Self {
        Self {
            rings: 2,
            ring_size: 4,
            ring_ratio: 0.25,
            overlap: 2,
            stem_clusters: true,
            leaf_particles: 2,
            stiffness_scale: 1.0,
            min_radius: 0.0015,
            leaf_stiffness: 1.0,
            leaf_turbulence: 0.3,
            leaf_reaction: false,
            damping_ratio: crate::physics::STRUCTURAL_DAMPING,
            drag: 0.8,
            leaf_drag: 0.05,
            drag_scale: 0.85,
            air_damping: 1.0,
            reconfiguration_speed: crate::physics::DragModel::default().reconfiguration_speed,
            vogel_exponent: crate::physics::DragModel::default().vogel_exponent,
            gravity: 9.81,
            prestressed: true,
            beta: 0.0,
            polar_iterations: 2,
            fused: true,
            substeps: 1,
            substep_rate: 480.0,
            calibrate: true,
        }
    }
}

impl HsmParams {
    /// The cluster sizes of Song's Tables 2 and 3 (42–60 particles per cluster): segment
    /// clusters of 4 rings of 14 (42 particles of their own, 56 at the root), leaves of 42
    /// blade particles, no stem clusters (the paper's counts have none), one substep per step
    /// (the paper's frame is one shape-matching pass, Müller's clamp, no calibration).
    pub fn song_tables() -> Self {
        Self {
            rings: 4,
            ring_size: 14,
            leaf_particles: 42,
            stem_clusters: false,
            substeps: 1,
            substep_rate: 0.0,
            calibrate: false,
            ..Self::default()
        }
    }
}

/// An unusable parameter or a layout beyond its limits.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HsmError {
    /// A parameter outside its range.
    #[error("hsm parameter `{field}` = {value}: {expected}")]
    Param { field: &'static str, value: f32, expected: &'static str },
    /// The layout would exceed a limit.
    #[error("hsm layout needs {needed} {what}, more than the limit of {limit}")]
    TooLarge { what: &'static str, needed: usize, limit: usize },
}

/// Largest number of particles (and of slots) in one layout: 64 million (≈ 4 GB of state).
pub const MAX_PARTICLES: usize = 64 << 20;

/// Highest [`HsmParams::substep_rate`], Hz.
pub const MAX_SUBSTEP_RATE: f32 = 100_000.0;

/// Most substeps one `step` call runs (a step of `dt` beyond `MAX_SUBSTEPS / r` seconds
/// runs this many, longer ones).
pub const MAX_SUBSTEPS: u32 = 1 << 16;

impl HsmParams {
    /// Checks every field's range.
    pub fn check(&self) -> Result<(), HsmError> {
        let bad = |field, value: f32, expected| Err(HsmError::Param { field, value, expected });
        if !(2..=MAX_PER_CLUSTER).contains(&self.rings) {
            return bad("rings", self.rings as f32, "expected 2 to 64");
        }
        if !(3..=MAX_PER_CLUSTER).contains(&self.ring_size) {
            return bad("ring_size", self.ring_size as f32, "expected 3 to 64");
        }
        if !(1..=2).contains(&self.overlap) {
            return bad("overlap", self.overlap as f32, "expected 1 or 2");
        }
        if !(1..=MAX_PER_CLUSTER).contains(&self.leaf_particles) {
            return bad("leaf_particles", self.leaf_particles as f32, "expected 1 to 64");
        }
        if !(self.ring_ratio >= 0.0 && self.ring_ratio <= 10.0) {
            return bad("ring_ratio", self.ring_ratio, "expected 0 to 10");
        }
        for (field, k) in [("stiffness_scale", self.stiffness_scale), ("leaf_stiffness", self.leaf_stiffness)] {
            if !(k.is_finite() && k > 0.0) {
                return bad(field, k, "expected a positive number");
            }
        }
        if !(self.min_radius.is_finite() && self.min_radius >= 0.0) {
            return bad("min_radius", self.min_radius, "expected a finite number ≥ 0 (m)");
        }
        if !(self.leaf_turbulence.is_finite() && (0.0..=10.0).contains(&self.leaf_turbulence)) {
            return bad("leaf_turbulence", self.leaf_turbulence, "expected 0 to 10");
        }
        if !(self.damping_ratio.is_finite() && (0.0..=10.0).contains(&self.damping_ratio)) {
            return bad("damping_ratio", self.damping_ratio, "expected 0 to 10");
        }
        if !(self.substep_rate.is_finite() && (0.0..=MAX_SUBSTEP_RATE).contains(&self.substep_rate)) {
            return bad("substep_rate", self.substep_rate, "expected 0 to 100000 (Hz)");
        }
        if !(self.drag_scale.is_finite() && (0.0..=1000.0).contains(&self.drag_scale)) {
            return bad("drag_scale", self.drag_scale, "expected 0 to 1000");
        }
        if !(self.air_damping.is_finite() && (0.0..=1000.0).contains(&self.air_damping)) {
            return bad("air_damping", self.air_damping, "expected 0 to 1000");
        }
        if !(self.reconfiguration_speed.is_finite() && self.reconfiguration_speed > 0.0) {
            return bad("reconfiguration_speed", self.reconfiguration_speed, "expected a positive speed (m/s)");
        }
        if !(-2.0..=0.0).contains(&self.vogel_exponent) {
            return bad("vogel_exponent", self.vogel_exponent, "expected −2 to 0");
        }
        for (field, v) in [("drag", self.drag), ("leaf_drag", self.leaf_drag), ("gravity", self.gravity.abs())] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, v, "expected a finite number ≥ 0");
            }
        }
        if !(0.0..=1.0).contains(&self.beta) {
            return bad("beta", self.beta, "expected 0 to 1");
        }
        if !(1..=64).contains(&self.polar_iterations) {
            return bad("polar_iterations", self.polar_iterations as f32, "expected 1 to 64");
        }
        if !(1..=1000).contains(&self.substeps) {
            return bad("substeps", self.substeps as f32, "expected 1 to 1000");
        }
        Ok(())
    }
}
