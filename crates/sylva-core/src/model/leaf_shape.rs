//! Leaf outlines (Weber–Penn `LeafShape`): where a blade lies inside its leaf's (u, v)
//! square — u across (0.5 the midrib), v from the attachment (0) to the tip (1); the mesh
//! scales the square to the leaf's width and length. The leaf mesher's polygon holds the
//! outline, and the renderer's fragment test and the exported texture's alpha cut it
//! (the renderer's `leaf_shape.wgsl` is the WGSL twin of [`LeafShape::radius`]; the rims
//! are made here once per mesh layout and read by both mesher twins).
//!
//! | index | name | outline |
//! | ---: | --- | --- |
//! | 0 | `disc` | the blade: rounded base, pointed tip, inside Akagi's two half-circles (the four Weber–Penn species) |
//! | 1 | `disc1` | rounded triangle, a corner at the tip and two at the base (poplar, birch) |
//! | 2 | `disc2` | narrow ellipse, 0.44 as wide as long (willow, lanceolate) |
//! | 3 | `disc3` | wide ellipse, nearly round (aspen's orbicular leaves) |
//! | 4 | `square` | rounded square |
//! | 5 | `palm` | long narrow blade with leaflet teeth (a frond) |
//! | 6 | `needle` | conifer needle, a tenth as wide as long |
//! | 7 | `star` | five lobes from the base (maple, sweetgum) |
//! | 8 | `heart` | cordate: notched at the petiole, narrowing to the tip (linden, redbud) |
//!
//! Outlines 1–8 are polar about the square's centre: `r(θ)` with θ from the tip toward +u;
//! the disc keeps the half-width profile the renderer has always cut.

use serde::{Deserialize, Serialize};
use std::f32::consts::{PI, TAU};

/// A leaf outline; a species file names it or gives its index (0–8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum LeafShape {
    /// 0: rounded base, pointed tip.
    #[default]
    Disc,
    /// 1: rounded triangle.
    Disc1,
    /// 2: narrow ellipse.
    Disc2,
    /// 3: wide ellipse.
    Disc3,
    /// 4: rounded square.
    Square,
    /// 5: long toothed blade (palm fronds).
    Palm,
    /// 6: conifer needle.
    Needle,
    /// 7: five lobes.
    Star,
    /// 8: heart.
    Heart,
}

impl LeafShape {
    /// Every shape, by index.
    pub const ALL: [LeafShape; 9] = [
        Self::Disc,
        Self::Disc1,
        Self::Disc2,
        Self::Disc3,
        Self::Square,
        Self::Palm,
        Self::Needle,
        Self::Star,
        Self::Heart,
    ];
    /// Names, by index.
    pub const NAMES: [&'static str; 9] =
        ["disc", "disc1", "disc2", "disc3", "square", "palm", "needle", "star", "heart"];

    /// Index 0–8 (what the mesh and the GPU carry).
    pub fn index(self) -> u32 {
        Self::ALL.iter().position(|s| *s == self).expect("listed") as u32
    }

    /// The shape of an index; out of range is the disc.
    pub fn from_index(i: u32) -> Self {
        Self::ALL.get(i as usize).copied().unwrap_or_default()
    }

    /// Name as species files write it.
    pub fn name(self) -> &'static str {
        Self::NAMES[self.index() as usize]
    }

    /// Distance from the square's centre (0.5, 0.5) to the outline at angle θ (radians from
    /// the tip toward +u), for the polar shapes (1–8); the disc's polygon ellipse (0.5).
    /// As `leaf_radius` in `leaf_shape.wgsl`.
    pub fn radius(self, theta: f32) -> f32 {
        leaf_radius(self.index(), theta)
    }

    /// Whether (u, v) is on the blade.
    pub fn contains(self, u: f32, v: f32) -> bool {
        if self == Self::Disc {
            return (u - 0.5).abs() <= disc_half_width(v);
        }
        let (x, y) = (u - 0.5, v - 0.5);
        let d = (x * x + y * y).sqrt();
        d <= self.radius(x.atan2(y))
    }

    /// Rim vertex `k` of `sides` of the leaf polygon, (u, v): the disc's ellipse of two
    /// half-circles about the circle that holds the blade, or for the polar shapes a polygon
    /// that holds the outline ([`leaf_rim`]). Either may reach a few hundredths past the
    /// square, where the texture's border is clear.
    pub fn rim(self, k: u32, sides: u32) -> (f32, f32) {
        leaf_rim(self.index(), k, sides)
    }
}

/// Half-width of the disc's blade at `v` (0 base … 1 tip), in (u, v) units: rounded at the
/// base, pointed at the tip, never wider than the polygon's ellipse.
pub fn disc_half_width(v: f32) -> f32 {
    if !(0.0..=1.0).contains(&v) {
        return 0.0;
    }
    0.46 * (PI * v.powf(0.75)).sin().max(0.0).powf(0.9) * (1.0 - v).powf(0.15)
}

/// An ellipse's radius at θ, semi-axes `a` across and `b` along.
#[inline]
fn ellipse(a: f32, b: f32, theta: f32) -> f32 {
    let (s, c) = (theta.sin() / a, theta.cos() / b);
    1.0 / (s * s + c * c).sqrt()
}

/// [`LeafShape::radius`] by index: same operations as `leaf_radius` in `leaf_shape.wgsl`.
pub fn leaf_radius(shape: u32, theta: f32) -> f32 {
    let (s, c) = (theta.sin(), theta.cos());
    match shape {
        1 => 0.4 * (1.0 + 0.15 * (3.0 * theta).cos()),
        2 => ellipse(0.22, 0.49, theta),
        3 => ellipse(0.47, 0.49, theta),
        4 => 0.47 / (s.abs().powf(6.0) + c.abs().powf(6.0)).powf(1.0 / 6.0),
        5 => ellipse(0.16, 0.49, theta) * (0.72 + 0.28 * (14.0 * theta).cos().abs()),
        6 => ellipse(0.05, 0.49, theta),
        7 => 0.48 * (0.5 + 0.5 * (2.5 * theta).cos().abs().sqrt()),
        8 => {
            let drop = (0.5 * theta).cos().abs().powf(10.0);
            let notch = (-c).max(0.0).powf(12.0);
            0.5 * (0.6 + 0.4 * drop - 0.4 * notch)
        }
        _ => 0.5,
    }
}

/// Half-extents (across, along) of the polar shapes' outlines about the square's centre:
/// the rim is built where the outline, stretched by them, is about round.
fn leaf_box(shape: u32) -> (f32, f32) {
    match shape {
        1 => (0.42, 0.48),
        2 => (0.22, 0.49),
        3 => (0.47, 0.49),
        4 => (0.47, 0.47),
        5 => (0.16, 0.49),
        6 => (0.05, 0.49),
        7 => (0.48, 0.48),
        8 => (0.33, 0.5),
        _ => (0.5, 0.5),
    }
}

/// Samples per sector when a rim vertex finds the outline around it.
const RIM_SAMPLES: u32 = 16;
/// Margin for what the samples miss between them.
const RIM_MARGIN: f32 = 1.02;

/// [`LeafShape::rim`] by index (`MeshLayout::leaf_rim_table` holds every shape's). In the
/// outline stretched by `leaf_box` to about a circle, vertex k sits at angle π − k·step
/// (from the base through +u); its radius keeps both chords beside it outside every sampled
/// outline point of their sectors (a chord with both ends at R passes at R cos(φ − mid) /
/// cos(step / 2) in direction φ, and a longer end only moves it out). Stretching back keeps
/// chords chords, so the polygon holds the outline.
pub fn leaf_rim(shape: u32, k: u32, sides: u32) -> (f32, f32) {
    let step = TAU / sides as f32;
    let a = TAU * k as f32 / sides as f32;
    if shape == 0 {
        // Akagi's two half-circles, about the circle of radius ½ that holds the blade.
        let r = 0.5 / (0.5 * step).cos();
        return (0.5 + r * a.sin(), 0.5 - r * a.cos());
    }
    let (bx, by) = leaf_box(shape);
    let alpha = PI - a;
    let mut r = 0.0f32;
    for j in 0..=2 * RIM_SAMPLES {
        let off = step * (j as f32 / RIM_SAMPLES as f32 - 1.0);
        let phi = alpha + off;
        let theta = (bx * phi.sin()).atan2(by * phi.cos());
        let rr = leaf_radius(shape, theta);
        let (x, y) = (rr * theta.sin() / bx, rr * theta.cos() / by);
        r = r.max((x * x + y * y).sqrt() * (off.abs() - 0.5 * step).cos());
    }
    r = r * RIM_MARGIN / (0.5 * step).cos();
    (0.5 + bx * r * alpha.sin(), 0.5 + by * r * alpha.cos())
}

impl Serialize for LeafShape {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for LeafShape {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = LeafShape;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "a leaf shape: one of {} or its index 0–8", LeafShape::NAMES.join(", "))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<LeafShape, E> {
                let found = LeafShape::NAMES.iter().position(|n| n.eq_ignore_ascii_case(v));
                found.map(|i| LeafShape::ALL[i]).ok_or_else(|| {
                    E::custom(format!(
                        "unknown leaf_shape `{}`, expected one of {} or an index 0–8",
                        crate::io::cut(v),
                        LeafShape::NAMES.join(", ")
                    ))
                })
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<LeafShape, E> {
                match u32::try_from(v) {
                    Ok(i) if (i as usize) < LeafShape::ALL.len() => Ok(LeafShape::ALL[i as usize]),
                    _ => Err(E::custom(format!("leaf_shape {v} is outside 0–8 ({})", LeafShape::NAMES.join(", ")))),
                }
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<LeafShape, E> {
                self.visit_i64(i64::try_from(v).unwrap_or(i64::MAX))
            }
        }
        d.deserialize_any(Visitor)
    }
}
