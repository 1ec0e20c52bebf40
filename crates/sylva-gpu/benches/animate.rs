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
    println!("{:>9} {:>14} {:>14} {:>10}   paper (7900 GTX)", "branches", "cpu updates/s", "gpu updates/s", "gpu/cpu");
    for (iterations, paper) in [(16u32, 600.0), (18, 180.0)] {
        let g =
            Grammar::parse("axiom: A(1)\nA(l) -> F(l)[+(30)A(l*0.8)][-(30)/(90)A(l*0.8)]\n", "binary.lsys").unwrap();
        let t = g.generate(&LSystemOptions { seed: 1, iterations: Some(iterations), ..Default::default() }).unwrap();
        let m = Skjermo::new(&t, SkjermoParams::default());
        let state = m.rest_state(&t);
        let mut next = state.stems.clone();
        let n = t.stems.len();
        let cpu = time(7, || {
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
            Some(gr) => println!("{n:>9} {cpu_rate:>14.1} {gr:>14.1} {:>9.2}×   {paper} updates/s", gr / cpu_rate),
            None => println!("{n:>9} {cpu_rate:>14.1} {:>14} {:>10}   {paper} updates/s", "–", "–"),
        }
    }
}

fn row(name: &str, n: f64, method: &str, cpu: f64, gpu: Option<f64>) {
    match gpu {
        Some(g) => println!("{name:<16} {n:>9} {method:<6} {cpu:>12.3} {g:>12.3} {:>9.2}×", g / cpu),
        None => println!("{name:<16} {n:>9} {method:<6} {cpu:>12.3} {:>12} {:>10}", "–", "–"),
    }
}
