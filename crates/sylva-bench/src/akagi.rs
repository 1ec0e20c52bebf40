//! `sylva bench akagi-t2`: Akagi & Kitajima's Table 2 — regenerating the whole mesh of a
//! forest every frame, 108,808 … 4,109,056 triangles, on one CPU thread, on every CPU core
//! and on the GPU, with the paper's figures beside ours.
//!
//! Each row meshes a forest of whole trees (Quaking Aspens with different seeds, topped up
//! with palms) whose triangle count first reaches the paper's; the actual count is
//! reported. A frame is every bark and leaf vertex of the forest from a wind pose (Zioma at
//! t = 2 s), as `sylva render` does it. GPU frames are the two mesh kernels, several frames
//! per submission, wall clock to completion. The paper's figures include drawing (about
//! 0.1 % of its CPU time); ours time generation only.

use crate::harness::{
    COMMANDS_HEADING, Commands, Env, Machine, commands_cell, count_gpu, markdown_head, measure, measure_gpu,
    write_atomic,
};
use crate::plot::{Series, plot_series};
use crate::tables::AKAGI_TABLE_2;
use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use plotters::style::RGBColor;
use serde::Serialize;
use std::mem::size_of;
use std::path::PathBuf;
use sylva_core::Tree;
use sylva_core::mesh::{MeshLayout, MeshParams, RawRing, RawVertex};
use sylva_core::methods::zioma::{Zioma, ZiomaParams};
use sylva_core::model::{RawLeaf, RawSegment};
use sylva_core::pose::seam_buffers;
use sylva_core::species::SpeciesSource;
use sylva_core::wind::WindScene;
use sylva_gpu::mesh::MeshParts;

/// One row.
#[derive(Debug, Clone, Serialize)]
pub struct AkagiRow {
    /// The paper's polygons.
    pub paper_triangles: usize,
    /// The paper's CPU (one thread) ms per frame.
    pub paper_cpu_ms: f64,
    /// The paper's GPU ms per frame.
    pub paper_gpu_ms: f64,
    /// Our triangles.
    pub triangles: usize,
    /// Our vertices.
    pub vertices: usize,
    /// Trees in the forest.
    pub trees: usize,
    /// Bytes written and read per frame (vertices out, rings, leaves and pose in).
    pub bytes_per_frame: usize,
    /// `bytes_per_frame` over the triangles.
    pub bytes_per_triangle: f64,
    /// CPU one thread, ms per frame (median, min, max).
    pub cpu_one_ms: Option<[f64; 3]>,
    /// CPU all threads, ms per frame.
    pub cpu_all_ms: Option<[f64; 3]>,
    /// GPU, ms per frame.
    pub gpu_ms: Option<[f64; 3]>,
    /// GPU, ms per frame, each invocation writing its run of vertices directly instead of
    /// the workgroup's runs together (`GpuMesh::set_staged(false)`).
    pub gpu_direct_ms: Option<[f64; 3]>,
    /// The GPU's commands per frame.
    pub gpu_commands: Option<Commands>,
    /// GPU ms per frame of each kernel alone (`GpuMesh::set_parts`, runs staged), medians:
    /// `mesh_tubes`, `mesh_detail`, `mesh_leaves`.
    pub gpu_kernel_ms: Option<[f64; 3]>,
    /// CPU (all threads) bytes/s over the measured copy bandwidth.
    pub cpu_bandwidth_fraction: Option<f64>,
    /// GPU bytes/s over the measured copy bandwidth.
    pub gpu_bandwidth_fraction: Option<f64>,
}

pub(crate) fn cell(v: Option<[f64; 3]>) -> String {
    v.map_or("–".into(), |[m, lo, hi]| format!("{m:.2} ({lo:.2}–{hi:.2})"))
}

/// A table's JSON file: its name, the machine and the rows.
#[derive(Serialize)]
pub(crate) struct Report<'a, R: Serialize> {
    /// The table's name on the command line.
    pub table: &'static str,
    /// Where and when it ran.
    pub machine: &'a Machine,
    /// The rows, smallest first.
    pub rows: &'a [R],
}

/// Runs the table; returns the files written.
pub(crate) fn run(env: &Env<'_>) -> Result<Vec<PathBuf>> {
    let (quick, budget, time_cpu, ctx) = (env.quick, env.budget, env.time_cpu, env.ctx);
    let rows = if quick { &AKAGI_TABLE_2[..3] } else { &AKAGI_TABLE_2[..] };
    let wind = WindScene::resolve("gusty")?;
    let (fields, waves) = wind.pack();
    let params = MeshParams::default();
    // A pool of trees, generated on demand: aspens by seed, palms to top up.
    let aspen = SpeciesSource::resolve("quaking_aspen")?;
    let palm = SpeciesSource::resolve("palm")?;
    let mut pool: Vec<(Tree, MeshLayout)> = Vec::new();
    let mut palms: Vec<(Tree, MeshLayout)> = Vec::new();
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let (cpu_bw, gpu_bw) = (env.machine.cpu_bandwidth, env.machine.gpu_bandwidth);
    let bar = ProgressBar::new(rows.len() as u64).with_style(
        ProgressStyle::with_template("{msg:>10} [{bar:30}] {pos}/{len} rows, {elapsed}").expect("valid template"),
    );
    bar.set_message("akagi-t2");
    let mut out = Vec::new();
    for &(paper_triangles, paper_cpu_s, paper_gpu_s) in rows {
        // The forest: whole aspens while they fit, then palms until the count is reached.
        let mut chosen: Vec<(bool, usize)> = Vec::new();
        let mut total = 0usize;
        let aspen_tris = {
            if pool.is_empty() {
                let t = aspen.generate(1, &Default::default(), None)?;
                let l = MeshLayout::new(&t, params)?;
                pool.push((t, l));
            }
            pool[0].1.triangle_count()
        };
        while total + aspen_tris <= paper_triangles {
            let k = chosen.iter().filter(|c| c.0).count();
            if k == pool.len() {
                let t = aspen.generate(k as u64 + 1, &Default::default(), None)?;
                let l = MeshLayout::new(&t, params)?;
                pool.push((t, l));
            }
            total += pool[k].1.triangle_count();
            chosen.push((true, k));
        }
        while total < paper_triangles {
            let k = chosen.iter().filter(|c| !c.0).count();
            if k == palms.len() {
                let t = palm.generate(k as u64 + 1, &Default::default(), None)?;
                let l = MeshLayout::new(&t, params)?;
                palms.push((t, l));
            }
            total += palms[k].1.triangle_count();
            chosen.push((false, k));
        }
        let members: Vec<&(Tree, MeshLayout)> =
            chosen.iter().map(|&(a, k)| if a { &pool[k] } else { &palms[k] }).collect();
        let layout = MeshLayout::concat(&members.iter().map(|m| &m.1).collect::<Vec<_>>())?;
        let (mut joint, mut acc) = (Vec::new(), Vec::new());
        for (t, _) in &members {
            let delta = Zioma::new(t, ZiomaParams::default()).rotations_packed(t, &fields, &waves, 2.0);
            let (j, a) = seam_buffers(t, &delta);
            joint.extend(j);
            acc.extend(a);
        }
        let vertices = layout.tube_vertex_count() + layout.leaf_vertex_count();
        let bytes = vertices * size_of::<RawVertex>()
            + layout.rings.len() * size_of::<RawRing>()
            + layout.leaves.len() * size_of::<RawLeaf>()
            + layout.segments.len() * (size_of::<RawSegment>() + 2 * size_of::<[f32; 4]>());
        let info = layout.info();
        let mut tubes = vec![bytemuck::Zeroable::zeroed(); layout.tube_vertex_count()];
        let mut leaves = vec![bytemuck::Zeroable::zeroed(); layout.leaf_vertex_count()];
        let rim = layout.leaf_rim_table();
        let mut frame = || {
            sylva_core::mesh::mesh_tubes(&info, &layout.rings, &layout.segments, &joint, &acc, &mut tubes);
            sylva_core::mesh::mesh_leaves(
                &info,
                &layout.leaves,
                &layout.segments,
                &joint,
                &acc,
                &[],
                &rim,
                &mut leaves,
            );
        };
        let (cpu_one, cpu_all) = if time_cpu {
            let one = one_thread.install(|| {
                measure(budget, |n| {
                    (0..n).for_each(|_| frame());
                    Ok(())
                })
            })?;
            let all = measure(budget, |n| {
                (0..n).for_each(|_| frame());
                Ok(())
            })?;
            (Some(one), Some(all))
        } else {
            (None, None)
        };
        let (gpu, gpu_direct, gpu_commands, gpu_kernel_ms) = match ctx {
            Some(c) => {
                let mut mesh = sylva_gpu::mesh::GpuMesh::new(c, &layout)?;
                let jb = sylva_gpu::kernel::upload(c, "bench joints", &joint)?;
                let ab = sylva_gpu::kernel::upload(c, "bench rotations", &acc)?;
                let time = |mesh: &sylva_gpu::mesh::GpuMesh| -> Result<_> {
                    let mut frames = |n| {
                        let mut e = c.device.create_command_encoder(&Default::default());
                        for _ in 0..n {
                            mesh.record(c, &mut e, &jb, &ab);
                        }
                        c.submit([e.finish()]);
                        Ok(())
                    };
                    Ok((measure_gpu(budget, c, &mut frames)?, count_gpu(c, &mut frames)?))
                };
                let (staged, commands) = time(&mesh)?;
                mesh.set_staged(c, false);
                let (direct, _) = time(&mesh)?;
                mesh.set_staged(c, true);
                let mut kernels = [0.0; 3];
                for (k, ms) in kernels.iter_mut().enumerate() {
                    mesh.set_parts(MeshParts { tubes: k == 0, detail: k == 1, leaves: k == 2 });
                    *ms = time(&mesh)?.0.ms()[0];
                }
                (Some(staged), Some(direct), Some(commands), Some(kernels))
            }
            None => (None, None, None, None),
        };
        let row = AkagiRow {
            paper_triangles,
            paper_cpu_ms: paper_cpu_s,
            paper_gpu_ms: paper_gpu_s,
            triangles: layout.triangle_count(),
            vertices,
            trees: members.len(),
            bytes_per_frame: bytes,
            bytes_per_triangle: bytes as f64 / layout.triangle_count().max(1) as f64,
            cpu_one_ms: cpu_one.map(|r| r.ms()),
            cpu_all_ms: cpu_all.map(|r| r.ms()),
            gpu_ms: gpu.map(|r| r.ms()),
            gpu_direct_ms: gpu_direct.map(|r| r.ms()),
            gpu_commands,
            gpu_kernel_ms,
            cpu_bandwidth_fraction: cpu_all.map(|r| r.median * bytes as f64 / cpu_bw),
            gpu_bandwidth_fraction: gpu.zip(gpu_bw).map(|(r, b)| r.median * bytes as f64 / b),
        };
        bar.suspend(|| {
            println!(
                "{:>9} triangles ({} trees): CPU 1 thread {} ms, all threads {} ms, GPU {} ms (paper CPU {:.2}, GPU {:.3}){}",
                row.triangles,
                row.trees,
                cell(row.cpu_one_ms),
                cell(row.cpu_all_ms),
                cell(row.gpu_ms),
                row.paper_cpu_ms,
                row.paper_gpu_ms,
                row.gpu_kernel_ms.map_or(String::new(), |[t, d, l]| {
                    let i = layout.info();
                    format!(
                        "; alone: {} rings {t:.3} ms, {} midpoints {d:.3} ms, {} leaves {l:.3} ms",
                        i.rings, i.details, i.leaves
                    )
                })
            )
        });
        out.push(row);
        bar.inc(1);
    }
    bar.finish_and_clear();

    let mut md = markdown_head("Akagi & Kitajima Table 2: mesh regeneration per frame", "akagi-t2", env.machine);
    md += "ms per frame, median (min–max). The paper: Core2 QX9650 one thread, GeForce GTX 280, generation + drawing.\n\n";
    md += &format!(
        "| paper triangles | paper CPU ms | paper GPU ms | paper CPU/GPU | triangles | trees | MB/frame | B/triangle | CPU 1 thread ms | CPU all threads ms | CPU % of bandwidth | GPU ms | GPU ms, runs direct | GPU ms, tubes / detail / leaves alone | GPU % of bandwidth | CPU 1 thread / GPU | CPU all / GPU | {} |\n",
        COMMANDS_HEADING.replace("step", "frame")
    );
    md += "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    let ratio = |a: Option<[f64; 3]>, b: Option<[f64; 3]>| match (a, b) {
        (Some(a), Some(b)) => format!("{:.1}", a[0] / b[0]),
        _ => "–".into(),
    };
    for r in &out {
        md += &format!(
            "| {} | {:.2} | {:.3} | {:.0} | {} | {} | {:.1} | {:.1} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.paper_triangles,
            r.paper_cpu_ms,
            r.paper_gpu_ms,
            r.paper_cpu_ms / r.paper_gpu_ms,
            r.triangles,
            r.trees,
            r.bytes_per_frame as f64 / 1e6,
            r.bytes_per_triangle,
            cell(r.cpu_one_ms),
            cell(r.cpu_all_ms),
            r.cpu_bandwidth_fraction.map_or("–".into(), |f| format!("{:.1} %", 100.0 * f)),
            cell(r.gpu_ms),
            cell(r.gpu_direct_ms),
            r.gpu_kernel_ms.map_or("–".into(), |[t, d, l]| format!("{t:.3} / {d:.3} / {l:.3}")),
            r.gpu_bandwidth_fraction.map_or("–".into(), |f| format!("{:.1} %", 100.0 * f)),
            ratio(r.cpu_one_ms, r.gpu_ms),
            ratio(r.cpu_all_ms, r.gpu_ms),
            commands_cell(r.gpu_commands),
        );
    }
    let json = serde_json::to_string_pretty(&Report { table: "akagi-t2", machine: env.machine, rows: &out })?;
    let out_dir = env.out_dir;
    let (md_path, json_path, png_path) =
        (out_dir.join("akagi-t2.md"), out_dir.join("akagi-t2.json"), out_dir.join("akagi-t2.png"));
    write_atomic(&md_path, md.as_bytes())?;
    write_atomic(&json_path, json.as_bytes())?;
    let pick = |f: fn(&AkagiRow) -> Option<f64>| -> Vec<(f64, f64)> {
        out.iter().filter_map(|r| f(r).map(|y| (r.triangles as f64, y))).collect()
    };
    let series: Vec<Series> = vec![
        (
            "paper CPU (1 thread)",
            RGBColor(170, 170, 170),
            out.iter().map(|r| (r.paper_triangles as f64, r.paper_cpu_ms)).collect(),
        ),
        (
            "paper GPU (GTX 280)",
            RGBColor(90, 90, 90),
            out.iter().map(|r| (r.paper_triangles as f64, r.paper_gpu_ms)).collect(),
        ),
        ("CPU 1 thread", RGBColor(230, 140, 60), pick(|r| r.cpu_one_ms.map(|v| v[0]))),
        ("CPU all threads", RGBColor(200, 60, 40), pick(|r| r.cpu_all_ms.map(|v| v[0]))),
        ("GPU", RGBColor(40, 90, 200), pick(|r| r.gpu_ms.map(|v| v[0]))),
    ];
    plot_series("Akagi & Kitajima Table 2 — mesh regeneration", "triangles", "ms per frame", series, &png_path)
        .context("plotting akagi-t2")?;
    println!("{md}");
    Ok(vec![md_path, json_path, png_path])
}
