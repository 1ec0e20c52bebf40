//! `sylva bench`: the papers' result tables at their exact sizes, on the CPU and the GPU in
//! one run, with the paper's figure beside ours, a Markdown table, a JSON file and a plot.
//!
//! Tables: `song-t2`, `song-t3` (here), `akagi-t2` ([`crate::bench_akagi`]), `zioma-t6-1`
//! ([`crate::bench_zioma`]) and `skjermo` ([`crate::bench_skjermo`]).
//!
//! Timing: a warm-up, then repeated samples of several steps each (the count chosen so a
//! sample takes about a fifth of the time budget); the median and the spread (min–max) of
//! the samples are reported. GPU samples are timed with timestamp queries where the adapter
//! has them (the GPU's clock from the first pass of the sample to the end of the last,
//! [`sylva_gpu::timer::GpuTimer`]), otherwise by wall clock from submission to completion;
//! each rate says which (`clock`). Every row also states how close it runs to this
//! machine's memory bandwidth, measured by the bench itself (a parallel copy on the CPU, a
//! buffer copy on the GPU).

use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use plotters::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;
use sylva_core::methods::hsm::{Hsm, HsmLayout, HsmParams, SONG_TABLE_2, SONG_TABLE_3};
use sylva_core::species::SpeciesSource;
use sylva_core::wind::WindScene;

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

/// A timing: median and spread of the samples, in steps per second.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Rate {
    /// Median of the samples, steps/s.
    pub median: f64,
    /// Slowest sample, steps/s.
    pub min: f64,
    /// Fastest sample, steps/s.
    pub max: f64,
    /// Samples taken.
    pub samples: usize,
    /// Steps per sample.
    pub steps_per_sample: usize,
    /// How the samples were timed: `wall clock` or `timestamp queries`.
    pub clock: &'static str,
}

impl Rate {
    /// Milliseconds per step: [median, fastest, slowest].
    pub fn ms(&self) -> [f64; 3] {
        [1e3 / self.median, 1e3 / self.max, 1e3 / self.min]
    }
}

/// One row of a table.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// The paper's clusters.
    pub paper_clusters: usize,
    /// The paper's particles.
    pub paper_particles: usize,
    /// The paper's frames per second (GTX 580).
    pub paper_fps: f64,
    /// Our clusters.
    pub clusters: usize,
    /// Our particles.
    pub particles: usize,
    /// Bytes the four stages move per step (the GPU's passes).
    pub bytes_per_step: usize,
    /// Bytes the CPU's step moves (its fused pass runs over runs of particles that share
    /// their clusters, reading each cluster once per run).
    pub cpu_bytes_per_step: usize,
    /// CPU steps per second.
    pub cpu: Option<Rate>,
    /// GPU steps per second.
    pub gpu: Option<Rate>,
    /// CPU bytes per second over the measured CPU copy bandwidth.
    pub cpu_bandwidth_fraction: Option<f64>,
    /// GPU bytes per second over the measured GPU copy bandwidth.
    pub gpu_bandwidth_fraction: Option<f64>,
}

/// The machine a bench ran on.
#[derive(Debug, Clone, Serialize)]
pub struct Machine {
    /// CPU model name.
    pub cpu: String,
    /// Hardware threads available.
    pub cores: usize,
    /// rayon worker threads.
    pub threads: usize,
    /// GPU adapter, backend and driver (when the GPU was timed).
    pub gpu: Option<String>,
    /// Measured CPU copy bandwidth (read + write), bytes/s.
    pub cpu_bandwidth: f64,
    /// Measured GPU buffer-copy bandwidth (read + write), bytes/s.
    pub gpu_bandwidth: Option<f64>,
    /// How GPU work is timed: `timestamp queries` or `wall clock`.
    pub gpu_clock: Option<&'static str>,
    /// UTC time of the run.
    pub date: String,
    /// The command line.
    pub command: String,
}

/// One reproduced table.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// `song-t2` or `song-t3`.
    pub table: String,
    /// What the rows time.
    pub title: String,
    /// The machine.
    pub machine: Machine,
    /// The rows, smallest first.
    pub rows: Vec<Row>,
}

/// What every table's runner needs.
pub(crate) struct Env<'a> {
    /// Small sizes only.
    pub quick: bool,
    /// Time budget per measurement, s.
    pub budget: f64,
    /// Whether to time the CPU.
    pub time_cpu: bool,
    /// The GPU, when it is timed.
    pub ctx: Option<&'static sylva_gpu::GpuContext>,
    /// Where the files go.
    pub out_dir: &'a Path,
    /// The machine record.
    pub machine: &'a Machine,
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
    let machine = Machine {
        cpu: cpu_model(),
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        threads: rayon::current_num_threads(),
        gpu: ctx.map(|c| c.summary.to_string()),
        cpu_bandwidth: cpu_bandwidth(),
        gpu_bandwidth: match ctx {
            Some(c) => Some(gpu_bandwidth(c)?),
            None => None,
        },
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
    if let (Some(g), Some(b), Some(clock)) = (&machine.gpu, machine.gpu_bandwidth, machine.gpu_clock) {
        println!("GPU: {g}, copy bandwidth {:.1} GB/s, timed by {clock}", b / 1e9);
    }
    let env = Env { quick: args.quick, budget, time_cpu, ctx, out_dir: &args.out_dir, machine: &machine };
    std::fs::create_dir_all(&args.out_dir).with_context(|| format!("creating {}", args.out_dir.display()))?;
    let wind = WindScene::resolve("gusty")?;
    let (fields, waves) = wind.pack();
    let params = HsmParams::song_tables();
    let mut written = Vec::new();
    for table in tables {
        let (name, title, rows, copies) = match table {
            Table::SongT2 => ("song-t2", "Song et al. Table 2: one tree", &SONG_TABLE_2, 1),
            Table::SongT3 => ("song-t3", "Song et al. Table 3: ten trees", &SONG_TABLE_3, 10),
            Table::AkagiT2 => {
                written.extend(crate::bench_akagi::run(&env)?);
                continue;
            }
            Table::ZiomaT61 => {
                written.extend(crate::bench_zioma::run(&env)?);
                continue;
            }
            Table::Skjermo => {
                written.extend(crate::bench_skjermo::run(&env)?);
                continue;
            }
            Table::All => unreachable!("expanded above"),
        };
        let rows = if args.quick { &rows[..3] } else { &rows[..] };
        let bar = ProgressBar::new(rows.len() as u64).with_style(
            ProgressStyle::with_template("{msg:>10} [{bar:30}] {pos}/{len} rows, {elapsed}").expect("valid template"),
        );
        bar.set_message(name);
        let mut out = Vec::new();
        for &(paper_clusters, paper_particles, paper_fps) in rows {
            let one = HsmLayout::new(&tree, &params, Some(paper_clusters / copies))?;
            let layout = if copies > 1 { one.forest(copies, 2.0 * tree.height().max(1.0))? } else { one };
            let hsm = Hsm::from_layout(&tree, params, layout);
            let bytes = hsm.layout.bytes_per_step(params.fused);
            let cpu_bytes = hsm.cpu_bytes_per_step();
            let dt = 1.0 / 60.0;
            let cpu = time_cpu.then(|| {
                let mut state = hsm.rest_state();
                measure(budget, |n| {
                    for _ in 0..n {
                        hsm.step(&fields, &waves, &mut state, dt);
                    }
                    Ok(())
                })
            });
            let cpu = cpu.transpose()?;
            let gpu = match ctx {
                Some(c) => {
                    let mut g = sylva_gpu::hsm::GpuHsm::new(c, None, &hsm, &wind)?;
                    Some(measure_gpu(budget, c, |n| {
                        g.advance(c, &hsm, dt, n);
                        Ok(())
                    })?)
                }
                None => None,
            };
            let row = Row {
                paper_clusters,
                paper_particles,
                paper_fps,
                clusters: hsm.layout.cluster_count(),
                particles: hsm.layout.particle_count(),
                bytes_per_step: bytes,
                cpu_bytes_per_step: cpu_bytes,
                cpu_bandwidth_fraction: cpu.map(|r| r.median * cpu_bytes as f64 / machine.cpu_bandwidth),
                gpu_bandwidth_fraction: gpu.zip(machine.gpu_bandwidth).map(|(r, b)| r.median * bytes as f64 / b),
                cpu,
                gpu,
            };
            bar.suspend(|| println!("{}", row_line(&row)));
            out.push(row);
            bar.inc(1);
        }
        bar.finish_and_clear();
        let report = Report { table: name.into(), title: title.into(), machine: machine.clone(), rows: out };
        let md = args.out_dir.join(format!("{name}.md"));
        write_atomic(&md, markdown(&report).as_bytes())?;
        let json = args.out_dir.join(format!("{name}.json"));
        write_atomic(&json, serde_json::to_string_pretty(&report)?.as_bytes())?;
        let png = args.out_dir.join(format!("{name}.png"));
        plot(&report, &png)?;
        println!("{}", markdown(&report));
        written.extend([md, json, png]);
    }
    Ok(written)
}

/// Times `f(n)` (n steps) by wall clock: one warm-up call, a step count that makes a sample
/// about a fifth of `budget`, then samples until the budget is spent (at least 3, at most
/// 15).
pub(crate) fn measure(budget: f64, mut f: impl FnMut(usize) -> Result<()>) -> Result<Rate> {
    sample(budget, |n| {
        let t0 = Instant::now();
        f(n)?;
        Ok((t0.elapsed().as_secs_f64(), false))
    })
}

/// Times GPU work as [`measure`] does; `f(n)` submits n steps (it need not wait). With
/// timestamp queries a sample is the GPU's time from the first submission to the end of the
/// last; without them, wall clock from the first submission to completion.
pub(crate) fn measure_gpu(
    budget: f64,
    ctx: &sylva_gpu::GpuContext,
    mut f: impl FnMut(usize) -> Result<()>,
) -> Result<Rate> {
    let timer = sylva_gpu::timer::GpuTimer::new(ctx);
    sample(budget, |n| {
        ctx.wait()?;
        let t0 = Instant::now();
        if let Some(t) = &timer {
            t.start(ctx);
        }
        f(n)?;
        let stamped = match &timer {
            Some(t) => {
                t.stop(ctx);
                t.read(ctx)?
            }
            None => None,
        };
        ctx.wait()?;
        Ok(match stamped {
            Some(d) => (d.as_secs_f64(), true),
            None => (t0.elapsed().as_secs_f64(), false),
        })
    })
}

/// The sampling loop: `f(n)` runs n steps and returns (seconds, timed by timestamps).
fn sample(budget: f64, mut f: impl FnMut(usize) -> Result<(f64, bool)>) -> Result<Rate> {
    let one = f(1)?.0.max(1e-7);
    // A second probe with more steps, now that caches and pipelines are warm.
    let probe = ((budget / 20.0 / one) as usize).clamp(1, 100_000);
    let per = (f(probe)?.0 / probe as f64).max(1e-8);
    let n = ((budget / 5.0 / per) as usize).clamp(1, 1_000_000);
    let mut rates = Vec::new();
    let mut stamped = true;
    let start = Instant::now();
    while rates.len() < 3 || (start.elapsed().as_secs_f64() < budget && rates.len() < 15) {
        let (secs, s) = f(n)?;
        stamped &= s;
        rates.push(n as f64 / secs.max(1e-9));
    }
    rates.sort_by(f64::total_cmp);
    Ok(Rate {
        median: rates[rates.len() / 2],
        min: rates[0],
        max: rates[rates.len() - 1],
        samples: rates.len(),
        steps_per_sample: n,
        clock: if stamped { "timestamp queries" } else { "wall clock" },
    })
}

pub(crate) fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

/// Parallel copy of 64 MiB (best of 5): bytes read plus bytes written per second.
pub(crate) fn cpu_bandwidth() -> f64 {
    use rayon::prelude::*;
    let n = 16 << 20;
    let src = vec![1.0f32; n];
    let mut dst = vec![0.0f32; n];
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t0 = Instant::now();
        dst.par_chunks_mut(1 << 16).zip(src.par_chunks(1 << 16)).for_each(|(d, s)| d.copy_from_slice(s));
        best = best.min(t0.elapsed().as_secs_f64());
    }
    std::hint::black_box(&dst);
    2.0 * (n * 4) as f64 / best.max(1e-9)
}

/// Buffer-to-buffer copy of 64 MiB on the GPU (best of 5): bytes read plus written per second.
pub(crate) fn gpu_bandwidth(ctx: &sylva_gpu::GpuContext) -> Result<f64> {
    let bytes = 64u64 << 20;
    let make = |label| {
        ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes,
            usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    };
    let (a, b) = (make("bandwidth a"), make("bandwidth b"));
    let mut best = f64::INFINITY;
    for _ in 0..6 {
        let mut e = ctx.device.create_command_encoder(&Default::default());
        e.copy_buffer_to_buffer(&a, 0, &b, 0, bytes);
        ctx.wait()?;
        let t0 = Instant::now();
        ctx.queue.submit([e.finish()]);
        ctx.wait()?;
        best = best.min(t0.elapsed().as_secs_f64());
    }
    Ok(2.0 * bytes as f64 / best.max(1e-9))
}

pub(crate) fn rate_cell(r: Option<Rate>) -> String {
    r.map_or("–".into(), |r| format!("{:.0} ({:.0}–{:.0})", r.median, r.min, r.max))
}

fn ratio_cell(r: Option<Rate>, paper: f64) -> String {
    r.map_or("–".into(), |r| format!("{:.2}", r.median / paper))
}

fn frac_cell(f: Option<f64>) -> String {
    f.map_or("–".into(), |f| format!("{:.1} %", 100.0 * f))
}

fn row_line(r: &Row) -> String {
    format!(
        "{:>6} clusters {:>8} particles: CPU {} steps/s, GPU {} steps/s (paper {:.0})",
        r.clusters,
        r.particles,
        rate_cell(r.cpu),
        rate_cell(r.gpu),
        r.paper_fps
    )
}

/// The heading and machine paragraph every table's Markdown starts with.
pub(crate) fn markdown_head(title: &str, table: &str, m: &Machine) -> String {
    let mut s = format!("### {title} ({table})\n\n");
    s += &format!(
        "Machine: {} ({} threads of {} cores), CPU copy bandwidth {:.1} GB/s",
        m.cpu,
        m.threads,
        m.cores,
        m.cpu_bandwidth / 1e9
    );
    if let (Some(g), Some(b)) = (&m.gpu, m.gpu_bandwidth) {
        s +=
            &format!("; GPU {g}, copy bandwidth {:.1} GB/s, timed by {}", b / 1e9, m.gpu_clock.unwrap_or("wall clock"));
    }
    s += &format!(".\nDate {}. Command `{}`.\n\n", m.date, m.command);
    s
}

fn markdown(rep: &Report) -> String {
    let mut s = markdown_head(&rep.title, &rep.table, &rep.machine);
    s += "| paper clusters | paper particles | paper steps/s (GTX 580) | clusters | particles | CPU MB/step | CPU steps/s (median, min–max) | CPU / paper | CPU % of bandwidth | GPU MB/step | GPU steps/s | GPU / paper | GPU % of bandwidth | GPU / CPU |\n";
    s += "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    for r in &rep.rows {
        let gpu_cpu = match (r.gpu, r.cpu) {
            (Some(g), Some(c)) => format!("{:.2}", g.median / c.median),
            _ => "–".into(),
        };
        s += &format!(
            "| {} | {} | {:.0} | {} | {} | {:.2} | {} | {} | {} | {:.2} | {} | {} | {} | {} |\n",
            r.paper_clusters,
            r.paper_particles,
            r.paper_fps,
            r.clusters,
            r.particles,
            r.cpu_bytes_per_step as f64 / 1e6,
            rate_cell(r.cpu),
            ratio_cell(r.cpu, r.paper_fps),
            frac_cell(r.cpu_bandwidth_fraction),
            r.bytes_per_step as f64 / 1e6,
            rate_cell(r.gpu),
            ratio_cell(r.gpu, r.paper_fps),
            frac_cell(r.gpu_bandwidth_fraction),
            gpu_cpu
        );
    }
    s
}

/// Steps per second against particles, log–log: the paper, the CPU and the GPU.
fn plot(rep: &Report, path: &Path) -> Result<()> {
    plot_series(
        &format!("{} — steps per second", rep.title),
        "particles",
        "steps per second",
        vec![
            (
                "paper (GTX 580)",
                RGBColor(120, 120, 120),
                rep.rows.iter().map(|r| (r.paper_particles as f64, r.paper_fps)).collect(),
            ),
            (
                "CPU",
                RGBColor(200, 60, 40),
                rep.rows.iter().filter_map(|r| r.cpu.map(|c| (r.particles as f64, c.median))).collect(),
            ),
            (
                "GPU",
                RGBColor(40, 90, 200),
                rep.rows.iter().filter_map(|r| r.gpu.map(|g| (r.particles as f64, g.median))).collect(),
            ),
        ],
        path,
    )
}

/// A named, coloured series of (x, y) points.
pub(crate) type Series = (&'static str, RGBColor, Vec<(f64, f64)>);

/// A log–log line plot of `series`, written atomically to `path` (PNG).
pub(crate) fn plot_series(title: &str, x_desc: &str, y_desc: &str, series: Vec<Series>, path: &Path) -> Result<()> {
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, crate::wind_cmd::FONT);
    let tmp = path.with_extension("tmp.png");
    {
        let root = BitMapBackend::new(&tmp, (900, 600)).into_drawing_area();
        root.fill(&WHITE)?;
        let pts = series.iter().flat_map(|s| s.2.iter().copied());
        let (mut x_lo, mut x_hi, mut y_lo, mut y_hi) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
        for (x, y) in pts {
            (x_lo, x_hi, y_lo, y_hi) = (x_lo.min(x), x_hi.max(x), y_lo.min(y), y_hi.max(y));
        }
        let (x_lo, x_hi) = (x_lo.min(x_hi).max(1e-9) * 0.7, x_hi.max(1.0) * 1.4);
        let (y_lo, y_hi) = (y_lo.min(y_hi).max(1e-6) * 0.5, y_hi.max(1e-3) * 2.0);
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d((x_lo..x_hi).log_scale(), (y_lo..y_hi).log_scale())?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| if *y >= 10.0 { format!("{y:.0}") } else { format!("{y:.2}") })
            .draw()?;
        for (label, color, pts) in series {
            if pts.is_empty() {
                continue;
            }
            chart
                .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))?;
        }
        chart.configure_series_labels().border_style(BLACK).background_style(WHITE.mix(0.9)).draw()?;
        root.present()?;
    }
    std::fs::rename(&tmp, path).with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = path.with_extension(format!("{}.tmp", path.extension().and_then(|e| e.to_str()).unwrap_or("out")));
    std::fs::write(&tmp, bytes).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("writing {}", path.display()))
}
