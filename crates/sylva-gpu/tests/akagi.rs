//! Akagi's method: GPU vs CPU after 240 steps, on every preset.

mod common;

use std::sync::Arc;
use sylva_core::methods::Method;
use sylva_core::methods::akagi::{Akagi, AkagiParams};
use sylva_core::pose::Pose;
use sylva_core::species::{PRESETS, SpeciesSource};
use sylva_core::wind::WindScene;
use sylva_gpu::methods::GpuAnimator;
use sylva_gpu::methods::akagi::GpuAkagi;
use sylva_gpu::wind::GpuWind;

/// Joint positions within 1e-4 × tree height after 240 steps (4 s) at 60 Hz in gusty wind:
/// both sides run the same f32 operations in the same order (children summed in index
/// order). Each step is one dispatch per depth of the tree, which a software rasteriser
/// runs slowly: 240 steps keep the test to minutes on lavapipe.
#[test]
fn akagi_matches_after_240_steps_on_every_preset() {
    let Some(ctx) = common::gpu() else { return };
    let wind = WindScene::resolve("gusty").unwrap();
    let fw = wind.packed();
    for p in PRESETS {
        let t = SpeciesSource::from_preset(p).unwrap().generate(1, &Default::default(), None).unwrap();
        let a = Akagi::new(&t, AkagiParams::default());
        let mut cpu = a.rest_state(&t);
        let mut gpu = GpuAkagi::new(ctx, Arc::new(t.clone()), &a, &GpuWind::from_scene(ctx, &wind).unwrap()).unwrap();
        for _ in 0..240 {
            a.step(&t, &fw, &mut cpu, 1.0 / 60.0);
            gpu.step(ctx, 1.0 / 60.0);
        }
        let g = gpu.read_pose(ctx).unwrap();
        let height = t.height();
        let mut worst = 0.0f32;
        for i in 0..t.segments.len() {
            let d = (cpu.pose.start[i] - g.start[i]).length();
            worst = worst.max(d);
            assert!(d <= 1e-4 * height, "{}: segment {i} differs by {d} m (tolerance {})", p.name, 1e-4 * height);
        }
        assert_ne!(cpu.pose, Pose::rest(&t), "{}: nothing moved", p.name);
        println!("akagi {:<16} worst joint difference {:.2e} × height", p.name, worst / height);
    }
}

#[test]
fn akagi_on_the_gpu_stays_at_rest_in_still_air() {
    let Some(ctx) = common::gpu() else { return };
    let t = SpeciesSource::resolve("monopodial").unwrap().generate(1, &Default::default(), None).unwrap();
    let a = Akagi::new(&t, AkagiParams::default());
    let mut g = GpuAkagi::new(ctx, Arc::new(t.clone()), &a, &GpuWind::calm(ctx).unwrap()).unwrap();
    for _ in 0..50 {
        g.step(ctx, 1.0 / 60.0);
    }
    assert_eq!(g.read_pose(ctx).unwrap(), Pose::rest(&t));
}
