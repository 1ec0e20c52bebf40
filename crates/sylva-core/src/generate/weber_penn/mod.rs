//! Weber & Penn (1995) parametric trees (Skjermo §2.1).
//!
//! Follows the paper's algorithm: the trunk length and radius from Scale, Ratio and 0Scale;
//! stems of `nCurveRes` segments bent by `nCurve`/`nCurveBack`/`nCurveV` and, from level 2,
//! AttractionUp; splits (`0BaseSplits`, `nSegSplits`, fractions carried to the next
//! segment; the stems after a split share the branches and leaves, and with
//! `split_shares_section` the section); child counts, lengths, radii, down and rotate
//! angles from the paper's formulas (ShapeRatio for the trunk's children); taper (`nTaper`
//! 0–3) and Flare; pruning to the envelope; leaves on the last level (a fan at the tip when
//! `Leaves` < 0).
//!
//! Children of a stem sit at evenly spaced offsets: child `i` of `N` at
//! `lo + (hi − lo)(i + ½)/N` along the stem's branching range (`BaseSize·Scale` to the tip for
//! the trunk, base to tip otherwise). Fractional counts round to the nearest whole number.
//!
//! Every stem draws from its own random stream keyed by the seed and its path in the tree,
//! and the trunk's children grow in parallel: the tree is bit-identical for any thread count.

mod params;

pub use params::{FieldError, LeafShape, LevelParams, WeberPennParams};

use crate::limits::{LimitExceeded, Limits};
use crate::model::{LeafDraft, ModelError, Tree, TreeBuilder};
use crate::rng::{Stream, child_key, mix64};
use glam::{DQuat, DVec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Errors from Weber–Penn generation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WeberPennError {
    /// A parameter is out of range.
    #[error("`{field}`: {message}")]
    Param { field: String, message: String },
    /// A size limit would have been exceeded.
    #[error(transparent)]
    Limit(#[from] LimitExceeded),
    /// The tree broke a model invariant.
    #[error(transparent)]
    Model(#[from] ModelError),
}

/// Weber & Penn's ShapeRatio(shape, ratio); shape 8 is the pruning envelope.
pub fn shape_ratio(p: &WeberPennParams, shape: u32, ratio: f64) -> f64 {
    match shape {
        0 => 0.2 + 0.8 * ratio,
        1 => 0.2 + 0.8 * (std::f64::consts::PI * ratio).sin(),
        2 => 0.2 + 0.8 * (0.5 * std::f64::consts::PI * ratio).sin(),
        3 => 1.0,
        4 => 0.5 + 0.5 * ratio,
        5 => {
            if ratio <= 0.7 {
                ratio / 0.7
            } else {
                (1.0 - ratio) / 0.3
            }
        }
        6 => 1.0 - 0.8 * ratio,
        7 => {
            if ratio <= 0.7 {
                0.5 + 0.5 * ratio / 0.7
            } else {
                0.5 + 0.5 * (1.0 - ratio) / 0.3
            }
        }
        _ => envelope(p, ratio),
    }
}

/// The pruning envelope (ShapeRatio 8): `ratio` is 0 at the top of the tree, 1 at BaseSize.
fn envelope(p: &WeberPennParams, ratio: f64) -> f64 {
    if !(0.0..=1.0).contains(&ratio) {
        return 0.0;
    }
    let peak = p.prune_width_peak;
    if ratio < 1.0 - peak {
        (ratio / (1.0 - peak)).powf(p.prune_power_high)
    } else {
        ((1.0 - ratio) / peak.max(1e-12)).powf(p.prune_power_low)
    }
}

fn rot_x(deg: f64) -> DQuat {
    DQuat::from_rotation_x(deg.to_radians())
}
fn rot_y(deg: f64) -> DQuat {
    DQuat::from_rotation_y(deg.to_radians())
}

/// What a stem needs to grow.
#[derive(Debug, Clone)]
struct StemSpec {
    level: usize,
    start: DVec3,
    frame: DQuat,
    /// Full length of the stem (a clone keeps its original's length).
    length: f64,
    /// Radius at the stem's base (before taper and flare).
    radius: f64,
    /// The sampled `nLength ± nLengthV` this stem's length came from.
    length_max: f64,
    /// Offset of the stem along its parent, and the parent's length (m).
    offset: f64,
    parent_length: f64,
    /// Parent attachment in the draft list (stem, local segment, fraction).
    parent: Option<(usize, usize, f64)>,
    key: u64,
    /// First segment (clones continue their original from here).
    seg_start: usize,
    split_err: f64,
    /// Share of the parent's child density this stem carries: a split into k + 1 stems
    /// divides the density of everything after it among them, so splitting does not
    /// multiply branches and leaves.
    density: f64,
}

struct Trace {
    points: Vec<DVec3>,
    frames: Vec<DQuat>,
    radii: Vec<f64>,
    /// (local segment index the clones start at, their frames, carried split error).
    splits: Vec<(usize, Vec<DQuat>, f64)>,
    /// Child density of each segment (see [`StemSpec::density`]).
    density: Vec<f64>,
}

struct Gen<'a> {
    p: &'a WeberPennParams,
    limits: &'a Limits,
    segments: &'a AtomicUsize,
    leaves: &'a AtomicUsize,
    scale_tree: f64,
    base_length: f64,
}

impl Gen<'_> {
    /// Radius at fraction `z` of a stem's length (taper, and flare on the trunk).
    fn radius_at(&self, level: usize, radius: f64, length: f64, z: f64) -> f64 {
        let taper = self.p.level[level].taper;
        let unit_taper = if taper < 1.0 {
            taper
        } else if taper < 2.0 {
            2.0 - taper
        } else {
            0.0
        };
        let taper_z = radius * (1.0 - unit_taper * z);
        let mut r = if taper < 1.0 {
            taper_z
        } else {
            let z2 = (1.0 - z) * length;
            let depth = if taper < 2.0 || z2 < taper_z { 1.0 } else { taper - 2.0 };
            let z3 = if taper < 2.0 { z2 } else { (z2 - 2.0 * taper_z * (z2 / (2.0 * taper_z) + 0.5).floor()).abs() };
            if taper < 2.0 && z3 >= taper_z {
                taper_z
            } else {
                (1.0 - depth) * taper_z + depth * (taper_z * taper_z - (z3 - taper_z).powi(2)).max(0.0).sqrt()
            }
        };
        if level == 0 {
            let y = (1.0 - 8.0 * z).max(0.0);
            r *= self.p.flare * (100f64.powf(y) - 1.0) / 100.0 + 1.0;
        }
        r
    }

    /// Follows a stem from `spec.seg_start` to its tip: points, frames, radii and splits.
    fn trace(&self, spec: &StemSpec, length: f64) -> Trace {
        let lp = &self.p.level[spec.level];
        let n = lp.curve_res as usize;
        let seg_len = length / n as f64;
        let mut rng = Stream::new(spec.key);
        let mut frame = spec.frame;
        let mut pos = spec.start;
        let cap = n - spec.seg_start + 1;
        let mut t = Trace {
            points: Vec::with_capacity(cap),
            frames: Vec::with_capacity(cap),
            radii: Vec::with_capacity(cap),
            splits: Vec::new(),
            density: Vec::with_capacity(cap),
        };
        let mut density = spec.density;
        t.points.push(pos);
        t.radii.push(self.radius_at(spec.level, spec.radius, length, spec.seg_start as f64 / n as f64));
        let mut err = spec.split_err;
        let half = n as f64 / 2.0;
        for i in spec.seg_start..n {
            if i > spec.seg_start || spec.seg_start > 0 {
                // Curvature (and helix) between segments.
                let mut delta = if lp.curve_back == 0.0 {
                    lp.curve / n as f64
                } else if (i as f64) < half {
                    lp.curve / half
                } else {
                    lp.curve_back / half
                };
                if lp.curve_v >= 0.0 {
                    delta += rng.var(lp.curve_v) / n as f64;
                    frame *= rot_x(delta);
                } else {
                    let spin = 360.0 * i as f64 / n as f64;
                    frame = frame * rot_y(spin) * rot_x(lp.curve_v.abs() / n as f64) * rot_y(-spin) * rot_x(delta);
                }
                if spec.level >= 2 && self.p.attraction_up != 0.0 {
                    let h = frame * DVec3::Y;
                    let declination = h.y.clamp(-1.0, 1.0).acos();
                    let cos_orient = (frame * DVec3::Z).y;
                    let up = self.p.attraction_up * declination * cos_orient / n as f64;
                    frame *= DQuat::from_rotation_x(up.clamp(-declination, std::f64::consts::PI - declination));
                }
            }
            pos += frame * DVec3::Y * seg_len;
            t.points.push(pos);
            t.frames.push(frame);
            t.density.push(density);
            t.radii.push(self.radius_at(spec.level, spec.radius, length, (i + 1) as f64 / n as f64));
            if i + 1 < n {
                let k = if spec.level == 0 && i == 0 && self.p.base_splits > 0 {
                    self.p.base_splits as f64
                } else {
                    let total = lp.seg_splits + err;
                    let k = total.round();
                    err = total - k;
                    k
                };
                if k >= 1.0 {
                    let k = k as usize;
                    let h = frame * DVec3::Y;
                    let declination = h.y.clamp(-1.0, 1.0).acos().to_degrees();
                    let angle = (lp.split_angle + rng.var(lp.split_angle_v) - declination).max(0.0);
                    let r0 = rng.unit() * 360.0;
                    let clones =
                        (1..=k).map(|j| frame * rot_y(r0 + j as f64 * 360.0 / (k + 1) as f64) * rot_x(angle)).collect();
                    density /= (k + 1) as f64;
                    t.splits.push((i + 1 - spec.seg_start, clones, err));
                    frame = frame * rot_y(r0) * rot_x(angle);
                }
            }
        }
        t
    }

    fn inside_envelope(&self, q: DVec3) -> bool {
        let r = (q.x * q.x + q.z * q.z).sqrt();
        let ratio = (self.scale_tree - q.y) / (self.scale_tree * (1.0 - self.p.base_size)).max(1e-9);
        r / self.scale_tree < self.p.prune_width * envelope(self.p, ratio)
    }

    /// Grows a stem, its clones and (if `recurse`) its whole subtree into `b`. Returns the
    /// child specs it did not grow (all of them when `recurse` is false).
    fn grow(&self, spec: StemSpec, b: &mut TreeBuilder, recurse: bool) -> Result<Vec<StemSpec>, WeberPennError> {
        let mut deferred = Vec::new();
        let mut pending = vec![spec];
        while let Some(mut spec) = pending.pop() {
            let mut length = spec.length;
            if self.p.prune_ratio > 0.0 && spec.level >= 1 && spec.seg_start == 0 {
                let orig = length;
                let mut l = orig;
                for _ in 0..12 {
                    let t = self.trace(&spec, l);
                    if t.points.iter().all(|&q| self.inside_envelope(q)) {
                        break;
                    }
                    l *= 0.75;
                }
                length = orig + (l - orig) * self.p.prune_ratio;
                spec.length = length;
            }
            let t = self.trace(&spec, length);
            let nseg = t.frames.len();
            if self.segments.fetch_add(nseg, Ordering::Relaxed) + nseg > self.limits.max_segments {
                return Err(LimitExceeded { limit: "max_segments", value: self.limits.max_segments }.into());
            }
            let me = b.add_stem(spec.parent, spec.level as u8);
            for s in 0..nseg {
                let share = if self.p.split_shares_section { t.density[s].sqrt() } else { 1.0 };
                b.push_segment(
                    me,
                    t.points[s],
                    t.points[s + 1],
                    t.frames[s],
                    share * t.radii[s],
                    share * t.radii[s + 1],
                );
            }
            // Clones continue the stem from the split.
            for (j, (local, frames, err)) in t.splits.iter().enumerate() {
                for (c, f) in frames.iter().enumerate() {
                    pending.push(StemSpec {
                        start: t.points[*local],
                        frame: *f,
                        parent: Some((me, local - 1, 1.0)),
                        key: child_key(spec.key, 0xC10E_0000 + (j * 64 + c) as u64),
                        seg_start: spec.seg_start + local,
                        split_err: *err,
                        density: t.density[*local],
                        ..spec.clone()
                    });
                }
            }
            let children = self.place_children(&spec, &t, me, length, b)?;
            if recurse {
                for c in children {
                    deferred.extend(self.grow(c, b, true)?);
                }
            } else {
                deferred.extend(children);
            }
        }
        Ok(deferred)
    }

    /// Child stems (or leaves, on the last level) of one traced stem.
    fn place_children(
        &self,
        spec: &StemSpec,
        t: &Trace,
        me: usize,
        length: f64,
        b: &mut TreeBuilder,
    ) -> Result<Vec<StemSpec>, WeberPennError> {
        let p = self.p;
        let level = spec.level;
        let last = p.levels as usize - 1;
        let n = p.level[level].curve_res as usize;
        let seg_len = length / n as f64;
        let base = if level == 0 { self.base_length.min(length) } else { 0.0 };
        let lo = (spec.seg_start as f64 * seg_len).max(base);
        let hi = length;
        // Share of the full child count: the stem's branching range weighted by density.
        let share = if length - base > 0.0 {
            let mut acc = 0.0;
            for (local, d) in t.density.iter().enumerate() {
                let a = ((spec.seg_start + local) as f64 * seg_len).max(lo);
                let b = ((spec.seg_start + local + 1) as f64 * seg_len).min(hi);
                acc += d * (b - a).max(0.0);
            }
            acc / (length - base)
        } else {
            0.0
        };
        let mut rng = Stream::new(child_key(spec.key, 0xC41D));
        // Where along this stem, as (position, frame, local segment, fraction).
        let at = |offset: f64| {
            let s = ((offset / seg_len).floor() as usize).clamp(spec.seg_start, n - 1);
            let local = s - spec.seg_start;
            let frac = (offset / seg_len - s as f64).clamp(0.0, 1.0);
            let pos = t.points[local].lerp(t.points[local + 1], frac);
            (pos, t.frames[local], local, frac)
        };
        if level == last {
            if p.leaves == 0.0 {
                return Ok(Vec::new());
            }
            let lt = p.level.get(p.levels as usize).cloned().unwrap_or_default();
            let q = p.leaf_quality;
            let leaf_len = p.leaf_scale / q.sqrt();
            let leaf_w = p.leaf_scale * p.leaf_scale_x / q.sqrt();
            let mut leaves = Vec::new();
            if p.leaves > 0.0 {
                let ratio = if spec.parent_length > 0.0 { spec.offset / spec.parent_length } else { 1.0 };
                let count = (p.leaves * shape_ratio(p, 4, ratio) * q * share).round() as usize;
                let mut rot_acc = 0.0;
                let mut sign = 1.0;
                for i in 0..count {
                    let offset = lo + (hi - lo) * (i as f64 + 0.5) / count as f64;
                    let (pos, frame, local, _) = at(offset);
                    let down = lt.down_angle + rng.var(lt.down_angle_v.abs());
                    let rot = self.rotate_angle(&lt, &mut rng, &mut rot_acc, &mut sign);
                    leaves.push((local, pos, frame * rot_y(rot) * rot_x(down)));
                }
            } else {
                let count = (-p.leaves * q).round() as usize;
                let (pos, frame) = (t.points[t.points.len() - 1], t.frames[t.frames.len() - 1]);
                for i in 0..count {
                    let down = lt.down_angle + rng.var(lt.down_angle_v.abs());
                    let rot = i as f64 * 360.0 / count as f64;
                    leaves.push((t.frames.len() - 1, pos, frame * rot_y(rot) * rot_x(down)));
                }
            }
            if self.leaves.fetch_add(leaves.len(), Ordering::Relaxed) + leaves.len() > self.limits.max_leaves {
                return Err(LimitExceeded { limit: "max_leaves", value: self.limits.max_leaves }.into());
            }
            for (local, pos, mut q) in leaves {
                if p.leaf_bend > 0.0 {
                    let normal = q * DVec3::Z;
                    let outward = DVec3::new(pos.x, 0.0, pos.z).normalize_or_zero();
                    let target = (outward + DVec3::Y).normalize();
                    let bend = DQuat::IDENTITY.slerp(DQuat::from_rotation_arc(normal, target), p.leaf_bend);
                    q = (bend * q).normalize();
                }
                b.leaves.push(LeafDraft {
                    stem: me,
                    segment: local,
                    position: pos,
                    orientation: q,
                    width: leaf_w,
                    length: leaf_len,
                });
            }
            return Ok(Vec::new());
        }
        let c = level + 1;
        let lc = &p.level[c];
        let stems = if level == 0 {
            lc.branches
        } else if level == 1 {
            lc.branches * (0.2 + 0.8 * (length / spec.parent_length.max(1e-12)) / spec.length_max.max(1e-12))
        } else {
            lc.branches * (1.0 - 0.5 * spec.offset / spec.parent_length.max(1e-12))
        };
        let count = (stems.max(0.0) * share).round() as usize;
        let mut out = Vec::with_capacity(count);
        let mut rot_acc = 0.0;
        let mut sign = 1.0;
        for i in 0..count {
            let offset = lo + (hi - lo) * (i as f64 + 0.5) / count as f64;
            let (pos, frame, local, frac) = at(offset);
            let length_max = lc.length + rng.var(lc.length_v);
            let mut length_child = if level == 0 {
                let ratio = (length - offset) / (length - self.base_length).max(1e-12);
                length * length_max * shape_ratio(p, p.shape, ratio)
            } else {
                length_max * (length - 0.6 * offset)
            };
            length_child = length_child.max(0.0);
            let share = if p.split_shares_section { t.density[local].sqrt() } else { 1.0 };
            let parent_r = share * self.radius_at(level, spec.radius, length, offset / length);
            let radius = (spec.radius * (length_child / length).powf(p.ratio_power)).min(parent_r);
            let down = if lc.down_angle_v >= 0.0 {
                lc.down_angle + rng.var(lc.down_angle_v)
            } else {
                let denom = if level == 0 { length - self.base_length } else { length };
                let ratio = (length - offset) / denom.max(1e-12);
                lc.down_angle + lc.down_angle_v * (1.0 - 2.0 * shape_ratio(p, 0, ratio))
            };
            let rot = self.rotate_angle(lc, &mut rng, &mut rot_acc, &mut sign);
            if length_child <= 0.0 || radius <= 0.0 {
                continue;
            }
            out.push(StemSpec {
                level: c,
                start: pos,
                frame: frame * rot_y(rot) * rot_x(down),
                length: length_child,
                radius,
                length_max,
                offset,
                parent_length: length,
                parent: Some((me, local, frac)),
                key: child_key(spec.key, i as u64),
                seg_start: 0,
                split_err: 0.0,
                density: 1.0,
            });
        }
        Ok(out)
    }

    fn rotate_angle(&self, l: &LevelParams, rng: &mut Stream, acc: &mut f64, sign: &mut f64) -> f64 {
        if l.rotate >= 0.0 {
            *acc = (*acc + l.rotate + rng.var(l.rotate_v)) % 360.0;
            *acc
        } else {
            let r = *sign * (180.0 + l.rotate + rng.var(l.rotate_v));
            *sign = -*sign;
            r
        }
    }
}

impl WeberPennParams {
    /// Grows the tree for `seed`.
    pub fn generate(&self, seed: u64, limits: &Limits) -> Result<Tree, WeberPennError> {
        self.check().map_err(|e| WeberPennError::Param { field: e.field, message: e.message })?;
        let p = self;
        let root_key = mix64(seed ^ 0x5745_4245_5250_454E);
        let mut rng = Stream::new(child_key(root_key, u64::MAX));
        // A tenth of Scale at least (CA Black Oak's published ScaleV equals its Scale).
        let scale_tree = (p.scale + rng.var(p.scale_v)).max(0.1 * p.scale);
        let z_scale = p.z_scale + rng.var(p.z_scale_v);
        let l0 = &p.level[0];
        let length_trunk = ((l0.length + rng.var(l0.length_v)) * scale_tree).max(1e-3);
        let radius_trunk = length_trunk * p.ratio * (p.trunk_scale + rng.var(p.trunk_scale_v));
        let roll = rng.unit() * 360.0;
        let segments = AtomicUsize::new(0);
        let leaves = AtomicUsize::new(0);
        let g =
            Gen { p, limits, segments: &segments, leaves: &leaves, scale_tree, base_length: p.base_size * scale_tree };
        let trunk = StemSpec {
            level: 0,
            start: DVec3::ZERO,
            frame: rot_y(roll),
            length: length_trunk,
            radius: radius_trunk,
            length_max: l0.length,
            offset: 0.0,
            parent_length: length_trunk,
            parent: None,
            key: child_key(root_key, 0),
            seg_start: 0,
            split_err: 0.0,
            density: 1.0,
        };
        let mut b = TreeBuilder::default();
        let children = g.grow(trunk, &mut b, false)?;
        // The trunk's children grow in parallel, each into its own builder.
        let subtrees: Vec<Result<TreeBuilder, WeberPennError>> = children
            .into_par_iter()
            .map(|spec| {
                let mut sb = TreeBuilder::default();
                let rest = g.grow(spec, &mut sb, true)?;
                debug_assert!(rest.is_empty());
                Ok(sb)
            })
            .collect();
        for sub in subtrees {
            b.append_subtree(sub?);
        }
        if (z_scale - 1.0).abs() > 0.0 {
            b.scale_heights(z_scale);
        }
        let mut tree = b.build(&p.name, seed, p.wood)?;
        tree.trunk_shape = crate::model::TrunkShape {
            flare: p.flare as f32,
            lobes: p.lobes,
            lobe_depth: p.lobe_depth as f32,
            bulges: p.bulges as f32,
            bulge_depth: p.bulge_depth as f32,
        };
        tree.leaf_shape = p.leaf_shape;
        tree.leaf_motion = p.leaf_motion;
        Ok(tree)
    }
}
