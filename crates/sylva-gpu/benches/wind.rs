//! Wind samples per second on the CPU (rayon, all cores) and on the GPU, and their ratio
//! from the same run. Scene: the `gusty` preset (constant + 3 sines + 64-wave turbulence +
//! gust front + vortex). GPU figures are kernel time (timestamp queries where available,
//! else wall clock with synchronisation); uploads and readbacks are excluded and reported
//! separately.
//!
//! Run: `WGPU_BACKEND=vulkan cargo bench -p sylva-gpu --bench wind`.

use criterion::{Criterion, Throughput, criterion_group};
use std::time::{Duration, Instant};
use sylva_core::wind::WindScene;
use sylva_gpu::GpuContext;
use sylva_gpu::wind::WindSampler;

const N: usize = 1 << 20;

fn samples() -> Vec<[f32; 4]> {
    (0..N)
        .map(|i| [(i % 1024) as f32 * 0.2 - 100.0, 5.0, (i / 1024) as f32 * 0.2 - 100.0, (i % 977) as f32 * 0.1])
        .collect()
}

fn scene() -> WindScene {
    WindScene::resolve("gusty").unwrap()
}

fn cpu_once(
    fields: &[sylva_core::wind::raw::RawField],
    waves: &[sylva_core::wind::raw::RawWave],
    s: &[[f32; 4]],
    out: &mut [[f32; 4]],
) -> Duration {
    let t = Instant::now();
    sylva_core::wind::sample::wind_sample(fields, waves, s, out);
    t.elapsed()
}

fn benches(c: &mut Criterion) {
    let s = samples();
    let fieldswaves = scene().packed();
    let mut out = vec![[0.0f32; 4]; N];
    let mut g = c.benchmark_group("wind_samples");
    g.throughput(Throughput::Elements(N as u64)).sample_size(10);
    g.bench_function("cpu", |b| {
        b.iter_custom(|iters| (0..iters).map(|_| cpu_once(&fieldswaves.fields, &fieldswaves.waves, &s, &mut out)).sum())
    });
    match GpuContext::shared() {
        Ok(ctx) => {
            let sampler = WindSampler::new(ctx, &scene()).unwrap();
            g.bench_function("gpu_kernel", |b| {
                b.iter_custom(|iters| (0..iters).map(|_| sampler.sample_timed(ctx, &s).unwrap().1.best()).sum())
            });
            g.bench_function("gpu_with_transfers", |b| b.iter(|| sampler.sample(ctx, &s).unwrap()));
        }
        Err(e) => eprintln!("no GPU: {e}"),
    }
    g.finish();
}

fn median(mut v: Vec<Duration>) -> (Duration, Duration, Duration) {
    v.sort();
    (v[v.len() / 2], v[0], v[v.len() - 1])
}

/// CPU and GPU in one run, so the ratio compares like with like.
fn summary() {
    let s = samples();
    let fieldswaves = scene().packed();
    let mut out = vec![[0.0f32; 4]; N];
    cpu_once(&fieldswaves.fields, &fieldswaves.waves, &s, &mut out);
    let (cpu, cpu_lo, cpu_hi) =
        median((0..7).map(|_| cpu_once(&fieldswaves.fields, &fieldswaves.waves, &s, &mut out)).collect());
    let rate = |d: Duration| N as f64 / d.as_secs_f64() / 1e6;
    println!("\nwind samples, {N} per run, `gusty` scene, {} CPU threads", rayon::current_num_threads());
    println!(
        "  cpu        : {:8.2} M samples/s (median of 7; {:.1}–{:.1} ms)",
        rate(cpu),
        cpu_lo.as_secs_f64() * 1e3,
        cpu_hi.as_secs_f64() * 1e3
    );
    if let Ok(ctx) = GpuContext::shared() {
        let sampler = WindSampler::new(ctx, &scene()).unwrap();
        sampler.sample(ctx, &s).unwrap();
        let runs: Vec<_> = (0..7).map(|_| sampler.sample_timed(ctx, &s).unwrap().1).collect();
        let (gpu, gpu_lo, gpu_hi) = median(runs.iter().map(|t| t.best()).collect());
        let t = Instant::now();
        sampler.sample(ctx, &s).unwrap();
        let with_io = t.elapsed();
        println!(
            "  gpu kernel : {:8.2} M samples/s (median of 7; {:.1}–{:.1} ms; {}) on {}",
            rate(gpu),
            gpu_lo.as_secs_f64() * 1e3,
            gpu_hi.as_secs_f64() * 1e3,
            if ctx.timestamps { "timestamp queries" } else { "wall clock" },
            ctx.summary
        );
        println!("  gpu + I/O  : {:8.2} M samples/s (upload and readback included)", rate(with_io));
        println!(
            "  GPU / CPU  : {:8.2}× (kernel), {:.2}× (with I/O)",
            cpu.as_secs_f64() / gpu.as_secs_f64(),
            cpu.as_secs_f64() / with_io.as_secs_f64()
        );
    }
}

criterion_group!(wind, benches);

fn main() {
    wind();
    Criterion::default().configure_from_args().final_summary();
    summary();
}
