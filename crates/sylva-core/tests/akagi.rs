//! Akagi's force propagation with damped angular springs.

use glam::Vec3;
use sylva_core::methods::Method;
use sylva_core::methods::akagi::{Akagi, AkagiParams, max_tip_displacement, mean_shift};
use sylva_core::pose::Pose;
use sylva_core::species::SpeciesSource;
use sylva_core::wind::{Constant, WindField, WindScene};
use sylva_core::{Grammar, LSystemOptions, Tree};

fn tree(name: &str) -> Tree {
    SpeciesSource::resolve(name).unwrap().generate(2, &Default::default(), None).unwrap()
}

fn constant(speed: f32) -> WindScene {
    WindScene { fields: vec![WindField::Constant(Constant { direction: [1.0, 0.0, 0.0], speed })] }
}

#[test]
fn still_air_keeps_the_exact_rest_pose() {
    for name in ["monopodial", "quaking_aspen"] {
        let t = tree(name);
        let a = Akagi::new(&t, AkagiParams::default());
        let mut s = a.rest_state(&t);
        for _ in 0..200 {
            a.step(&t, &WindScene::default().packed(), &mut s, 1.0 / 60.0);
        }
        assert_eq!(s.pose, Pose::rest(&t), "{name}");
    }
}

#[test]
fn constant_wind_bends_downwind_more_as_it_rises() {
    let t = tree("monopodial");
    let a = Akagi::new(&t, AkagiParams::default());
    let mut last = 0.0;
    for speed in [3.0, 6.0, 12.0, 24.0] {
        let wind = constant(speed);
        let fw = wind.packed();
        let mut s = a.rest_state(&t);
        let mut sum = Vec3::ZERO;
        for k in 0..900 {
            a.step(&t, &fw, &mut s, 1.0 / 60.0);
            if k >= 600 {
                sum += mean_shift(&t, &s.pose);
            }
        }
        let shift = sum / 300.0;
        assert!(shift.x > last, "{speed} m/s: {shift} after {last}");
        assert!(shift.z.abs() < 0.2 * shift.x, "not downwind: {shift}");
        last = shift.x;
    }
}

/// One segment, released from a deflection: it rings at its stem's first mode (the
/// continuous cantilever's, `physics::beam`), damped: ω_d = ω · √(1 − ζ²). Its joint is the
/// spring k = E I / L with the modal inertia k / ω².
#[test]
fn a_single_cantilever_rings_at_the_spring_frequency() {
    let t = Grammar::parse("width-scale: 0.02\naxiom: !(1)F(1)\n", "one.lsys")
        .unwrap()
        .generate(&LSystemOptions::default())
        .unwrap();
    let params = AkagiParams { damping_ratio: 0.05, ..Default::default() };
    let a = Akagi::new(&t, params);
    let wn = sylva_core::physics::stem_frequencies(&t, params.min_radius).omega[0];
    assert!(wn > 0.0 && (a.natural_frequency(0) - wn).abs() < 1e-3 * wn, "{} vs {wn}", a.natural_frequency(0));
    let wd = wn * (1.0 - 0.05f32 * 0.05).sqrt();
    // Deflect by a steady wind, then stop it.
    let mut s = a.rest_state(&t);
    let dt = 2e-4 * std::f32::consts::TAU / wn;
    for _ in 0..20_000 {
        a.step(&t, &constant(15.0).packed(), &mut s, dt);
    }
    let calm = WindScene::default();
    let mut crossings = Vec::new();
    let mut prev = s.theta[0][2];
    for k in 0..60_000 {
        a.step(&t, &calm.packed(), &mut s, dt);
        let th = s.theta[0][2];
        if prev < 0.0 && th >= 0.0 {
            crossings.push(k as f32 * dt);
        }
        prev = th;
    }
    assert!(crossings.len() >= 4, "{crossings:?}");
    let period = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f32;
    let measured = std::f32::consts::TAU / period;
    assert!((measured / wd - 1.0).abs() < 0.05, "ω measured {measured}, analytic {wd}");
}

/// After the wind stops, motion decays below 1 % of its peak within the time the damping
/// predicts for the slowest joint, ln(100) / (ζ ω_min), plus one period of that joint for
/// the coupling between joints.
#[test]
fn motion_dies_away_after_the_wind_stops() {
    let t = tree("monopodial");
    let a = Akagi::new(&t, AkagiParams::default());
    let mut s = a.rest_state(&t);
    let dt = 1.0 / 240.0;
    let gust = constant(20.0);
    let mut peak: f32 = 0.0;
    for _ in 0..960 {
        a.step(&t, &gust.packed(), &mut s, dt);
        peak = peak.max(max_tip_displacement(&t, &s.pose));
    }
    let w_min = (0..t.segments.len()).map(|i| a.natural_frequency(i)).fold(f32::MAX, f32::min);
    let predicted = (100f32).ln() / (a.params.damping_ratio * w_min) + std::f32::consts::TAU / w_min;
    let calm = WindScene::default();
    let mut settled_at = None;
    let mut k = 0;
    while (k as f32) * dt < 2.0 * predicted {
        a.step(&t, &calm.packed(), &mut s, dt);
        k += 1;
        let d = max_tip_displacement(&t, &s.pose);
        if d < 0.01 * peak && settled_at.is_none() {
            settled_at = Some(k as f32 * dt);
        } else if d >= 0.01 * peak {
            settled_at = None;
        }
    }
    let at = settled_at.expect("never settled");
    assert!(at <= predicted, "settled at {at} s, predicted {predicted} s (peak {peak} m)");
}

#[test]
fn a_100_000_step_storm_stays_sound() {
    let t = tree("stochastic_bush");
    let mut wind = WindScene::resolve("gusty").unwrap();
    if let WindField::Constant(c) = &mut wind.fields[0] {
        c.speed = 40.0;
    }
    let fw = wind.packed();
    let a = Akagi::new(&t, AkagiParams::default());
    let mut s = a.rest_state(&t);
    for k in 0..100_000 {
        a.step(&t, &fw, &mut s, 1.0 / 60.0);
        if k % 5_000 == 0 || k == 99_999 {
            if let Err(e) = s.pose.check_sound(&t) {
                panic!("step {k}: {e}");
            }
        }
    }
}

#[test]
fn akagi_is_identical_on_any_thread_count() {
    let t = tree("quaking_aspen");
    let wind = WindScene::resolve("gusty").unwrap();
    let run = |n| {
        rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap().install(|| {
            let a = Akagi::new(&t, AkagiParams::default());
            let mut s = a.rest_state(&t);
            for _ in 0..60 {
                a.step(&t, &wind.packed(), &mut s, 1.0 / 60.0);
            }
            s
        })
    };
    let one = run(1);
    assert_eq!(one, run(3));
    assert_ne!(one.pose, Pose::rest(&t));
}
