//! `sylva bench zioma-t6-1`: Zioma's Table 6-1 — 30 … 1,000 instances of an 80-branch tree,
//! every instance posed by the procedural wind and skinned (§6.5) every frame.
//!
//! The tree is a trunk and 79 side branches of four segments (395 segments), meshed as
//! 8-sided tubes with one cross-section per segment: 4,275 skinned vertices per instance
//! against the paper's 4,617. Each instance has its own position, heading, phase and trunk
//! seed ([`ZiomaInstance::grid`]). Per row:
//! - **pose**: every instance's branch rotations and forward kinematics (CPU: rayon; GPU: one
//!   dispatch over all instances' segments and one forward-kinematics pass);
//! - **frame**: pose and two-bone skinning of every instance's copy of the rest mesh — what
//!   the paper's DirectX columns measure — at SLOD3 (trunk and branches);
//! - **SLOD2 frame**: the same with the trunk alone simulated ([`Lod::TrunkOnly`]), the
//!   paper's DirectX 10 SLOD2 column;
//! - **skinning only**: skinning from a fixed pose, the paper's "two-bone skinning without
//!   branch simulation" column.

use crate::akagi::{Report, cell};
use crate::harness::{
    COMMANDS_HEADING, Commands, Env, commands_cell, count_gpu, markdown_head, measure, measure_gpu, write_atomic,
};
use crate::plot::{Series, plot_series};
use crate::tables::ZIOMA_TABLE_6_1;
use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use plotters::style::RGBColor;
use serde::Serialize;
use std::path::PathBuf;
use sylva_core::mesh::{MeshLayout, MeshParams, RawVertex, SkinLayout};
use sylva_core::methods::zioma::{Lod, Zioma, ZiomaInstance, ZiomaParams};
use sylva_core::pose::{Pose, seam_buffers};
use sylva_core::wind::WindScene;
use sylva_core::{Grammar, LSystemOptions, Tree};
use sylva_gpu::methods::GpuAnimator;

/// The 80-branch tree: a trunk of 80 segments and 79 side branches of four segments.
pub const EIGHTY_BRANCHES: &str =
    "axiom: !(0.3)T(79)\nT(n) : n > 0 -> F(0.15)[&(55)/(137.5*n)!(0.06)F(0.5)F(0.45)F(0.4)F(0.3)]T(n-1)\n";

/// One row.
#[derive(Debug, Clone, Serialize)]
pub struct ZiomaRow {
    /// Instances.
    pub instances: usize,
    /// Branches over all instances.
    pub branches: usize,
    /// Segments over all instances.
    pub segments: usize,
    /// Skinned vertices per instance.
    pub vertices_per_instance: usize,
    /// The paper's DirectX 9 ms per frame.
    pub paper_dx9_ms: f64,
    /// The paper's DirectX 10 ms per frame at SLOD3 (trunk and branches).
    pub paper_dx10_ms: f64,
    /// The paper's DirectX 10 ms per frame at SLOD2 (trunk only).
    pub paper_dx10_slod2_ms: f64,
    /// The paper's skinning-only ms per frame.
    pub paper_skin_ms: f64,
    /// Bytes read and written per frame (pose and skinning, each buffer once).
    pub bytes_per_frame: usize,
    /// CPU pose ms (median, fastest, slowest).
    pub cpu_pose_ms: Option<[f64; 3]>,
    /// CPU pose + skinning ms.
    pub cpu_frame_ms: Option<[f64; 3]>,
    /// CPU pose (trunk only) + skinning ms.
    pub cpu_frame_slod2_ms: Option<[f64; 3]>,
    /// CPU skinning only ms.
    pub cpu_skin_ms: Option<[f64; 3]>,
    /// GPU pose ms.
    pub gpu_pose_ms: Option<[f64; 3]>,
    /// GPU pose + skinning ms.
    pub gpu_frame_ms: Option<[f64; 3]>,
    /// GPU pose (trunk only) + skinning ms.
    pub gpu_frame_slod2_ms: Option<[f64; 3]>,
    /// GPU skinning only ms.
    pub gpu_skin_ms: Option<[f64; 3]>,
    /// The GPU frame's commands (pose and skinning, SLOD3).
    pub gpu_frame_commands: Option<Commands>,
    /// How the GPU was timed.
    pub gpu_clock: Option<&'static str>,
    /// Why the GPU skinning columns are empty, when they are (one instance's skinned
    /// vertices exceed the device's largest storage binding; more instances are batched).
    pub gpu_skin_skipped: Option<String>,
    /// CPU frame bytes/s over the measured copy bandwidth.
    pub cpu_bandwidth_fraction: Option<f64>,
    /// GPU frame bytes/s over the measured copy bandwidth.
    pub gpu_bandwidth_fraction: Option<f64>,
}

/// The benchmark tree and its skinned rest mesh.
fn eighty() -> Result<(Tree, MeshLayout, SkinLayout)> {
    let g = Grammar::parse(EIGHTY_BRANCHES, "eighty.lsys")?;
    let tree = g.generate(&LSystemOptions { seed: 1, iterations: Some(80), ..Default::default() })?;
    anyhow::ensure!(tree.stems.len() == 80, "the benchmark tree has {} branches, expected 80", tree.stems.len());
    let layout = MeshLayout::new(&tree, MeshParams { sides: 8, samples: 1, leaves: false, ..Default::default() })?;
    let skin = SkinLayout::new(&layout);
    Ok((tree, layout, skin))
}

/// Runs the table; returns the files written.
pub(crate) fn run(env: &Env<'_>) -> Result<Vec<PathBuf>> {
    let rows = if env.quick { &ZIOMA_TABLE_6_1[..3] } else { &ZIOMA_TABLE_6_1[..] };
    let wind = WindScene::resolve("gusty")?;
    let (fields, waves) = wind.pack();
    let (tree, layout, skin) = eighty()?;
    let z = Zioma::new(&tree, ZiomaParams::default());
    let z2 = Zioma::new(&tree, ZiomaParams { lod: Lod::TrunkOnly, ..ZiomaParams::default() });
    let n_seg = tree.segments.len();
    let verts = skin.tube_rest.len();
    let bar = ProgressBar::new(rows.len() as u64).with_style(
        ProgressStyle::with_template("{msg:>10} [{bar:30}] {pos}/{len} rows, {elapsed}").expect("valid template"),
    );
    bar.set_message("zioma-t6-1");
    let mut out = Vec::new();
    for &(instances, paper_branches, paper_dx9_ms, paper_dx10_ms, paper_dx10_slod2_ms, paper_skin_ms) in rows {
        let placed = ZiomaInstance::grid(instances, 8.0, 1);
        // Pose: each instance's record read and its frame written then read; segments and
        // stems read, rotations written then read, joints and accumulated rotations written.
        // Skinning: rest vertex and weights read, vertex written.
        let pose_bytes = instances
            * (std::mem::size_of::<sylva_core::methods::zioma::RawZiomaInstance>()
                + 2 * std::mem::size_of::<sylva_core::methods::zioma::RawZiomaFrame>()
                + n_seg * (std::mem::size_of::<sylva_core::model::RawSegment>() + 16 + 16 + 16 + 16)
                + tree.stems.len() * std::mem::size_of::<sylva_core::methods::zioma::RawZiomaStem>());
        let skin_bytes = instances * verts * (2 * std::mem::size_of::<RawVertex>() + 16);
        let bytes = pose_bytes + skin_bytes;
        let mut t = 0.0f32;
        let mut tick = || {
            t += 1.0 / 60.0;
            t
        };
        let rest_delta = vec![[0.0f32, 0.0, 0.0, 1.0]; n_seg * instances];
        let (rest_joint, rest_acc) = seam_buffers(&tree, &rest_delta);
        let (cpu_pose, cpu_frame, cpu_frame_slod2, cpu_skin) = if env.time_cpu {
            let pose = measure(env.budget, |n| {
                for _ in 0..n {
                    let d = z.rotations_instances(&tree, &fields, &waves, tick(), &placed);
                    std::hint::black_box(Pose::from_rotations_instances(&tree, &d));
                }
                Ok(())
            })?;
            let mut frame = |z: &Zioma| {
                measure(env.budget, |n| {
                    for _ in 0..n {
                        let d = z.rotations_instances(&tree, &fields, &waves, tick(), &placed);
                        let (joint, acc) = seam_buffers(&tree, &d);
                        std::hint::black_box(skin.skin(&joint, &acc, instances as u32));
                    }
                    Ok(())
                })
            };
            let (frame, frame_slod2) = (frame(&z)?, frame(&z2)?);
            let skin_only = measure(env.budget, |n| {
                for _ in 0..n {
                    std::hint::black_box(skin.skin(&rest_joint, &rest_acc, instances as u32));
                }
                Ok(())
            })?;
            (Some(pose), Some(frame), Some(frame_slod2), Some(skin_only))
        } else {
            (None, None, None, None)
        };
        let mut gpu_skin_skipped = None;
        let (gpu_pose, gpu_frame, gpu_frame_slod2, gpu_skin, gpu_frame_commands) = match env.ctx {
            Some(c) => {
                let gpu_wind = sylva_gpu::wind::GpuWind::from_scene(c, &wind)?;
                let shared = std::sync::Arc::new(tree.clone());
                let new = |z: &Zioma| {
                    sylva_gpu::methods::zioma::GpuZioma::with_instances(
                        c,
                        shared.clone(),
                        z.clone(),
                        &gpu_wind,
                        &placed,
                    )
                };
                let (mut g, mut g2) = (new(&z)?, new(&z2)?);
                let pose = measure_gpu(env.budget, c, |n| {
                    for _ in 0..n {
                        g.submit(c, tick());
                    }
                    Ok(())
                })?;
                let gs = match sylva_gpu::mesh::skin::GpuSkin::new(c, &layout, &skin, instances as u32) {
                    Ok(gs) => Some(gs),
                    Err(e @ sylva_gpu::GpuError::TooLarge { .. }) => {
                        bar.suspend(|| println!("{instances} instances: no GPU skinning: {e}"));
                        gpu_skin_skipped = Some(e.to_string());
                        None
                    }
                    Err(e) => return Err(e).context("skinning every instance on the GPU"),
                };
                let (frame, frame_slod2, skin_only, commands) = match gs {
                    Some(gs) => {
                        let mut frames = |g: &mut sylva_gpu::methods::zioma::GpuZioma, n| {
                            for _ in 0..n {
                                // Pose and skinning in one submission.
                                let mut e = c.device.create_command_encoder(&Default::default());
                                g.record(c, &mut e, tick());
                                let pose = g.pose_buffers();
                                gs.record(c, &mut e, pose.joints_buffer(), pose.acc_buffer());
                                c.submit([e.finish()]);
                            }
                            Ok(())
                        };
                        let frame = measure_gpu(env.budget, c, |n| frames(&mut g, n))?;
                        let commands = count_gpu(c, |n| frames(&mut g, n))?;
                        let frame_slod2 = measure_gpu(env.budget, c, |n| frames(&mut g2, n))?;
                        let jb = sylva_gpu::kernel::upload(c, "rest joints", &rest_joint)?;
                        let ab = sylva_gpu::kernel::upload(c, "rest rotations", &rest_acc)?;
                        let skin_only = measure_gpu(env.budget, c, |n| {
                            let mut e = c.device.create_command_encoder(&Default::default());
                            for _ in 0..n {
                                gs.record(c, &mut e, &jb, &ab);
                            }
                            c.submit([e.finish()]);
                            Ok(())
                        })?;
                        (Some(frame), Some(frame_slod2), Some(skin_only), Some(commands))
                    }
                    None => (None, None, None, None),
                };
                (Some(pose), frame, frame_slod2, skin_only, commands)
            }
            None => (None, None, None, None, None),
        };
        let row = ZiomaRow {
            instances,
            branches: instances * tree.stems.len(),
            segments: instances * n_seg,
            vertices_per_instance: verts,
            paper_dx9_ms,
            paper_dx10_ms,
            paper_dx10_slod2_ms,
            paper_skin_ms,
            bytes_per_frame: bytes,
            cpu_pose_ms: cpu_pose.map(|r| r.ms()),
            cpu_frame_ms: cpu_frame.map(|r| r.ms()),
            cpu_frame_slod2_ms: cpu_frame_slod2.map(|r| r.ms()),
            cpu_skin_ms: cpu_skin.map(|r| r.ms()),
            gpu_pose_ms: gpu_pose.map(|r| r.ms()),
            gpu_frame_ms: gpu_frame.map(|r| r.ms()),
            gpu_frame_slod2_ms: gpu_frame_slod2.map(|r| r.ms()),
            gpu_skin_ms: gpu_skin.map(|r| r.ms()),
            gpu_frame_commands,
            gpu_clock: gpu_pose.map(|r| r.clock),
            gpu_skin_skipped,
            cpu_bandwidth_fraction: cpu_frame.map(|r| r.median * bytes as f64 / env.machine.cpu_bandwidth),
            gpu_bandwidth_fraction: gpu_frame.zip(env.machine.gpu_bandwidth).map(|(r, b)| r.median * bytes as f64 / b),
        };
        debug_assert_eq!(row.branches, paper_branches);
        bar.suspend(|| {
            println!(
                "{:>5} instances ({} branches): CPU pose {} ms, frame {} ms (SLOD2 {}); GPU pose {} ms, frame {} ms \
                 (SLOD2 {}); paper DX10 {:.2} ms (SLOD2 {:.2})",
                row.instances,
                row.branches,
                cell(row.cpu_pose_ms),
                cell(row.cpu_frame_ms),
                cell(row.cpu_frame_slod2_ms),
                cell(row.gpu_pose_ms),
                cell(row.gpu_frame_ms),
                cell(row.gpu_frame_slod2_ms),
                row.paper_dx10_ms,
                row.paper_dx10_slod2_ms
            )
        });
        out.push(row);
        bar.inc(1);
    }
    bar.finish_and_clear();

    let mut md =
        markdown_head("Zioma Table 6-1: instanced trees, pose and skinning per frame", "zioma-t6-1", env.machine);
    md += &format!(
        "ms per frame, median (fastest–slowest). An 80-branch tree ({n_seg} segments, {verts} skinned vertices per \
         instance; the paper: 4,617). Frame = pose + two-bone skinning of every instance (the paper's DirectX \
         columns, Xeon 2.33 GHz + GeForce 8800 GTX) at SLOD3 (trunk and branches) and SLOD2 (trunk only); \
         skinning only = from a fixed pose (the paper's skinning without branch simulation).\n\n"
    );
    md += &format!(
        "| instances | branches | paper DX9 ms | paper DX10 SLOD3 ms | paper DX10 SLOD2 ms | paper skinning ms | MB/frame | CPU pose ms | CPU frame ms | CPU SLOD2 frame ms | CPU skinning ms | CPU frame / paper DX10 | CPU SLOD2 / paper SLOD2 | CPU % of bandwidth | GPU pose ms | GPU frame ms | GPU SLOD2 frame ms | GPU skinning ms | GPU frame / paper DX10 | GPU SLOD2 / paper SLOD2 | GPU % of bandwidth | CPU / GPU frame | {} (frame) |\n",
        COMMANDS_HEADING.replace("step", "frame")
    );
    md += "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    let over = |a: Option<[f64; 3]>, b: f64| a.map_or("–".into(), |a| format!("{:.2}", a[0] / b));
    let pct = |f: Option<f64>| f.map_or("–".into(), |f| format!("{:.1} %", 100.0 * f));
    for r in &out {
        md += &format!(
            "| {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.1} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.instances,
            r.branches,
            r.paper_dx9_ms,
            r.paper_dx10_ms,
            r.paper_dx10_slod2_ms,
            r.paper_skin_ms,
            r.bytes_per_frame as f64 / 1e6,
            cell(r.cpu_pose_ms),
            cell(r.cpu_frame_ms),
            cell(r.cpu_frame_slod2_ms),
            cell(r.cpu_skin_ms),
            over(r.cpu_frame_ms, r.paper_dx10_ms),
            over(r.cpu_frame_slod2_ms, r.paper_dx10_slod2_ms),
            pct(r.cpu_bandwidth_fraction),
            cell(r.gpu_pose_ms),
            cell(r.gpu_frame_ms),
            cell(r.gpu_frame_slod2_ms),
            cell(r.gpu_skin_ms),
            over(r.gpu_frame_ms, r.paper_dx10_ms),
            over(r.gpu_frame_slod2_ms, r.paper_dx10_slod2_ms),
            pct(r.gpu_bandwidth_fraction),
            match (r.cpu_frame_ms, r.gpu_frame_ms) {
                (Some(c), Some(g)) => format!("{:.2}", c[0] / g[0]),
                _ => "–".into(),
            },
            commands_cell(r.gpu_frame_commands),
        );
    }
    for r in out.iter().filter(|r| r.gpu_skin_skipped.is_some()) {
        md += &format!(
            "\nNo GPU skinning at {} instances: {}.\n",
            r.instances,
            r.gpu_skin_skipped.as_deref().unwrap_or_default()
        );
    }
    let json = serde_json::to_string_pretty(&Report { table: "zioma-t6-1", machine: env.machine, rows: &out })?;
    let (md_path, json_path, png_path) =
        (env.out_dir.join("zioma-t6-1.md"), env.out_dir.join("zioma-t6-1.json"), env.out_dir.join("zioma-t6-1.png"));
    write_atomic(&md_path, md.as_bytes())?;
    write_atomic(&json_path, json.as_bytes())?;
    let pick = |f: fn(&ZiomaRow) -> Option<[f64; 3]>| -> Vec<(f64, f64)> {
        out.iter().filter_map(|r| f(r).map(|y| (r.instances as f64, y[0]))).collect()
    };
    let series: Vec<Series> = vec![
        (
            "paper DX10 (8800 GTX)",
            RGBColor(120, 120, 120),
            out.iter().map(|r| (r.instances as f64, r.paper_dx10_ms)).collect(),
        ),
        (
            "paper DX10 SLOD2",
            RGBColor(180, 180, 180),
            out.iter().map(|r| (r.instances as f64, r.paper_dx10_slod2_ms)).collect(),
        ),
        ("CPU frame", RGBColor(200, 60, 40), pick(|r| r.cpu_frame_ms)),
        ("CPU SLOD2 frame", RGBColor(240, 120, 100), pick(|r| r.cpu_frame_slod2_ms)),
        ("CPU pose", RGBColor(230, 140, 60), pick(|r| r.cpu_pose_ms)),
        ("GPU frame", RGBColor(40, 90, 200), pick(|r| r.gpu_frame_ms)),
        ("GPU SLOD2 frame", RGBColor(120, 150, 240), pick(|r| r.gpu_frame_slod2_ms)),
        ("GPU pose", RGBColor(90, 160, 230), pick(|r| r.gpu_pose_ms)),
    ];
    plot_series("Zioma Table 6-1 — pose and skinning per frame", "instances", "ms per frame", series, &png_path)
        .context("plotting zioma-t6-1")?;
    println!("{md}");
    Ok(vec![md_path, json_path, png_path])
}
