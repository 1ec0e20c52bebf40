//! Animation methods, CPU vs GPU in one run: Zioma (pose per frame) and Akagi (step per
//! frame) on presets of increasing size. Reports segments per second and the GPU/CPU
//! ratio. GPU figures are wall clock with synchronisation (a frame is several dispatches);
//! the Akagi GPU step is measured over 60 steps followed by one readback.
//!
//! Run: `WGPU_BACKEND=vulkan cargo bench -p sylva-gpu --bench animate`. The papers' tables
//! (Zioma's instancing, Skjermo's branch updates, …) are `sylva bench`.

use std::sync::Arc;
use std::time::{Duration, Instant};
use sylva_core::methods::Method;
use sylva_core::methods::akagi::{Akagi, AkagiParams};
use sylva_core::methods::zioma::{Zioma, ZiomaParams};
use sylva_core::species::SpeciesSource;
use sylva_core::wind::WindScene;
use sylva_gpu::GpuContext;
use sylva_gpu::methods::GpuAnimator;
use sylva_gpu::methods::akagi::GpuAkagi;
use sylva_gpu::methods::zioma::GpuZioma;
use sylva_gpu::wind::GpuWind;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn time(reps: usize, mut f: impl FnMut()) -> Duration {
    f();
    median(
        (0..reps)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed()
            })
            .collect(),
    )
}

fn main() {
    let wind = WindScene::resolve("gusty").unwrap();
    let fieldswaves = wind.packed();
    let ctx = GpuContext::shared().ok();
    if let Some(c) = ctx {
        println!("GPU: {}", c.summary);
    }
    println!("CPU threads: {}", rayon::current_num_threads());
    println!(
        "{:<16} {:>9} {:<6} {:>12} {:>12} {:>10}",
        "tree", "segments", "method", "cpu Mseg/s", "gpu Mseg/s", "gpu/cpu"
    );
    for name in ["quaking_aspen", "black_tupelo", "weeping_willow"] {
        let t = SpeciesSource::resolve(name).unwrap().generate(1, &Default::default(), None).unwrap();
        let n = t.segments.len() as f64;
        let rate = |d: Duration, frames: f64| n * frames / d.as_secs_f64() / 1e6;
        // Zioma: one pose per frame.
        let z = Zioma::new(&t, ZiomaParams::default());
        let mut tt = 0.0;
        let cpu = time(9, || {
            tt += 1.0 / 60.0;
            std::hint::black_box(z.pose_at(&t, &wind.packed(), tt));
        });
        let gpu = ctx.map(|c| {
            let mut g =
                GpuZioma::new(c, Arc::new(t.clone()), z.clone(), &GpuWind::from_scene(c, &wind).unwrap()).unwrap();
            time(9, || {
                tt += 1.0 / 60.0;
                std::hint::black_box(g.pose(c, tt).unwrap());
            })
        });
        row(name, n, "zioma", rate(cpu, 1.0), gpu.map(|g| rate(g, 1.0)));
        // Akagi: 60 steps.
        let a = Akagi::new(&t, AkagiParams::default());
        let mut s = a.rest_state(&t);
        let cpu = time(3, || {
            for _ in 0..60 {
                a.step(&t, &fieldswaves, &mut s, 1.0 / 60.0);
            }
        });
        let gpu = ctx.map(|c| {
            let mut g = GpuAkagi::new(c, Arc::new(t.clone()), &a, &GpuWind::from_scene(c, &wind).unwrap()).unwrap();
            time(3, || {
                for _ in 0..60 {
                    g.step(c, 1.0 / 60.0);
                }
                std::hint::black_box(g.read_pose(c).unwrap());
            })
        });
        row(name, n, "akagi", rate(cpu, 60.0), gpu.map(|g| rate(g, 60.0)));
    }
    fk_table(ctx);
}

/// Forward kinematics on the GPU, the three ways to walk the hierarchy: every segment walks
/// its ancestor chain (two dispatches), one dispatch per depth root first, or pointer
/// jumping (2⌈log₂(depth + 1)⌉ + 2 dispatches). Poses recorded into one submission, then
/// waited for; median of several submissions. Then single stems of N = 1k…64k segments,
/// where depth = N: per-pose time and the exponent fitted from 1k to 64k.
fn fk_table(ctx: Option<&'static GpuContext>) {
    use sylva_gpu::pose::{FkStrategy, GpuPose};
    let Some(c) = ctx else { return };
    // Milliseconds per pose, `poses` poses per submission, median of `reps` submissions.
    let per_pose = |t: &sylva_core::Tree, strategy, poses: usize, reps: usize| {
        let p = GpuPose::with_strategy(c, t, strategy).unwrap();
        c.queue.write_buffer(
            p.delta_buffer(),
            0,
            bytemuck::cast_slice(&vec![[0.0f32, 0.0, 0.0, 1.0]; t.segments.len()]),
        );
        let d = time(reps, || {
            let mut e = c.device.create_command_encoder(&Default::default());
            for _ in 0..poses {
                p.record(c, &mut e);
            }
            c.submit([e.finish()]);
            c.wait().unwrap();
        });
        d.as_secs_f64() * 1e3 / poses as f64
    };
    println!("\nForward kinematics on the GPU (M segments/s; 20 poses per submission)");
    println!(
        "{:<16} {:>9} {:>6} {:>14} {:>14} {:>14} {:>10} {:>10}",
        "tree", "segments", "depth", "ancestor walk", "by level", "jumping", "walk/level", "walk/jump"
    );
    for name in ["quaking_aspen", "black_tupelo", "weeping_willow", "sympodial"] {
        let t = SpeciesSource::resolve(name).unwrap().generate(1, &Default::default(), None).unwrap();
        let n = t.segments.len();
        let depth = sylva_gpu::pose::max_depth(&t.segments.parent);
        let rate = |strategy| n as f64 / per_pose(&t, strategy, 20, 7) / 1e3;
        let (walk, level, jump) =
            (rate(FkStrategy::AncestorWalk), rate(FkStrategy::LevelByLevel), rate(FkStrategy::PointerJump));
        println!(
            "{name:<16} {n:>9} {depth:>6} {walk:>14.2} {level:>14.2} {jump:>14.2} {:>9.2}× {:>9.2}×",
            walk / level,
            walk / jump
        );
    }
    // One stem N deep: the walk's work grows as N², level by level makes N dispatches, and
    // pointer jumping does N log N work in 2 log N + 2 dispatches. The walk stops at 16k
    // (quadratic: minutes per pose beyond on a CPU adapter), level by level at 4k.
    println!("\nOne stem of N segments (depth N): ms per pose; default = FkStrategy::for_tree");
    println!("{:>7} {:>14} {:>14} {:>14} {:>10}", "N", "ancestor walk", "by level", "jumping", "default");
    let mut fit = Vec::new();
    for n in [250usize, 1_000, 4_000, 16_000, 64_000] {
        let text = format!("iterations: {n}\naxiom: A\nA -> F/(37)&(1)A\n");
        let options = sylva_core::LSystemOptions {
            limits: sylva_core::Limits { max_iterations: 100_000, ..Default::default() },
            ..Default::default()
        };
        let t = sylva_core::Grammar::parse_with_limits(&text, "stem.lsys", &options.limits)
            .unwrap()
            .generate(&options)
            .unwrap();
        let cell = |ms: Option<f64>| ms.map_or("–".to_string(), |m| format!("{m:.3}"));
        let walk = (n <= 16_000).then(|| per_pose(&t, FkStrategy::AncestorWalk, 2, 3));
        let level = (n <= 4_000).then(|| per_pose(&t, FkStrategy::LevelByLevel, 2, 3));
        let jump = per_pose(&t, FkStrategy::PointerJump, 4, 5);
        if n >= 1_000 {
            fit.push((n, jump));
        }
        println!(
            "{n:>7} {:>14} {:>14} {:>14} {:>10}",
            cell(walk),
            cell(level),
            cell(Some(jump)),
            format!("{:?}", FkStrategy::for_tree(&t.segments.parent))
                .replace("AncestorWalk", "walk")
                .replace("PointerJump", "jump")
        );
    }
    let ((n0, t0), (n1, t1)) = (fit[0], fit[fit.len() - 1]);
    println!(
        "pointer jumping, fitted exponent {n0} → {n1}: {:.2} (ln(t₁/t₀) / ln(N₁/N₀))",
        (t1 / t0).ln() / (n1 as f64 / n0 as f64).ln()
    );
}

fn row(name: &str, n: f64, method: &str, cpu: f64, gpu: Option<f64>) {
    match gpu {
        Some(g) => println!("{name:<16} {n:>9} {method:<6} {cpu:>12.3} {g:>12.3} {:>9.2}×", g / cpu),
        None => println!("{name:<16} {n:>9} {method:<6} {cpu:>12.3} {:>12} {:>10}", "–", "–"),
    }
}
