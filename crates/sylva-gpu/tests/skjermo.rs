//! Skjermo's method: GPU vs CPU after 240 steps, on every preset.

mod common;

use std::sync::Arc;
use sylva_core::methods::Method;
use sylva_core::methods::skjermo::{Skjermo, SkjermoParams};
use sylva_core::pose::Pose;
use sylva_core::species::{PRESETS, SpeciesSource};
use sylva_core::wind::WindScene;
use sylva_gpu::methods::skjermo::GpuSkjermo;
use sylva_gpu::wind::GpuWind;

/// Joint positions and control points within 1e-4 × tree height after 240 steps (4 s) at
/// 60 Hz in gusty wind (level d answers d steps late: every level has moved long before).
/// One submission per step runs slowly on a software rasteriser: 240 keep it to minutes.
#[test]
fn skjermo_matches_after_240_steps_on_every_preset() {
    let Some(ctx) = common::gpu() else { return };
    let wind = WindScene::resolve("gusty").unwrap();
    let fw = wind.packed();
    for p in PRESETS {
        let t = SpeciesSource::from_preset(p).unwrap().generate(1, &Default::default(), None).unwrap();
        let m = Skjermo::new(&t, SkjermoParams::default());
        let mut cpu = m.rest_state(&t);
        let mut gpu = GpuSkjermo::new(ctx, Arc::new(t.clone()), &m, &GpuWind::from_scene(ctx, &wind).unwrap()).unwrap();
        for _ in 0..240 {
            m.step(&t, &fw, &mut cpu, 1.0 / 60.0);
            gpu.step(ctx, 1.0 / 60.0);
        }
        let g = gpu.read(ctx).unwrap();
        let tol = 1e-4 * t.height();
        let mut worst = 0.0f32;
        for i in 0..t.segments.len() {
            let d = (cpu.pose.start[i] - g.start[i]).length();
            worst = worst.max(d);
            assert!(d <= tol, "{}: segment {i} differs by {d} m (tolerance {tol})", p.name);
        }
        for (a, b) in cpu.pose.bezier.as_ref().unwrap().iter().zip(g.bezier.as_ref().unwrap()) {
            for j in 0..4 {
                assert!((a[j] - b[j]).length() <= tol, "{}: control point {j} differs", p.name);
            }
        }
        assert_ne!(cpu.pose.start, Pose::rest(&t).start, "{}: nothing moved", p.name);
        println!("skjermo {:<16} worst joint difference {:.2e} × height", p.name, worst / t.height());
    }
}

#[test]
fn skjermo_on_the_gpu_stays_at_rest_in_still_air() {
    let Some(ctx) = common::gpu() else { return };
    let t = SpeciesSource::resolve("black_tupelo").unwrap().generate(1, &Default::default(), None).unwrap();
    let m = Skjermo::new(&t, SkjermoParams::default());
    let mut g = GpuSkjermo::new(ctx, Arc::new(t.clone()), &m, &GpuWind::calm(ctx).unwrap()).unwrap();
    for _ in 0..20 {
        g.step(ctx, 1.0 / 60.0);
    }
    let pose = g.read(ctx).unwrap();
    assert_eq!(pose.start, Pose::rest(&t).start);
    assert_eq!(pose.bezier.unwrap(), t.stems.bezier);
}
