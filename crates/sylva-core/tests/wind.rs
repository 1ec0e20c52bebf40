//! Wind fields: the papers' formulas at hand-computed points, the physics each primitive
//! promises, the turbulence spectrum, TOML round trips and errors.

use glam::Vec3;
use rand::{Rng, SeedableRng};
use sylva_core::methods::zioma::trunk::TrunkNoise;
use sylva_core::species::SpeciesSource;
use sylva_core::wind::*;

fn one(f: WindField) -> WindScene {
    WindScene { fields: vec![f] }
}

fn two_waves(sharpness: Option<f32>) -> WindScene {
    one(WindField::SumOfSines(SumOfSines {
        waves: vec![
            SineWave { amplitude: 2.0, direction_deg: 30.0, wavelength: 10.0, speed: 3.0 },
            SineWave { amplitude: 1.0, direction_deg: 120.0, wavelength: 25.0, speed: 5.0 },
        ],
        sharpness,
        fade_in: None,
        fade_out: None,
    }))
}

/// Skjermo eq. 13 at (x, z) = (1, 2), t = 0.5, by hand, with the phase travelling downwind
/// (`θ = D·x w − t φ`):
/// wave 1: D = (cos 30°, sin 30°) = (0.866025, 0.5), w = 2π/10 = 0.628319, φ = 3w = 1.884956,
///   θ₁ = (0.866025·1 + 0.5·2)·0.628319 − 0.5·1.884956 = 0.229981, sin θ₁ = 0.227959;
/// wave 2: D = (−0.5, 0.866025), w = 2π/25 = 0.251327, φ = 5w = 1.256637,
///   θ₂ = (−0.5 + 1.732051)·0.251327 − 0.5·1.256637 = −0.318670, sin θ₂ = −0.313304;
/// F = D₁·2·0.227959 + D₂·1·(−0.313304) = (0.551488, 0, −0.043371).
#[test]
fn sum_of_sines_reproduces_eq_13() {
    let v = two_waves(None).sample(Vec3::new(1.0, 7.0, 2.0), 0.5);
    assert!((v - Vec3::new(0.551488, 0.0, -0.043371)).length() < 2e-5, "{v}");
}

/// Eq. 14 with k = 2 at the same point: F = Σ Dᵢ Aᵢ ((sin θᵢ + 1)/2)²
/// = D₁·2·0.613979² + D₂·1·0.343348² = (0.593988, 0, 0.479064).
#[test]
fn sum_of_sines_reproduces_eq_14() {
    let v = two_waves(Some(2.0)).sample(Vec3::new(1.0, 0.0, 2.0), 0.5);
    assert!((v - Vec3::new(0.593988, 0.0, 0.479064)).length() < 2e-5, "{v}");
}

#[test]
fn sharpness_above_one_sharpens_peaks_and_flattens_troughs() {
    let wave = |k: f32| {
        one(WindField::SumOfSines(SumOfSines {
            waves: vec![SineWave { amplitude: 1.0, direction_deg: 0.0, wavelength: 10.0, speed: 10.0 }],
            sharpness: Some(k),
            fade_in: None,
            fade_out: None,
        }))
    };
    // One period (1 s) at the origin, 10,000 samples.
    let series = |k: f32| -> Vec<f32> { (0..10_000).map(|i| wave(k).sample(Vec3::ZERO, i as f32 * 1e-4).x).collect() };
    let (s1, s4) = (series(1.0), series(4.0));
    let frac = |s: &[f32], f: &dyn Fn(f32) -> bool| s.iter().filter(|v| f(**v)).count() as f32 / s.len() as f32;
    // Same peak (A) and floor (0)...
    for s in [&s1, &s4] {
        assert!((s.iter().cloned().fold(f32::MIN, f32::max) - 1.0).abs() < 1e-4);
        assert!(s.iter().cloned().fold(f32::MAX, f32::min).abs() < 1e-4);
    }
    // ...but narrower peaks: less time above half the peak,
    let (h1, h4) = (frac(&s1, &|v| v > 0.5), frac(&s4, &|v| v > 0.5));
    assert!((h1 - 0.5).abs() < 0.01 && h4 < 0.3, "{h1} {h4}");
    // and flatter, wider troughs: more time near zero.
    let (t1, t4) = (frac(&s1, &|v| v < 0.05), frac(&s4, &|v| v < 0.05));
    assert!(t4 > 2.0 * t1, "{t1} {t4}");
}

#[test]
fn gust_front_arrives_downstream_later_by_distance_over_speed() {
    let speed = 8.0;
    let scene = one(WindField::GustFront(GustFront {
        origin: [0.0, 0.0],
        direction_deg: 45.0,
        strength: 12.0,
        speed,
        width: 10.0,
        length: 60.0,
        radius: 500.0,
        start: 2.0,
    }));
    let dir = Vec3::new(45f32.to_radians().cos(), 0.0, 45f32.to_radians().sin());
    // First time the wind reaches half strength at a point `d` metres downstream.
    let arrival = |d: f32| -> f32 {
        let p = dir * d + Vec3::new(0.0, 3.0, 0.0);
        let mut t = 0.0;
        while scene.sample(p, t).length() < 6.0 {
            t += 1e-3;
            assert!(t < 100.0);
        }
        t
    };
    let (a20, a60, a140) = (arrival(20.0), arrival(60.0), arrival(140.0));
    assert!((a60 - a20 - 40.0 / speed).abs() < 2e-3, "{a20} {a60}");
    assert!((a140 - a20 - 120.0 / speed).abs() < 2e-3, "{a20} {a140}");
    // Half strength is reached half-way up the rising edge (width 10 m): 5 m before the front.
    assert!((a20 - (2.0 + (20.0 - 5.0) / speed)).abs() < 2e-3, "{a20}");
    // The wind blows along the front's direction.
    let v = scene.sample(dir * 20.0, a20 + 1.0);
    assert!(v.normalize().dot(dir) > 0.9999);
}

#[test]
fn vortex_turns_about_a_vertical_axis_with_peak_speed_at_its_radius() {
    let scene = one(WindField::Vortex(Vortex {
        centre: [10.0, -5.0],
        drift: [0.0, 0.0],
        strength: 15.0,
        radius: 8.0,
        updraft: 2.0,
        start: 1.0,
        duration: 20.0,
        fade: 2.0,
    }));
    let c = Vec3::new(10.0, 0.0, -5.0);
    let t = 10.0;
    let speed_at = |r: f32| scene.sample(c + Vec3::X * r, t).with_y(0.0).length();
    let peak_r = (1..400).map(|i| i as f32 * 0.1).max_by(|a, b| speed_at(*a).total_cmp(&speed_at(*b))).unwrap();
    assert!((peak_r - 8.0).abs() < 0.15, "{peak_r}");
    assert!((speed_at(8.0) - 15.0).abs() < 0.05, "{}", speed_at(8.0));
    // Tangential everywhere (no radial component), counter-clockwise seen from above.
    for a in 0..12 {
        let ang = a as f32 * 0.5;
        let r = Vec3::new(ang.cos(), 0.0, ang.sin()) * 5.0;
        let v = scene.sample(c + r, t).with_y(0.0);
        assert!(v.dot(r).abs() < 1e-4 * v.length() * 5.0);
        assert!(Vec3::Y.dot(r.cross(v)) > 0.0, "not counter-clockwise");
    }
    // Updraft at the centre; nothing before it starts or after it ends.
    assert!((scene.sample(c, t).y - 2.0).abs() < 1e-4);
    assert_eq!(scene.sample(c + Vec3::X * 8.0, 0.5), Vec3::ZERO);
    assert_eq!(scene.sample(c + Vec3::X * 8.0, 21.5), Vec3::ZERO);
}

#[test]
fn blast_expands_outward_and_decays() {
    let scene = one(WindField::Blast(Blast {
        centre: [0.0, 1.0, 0.0],
        strength: 40.0,
        start: 3.0,
        speed: 50.0,
        width: 4.0,
        decay: 2.0,
        radius: 300.0,
    }));
    let c = Vec3::new(0.0, 1.0, 0.0);
    let dir = Vec3::new(0.6, 0.0, 0.8);
    for tau in [0.5f32, 1.0, 2.0] {
        let peak = (1..2000)
            .map(|i| i as f32 * 0.1)
            .max_by(|a, b| {
                scene
                    .sample(c + dir * *a, 3.0 + tau)
                    .length()
                    .total_cmp(&scene.sample(c + dir * *b, 3.0 + tau).length())
            })
            .unwrap();
        assert!((peak - 50.0 * tau).abs() < 0.2, "tau {tau}: shell at {peak}");
        let v = scene.sample(c + dir * peak, 3.0 + tau);
        assert!(v.normalize().dot(dir) > 0.9999, "not outward");
        assert!((v.length() - 40.0 * (-tau / 2.0).exp()).abs() < 0.05);
    }
    assert_eq!(scene.sample(c + dir * 10.0, 2.9), Vec3::ZERO);
    assert_eq!(scene.sample(c + dir * 350.0, 3.0 + 7.0), Vec3::ZERO);
}

/// Log-log slope of the temporal power spectrum of turbulence at one point, by FFT of a
/// long series and a least-squares fit over log-spaced bins inside [lo, hi] Hz.
fn spectral_slope_of(turb: Turbulence, lo: f64, hi: f64) -> f64 {
    use rustfft::{FftPlanner, num_complex::Complex};
    let (fields, waves) = one(WindField::Turbulence(turb)).pack();
    let n = 1 << 17;
    let dt = 0.04f64;
    let p = Vec3::new(3.0, 10.0, -7.0);
    let mut buf: Vec<Complex<f64>> = (0..n)
        .map(|i| {
            Complex::new(sylva_core::wind::sample::wind_at(&fields, &waves, p, (i as f64 * dt) as f32).x as f64, 0.0)
        })
        .collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    let df = 1.0 / (n as f64 * dt);
    // Bins of 0.1 decade.
    let (lo, hi) = (lo.log10(), hi.log10());
    let nb = ((hi - lo) / 0.1).round() as usize;
    let mut pts = Vec::new();
    for b in 0..nb {
        let (f0, f1) = (10f64.powf(lo + b as f64 * 0.1), 10f64.powf(lo + (b + 1) as f64 * 0.1));
        let (k0, k1) = ((f0 / df).ceil() as usize, (f1 / df).floor() as usize);
        let power: f64 = (k0..=k1).map(|k| buf[k].norm_sqr()).sum();
        pts.push(((0.5 * (f0 + f1)).log10(), (power / (f1 - f0)).log10()));
    }
    let m = pts.len() as f64;
    let (sx, sy) = (pts.iter().map(|p| p.0).sum::<f64>(), pts.iter().map(|p| p.1).sum::<f64>());
    let sxx = pts.iter().map(|p| p.0 * p.0).sum::<f64>();
    let sxy = pts.iter().map(|p| p.0 * p.1).sum::<f64>();
    (m * sxy - sx * sy) / (m * sxx - sx * sx)
}

fn spectral_slope(beta: f32) -> f64 {
    let turb = Turbulence {
        intensity: 2.0,
        beta,
        f_min: 0.005,
        f_max: 5.0,
        components: 512,
        mean_speed: 5.0,
        vertical: 0.3,
        seed: 3,
        direction_deg: None,
        fade_in: None,
        fade_out: None,
    };
    spectral_slope_of(turb, 0.02, 3.0)
}

#[test]
fn turbulence_spectrum_follows_one_over_f_to_the_beta() {
    for beta in [1.0f32, 5.0 / 3.0, 2.0] {
        let slope = spectral_slope(beta);
        println!("β = {beta:.3}: fitted slope {slope:.3}");
        assert!((slope + beta as f64).abs() < 0.1, "β = {beta}: slope {slope}");
    }
}

#[test]
fn turbulence_has_the_requested_intensity_and_is_spatially_coherent() {
    let turb = Turbulence {
        intensity: 1.5,
        beta: 5.0 / 3.0,
        f_min: 0.01,
        f_max: 5.0,
        components: 64,
        mean_speed: 5.0,
        vertical: 0.3,
        seed: 9,
        direction_deg: None,
        fade_in: None,
        fade_out: None,
    };
    let scene = one(WindField::Turbulence(turb));
    let (f, w) = scene.pack();
    let at = |p: Vec3, t: f32| sylva_core::wind::sample::wind_at(&f, &w, p, t);
    let n = 200_000;
    let rms = ((0..n).map(|i| at(Vec3::ZERO, i as f32 * 0.05).x.powi(2) as f64).sum::<f64>() / n as f64).sqrt();
    assert!((rms - 1.5).abs() < 0.2, "rms {rms}");
    // Nearby points move together, distant ones do not.
    let corr = |d: f32| {
        let (mut ab, mut aa, mut bb) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..20_000 {
            let t = i as f32 * 0.1;
            let (a, b) = (at(Vec3::ZERO, t).x as f64, at(Vec3::new(d, 0.0, 0.0), t).x as f64);
            ab += a * b;
            aa += a * a;
            bb += b * b;
        }
        ab / (aa * bb).sqrt()
    };
    assert!(corr(0.5) > 0.95, "{}", corr(0.5));
    assert!(corr(2000.0).abs() < 0.5, "{}", corr(2000.0));
}

#[test]
fn scenes_round_trip_through_toml() {
    let text = include_str!("../../../presets/wind/gusty.toml");
    let scene = WindScene::from_toml(text, "gusty.toml").unwrap();
    assert!(scene.fields.len() >= 4);
    let again = WindScene::from_toml(&scene.to_toml(), "again.toml").unwrap();
    assert_eq!(scene, again);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("w.toml");
    scene.save(&path).unwrap();
    assert_eq!(WindScene::load(&path).unwrap(), scene);
    // Sampling is the sum of the fields, once each turbulence field is told the direction
    // the whole scene carries it (alone, a field has no mean wind to follow).
    let p = Vec3::new(3.0, 4.0, 5.0);
    let mean = scene.mean_direction();
    let pinned = |f: &WindField| match f {
        WindField::Turbulence(t) => {
            WindField::Turbulence(Turbulence { direction_deg: Some(mean.z.atan2(mean.x).to_degrees()), ..t.clone() })
        }
        other => other.clone(),
    };
    assert!(scene.fields.iter().any(|f| matches!(f, WindField::Turbulence(_))));
    let sum: Vec3 = scene.fields.iter().map(|f| one(pinned(f)).sample(p, 12.0)).sum();
    assert!((scene.sample(p, 12.0) - sum).length() < 1e-4);
}

#[test]
fn bad_scenes_name_the_line_and_field() {
    let e = WindScene::from_toml(
        "[[field]]\nkind = \"constant\"\ndirection = [1, 0, 0]\nspeed = 3\ngustiness = 2\n",
        "w.toml",
    )
    .unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with("w.toml:") && msg.contains("gustiness"), "{msg}");
    let e = WindScene::from_toml("[[field]]\nkind = \"hurricane\"\n", "w.toml").unwrap_err().to_string();
    assert!(e.contains("hurricane"), "{e}");
    let e = WindScene::from_toml("[[field]]\nkind = \"constant\"\ndirection = [1, 0, 0]\nspeed = nan\n", "w.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("field[0].speed"), "{e}");
    let e = WindScene::from_toml(
        "[[field]]\nkind = \"constant\"\ndirection = [1, 0, 0]\nspeed = 1\n[[field]]\nkind = \"turbulence\"\nintensity = 1\ncomponents = 100000\n",
        "w.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("field[1].components"), "{e}");
}

/// A thicker trunk sways faster and bends less; a taller one sways slower; calm air does not
/// move it; the bend grows as `U² g(U)`; the oscillator's response has the textbook gain
/// and lag; trees with different seeds move differently.
#[test]
fn trunk_model_follows_size_stiffness_and_wind() {
    use sylva_core::methods::zioma::trunk::TrunkModel;
    use sylva_core::physics::{BRANCH_DRAG, DragModel, LEAF_DRAG};
    let grown = |name: &str, scale: f64, ratio: f64| {
        let SpeciesSource::WeberPenn { file, mut params } = SpeciesSource::resolve(name).unwrap() else { panic!() };
        params.scale *= scale;
        params.ratio *= ratio;
        let t = SpeciesSource::WeberPenn { file, params }.generate(1, &Default::default(), None).unwrap();
        TrunkModel::for_tree(&t, BRANCH_DRAG, LEAF_DRAG)
    };
    let (slender, stout, tall) =
        (grown("quaking_aspen", 1.0, 1.0), grown("quaking_aspen", 1.0, 2.0), grown("quaking_aspen", 2.0, 1.0));
    assert!(stout.natural_frequency > 1.5 * slender.natural_frequency, "{stout:?} {slender:?}");
    assert!(stout.static_bend(10.0) < slender.static_bend(10.0) / 4.0);
    assert!(tall.natural_frequency < slender.natural_frequency);
    assert_eq!(slender.static_bend(0.0), 0.0);
    let g = |u: f32| u * u * DragModel::default().reconfiguration(u);
    let ratio = slender.static_bend(8.0) / slender.static_bend(4.0);
    assert!((ratio / (g(8.0) / g(4.0)) - 1.0).abs() < 1e-4, "{ratio}");
    // Damping: the wood's in still air, rising with the wind.
    assert!((slender.damping(0.0) - slender.damping_ratio).abs() < 1e-7);
    assert!(slender.damping(10.0) > slender.damping(5.0) && slender.damping(5.0) > slender.damping(0.0));
    // Gain 1 and no lag far below f₀, 1/(2ζ) and a quarter turn at f₀, ~r⁻² and half a turn
    // far above.
    let f0 = slender.natural_frequency;
    let (g0, l0) = slender.response(0.001 * f0, 0.05);
    assert!((g0 - 1.0).abs() < 1e-4 && l0.abs() < 1e-3);
    let (g1, l1) = slender.response(f0, 0.05);
    assert!((g1 - 10.0).abs() < 1e-3 && (l1 - std::f32::consts::FRAC_PI_2).abs() < 1e-5, "{g1} {l1}");
    let (g2, l2) = slender.response(10.0 * f0, 0.05);
    assert!((g2 * 99.0 - 1.0).abs() < 0.01 && l2 > 3.1, "{g2} {l2}");
    let noise = TrunkNoise::new(f0, 0.1);
    assert_ne!(noise.angles(10.0, 1), noise.angles(10.0, 2));
    assert_eq!(TrunkNoise::new(f0, 0.0).angles(3.0, 1), [0.0; 3]);
}

/// The wind through a filter of gain 1 and no lag is the wind; through a damped oscillator,
/// a single sine at the natural frequency comes out 1/(2ζ) times as large and a quarter of a
/// period late, and a constant wind passes unchanged.
#[test]
fn wind_through_a_filter_scales_and_delays_each_wave() {
    use sylva_core::wind::sample::{wind_at, wind_through};
    let wind = WindScene::resolve("gusty").unwrap().packed();
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    for _ in 0..2000 {
        let p = Vec3::new(rng.random_range(-50.0..50.0), rng.random_range(0.0..20.0), rng.random_range(-50.0..50.0));
        let t = rng.random_range(0.0..300.0);
        let (a, b) =
            (wind_at(&wind.fields, &wind.waves, p, t), wind_through(&wind.fields, &wind.waves, p, t, |_| (1.0, 0.0)));
        assert!((a - b).length() < 1e-4 * (1.0 + a.length()), "{a} {b}");
    }
    // One turbulence-free sine of 0.5 Hz on top of 3 m/s.
    let scene = WindScene::from_toml(
        r#"
        [[field]]
        kind = "constant"
        direction = [1.0, 0.0, 0.0]
        speed = 3.0
        [[field]]
        kind = "sum_of_sines"
        waves = [{ amplitude = 1.0, direction_deg = 0.0, wavelength = 12.0, speed = 6.0 }]
        "#,
        "sine.toml",
    )
    .unwrap();
    let w = scene.packed();
    let f0 = 0.5;
    let h = |f: f32| {
        let r = f / f0;
        let (re, im) = (1.0 - r * r, 2.0 * 0.1 * r);
        (1.0 / (re * re + im * im).sqrt(), im.atan2(re))
    };
    let dt = 0.01;
    let series = |filtered: bool| -> Vec<f32> {
        (0..4000)
            .map(|k| {
                let t = k as f32 * dt;
                let v =
                    if filtered { wind_through(&w.fields, &w.waves, Vec3::ZERO, t, h) } else { w.at(Vec3::ZERO, t) };
                v.x
            })
            .collect()
    };
    let (raw, out) = (series(false), series(true));
    let swing = |x: &[f32]| x.iter().cloned().fold(f32::MIN, f32::max) - x.iter().cloned().fold(f32::MAX, f32::min);
    let mean = |x: &[f32]| x.iter().sum::<f32>() / x.len() as f32;
    println!("swing {} → {}, mean {} → {}", swing(&raw), swing(&out), mean(&raw), mean(&out));
    assert!((swing(&out) / swing(&raw) - 5.0).abs() < 0.05, "gain {}", swing(&out) / swing(&raw));
    assert!((mean(&out) - mean(&raw)).abs() < 0.02, "the mean moved");
    // The filtered wave peaks a quarter period (0.5 s) after the raw one.
    let peak = |x: &[f32]| (0..200).max_by(|&a, &b| x[a].total_cmp(&x[b])).unwrap() as f32 * dt;
    let lag = (peak(&out) - peak(&raw)).rem_euclid(2.0);
    assert!((lag - 0.5).abs() < 0.03, "lag {lag} s");
}

/// Gusts travel downwind (frozen turbulence and the sum of sines' waves carried with the
/// mean wind): in the `gusty` preset, the speed 12 m downwind of a point follows the speed
/// there, about 12 m / 6 m/s = 2 s later; the cross-correlation peaks at a positive lag.
#[test]
fn gusty_wind_gusts_travel_downwind_from_probe_to_probe() {
    let scene = WindScene::resolve("gusty").unwrap();
    let wind = scene.packed();
    let d = scene.mean_direction();
    let (up, down) = (Vec3::new(0.0, 8.0, 0.0), Vec3::new(0.0, 8.0, 0.0) + d * 12.0);
    // Before the gust front (t = 5 s) and the vortex (t = 8 s) arrive; then after them.
    let dt = 0.05f32;
    let series = |p: Vec3| -> Vec<f64> {
        (0..6000).map(|i| wind.at(p, 100.0 + i as f32 * dt).dot(d) as f64).collect::<Vec<_>>()
    };
    let (a, b) = (series(up), series(down));
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
    let (ma, mb) = (mean(&a), mean(&b));
    let corr = |lag: i64| {
        let mut s = 0.0;
        for i in 0..a.len() as i64 {
            let j = i + lag;
            if j >= 0 && (j as usize) < b.len() {
                s += (a[i as usize] - ma) * (b[j as usize] - mb);
            }
        }
        s
    };
    let best = (-120..=120).max_by(|&x, &y| corr(x).total_cmp(&corr(y))).unwrap();
    let lag_s = best as f32 * dt;
    println!("downwind probe lags the upwind one by {lag_s:.2} s");
    assert!(lag_s > 0.5, "the downwind probe leads by {:.2} s: gusts travel upwind", -lag_s);
    assert!((lag_s - 2.0).abs() < 1.0, "lag {lag_s:.2} s, expected about 2 s (12 m at 6 m/s)");
}

/// The `gusty` preset's atmospheric turbulence (48 waves, 0.01–1.5 Hz) has the spectrum it
/// asks for, β = 5/3 within ±0.1; its crown band (16 waves, 1.5–8 Hz, too few per 0.1 decade
/// for a slope) puts its rms above 1.5 Hz and none of it below, within 5 %.
#[test]
fn gusty_turbulence_has_the_configured_spectral_slope() {
    let scene = WindScene::resolve("gusty").unwrap();
    let bands: Vec<&Turbulence> =
        scene.fields.iter().filter_map(|f| if let WindField::Turbulence(t) = f { Some(t) } else { None }).collect();
    let [air, crown] = bands[..] else { panic!("gusty has the atmosphere's and the crown's turbulence") };
    let slope = spectral_slope_of(air.clone(), 0.03, air.f_max as f64 / 1.15);
    println!("gusty turbulence: fitted slope {slope:.3}, configured −{:.3}", air.beta);
    assert!((slope + air.beta as f64).abs() < 0.1, "slope {slope}, β {}", air.beta);
    let (fields, waves) = one(WindField::Turbulence(crown.clone())).pack();
    let dt = 0.01f32;
    let v: Vec<Vec3> = (0..60_000)
        .map(|i| sylva_core::wind::sample::wind_at(&fields, &waves, Vec3::new(3.0, 10.0, -7.0), i as f32 * dt))
        .collect();
    let x: Vec<f32> = v.iter().map(|v| v.x).collect();
    let (above, all) = sylva_core::physics::measure::variance_above(&x, dt, crown.f_min);
    // Each horizontal component's rms, as configured: the mean of the two.
    let rms = (v.iter().map(|v| v.x * v.x + v.z * v.z).sum::<f32>() / (2 * v.len()) as f32).sqrt();
    println!(
        "gusty crown band: rms {rms:.3} m/s (configured {}), {:.1} % above {} Hz",
        crown.intensity,
        100.0 * above / all,
        crown.f_min
    );
    assert!((rms / crown.intensity - 1.0).abs() < 0.05, "rms {rms}");
    assert!(above / all > 0.95, "{}", above / all);
}

/// The packed envelope of a wave field: exactly 1 without fades (so a scene without them
/// samples as it did, bit for bit), a smoothstep in and out with them.
#[test]
fn a_fade_is_a_smoothstep_and_no_fade_is_exactly_one() {
    use sylva_core::wind::sample::wave_envelope;
    let none = Fade::envelope(None, None);
    for t in [-1e7f32, -3.5, 0.0, 1e-3, 17.25, 600.0, 1e7] {
        assert_eq!(wave_envelope(none, t), 1.0, "t = {t}");
    }
    let b = Fade::envelope(Some(Fade { start: 10.0, duration: 2.0 }), Some(Fade { start: 20.0, duration: 4.0 }));
    for (t, want) in
        [(9.0, 0.0), (10.0, 0.0), (11.0, 0.5), (12.0, 1.0), (15.0, 1.0), (22.0, 0.5), (24.0, 0.0), (30.0, 0.0)]
    {
        assert!((wave_envelope(b, t) - want).abs() < 1e-6, "t = {t}: {} against {want}", wave_envelope(b, t));
    }
    let e = WindScene::from_toml(
        "[[field]]\nkind = \"sum_of_sines\"\nwaves = []\nfade_in = { start = 1.0, duration = 0.0 }\n",
        "w.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("w.toml:4") && e.contains("field[0].fade_in.duration"), "{e}");
}

/// Skjermo §5: changing the waves at once jumps the wind; [`WindScene::blend_waves`] takes the
/// old waves out over the blend, then brings the new ones in, so the wind never changes faster
/// than its waves and the blend's own slope allow. Waves in both scenes are left alone.
#[test]
fn blending_takes_the_old_waves_out_before_the_new_ones_come_in() {
    let sines = |a: f32, deg: f32, lambda: f32| {
        WindField::SumOfSines(SumOfSines {
            waves: vec![SineWave { amplitude: a, direction_deg: deg, wavelength: lambda, speed: 6.0 }],
            sharpness: None,
            fade_in: None,
            fade_out: None,
        })
    };
    let breeze = |s: f32| WindField::Constant(Constant { direction: [1.0, 0.0, 0.0], speed: s });
    let turb = WindScene::resolve("gusty").unwrap().fields.into_iter().find(|f| matches!(f, WindField::Turbulence(_)));
    let turb = turb.unwrap();
    let old = WindScene { fields: vec![breeze(5.0), sines(2.0, 0.0, 20.0), turb.clone()] };
    let next = WindScene { fields: vec![breeze(6.0), sines(2.5, 40.0, 13.0), turb.clone()] };
    let (at, d) = (10.0f32, 1.5f32);
    let blended = old.blend_waves(&next, at, d);
    assert_eq!(blended.fields.len(), 4, "{blended:#?}");
    assert_eq!(blended.fields[2], turb, "the unchanged turbulence is kept as it was");
    let alone = |f: &WindField| WindScene { fields: vec![f.clone()] };
    let p = Vec3::new(3.0, 5.0, -2.0);
    let (gone, came) = (alone(&blended.fields[3]), alone(&blended.fields[1]));
    for t in [0.0f32, 5.0, 9.99] {
        assert_eq!(gone.sample(p, t), alone(&old.fields[1]).sample(p, t), "old waves at {t} s");
        assert_eq!(came.sample(p, t), Vec3::ZERO, "new waves at {t} s");
    }
    for t in [at + d, 13.0, 30.0] {
        assert_eq!(gone.sample(p, t), Vec3::ZERO, "old waves at {t} s");
    }
    for t in [at + 2.0 * d, 20.0, 30.0] {
        assert_eq!(came.sample(p, t), alone(&next.fields[1]).sample(p, t), "new waves at {t} s");
    }
    // Rate of change through the blend: each wave's own (A ω) plus the envelope's
    // (1.5 A / d at most), on top of the turbulence's, measured before the change.
    let step = 1e-3f32;
    let rate = |s: &WindScene, from: f32, to: f32| {
        let n = ((to - from) / step) as usize;
        (0..n)
            .map(|k| {
                let t = from + k as f32 * step;
                ((s.sample(p, t + step) - s.sample(p, t)) / step).length()
            })
            .fold(0.0f32, f32::max)
    };
    let waves_only = |s: &WindScene| WindScene {
        fields: s.fields.iter().filter(|f| matches!(f, WindField::SumOfSines(_))).cloned().collect(),
    };
    let omega = |a: f32, lambda: f32| a * std::f32::consts::TAU * 6.0 / lambda;
    let bound = omega(2.0, 20.0).max(omega(2.5, 13.0)) + 1.5 * 2.5 / d;
    let through = rate(&waves_only(&blended), at - 0.5, at + 2.0 * d + 0.5);
    println!("waves' rate of change through the blend {through:.2} m/s², bound {bound:.2}");
    assert!(through <= 1.02 * bound, "{through} m/s² against {bound}");
    // At once, the waves jump (the test's measure sees it).
    let abrupt = old.blend_waves(&next, at, 0.0);
    assert_eq!(abrupt, next);
    let jump = (waves_only(&abrupt).sample(p, at) - waves_only(&old).sample(p, at)).length();
    assert!(jump / step > 10.0 * bound, "switching at once moves the wind only {jump} m/s");
    // A second edit in the middle of a blend keeps the old waves on their way out as they
    // were, drops the waves that had yet to come in, and brings the newest in after the blend.
    let third = WindScene { fields: vec![breeze(6.0), sines(1.0, 90.0, 30.0), turb] };
    let again = blended.blend_waves(&third, at + 0.5, d);
    assert_eq!(again.fields.len(), 4, "{again:#?}");
    assert_eq!(again.fields[3], blended.fields[3], "the old waves' blend out goes on as it was");
    let (fade_in, _) = again.fields[1].fades().unwrap();
    assert_eq!(fade_in, Some(Fade { start: at + 0.5 + d, duration: d }));
    // Sixty edits a second (a dragged slider) keep one set going out and one coming in.
    let mut dragged = again;
    for k in 1..=120 {
        let next = WindScene { fields: vec![breeze(6.0), sines(1.0 + 0.01 * k as f32, 90.0, 30.0)] };
        dragged = dragged.blend_waves(&next, at + 0.5 + k as f32 / 60.0, d);
        assert!(dragged.fields.len() <= 4, "edit {k}: {} fields", dragged.fields.len());
    }
}
