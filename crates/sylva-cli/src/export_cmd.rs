//! `sylva export`: a tree as glTF 2.0 (`.glb` or `.gltf`) with a skin and wind baked from
//! any method, hierarchy attributes for engine-side wind, and levels of detail.

use crate::simulate_cmd::TreeWindArgs;
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::time::Instant;
use sylva_core::export::{BakeParams, DEFAULT_LODS, GltfOptions, JointMode, Lod, bake, write_gltf};
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
    /// Joints of the skin.
    #[arg(long, value_enum, default_value = "segment", conflicts_with = "static_only")]
    pub joints: Joints,
    /// Refuse to write a skin with more joints than this (your engine's bone limit), leaf
    /// joints included.
    #[arg(long, conflicts_with = "static_only")]
    pub max_joints: Option<usize>,
    /// No leaf joints: leaves stay rigid with their branch in the clip (their flutter is
    /// still in the `_LEAF_FLUTTER` attribute, for an engine shader).
    #[arg(long, conflicts_with = "static_only")]
    pub no_leaf_joints: bool,
    /// A level of detail as `sides,samples,leaf_sides,leaf_keep` (repeat for several,
    /// finest first). Default: 8,3,8,1 6,2,6,0.5 4,1,4,0.25.
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
    Ok(Lod {
        sides: int(0, "sides")?,
        samples: int(1, "samples")?,
        leaf_sides: int(2, "leaf_sides")?,
        leaf_keep: parts[3].parse::<f32>().map_err(|_| format!("`{s}`: leaf_keep `{}` is not a number", parts[3]))?,
    })
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
    };
    let opts = GltfOptions {
        joints: match a.joints {
            Joints::Segment => JointMode::Segment,
            Joints::Stem => JointMode::Stem,
        },
        max_joints: a.max_joints,
        lods: if a.lods.is_empty() { DEFAULT_LODS.to_vec() } else { a.lods.clone() },
        leaf_joints: !a.no_leaf_joints,
    };
    let (tree, wind) = a.tree.resolve()?;
    let tree = std::sync::Arc::new(tree);
    let mut anim = MethodRegistry::builtin().cpu(&a.tree.method, tree.clone(), &a.tree.options())?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    export(anim.as_mut(), &wind, &params, &opts, a.static_only, &out)?;
    Ok(out)
}

/// Bakes `anim` (unless static) and writes, printing what was written and how long it took.
pub fn export(
    anim: &mut dyn Animator,
    wind: &WindScene,
    params: &BakeParams,
    opts: &GltfOptions,
    static_only: bool,
    out: &std::path::Path,
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
    let t1 = Instant::now();
    let report = write_gltf(tree, clip.as_ref(), opts, out)?;
    let written = t1.elapsed().as_secs_f64();
    let size = std::fs::metadata(out).map(|m| m.len()).unwrap_or(0);
    println!(
        "{} (seed {}): {} segments, {} stems, {} leaves",
        tree.name,
        tree.seed,
        tree.segments.len(),
        tree.stems.len(),
        tree.leaves.len()
    );
    println!(
        "  {:<5} {:>5} {:>7} {:>10} {:>10} {:>9} {:>10} {:>10}",
        "lod", "sides", "samples", "leaf sides", "leaf keep", "leaves", "triangles", "MiB"
    );
    for (k, l) in report.lods.iter().enumerate() {
        println!(
            "  {:<5} {:>5} {:>7} {:>10} {:>10} {:>9} {:>10} {:>10.2}",
            k,
            l.lod.sides,
            l.lod.samples,
            l.lod.leaf_sides,
            l.lod.leaf_keep,
            l.leaves,
            l.triangles,
            l.bytes as f64 / (1 << 20) as f64
        );
    }
    if let Some(c) = &clip {
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
    } else {
        println!("  static: no skin, no animation");
    }
    println!("  textures {:.2} MiB", report.texture_bytes as f64 / (1 << 20) as f64);
    if static_only {
        println!("  wrote in {written:.2} s");
    } else {
        println!("  baked in {baked:.2} s, wrote in {written:.2} s");
    }
    println!("wrote {} ({:.2} MiB)", out.display(), size as f64 / (1 << 20) as f64);
    if size == 0 {
        bail!("{}: the file is empty", out.display());
    }
    Ok(())
}
