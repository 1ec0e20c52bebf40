//! The pose seam and Zioma's method: GPU vs CPU.

mod common;

use glam::{Quat, Vec3};
use rand::{Rng, SeedableRng};
use sylva_core::Tree;
use sylva_core::animate::Pose;
use sylva_core::animate::zioma::{Zioma, ZiomaParams};
use sylva_core::species::{PRESETS, SpeciesSource};
use sylva_core::wind::WindScene;
use sylva_gpu::pose::{GpuPose, GpuZioma};

/// Joint positions agree within 1e-4 × tree height (the bound); orientations within
/// 1e-4 rad. Both sides walk the same ancestor chains with the same f32 operations.
fn compare(t: &Tree, cpu: &Pose, gpu: &Pose, what: &str) -> f32 {
    let height = t.height();
    let tol = 1e-4 * height;
    let mut worst = 0.0f32;
    for i in 0..t.segments.len() {
        let d = (cpu.start[i] - gpu.start[i]).length();
        worst = worst.max(d / height);
        assert!(d <= tol, "{what}: segment {i} joint {} vs {} (tol {tol})", cpu.start[i], gpu.start[i]);
        // |q₁ − q₂| ≈ half the angle between them for nearby unit quaternions (acos near 1
        // cannot resolve 1e-4 rad in f32).
        let (a, b) = (cpu.orientation[i], gpu.orientation[i]);
        let half = (a - b).length().min((a + b).length());
        assert!(2.0 * half <= 1e-4, "{what}: segment {i} turned {} rad apart", 2.0 * half);
    }
    worst
}

#[test]
fn forward_kinematics_matches_on_random_rotations() {
    let Some(ctx) = common::gpu() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    for name in ["black_tupelo", "weeping_willow", "sympodial"] {
        let t = SpeciesSource::resolve(name).unwrap().generate(5, &Default::default(), None).unwrap();
        let delta: Vec<[f32; 4]> = (0..t.segments.len())
            .map(|_| {
                let axis =
                    Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                Quat::from_axis_angle(axis.normalize_or(Vec3::X), rng.random_range(-0.2..0.2)).to_array()
            })
            .collect();
        let cpu = Pose::from_rotations(&t, &delta);
        let gpu = GpuPose::new(ctx, &t).unwrap().pose_from_rotations(ctx, &delta).unwrap();
        let worst = compare(&t, &cpu, &gpu, name);
        println!("fk {name}: worst joint difference {worst:.2e} × height");
    }
}

#[test]
fn zioma_matches_on_every_preset_at_random_times() {
    let Some(ctx) = common::gpu() else { return };
    let wind = WindScene::resolve("gusty").unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(12);
    for p in PRESETS {
        let t = SpeciesSource::from_preset(p).unwrap().generate(1, &Default::default(), None).unwrap();
        let z = Zioma::new(&t, ZiomaParams::default());
        let gpu = GpuZioma::new(ctx, &t, &z, &wind).unwrap();
        let mut worst = 0.0f32;
        for _ in 0..3 {
            let time = rng.random_range(0.0..120.0);
            let a = z.pose(&t, &wind, time);
            let b = gpu.pose(ctx, &t, &z, time).unwrap();
            worst = worst.max(compare(&t, &a, &b, p.name));
        }
        println!("zioma {:<16} worst joint difference {worst:.2e} × height", p.name);
    }
}

#[test]
fn zioma_on_the_gpu_is_at_rest_in_still_air() {
    let Some(ctx) = common::gpu() else { return };
    let t = SpeciesSource::resolve("quaking_aspen").unwrap().generate(1, &Default::default(), None).unwrap();
    let z = Zioma::new(&t, ZiomaParams::default());
    let gpu = GpuZioma::new(ctx, &t, &z, &WindScene::default()).unwrap();
    assert_eq!(gpu.pose(ctx, &t, &z, 5.0).unwrap(), Pose::rest(&t));
}
