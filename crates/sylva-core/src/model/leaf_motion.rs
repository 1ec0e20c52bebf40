//! How a tree's leaves move about their petioles: the parameters a species (`[leaf_motion]`)
//! and a scene tree (`leaf_motion = { … }`) set, carried by the [`super::Tree`]; the motion
//! itself is [`crate::leaves`].

use serde::{Deserialize, Serialize};

/// How leaves move (species `[leaf_motion]`, scene `[[tree]] leaf_motion = { … }`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LeafMotion {
    /// Scale of every leaf angle; 0 holds the leaves rigid on their twigs. Default 1.
    pub strength: f32,
    /// Petiole length over blade length. Default 0.5: simple leaves' petioles are 0.2–1 of
    /// the blade (aspens' and poplars' near 1).
    pub petiole_ratio: f32,
    /// Petiole diameter over blade width. Default 0.04 (2.4 mm on a 6 cm blade).
    pub petiole_diameter_ratio: f32,
    /// Young's modulus of the petiole, Pa. Default 0.3 GPa: fresh petioles are 0.1–1 GPa
    /// (Niklas 1991, "Flexural stiffness allometries of angiosperm and fern petioles").
    pub petiole_modulus: f32,
    /// Torsional over bending stiffness of the petiole, GJ/EI. Default 0.25: petioles twist
    /// 2–7 times more easily than they bend, flattened and grooved ones most (Vogel 1992,
    /// "Twist-to-bend ratios and cross-sectional shapes of petioles and stems").
    pub petiole_torsion: f32,
    /// Damping ratio of a leaf's swing. Default 0.15: leaves in air ring down within a few
    /// cycles (0.1–0.3).
    pub damping_ratio: f32,
    /// Normal-force coefficient of the blade (lift and drag together). Default 1.2: a flat
    /// plate across the flow (1.17).
    pub normal_force: f32,
    /// Flutter amplitude (RMS, in pitch and in twist) well above its onset, °. Default 12:
    /// leaves flutter by 5–30° about their mean (Tadrist et al. 2018).
    pub flutter_deg: f32,
    /// Wind speed at the leaf at which flutter reaches half its amplitude, m/s. Default 1.5:
    /// single leaves start to flutter at 1–3 m/s (Tadrist et al. 2015, torsional galloping).
    pub flutter_onset: f32,
    /// Fraction of the wind at its twig that a leaf feels inside the crown. Default 0.5: the
    /// mean wind in a crown's middle is 0.3–0.6 of the wind above it (Finnigan 2000).
    pub crown_wind: f32,
    /// Wind speed at the twig from which leaves tumble, flipping their undersides up and back
    /// (±25 % per leaf), m/s. Default 14: the silvery undersides show in a strong breeze
    /// (Beaufort 6).
    pub flip_speed: f32,
}

impl Default for LeafMotion {
    fn default() -> Self {
        Self {
            strength: 1.0,
            petiole_ratio: 0.5,
            petiole_diameter_ratio: 0.04,
            petiole_modulus: 0.3e9,
            petiole_torsion: 0.25,
            damping_ratio: 0.15,
            normal_force: 1.2,
            flutter_deg: 12.0,
            flutter_onset: 1.5,
            crown_wind: 0.5,
            flip_speed: 14.0,
        }
    }
}

impl LeafMotion {
    /// Checks every field; `Err((field, value, expected))`.
    pub fn check(&self) -> Result<(), (&'static str, f32, &'static str)> {
        let fields = [
            ("strength", self.strength, self.strength >= 0.0 && self.strength <= 10.0, "0 to 10"),
            (
                "petiole_ratio",
                self.petiole_ratio,
                self.petiole_ratio > 0.0 && self.petiole_ratio <= 10.0,
                "more than 0, at most 10",
            ),
            (
                "petiole_diameter_ratio",
                self.petiole_diameter_ratio,
                self.petiole_diameter_ratio > 0.0 && self.petiole_diameter_ratio <= 1.0,
                "more than 0, at most 1",
            ),
            (
                "petiole_modulus",
                self.petiole_modulus,
                self.petiole_modulus > 0.0 && self.petiole_modulus <= 1e12,
                "more than 0 Pa, at most 1e12",
            ),
            (
                "petiole_torsion",
                self.petiole_torsion,
                self.petiole_torsion > 0.0 && self.petiole_torsion <= 10.0,
                "more than 0, at most 10",
            ),
            (
                "damping_ratio",
                self.damping_ratio,
                self.damping_ratio > 0.0 && self.damping_ratio < 1.0,
                "more than 0, less than 1",
            ),
            ("normal_force", self.normal_force, self.normal_force >= 0.0 && self.normal_force <= 10.0, "0 to 10"),
            ("flutter_deg", self.flutter_deg, self.flutter_deg >= 0.0 && self.flutter_deg <= 90.0, "0 to 90"),
            (
                "flutter_onset",
                self.flutter_onset,
                self.flutter_onset > 0.0 && self.flutter_onset <= 100.0,
                "more than 0 m/s, at most 100",
            ),
            ("crown_wind", self.crown_wind, self.crown_wind >= 0.0 && self.crown_wind <= 1.0, "0 to 1"),
            (
                "flip_speed",
                self.flip_speed,
                self.flip_speed > 0.0 && self.flip_speed <= 1000.0,
                "more than 0 m/s, at most 1000",
            ),
        ];
        for (name, value, ok, expected) in fields {
            if !(ok && value.is_finite()) {
                return Err((name, value, expected));
            }
        }
        Ok(())
    }

    /// These parameters with `table`'s entries over them (a scene's `leaf_motion`).
    pub fn with_table(&self, table: &toml::Table) -> Result<Self, String> {
        let mut base = match toml::Value::try_from(self) {
            Ok(toml::Value::Table(t)) => t,
            _ => toml::Table::new(),
        };
        for (k, v) in table {
            // One field at a time, so a wrong type names its field.
            let mut one = base.clone();
            one.insert(k.clone(), v.clone());
            toml::Value::Table(one).try_into::<Self>().map_err(|e| format!("`{k}` = {v}: {}", e.message()))?;
            base.insert(k.clone(), v.clone());
        }
        let m: Self = toml::Value::Table(base).try_into().map_err(|e: toml::de::Error| e.message().to_string())?;
        m.check().map_err(|(field, value, expected)| format!("`{field}` = {value}: expected {expected}"))?;
        Ok(m)
    }
}
