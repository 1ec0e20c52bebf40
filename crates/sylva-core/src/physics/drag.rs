//! Drag on bark and leaves with reconfiguration, and the damping the tree's own motion
//! through the air adds.
//!
//! Drag on an area A in a wind w is `F = ½ ρ C_d A |w| w · g(|w|)` with
//! `g(u) = (1 + (u/U_r)²)^(B/2)`: quadratic in light wind and, above the reconfiguration
//! speed U_r, growing as `|w|^(2+B)` — leaves roll up and crowns streamline (Vogel 1989;
//! Vogel exponents B of −0.4 to −1.2 for leaves and crowns, −0.7 typical). The smooth form
//! has no kink at U_r. A part moving downwind at v feels the wind less, `F(w − v)`:
//! linearised, `F(w) − γ v` with `γ = ρ C_d A |w| g` — aerodynamic damping, which grows with
//! the wind and which methods apply implicitly, so it is stable at any wind.

use super::AIR_DENSITY;
use glam::Vec3;

/// Structural (internal) damping ratio of wood in bending. Default 0.04: field trees show
/// total damping ratios of 0.02–0.2 in sway, of which wood's internal part is under 0.05
/// (Moore & Maguire 2004, Forest Ecol. Manage. 194; James et al. 2006); the rest is the
/// aerodynamic damping the relative-velocity drag supplies.
pub const STRUCTURAL_DAMPING: f32 = 0.04;

/// Drag with reconfiguration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DragModel {
    /// Reconfiguration speed U_r, m/s (5: leaves begin to roll up between 4 and 8 m/s).
    pub reconfiguration_speed: f32,
    /// Vogel exponent B (−0.7, Vogel 1989).
    pub vogel_exponent: f32,
}

impl Default for DragModel {
    fn default() -> Self {
        Self { reconfiguration_speed: 5.0, vogel_exponent: -0.7 }
    }
}

impl DragModel {
    /// The factor `(1 + (u/U_r)²)^(B/2)` that reconfiguration applies to `u²`.
    #[inline]
    pub fn reconfiguration(&self, u: f32) -> f32 {
        let r = u / self.reconfiguration_speed;
        (1.0 + r * r).powf(0.5 * self.vogel_exponent)
    }

    /// Drag force on area `cd_area` (C_d · A, m²) in relative wind `w`, N.
    #[inline]
    pub fn force(&self, cd_area: f32, w: Vec3) -> Vec3 {
        let u = w.length();
        w * (0.5 * AIR_DENSITY * cd_area * u * self.reconfiguration(u))
    }

    /// Aerodynamic damping of area `cd_area` (C_d · A, m²) in a wind of speed `u`: how much
    /// the drag drops per m/s the part moves with the wind, `ρ C_d A u g(u)`, N·s/m.
    #[inline]
    pub fn damping(&self, cd_area: f32, u: f32) -> f32 {
        AIR_DENSITY * cd_area * u * self.reconfiguration(u)
    }
}
