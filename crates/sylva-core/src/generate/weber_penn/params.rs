//! Weber & Penn (1995) parameters, read from TOML species presets.
//!
//! Names follow the paper in snake case (`nDownAngleV` → `down_angle_v` in the `n`-th
//! `[[level]]` table). Angles are in degrees, lengths in metres unless noted.

use crate::model::WoodProperties;
use serde::{Deserialize, Serialize};

pub use crate::model::LeafShape;

/// Parameters of one level (`n` in the paper's `nLength`, …); level 0 is the trunk.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LevelParams {
    /// nLength: length of a stem as a fraction (of the parent, or for the trunk of Scale).
    pub length: f64,
    /// nLengthV: variation of `length`.
    pub length_v: f64,
    /// nTaper: 0 = cylinder, 1 = cone, 1–2 = blunt tip, 2–3 = periodic (bumpy) tapering.
    pub taper: f64,
    /// nSegSplits: splits per segment; fractions carry over to the next segment.
    pub seg_splits: f64,
    /// nSplitAngle: angle between the stems after a split, degrees.
    pub split_angle: f64,
    /// nSplitAngleV.
    pub split_angle_v: f64,
    /// nCurveRes: segments per stem.
    pub curve_res: u32,
    /// nCurve: total curvature along the stem, degrees.
    pub curve: f64,
    /// nCurveBack: curvature of the second half (0 = none), degrees.
    pub curve_back: f64,
    /// nCurveV: random curvature per stem, degrees; negative = helical stems.
    pub curve_v: f64,
    /// nBranches: child stems per parent (or leaves' level: unused).
    pub branches: f64,
    /// nDownAngle: angle between a child and its parent, degrees.
    pub down_angle: f64,
    /// nDownAngleV: variation; negative = varies with position along the parent.
    pub down_angle_v: f64,
    /// nRotate: angle about the parent between successive children; negative = alternate.
    pub rotate: f64,
    /// nRotateV.
    pub rotate_v: f64,
}

impl Default for LevelParams {
    fn default() -> Self {
        Self {
            length: 0.5,
            length_v: 0.0,
            taper: 1.0,
            seg_splits: 0.0,
            split_angle: 0.0,
            split_angle_v: 0.0,
            curve_res: 3,
            curve: 0.0,
            curve_back: 0.0,
            curve_v: 0.0,
            branches: 0.0,
            down_angle: 45.0,
            down_angle_v: 0.0,
            rotate: 140.0,
            rotate_v: 0.0,
        }
    }
}

/// The full Weber–Penn parameter set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeberPennParams {
    /// Display name.
    pub name: String,
    /// Where the values come from.
    #[serde(default)]
    pub source: String,
    /// Shape 0–8: conical, spherical, hemispherical, cylindrical, tapered cylindrical, flame,
    /// inverse conical, tend flame, envelope (uses the prune parameters).
    pub shape: u32,
    /// BaseSize: fraction of the trunk without branches.
    pub base_size: f64,
    /// Scale: tree size, m.
    pub scale: f64,
    /// ScaleV.
    pub scale_v: f64,
    /// ZScale: vertical scaling of the tree.
    #[serde(default = "one")]
    pub z_scale: f64,
    /// ZScaleV.
    #[serde(default)]
    pub z_scale_v: f64,
    /// Levels: stem levels, trunk included (1–8). Leaves grow on the last level.
    pub levels: u32,
    /// Ratio: trunk radius / trunk length.
    pub ratio: f64,
    /// RatioPower: how child radii follow child lengths.
    pub ratio_power: f64,
    /// Lobes: lobes of the trunk cross-section (meshing).
    #[serde(default)]
    pub lobes: u32,
    /// LobeDepth (meshing).
    #[serde(default)]
    pub lobe_depth: f64,
    /// Flare: extra trunk radius at the base, fraction.
    #[serde(default)]
    pub flare: f64,
    /// Bulges along each stem for Skjermo's deformer (eq. 4, `b_n`; not Weber–Penn's).
    /// Default 0: none.
    #[serde(default)]
    pub bulges: f64,
    /// Depth of the bulges (eq. 4, `b_d`), fraction of the radius, 0 to 0.9. Default 0.
    #[serde(default)]
    pub bulge_depth: f64,
    /// 0Scale: trunk radius scale.
    #[serde(default = "one")]
    pub trunk_scale: f64,
    /// 0ScaleV.
    #[serde(default)]
    pub trunk_scale_v: f64,
    /// 0BaseSplits: splits at the base of the trunk's first segment.
    #[serde(default)]
    pub base_splits: u32,
    /// Whether a split shares the stem's section among the stems it makes, as it shares their
    /// branches and leaves: each of `k + 1` keeps `1/(k + 1)` of the area, its radius
    /// `1/√(k + 1)` (Leonardo's rule, `Σd²` kept across a fork; Eloy 2011 finds the exponent
    /// 1.8–2.3 in measured trees). Default false: each keeps the full radius (Weber & Penn).
    #[serde(default)]
    pub split_shares_section: bool,
    /// AttractionUp: upward (negative: downward) curving of level ≥ 2 stems.
    #[serde(default)]
    pub attraction_up: f64,
    /// PruneRatio: 0 = no pruning, 1 = full pruning to the envelope.
    #[serde(default)]
    pub prune_ratio: f64,
    /// PruneWidth: envelope width / tree height.
    #[serde(default = "half")]
    pub prune_width: f64,
    /// PruneWidthPeak: height fraction of the envelope's widest point.
    #[serde(default = "half")]
    pub prune_width_peak: f64,
    /// PrunePowerLow: curvature of the envelope's lower part.
    #[serde(default = "half")]
    pub prune_power_low: f64,
    /// PrunePowerHigh: curvature of the envelope's upper part.
    #[serde(default = "half")]
    pub prune_power_high: f64,
    /// Leaves per last-level stem; negative = a fan of leaves at each stem tip.
    #[serde(default)]
    pub leaves: f64,
    /// LeafShape: the leaves' outline, a name or its index 0–8 (`model::leaf_shape`).
    #[serde(default)]
    pub leaf_shape: LeafShape,
    /// LeafScale: leaf length, m.
    #[serde(default = "tenth")]
    pub leaf_scale: f64,
    /// LeafScaleX: leaf width / length.
    #[serde(default = "half")]
    pub leaf_scale_x: f64,
    /// LeafBend: how far leaves turn to face outward and up (0–1).
    #[serde(default)]
    pub leaf_bend: f64,
    /// LeafQuality: multiplies leaf count, divides leaf size by its square root.
    #[serde(default = "one")]
    pub leaf_quality: f64,
    /// Per-level parameters: `levels` tables, plus optionally one more whose down and
    /// rotate angles place the leaves.
    pub level: Vec<LevelParams>,
    /// Wood properties for mass and stiffness.
    #[serde(default)]
    pub wood: WoodProperties,
    /// How the leaves move about their petioles.
    #[serde(default)]
    pub leaf_motion: crate::model::LeafMotion,
}

fn one() -> f64 {
    1.0
}
fn half() -> f64 {
    0.5
}
fn tenth() -> f64 {
    0.1
}

/// An out-of-range field: its dotted path (e.g. `level[1].length`) and what was expected.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldError {
    /// Dotted path of the field.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl WeberPennParams {
    /// Checks every value's range; the first bad field is reported.
    pub fn check(&self) -> Result<(), FieldError> {
        let bad = |field: String, message: String| Err(FieldError { field, message });
        macro_rules! finite {
            ($path:expr, $v:expr) => {
                if !$v.is_finite() {
                    return bad($path, format!("{} is not a finite number", $v));
                }
            };
        }
        macro_rules! range {
            ($path:expr, $v:expr, $lo:expr, $hi:expr) => {
                finite!($path, $v);
                if !($lo..=$hi).contains(&$v) {
                    return bad($path, format!("{} is outside [{}, {}]", $v, $lo, $hi));
                }
            };
        }
        let f = |s: &str| s.to_string();
        if !(1..=8).contains(&self.levels) {
            return bad(f("levels"), format!("{} is outside [1, 8]", self.levels));
        }
        if self.shape > 8 {
            return bad(f("shape"), format!("{} is not a shape 0–8", self.shape));
        }
        range!(f("base_size"), self.base_size, 0.0, 1.0);
        range!(f("scale"), self.scale, 1e-3, 1e4);
        range!(f("scale_v"), self.scale_v, 0.0, 1e4);
        if self.scale_v > self.scale {
            return bad(f("scale_v"), format!("{} must not exceed scale ({})", self.scale_v, self.scale));
        }
        range!(f("z_scale"), self.z_scale, 1e-3, 100.0);
        range!(f("z_scale_v"), self.z_scale_v, 0.0, 100.0);
        if self.z_scale_v >= self.z_scale {
            return bad(f("z_scale_v"), format!("{} must be smaller than z_scale ({})", self.z_scale_v, self.z_scale));
        }
        range!(f("ratio"), self.ratio, 1e-6, 1.0);
        range!(f("ratio_power"), self.ratio_power, 0.0, 10.0);
        // Below 0.9: at depth 1 a lobed section pinches to a point.
        range!(f("lobe_depth"), self.lobe_depth, 0.0, 0.89);
        range!(f("flare"), self.flare, 0.0, 10.0);
        range!(f("bulges"), self.bulges, 0.0, 100.0);
        range!(f("bulge_depth"), self.bulge_depth, 0.0, 0.89);
        range!(f("trunk_scale"), self.trunk_scale, 1e-6, 100.0);
        range!(f("trunk_scale_v"), self.trunk_scale_v, 0.0, 100.0);
        if self.trunk_scale_v >= self.trunk_scale {
            return bad(
                f("trunk_scale_v"),
                format!("{} must be smaller than trunk_scale ({})", self.trunk_scale_v, self.trunk_scale),
            );
        }
        if self.base_splits > 16 {
            return bad(f("base_splits"), format!("{} is outside [0, 16]", self.base_splits));
        }
        if self.lobes > 64 {
            return bad(f("lobes"), format!("{} is outside [0, 64]", self.lobes));
        }
        range!(f("attraction_up"), self.attraction_up, -100.0, 100.0);
        range!(f("prune_ratio"), self.prune_ratio, 0.0, 1.0);
        range!(f("prune_width"), self.prune_width, 1e-6, 100.0);
        range!(f("prune_width_peak"), self.prune_width_peak, 0.0, 1.0);
        range!(f("prune_power_low"), self.prune_power_low, 0.0, 100.0);
        range!(f("prune_power_high"), self.prune_power_high, 0.0, 100.0);
        range!(f("leaves"), self.leaves, -10_000.0, 10_000.0);
        range!(f("leaf_scale"), self.leaf_scale, 1e-6, 100.0);
        range!(f("leaf_scale_x"), self.leaf_scale_x, 1e-6, 100.0);
        range!(f("leaf_bend"), self.leaf_bend, 0.0, 1.0);
        range!(f("leaf_quality"), self.leaf_quality, 1e-3, 100.0);
        let want = self.levels as usize;
        if self.level.len() < want || self.level.len() > want + 1 {
            return bad(
                f("level"),
                format!(
                    "{} [[level]] tables for levels = {}; expected {} (one per stem level) or {} (plus one placing the leaves)",
                    self.level.len(),
                    self.levels,
                    want,
                    want + 1
                ),
            );
        }
        for (n, l) in self.level.iter().enumerate() {
            let p = |name: &str| format!("level[{n}].{name}");
            range!(p("length"), l.length, 0.0, 100.0);
            range!(p("length_v"), l.length_v, 0.0, 100.0);
            range!(p("taper"), l.taper, 0.0, 3.0);
            range!(p("seg_splits"), l.seg_splits, 0.0, 8.0);
            range!(p("split_angle"), l.split_angle, -360.0, 360.0);
            range!(p("split_angle_v"), l.split_angle_v, 0.0, 360.0);
            if n < want && !(1..=1000).contains(&l.curve_res) {
                return bad(p("curve_res"), format!("{} is outside [1, 1000]", l.curve_res));
            }
            range!(p("curve"), l.curve, -3600.0, 3600.0);
            range!(p("curve_back"), l.curve_back, -3600.0, 3600.0);
            range!(p("curve_v"), l.curve_v, -3600.0, 3600.0);
            range!(p("branches"), l.branches, 0.0, 100_000.0);
            range!(p("down_angle"), l.down_angle, -360.0, 360.0);
            range!(p("down_angle_v"), l.down_angle_v, -360.0, 360.0);
            range!(p("rotate"), l.rotate, -360.0, 360.0);
            range!(p("rotate_v"), l.rotate_v, 0.0, 360.0);
        }
        let w = &self.wood;
        for (name, v) in [
            ("wood.young_modulus", w.young_modulus),
            ("wood.density", w.density),
            ("wood.leaf_areal_density", w.leaf_areal_density),
        ] {
            if !v.is_finite() || v <= 0.0 {
                return bad(f(name), format!("{v} must be finite and > 0"));
            }
        }
        if let Err((name, v, expected)) = self.leaf_motion.check() {
            return bad(format!("leaf_motion.{name}"), format!("{v}: expected {expected}"));
        }
        Ok(())
    }
}
