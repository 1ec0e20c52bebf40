//! Sylva's bench harness (`sylva bench`): the papers' result tables at their exact sizes, on
//! the CPU and the GPU in one run, with the paper's figure beside ours, a Markdown table, a
//! JSON file and a plot.
//!
//! Tables ([`tables`] holds the published figures): `song-t2`, `song-t3` ([`song`]),
//! `akagi-t2` ([`akagi`]), `zioma-t6-1` ([`zioma`]) and `skjermo` ([`skjermo`]).
//!
//! Timing: a warm-up, then repeated samples of several steps each (the count chosen so a
//! sample takes about a fifth of the time budget); the median and the spread (min–max) of
//! the samples are reported. GPU samples are timed with timestamp queries where the adapter
//! has them (the GPU's clock from the first pass of the sample to the end of the last,
//! [`sylva_gpu::timer::GpuTimer`]), otherwise by wall clock from submission to completion;
//! each rate says which (`clock`). Every row also states how close it runs to this
//! machine's memory bandwidth, measured by the bench itself (a parallel copy on the CPU, a
//! buffer copy on the GPU).

pub mod akagi;
pub mod fidelity;
pub mod harness;
pub mod plot;
pub mod skjermo;
pub mod song;
pub mod tables;
pub mod zioma;

use anyhow::{Context, Result, bail};
use harness::{Env, Machine, cpu_bandwidth, cpu_model, gpu_bandwidth, gpu_figures, gpu_probes};
use std::path::PathBuf;
use sylva_core::species::SpeciesSource;

/// Which table to reproduce.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Table {
    /// Song et al. Table 2: one tree, 5…4,975 clusters.
    SongT2,
    /// Song et al. Table 3: ten trees, 50…49,750 clusters.
    SongT3,
    /// Akagi & Kitajima Table 2: mesh regeneration, 108,808…4,109,056 triangles.
    AkagiT2,
    /// Zioma Table 6-1: 30…1,000 instances of an 80-branch tree, pose and skinning.
    #[value(name = "zioma-t6-1")]
    ZiomaT61,
    /// Skjermo's figure: 65,535 and 262,143 branches updated per second.
    Skjermo,
    /// Every table.
    All,
}

/// Which backends to time.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backends {
    /// The CPU reference (rayon, every core).
    Cpu,
    /// The wgpu compute kernels.
    Gpu,
    /// Both, in the same run.
    Both,
}

/// Arguments of `sylva bench`.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// The table to reproduce.
    #[arg(value_enum)]
    pub table: Table,
    /// Backends to time.
    #[arg(long, value_enum, default_value = "both")]
    pub backend: Backends,
    /// Only the three smallest sizes of each table, with a short time budget (seconds).
    #[arg(long)]
    pub quick: bool,
    /// Time budget per measurement, s (default 1; 0.1 with --quick).
    #[arg(long)]
    pub budget: Option<f64>,
    /// Directory for the Markdown, JSON and PNG outputs.
    #[arg(long, default_value = "bench")]
    pub out_dir: PathBuf,
    /// The tree whose clusters are timed (truncated, root first, to each size).
    #[arg(long, default_value = "quaking_aspen")]
    pub species: String,
}

/// Runs `sylva bench` and returns the files written.
pub fn run(args: &BenchArgs) -> Result<Vec<PathBuf>> {
    let budget = args.budget.unwrap_or(if args.quick { 0.1 } else { 1.0 });
    if !(budget.is_finite() && budget > 0.0 && budget <= 600.0) {
        bail!("--budget {budget}: expected a time budget in seconds, above 0 and at most 600");
    }
    let tables: Vec<Table> = match args.table {
        Table::All => vec![Table::SongT2, Table::SongT3, Table::AkagiT2, Table::ZiomaT61, Table::Skjermo],
        one => vec![one],
    };
    let ctx = match args.backend {
        Backends::Cpu => None,
        _ => Some(sylva_gpu::GpuContext::shared().context("--backend gpu/both needs a GPU adapter")?),
    };
    let time_cpu = args.backend != Backends::Gpu;
    let tree = SpeciesSource::resolve(&args.species)?.generate(1, &Default::default(), None)?;
    let buffer_copy = ctx.map(gpu_bandwidth).transpose()?;
    let probes = match ctx {
        Some(c) => gpu_probes(c)?,
        None => None,
    };
    let kernel_copy = probes.map(|p| p.kernel_copy);
    let machine = Machine {
        cpu: cpu_model(),
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        threads: rayon::current_num_threads(),
        gpu: ctx.map(|c| match c.subgroup_size {
            Some(n) => format!("{}, subgroups of {n}", c.summary),
            None => format!("{}, no fixed subgroup size", c.summary),
        }),
        cpu_bandwidth: cpu_bandwidth(),
        gpu_bandwidth: buffer_copy.map(|b| kernel_copy.map_or(b, |k| b.max(k))),
        gpu_buffer_copy: buffer_copy,
        gpu_kernel_copy: kernel_copy,
        gpu_dispatch: probes.map(|p| p.dispatch),
        gpu_pass: probes.map(|p| p.pass),
        gpu_clock: ctx.map(|c| if c.timestamps { "timestamp queries" } else { "wall clock" }),
        date: humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string(),
        command: std::env::args().collect::<Vec<_>>().join(" "),
    };
    println!(
        "CPU: {} ({} threads), copy bandwidth {:.1} GB/s",
        machine.cpu,
        machine.threads,
        machine.cpu_bandwidth / 1e9
    );
    if let (Some(g), Some(clock)) = (&machine.gpu, machine.gpu_clock) {
        println!("GPU: {g}, {}, timed by {clock}", gpu_figures(&machine));
    }
    let env = Env { quick: args.quick, budget, time_cpu, ctx, out_dir: &args.out_dir, machine: &machine };
    std::fs::create_dir_all(&args.out_dir).with_context(|| format!("creating {}", args.out_dir.display()))?;
    let mut written = Vec::new();
    for table in tables {
        written.extend(match table {
            Table::SongT2 => song::run(&env, &tree, false)?,
            Table::SongT3 => song::run(&env, &tree, true)?,
            Table::AkagiT2 => akagi::run(&env)?,
            Table::ZiomaT61 => zioma::run(&env)?,
            Table::Skjermo => skjermo::run(&env)?,
            Table::All => unreachable!("expanded above"),
        });
    }
    Ok(written)
}
