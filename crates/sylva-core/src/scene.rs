//! Scene files (TOML) for `sylva render`: trees (species or grammar, seed, placement,
//! animation method, instanced copies), wind, camera, sun, image size, duration and output.
//!
//! ```toml
//! wind = "gusty"                 # a preset or a wind TOML (relative to this file)
//! [output]
//! dir = "out/render"
//! width = 960
//! height = 540
//! fps = 15
//! seconds = 4
//! [camera]
//! eye = [0, 7, 32]
//! target = [0, 6, 0]
//! fov_deg = 45
//! [[tree]]
//! species = "quaking_aspen"      # a preset, a species TOML or an .lsys grammar
//! method = "zioma"               # zioma | akagi | skjermo | hsm (or a registered one)
//! params = { amplitude = 1.2 }  # the method's own parameters
//! position = [-9, 0, 0]
//! copies = [{ position = [-30, 0, -40], yaw_deg = 40 }]
//! phase_groups = 4               # akagi/skjermo/hsm: simulations the copies are dealt among
//! ```
//!
//! Unknown keys, wrong types and out-of-range values are errors naming the file, line and
//! field.

use crate::io::field_line;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// An animation method by name, as a scene file spells it (`zioma`, `akagi`, `skjermo`,
/// `hsm`, or a method an application registered). Which names exist is the runtime's
/// registry's to say ([`Scene::check_methods`]).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Deserialize, Serialize)]
#[serde(transparent)]
pub struct MethodName(String);

impl MethodName {
    /// The name `name`.
    pub fn new(name: impl Into<String>) -> Self {
        Self(name.into())
    }

    /// The name.
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl PartialEq<&str> for MethodName {
    fn eq(&self, other: &&str) -> bool {
        self.0 == *other
    }
}

impl std::fmt::Display for MethodName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// The text a scene was read from, kept to locate errors found after parsing (a method's
/// parameters, a name the registry does not know). Not part of a scene's value: two scenes
/// that differ only in it are equal.
#[derive(Debug, Clone, Default)]
pub struct SourceText(pub std::sync::Arc<str>);

impl PartialEq for SourceText {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// Where the simulation runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum BackendChoice {
    /// GPU on a hardware adapter, CPU on a software rasteriser (where the CPU path is
    /// faster).
    #[default]
    Auto,
    /// The CPU reference.
    Cpu,
    /// The GPU kernels.
    Gpu,
}

/// Image and animation output.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Output {
    /// Directory for the animation and frames (relative to the working directory).
    pub dir: PathBuf,
    /// Base name of the files written (`<name>.gif`, `<name>.mp4`, `frames/<name>_0000.png`).
    pub name: String,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Frames per second of the animation.
    pub fps: f32,
    /// Duration, s.
    pub seconds: f32,
    /// Simulated time before the first frame, s (stateful methods start at rest).
    pub preroll: f32,
    /// Simulation steps per second (stateful methods), Hz.
    pub sim_rate: f32,
    /// Write the GIF.
    pub gif: bool,
    /// Write PNG frames.
    pub png: bool,
    /// Write an MP4 when `ffmpeg` is on the PATH.
    pub mp4: bool,
    /// Samples per pixel (1 or 4).
    pub msaa: u32,
    /// Draw each tree's label.
    pub labels: bool,
}

impl Default for Output {
    fn default() -> Self {
        Self {
            dir: PathBuf::from("out/render"),
            name: "sylva".into(),
            width: 960,
            height: 540,
            fps: 15.0,
            seconds: 4.0,
            preroll: 1.0,
            sim_rate: 60.0,
            gif: true,
            png: true,
            mp4: true,
            msaa: 4,
            labels: true,
        }
    }
}

/// The camera.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct CameraSettings {
    /// Eye position, m.
    pub eye: [f32; 3],
    /// Point looked at, m.
    pub target: [f32; 3],
    /// Vertical field of view, degrees.
    pub fov_deg: f32,
}

impl Default for CameraSettings {
    fn default() -> Self {
        Self { eye: [0.0, 7.0, 34.0], target: [0.0, 6.5, 0.0], fov_deg: 45.0 }
    }
}

/// The sun.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Sun {
    /// Direction towards the sun (normalised on use).
    pub direction: [f32; 3],
    /// Intensity multiplier.
    pub intensity: f32,
}

impl Default for Sun {
    fn default() -> Self {
        Self { direction: [0.45, 0.75, 0.35], intensity: 2.6 }
    }
}

/// An extra instance of a tree: drawn by instancing with the same animated mesh.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Copy {
    /// Position, m.
    pub position: [f32; 3],
    /// Rotation about +Y, degrees.
    #[serde(default)]
    pub yaw_deg: f32,
    /// Uniform scale.
    #[serde(default = "one")]
    pub scale: f32,
}

fn one() -> f32 {
    1.0
}

fn default_seed() -> u64 {
    1
}

/// One tree of the scene.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SceneTree {
    /// A preset name, a Weber–Penn TOML or an L-system grammar (paths relative to the scene
    /// file).
    pub species: String,
    /// Random seed.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Animation method.
    pub method: MethodName,
    /// The method's parameters (its `Params` fields by name; absent ones keep their
    /// defaults), e.g. `params = { damping_ratio = 0.1 }`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub params: Option<toml::Table>,
    /// Position of the root, m.
    #[serde(default)]
    pub position: [f32; 3],
    /// Rotation about +Y, degrees.
    #[serde(default)]
    pub yaw_deg: f32,
    /// Uniform scale.
    #[serde(default = "one")]
    pub scale: f32,
    /// Label drawn under the tree (default: species and method).
    #[serde(default)]
    pub label: Option<String>,
    /// Leaf colour (linear RGB, 0…1).
    #[serde(default)]
    pub tint: Option<[f32; 3]>,
    /// Where the simulation runs.
    #[serde(default)]
    pub backend: BackendChoice,
    /// Sides of the bark tubes (default 8).
    #[serde(default)]
    pub sides: Option<u32>,
    /// Sides of the leaf polygons (default 8).
    #[serde(default)]
    pub leaf_sides: Option<u32>,
    /// More instances of this tree. Zioma's copies each get their own pose (wind sampled at
    /// the copy, its own phase and trunk seed, §6.5); the other methods' copies share
    /// `phase_groups` simulations.
    #[serde(default)]
    pub copies: Vec<Copy>,
    /// Independent simulations the instances of a stateful-method tree (akagi, skjermo,
    /// hsm) are dealt among, round robin (1 to [`MAX_PHASE_GROUPS`], default 4). Each starts
    /// at a different point of the wind ([`SceneTree::phase_groups`]), so copies in
    /// different groups sway out of step; each costs a simulation and a mesh per frame.
    #[serde(default = "default_phase_groups")]
    pub phase_groups: u32,
    /// How its leaves move, over the species' ([`crate::leaves::LeafMotion`] fields by name,
    /// e.g. `leaf_motion = { strength = 0.5 }`; `strength = 0` holds them rigid).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub leaf_motion: Option<toml::Table>,
}

fn default_phase_groups() -> u32 {
    4
}

/// Most independent simulations per scene tree.
pub const MAX_PHASE_GROUPS: u32 = 16;

/// How far apart, in seconds of wind, phase groups start: offsets spread over this span.
/// Longer than the gusts' correlation time of the presets (a few seconds), so groups do not
/// move alike.
pub const PHASE_SPAN_S: f32 = 8.0;

/// Instances that share one simulation, and where in the wind it starts.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseGroup {
    /// Extra pre-roll of this group's simulation, s (0 for the group holding the tree
    /// itself): the group samples the wind this much later than the scene's clock.
    pub offset_s: f32,
    /// Instances: 0 is the tree itself, k ≥ 1 is `copies[k − 1]`.
    pub members: Vec<usize>,
}

impl SceneTree {
    /// The instances dealt among independent simulations. A method that poses every
    /// instance on its own (`per_instance`, Zioma) keeps its instances in one group. For the
    /// others there are `min(phase_groups, instances)` groups; instance k goes to group k mod groups, and
    /// group g ≥ 1 starts `PHASE_SPAN_S · frac(g/φ + u)` seconds into the wind (φ the golden
    /// ratio, u from the seed): offsets as evenly spread as a sequence can be, different
    /// for every group.
    pub fn phase_groups(&self, per_instance: bool) -> Vec<PhaseGroup> {
        let instances = 1 + self.copies.len();
        let groups =
            if per_instance { 1 } else { (self.phase_groups.clamp(1, MAX_PHASE_GROUPS) as usize).min(instances) };
        let u = (crate::rng::mix64(self.seed ^ 0x5EED_F00D) >> 40) as f32 / (1u64 << 24) as f32;
        (0..groups)
            .map(|g| PhaseGroup {
                offset_s: if g == 0 { 0.0 } else { PHASE_SPAN_S * (g as f32 * 0.618_034 + u).fract() },
                members: (g..instances).step_by(groups).collect(),
            })
            .collect()
    }
}

/// A scene.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Wind preset or file.
    #[serde(default = "default_wind")]
    pub wind: String,
    /// Output settings.
    #[serde(default)]
    pub output: Output,
    /// Camera.
    #[serde(default)]
    pub camera: CameraSettings,
    /// Sun.
    #[serde(default)]
    pub sun: Sun,
    /// Trees.
    #[serde(rename = "tree")]
    pub trees: Vec<SceneTree>,
    /// Directory that relative paths in the scene are resolved against.
    #[serde(skip)]
    pub base_dir: PathBuf,
    /// Where the scene came from (for messages).
    #[serde(skip)]
    pub file: String,
    /// The text it was read from (for messages).
    #[serde(skip)]
    pub source: SourceText,
    /// Limits on each tree's growth and on the scene's size (set by the application; the
    /// CLI's `--max-…` flags).
    #[serde(skip)]
    pub limits: crate::Limits,
}

fn default_wind() -> String {
    "gusty".into()
}

/// The built-in default scene: four species, one per animation method, labelled, with a
/// few instanced aspens behind them, in gusty wind.
pub const DEFAULT_SCENE: &str = include_str!("../../../presets/scenes/default.toml");

/// Largest number of frames a scene may ask for.
pub const MAX_FRAMES: u32 = 10_000;
/// Largest number of `[[tree]]` entries.
pub const MAX_TREES: usize = 64;
/// Largest number of instances over all trees.
pub const MAX_INSTANCES: usize = 100_000;

/// Errors reading a scene.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// TOML syntax, unknown keys, wrong types.
    #[error("{file}:{line}:{column}: {message}")]
    Toml { file: String, line: usize, column: usize, message: String },
    /// A value out of range.
    #[error("{file}:{line}: field `{field}` = {value}: expected {expected}")]
    Value { file: String, line: usize, field: String, value: String, expected: String },
    /// The file could not be read.
    #[error("{file}: {message}")]
    Io { file: String, message: String },
}

impl Scene {
    /// The built-in default scene.
    pub fn default_scene() -> Self {
        Self::from_toml(DEFAULT_SCENE, "presets/scenes/default.toml", Path::new("."))
            .expect("the default scene is valid")
    }

    /// The scene as TOML text that [`Scene::from_toml`] reads back to an equal scene (a
    /// viewer's "save").
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).expect("a scene is always representable in TOML")
    }

    /// Reads a scene file (at most 1 MiB).
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        let file = path.display().to_string();
        let text = crate::io::read_text(path).map_err(|message| SceneError::Io { file: file.clone(), message })?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_toml(&text, &file, &base)
    }

    /// Parses scene text; `file` names it in errors, `base_dir` anchors relative paths.
    pub fn from_toml(text: &str, file: &str, base_dir: &Path) -> Result<Self, SceneError> {
        let mut scene: Scene = toml::from_str(text).map_err(|e| {
            let (line, column, message) = crate::io::toml_error(text, &e);
            SceneError::Toml { file: file.to_string(), line, column, message }
        })?;
        scene.base_dir = base_dir.to_path_buf();
        scene.file = file.to_string();
        scene.source = SourceText(text.into());
        if let Some((field, written, read)) = crate::io::dropped_elements(text, &scene) {
            return Err(SceneError::Value {
                file: file.to_string(),
                line: field_line(text, &field),
                field,
                value: format!("{written} elements"),
                expected: format!("{read} elements"),
            });
        }
        scene.check().map_err(|(field, value, expected)| SceneError::Value {
            file: file.to_string(),
            line: field_line(text, &field),
            field,
            value,
            expected: expected.to_string(),
        })?;
        Ok(scene)
    }

    /// The line of the scene's text where `field` (`tree[2].method`) is set; 1 when unknown.
    pub fn line_of(&self, field: &str) -> usize {
        crate::io::nested_field_line(&self.source.0, field)
    }

    /// Checks that every tree's method is one of `known` (the runtime's registry).
    pub fn check_methods(&self, known: &[&str]) -> Result<(), SceneError> {
        for (i, t) in self.trees.iter().enumerate() {
            if !known.contains(&t.method.as_str()) {
                let field = format!("tree[{i}].method");
                return Err(SceneError::Value {
                    file: self.file.clone(),
                    line: self.line_of(&field),
                    value: format!("{:?}", t.method.as_str()),
                    field,
                    expected: format!("one of {}", known.join(", ")),
                });
            }
        }
        Ok(())
    }

    /// Frames to render.
    pub fn frames(&self) -> u32 {
        (self.output.seconds * self.output.fps).round().max(1.0) as u32
    }

    /// A path from the scene (species or wind file), resolved against the scene's
    /// directory when relative and present there.
    pub fn resolve_path(&self, arg: &str) -> String {
        let p = Path::new(arg);
        if p.is_relative() && !self.base_dir.as_os_str().is_empty() {
            let joined = self.base_dir.join(p);
            if joined.exists() {
                return joined.display().to_string();
            }
        }
        arg.to_string()
    }

    /// Checks ranges; the error is (field, value, expected).
    pub fn check(&self) -> Result<(), (String, String, &'static str)> {
        let o = &self.output;
        let err = |f: &str, v: String, e| Err((f.to_string(), v, e));
        if !(16..=8192).contains(&o.width) {
            return err("output.width", o.width.to_string(), "16 to 8192 pixels");
        }
        if !(16..=8192).contains(&o.height) {
            return err("output.height", o.height.to_string(), "16 to 8192 pixels");
        }
        if !(o.fps.is_finite() && o.fps > 0.0 && o.fps <= 120.0) {
            return err("output.fps", o.fps.to_string(), "a number in (0, 120]");
        }
        if !(o.seconds.is_finite() && o.seconds > 0.0) {
            return err("output.seconds", o.seconds.to_string(), "a positive number of seconds");
        }
        if o.seconds * o.fps > MAX_FRAMES as f32 {
            return err("output.seconds", o.seconds.to_string(), "at most 10,000 frames (seconds × fps)");
        }
        if !(o.preroll.is_finite() && (0.0..=60.0).contains(&o.preroll)) {
            return err("output.preroll", o.preroll.to_string(), "0 to 60 seconds");
        }
        if !(o.sim_rate.is_finite() && o.sim_rate >= o.fps && o.sim_rate <= 2000.0) {
            return err("output.sim_rate", o.sim_rate.to_string(), "at least fps and at most 2000 Hz");
        }
        if !matches!(o.msaa, 1 | 4) {
            return err("output.msaa", o.msaa.to_string(), "1 or 4");
        }
        if o.name.is_empty() || o.name.contains(['/', '\\']) {
            return err("output.name", format!("{:?}", o.name), "a plain file name");
        }
        let c = &self.camera;
        if !(c.fov_deg.is_finite() && c.fov_deg > 1.0 && c.fov_deg < 170.0) {
            return err("camera.fov_deg", c.fov_deg.to_string(), "1 to 170 degrees");
        }
        let (eye, target) = (glam::Vec3::from_array(c.eye), glam::Vec3::from_array(c.target));
        if !eye.is_finite() {
            return err("camera.eye", format!("{:?}", c.eye), "finite coordinates");
        }
        if !target.is_finite() {
            return err("camera.target", format!("{:?}", c.target), "finite coordinates");
        }
        if (eye - target).length() < 1e-3 {
            return err("camera.target", format!("{:?}", c.target), "a point away from the eye");
        }
        if !glam::Vec3::from_array(self.sun.direction).is_finite()
            || glam::Vec3::from_array(self.sun.direction).length() < 1e-6
        {
            return err("sun.direction", format!("{:?}", self.sun.direction), "a non-zero direction");
        }
        if !(self.sun.intensity.is_finite() && (0.0..=100.0).contains(&self.sun.intensity)) {
            return err("sun.intensity", self.sun.intensity.to_string(), "0 to 100");
        }
        if self.trees.is_empty() {
            return err("tree", "none".into(), "at least one [[tree]]");
        }
        if self.trees.len() > MAX_TREES {
            return err("tree", self.trees.len().to_string(), "at most 64 [[tree]] tables");
        }
        let instances: usize = self.trees.iter().map(|t| 1 + t.copies.len()).sum();
        if instances > MAX_INSTANCES {
            return err("tree", instances.to_string(), "at most 100,000 instances in all");
        }
        for (i, t) in self.trees.iter().enumerate() {
            let f = |k: &str| format!("tree[{i}].{k}");
            let m = t.method.as_str();
            if m.is_empty()
                || m.len() > 64
                || !m.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
            {
                return err(
                    &f("method"),
                    format!("{m:?}"),
                    "a method name (zioma, akagi, skjermo, hsm or one registered)",
                );
            }
            if !glam::Vec3::from_array(t.position).is_finite() {
                return err(&f("position"), format!("{:?}", t.position), "finite coordinates");
            }
            if !(t.yaw_deg.is_finite() && t.yaw_deg.abs() <= 1e4) {
                return err(&f("yaw_deg"), t.yaw_deg.to_string(), "-10000 to 10000 degrees");
            }
            if !(t.scale.is_finite() && t.scale > 0.0 && t.scale <= 100.0) {
                return err(&f("scale"), t.scale.to_string(), "a scale in (0, 100]");
            }
            if let Some(c) = t.tint {
                if !c.iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v)) {
                    return err(&f("tint"), format!("{c:?}"), "three values in 0…1");
                }
            }
            for (k, v) in [("sides", t.sides), ("leaf_sides", t.leaf_sides)] {
                if let Some(v) = v {
                    if !(3..=crate::mesh::MAX_SIDES).contains(&v) {
                        return err(&f(k), v.to_string(), "3 to 64 sides");
                    }
                }
            }
            if !(1..=MAX_PHASE_GROUPS).contains(&t.phase_groups) {
                return err(&f("phase_groups"), t.phase_groups.to_string(), "1 to 16 simulations");
            }
            if let Some(table) = &t.leaf_motion {
                if let Err(message) = crate::model::LeafMotion::default().with_table(table) {
                    return err(
                        &f("leaf_motion"),
                        message,
                        "leaf motion fields in range (see `sylva_core::leaves::LeafMotion`)",
                    );
                }
            }
            for (k, c) in t.copies.iter().enumerate() {
                let f = |key: &str| format!("tree[{i}].copies[{k}].{key}");
                if !glam::Vec3::from_array(c.position).is_finite() {
                    return err(&f("position"), format!("{:?}", c.position), "finite coordinates");
                }
                if !(c.yaw_deg.is_finite() && c.yaw_deg.abs() <= 1e4) {
                    return err(&f("yaw_deg"), c.yaw_deg.to_string(), "-10000 to 10000 degrees");
                }
                if !(c.scale.is_finite() && c.scale > 0.0 && c.scale <= 100.0) {
                    return err(&f("scale"), c.scale.to_string(), "a scale in (0, 100]");
                }
            }
        }
        Ok(())
    }
}
