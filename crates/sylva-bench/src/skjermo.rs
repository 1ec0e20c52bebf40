//! `sylva bench skjermo`: Skjermo's results — the wind update of 65,536 and 262,144 branches
//! per second (GeForce 7900 GTX: 600 and 180 updates/s).
//!
//! The trees are binary trees of one-segment stems (16 and 18 L-system iterations: 65,535
//! and 262,143 stems). An update is the step the paper counts: every stem re-attaches to
//! its parent's curve from the previous step, samples the wind and bends P2 and P3 (eqs.
//! 15–17), the two state buffers ping-ponging; no pose, no mesh. The wind is the paper's
//! setting, four sines (eqs. 11–14). CPU rows time the fast path (sixteen stems per lane
//! group, rayon) and the reference kernel (one stem at a time, the WGSL's twin); GPU rows
//! `skjermo.wgsl`, one dispatch per update, a sample's updates in one submission. `--quick`
//! times 4,095 and 16,383 branches instead (no paper figure).

use crate::akagi::Report;
use crate::harness::{
    COMMANDS_HEADING, Commands, Env, Rate, commands_cell, count_gpu, markdown_head, measure, measure_gpu,
    rate_cell as rate, write_atomic,
};
use crate::plot::{Series, plot_series};
use crate::tables::{BENCH_BINARY_TREE, BENCH_FOUR_SINES, SKJERMO_FIGURE};
use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use plotters::style::RGBColor;
use serde::Serialize;
use std::path::PathBuf;
use sylva_core::methods::Method;
use sylva_core::methods::skjermo::lanes::{OscLanes, StateLanes, StemLanes, SwayLanes};
use sylva_core::methods::skjermo::{RawSkjermoState, RawSkjermoStem, Skjermo, SkjermoParams};
use sylva_core::wind::WindScene;
use sylva_core::{Grammar, LSystemOptions};

/// One row.
#[derive(Debug, Clone, Serialize)]
pub struct SkjermoRow {
    /// The paper's branches (`None` for the quick sizes).
    pub paper_branches: Option<usize>,
    /// The paper's updates per second.
    pub paper_updates_per_s: Option<f64>,
    /// Our branches (stems).
    pub branches: usize,
    /// Bytes read and written per update by the GPU kernel and the CPU reference (stem
    /// constants and state in, state out).
    pub bytes_per_update: usize,
    /// The same for the CPU fast path, whose lane groups hold fewer constants per stem.
    pub cpu_bytes_per_update: usize,
    /// CPU fast path, updates/s.
    pub cpu: Option<Rate>,
    /// CPU fast path with the published form (the bend following the wind at once, no
    /// reconfiguration), updates/s: what the second-order bend costs.
    pub cpu_published: Option<Rate>,
    /// CPU reference kernel, updates/s.
    pub cpu_reference: Option<Rate>,
    /// GPU, updates/s.
    pub gpu: Option<Rate>,
    /// The GPU's commands per update.
    pub gpu_commands: Option<Commands>,
    /// CPU bytes/s over the measured copy bandwidth.
    pub cpu_bandwidth_fraction: Option<f64>,
    /// GPU bytes/s over the measured copy bandwidth.
    pub gpu_bandwidth_fraction: Option<f64>,
}

/// Runs the table; returns the files written.
pub(crate) fn run(env: &Env<'_>) -> Result<Vec<PathBuf>> {
    let sizes: Vec<(u32, Option<(usize, f64)>)> = if env.quick {
        vec![(12, None), (14, None)]
    } else {
        vec![(16, Some(SKJERMO_FIGURE[0])), (18, Some(SKJERMO_FIGURE[1]))]
    };
    let wind = WindScene::from_toml(BENCH_FOUR_SINES, "four sines")?;
    let (fields, waves) = wind.pack();
    let grammar = Grammar::parse(BENCH_BINARY_TREE, "binary.lsys")?;
    let bar = ProgressBar::new(sizes.len() as u64).with_style(
        ProgressStyle::with_template("{msg:>10} [{bar:30}] {pos}/{len} rows, {elapsed}").expect("valid template"),
    );
    bar.set_message("skjermo");
    let dt = 1.0 / 60.0;
    let mut out = Vec::new();
    for (iterations, paper) in sizes {
        let tree = grammar.generate(&LSystemOptions { seed: 1, iterations: Some(iterations), ..Default::default() })?;
        let m = Skjermo::new(&tree, SkjermoParams::default());
        let n = tree.stems.len();
        // Per stem: its constants and its and its parent's previous state read, its next
        // state written; on the CPU also its bend oscillator's coefficients read and its
        // oscillator read and written in place.
        let bytes = n * (std::mem::size_of::<RawSkjermoStem>() + 3 * std::mem::size_of::<RawSkjermoState>());
        let cpu_bytes = m.lanes.len()
            * (std::mem::size_of::<StemLanes>()
                + std::mem::size_of::<OscLanes>()
                + 3 * std::mem::size_of::<StateLanes>()
                + 2 * std::mem::size_of::<SwayLanes>());
        let (cpu, cpu_published, cpu_reference) = if env.time_cpu {
            let mut state = m.rest_state(&tree);
            let fast = measure(env.budget, |k| {
                for _ in 0..k {
                    m.step_stems(&fields, &waves, &mut state, dt);
                }
                Ok(())
            })?;
            let published =
                Skjermo::new(&tree, SkjermoParams { dynamics: false, vogel_exponent: 0.0, ..SkjermoParams::default() });
            let mut state = published.rest_state(&tree);
            let published = measure(env.budget, |k| {
                for _ in 0..k {
                    published.step_stems(&fields, &waves, &mut state, dt);
                }
                Ok(())
            })?;
            let mut state = m.rest_state(&tree);
            let reference = measure(env.budget, |k| {
                for _ in 0..k {
                    m.step_reference(&fields, &waves, &mut state, dt);
                }
                Ok(())
            })?;
            (Some(fast), Some(published), Some(reference))
        } else {
            (None, None, None)
        };
        let (gpu, gpu_commands) = match env.ctx {
            Some(c) => {
                let mut g = sylva_gpu::methods::skjermo::GpuSkjermo::new(
                    c,
                    std::sync::Arc::new(tree.clone()),
                    &m,
                    &sylva_gpu::wind::GpuWind::from_scene(c, &wind)?,
                )?;
                // A sample's updates in one submission, as a frame's substeps would be.
                let mut updates = |k| {
                    g.advance_steps(c, dt, k, false);
                    Ok(())
                };
                (Some(measure_gpu(env.budget, c, &mut updates)?), Some(count_gpu(c, &mut updates)?))
            }
            None => (None, None),
        };
        let row = SkjermoRow {
            paper_branches: paper.map(|p| p.0),
            paper_updates_per_s: paper.map(|p| p.1),
            branches: n,
            bytes_per_update: bytes,
            cpu_bytes_per_update: cpu_bytes,
            cpu_bandwidth_fraction: cpu.map(|r| r.median * cpu_bytes as f64 / env.machine.cpu_bandwidth),
            gpu_bandwidth_fraction: gpu.zip(env.machine.gpu_bandwidth).map(|(r, b)| r.median * bytes as f64 / b),
            cpu,
            cpu_published,
            cpu_reference,
            gpu,
            gpu_commands,
        };
        bar.suspend(|| {
            println!(
                "{:>7} branches: CPU {} updates/s (reference kernel {}), GPU {} updates/s{}",
                row.branches,
                rate(row.cpu),
                rate(row.cpu_reference),
                rate(row.gpu),
                row.paper_updates_per_s.map_or(String::new(), |p| format!(" (paper {p:.0})"))
            )
        });
        out.push(row);
        bar.inc(1);
    }
    bar.finish_and_clear();

    let mut md = markdown_head("Skjermo: branches updated per second", "skjermo", env.machine);
    md += &format!(
        "Updates per second, median (slowest–fastest). Wind: four sines (the paper's setting). The paper: \
         GeForce 7900 GTX, the wind animation shader alone. MB/update: stem constants and state read, state \
         written; the CPU fast path's lane groups hold {} bytes of constants per stem, the GPU's (and the \
         reference kernel's) records {}. Over 100 % of bandwidth: part of the working set stays in cache. \
         Published form: the fast path with eq. 16 as printed (the bend follows the wind at once, no \
         reconfiguration), against the default second-order bend.\n\n",
        std::mem::size_of::<StemLanes>() / sylva_core::methods::skjermo::lanes::LANES,
        std::mem::size_of::<RawSkjermoStem>()
    );
    md += &format!(
        "| paper branches | paper updates/s | branches | MB/update (CPU / GPU) | CPU updates/s | CPU, published form | CPU / published | CPU reference kernel | CPU / paper | CPU % of bandwidth | GPU updates/s | GPU / paper | GPU % of bandwidth | GPU / CPU | {} |\n",
        COMMANDS_HEADING.replace("step", "update")
    );
    md +=
        "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    let over = |r: Option<Rate>, p: Option<f64>| match (r, p) {
        (Some(r), Some(p)) => format!("{:.2}", r.median / p),
        _ => "–".into(),
    };
    let pct = |f: Option<f64>| f.map_or("–".into(), |f| format!("{:.1} %", 100.0 * f));
    for r in &out {
        md += &format!(
            "| {} | {} | {} | {:.1} / {:.1} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.paper_branches.map_or("–".into(), |b| b.to_string()),
            r.paper_updates_per_s.map_or("–".into(), |p| format!("{p:.0}")),
            r.branches,
            r.cpu_bytes_per_update as f64 / 1e6,
            r.bytes_per_update as f64 / 1e6,
            rate(r.cpu),
            rate(r.cpu_published),
            over(r.cpu, r.cpu_published.map(|p| p.median)),
            rate(r.cpu_reference),
            over(r.cpu, r.paper_updates_per_s),
            pct(r.cpu_bandwidth_fraction),
            rate(r.gpu),
            over(r.gpu, r.paper_updates_per_s),
            pct(r.gpu_bandwidth_fraction),
            match (r.gpu, r.cpu) {
                (Some(g), Some(c)) => format!("{:.2}", g.median / c.median),
                _ => "–".into(),
            },
            commands_cell(r.gpu_commands),
        );
    }
    let json = serde_json::to_string_pretty(&Report { table: "skjermo", machine: env.machine, rows: &out })?;
    let (md_path, json_path, png_path) =
        (env.out_dir.join("skjermo.md"), env.out_dir.join("skjermo.json"), env.out_dir.join("skjermo.png"));
    write_atomic(&md_path, md.as_bytes())?;
    write_atomic(&json_path, json.as_bytes())?;
    let pick = |f: fn(&SkjermoRow) -> Option<Rate>| -> Vec<(f64, f64)> {
        out.iter().filter_map(|r| f(r).map(|y| (r.branches as f64, y.median))).collect()
    };
    let series: Vec<Series> = vec![
        (
            "paper (7900 GTX)",
            RGBColor(120, 120, 120),
            out.iter()
                .filter_map(|r| r.paper_branches.zip(r.paper_updates_per_s).map(|(b, p)| (b as f64, p)))
                .collect(),
        ),
        ("CPU", RGBColor(200, 60, 40), pick(|r| r.cpu)),
        ("CPU reference kernel", RGBColor(230, 140, 60), pick(|r| r.cpu_reference)),
        ("GPU", RGBColor(40, 90, 200), pick(|r| r.gpu)),
    ];
    plot_series("Skjermo — branches updated per second", "branches", "updates per second", series, &png_path)
        .context("plotting skjermo")?;
    println!("{md}");
    Ok(vec![md_path, json_path, png_path])
}
