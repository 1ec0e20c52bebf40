//! `sylva export`: a tree as glTF 2.0 (`.glb` or `.gltf`) with a skin and wind baked from
//! any method, hierarchy attributes for engine-side wind, and levels of detail.

use crate::simulate_cmd::TreeWindArgs;
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::time::Instant;
use sylva_core::export::gltf::{GAME_BUDGET, Target};
use sylva_core::export::{BakeParams, GltfOptions, JointMode, Lod, bake, write_gltf};
use sylva_core::methods::Animator;
use sylva_core::wind::WindScene;
use sylva_runtime::MethodRegistry;

/// Joints of the skin.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Joints {
    /// One joint per segment: the full motion.
    Segment,
    /// One joint per stem (for engines with a bone limit): each stem moves rigidly about
    /// its base.
    Stem,
    /// The thickest segments within `--max-joints` (default 256), leaf joints included:
    /// thinner stems ride with their parents.
    Budget,
}

/// What the export is for.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExportTarget {
    /// A game asset: at most 256 joints, LODs of at most 50 k / 16 k / 5 k triangles with
    /// leaf cards, quantised data, reduced keys, hierarchy packed in TEXCOORD_1…3.
    Game,
    /// Full detail: a joint per segment, every leaf and stem, float data, every key, the
    /// custom hierarchy attributes as well.
    Film,
}

/// Arguments of `sylva export`.
#[derive(clap::Args, Debug)]
pub struct ExportArgs {
    /// Tree, the method baked into the clip, and wind.
    #[command(flatten)]
    pub tree: TreeWindArgs,
    /// Clip length, s.
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    pub seconds: f32,
    /// Frames (animation keys) per second.
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    pub fps: f32,
    /// Make the clip loop seamlessly: the ends are cross-faded over `--blend` seconds.
    #[arg(long = "loop", default_value_t = false, conflicts_with = "static_only")]
    pub looped: bool,
    /// Cross-fade window of a looping clip, s.
    #[arg(long, default_value_t = BakeParams::default().blend, allow_negative_numbers = true)]
    pub blend: f32,
    /// Simulated time before the clip starts, s (stateful methods settle into the wind).
    #[arg(long, default_value_t = BakeParams::default().preroll, allow_negative_numbers = true)]
    pub preroll: f32,
    /// Simulation steps per second of stateful methods.
    #[arg(long, default_value_t = BakeParams::default().sim_rate)]
    pub sim_rate: f32,
    /// Static export: the mesh and hierarchy attributes, no skin, no animation.
    #[arg(long = "static", default_value_t = false)]
    pub static_only: bool,
    /// What the export is for: sets the joints, levels of detail, data format and keys
    /// below unless they are given.
    #[arg(long, value_enum, default_value = "game")]
    pub target: ExportTarget,
    /// Joints of the skin. Default: budget (game), segment (film).
    #[arg(long, value_enum, conflicts_with = "static_only")]
    pub joints: Option<Joints>,
    /// Joints allowed in the skin, leaf joints included (your engine's bone limit): the
    /// budget of `--joints budget`, a limit the other modes refuse to pass. Default: 256
    /// (game), none (film).
    #[arg(long, conflicts_with = "static_only")]
    pub max_joints: Option<usize>,
    /// Also write the hierarchy as the custom float attributes `_PIVOT`, `_BRANCH_AXIS`,
    /// `_HIERARCHY_DEPTH`, `_PARENT_PIVOT`, `_PHASE`, `_LEAF_FLUTTER` (film always does).
    #[arg(long)]
    pub custom_attributes: bool,
    /// Float vertex data without `KHR_mesh_quantization` (for importers without it, such as
    /// Godot 3's); the film target always writes floats.
    #[arg(long)]
    pub no_quantize: bool,
    /// Drop rotation keys that the slerp between their neighbours reproduces within this
    /// angle, degrees (0 keeps every key). Default: 0.05 (game), 0 (film).
    #[arg(long, conflicts_with = "static_only", allow_negative_numbers = true)]
    pub key_tolerance: Option<f32>,
    /// One file per level of detail (`<out>_LOD0.glb`, `_LOD1`, …) instead of one file.
    #[arg(long)]
    pub lod_files: bool,
    /// Compress vertex, index and animation data with `EXT_meshopt_compression` (required
    /// by the file: the loader needs a meshopt decoder, as three.js's `setMeshoptDecoder`).
    #[arg(long)]
    pub meshopt: bool,
    /// No leaf joints: leaves stay rigid with their branch in the clip (their flutter is
    /// still in the `_LEAF_FLUTTER` attribute, for an engine shader).
    #[arg(long, conflicts_with = "static_only")]
    pub no_leaf_joints: bool,
    /// A level of detail as `sides,samples,leaf_sides,leaf_keep` (repeat for several,
    /// finest first), every stem meshed and leaves as blades. Default: the game target's
    /// budgeted levels; film's 8,3,8,1 6,2,6,0.5 4,1,4,0.25.
    #[arg(long = "lod", value_parser = parse_lod)]
    pub lods: Vec<Lod>,
    /// Output file: `.glb` (binary) or `.gltf` (JSON, buffers embedded). Default:
    /// out/<species>.glb.
    #[arg(long, short)]
    pub out: Option<PathBuf>,
}

fn parse_lod(s: &str) -> Result<Lod, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 4 {
        return Err(format!("`{s}`: expected four values `sides,samples,leaf_sides,leaf_keep`, e.g. 6,2,6,0.5"));
    }
    let int = |i: usize, name: &str| {
        parts[i].parse::<u32>().map_err(|_| format!("`{s}`: {name} `{}` is not a whole number", parts[i]))
    };
    Ok(Lod::film(
        int(0, "sides")?,
        int(1, "samples")?,
        int(2, "leaf_sides")?,
        parts[3].parse::<f32>().map_err(|_| format!("`{s}`: leaf_keep `{}` is not a number", parts[3]))?,
    ))
}

/// Runs the command; returns the file written.
pub fn run(a: &ExportArgs) -> Result<PathBuf> {
    let out = a.out.clone().unwrap_or_else(|| {
        let stem = std::path::Path::new(&a.tree.species)
            .file_stem()
            .map_or_else(|| "tree".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from("out").join(format!("{stem}.glb"))
    });
    let params = BakeParams {
        seconds: a.seconds,
        fps: a.fps,
        looped: a.looped,
        blend: a.blend,
        preroll: a.preroll,
        sim_rate: a.sim_rate,
        per_leaf: false,
    };
    let (tree, wind) = a.tree.resolve()?;
    let opts = options(a, &tree);
    let tree = std::sync::Arc::new(tree);
    let mut anim = MethodRegistry::builtin().cpu(&a.tree.method, tree.clone(), &a.tree.options())?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let files: Vec<(GltfOptions, PathBuf)> = if a.lod_files {
        (0..opts.lods.len())
            .map(|k| (GltfOptions { lods: vec![opts.lods[k]], first_lod: k, ..opts.clone() }, lod_path(&out, k)))
            .collect()
    } else {
        vec![(opts, out.clone())]
    };
    export(anim.as_mut(), &wind, &params, &files, a.static_only)?;
    if a.target == ExportTarget::Game {
        let b = GAME_BUDGET;
        println!(
            "game budget: {} joints per skin, {} triangles per level of detail, {} MiB for a 10 s clip at 30 fps",
            b.joints,
            b.triangles.map(|t| t.to_string()).join(" / "),
            b.bytes >> 20
        );
    }
    Ok(out)
}

/// `out` with `_LOD<k>` before its extension.
pub fn lod_path(out: &std::path::Path, k: usize) -> PathBuf {
    let stem = out.file_stem().map_or_else(|| "tree".into(), |s| s.to_string_lossy().into_owned());
    let ext = out.extension().map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
    out.with_file_name(format!("{stem}_LOD{k}{ext}"))
}

/// The export options: the target's, with what the command line gives instead.
fn options(a: &ExportArgs, tree: &sylva_core::model::Tree) -> GltfOptions {
    let target = match a.target {
        ExportTarget::Game => Target::Game,
        ExportTarget::Film => Target::Film,
    };
    let mut opts = GltfOptions::for_target(target, tree);
    if let Some(j) = a.joints {
        opts.joints = match j {
            Joints::Segment => JointMode::Segment,
            Joints::Stem => JointMode::Stem,
            Joints::Budget => JointMode::Budget(a.max_joints.unwrap_or(GAME_BUDGET.joints)),
        };
    }
    if let Some(m) = a.max_joints {
        opts.max_joints = Some(m);
        if let JointMode::Budget(_) = opts.joints {
            opts.joints = JointMode::Budget(m);
        }
    } else if a.joints.is_some() && a.joints != Some(Joints::Budget) {
        opts.max_joints = None;
    }
    if !a.lods.is_empty() {
        opts.lods = a.lods.clone();
    }
    opts.leaf_joints = !a.no_leaf_joints;
    opts.custom_attributes |= a.custom_attributes;
    opts.quantize &= !a.no_quantize;
    opts.meshopt = a.meshopt;
    if let Some(t) = a.key_tolerance {
        opts.key_tolerance_deg = t;
    }
    opts
}

/// Bakes `anim` once (unless static) and writes each file with its options, printing what
/// was written and how long it took.
pub fn export(
    anim: &mut dyn Animator,
    wind: &WindScene,
    params: &BakeParams,
    files: &[(GltfOptions, PathBuf)],
    static_only: bool,
) -> Result<()> {
    let tree = anim.tree().clone();
    let tree = &*tree;
    let t0 = Instant::now();
    let clip = if static_only {
        None
    } else {
        let bar = ProgressBar::new(0);
        bar.set_style(
            ProgressStyle::with_template("baking {msg} {bar:40} {pos}/{len} frames, {eta} left")
                .expect("static template"),
        );
        bar.set_message(anim.name());
        let clip = bake(anim, wind, params, &mut |done, total| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        })
        .context("baking the animation")?;
        bar.finish_and_clear();
        Some(clip)
    };
    let baked = t0.elapsed().as_secs_f64();
    println!(
        "{} (seed {}): {} segments, {} stems, {} leaves",
        tree.name,
        tree.seed,
        tree.segments.len(),
        tree.stems.len(),
        tree.leaves.len()
    );
    if !static_only {
        println!("  baked in {baked:.2} s");
    }
    for (opts, out) in files {
        write_one(tree, clip.as_ref(), opts, out)?;
    }
    Ok(())
}

/// Writes one file and prints what it holds.
fn write_one(
    tree: &sylva_core::model::Tree,
    clip: Option<&sylva_core::export::Clip>,
    opts: &GltfOptions,
    out: &std::path::Path,
) -> Result<()> {
    let t1 = Instant::now();
    let report = write_gltf(tree, clip, opts, out)?;
    let written = t1.elapsed().as_secs_f64();
    let size = std::fs::metadata(out).map(|m| m.len()).unwrap_or(0);
    println!(
        "  {:<5} {:>5} {:>7} {:>11} {:>10} {:>10} {:>9} {:>10} {:>10}",
        "lod", "sides", "samples", "stems ≥ mm", "leaf sides", "leaf keep", "leaves", "triangles", "MiB"
    );
    for (k, l) in report.lods.iter().enumerate() {
        println!(
            "  {:<5} {:>5} {:>7} {:>11.1} {:>10} {:>10.3} {:>9} {:>10} {:>10.2}",
            k,
            l.lod.sides,
            l.lod.samples,
            l.lod.min_radius * 1000.0,
            if l.lod.cards { "cards".to_string() } else { l.lod.leaf_sides.to_string() },
            l.lod.leaf_keep,
            l.leaves,
            l.triangles,
            l.bytes as f64 / (1 << 20) as f64
        );
    }
    if let Some(c) = clip {
        println!(
            "  skin: {} joints ({} of them leaf joints); animation `{}`: {} keys ({:.2} s at {} fps{}), {} channels, {:.2} MiB",
            report.joints,
            report.leaf_joints,
            if c.looped { "wind_loop" } else { "wind" },
            report.frames,
            c.duration(),
            c.fps,
            if c.looped { ", looping" } else { "" },
            report.channels,
            report.animation_bytes as f64 / (1 << 20) as f64
        );
        if report.keys < report.frames * report.channels {
            println!(
                "  keys reduced within {}°: {} of {} kept ({:.0} %)",
                opts.key_tolerance_deg,
                report.keys,
                report.frames * report.channels,
                100.0 * report.keys as f64 / (report.frames * report.channels).max(1) as f64
            );
        }
    } else {
        println!("  static: no skin, no animation");
    }
    println!("  textures {:.2} MiB", report.texture_bytes as f64 / (1 << 20) as f64);
    println!("  wrote in {written:.2} s");
    println!("wrote {} ({:.2} MiB)", out.display(), size as f64 / (1 << 20) as f64);
    if size == 0 {
        bail!("{}: the file is empty", out.display());
    }
    Ok(())
}
