//! Skjermo's method: GPU vs CPU after 240 steps, on every preset.

mod common;

use rand::{Rng, SeedableRng};
use std::sync::Arc;
use sylva_core::methods::Method;
use sylva_core::methods::skjermo::{Skjermo, SkjermoParams};
use sylva_core::pose::Pose;
use sylva_core::species::{PRESETS, SpeciesSource};
use sylva_core::wind::WindScene;
use sylva_gpu::methods::skjermo::GpuSkjermo;
use sylva_gpu::wind::GpuWind;

/// Joint positions and control points within 1e-4 × tree height after 240 steps (4 s) at
/// 60 Hz in gusty wind (level d answers d steps late: every level has moved long before),
/// the GPU's in one submission.
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
        }
        gpu.advance_steps(ctx, 1.0 / 60.0, 240, true);
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

/// A frame's steps recorded into one submission (each step's time copied into the step
/// buffer between its dispatches, the state buffers ping-ponging) give the same pose, curves
/// and leaves as the steps submitted one by one, bit for bit, on random trees, time steps and
/// step counts.
#[test]
fn skjermo_steps_in_one_submission_match_steps_submitted_one_by_one() {
    let Some(ctx) = common::gpu() else { return };
    let wind = WindScene::resolve("gusty").unwrap();
    let gpu_wind = GpuWind::from_scene(ctx, &wind).unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(32);
    for species in ["quaking_aspen", "palm"] {
        let t = SpeciesSource::resolve(species).unwrap().generate(rng.random_range(1..1000), &Default::default(), None);
        let t = t.unwrap();
        let m = Skjermo::new(&t, SkjermoParams::default());
        let tree = Arc::new(t.clone());
        let mut one_by_one = GpuSkjermo::new(ctx, tree.clone(), &m, &gpu_wind).unwrap();
        let mut batched = GpuSkjermo::new(ctx, tree, &m, &gpu_wind).unwrap();
        let dt = rng.random_range(0.5f32..2.0) / 60.0;
        for frame in 0..3 {
            let steps = rng.random_range(1..8);
            for _ in 0..steps {
                one_by_one.step(ctx, dt);
            }
            batched.advance_steps(ctx, dt, steps, true);
            assert_eq!(one_by_one.time, batched.time);
            let (a, b) = (one_by_one.read(ctx).unwrap(), batched.read(ctx).unwrap());
            assert_eq!(a, b, "{species}, frame {frame} ({steps} steps of {dt} s)");
            assert_ne!(a.start, Pose::rest(&t).start, "{species}: nothing moved");
            use sylva_gpu::methods::GpuAnimator;
            let leaves = |g: &GpuSkjermo| g.pose_buffers().read_leaves(ctx).unwrap();
            assert_eq!(leaves(&one_by_one), leaves(&batched), "{species}: leaf rotations");
        }
    }
}
