//! Wind fields: velocity `v = G(x, t)` in m/s at a position x (m, +Y up) and time t (s).
//!
//! A [`WindScene`] is a sum of fields (Zioma §6.3.1: global wind plus sparse analytic
//! primitives), read from and written to TOML:
//!
//! * [`Constant`]: direction and speed.
//! * [`SumOfSines`]: Skjermo eqs. 11–14 — waves with amplitude, horizontal direction,
//!   wavelength (→ w = 2π/λ) and speed (→ φ = speed·w); `sharpness` k selects eq. 14.
//! * [`GustFront`]: a front travelling across the terrain; wind rises over `width` ahead of
//!   the front and decays over `length` behind it.
//! * [`Vortex`]: a Lamb–Oseen vortex about a vertical axis that drifts, fades in and out.
//! * [`Blast`]: an explosion — an outward shell expanding at `speed` and decaying.
//! * [`Grid`]: velocities on a 2-D or 3-D grid read from a file (Zioma's wind texture, a
//!   fluid solver's slices), scrolling and stepping through frames.
//! * [`Turbulence`]: spatially coherent noise with a 1/f^β temporal power spectrum
//!   (Ota 2003), by spectral synthesis: log-spaced waves with amplitudes ∝ f^((1−β)/2),
//!   advected at `mean_speed` (Taylor's frozen turbulence sets the spatial scale).
//!
//! The two wave fields (sums of sines and turbulence) may [`Fade`] in and out: Skjermo §5
//! blends one set of waves out before the next comes in, since a wave whose parameters
//! change at once jumps the branches ([`WindScene::blend_waves`]).
//!
//! Every field is evaluated through its packed form ([`raw`]) by [`crate::wind::sample`],
//! the CPU twin of the WGSL kernel, so the friendly API and the GPU share one definition.

mod check;
pub mod fade;
pub mod grid;
pub mod lanes;
pub mod noise;
pub mod raw;
pub mod sample;

pub use fade::Fade;
pub use grid::{Grid, GridData};

use crate::rng::{Stream, mix64};
use crate::wind::sample::wind_at;
use glam::Vec3;
use raw::{RawField, RawWave, kind};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Constant wind.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Constant {
    /// Direction the air moves toward (normalised on use).
    pub direction: [f32; 3],
    /// Speed, m/s.
    pub speed: f32,
}

/// One wave of a sum of sines (Skjermo eq. 11).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SineWave {
    /// Amplitude A, m/s.
    pub amplitude: f32,
    /// Direction D on the horizontal plane, degrees from +X toward +Z.
    pub direction_deg: f32,
    /// Wavelength, m (w = 2π / wavelength).
    pub wavelength: f32,
    /// Speed, m/s (φ = speed · w). The phase is `D·x w − t φ`, so the wave travels toward
    /// +D, downwind (eq. 11 as printed, `D·x w + t φ`, carries its gusts upwind).
    pub speed: f32,
}

/// Sum of sines (Skjermo eqs. 11–14).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SumOfSines {
    /// The waves (Skjermo uses at most four; any number works).
    pub waves: Vec<SineWave>,
    /// Sharpness exponent k. Absent: eq. 13, `Σ Dᵢ Aᵢ sin θᵢ`. Present: eq. 14,
    /// `Σ Dᵢ Aᵢ ((sin θᵢ + 1)/2)^k` — the `+1` of Fernando's formulation that the paper
    /// cites (as printed, a fractional k of a negative sine is undefined). Eq. 14's `1/l`
    /// (control-polygon length) belongs to the bending method, not the field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sharpness: Option<f32>,
    /// The waves come in over this time (silent before it). Absent: always in.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fade_in: Option<Fade>,
    /// The waves go out over this time (silent after it). Absent: never out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fade_out: Option<Fade>,
}

/// A travelling gust front.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GustFront {
    /// Where the front starts, (x, z) m.
    pub origin: [f32; 2],
    /// Travel direction, degrees from +X toward +Z; the wind blows this way.
    pub direction_deg: f32,
    /// Peak wind added behind the front, m/s.
    pub strength: f32,
    /// Front speed, m/s.
    pub speed: f32,
    /// Thickness of the rising edge ahead of the front, m.
    pub width: f32,
    /// Decay length of the gust behind the front, m.
    pub length: f32,
    /// Half-width of the front across its direction, m.
    pub radius: f32,
    /// Time the front leaves `origin`, s.
    #[serde(default)]
    pub start: f32,
}

/// A vortex about a vertical axis (Lamb–Oseen profile: peak tangential speed at `radius`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vortex {
    /// Centre at `start`, (x, z) m.
    pub centre: [f32; 2],
    /// Drift velocity of the centre, (x, z) m/s.
    #[serde(default)]
    pub drift: [f32; 2],
    /// Peak tangential speed, m/s; positive turns counter-clockwise seen from above.
    pub strength: f32,
    /// Core radius, m.
    pub radius: f32,
    /// Updraft at the centre, m/s.
    #[serde(default)]
    pub updraft: f32,
    /// Start time, s.
    #[serde(default)]
    pub start: f32,
    /// Lifetime, s.
    pub duration: f32,
    /// Fade-in and fade-out time, s.
    #[serde(default = "one")]
    pub fade: f32,
}

/// A blast: an outward shell expanding from `centre` and decaying.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Blast {
    /// Centre, (x, y, z) m.
    pub centre: [f32; 3],
    /// Peak outward wind at the start, m/s.
    pub strength: f32,
    /// Time of the explosion, s.
    #[serde(default)]
    pub start: f32,
    /// Expansion speed of the shell, m/s.
    pub speed: f32,
    /// Shell thickness, m.
    pub width: f32,
    /// Decay time constant, s.
    pub decay: f32,
    /// Range beyond which the blast has no effect, m.
    pub radius: f32,
}

/// Spatially coherent turbulence with a 1/f^β temporal spectrum.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Turbulence {
    /// Root-mean-square speed of each horizontal component, m/s.
    pub intensity: f32,
    /// Spectral exponent β: power ∝ 1/f^β (5/3 for the inertial range of atmospheric
    /// turbulence).
    #[serde(default = "five_thirds")]
    pub beta: f32,
    /// Lowest frequency, Hz.
    #[serde(default = "f_min")]
    pub f_min: f32,
    /// Highest frequency, Hz.
    #[serde(default = "f_max")]
    pub f_max: f32,
    /// Number of waves (more: smoother spectrum, slower sampling).
    #[serde(default = "components")]
    pub components: u32,
    /// Speed that carries the eddies, m/s: a wave of frequency f has wavelength
    /// `mean_speed / f` along the wind (Taylor's frozen turbulence).
    #[serde(default = "mean_speed")]
    pub mean_speed: f32,
    /// Direction the eddies travel, degrees from +X toward +Z. Absent: the scene's mean
    /// wind (the sum of its constant fields; +X in a scene without one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction_deg: Option<f32>,
    /// Vertical rms as a fraction of the horizontal.
    #[serde(default = "vertical")]
    pub vertical: f32,
    /// Seed of the random phases and directions.
    #[serde(default)]
    pub seed: u64,
    /// The waves come in over this time (silent before it). Absent: always in.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fade_in: Option<Fade>,
    /// The waves go out over this time (silent after it). Absent: never out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fade_out: Option<Fade>,
}

fn one() -> f32 {
    1.0
}
fn five_thirds() -> f32 {
    5.0 / 3.0
}
fn f_min() -> f32 {
    0.01
}
fn f_max() -> f32 {
    5.0
}
fn components() -> u32 {
    64
}
fn mean_speed() -> f32 {
    5.0
}
fn vertical() -> f32 {
    0.3
}

/// One field of a scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum WindField {
    /// See [`Constant`].
    Constant(Constant),
    /// See [`SumOfSines`].
    SumOfSines(SumOfSines),
    /// See [`GustFront`].
    GustFront(GustFront),
    /// See [`Vortex`].
    Vortex(Vortex),
    /// See [`Blast`].
    Blast(Blast),
    /// See [`Turbulence`].
    Turbulence(Turbulence),
    /// See [`Grid`].
    Grid(Grid),
}

/// A scene's wind: the sum of its fields.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WindScene {
    /// Fields, summed.
    #[serde(default, rename = "field")]
    pub fields: Vec<WindField>,
}

/// Errors reading or checking a wind scene.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WindError {
    /// TOML syntax, unknown keys, wrong types.
    #[error("{file}:{line}:{column}: {message}")]
    Toml { file: String, line: usize, column: usize, message: String },
    /// A value out of range.
    #[error("{file}:{line}: field[{index}].{field}: {message}")]
    Value { file: String, line: usize, index: usize, field: String, message: String },
    /// The file could not be read or written.
    #[error("{file}: {message}")]
    Io { file: String, message: String },
}

/// A wind scene in the packed form every kernel reads: one record per field and a table of
/// waves ([`WindScene::pack`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PackedWind {
    /// One record per field.
    pub fields: Vec<RawField>,
    /// Waves of the sums of sines and of turbulence.
    pub waves: Vec<RawWave>,
}

impl PackedWind {
    /// Still air.
    pub fn calm() -> Self {
        Self::default()
    }

    /// Wind velocity at `p` and `t`, m/s.
    pub fn at(&self, p: Vec3, t: f32) -> Vec3 {
        wind_at(&self.fields, &self.waves, p, t)
    }
}

/// Wind scenes shipped in `presets/wind/`: (name, file, text).
pub const PRESETS: &[(&str, &str, &str)] = &[
    ("gusty", "presets/wind/gusty.toml", include_str!("../../../../presets/wind/gusty.toml")),
    ("blast", "presets/wind/blast.toml", include_str!("../../../../presets/wind/blast.toml")),
    ("eddies", "presets/wind/eddies.toml", include_str!("../../../../presets/wind/eddies.toml")),
];

/// Files the wind presets read (grids), by their path in the repository: a preset reads the
/// same wherever it is run from.
pub const PRESET_FILES: &[(&str, &[u8])] =
    &[("presets/wind/eddies.png", include_bytes!("../../../../presets/wind/eddies.png"))];

impl WindScene {
    /// A preset name (`gusty`, `blast`, `eddies`) or a TOML file path.
    pub fn resolve(arg: &str) -> Result<Self, WindError> {
        if let Some((_, file, text)) = PRESETS.iter().find(|p| p.0 == arg) {
            return Self::from_toml(text, file);
        }
        let path = Path::new(arg);
        if !path.exists() {
            let names: Vec<&str> = PRESETS.iter().map(|p| p.0).collect();
            return Err(WindError::Io {
                file: arg.to_string(),
                message: format!("no such file or wind preset (presets: {})", names.join(", ")),
            });
        }
        Self::load(path)
    }
}

/// Largest number of waves in one sum of sines or turbulence field.
pub const MAX_WAVES: u32 = 4096;

fn horizontal(deg: f32) -> (f32, f32) {
    let r = deg.to_radians();
    (r.cos(), r.sin())
}

impl WindScene {
    /// Parses TOML; `file` names it in errors.
    pub fn from_toml(text: &str, file: &str) -> Result<Self, WindError> {
        let mut scene: WindScene = toml::from_str(text).map_err(|e| {
            let (line, column, message) =
                check::field_table_error(text).unwrap_or_else(|| crate::io::toml_error(text, &e));
            WindError::Toml { file: file.to_string(), line, column, message }
        })?;
        scene.check().map_err(|(index, field, message)| WindError::Value {
            file: file.to_string(),
            line: crate::io::field_line(text, &format!("field[{index}].{field}")),
            index,
            field,
            message,
        })?;
        let dir = Path::new(file).parent().unwrap_or(Path::new(""));
        let read = |name: &str| {
            let path = dir.join(name);
            let shipped = PRESET_FILES.iter().find(|f| Path::new(f.0) == path);
            match shipped {
                Some((_, bytes)) if !path.exists() => Ok(bytes.to_vec()),
                _ => grid::read_limited(&path, grid::MAX_GRID_FILE_BYTES)
                    .map_err(|e| format!("{e} (looked for {})", path.display())),
            }
        };
        for (index, f) in scene.fields.iter_mut().enumerate() {
            if let WindField::Grid(g) = f {
                g.load(read).map_err(|message| WindError::Value {
                    file: file.to_string(),
                    line: crate::io::field_line(text, &format!("field[{index}].file")),
                    index,
                    field: "file".into(),
                    message,
                })?;
            }
        }
        Ok(scene)
    }

    /// Reads a TOML file.
    pub fn load(path: &Path) -> Result<Self, WindError> {
        let file = path.display().to_string();
        let text = crate::io::read_text(path).map_err(|message| WindError::Io { file: file.clone(), message })?;
        Self::from_toml(&text, &file)
    }

    /// TOML text of the scene.
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).expect("wind scenes always serialise")
    }

    /// Writes the scene as TOML, atomically.
    pub fn save(&self, path: &Path) -> Result<(), WindError> {
        let text = self.to_toml();
        crate::io::write_atomic(path, |w| w.write_all(text.as_bytes()))
            .map_err(|e| WindError::Io { file: path.display().to_string(), message: e.to_string() })
    }

    /// The packed form the GPU reads (and the CPU evaluates): one record per field and a
    /// table of waves.
    pub fn pack(&self) -> (Vec<RawField>, Vec<RawWave>) {
        let mut fields = Vec::with_capacity(self.fields.len());
        let mut waves = Vec::new();
        for f in &self.fields {
            let mut r = RawField {
                kind: 0,
                wave_offset: waves.len() as u32,
                wave_count: 0,
                _pad: 0,
                a: [0.0; 4],
                b: [0.0; 4],
                c: [0.0; 4],
            };
            match f {
                WindField::Constant(c) => {
                    r.kind = kind::CONSTANT;
                    let d = Vec3::from_array(c.direction).normalize_or_zero() * c.speed;
                    r.a = [d.x, d.y, d.z, 0.0];
                }
                WindField::SumOfSines(s) => {
                    r.kind = kind::SUM_OF_SINES;
                    r.a = [s.sharpness.unwrap_or(1.0), if s.sharpness.is_some() { 1.0 } else { 0.0 }, 0.0, 0.0];
                    r.b = Fade::envelope(s.fade_in, s.fade_out);
                    for w in &s.waves {
                        let (dx, dz) = horizontal(w.direction_deg);
                        let wn = std::f32::consts::TAU / w.wavelength;
                        waves.push(RawWave {
                            dir: [dx * w.amplitude, 0.0, dz * w.amplitude, 0.0],
                            k: [dx * wn, 0.0, dz * wn, -w.speed * wn],
                            phase: [0.0; 4],
                        });
                    }
                }
                WindField::GustFront(g) => {
                    r.kind = kind::GUST_FRONT;
                    let (dx, dz) = horizontal(g.direction_deg);
                    r.a = [g.origin[0], g.origin[1], dx, dz];
                    r.b = [g.strength, g.speed, g.width, g.length];
                    r.c = [g.start, g.radius, 0.0, 0.0];
                }
                WindField::Vortex(v) => {
                    r.kind = kind::VORTEX;
                    r.a = [v.centre[0], v.centre[1], v.drift[0], v.drift[1]];
                    r.b = [v.strength, v.radius, v.start, v.duration];
                    r.c = [v.fade, v.updraft, 0.0, 0.0];
                }
                WindField::Blast(b) => {
                    r.kind = kind::BLAST;
                    r.a = [b.centre[0], b.centre[1], b.centre[2], b.strength];
                    r.b = [b.start, b.speed, b.width, b.decay];
                    r.c = [b.radius, 0.0, 0.0, 0.0];
                }
                WindField::Turbulence(t) => {
                    r.kind = kind::TURBULENCE;
                    r.b = Fade::envelope(t.fade_in, t.fade_out);
                    waves.extend(t.waves_along(self.mean_direction()));
                }
                WindField::Grid(g) => g.pack(&mut r, &mut waves),
            }
            r.wave_count = waves.len() as u32 - r.wave_offset;
            fields.push(r);
        }
        (fields, waves)
    }

    /// The horizontal unit direction of the scene's mean wind: the sum of its constant
    /// fields (+X when they cancel or there are none).
    pub fn mean_direction(&self) -> Vec3 {
        let sum: Vec3 = self
            .fields
            .iter()
            .filter_map(|f| match f {
                WindField::Constant(c) => Some(Vec3::from_array(c.direction).normalize_or_zero() * c.speed),
                _ => None,
            })
            .sum();
        Vec3::new(sum.x, 0.0, sum.z).try_normalize().unwrap_or(Vec3::X)
    }

    /// [`Self::pack`] as one value.
    pub fn packed(&self) -> PackedWind {
        let (fields, waves) = self.pack();
        PackedWind { fields, waves }
    }

    /// Wind velocity at `p` and `t` (packs the scene each call; pack once and use
    /// [`crate::wind::sample::wind_at`] in loops).
    pub fn sample(&self, p: Vec3, t: f32) -> Vec3 {
        let (f, w) = self.pack();
        wind_at(&f, &w, p, t)
    }
}

impl Turbulence {
    /// The waves of the spectral synthesis, travelling along the +X axis unless
    /// `direction_deg` says otherwise (see [`Self::waves_along`]).
    pub fn waves(&self) -> Vec<RawWave> {
        self.waves_along(Vec3::X)
    }

    /// The waves of the spectral synthesis, frozen turbulence carried along `mean` (a
    /// horizontal direction, used when `direction_deg` is absent). Frequencies: one per
    /// log-uniform band of [f_min, f_max], jittered inside it; a wave's power is the
    /// integral of f^(−β) over its band, so the sum has the 1/f^β spectrum whatever the
    /// number of waves; normalised so each horizontal component has rms `intensity`. Random
    /// phase and velocity direction (mostly horizontal). Wave vector `k = (2π f / U) û + k⊥`
    /// with û the travel direction and a lateral part |k⊥| ≤ 2π f / U: every wave's phase
    /// `2π f t − k·x` is constant along `x = x₀ + U û t`, so the whole pattern moves
    /// downwind at `mean_speed` (Taylor's hypothesis) while points across the wind decorrelate.
    pub fn waves_along(&self, mean: Vec3) -> Vec<RawWave> {
        let n = self.components as usize;
        let mut rng = Stream::new(mix64(self.seed ^ 0x7475_7262));
        let along = match self.direction_deg {
            Some(deg) => {
                let (c, s) = horizontal(deg);
                glam::DVec3::new(c as f64, 0.0, s as f64)
            }
            None => glam::DVec3::new(mean.x as f64, 0.0, mean.z as f64).try_normalize().unwrap_or(glam::DVec3::X),
        };
        let across = glam::DVec3::new(-along.z, 0.0, along.x);
        let ratio = (self.f_max / self.f_min) as f64;
        let beta = self.beta as f64;
        // ∫ f^(−β) df over [a, b].
        let band_power = |a: f64, b: f64| {
            if (beta - 1.0).abs() < 1e-9 {
                (b / a).ln()
            } else {
                (b.powf(1.0 - beta) - a.powf(1.0 - beta)) / (1.0 - beta)
            }
        };
        let mut out = Vec::with_capacity(n);
        let mut power = 0.0f64;
        for i in 0..n {
            let (lo, hi) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
            let u = (i as f64 + rng.unit()) / n as f64;
            let f = self.f_min as f64 * ratio.powf(u);
            let a = band_power(self.f_min as f64 * ratio.powf(lo), self.f_min as f64 * ratio.powf(hi)).sqrt();
            let heading = rng.unit() * std::f64::consts::TAU;
            let tilt = (rng.unit() * 2.0 - 1.0) * self.vertical as f64;
            let dir = glam::DVec3::new(heading.cos(), tilt, heading.sin());
            let lateral = rng.unit() * 2.0 - 1.0;
            let kmag = std::f64::consts::TAU * f / self.mean_speed as f64;
            let k = (along + across * lateral) * kmag;
            let phase = rng.unit();
            // Mean square of one horizontal component: a² · ½ · ½ (sin² and cos² of heading).
            power += a * a * 0.25;
            out.push((dir * a, [k.x, 0.0, k.z], f, phase));
        }
        let scale = if power > 0.0 { self.intensity as f64 / power.sqrt() } else { 0.0 };
        out.into_iter()
            .map(|(d, k, f, phase)| RawWave {
                dir: [(d.x * scale) as f32, (d.y * scale) as f32, (d.z * scale) as f32, 0.0],
                k: [k[0] as f32, 0.0, k[2] as f32, f as f32],
                phase: [phase as f32, 0.0, 0.0, 0.0],
            })
            .collect()
    }
}
