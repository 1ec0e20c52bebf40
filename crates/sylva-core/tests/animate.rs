//! The pose seam and Zioma's method.

use glam::{Quat, Vec3};
use sylva_core::methods::zioma::{Lod, Zioma, ZiomaParams};
use sylva_core::pose::{Pose, displacement};
use sylva_core::species::{PRESETS, SpeciesSource};
use sylva_core::wind::{Constant, WindField, WindScene};
use sylva_core::{Grammar, LSystemOptions, Tree};

fn tree(name: &str) -> Tree {
    SpeciesSource::resolve(name).unwrap().generate(3, &Default::default(), None).unwrap()
}

fn constant(speed: f32, dir: [f32; 3]) -> WindScene {
    WindScene { fields: vec![WindField::Constant(Constant { direction: dir, speed })] }
}

#[test]
fn identity_rotations_give_exactly_the_rest_pose() {
    for p in PRESETS {
        let t = SpeciesSource::from_preset(p).unwrap().generate(1, &Default::default(), None).unwrap();
        let pose = Pose::from_rotations(&t, &vec![[0.0, 0.0, 0.0, 1.0]; t.segments.len()]);
        assert_eq!(pose, Pose::rest(&t), "{}", p.name);
    }
}

#[test]
fn forward_kinematics_matches_a_hand_computed_chain() {
    // Three unit segments straight up; the root turns 90° about +Z, the second a further
    // 90°: joints at (0,0,0), (0,1,0)→(−1,0,0), (0,2,0)→(−1,0,0)+(0,−1,0)... by hand:
    // root rotated: segment 0 points along −X, joint 1 at (−1, 0, 0); segment 1 turned by
    // 180° in total points along −Y, joint 2 at (−1, −1, 0); segment 2 follows: tip (−1, −2, 0).
    let t = Grammar::parse("axiom: FFF\n", "c.lsys").unwrap().generate(&LSystemOptions::default()).unwrap();
    let q = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2).to_array();
    let id = [0.0, 0.0, 0.0, 1.0];
    let pose = Pose::from_rotations(&t, &[q, q, id]);
    let close = |a: Vec3, b: Vec3| assert!((a - b).length() < 1e-5, "{a} vs {b}");
    close(pose.start[0], Vec3::ZERO);
    close(pose.start[1], Vec3::new(-1.0, 0.0, 0.0));
    close(pose.start[2], Vec3::new(-1.0, -1.0, 0.0));
    close(pose.end(&t, 2), Vec3::new(-1.0, -2.0, 0.0));
}

/// Random unit rotations of up to about 0.3 rad, one per segment and instance.
fn random_rotations(n: usize, seed: u64) -> Vec<[f32; 4]> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let axis = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            Quat::from_axis_angle(axis.try_normalize().unwrap_or(Vec3::Y), rng.random_range(-0.3..0.3)).to_array()
        })
        .collect()
}

#[test]
fn one_pass_forward_kinematics_matches_the_gpu_kernels_twins() {
    use sylva_core::pose::fk::{
        depth_buckets, jump_ancestors, pose_accumulate, pose_forward, pose_jump, pose_level, pose_positions,
        positions_forward,
    };
    let deep = Grammar::parse("iterations: 900\naxiom: A\nA -> F/(37)&(1)A\n", "stem.lsys")
        .unwrap()
        .generate(&LSystemOptions::default())
        .unwrap();
    for (name, t, instances) in [("aspen", tree("quaking_aspen"), 3), ("900-segment stem", deep, 1)] {
        let n = t.segments.len();
        let parent = &t.segments.parent;
        let rest: Vec<[f32; 4]> = t.segments.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        let delta = random_rotations(n * instances, 7);
        let (mut acc, mut joints) = (vec![[0.0f32; 4]; n * instances], vec![[0.0f32; 4]; n * instances]);
        pose_forward(parent, &rest, &delta, &mut acc, &mut joints);
        // Level by level (pose_level.wgsl's twin) does the same arithmetic: bit for bit.
        for k in 0..instances {
            let r = k * n..(k + 1) * n;
            let (mut la, mut ld, mut lj) = (vec![[0.0f32; 4]; n], vec![[0.0f32; 4]; n], vec![[0.0f32; 4]; n]);
            for b in depth_buckets(parent) {
                pose_level(&b, parent, &rest, &delta[r.clone()], &mut la, &mut ld, &mut lj);
            }
            assert_eq!(la, acc[r.clone()], "{name}: rotations, instance {k}");
            assert_eq!(lj, joints[r.clone()], "{name}: joints, instance {k}");
        }
        // The ancestor walks multiply in another order: equal to rounding. Tolerance: 1e-5 of
        // the tree's height per joint and 1e-5 per quaternion component, over a chain of up
        // to 900 rotations.
        let (mut wa, mut wj) = (vec![[0.0f32; 4]; n * instances], vec![[0.0f32; 4]; n * instances]);
        pose_accumulate(parent, &delta, &mut wa);
        pose_positions(parent, &rest, &wa, &mut wj);
        let height = t.stats().height.max(1.0);
        for i in 0..n * instances {
            let dq = (Quat::from_array(acc[i]).dot(Quat::from_array(wa[i])).abs() - 1.0).abs();
            assert!(dq < 1e-5, "{name}: segment {i}: rotations differ by {dq}");
            let dj = (Vec3::from_slice(&joints[i][..3]) - Vec3::from_slice(&wj[i][..3])).length();
            assert!(dj < 1e-5 * height * (1.0 + n as f32 / 100.0), "{name}: segment {i}: joints differ by {dj} m");
        }
        // Positions from given rotations (HSM's path) match the full pass.
        let mut pj = vec![[0.0f32; 4]; n * instances];
        positions_forward(parent, &rest, &acc, &mut pj);
        assert_eq!(pj, joints, "{name}: positions_forward");
        // Pointer jumping (the deep-hierarchy GPU kernels' twins): ⌈log₂(depth + 1)⌉ rounds,
        // each pointer twice as far up, and the same pose to the walks' tolerance.
        let rounds = jump_ancestors(parent);
        let depth = depth_buckets(parent).len() - 1;
        assert_eq!(rounds.len(), (depth + 1).next_power_of_two().trailing_zeros() as usize, "{name}: rounds");
        let (mut ja, mut jj) = (vec![[0.0f32; 4]; n * instances], vec![[0.0f32; 4]; n * instances]);
        pose_jump(&rounds, parent, &rest, &delta, &mut ja, &mut jj);
        for i in 0..n * instances {
            let dq = (Quat::from_array(acc[i]).dot(Quat::from_array(ja[i])).abs() - 1.0).abs();
            assert!(dq < 1e-5, "{name}: segment {i}: jumped rotations differ by {dq}");
            let dj = (Vec3::from_slice(&joints[i][..3]) - Vec3::from_slice(&jj[i][..3])).length();
            assert!(
                dj < 1e-5 * height * (1.0 + n as f32 / 100.0),
                "{name}: segment {i}: jumped joints differ by {dj} m"
            );
        }
        let identity = vec![[0.0f32, 0.0, 0.0, 1.0]; n * instances];
        pose_jump(&rounds, parent, &rest, &identity, &mut ja, &mut jj);
        assert!(jj.chunks(n).all(|c| c == rest.as_slice()), "{name}: identity rotations give the rest joints exactly");
    }
}

/// Pointer jumping's ancestor lists: round k points 2^k levels up, or nowhere past the root.
#[test]
fn pointer_jumping_points_twice_as_far_each_round() {
    use sylva_core::model::NONE;
    let t = tree("weeping_willow");
    let parent = &t.segments.parent;
    let up = |mut i: u32, levels: usize| {
        for _ in 0..levels {
            if i == NONE {
                break;
            }
            i = parent[i as usize];
        }
        i
    };
    let rounds = sylva_core::pose::fk::jump_ancestors(parent);
    assert!(rounds.len() >= 5, "the willow is more than 16 levels deep");
    for (k, anc) in rounds.iter().enumerate() {
        for (i, &a) in anc.iter().enumerate() {
            assert_eq!(a, up(i as u32, 1 << k), "round {k}, segment {i}");
        }
    }
    assert!(rounds.last().unwrap().iter().any(|&a| a != NONE), "no round is spent on nothing");
}

#[test]
fn zioma_in_still_air_is_exactly_at_rest() {
    for p in PRESETS {
        let t = SpeciesSource::from_preset(p).unwrap().generate(2, &Default::default(), None).unwrap();
        let z = Zioma::new(&t, ZiomaParams::default());
        for time in [0.0, 3.7, 1000.0] {
            assert_eq!(z.pose_at(&t, &WindScene::default().packed(), time), Pose::rest(&t), "{} at {time}", p.name);
        }
    }
}

/// Mean crown displacement over many times, in constant wind.
fn mean_crown_shift(t: &Tree, z: &Zioma, wind: &WindScene) -> Vec3 {
    (0..24).map(|k| displacement(t, &z.pose_at(t, &wind.packed(), 0.37 * k as f32)).crown_mean).sum::<Vec3>() / 24.0
}

#[test]
fn zioma_leans_downwind_more_as_the_wind_rises() {
    for name in ["quaking_aspen", "black_tupelo", "monopodial"] {
        let t = tree(name);
        let z = Zioma::new(&t, ZiomaParams::default());
        for dir in [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.6, 0.0, 0.8]] {
            let w = Vec3::from_array(dir).normalize();
            let mut last = 0.0;
            for speed in [2.0, 5.0, 10.0, 20.0] {
                let shift = mean_crown_shift(&t, &z, &constant(speed, dir));
                let along = shift.dot(w);
                let across = (shift - w * along).with_y(0.0).length();
                assert!(along > last, "{name} {dir:?}: {along} at {speed} m/s after {last}");
                assert!(across < 0.5 * along, "{name}: mean shift not downwind ({shift})");
                last = along;
            }
        }
    }
}

#[test]
fn zioma_is_stateless_and_thread_independent() {
    let t = tree("black_tupelo");
    let wind = WindScene::resolve("gusty").unwrap();
    let z = Zioma::new(&t, ZiomaParams::default());
    let fresh = Zioma::new(&t, ZiomaParams::default()).pose_at(&t, &wind.packed(), 12.5);
    for k in 0..20 {
        z.pose_at(&t, &wind.packed(), k as f32 * 0.9);
    }
    assert_eq!(z.pose_at(&t, &wind.packed(), 12.5), fresh);
    let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap();
    let one = pool(1).install(|| z.pose_at(&t, &wind.packed(), 7.25));
    let three = pool(3).install(|| z.pose_at(&t, &wind.packed(), 7.25));
    assert_eq!(one, three);
    assert_ne!(z.pose_at(&t, &wind.packed(), 7.25), z.pose_at(&t, &wind.packed(), 7.5), "the tree does not move");
}

/// Zioma is stateless, so 100,000 steps at 60 Hz (1,667 s) are covered by poses at times
/// spread over that span; none may break the skeleton.
#[test]
fn zioma_in_a_40_m_per_s_gusty_storm_stays_sound() {
    let mut wind = WindScene::resolve("gusty").unwrap();
    if let WindField::Constant(c) = &mut wind.fields[0] {
        c.speed = 40.0;
    }
    for name in ["quaking_aspen", "weeping_willow", "palm", "ternary"] {
        let t = tree(name);
        let z = Zioma::new(&t, ZiomaParams::default());
        for k in 0..40 {
            let time = k as f32 * (100_000.0 / 60.0 / 40.0) + 0.123;
            let pose = z.pose_at(&t, &wind.packed(), time);
            if let Err(e) = pose.check_sound(&t) {
                panic!("{name} at {time}: {e}");
            }
        }
    }
}

#[test]
fn trunk_only_lod_moves_branches_rigidly() {
    let t = tree("quaking_aspen");
    let wind = constant(15.0, [1.0, 0.0, 0.0]);
    let z = Zioma::new(&t, ZiomaParams { lod: Lod::TrunkOnly, ..Default::default() });
    let d = z.rotations(&t, &wind, 4.0);
    for (di, level) in d.iter().zip(&t.segments.level) {
        if *level > 0 {
            assert_eq!(*di, [0.0, 0.0, 0.0, 1.0]);
        }
    }
    let full = Zioma::new(&t, ZiomaParams::default()).rotations(&t, &wind, 4.0);
    assert!((0..t.segments.len()).any(|i| t.segments.level[i] > 0 && full[i] != [0.0, 0.0, 0.0, 1.0]));
    // The trunk moves the same way in both.
    let pose = z.pose_at(&t, &wind.packed(), 4.0);
    assert!(displacement(&t, &pose).max[0] > 0.0);
}

/// Zioma's instances once shared the tree's ring, taken at its own crown: when the wind
/// changed, every copy where the wind differs (a forest's) jumped by the difference between
/// its wind's answer and the crown's. Each registered instance keeps its own ring, taken at
/// its own crown, so its trunk's lean and bands are continuous across a change (here the
/// gusty wind stopping at 3 s, then a steady 8 m/s wind starting a second later while the
/// trunks still ring), within 1e-5 rad; with the tree's ring they jump by more than 1e-3 rad
/// somewhere in the grid, so the check can fail.
#[test]
fn zioma_instances_jumped_when_the_wind_changed() {
    use sylva_core::methods::Method;
    use sylva_core::methods::zioma::{RawZiomaFrame, ZiomaInstance};
    use sylva_core::wind::PackedWind;
    let t = tree("quaking_aspen");
    let z = Zioma::new(&t, ZiomaParams::default());
    let gusty = WindScene::resolve("gusty").unwrap().packed();
    let winds = [PackedWind::calm(), constant(8.0, [0.3, 0.0, 1.0]).packed()];
    let instances = ZiomaInstance::grid(16, 40.0, 3);
    let mut s = z.rest_state(&t);
    z.set_instances(&t, &mut s, &instances);
    for _ in 0..180 {
        z.step(&t, &gusty, &mut s, 1.0 / 60.0);
    }
    let lean = |f: &RawZiomaFrame| Vec3::from_array(f.wind_dir) * f.trunk[0];
    let mut old_wind = gusty;
    for new_wind in winds {
        let (change, before) = (s.time, s.rings.clone());
        assert_eq!(before.len(), instances.len());
        z.step(&t, &new_wind, &mut s, 1.0 / 60.0);
        let old = z.frames_for(&old_wind.fields, &old_wind.waves, change, &instances, &before);
        let new = z.frames_for(&new_wind.fields, &new_wind.waves, change, &instances, &s.rings);
        let shared = vec![s.ring; instances.len()];
        let shared = z.frames_for(&new_wind.fields, &new_wind.waves, change, &instances, &shared);
        let (mut worst, mut worst_shared) = (0.0f32, 0.0f32);
        for k in 0..instances.len() {
            let jump = (lean(&old[k]) - lean(&new[k])).length();
            let bands = (0..3).map(|a| (old[k].trunk[a] - new[k].trunk[a]).abs()).fold(0.0, f32::max);
            assert!(jump <= 1e-5 && bands <= 1e-5, "{change} s, instance {k}: the trunk jumps {jump} rad ({bands})");
            assert!(lean(&old[k]).length() > 1e-3, "{change} s, instance {k} does not lean");
            worst = worst.max(jump);
            worst_shared = worst_shared.max((lean(&old[k]) - lean(&shared[k])).length());
        }
        println!("change at {change} s: worst jump {worst:.1e} rad; with the tree's ring {worst_shared:.1e} rad");
        assert!(worst_shared > 1e-3, "the tree's ring would do as well ({worst_shared} rad): the check cannot fail");
        for _ in 0..59 {
            z.step(&t, &new_wind, &mut s, 1.0 / 60.0);
        }
        old_wind = new_wind;
    }
}
