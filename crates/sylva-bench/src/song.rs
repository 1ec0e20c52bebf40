//! Song et al.'s Tables 2 and 3: hierarchical shape matching steps per second against the
//! number of clusters, one tree and ten, on the CPU and the GPU.

use crate::harness::{
    COMMANDS_HEADING, Commands, Env, Machine, Rate, commands_cell, count_gpu, frac_cell, markdown_head, measure,
    measure_gpu, rate_cell, ratio_cell, write_atomic,
};
use crate::plot::plot_series;
use crate::tables::{SONG_TABLE_2, SONG_TABLE_3};
use anyhow::Result;
use indicatif::{ProgressBar, ProgressStyle};
use plotters::style::RGBColor;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::methods::hsm::{Hsm, HsmLayout, HsmParams};
use sylva_core::wind::WindScene;
use sylva_gpu::wind::GpuWind;

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
    /// The GPU's commands per step.
    pub gpu_commands: Option<Commands>,
    /// CPU bytes per second over the measured CPU copy bandwidth.
    pub cpu_bandwidth_fraction: Option<f64>,
    /// GPU bytes per second over the measured GPU copy bandwidth.
    pub gpu_bandwidth_fraction: Option<f64>,
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

/// Table 2 (`copies` = 1) or Table 3 (10) on `tree`'s clusters.
pub fn run(env: &Env<'_>, tree: &Tree, table3: bool) -> Result<Vec<PathBuf>> {
    let (name, title, rows, copies) = if table3 {
        ("song-t3", "Song et al. Table 3: ten trees", &SONG_TABLE_3, 10)
    } else {
        ("song-t2", "Song et al. Table 2: one tree", &SONG_TABLE_2, 1)
    };
    let wind = WindScene::resolve("gusty")?;
    let packed = wind.packed();
    let params = HsmParams::song_tables();
    let rows = if env.quick { &rows[..3] } else { &rows[..] };
    let bar = ProgressBar::new(rows.len() as u64).with_style(
        ProgressStyle::with_template("{msg:>10} [{bar:30}] {pos}/{len} rows, {elapsed}").expect("valid template"),
    );
    bar.set_message(name);
    let mut out = Vec::new();
    for &(paper_clusters, paper_particles, paper_fps) in rows {
        let one = HsmLayout::new(tree, &params, Some(paper_clusters / copies))?;
        let layout = if copies > 1 { one.forest(copies, 2.0 * tree.height().max(1.0))? } else { one };
        let hsm = Arc::new(Hsm::from_layout(tree, params, layout));
        let bytes = hsm.layout.bytes_per_step(params.fused);
        let cpu_bytes = hsm.cpu_bytes_per_step();
        let dt = 1.0 / 60.0;
        let cpu = env.time_cpu.then(|| {
            let mut state = hsm.state_at_rest();
            measure(env.budget, |n| {
                for _ in 0..n {
                    hsm.step_packed(&packed.fields, &packed.waves, &mut state, dt);
                }
                Ok(())
            })
        });
        let cpu = cpu.transpose()?;
        let (gpu, gpu_commands) = match env.ctx {
            Some(c) => {
                let mut g =
                    sylva_gpu::methods::hsm::GpuHsm::new(c, None, hsm.clone(), &GpuWind::from_scene(c, &wind)?)?;
                let mut steps = |n| {
                    g.advance_steps(c, dt, n);
                    Ok(())
                };
                (Some(measure_gpu(env.budget, c, &mut steps)?), Some(count_gpu(c, &mut steps)?))
            }
            None => (None, None),
        };
        let machine = env.machine;
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
            gpu_commands,
        };
        bar.suspend(|| println!("{}", row_line(&row)));
        out.push(row);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let report = Report { table: name.into(), title: title.into(), machine: env.machine.clone(), rows: out };
    let md = env.out_dir.join(format!("{name}.md"));
    write_atomic(&md, markdown(&report).as_bytes())?;
    let json = env.out_dir.join(format!("{name}.json"));
    write_atomic(&json, serde_json::to_string_pretty(&report)?.as_bytes())?;
    let png = env.out_dir.join(format!("{name}.png"));
    plot(&report, &png)?;
    println!("{}", markdown(&report));
    Ok(vec![md, json, png])
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

fn markdown(rep: &Report) -> String {
    let mut s = markdown_head(&rep.title, &rep.table, &rep.machine);
    s += &format!(
        "| paper clusters | paper particles | paper steps/s (GTX 580) | clusters | particles | CPU MB/step | CPU steps/s (median, min–max) | CPU / paper | CPU % of bandwidth | GPU MB/step | GPU steps/s | GPU / paper | GPU % of bandwidth | GPU / CPU | {COMMANDS_HEADING} |\n"
    );
    s += "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    for r in &rep.rows {
        let gpu_cpu = match (r.gpu, r.cpu) {
            (Some(g), Some(c)) => format!("{:.2}", g.median / c.median),
            _ => "–".into(),
        };
        s += &format!(
            "| {} | {} | {:.0} | {} | {} | {:.2} | {} | {} | {} | {:.2} | {} | {} | {} | {} | {} |\n",
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
            gpu_cpu,
            commands_cell(r.gpu_commands),
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
