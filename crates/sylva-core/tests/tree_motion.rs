//! Trees that move like trees: each method's sway measured as field studies measure real
//! trees (pluck and step tests, spectra), held to beam theory and field ranges. Small trees,
//! so the tests stay quick.
//!
//! Field references: sway frequency 0.2–1 Hz for 10–30 m trees, linear in DBH/H²
//! (Moore & Maguire 2004, 602 trees); damping ratios 0.02–0.2, rising with wind speed;
//! trunk-top sway in a moderate breeze 0.5–3 % of the height.

use glam::Vec3;
use sylva_core::methods::Method;
use sylva_core::methods::akagi::{Akagi, AkagiParams};
use sylva_core::physics::measure::{damping_ratio, linear_fit, sway_frequency};
use sylva_core::physics::stem_frequencies;
use sylva_core::pose::Pose;
use sylva_core::species::{PRESETS, PresetKind, SpeciesSource};
use sylva_core::wind::{Constant, PackedWind, Turbulence, WindField, WindScene};
use sylva_core::{Grammar, LSystemOptions, Tree};

/// A Weber–Penn preset with its size scaled by `factor` (radii follow, as the species ties
/// them to length).
fn species(name: &str, factor: f64, seed: u64) -> Tree {
    let SpeciesSource::WeberPenn { file, mut params } = SpeciesSource::resolve(name).unwrap() else {
        panic!("{name} is not a Weber–Penn species")
    };
    params.scale *= factor;
    params.scale_v *= factor;
    SpeciesSource::WeberPenn { file, params }.generate(seed, &Default::default(), None).unwrap()
}

/// A small aspen (about 6 m) for the dynamic tests.
fn small_aspen() -> Tree {
    species("quaking_aspen", 0.5, 1)
}

fn constant(speed: f32) -> WindScene {
    WindScene { fields: vec![WindField::Constant(Constant { direction: [1.0, 0.0, 0.0], speed })] }
}

/// Last segment of the trunk (stem 0).
fn trunk_top(tree: &Tree) -> usize {
    (tree.stems.first_segment[0] + tree.stems.segment_count[0] - 1) as usize
}

/// Runs `steps` steps of `dt` in `wind`, recording `probe(pose)` after each.
fn record<M: Method>(
    m: &M,
    tree: &Tree,
    state: &mut M::State,
    wind: &PackedWind,
    dt: f32,
    steps: usize,
    mut probe: impl FnMut(&Pose) -> Vec3,
) -> Vec<Vec3> {
    (0..steps)
        .map(|_| {
            m.step(tree, wind, state, dt);
            probe(&m.pose(tree, wind, state))
        })
        .collect()
}

/// Pluck: a steady wind for `load` s, then still air for `ring` s; the trunk top's
/// downwind displacement while it rings.
fn pluck<M: Method>(m: &M, tree: &Tree, speed: f32, dt: f32, load: f32, ring: f32) -> Vec<f32> {
    let top = trunk_top(tree);
    let rest = tree.segments.end(top);
    let mut s = m.rest_state(tree);
    let probe = |p: &Pose| p.end(tree, top) - rest;
    record(m, tree, &mut s, &constant(speed).packed(), dt, (load / dt) as usize, probe);
    let calm = WindScene::default().packed();
    record(m, tree, &mut s, &calm, dt, (ring / dt) as usize, probe).iter().map(|d| d.x).collect()
}

/// A uniform cantilever: one straight stem of 20 equal segments, 5 m long, no leaves.
fn cantilever() -> Tree {
    let axiom = "!(1)".to_string() + &"F(0.25)".repeat(20);
    let t = Grammar::parse(&format!("width-scale: 0.04\naxiom: {axiom}\n"), "cantilever.lsys")
        .unwrap()
        .generate(&LSystemOptions::default())
        .unwrap();
    let r = &t.segments.radius_base;
    assert_eq!(t.segments.len(), 20);
    assert!(r.iter().chain(&t.segments.radius_tip).all(|&x| x == r[0]), "not uniform: {r:?}");
    assert!(t.leaves.is_empty());
    t
}

/// f₁ = (1.875² / 2π) · √(E I / (ρ A)) / L² of a uniform round cantilever.
fn beam_frequency(t: &Tree) -> f32 {
    let (r, l) = (t.segments.radius_base[0], t.stems.length[0]);
    let (e, rho) = (t.wood.young_modulus, t.wood.density);
    1.875f32.powi(2) / std::f32::consts::TAU * (e * r * r / (4.0 * rho)).sqrt() / (l * l)
}

#[test]
fn the_stem_frequency_of_a_uniform_cantilever_is_the_beam_formula() {
    let t = cantilever();
    let f = stem_frequencies(&t, 0.0).hz(0);
    let beam = beam_frequency(&t);
    // The 20-segment chain of joint springs is 4–5 % softer than the continuous beam.
    assert!((f / beam - 1.0).abs() < 0.1, "Rayleigh {f} Hz, beam formula {beam} Hz");
}

#[test]
fn akagi_sways_a_uniform_cantilever_at_the_beam_formula() {
    let t = cantilever();
    let a = Akagi::new(&t, AkagiParams::default());
    let series = pluck(&a, &t, 2.0, 1.0 / 60.0, 1.0, 30.0);
    let f = sway_frequency(&series, 1.0 / 60.0).expect("no sway");
    let beam = beam_frequency(&t);
    println!("akagi cantilever {f:.3} Hz, beam {beam:.3} Hz");
    assert!((f / beam - 1.0).abs() < 0.15, "akagi {f} Hz, beam formula {beam} Hz");
}

#[test]
fn akagi_trunk_frequency_does_not_depend_on_the_time_step() {
    let t = small_aspen();
    let a = Akagi::new(&t, AkagiParams::default());
    let f: Vec<f32> = [30.0f32, 60.0, 120.0, 240.0]
        .iter()
        .map(|&rate| sway_frequency(&pluck(&a, &t, 8.0, 1.0 / rate, 1.5, 12.0), 1.0 / rate).expect("no sway"))
        .collect();
    println!("akagi trunk frequency at 30/60/120/240 Hz: {f:?}");
    let (lo, hi) = (f.iter().cloned().fold(f32::MAX, f32::min), f.iter().cloned().fold(0.0, f32::max));
    assert!(hi / lo - 1.0 < 0.05, "{f:?}");
}

/// Frequency of the first mode against DBH/H² across a size series of the aspen (×0.8 to
/// ×2, 10–25 m): linear with R² ≥ 0.9, and 0.2–1 Hz. Every other Weber–Penn preset's series
/// is printed beside it.
#[test]
fn trunk_frequency_is_linear_in_dbh_over_height_squared() {
    let mut failures = Vec::new();
    for p in PRESETS.iter().filter(|p| matches!(p.kind, PresetKind::Species)) {
        let mut points = Vec::new();
        for factor in [0.8, 1.0, 1.3, 1.6, 2.0] {
            let t = species(p.name, factor, 1);
            let (h, dbh) = (t.height(), t.dbh().unwrap());
            let f = stem_frequencies(&t, AkagiParams::default().min_radius).hz(0);
            println!("{:<16} ×{factor:<3} H {h:5.1} m DBH {:5.3} m f {f:.3} Hz", p.name, dbh);
            let held = p.name == "quaking_aspen";
            if held && (10.0..=30.0).contains(&h) && !(0.2..=1.0).contains(&f) {
                failures.push(format!("{} ×{factor}: {f} Hz at {h} m", p.name));
            }
            points.push(((dbh / (h * h)) as f64, f as f64));
        }
        let (_, _, r2) = linear_fit(&points);
        println!("{:<16} R² {r2:.3}", p.name);
        if p.name == "quaking_aspen" && r2 < 0.9 {
            failures.push(format!("{}: R² {r2}", p.name));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Step response: a wind that starts at once; the trunk top rings about its new lean with
/// the structural damping and the air's, which grows with the wind.
#[test]
fn akagi_damping_is_in_the_field_range_and_rises_with_wind() {
    let t = small_aspen();
    let a = Akagi::new(&t, AkagiParams::default());
    let dt = 1.0 / 60.0;
    let top = trunk_top(&t);
    let rest = t.segments.end(top);
    let mut zetas = Vec::new();
    for speed in [3.0f32, 6.0, 10.0] {
        let mut s = a.rest_state(&t);
        let x: Vec<f32> = record(&a, &t, &mut s, &constant(speed).packed(), dt, 1200, |p| p.end(&t, top) - rest)
            .iter()
            .map(|d| d.x)
            .collect();
        let lean = x[900..].iter().sum::<f32>() / 300.0;
        let peak = x.iter().map(|v| (v - lean).abs()).fold(0.0, f32::max);
        let z = damping_ratio(&x[..900], lean, 0.05 * peak).expect("no ringing");
        println!("akagi {speed} m/s: lean {lean:.3} m, ζ {z:.3}");
        assert!((0.02..=0.2).contains(&z), "{speed} m/s: ζ {z}");
        zetas.push(z);
    }
    assert!(zetas.windows(2).all(|w| w[1] > w[0]), "damping does not rise with wind: {zetas:?}");
}

/// Standard deviation of the trunk top's horizontal motion in the `gusty` preset (6 m/s
/// mean), as a fraction of height.
#[test]
fn akagi_sways_half_to_three_percent_of_its_height_in_a_moderate_breeze() {
    let t = species("quaking_aspen", 1.0, 1);
    let a = Akagi::new(&t, AkagiParams::default());
    let wind = WindScene::resolve("gusty").unwrap().packed();
    let top = trunk_top(&t);
    let mut s = a.rest_state(&t);
    let dt = 1.0 / 60.0;
    let d = record(&a, &t, &mut s, &wind, dt, 3600, |p| p.end(&t, top));
    let tail = &d[600..];
    let mean = tail.iter().copied().sum::<Vec3>() / tail.len() as f32;
    let var =
        tail.iter().map(|p| ((*p - mean) * Vec3::new(1.0, 0.0, 1.0)).length_squared()).sum::<f32>() / tail.len() as f32;
    let sway = var.sqrt() / t.height();
    println!("akagi aspen ({:.1} m): trunk-top sway {:.2} % of height", t.height(), 100.0 * sway);
    assert!((0.005..=0.03).contains(&sway), "sway {} % of height", 100.0 * sway);
}

/// Ten simulated minutes of 60 m/s wind with turbulence: no NaN, bends bounded.
#[test]
fn akagi_survives_ten_minutes_of_hurricane() {
    let t = SpeciesSource::resolve("monopodial").unwrap().generate(2, &Default::default(), None).unwrap();
    println!("{} segments", t.segments.len());
    let a = Akagi::new(&t, AkagiParams::default());
    let mut wind = constant(60.0);
    wind.fields.push(WindField::Turbulence(Turbulence {
        intensity: 12.0,
        mean_speed: 60.0,
        ..match WindScene::resolve("gusty").unwrap().fields.into_iter().find(|f| matches!(f, WindField::Turbulence(_)))
        {
            Some(WindField::Turbulence(t)) => t,
            _ => unreachable!(),
        }
    }));
    let fw = wind.packed();
    let mut s = a.rest_state(&t);
    for k in 0..36_000 {
        a.step(&t, &fw, &mut s, 1.0 / 60.0);
        if k % 600 == 599 {
            s.pose.check_sound(&t).unwrap_or_else(|e| panic!("step {k}: {e}"));
            let worst = s.theta.iter().map(|th| Vec3::new(th[0], th[1], th[2]).length()).fold(0.0, f32::max);
            let stop = 3.0 * a.params.stiffening_angle + 1e-4;
            assert!(worst <= stop, "step {k}: a joint bent {worst} rad, past the stop at {stop}");
        }
    }
}
