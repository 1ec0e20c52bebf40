//! The pose seam and Zioma's method: GPU vs CPU.

mod common;

use glam::{Quat, Vec3};
use rand::{Rng, SeedableRng};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::methods::zioma::{Zioma, ZiomaParams};
use sylva_core::pose::Pose;
use sylva_core::species::{PRESETS, SpeciesSource};
use sylva_core::wind::WindScene;
use sylva_gpu::methods::zioma::GpuZioma;
use sylva_gpu::pose::{FkStrategy, GpuPose};
use sylva_gpu::wind::GpuWind;

/// The angle between two nearby unit quaternions: |q₁ − q₂| ≈ half of it (acos near 1
/// cannot resolve 1e-4 rad in f32).
fn angle(a: Quat, b: Quat) -> f32 {
    2.0 * (a - b).length().min((a + b).length())
}

/// Joint positions agree within 1e-4 × tree height (the bound); orientations within
/// 1e-4 rad plus `allowance[i]` where given. Both sides walk the same ancestor chains with
/// the same f32 operations.
fn compare_within(t: &Tree, cpu: &Pose, gpu: &Pose, allowance: Option<&[f32]>, what: &str) -> f32 {
    let height = t.height();
    let tol = 1e-4 * height;
    let mut worst = 0.0f32;
    for i in 0..t.segments.len() {
        let d = (cpu.start[i] - gpu.start[i]).length();
        worst = worst.max(d / height);
        assert!(d <= tol, "{what}: segment {i} joint {} vs {} (tol {tol})", cpu.start[i], gpu.start[i]);
        let turn = angle(cpu.orientation[i], gpu.orientation[i]);
        let bound = 1e-4 + allowance.map_or(0.0, |a| a[i]);
        assert!(turn <= bound, "{what}: segment {i} turned {turn} rad apart (bound {bound})");
    }
    worst
}

fn compare(t: &Tree, cpu: &Pose, gpu: &Pose, what: &str) -> f32 {
    compare_within(t, cpu, gpu, None, what)
}

/// How far each segment of Zioma's pose turns when time moves by two f32 ulps either way
/// (rad). Zioma's angles are functions of phases `f t + φ` (branch noise at up to 2.7 × a
/// twig's frequency, the wind's `ω t`), and at t ≈ 100 s one ulp of such a phase is ~1e-5 of
/// a cycle or more; a GPU that fuses `f * t + φ` into one rounding, as NVIDIA's Vulkan driver
/// does, rounds the phase differently from the CPU by about that much. Measured on an NVIDIA
/// H100: twigs 1.8e-4 rad apart at t = 118 s, over the plain 1e-4 rad bound; lavapipe,
/// which does not fuse, stays under 1e-5.
fn time_rounding_allowance(z: &Zioma, t: &Tree, wind: &WindScene, time: f32) -> Vec<f32> {
    let at = z.pose_at(t, &wind.packed(), time);
    let dt = 2.0 * time.abs() * 2f32.powi(-23);
    let (early, late) = (z.pose_at(t, &wind.packed(), time - dt), z.pose_at(t, &wind.packed(), time + dt));
    (0..t.segments.len())
        .map(|i| angle(at.orientation[i], early.orientation[i]).max(angle(at.orientation[i], late.orientation[i])))
        .collect()
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
        // The level-by-level alternative: the same pose to rounding (it multiplies and sums
        // root first rather than leaf first), and its CPU twin likewise.
        let level = GpuPose::with_strategy(ctx, &t, FkStrategy::LevelByLevel).unwrap();
        let gpu = level.pose_from_rotations(ctx, &delta).unwrap();
        let worst = compare(&t, &cpu, &gpu, &format!("{name} level by level"));
        println!("fk {name} level by level: worst joint difference {worst:.2e} × height");
        let n = t.segments.len();
        let rest: Vec<[f32; 4]> = t.segments.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        let (mut acc, mut disp, mut joints) = (vec![[0.0f32; 4]; n], vec![[0.0f32; 4]; n], vec![[0.0f32; 4]; n]);
        for b in sylva_core::pose::fk::depth_buckets(&t.segments.parent) {
            sylva_core::pose::fk::pose_level(&b, &t.segments.parent, &rest, &delta, &mut acc, &mut disp, &mut joints);
        }
        let twin = Pose {
            start: joints.iter().map(|p| Vec3::new(p[0], p[1], p[2])).collect(),
            orientation: acc.iter().zip(&t.segments.orientation).map(|(d, q)| Quat::from_array(*d) * *q).collect(),
            bezier: None,
        };
        compare(&t, &twin, &gpu, &format!("{name} level-by-level twin"));
        // Pointer jumping: the same pose to rounding (products and sums in a tree of pairs).
        let jump = GpuPose::with_strategy(ctx, &t, FkStrategy::PointerJump).unwrap();
        let worst = compare(&t, &cpu, &jump.pose_from_rotations(ctx, &delta).unwrap(), &format!("{name} jumping"));
        println!("fk {name} pointer jumping: worst joint difference {worst:.2e} × height");
    }
    // Identity rotations give the rest pose exactly either way.
    let t = SpeciesSource::resolve("quaking_aspen").unwrap().generate(1, &Default::default(), None).unwrap();
    let identity = vec![[0.0f32, 0.0, 0.0, 1.0]; t.segments.len()];
    for strategy in [FkStrategy::AncestorWalk, FkStrategy::LevelByLevel, FkStrategy::PointerJump] {
        let pose = GpuPose::with_strategy(ctx, &t, strategy).unwrap();
        assert_eq!(pose.strategy(), strategy);
        let gpu = pose.pose_from_rotations(ctx, &identity).unwrap();
        assert_eq!(gpu.start, t.segments.start, "{strategy:?}");
    }
}

/// Deep hierarchies jump pointers (`FkStrategy::for_tree`): a 900-segment stem with random
/// rotations, three instances, against pointer jumping's CPU twin (the same products and sums
/// in the same tree of pairs; glam and `quat.wgsl` round a product differently, and a chain
/// of 900 compounds it: within 2e-5 × height and 2e-5 per quaternion component; lavapipe
/// measures 4e-6) and against
/// the CPU's one pass (another order: within 1e-4 × height, the parity bound). The
/// joints-only path (HSM's) as well.
#[test]
fn pointer_jumping_matches_on_a_deep_stem() {
    use sylva_core::pose::fk::{jump_ancestors, pose_forward, pose_jump, pose_jump_joints, pose_jump_sums};
    use sylva_core::pose::fk::{pose_jump_terms, positions_forward};
    use sylva_gpu::kernel::read_back;
    let Some(ctx) = common::gpu() else { return };
    let t = sylva_core::Grammar::parse("iterations: 900\naxiom: A\nA -> F/(37)&(1)A\n", "stem.lsys")
        .unwrap()
        .generate(&Default::default())
        .unwrap();
    let (n, instances) = (t.segments.len(), 3);
    assert_eq!(FkStrategy::for_tree(&t.segments.parent), FkStrategy::PointerJump);
    let willow = SpeciesSource::resolve("weeping_willow").unwrap().generate(1, &Default::default(), None).unwrap();
    assert_eq!(FkStrategy::for_tree(&willow.segments.parent), FkStrategy::AncestorWalk, "shipped species walk");
    let pose = GpuPose::with_instances(ctx, &t, instances).unwrap();
    assert_eq!(pose.strategy(), FkStrategy::PointerJump);
    let mut rng = rand::rngs::StdRng::seed_from_u64(13);
    let delta: Vec<[f32; 4]> = (0..n * instances)
        .map(|_| {
            let axis = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            Quat::from_axis_angle(axis.normalize_or(Vec3::X), rng.random_range(-0.05..0.05)).to_array()
        })
        .collect();
    ctx.queue.write_buffer(pose.delta_buffer(), 0, bytemuck::cast_slice(&delta));
    let mut e = ctx.device.create_command_encoder(&Default::default());
    pose.record(ctx, &mut e);
    ctx.submit([e.finish()]);
    let gpu_acc: Vec<[f32; 4]> = read_back(ctx, pose.acc_buffer(), n * instances).unwrap();
    let gpu_joints: Vec<[f32; 4]> = read_back(ctx, pose.joints_buffer(), n * instances).unwrap();
    let parent = &t.segments.parent;
    let rest: Vec<[f32; 4]> = t.segments.start.iter().map(|p| p.extend(0.0).to_array()).collect();
    let total = n * instances;
    let (mut twin_acc, mut twin_joints) = (vec![[0.0f32; 4]; total], vec![[0.0f32; 4]; total]);
    pose_jump(&jump_ancestors(parent), parent, &rest, &delta, &mut twin_acc, &mut twin_joints);
    let (mut one_acc, mut one_joints) = (vec![[0.0f32; 4]; total], vec![[0.0f32; 4]; total]);
    pose_forward(parent, &rest, &delta, &mut one_acc, &mut one_joints);
    let height = t.height();
    let v = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
    let q = |a: [f32; 4]| Quat::from_array(a);
    let (mut worst_twin, mut worst_one) = (0.0f32, 0.0f32);
    for i in 0..total {
        let (dt, d1) =
            ((v(gpu_joints[i]) - v(twin_joints[i])).length(), (v(gpu_joints[i]) - v(one_joints[i])).length());
        worst_twin = worst_twin.max(dt / height);
        worst_one = worst_one.max(d1 / height);
        assert!(dt <= 2e-5 * height, "segment {i}: GPU joint {dt} m from its twin");
        assert!(d1 <= 1e-4 * height, "segment {i}: GPU joint {d1} m from the CPU's one pass");
        let dq = glam::Vec4::from(q(gpu_acc[i]) - q(twin_acc[i])).abs().max_element();
        assert!(dq <= 2e-5, "segment {i}: rotation vs twin: {dq}, {:?} vs {:?}", gpu_acc[i], twin_acc[i]);
        assert!(angle(q(gpu_acc[i]), q(one_acc[i])) <= 1e-4, "segment {i}: rotation vs one pass");
    }
    // Instances are independent: each one's pose is its own rotations'.
    assert_ne!(gpu_joints[n - 1], gpu_joints[2 * n - 1], "instances differ");
    println!(
        "pointer jumping, 900-segment stem × 3: worst joint {worst_twin:.2e} × height from its twin, {worst_one:.2e} from the one pass"
    );

    // Joints only, from rotations written into acc (HSM's path).
    ctx.queue.write_buffer(pose.acc_buffer(), 0, bytemuck::cast_slice(&one_acc));
    let mut e = ctx.device.create_command_encoder(&Default::default());
    pose.record_positions(ctx, &mut e);
    ctx.submit([e.finish()]);
    let gpu_joints: Vec<[f32; 4]> = read_back(ctx, pose.joints_buffer(), total).unwrap();
    let mut terms = vec![[0.0f32; 4]; total];
    pose_jump_terms(parent, &rest, &one_acc, &mut terms);
    for anc in jump_ancestors(parent) {
        let mut next = vec![[0.0f32; 4]; total];
        pose_jump_sums(&anc, &terms, &mut next);
        terms = next;
    }
    let mut twin = vec![[0.0f32; 4]; total];
    pose_jump_joints(&rest, &terms, &mut twin);
    let mut one = vec![[0.0f32; 4]; total];
    positions_forward(parent, &rest, &one_acc, &mut one);
    for i in 0..total {
        assert!((v(gpu_joints[i]) - v(twin[i])).length() <= 2e-5 * height, "positions, segment {i}: vs twin");
        assert!((v(gpu_joints[i]) - v(one[i])).length() <= 1e-4 * height, "positions, segment {i}: vs one pass");
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
        let mut gpu =
            GpuZioma::new(ctx, Arc::new(t.clone()), z.clone(), &GpuWind::from_scene(ctx, &wind).unwrap()).unwrap();
        let mut worst = 0.0f32;
        for _ in 0..3 {
            let time = rng.random_range(0.0..120.0);
            let a = z.pose_at(&t, &wind.packed(), time);
            let b = gpu.pose(ctx, time).unwrap();
            let allowance = time_rounding_allowance(&z, &t, &wind, time);
            worst = worst.max(compare_within(&t, &a, &b, Some(&allowance), p.name));
        }
        println!("zioma {:<16} worst joint difference {worst:.2e} × height", p.name);
    }
}

/// Zioma on the bush with `instances` (none: the single tree), on the CPU (instances
/// registered) and the GPU, through 5 s of the gusty wind and then a second of calm.
fn gusty_then_calm(
    ctx: &sylva_gpu::GpuContext,
    instances: &[sylva_core::pose::Placement],
) -> (Tree, Zioma, sylva_core::methods::zioma::ZiomaState, GpuZioma) {
    use sylva_core::methods::Method;
    use sylva_core::wind::PackedWind;
    use sylva_gpu::methods::GpuAnimator;
    let wind = WindScene::resolve("gusty").unwrap();
    let (fw, calm) = (wind.packed(), PackedWind::calm());
    let t = SpeciesSource::resolve("stochastic_bush").unwrap().generate(4, &Default::default(), None).unwrap();
    let z = Zioma::new(&t, ZiomaParams::default());
    let gpu_wind = GpuWind::from_scene(ctx, &wind).unwrap();
    let mut gpu = GpuZioma::with_instances(ctx, Arc::new(t.clone()), z.clone(), &gpu_wind, instances).unwrap();
    let mut s = z.rest_state(&t);
    z.set_instances(&t, &mut s, instances);
    for _ in 0..300 {
        z.step(&t, &fw, &mut s, 1.0 / 60.0);
    }
    gpu.advance(ctx, 1.0 / 60.0, 300);
    gpu.set_wind(&GpuWind::calm(ctx).unwrap());
    for _ in 0..60 {
        z.step(&t, &calm, &mut s, 1.0 / 60.0);
    }
    gpu.advance(ctx, 1.0 / 60.0, 60);
    assert_eq!(gpu.time, s.time);
    (t, z, s, gpu)
}

/// When the wind stops, the GPU's trunk rings down as the CPU's state does (`set_wind` starts
/// the same ring): a second into the calm the poses agree within 1e-4 × height, and the tree
/// is still moving.
#[test]
fn zioma_rings_down_on_the_gpu_as_on_the_cpu_when_the_wind_stops() {
    use sylva_core::methods::Method;
    let Some(ctx) = common::gpu() else { return };
    let (t, z, s, mut gpu) = gusty_then_calm(ctx, &[]);
    let cpu = z.pose(&t, &sylva_core::wind::PackedWind::calm(), &s);
    compare(&t, &cpu, &gpu.pose(ctx, s.time).unwrap(), "a second into the calm");
    assert_ne!(cpu, Pose::rest(&t), "the trunk does not ring");
}

/// A forest's copies each ring down by their own ring on the GPU as on the CPU (the
/// instances registered with `set_instances`): a second after the gusty wind stops, every
/// instance's pose agrees within 1e-4 × height, and the copies still move, each its own way.
#[test]
fn zioma_instances_ring_down_on_the_gpu_as_on_the_cpu() {
    use sylva_core::methods::Method;
    use sylva_core::methods::zioma::ZiomaInstance;
    use sylva_core::pose::SeamPose;
    let Some(ctx) = common::gpu() else { return };
    let instances = ZiomaInstance::grid(9, 40.0, 5);
    let (t, z, s, mut gpu) = gusty_then_calm(ctx, &instances);
    let mut seam = SeamPose::default();
    assert!(z.seam_instances(&t, &sylva_core::wind::PackedWind::calm(), &s, &instances, &mut seam));
    let got = gpu.poses(ctx, s.time).unwrap();
    for (k, g) in got.iter().enumerate() {
        let cpu = seam.pose(&t, k);
        compare(&t, &cpu, g, &format!("instance {k}, a second into the calm"));
        assert_ne!(cpu, Pose::rest(&t), "instance {k} does not ring");
    }
    assert_ne!(got[0].start, got[1].start, "the copies ring alike");
}

/// `reset` returns the GPU's copies to rest as the CPU's `reset` returns its state: in
/// still air every copy is at rest bit for bit at once (they were ringing), and when the gusty
/// wind then starts over from the reset time, the copies follow the CPU's within 1e-4 ×
/// height half a second later.
#[test]
fn zioma_reset_on_the_gpu_forgot_its_rings() {
    use sylva_core::methods::Method;
    use sylva_core::methods::zioma::ZiomaInstance;
    use sylva_core::pose::SeamPose;
    use sylva_gpu::methods::GpuAnimator;
    let Some(ctx) = common::gpu() else { return };
    let instances = ZiomaInstance::grid(9, 40.0, 5);
    let (t, z, s, mut gpu) = gusty_then_calm(ctx, &instances);
    let at = s.time;
    assert!(gpu.poses(ctx, at).unwrap().iter().any(|p| *p != Pose::rest(&t)), "nothing rang before the reset");
    gpu.reset(ctx, at);
    for (k, p) in gpu.poses(ctx, at).unwrap().iter().enumerate() {
        assert_eq!(*p, Pose::rest(&t), "instance {k} still rings after the reset");
    }
    let wind = WindScene::resolve("gusty").unwrap();
    let fw = wind.packed();
    gpu.set_wind(&GpuWind::from_scene(ctx, &wind).unwrap());
    gpu.reset(ctx, at);
    let mut cpu = z.rest_state(&t);
    z.set_time(&mut cpu, at);
    z.set_instances(&t, &mut cpu, &instances);
    for _ in 0..30 {
        z.step(&t, &fw, &mut cpu, 1.0 / 60.0);
    }
    gpu.advance(ctx, 1.0 / 60.0, 30);
    assert_eq!(gpu.time, cpu.time);
    let mut seam = SeamPose::default();
    assert!(z.seam_instances(&t, &fw, &cpu, &instances, &mut seam));
    for (k, g) in gpu.poses(ctx, cpu.time).unwrap().iter().enumerate() {
        compare(&t, &seam.pose(&t, k), g, &format!("instance {k}, half a second after the reset"));
    }
}

#[test]
fn zioma_on_the_gpu_is_at_rest_in_still_air() {
    let Some(ctx) = common::gpu() else { return };
    let t = SpeciesSource::resolve("quaking_aspen").unwrap().generate(1, &Default::default(), None).unwrap();
    let z = Zioma::new(&t, ZiomaParams::default());
    let mut gpu = GpuZioma::new(ctx, Arc::new(t.clone()), z.clone(), &GpuWind::calm(ctx).unwrap()).unwrap();
    assert_eq!(gpu.pose(ctx, 5.0).unwrap(), Pose::rest(&t));
}

/// Instancing (§6.5): many placed, turned, phase-shifted copies of one tree in one dispatch.
/// GPU vs CPU per instance within 1e-4 × height; an instance at the origin, unturned, with no
/// phase or seed reproduces the single tree exactly; instances at different places differ.
#[test]
fn zioma_instances_match_and_sway_independently() {
    use sylva_core::methods::zioma::ZiomaInstance;
    let Some(ctx) = common::gpu() else { return };
    let wind = WindScene::resolve("gusty").unwrap();
    let fw = wind.packed();
    let t = SpeciesSource::resolve("stochastic_bush").unwrap().generate(4, &Default::default(), None).unwrap();
    let z = Zioma::new(&t, ZiomaParams::default());
    let mut instances = ZiomaInstance::grid(37, 6.0, 9);
    instances[0] = ZiomaInstance::default();
    let mut gpu = GpuZioma::with_instances(
        ctx,
        Arc::new(t.clone()),
        z.clone(),
        &GpuWind::from_scene(ctx, &wind).unwrap(),
        &instances,
    )
    .unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(13);
    for _ in 0..3 {
        let time = rng.random_range(0.0..60.0);
        let cpu =
            Pose::from_rotations_instances(&t, &z.rotations_instances(&t, &fw.fields, &fw.waves, time, &instances));
        let got = gpu.poses(ctx, time).unwrap();
        assert_eq!(cpu.len(), instances.len());
        assert_eq!(got.len(), instances.len());
        for (k, (a, b)) in cpu.iter().zip(&got).enumerate() {
            compare(&t, a, b, &format!("instance {k} at {time} s"));
        }
        assert_eq!(cpu[0], z.pose_at(&t, &wind.packed(), time), "an instance at the origin is the single tree");
        let distinct = cpu.windows(2).filter(|p| p[0].start != p[1].start).count();
        assert!(distinct >= instances.len() - 2, "instances sway alike: {distinct} differ");
    }
}

/// The frame kernel (`zioma_frames.wgsl`) against its CPU twin, on every wind preset, three
/// trees, random instances (±300 m, any yaw), each with its own random ring (or none; three
/// in ten of the rest begun within the last 10 ms) and random times up to 600 s.
/// Tolerances: the lean direction within 2e-4 rad, the trunk angles within 1e-5 rad and
/// their rate within 1e-3 rad/s, each plus how far the CPU's own value moves when the time
/// moves by two f32 ulps (as [`time_rounding_allowance`]: a GPU that fuses `ω t + φ` rounds
/// the wind's phases differently); the heading within 1e-6, the rest of the record bit for
/// bit. Lavapipe, 2026-12-06: 4.6e-5 rad, 1.0e-7 rad and 1.6e-3 rad/s at worst (the rate of a
/// ring begun within 10 ms, differenced over a span of 10–20 ms at t ≈ 573 s, where an f32
/// ulp of time is 61 µs: inside the allowance, 1.5e-3 to 8.5e-3 rad/s there).
#[test]
fn zioma_frames_match_their_cpu_twin() {
    use sylva_core::methods::zioma::frames::zioma_frames;
    use sylva_core::methods::zioma::{RawZiomaFrame, RawZiomaInstance, RawZiomaRing, Ring};
    let Some(ctx) = common::gpu() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(31);
    let mut worst = [0.0f32; 3];
    for (name, _, _) in sylva_core::wind::PRESETS {
        let wind = WindScene::resolve(name).unwrap();
        let packed = wind.packed();
        let gpu_wind = GpuWind::from_scene(ctx, &wind).unwrap();
        for species in ["quaking_aspen", "stochastic_bush", "palm"] {
            let t = SpeciesSource::resolve(species).unwrap().generate(rng.random(), &Default::default(), None).unwrap();
            let z = Zioma::new(&t, ZiomaParams { seed: rng.random(), ..Default::default() });
            let instances: Vec<RawZiomaInstance> = (0..97)
                .map(|_| RawZiomaInstance {
                    position: [rng.random_range(-300.0..300.0), 0.0, rng.random_range(-300.0..300.0)],
                    yaw: rng.random_range(0.0..std::f32::consts::TAU),
                    phase: rng.random(),
                    seed: rng.random(),
                    _pad: [0; 2],
                })
                .collect();
            for round in 0..3 {
                let time = rng.random_range(0.0..600.0);
                let rings: Vec<RawZiomaRing> = (0..instances.len())
                    .map(|_| {
                        if round == 0 || rng.random_bool(0.2) {
                            return RawZiomaRing::from(&Ring::default());
                        }
                        let v = |rng: &mut rand::rngs::StdRng, s: f32| {
                            Vec3::new(rng.random_range(-s..s), 0.0, rng.random_range(-s..s))
                        };
                        RawZiomaRing::from(&Ring {
                            bend: v(&mut rng, 0.1),
                            rate: v(&mut rng, 0.5),
                            // Three in ten begun within the rate's 10 ms reach, which it does
                            // not difference back past.
                            since: time
                                - if rng.random_bool(0.3) {
                                    rng.random_range(0.0..0.01)
                                } else {
                                    rng.random_range(0.0..10.0)
                                },
                            zeta: rng.random_range(0.02..0.3),
                        })
                    })
                    .collect();
                let cpu_at = |time: f32| {
                    let mut out = vec![<RawZiomaFrame as bytemuck::Zeroable>::zeroed(); instances.len()];
                    zioma_frames(&packed.fields, &packed.waves, &[z.raw_trunk(time)], &instances, &rings, &mut out);
                    out
                };
                let cpu = cpu_at(time);
                let dt = 2.0 * time * 2f32.powi(-23);
                let (early, late) = (cpu_at(time - dt), cpu_at(time + dt));
                let gpu = sylva_gpu::methods::zioma::frames::zioma_frames(
                    ctx,
                    &gpu_wind,
                    &z.raw_trunk(time),
                    &instances,
                    &rings,
                )
                .unwrap();
                for (k, (a, b)) in cpu.iter().zip(&gpu).enumerate() {
                    let what = format!("{name}, {species}, instance {k}, t = {time} s, ring {:?}", rings[k]);
                    let spread =
                        |f: &dyn Fn(&RawZiomaFrame) -> f32| (f(a) - f(&early[k])).abs().max((f(a) - f(&late[k])).abs());
                    let dir = |f: &RawZiomaFrame| Vec3::from_array(f.wind_dir);
                    // The chord between unit vectors: acos near 1 cannot resolve 1e-4 rad in f32.
                    let turn = (dir(a) - dir(b)).length();
                    let allowed = (dir(a) - dir(&early[k])).length().max((dir(a) - dir(&late[k])).length());
                    assert!(turn.is_finite() && turn <= 2e-4 + allowed, "{what}: lean {turn} rad apart");
                    worst[0] = worst[0].max(turn);
                    for axis in 0..3 {
                        let d = (a.trunk[axis] - b.trunk[axis]).abs();
                        let bound = 1e-5 + spread(&|f| f.trunk[axis]);
                        assert!(d <= bound, "{what}: trunk angle {axis}: {} vs {}", a.trunk[axis], b.trunk[axis]);
                        worst[1] = worst[1].max(d);
                    }
                    let d = (a.trunk_rate - b.trunk_rate).abs();
                    assert!(d <= 1e-3 + spread(&|f| f.trunk_rate), "{what}: rate {} vs {}", a.trunk_rate, b.trunk_rate);
                    worst[2] = worst[2].max(d);
                    let rest =
                        |f: &RawZiomaFrame| (f.time, f.lod, f.amplitude, f.max_bend, f.inertia, f.origin, f.phase);
                    assert_eq!(rest(a), rest(b), "{what}");
                    for h in 0..2 {
                        assert!(
                            (a.heading[h] - b.heading[h]).abs() <= 1e-6,
                            "{what}: heading {:?} vs {:?}",
                            a.heading,
                            b.heading
                        );
                    }
                }
            }
        }
    }
    println!(
        "zioma frames: worst lean {:.1e} rad, trunk angle {:.1e} rad, rate {:.1e} rad/s",
        worst[0], worst[1], worst[2]
    );
}
