//! Animation methods, CPU vs GPU in one run: Zioma (pose per frame) and Akagi (step per
//! frame) on presets of increasing size. Reports segments per second and the GPU/CPU
//! ratio. GPU figures are wall clock with synchronisation (a frame is several dispatches);
//! the Akagi GPU step is measured over 60 steps followed by one readback.
//!
//! Run: `WGPU_BACKEND=vulkan cargo bench -p sylva-gpu --bench animate`.

use std::time::{Duration, Instant};
use sylva_core::animate::akagi::{Akagi, AkagiParams};
use sylva_core::animate::zioma::{Zioma, ZiomaParams};
use sylva_core::species::SpeciesSource;
use sylva_core::wind::WindScene;
use sylva_gpu::GpuContext;
use sylva_gpu::pose::{GpuAkagi, GpuZioma};

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
    let (fields, waves) = wind.pack();
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
            std::hint::black_box(z.pose(&t, &wind, tt));
        });
        let gpu = ctx.map(|c| {
            let g = GpuZioma::new(c, &t, &z, &wind).unwrap();
            time(9, || {
                tt += 1.0 / 60.0;
                std::hint::black_box(g.pose(c, &t, &z, tt).unwrap());
            })
        });
        row(name, n, "zioma", rate(cpu, 1.0), gpu.map(|g| rate(g, 1.0)));
        // Akagi: 60 steps.
        let a = Akagi::new(&t, AkagiParams::default());
        let mut s = a.rest_state(&t);
        let cpu = time(3, || {
            for _ in 0..60 {
                a.step(&t, &fields, &waves, &mut s, 1.0 / 60.0);
            }
        });
        let gpu = ctx.map(|c| {
            let mut g = GpuAkagi::new(c, &t, &a, &wind).unwrap();
            time(3, || {
                for _ in 0..60 {
                    g.step(c, 1.0 / 60.0);
                }
                std::hint::black_box(g.read(c).unwrap());
            })
        });
        row(name, n, "akagi", rate(cpu, 60.0), gpu.map(|g| rate(g, 60.0)));
    }
    fk_table(ctx);
    zioma_instances_table(ctx, &wind);
    skjermo_table(ctx, "`gusty` (72 terms)", WindScene::resolve("gusty").unwrap());
    // The paper's setting: four sines (eqs. 11-14).
    let sines = WindScene::from_toml(
        "[[field]]\nkind = \"sum_of_sines\"\nsharpness = 2.0\nwaves = [\n\
         { amplitude = 4.0, direction_deg = 0.0, wavelength = 40.0, speed = 6.0 },\n\
         { amplitude = 2.0, direction_deg = 30.0, wavelength = 17.0, speed = 4.0 },\n\
         { amplitude = 1.0, direction_deg = -25.0, wavelength = 9.0, speed = 3.0 },\n\
         { amplitude = 0.5, direction_deg = 60.0, wavelength = 5.0, speed = 2.0 },\n]\n",
        "sines.toml",
    )
    .unwrap();
    skjermo_table(ctx, "four sines (the paper's setting)", sines);
}

/// Skjermo's figure: branches updated per second (the step: re-attach, sample the wind,
/// bend), on binary trees of 65,535 and 262,143 one-segment stems (paper: 65,536 branches
/// at 600 updates/s and 262,144 at 180/s on a GeForce 7900 GTX).
fn skjermo_table(ctx: Option<&'static GpuContext>, wind_name: &str, wind: WindScene) {
    use sylva_core::animate::skjermo::{Skjermo, SkjermoParams};
    use sylva_core::{Grammar, LSystemOptions};
    let (fields, waves) = wind.pack();
    println!("\nSkjermo step (branches updated per second), wind {wind_name}");
    println!(
        "{:>9} {:>14} {:>14} {:>14} {:>10}   paper (7900 GTX)",
        "branches", "cpu updates/s", "cpu ref upd/s", "gpu updates/s", "gpu/cpu"
    );
    for (iterations, paper) in [(16u32, 600.0), (18, 180.0)] {
        let g =
            Grammar::parse("axiom: A(1)\nA(l) -> F(l)[+(30)A(l*0.8)][-(30)/(90)A(l*0.8)]\n", "binary.lsys").unwrap();
        let t = g.generate(&LSystemOptions { seed: 1, iterations: Some(iterations), ..Default::default() }).unwrap();
        let m = Skjermo::new(&t, SkjermoParams::default());
        let n = t.stems.len();
        // The CPU path: eight stems per lane group, buffers ping-pong.
        let mut state = m.rest_state(&t);
        let cpu = time(15, || m.step_stems(&fields, &waves, &mut state, 1.0 / 60.0));
        // The reference kernel (one stem at a time; the WGSL's twin).
        let state = m.rest_state(&t);
        let mut next = state.stems.clone();
        let reference = time(5, || {
            sylva_core::cpu::skjermo::skjermo_step(
                &fields,
                &waves,
                &m.stems,
                &state.stems,
                m.step_params(1.0),
                &mut next,
            );
        });
        let cpu_rate = 1.0 / cpu.as_secs_f64();
        let ref_rate = 1.0 / reference.as_secs_f64();
        let gpu_rate = ctx.map(|c| {
            let mut g = sylva_gpu::pose::GpuSkjermo::new(c, &t, &m, &wind).unwrap();
            let d = time(3, || {
                for _ in 0..20 {
                    g.step_only(c, 1.0 / 60.0);
                }
                c.wait().unwrap();
            });
            20.0 / d.as_secs_f64()
        });
        match gpu_rate {
            Some(gr) => println!(
                "{n:>9} {cpu_rate:>14.1} {ref_rate:>14.1} {gr:>14.1} {:>9.2}×   {paper} updates/s",
                gr / cpu_rate
            ),
            None => println!("{n:>9} {cpu_rate:>14.1} {ref_rate:>14.1} {:>14} {:>10}   {paper} updates/s", "–", "–"),
        }
    }
}

/// Forward kinematics on the GPU, the two ways to walk the hierarchy: every segment walks its
/// ancestor chain (two dispatches) or one dispatch per depth, root first. 20 poses recorded
/// into one submission, then waited for.
fn fk_table(ctx: Option<&'static GpuContext>) {
    use sylva_gpu::pose::{FkStrategy, GpuPose};
    let Some(c) = ctx else { return };
    println!("\nForward kinematics on the GPU (M segments/s; 20 poses per submission)");
    println!(
        "{:<16} {:>9} {:>6} {:>14} {:>14} {:>10}",
        "tree", "segments", "depth", "ancestor walk", "by level", "walk/level"
    );
    for name in ["quaking_aspen", "black_tupelo", "weeping_willow", "sympodial"] {
        let t = SpeciesSource::resolve(name).unwrap().generate(1, &Default::default(), None).unwrap();
        let n = t.segments.len();
        let depth = sylva_core::cpu::pose_fk::depth_buckets(&t.segments.parent).len();
        let delta = vec![[0.0f32, 0.0, 0.0, 1.0]; n];
        let rate = |strategy| {
            let p = GpuPose::with_strategy(c, &t, strategy).unwrap();
            c.queue.write_buffer(p.delta_buffer(), 0, bytemuck::cast_slice(&delta));
            let d = time(7, || {
                let mut e = c.device.create_command_encoder(&Default::default());
                for _ in 0..20 {
                    p.record(c, &mut e);
                }
                c.queue.submit([e.finish()]);
                c.wait().unwrap();
            });
            n as f64 * 20.0 / d.as_secs_f64() / 1e6
        };
        let (walk, level) = (rate(FkStrategy::AncestorWalk), rate(FkStrategy::LevelByLevel));
        println!("{name:<16} {n:>9} {depth:>6} {walk:>14.2} {level:>14.2} {:>9.2}×", walk / level);
    }
}

/// Zioma's Table 6-1 sizes: 30, 100, 256 and 1,000 instances of an 80-branch tree (a trunk
/// and 79 side branches of four segments), one pose per frame for every instance: CPU
/// (rotations + forward kinematics, rayon) and GPU (one dispatch over all instances' segments
/// and one forward-kinematics pass, waited for), then skinning (Zioma §6.5) of every
/// instance's copy of one rest mesh (8-sided tubes, one cross-section per segment: 4,275
/// vertices against the paper's 4,617): CPU `SkinLayout::skin`, GPU `skin_vertices.wgsl`.
/// The paper's figures (GeForce 8800 GTX) are pose + skinning.
fn zioma_instances_table(ctx: Option<&'static GpuContext>, wind: &WindScene) {
    use sylva_core::animate::zioma::ZiomaInstance;
    use sylva_core::{Grammar, LSystemOptions};
    let g = Grammar::parse(
        "axiom: !(0.3)T(79)\nT(n) : n > 0 -> F(0.15)[&(55)/(137.5*n)!(0.06)F(0.5)F(0.45)F(0.4)F(0.3)]T(n-1)\n",
        "eighty.lsys",
    )
    .unwrap();
    let t = g.generate(&LSystemOptions { seed: 1, iterations: Some(80), ..Default::default() }).unwrap();
    assert_eq!(t.stems.len(), 80);
    let z = Zioma::new(&t, ZiomaParams::default());
    let (fields, waves) = wind.pack();
    println!(
        "\nZioma instancing (Table 6-1 sizes; {} branches, {} segments per instance), ms per frame",
        t.stems.len(),
        t.segments.len()
    );
    let layout = sylva_core::mesh::MeshLayout::new(
        &t,
        sylva_core::mesh::MeshParams { sides: 8, samples: 1, leaves: false, ..Default::default() },
    )
    .unwrap();
    let skin = sylva_core::mesh::SkinLayout::new(&layout);
    println!(
        "{:>9} {:>9} {:>10} {:>10} {:>10} {:>14} {:>14} {:>10}   paper DX10 (8800 GTX, pose + skinning)",
        "instances", "branches", "cpu ms", "gpu ms", "gpu/cpu", "cpu+skin ms", "gpu+skin ms", "gpu/cpu"
    );
    println!("(skinning {} vertices per instance)", skin.tube_rest.len());
    for (count, paper) in [(30usize, 1.34), (100, 3.82), (256, 9.68), (1000, 37.61)] {
        let instances = ZiomaInstance::grid(count, 8.0, 1);
        let mut tt = 0.0;
        let cpu = time(9, || {
            tt += 1.0 / 60.0;
            let d = z.rotations_instances(&t, &fields, &waves, tt, &instances);
            std::hint::black_box(sylva_core::animate::Pose::from_rotations_instances(&t, &d));
        });
        let cpu_skin = time(5, || {
            tt += 1.0 / 60.0;
            let d = z.rotations_instances(&t, &fields, &waves, tt, &instances);
            let (joint, acc) = sylva_core::animate::seam_buffers(&t, &d);
            std::hint::black_box(skin.skin(&joint, &acc, count as u32));
        });
        let gpu = ctx.map(|c| {
            let g = GpuZioma::with_instances(c, &t, &z, wind, &instances).unwrap();
            let pose = time(9, || {
                tt += 1.0 / 60.0;
                g.submit(c, &t, &z, tt);
                c.wait().unwrap();
            });
            // Skinning every instance, unless the output exceeds the device's binding limit.
            let skinned = sylva_gpu::skin::GpuSkin::new(c, &layout, &skin, count as u32).ok().map(|gs| {
                time(9, || {
                    tt += 1.0 / 60.0;
                    g.submit(c, &t, &z, tt);
                    let mut e = c.device.create_command_encoder(&Default::default());
                    gs.record(c, &mut e, g.gpu_pose().joints_buffer(), g.gpu_pose().acc_buffer());
                    c.queue.submit([e.finish()]);
                    c.wait().unwrap();
                })
            });
            (pose, skinned)
        });
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let cell = |d: Option<Duration>| d.map_or("–".to_string(), |d| format!("{:.2}", ms(d)));
        let ratio =
            |a: Duration, b: Option<Duration>| b.map_or("–".to_string(), |b| format!("{:.2}×", ms(a) / ms(b)));
        let (gpu_pose, gpu_skin) = match gpu {
            Some((p, s)) => (Some(p), s),
            None => (None, None),
        };
        println!(
            "{count:>9} {:>9} {:>10.2} {:>10} {:>10} {:>14.2} {:>14} {:>10}   {paper} ms",
            count * t.stems.len(),
            ms(cpu),
            cell(gpu_pose),
            ratio(cpu, gpu_pose),
            ms(cpu_skin),
            cell(gpu_skin),
            ratio(cpu_skin, gpu_skin),
        );
    }
}

fn row(name: &str, n: f64, method: &str, cpu: f64, gpu: Option<f64>) {
    match gpu {
        Some(g) => println!("{name:<16} {n:>9} {method:<6} {cpu:>12.3} {g:>12.3} {:>9.2}×", g / cpu),
        None => println!("{name:<16} {n:>9} {method:<6} {cpu:>12.3} {:>12} {:>10}", "–", "–"),
    }
}
