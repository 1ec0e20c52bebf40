//! Wind fields (grids included) and trunk noise: GPU vs CPU on a million random (x, t)
//! samples per field.

mod common;

use glam::Vec3;
use rand::{Rng, SeedableRng};
use sylva_core::methods::zioma::trunk::TrunkNoise;
use sylva_core::wind::*;

const SAMPLES: usize = 1_000_000;

/// Random samples: x, z in ±150 m, y in 0–40 m, t in 0–120 s.
fn samples(seed: u64) -> Vec<[f32; 4]> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    (0..SAMPLES)
        .map(|_| {
            [
                rng.random_range(-150.0..150.0),
                rng.random_range(0.0..40.0),
                rng.random_range(-150.0..150.0),
                rng.random_range(0.0..120.0),
            ]
        })
        .collect()
}

/// One scene per field kind, with randomised parameters, and each field's tolerance: the
/// largest allowed |v_gpu − v_cpu| as a fraction of the field's peak speed, beyond the
/// phase allowance of [`phase_allowance`].
///
/// 1e-5 for every field: a handful of f32 operations whose rounding may differ (exp and sin
/// are not correctly rounded on either side; a grid's lerps may be fused). Measured on
/// lavapipe: ≤ 1.2e-6, and grids bit for bit.
fn scenes(rng: &mut rand::rngs::StdRng) -> Vec<(&'static str, WindScene, f32, f32)> {
    let mut r = |a: f32, b: f32| rng.random_range(a..b);
    let constant = Constant { direction: [r(-1.0, 1.0), r(-0.2, 0.2), r(-1.0, 1.0)], speed: r(1.0, 20.0) };
    let peak_c = constant.speed;
    let waves: Vec<SineWave> = (0..4)
        .map(|_| SineWave {
            amplitude: r(0.5, 4.0),
            direction_deg: r(0.0, 360.0),
            wavelength: r(5.0, 80.0),
            speed: r(1.0, 10.0),
        })
        .collect();
    let peak_s: f32 = waves.iter().map(|w| w.amplitude).sum();
    // Sines and turbulence blend in and out within the samples' 0–120 s (Skjermo §5).
    let mut fade = |from: f32| Some(Fade { start: from + r(0.0, 30.0), duration: r(1.0, 20.0) });
    let (sines_in, sines_out, turb_in, turb_out) = (fade(0.0), fade(60.0), fade(0.0), fade(60.0));
    let sines = SumOfSines { waves: waves.clone(), sharpness: None, fade_in: sines_in, fade_out: sines_out };
    let sharp = SumOfSines { waves, sharpness: Some(r(1.5, 6.0)), fade_in: None, fade_out: None };
    let gust = GustFront {
        origin: [r(-100.0, 0.0), r(-50.0, 50.0)],
        direction_deg: r(0.0, 360.0),
        strength: r(5.0, 20.0),
        speed: r(3.0, 15.0),
        width: r(5.0, 30.0),
        length: r(10.0, 100.0),
        radius: r(50.0, 200.0),
        start: r(0.0, 30.0),
    };
    let peak_g = gust.strength;
    let vortex = Vortex {
        centre: [r(-50.0, 50.0), r(-50.0, 50.0)],
        drift: [r(-2.0, 2.0), r(-2.0, 2.0)],
        strength: r(5.0, 30.0),
        radius: r(5.0, 40.0),
        updraft: r(0.0, 5.0),
        start: r(0.0, 20.0),
        duration: r(30.0, 90.0),
        fade: r(1.0, 10.0),
    };
    let peak_v = vortex.strength + vortex.updraft;
    let blast = Blast {
        centre: [r(-50.0, 50.0), r(0.0, 5.0), r(-50.0, 50.0)],
        strength: r(10.0, 60.0),
        start: r(0.0, 30.0),
        speed: r(20.0, 340.0),
        width: r(2.0, 20.0),
        decay: r(1.0, 20.0),
        radius: r(50.0, 250.0),
    };
    let peak_b = blast.strength;
    let turb = Turbulence {
        intensity: r(0.5, 4.0),
        beta: r(1.0, 2.0),
        f_min: 0.01,
        f_max: 5.0,
        components: 64,
        mean_speed: r(2.0, 12.0),
        vertical: 0.3,
        seed: 7,
        direction_deg: None,
        fade_in: turb_in,
        fade_out: turb_out,
    };
    let peak_t: f32 = turb.waves().iter().map(|w| Vec3::from_slice(&w.dir[..3]).length()).sum();
    // A 3-D grid held at its edges, stepping through frames and scrolling; and the eddies
    // preset's one-layer grid, wrapped. Samples reach well beyond both.
    let (size, frames) = ([7, 5, 6], 3);
    let nodes = (0..7 * 5 * 6 * 3).map(|_| [r(-8.0, 8.0), r(-2.0, 2.0), r(-8.0, 8.0)]).collect();
    let mut block =
        Grid::new(GridData::new(size, frames, nodes).unwrap(), [r(10.0, 30.0), r(4.0, 10.0), r(10.0, 30.0)]);
    (block.origin, block.scroll, block.frame_rate, block.wrap) =
        ([r(-80.0, -40.0), 0.0, r(-80.0, -40.0)], [r(-1.0, 1.0), 0.0, r(-1.0, 1.0)], r(0.1, 2.0), false);
    let peak_block = 8.0 * 3f32.sqrt();
    let eddies = WindScene::resolve("eddies").unwrap().fields.into_iter().find(|f| matches!(f, WindField::Grid(_)));
    let Some(WindField::Grid(eddies)) = eddies else { panic!("the eddies preset has a grid") };
    let peak_eddies =
        eddies.data.nodes.iter().map(|v| Vec3::from_array(*v).length()).fold(0.0, f32::max) * eddies.scale;
    let one = |f: WindField| WindScene { fields: vec![f] };
    vec![
        ("constant", one(WindField::Constant(constant)), peak_c, 1e-5),
        ("sum of sines (eq. 13), fading in and out", one(WindField::SumOfSines(sines)), peak_s, 1e-5),
        ("sum of sines (eq. 14)", one(WindField::SumOfSines(sharp)), peak_s, 1e-5),
        ("gust front", one(WindField::GustFront(gust)), peak_g, 1e-5),
        ("vortex", one(WindField::Vortex(vortex)), peak_v, 1e-5),
        ("blast", one(WindField::Blast(blast)), peak_b, 1e-5),
        ("turbulence, fading in and out", one(WindField::Turbulence(turb)), peak_t, 1e-5),
        ("grid, 3-D, frames, held", one(WindField::Grid(block)), peak_block, 1e-5),
        ("grid, eddies preset", one(WindField::Grid(eddies)), peak_eddies, 1e-5),
    ]
}

/// How far rounding alone can move a wave field at one sample (m/s). A wave's phase
/// `θ = k·x + ωt` (sums of sines) or `2π cycles − k·x` (turbulence) reaches ~1,500 rad here,
/// where one f32 ulp is ~1e-4 rad; a GPU that fuses `a * b + c` into one rounding, as NVIDIA's
/// Vulkan driver does, rounds θ differently from the CPU, and its `sin` of a large argument
/// reduces it differently too. So each wave may differ by its amplitude × the slope of its
/// profile (1 for eq. 13 and turbulence, sharpness/2 for eq. 14) × two ulps of |θ| (bounded
/// by |θ| 2⁻²²). Measured on an NVIDIA H100: 1.7e-5 × peak for eq. 13, which exceeded the
/// plain 1e-5 bound. Fields without waves get none.
fn phase_allowance(
    fields: &[sylva_core::wind::raw::RawField],
    waves: &[sylva_core::wind::raw::RawWave],
    x: [f32; 4],
) -> f32 {
    use sylva_core::wind::raw::kind;
    let p = Vec3::new(x[0], x[1], x[2]);
    let mut allow = 0.0f32;
    for f in fields {
        let slope = match f.kind {
            kind::SUM_OF_SINES if f.a[1] >= 0.5 => (0.5 * f.a[0]).max(1.0),
            kind::SUM_OF_SINES | kind::TURBULENCE => 1.0,
            _ => continue,
        };
        for w in &waves[f.wave_offset as usize..(f.wave_offset + f.wave_count) as usize] {
            let k = Vec3::from_slice(&w.k[..3]);
            let theta = if f.kind == kind::TURBULENCE {
                std::f32::consts::TAU + k.dot(p).abs()
            } else {
                (k.dot(p) + w.k[3] * x[3]).abs()
            };
            allow += Vec3::from_slice(&w.dir[..3]).length() * slope * theta * 2f32.powi(-22);
        }
    }
    allow
}

#[test]
fn every_field_matches_on_a_million_random_samples() {
    let Some(ctx) = common::gpu() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(2024);
    let s = samples(1);
    for (name, scene, peak, tol) in scenes(&mut rng) {
        let gpu = sylva_gpu::wind::WindSampler::new(ctx, &scene).unwrap().sample(ctx, &s).unwrap();
        let fieldswaves = scene.packed();
        let mut cpu = vec![[0.0f32; 4]; s.len()];
        sylva_core::wind::sample::wind_sample(&fieldswaves.fields, &fieldswaves.waves, &s, &mut cpu);
        let mut worst = 0.0f32;
        let mut worst_share = 0.0f32;
        let mut nonzero = 0usize;
        for i in 0..s.len() {
            let d = (Vec3::from_slice(&gpu[i][..3]) - Vec3::from_slice(&cpu[i][..3])).length();
            let bound = tol * peak + phase_allowance(&fieldswaves.fields, &fieldswaves.waves, s[i]);
            worst = worst.max(d / peak);
            worst_share = worst_share.max(d / bound);
            assert!(d <= bound, "{name}: sample {i} {:?}: |Δv| = {d:e} > {bound:e}", s[i]);
            nonzero += (Vec3::from_slice(&cpu[i][..3]).length() > 1e-3 * peak) as usize;
        }
        println!(
            "{name:<22} worst |Δv| / peak = {worst:.2e} (tolerance {tol:.0e} + phase allowance; worst {:.0}% of the \
             bound), {nonzero} non-zero samples",
            100.0 * worst_share
        );
        assert!(nonzero > 1000, "{name}: the random samples barely touch the field ({nonzero})");
    }
}

#[test]
fn a_composed_scene_matches_too() {
    let Some(ctx) = common::gpu() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(99);
    let mut scene = WindScene::default();
    let mut peak = 0.0;
    for (_, s, p, _) in scenes(&mut rng) {
        scene.fields.extend(s.fields);
        peak += p;
    }
    let s = samples(2);
    let gpu = sylva_gpu::wind::WindSampler::new(ctx, &scene).unwrap().sample(ctx, &s[..200_000]).unwrap();
    let fieldswaves = scene.packed();
    for (i, x) in s[..200_000].iter().enumerate().step_by(7) {
        let cpu = scene.sample(Vec3::new(x[0], x[1], x[2]), x[3]);
        let bound = 1e-5 * peak + phase_allowance(&fieldswaves.fields, &fieldswaves.waves, *x);
        assert!((Vec3::from_slice(&gpu[i][..3]) - cpu).length() <= bound, "sample {i}");
    }
}

/// Trunk angles agree within 1e-6 rad: value noise is integer hashing (bit-identical on both
/// sides) plus a few f32 operations.
#[test]
fn trunk_noise_matches_on_a_million_samples() {
    let Some(ctx) = common::gpu() else { return };
    let noise = TrunkNoise::new(0.6, 0.08);
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    let s: Vec<[f32; 4]> = (0..SAMPLES)
        .map(|_| [rng.random_range(0.0..600.0), f32::from_bits(rng.random::<u32>() & 0x3fff_ffff), 0.0, 0.0])
        .collect();
    let gpu = sylva_gpu::methods::zioma::trunk_noise::trunk_noise(ctx, &noise.bands, &s).unwrap();
    let mut cpu = vec![[0.0f32; 4]; s.len()];
    sylva_core::methods::zioma::trunk::trunk_noise(&noise.bands, &s, &mut cpu);
    let mut worst = 0.0f32;
    for i in 0..s.len() {
        for a in 0..3 {
            worst = worst.max((gpu[i][a] - cpu[i][a]).abs());
        }
    }
    println!("trunk noise worst |Δ| = {worst:e} rad (static bend {} rad)", noise.static_bend);
    assert!(worst <= 1e-6, "{worst}");
}

#[test]
fn kernel_timing_is_reported() {
    let Some(ctx) = common::gpu() else { return };
    let scene = WindScene { fields: vec![WindField::Constant(Constant { direction: [1.0, 0.0, 0.0], speed: 3.0 })] };
    let sampler = sylva_gpu::wind::WindSampler::new(ctx, &scene).unwrap();
    let (v, timing) = sampler.sample_timed(ctx, &samples(3)[..10_000]).unwrap();
    assert_eq!(v[0][0], 3.0);
    assert!(timing.wall.as_nanos() > 0);
    if ctx.timestamps {
        assert!(timing.gpu.is_some(), "adapter has timestamp queries but none were read");
    }
    println!("10k samples: {:?} (timestamps: {})", timing, ctx.timestamps);
}

/// The timer brackets work submitted between `start` and `stop`: the GPU time it reads is
/// positive and no longer than the wall clock around the same submissions.
#[test]
fn gpu_timer_brackets_several_submissions() {
    let Some(ctx) = common::gpu() else { return };
    let Some(timer) = sylva_gpu::timer::GpuTimer::new(ctx) else {
        assert!(!ctx.timestamps);
        println!("skipping: the adapter has no timestamp queries");
        return;
    };
    let scene = WindScene { fields: vec![WindField::Constant(Constant { direction: [1.0, 0.0, 0.0], speed: 3.0 })] };
    let sampler = sylva_gpu::wind::WindSampler::new(ctx, &scene).unwrap();
    let input = sylva_gpu::kernel::upload(ctx, "timer samples", &samples(5)[..100_000]).unwrap();
    ctx.wait().unwrap();
    let wall = std::time::Instant::now();
    timer.start(ctx);
    for _ in 0..4 {
        sampler.sample_into(ctx, &input, 100_000);
    }
    timer.stop(ctx);
    let gpu = timer.read(ctx).unwrap().expect("timestamps advanced");
    let wall = wall.elapsed();
    println!("4 × 100k samples: GPU {gpu:?}, wall {wall:?}");
    assert!(gpu > std::time::Duration::ZERO && gpu <= wall, "GPU {gpu:?}, wall {wall:?}");
}
