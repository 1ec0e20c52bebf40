//! Skjermo's Bézier bending.

use glam::Vec3;
use sylva_core::Tree;
use sylva_core::methods::Method;
use sylva_core::methods::skjermo::lanes::{StateLanes, SwayLanes};
use sylva_core::methods::skjermo::{Skjermo, SkjermoParams, SkjermoState};
use sylva_core::pose::{Pose, displacement};
use sylva_core::species::{PRESETS, SpeciesSource};
use sylva_core::wind::{Constant, WindField, WindScene};

fn tree(name: &str) -> Tree {
    SpeciesSource::resolve(name).unwrap().generate(2, &Default::default(), None).unwrap()
}

fn constant(speed: f32) -> WindScene {
    WindScene { fields: vec![WindField::Constant(Constant { direction: [1.0, 0.0, 0.0], speed })] }
}

#[test]
fn still_air_keeps_the_exact_rest_pose_and_curves() {
    for p in PRESETS {
        let t = SpeciesSource::from_preset(p).unwrap().generate(1, &Default::default(), None).unwrap();
        let m = Skjermo::new(&t, SkjermoParams::default());
        let mut s = m.rest_state(&t);
        let fw = WindScene::default().packed();
        for _ in 0..5 {
            m.step(&t, &fw, &mut s, 1.0 / 60.0);
        }
        assert_eq!(s.pose.start, Pose::rest(&t).start, "{}", p.name);
        assert_eq!(s.pose.orientation, Pose::rest(&t).orientation, "{}", p.name);
        assert_eq!(s.pose.bezier.as_ref().unwrap(), &t.stems.bezier, "{}", p.name);
    }
}

/// The rest orientations are a fixed point of one level of `skjermo_rest_orient` (what the
/// GPU runs to round them as it rounds its steps): applied depth + 1 times from zeros it
/// gives `Skjermo::rest_orient` bit for bit, and fewer times does not (so the depth is
/// needed and counted right).
#[test]
fn the_rest_orientation_kernel_rebuilds_the_rest_orientations() {
    use sylva_core::methods::skjermo::kernels::{skjermo_rest_orient, stem_depth};
    for p in PRESETS {
        let t = SpeciesSource::from_preset(p).unwrap().generate(1, &Default::default(), None).unwrap();
        let m = Skjermo::new(&t, SkjermoParams::default());
        let depth = stem_depth(&m.stems);
        let mut a = vec![[0.0f32; 4]; m.stems.len()];
        let mut b = a.clone();
        for level in 0..=depth {
            if level == depth && depth > 0 {
                assert_ne!(a, m.rest_orient, "{}: converged before the deepest level", p.name);
            }
            skjermo_rest_orient(&m.stems, &a, &mut b);
            std::mem::swap(&mut a, &mut b);
        }
        assert_eq!(a, m.rest_orient, "{}", p.name);
    }
}

#[test]
fn constant_wind_bends_downwind_more_as_it_rises() {
    for name in ["quaking_aspen", "monopodial"] {
        let t = tree(name);
        let m = Skjermo::new(&t, SkjermoParams::default());
        let mut last = 0.0;
        for speed in [2.0, 5.0, 10.0, 20.0] {
            let fw = constant(speed).packed();
            let mut s = m.rest_state(&t);
            for _ in 0..30 {
                m.step(&t, &fw, &mut s, 1.0 / 60.0);
            }
            let shift = displacement(&t, &s.pose).crown_mean;
            assert!(shift.x > last, "{name} {speed} m/s: {shift} after {last}");
            assert!(shift.z.abs() < 0.3 * shift.x, "{name}: {shift}");
            last = shift.x;
            // Control polygons keep their lengths (eq. 17).
            let b = s.pose.bezier.as_ref().unwrap();
            for (k, (bk, rk)) in b.iter().zip(&t.stems.bezier).enumerate() {
                for j in 1..4 {
                    let rest = (rk[j] - rk[j - 1]).length();
                    let now = (bk[j] - bk[j - 1]).length();
                    assert!((now - rest).abs() <= 1e-4 * rest.max(1e-3), "{name} stem {k} leg {j}: {rest} → {now}");
                }
            }
        }
    }
}

/// A stem re-attaches to its parent's curve of the previous step, so the trunk's motion
/// reaches level d one step after level d − 1: with only the trunk catching the wind, the
/// base of level d first moves in step d + 1 (the trunk bends in step 1).
#[test]
fn each_level_lags_one_step_behind_its_parent() {
    let t = tree("black_tupelo");
    let mut m = Skjermo::new(&t, SkjermoParams::default());
    for (k, st) in m.stems.iter_mut().enumerate() {
        if t.stems.level[k] > 0 {
            st.drag = 0.0;
        }
    }
    m.rebuild_lanes();
    let fw = constant(12.0).packed();
    let mut s = m.rest_state(&t);
    let levels = t.levels as usize;
    let mut first_move = vec![None; levels];
    for step in 1..=8u64 {
        m.step(&t, &fw, &mut s, 1.0 / 60.0);
        let b = s.pose.bezier.as_ref().unwrap();
        for (k, bk) in b.iter().enumerate() {
            let l = t.stems.level[k] as usize;
            if l > 0 && first_move[l].is_none() && bk[0] != t.stems.bezier[k][0] {
                first_move[l] = Some(step);
            }
        }
    }
    for (l, f) in first_move.iter().enumerate().skip(1) {
        assert_eq!(*f, Some(l as u64 + 1), "level {l} base first moved at {f:?}");
    }
}

#[test]
fn a_100_000_step_storm_stays_sound_and_threads_do_not_matter() {
    let t = tree("stochastic_bush");
    let mut wind = WindScene::resolve("gusty").unwrap();
    if let WindField::Constant(c) = &mut wind.fields[0] {
        c.speed = 40.0;
    }
    let fw = wind.packed();
    let m = Skjermo::new(&t, SkjermoParams::default());
    let mut s = m.rest_state(&t);
    for k in 0..100_000 {
        m.step(&t, &fw, &mut s, 1.0 / 60.0);
        if k % 10_000 == 0 || k == 99_999 {
            if let Err(e) = s.pose.check_sound(&t) {
                panic!("step {k}: {e}");
            }
            assert!(s.pose.bezier.as_ref().unwrap().iter().flatten().all(|p: &Vec3| p.is_finite()));
        }
    }
    let t = tree("quaking_aspen");
    let m = Skjermo::new(&t, SkjermoParams::default());
    let run = |n| {
        rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap().install(|| {
            let mut s = m.rest_state(&t);
            for _ in 0..40 {
                m.step(&t, &fw, &mut s, 1.0 / 60.0);
            }
            s
        })
    };
    assert_eq!(run(1), run(3));
}

/// The fast path (sixteen stems per lane group, folded constants, polynomial sine) against the
/// reference kernel (the WGSL's twin): the same step to rounding. Tolerance: 1e-5 × tree
/// height per control point after 300 steps of a gusty wind (turbulence and gust fields go
/// through the per-lane fallback) and of the paper's four sines (the lane-parallel wind).
#[test]
fn the_lane_path_matches_the_reference_kernel() {
    let sines = WindScene::from_toml(
        "[[field]]\nkind = \"sum_of_sines\"\nsharpness = 2.0\nwaves = [\n\
         { amplitude = 14.0, direction_deg = 10.0, wavelength = 30.0, speed = 6.0 },\n\
         { amplitude = 7.0, direction_deg = 40.0, wavelength = 11.0, speed = 4.0 },\n\
         { amplitude = 2.0, direction_deg = -30.0, wavelength = 7.0, speed = 3.0 },\n]\n",
        "sines.toml",
    )
    .unwrap();
    for (wname, wind) in [("gusty", WindScene::resolve("gusty").unwrap()), ("sines", sines)] {
        let fw = wind.packed();
        for p in PRESETS {
            let t = SpeciesSource::from_preset(p).unwrap().generate(3, &Default::default(), None).unwrap();
            let m = Skjermo::new(&t, SkjermoParams::default());
            let mut fast = m.rest_state(&t);
            let mut slow = m.rest_state(&t);
            for _ in 0..300 {
                m.step(&t, &fw, &mut fast, 1.0 / 60.0);
                m.step_reference(&fw.fields, &fw.waves, &mut slow, 1.0 / 60.0);
            }
            let tol = 1e-5 * t.height();
            curves_match(&fast, &slow, tol, &format!("{wname} {}", p.name));
            // The bend oscillators (updated in place on the lanes, ping-pong in the reference).
            let v = |a: &[f32; 4]| Vec3::from_slice(&a[..3]);
            let (mut bent, mut worst_rate) = (0.0f32, 0.0f32);
            for (k, (a, b)) in fast.sway.iter().zip(&slow.sway).enumerate() {
                bent = bent.max(v(&b.bend).length());
                assert!((v(&a.bend) - v(&b.bend)).length() <= tol, "{wname} {} stem {k} bend", p.name);
                worst_rate = worst_rate.max((v(&a.rate) - v(&b.rate)).length());
            }
            assert!(bent > 10.0 * tol, "{wname} {}: the oscillators should move ({bent})", p.name);
            // A rate is a bend's difference over a step: 60 × the bend's tolerance.
            assert!(worst_rate <= 60.0 * tol, "{wname} {}: rates differ by {worst_rate}", p.name);
        }
    }
}

/// The published form (eq. 16 as printed: the bend follows the wind at once) never touches
/// the bend oscillators, which the lane step updates in place: after 120 steps of `gusty`
/// they are at rest on both paths while the tree has moved, and the lane path matches the
/// reference within the same tolerance as the default form's.
#[test]
fn the_published_form_leaves_the_bend_oscillators_at_rest() {
    let fw = WindScene::resolve("gusty").unwrap().packed();
    let t = tree("quaking_aspen");
    let m = Skjermo::new(&t, SkjermoParams { dynamics: false, ..SkjermoParams::default() });
    let mut fast = m.rest_state(&t);
    let mut slow = m.rest_state(&t);
    for _ in 0..120 {
        m.step(&t, &fw, &mut fast, 1.0 / 60.0);
        m.step_reference(&fw.fields, &fw.waves, &mut slow, 1.0 / 60.0);
    }
    let rest = m.rest_state(&t);
    assert!(fast.sway == rest.sway && slow.sway == rest.sway && fast.sway_lanes == rest.sway_lanes);
    curves_match(&fast, &slow, 1e-5 * t.height(), "the published form");
}

/// Asserts that the lane path's control-point displacements (`fast`) are within `tol` of
/// the reference kernel's (`slow`), and that the wind moved the reference by more than ten
/// times that.
fn curves_match(fast: &SkjermoState, slow: &SkjermoState, tol: f32, what: &str) {
    let mut moved = 0.0f32;
    for (k, (a, b)) in fast.stems.iter().zip(&slow.stems).enumerate() {
        for j in 0..4 {
            let (da, db) = (Vec3::from_slice(&a.delta[j][..3]), Vec3::from_slice(&b.delta[j][..3]));
            moved = moved.max(db.length());
            assert!((da - db).length() <= tol, "{what} stem {k} P{j}: {da} vs {db}");
        }
    }
    assert!(moved > 10.0 * tol, "{what}: the wind should move the tree ({moved})");
}

/// Every bit of the lane groups' state: displacements and oscillators.
fn lane_bits(s: &[StateLanes], o: &[SwayLanes]) -> Vec<u32> {
    s.iter()
        .zip(o)
        .flat_map(|(g, o)| g.delta.iter().chain([&o.bend, &o.rate]).flat_map(|v| [v.x, v.y, v.z]))
        .flat_map(|v| v.to_array().map(f32::to_bits))
        .collect()
}

/// The lane step compiled for AVX2 (run where the CPU has it) and for the baseline x86-64
/// gives the same bits: 200 steps of `gusty` (lane sines with non-integer sharpness, lane
/// turbulence, per-lane gust front) and of `blast` (per-lane blast field), every preset. On
/// a CPU without AVX2 only the baseline runs, and the test says so.
#[test]
fn every_instruction_set_level_gives_the_same_bits() {
    use sylva_core::methods::skjermo::lanes::{coefficients, step};
    use sylva_core::simd::{Level, detected};
    if detected() == Level::Baseline {
        println!("this CPU has no AVX2: only the baseline level runs");
    }
    for wind in ["gusty", "blast"] {
        let fw = WindScene::resolve(wind).unwrap().packed();
        for p in PRESETS {
            let t = SpeciesSource::from_preset(p).unwrap().generate(4, &Default::default(), None).unwrap();
            let m = Skjermo::new(&t, SkjermoParams::default());
            let run = |level: Level| {
                let rest = m.rest_state(&t);
                let (mut s, mut sway) = (rest.lanes, rest.sway_lanes);
                let mut next = s.clone();
                let cs = coefficients(&m.modes, 1.0 / 60.0);
                for k in 1..=200 {
                    let at = m.lane_step(k as f32 / 60.0, 1.0 / 60.0);
                    step(level, &fw.fields, &fw.waves, &m.lanes, &cs, &s, &mut sway, at, &mut next);
                    std::mem::swap(&mut s, &mut next);
                }
                lane_bits(&s, &sway)
            };
            let base = run(Level::Baseline);
            assert!(base.iter().any(|&b| f32::from_bits(b) != 0.0), "{wind} {}: nothing moved", p.name);
            assert_eq!(base, run(detected()), "{wind} {}", p.name);
        }
    }
}

/// Regression for the AVX2 gather: a lane group whose parents lie outside the state (lane
/// groups edited by hand) reads them as none at every instruction set level, as a trunk does:
/// no out-of-bounds read, and the same bits as the same group with `NONE` parents.
#[test]
fn a_parent_outside_the_state_is_read_as_none_at_every_level() {
    use sylva_core::methods::skjermo::lanes::{coefficients, step};
    use sylva_core::model::NONE;
    use sylva_core::simd::{Level, detected};
    let t = tree("quaking_aspen");
    let m = Skjermo::new(&t, SkjermoParams::default());
    let fw = constant(12.0).packed();
    let groups = m.lanes.len();
    let outside = [16 * groups as u32, 16 * groups as u32 + 15, u32::MAX - 1, 1 << 31];
    let mut edited = m.lanes.clone();
    let mut none = m.lanes.clone();
    for (g, (e, n)) in edited.iter_mut().zip(&mut none).enumerate().skip(1).step_by(3) {
        for l in 0..16 {
            e.parent[l] = outside[(g + l) % outside.len()];
            n.parent[l] = NONE;
        }
    }
    let run = |lanes: &[_], level: Level| {
        let rest = m.rest_state(&t);
        let (mut s, mut sway) = (rest.lanes, rest.sway_lanes);
        let mut next = s.clone();
        let cs = coefficients(&m.modes, 1.0 / 60.0);
        for k in 1..=20 {
            let at = m.lane_step(k as f32 / 60.0, 1.0 / 60.0);
            step(level, &fw.fields, &fw.waves, lanes, &cs, &s, &mut sway, at, &mut next);
            std::mem::swap(&mut s, &mut next);
        }
        lane_bits(&s, &sway)
    };
    let want = run(&none, Level::Baseline);
    assert_ne!(want, run(&m.lanes, Level::Baseline), "the edit should change the result");
    for level in [Level::Baseline, detected()] {
        assert_eq!(run(&edited, level), want, "{level:?}");
    }
}

/// The attachment frame turns with its parent's tangent by the shortest arc and no further
/// (`transported_frame`): on random rest frames and tangents, the frame is orthonormal, its
/// tangent is the new one, its normal is glam's shortest-arc rotation of the rest normal
/// (within 2e-5 over 10,000 draws), and an unturned tangent gives the rest frame bit for bit.
#[test]
fn the_attachment_frame_turns_with_its_parent_without_twisting() {
    use rand::{Rng, SeedableRng};
    use sylva_core::methods::skjermo::{frame_from_tangent, transported_frame};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let v = |rng: &mut rand_chacha::ChaCha8Rng| {
        Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
    };
    let mut worst = 0.0f32;
    for _ in 0..10_000 {
        let (tan, o) = (v(&mut rng), v(&mut rng));
        let rest = frame_from_tangent(tan, o);
        assert_eq!(transported_frame(&rest, tan), rest);
        if rest[0].dot(rest[1]).abs() > 1e-6 {
            // O nearly along the tangent: the rest frame itself is not orthonormal to 1e-6.
            continue;
        }
        let now = tan + 0.8 * v(&mut rng) * tan.length();
        if now.normalize().dot(rest[0]) < -0.9 {
            continue;
        }
        let f = transported_frame(&rest, now);
        let want = glam::Quat::from_rotation_arc(rest[0], now.normalize()) * rest[1];
        for (a, b) in [(0, 1), (1, 2), (0, 2)] {
            assert!(f[a].dot(f[b]).abs() < 1e-5, "{a}·{b} = {}: rest {rest:?}, now {now}", f[a].dot(f[b]));
        }
        assert!((f[0] - now.normalize()).length() < 1e-6);
        worst = worst.max((f[1] - want).length());
    }
    println!("largest difference from the shortest arc: {worst:e}");
    assert!(worst < 2e-5, "normal off the shortest arc by {worst}");
}
