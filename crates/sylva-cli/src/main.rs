//! `sylva`: grow trees and move them in the wind. A thin shell over the libraries: the
//! runtime (`sylva-runtime`) runs scenes, the bench harness (`sylva-bench`) the papers'
//! tables, the viewer (`sylva-viewer`) the window.
//!
//! With no arguments, runs the main job: `sylva render` on the built-in default scene.

mod export_cmd;
mod limit_args;
mod render_cmd;
mod signals;
mod simulate_cmd;
mod view_cmd;
mod wind_cmd;

use anyhow::{Context, Result};

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::time::Instant;
use sylva_core::Tree;
use sylva_core::export::{ObjOptions, write_obj};
use sylva_core::species::{DEFAULT_SPECIES, PRESETS, PresetKind, SpeciesSource};

#[derive(Parser, Debug)]
#[command(name = "sylva", version, about = "Grow trees and move them in the wind, on the CPU and the GPU.")]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Generate a tree, print a summary and write a static OBJ mesh.
    Generate(GenerateArgs),
    /// List the species and grammars that ship with Sylva.
    Presets,
    /// Plot a wind scene: speed at a point over time, and a top-down map of the field.
    Wind(wind_cmd::WindArgs),
    /// Animate a tree in the wind and report how it moved (optionally a CSV trajectory).
    Simulate(simulate_cmd::SimulateArgs),
    /// Render a scene (the built-in default when none is given) to a GIF, PNG frames and,
    /// with ffmpeg installed, an MP4.
    Render(render_cmd::RenderArgs),
    /// Reproduce a paper's result table on the CPU and the GPU, with plots.
    Bench(sylva_bench::BenchArgs),
    /// Measure each method's motion as field studies measure trees (frequency against
    /// DBH/H², damping against wind, bend, flutter) beside the field references.
    Fidelity(sylva_bench::fidelity::FidelityArgs),
    /// Export a tree as glTF 2.0 (.glb/.gltf): mesh, materials, a skin and wind baked from
    /// any method (optionally looping), hierarchy attributes for engine wind shaders, LODs.
    Export(export_cmd::ExportArgs),
    /// Open the interactive viewer: the scene in a window, with wind, trees and methods
    /// under the user's control (blasts and vortices by clicking the ground).
    View(view_cmd::ViewArgs),
}

#[derive(clap::Args, Debug)]
struct GenerateArgs {
    /// A preset name (see `sylva presets`), a Weber–Penn TOML file or an L-system grammar file.
    #[arg(long, short, default_value = DEFAULT_SPECIES)]
    species: String,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Derivation steps of an L-system (overrides the grammar's `iterations`).
    #[arg(long)]
    iterations: Option<u32>,
    /// Output OBJ file (default: out/<species>.obj); `-` writes none.
    #[arg(long, short)]
    out: Option<PathBuf>,
    /// Sides of each branch tube in the OBJ (3 to 64, as export and scenes allow).
    #[arg(long, default_value_t = 6, value_parser = clap::value_parser!(u32).range(3..=64))]
    sides: u32,
    #[command(flatten)]
    limits: limit_args::LimitArgs,
    /// Worker threads (default: all cores; at most 4 per core). The tree is identical for
    /// any count.
    #[arg(long, value_parser = parse_threads)]
    threads: Option<usize>,
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    if let Err(e) = signals::install() {
        eprintln!("warning: no signal handling ({e}); an interrupt may leave temporary files");
    }
    match run(cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("Error: {}", report(&e));
            std::process::ExitCode::from(signals::exit_status().unwrap_or(1))
        }
    }
}

/// The error and its causes, each cause once: a cause whose text its wrapper already quotes
/// (a file name prefixed to a parse error) is not repeated.
fn report(e: &anyhow::Error) -> String {
    let mut out = e.to_string();
    let mut last = out.clone();
    for cause in e.chain().skip(1) {
        let text = cause.to_string();
        if !last.contains(&text) {
            out.push_str("\n  caused by: ");
            out.push_str(&text);
        }
        last = text;
    }
    out
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        None => render_cmd::run(&render_cmd::RenderArgs::default()),
        Some(Command::Render(args)) => render_cmd::run(&args),
        Some(Command::Generate(args)) => generate(args),
        Some(Command::Presets) => {
            presets();
            Ok(())
        }
        Some(Command::Simulate(args)) => simulate_cmd::run(&args),
        Some(Command::Export(args)) => export_cmd::run(&args).map(|_| ()),
        Some(Command::View(args)) => view_cmd::run(&args),
        Some(Command::Bench(args)) => {
            for p in sylva_bench::run(&args)? {
                println!("wrote {}", p.display());
            }
            Ok(())
        }
        Some(Command::Fidelity(args)) => {
            for p in sylva_bench::fidelity::run(&args)? {
                println!("wrote {}", p.display());
            }
            Ok(())
        }
        Some(Command::Wind(args)) => {
            for p in wind_cmd::run(&args)? {
                println!("wrote {}", p.display());
            }
            Ok(())
        }
    }
}

/// `--threads`: 1 to 4 per core.
fn parse_threads(s: &str) -> Result<usize, String> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let most = 4 * cores;
    match s.parse::<usize>() {
        Ok(n) if (1..=most).contains(&n) => Ok(n),
        _ => Err(format!("expected 1 to {most} (4 per core; this machine has {cores})")),
    }
}

fn presets() {
    println!("{:<18} {:<9} {:<36} description", "name", "kind", "file");
    for p in PRESETS {
        let kind = match p.kind {
            PresetKind::Species => "species",
            PresetKind::Grammar => "grammar",
        };
        let desc =
            SpeciesSource::from_preset(p).map(|s| s.name().to_string()).unwrap_or_else(|e| format!("(invalid: {e})"));
        println!("{:<18} {:<9} {:<36} {}", p.name, kind, p.file, desc);
    }
}

fn generate(args: GenerateArgs) -> Result<()> {
    if let Some(n) = args.threads {
        rayon::ThreadPoolBuilder::new().num_threads(n).build_global().context("setting up worker threads")?;
    }
    let limits = args.limits.limits();
    let source = SpeciesSource::resolve_with(&args.species, &limits)?;
    let t0 = Instant::now();
    let tree = source.generate(args.seed, &limits, args.iterations)?;
    let elapsed = t0.elapsed();
    summary(&tree, elapsed.as_secs_f64());
    let out = match &args.out {
        Some(p) if p.as_os_str() == "-" => None,
        Some(p) => Some(p.clone()),
        None => {
            // A preset by any of its names writes under its name (`Quaking Aspen` →
            // `quaking_aspen.obj`); a file under its stem.
            let stem = match sylva_core::species::Preset::find(&args.species) {
                Some(p) => p.name.to_string(),
                None => std::path::Path::new(&args.species)
                    .file_stem()
                    .map_or_else(|| "tree".into(), |s| s.to_string_lossy().into_owned()),
            };
            Some(PathBuf::from("out").join(format!("{stem}.obj")))
        }
    };
    if let Some(path) = out {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        let (v, f) = write_obj(&tree, &path, ObjOptions { sides: args.sides, leaves: true })
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {} ({v} vertices, {f} triangles)", path.display());
    }
    Ok(())
}

fn summary(t: &Tree, seconds: f64) {
    let s = t.stats();
    println!("{} (seed {}), generated in {:.1} ms", t.name, t.seed, seconds * 1e3);
    println!("  {:>5} {:>10} {:>8} {:>9}", "level", "segments", "stems", "leaves");
    for l in 0..s.segments_per_level.len() {
        println!("  {:>5} {:>10} {:>8} {:>9}", l, s.segments_per_level[l], s.stems_per_level[l], s.leaves_per_level[l]);
    }
    println!("  {:>5} {:>10} {:>8} {:>9}", "total", t.segments.len(), t.stems.len(), t.leaves.len());
    println!("  height {:.2} m, crown width {:.2} m, wood mass {:.1} kg", s.height, s.crown_width, s.mass);
    if let Some(dbh) = t.dbh() {
        let modes = sylva_core::physics::stem_frequencies(t, sylva_core::physics::MIN_RADIUS);
        println!(
            "  trunk diameter at breast height {:.3} m, DBH/H² {:.2e} 1/m, first mode {:.2} Hz",
            dbh,
            dbh / (s.height * s.height),
            modes.hz(0)
        );
    }
    println!(
        "  model memory {:.2} MiB, max children per segment {}",
        s.memory_bytes as f64 / (1 << 20) as f64,
        t.children.max_children
    );
    println!("  digest {}", t.digest());
}
