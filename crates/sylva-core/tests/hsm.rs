//! Hierarchical shape matching (Song et al.): cluster goals, sag, stability, determinism.

use glam::{DQuat, DVec3, Mat3, Quat, Vec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sylva_core::methods::Method;
use sylva_core::methods::akagi::max_tip_displacement;
use sylva_core::methods::hsm::kernels::{extract_rotation, hsm_clusters, hsm_goals};
use sylva_core::methods::hsm::{FIXED, Hsm, HsmLayout, HsmParams, HsmState, RawHsmClusterState};
use sylva_core::pose::Pose;
use sylva_core::species::{PRESETS, SpeciesSource};
use sylva_core::wind::{PackedWind, WindField, WindScene};
use sylva_core::{Tree, TreeBuilder, WoodProperties};

fn tree(name: &str) -> Tree {
    SpeciesSource::resolve(name).unwrap().generate(1, &Default::default(), None).unwrap()
}

fn storm(speed: f32) -> WindScene {
    let mut wind = WindScene::resolve("gusty").unwrap();
    if let WindField::Constant(c) = &mut wind.fields[0] {
        c.speed = speed;
    }
    wind
}

fn random_rotation(rng: &mut ChaCha8Rng, max_angle: f32) -> Quat {
    let axis = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
        .normalize_or(Vec3::Y);
    Quat::from_axis_angle(axis, rng.random_range(-max_angle..max_angle))
}

/// Every particle moved by one rigid transform (rotations up to 120°, cold start): each
/// cluster's goals land on its particles, so the averaged goals equal the positions (both
/// as displacements from rest).
#[test]
fn a_rigidly_moved_cluster_has_goals_at_its_positions() {
    let t = tree("stochastic_bush");
    let params = HsmParams { polar_iterations: 64, ..Default::default() };
    let h = Hsm::new(&t, params).unwrap();
    let l = &h.layout;
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for trial in 0..20 {
        let r = random_rotation(&mut rng, 2.1);
        let shift = Vec3::new(rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0));
        let mut s = h.state_at_rest();
        for (u, x0) in s.displacement.iter_mut().zip(&l.rest) {
            let x0 = Vec3::new(x0[0], x0[1], x0[2]);
            let d = (r * x0 + shift) - x0;
            *u = [d.x, d.y, d.z, u[3]];
        }
        let step = h.step_params(0.0, 1.0 / 240.0);
        // Cold start from R = I: thin clusters converge slowly, so let the warm start carry
        // the extraction over a few calls, as consecutive substeps do.
        for _ in 0..8 {
            hsm_clusters(&[], &[], &l.info, &l.clusters, &l.slots, &s.displacement, step, &mut s.clusters);
        }
        hsm_goals(&l.member_offset, &l.member, &s.clusters, &mut s.goal);
        for (i, (g, x)) in s.goal.iter().zip(&s.displacement).enumerate() {
            let d = (Vec3::new(g[0], g[1], g[2]) - Vec3::new(x[0], x[1], x[2])).length();
            assert!(d <= 1e-5, "trial {trial}: particle {i} goal off by {d} m");
        }
        for c in &s.clusters {
            let q = Quat::from_array(c.rotation);
            assert!(q.dot(r).abs() > 1.0 - 1e-5, "trial {trial}: cluster rotation {q:?}, moved by {r:?}");
        }
    }
}

/// Zero, rank-one, flat, inverted, tiny and huge matrices: always a unit quaternion.
#[test]
fn rotation_extraction_never_yields_nan() {
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let mut cases = vec![
        Mat3::ZERO,
        Mat3::from_diagonal(Vec3::new(1.0, 0.0, 0.0)),
        Mat3::from_diagonal(Vec3::new(-1.0, -1.0, -1.0)),
    ];
    for _ in 0..500 {
        let mut m = Mat3::from_cols_array(&std::array::from_fn(|_| rng.random_range(-1.0f32..1.0)));
        match rng.random_range(0..4) {
            0 => m.z_axis = Vec3::ZERO,                                          // flat
            1 => m = Mat3::from_cols(m.x_axis, m.x_axis * 2.0, m.x_axis * -0.5), // rank one
            2 => m *= 1e-30,
            _ => m *= 1e20,
        }
        cases.push(m);
    }
    for (k, m) in cases.iter().enumerate() {
        let start = random_rotation(&mut rng, 3.1);
        let q = extract_rotation(*m, start, 30);
        assert!(q.is_finite() && (q.length() - 1.0).abs() < 1e-5, "case {k}: {m:?} gave {q:?}");
    }
    // A proper rotation times a stretch is found from far away.
    for _ in 0..100 {
        let r = random_rotation(&mut rng, 3.0);
        let s = Mat3::from_diagonal(Vec3::new(
            rng.random_range(0.5..2.0),
            rng.random_range(0.5..2.0),
            rng.random_range(0.5..2.0),
        ));
        let q = extract_rotation(Mat3::from_quat(r) * s, Quat::IDENTITY, 64);
        assert!(q.dot(r).abs() > 1.0 - 1e-4, "{q:?} vs {r:?}");
    }
}

/// Regression: with Müller's step alone an elongated cluster turned about its long axis by
/// only `(σ₂ + σ₃) / (σ₁ + σ₂ + σ₃)` of the way per iteration, so two warm iterations per
/// step left palm fronds up to 1.8 rad from their optimal rotation (and a real GPU, rounding
/// differently, drifted 1.6e-3 × height from the CPU over 1,000 steps). Clusters 3–50× longer
/// than wide (σ₂/σ₁ from 4e-4 to 0.09) now reach their rotation within 1e-4 rad: in the
/// default two iterations from a step's turn (0.05 rad), in eight from 1 rad. Müller's step
/// alone is checked to miss by more than 1e-2 rad, so the test can fail.
#[test]
fn elongated_clusters_reach_their_rotation_in_two_iterations() {
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    for (turn, iterations) in [(0.05f32, 2u32), (1.0, 8)] {
        let (mut newton, mut muller) = (0.0f32, 0.0f32);
        for _ in 0..300 {
            let r = random_rotation(&mut rng, turn);
            let thin = rng.random_range(2e-2f32..3e-1);
            let s = Mat3::from_diagonal(Vec3::new(1.0, thin * thin, thin * thin * rng.random_range(0.0..1.0)));
            // The stretch's axes in a random frame, so the long axis is no coordinate axis.
            let f = Mat3::from_quat(random_rotation(&mut rng, 3.1));
            let a = Mat3::from_quat(r) * f * s * f.transpose();
            let angle = |q: Quat| 2.0 * (q - r).length().min((q + r).length());
            newton = newton.max(angle(extract_rotation(a, Quat::IDENTITY, iterations)));
            let mut q = Quat::IDENTITY;
            for _ in 0..iterations {
                let m = Mat3::from_quat(q);
                let g = m.x_axis.cross(a.x_axis) + m.y_axis.cross(a.y_axis) + m.z_axis.cross(a.z_axis);
                let tr = m.x_axis.dot(a.x_axis) + m.y_axis.dot(a.y_axis) + m.z_axis.dot(a.z_axis);
                let w = g / tr.abs();
                q = (Quat::from_axis_angle(w.normalize(), w.length()) * q).normalize();
            }
            muller = muller.max(angle(q));
        }
        println!(
            "from up to {turn} rad in {iterations} iterations: {newton:.1e} rad off (Müller's step alone {muller:.1e})"
        );
        assert!(newton < 1e-4, "from up to {turn} rad: {newton} rad off after {iterations} iterations");
        assert!(muller > 1e-2, "Müller's step alone converged ({muller} rad): the clusters are not elongated enough");
    }
}

/// Regression: the rotation step switched between Newton's and Müller's at thresholds (the
/// length of Müller's step, `det H`) and the iteration stopped below |ω| < 2e-6, so a
/// rounding difference that crossed one became a jump, and two runs 1e-10 m/s apart ended
/// 1e-5 × height apart after 1,000 steps (a GPU 5e-3). Now the step is blended: sweeping an
/// elongated cluster's turn finely across the old switch (|μ| = 0.05) and the blend's end
/// (0.1), and its thinness across `det H = 10⁻⁴ (tr B)³`, the rotation changes by no more
/// than a few times the input's change. A switched step jumps by `|H⁻¹ g − μ|`, here ≥ 3e-3
/// rad per 1e-5 of turn, which the bound excludes.
#[test]
fn rotation_extraction_has_no_jumps() {
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    let axis = Vec3::new(0.3, 1.0, -0.2).normalize();
    for _ in 0..20 {
        let f = Mat3::from_quat(random_rotation(&mut rng, 3.1));
        let thin = rng.random_range(0.05f32..0.3);
        let s = f * Mat3::from_diagonal(Vec3::new(1.0, thin * thin, 0.5 * thin * thin)) * f.transpose();
        let turn_axis = (axis + f.x_axis * rng.random_range(-0.5..0.5)).normalize();
        // Müller's step is about (turn × the stretch's scale) / tr: sweep the turn over the blend.
        let mut last: Option<(f32, Quat)> = None;
        let n = 4000;
        for k in 0..=n {
            let turn = 0.02 + 0.16 * k as f32 / n as f32;
            let a = Mat3::from_quat(Quat::from_axis_angle(turn_axis, turn)) * s;
            let q = extract_rotation(a, Quat::IDENTITY, 1);
            if let Some((t0, q0)) = last {
                let dq = 2.0 * (q - q0).length().min((q + q0).length());
                assert!(dq <= 8.0 * (turn - t0), "turn {t0} → {turn}: the rotation jumped by {dq} rad");
            }
            last = Some((turn, q));
        }
    }
    // Thinness across the positive-definite blend: det H / (tr B)³ from 5e-5 to 4e-4, turned
    // 0.02 rad about the long axis, where Newton's and Müller's steps differ by ~0.02 rad.
    // Formed from A, the turn about the axis is known only to ~ε/thinness (≤ 2e-3 rad here).
    for _ in 0..20 {
        let f = Mat3::from_quat(random_rotation(&mut rng, 3.1));
        let r = Quat::from_axis_angle(f.x_axis, 0.02);
        let mut last: Option<(f32, Quat)> = None;
        let n = 4000;
        for k in 0..=n {
            let thin = 5e-5 + 3.5e-4 * k as f32 / n as f32;
            let a = Mat3::from_quat(r) * f * Mat3::from_diagonal(Vec3::new(1.0, thin, 0.0)) * f.transpose();
            let q = extract_rotation(a, Quat::IDENTITY, 1);
            if let Some((t0, q0)) = last {
                let dq = 2.0 * (q - q0).length().min((q + q0).length());
                assert!(dq <= 5e-3, "thinness {t0} → {thin}: the rotation jumped by {dq} rad");
            }
            last = Some((thin, q));
        }
    }
}

/// A horizontal cantilever of six segments under bare gravity.
fn cantilever() -> Tree {
    let mut b = TreeBuilder::default();
    let stem = b.add_stem(None, 0);
    let frame = DQuat::from_rotation_z(-std::f64::consts::FRAC_PI_2); // local +Y along +X
    for k in 0..6 {
        let start = DVec3::new(0.5 * k as f64, 1.0, 0.0);
        b.push_segment(stem, start, start + DVec3::new(0.5, 0.0, 0.0), frame, 0.02, 0.02);
    }
    b.build("cantilever", 0, WoodProperties::default()).unwrap()
}

/// The static sag does not depend on the substep (α = k h² makes the pull a spring of
/// stiffness k), so it converges as substeps increase; it points down and is not trivial.
/// Exactly `substeps` substeps, uncalibrated: the scheme itself.
#[test]
fn a_cantilever_sags_the_same_whatever_the_substeps() {
    let t = cantilever();
    let mut sags = Vec::new();
    for substeps in [1, 2, 4, 8, 16] {
        let params = HsmParams {
            prestressed: false,
            stiffness_scale: 0.25,
            substeps,
            substep_rate: 0.0,
            calibrate: false,
            ..Default::default()
        };
        let h = Hsm::new(&t, params).unwrap();
        let alpha_max =
            h.layout.clusters.iter().map(|c| c.rest_cm[3]).fold(0.0, f32::max) / (240.0 * substeps as f32).powi(2);
        assert!(alpha_max < 1.0, "α {alpha_max} clamps: the test needs a soft chain");
        let mut s = h.state_at_rest();
        let steps = h.settle(&mut s, 1.0 / 240.0, 40_000, 1e-8);
        assert!(steps < 20_000, "{substeps} substeps: never settled");
        let tip = h.pose(&t, &PackedWind::calm(), &s).end(&t, 5);
        let rest = t.segments.end(5);
        sags.push(tip - rest);
    }
    println!("tip sag by substeps 1, 2, 4, 8, 16: {sags:?}");
    let last = sags[sags.len() - 1];
    assert!(last.y < -1e-3, "no sag: {last:?}");
    assert!(last.length() < 0.5 * 3.0, "the cantilever hangs instead of sagging: {last:?}");
    for w in sags.windows(2) {
        let d = (w[1] - w[0]).length();
        assert!(d <= 0.02 * last.length(), "sag changes by {d} m between substep counts: {sags:?}");
    }
}

/// Regression, named after what broke: each cluster's α was clamped at 1 *before* a shared
/// particle's goals were averaged, so every cluster stiffer than `1/h²` had an equal say, a
/// thick stem held the ring it shares with a twig no better than the twig did, and the
/// stochastic bush (3 cm stems of 8 GPa wood, ~50× stiffer than a 240 Hz step holds that
/// way) lay down in gusty wind: segment ends 2.0 m from rest on a 2.3 m bush, and with a
/// tenth of the wood's stiffness it bent *less* (1.4 m). With the mean weighted by `k h²`
/// (see `kernels::MAX_WEIGHT`), its segment ends stay within a tenth of its height, and
/// softer wood bends it more.
#[test]
fn a_stiff_bush_does_not_lie_down_in_gusty_wind() {
    let t = tree("stochastic_bush");
    let wood = most_bending(&t, 1.0);
    let soft = most_bending(&t, 0.1);
    println!(
        "bush of {:.2} m: segment ends up to {wood:.3} m from rest, {soft:.3} m with a tenth of the stiffness",
        t.height()
    );
    assert!(wood > 1e-3, "the bush did not move: {wood} m");
    assert!(wood < 0.1 * t.height(), "the bush bends {wood} m, more than a tenth of its {} m", t.height());
    assert!(soft > 1.5 * wood, "a tenth of the stiffness bends it {soft} m, against {wood} m");
}

/// The largest distance of any segment end from rest over 4 s of `gusty` at 60 frames/s,
/// with the wood's stiffness scaled by `stiffness_scale`.
fn most_bending(t: &Tree, stiffness_scale: f32) -> f32 {
    let fw = WindScene::resolve("gusty").unwrap().packed();
    let h = Hsm::new(t, HsmParams { stiffness_scale, ..Default::default() }).unwrap();
    let mut s = h.state_at_rest();
    let mut most = 0.0f32;
    for k in 0..240 {
        h.step_packed(&fw.fields, &fw.waves, &mut s, 1.0 / 60.0);
        if k % 6 == 5 {
            most = most.max(max_tip_displacement(t, &h.pose(t, &PackedWind::calm(), &s)));
        }
    }
    most
}

/// Regression, named after what broke: with the weights unbounded past 1, a thin lateral
/// whose rate is high only because it is light pulled the trunk rings it overlaps at that
/// rate and outweighed the trunk there, and monopodial's trunk followed its laterals: tips
/// 3.0 m from rest in gusty wind on a 9.8 m tree (0.24 m with every weight clamped at 1).
/// A weight now passes 1 only up to the smallest rate on its path to the root.
#[test]
fn light_laterals_do_not_drag_a_monopodial_trunk() {
    let t = tree("monopodial");
    let most = most_bending(&t, 1.0);
    println!("monopodial of {:.2} m: segment ends up to {most:.3} m from rest", t.height());
    assert!(most > 1e-3, "the tree did not move: {most} m");
    assert!(most < 0.05 * t.height(), "segment ends {most} m from rest, more than 5 % of {} m", t.height());
}

#[test]
fn still_air_keeps_the_exact_rest_pose() {
    for name in ["monopodial", "quaking_aspen"] {
        let t = tree(name);
        let h = Hsm::new(&t, HsmParams::default()).unwrap();
        let mut s = h.state_at_rest();
        let rest = s.clone();
        for _ in 0..60 {
            h.step(&t, &WindScene::default().packed(), &mut s, 1.0 / 60.0);
        }
        assert_eq!(s.displacement, rest.displacement, "{name}");
        assert_eq!(h.pose(&t, &PackedWind::calm(), &s), Pose::rest(&t), "{name}");
    }
}

fn max_speed(s: &HsmState) -> f32 {
    s.velocity.iter().map(|v| Vec3::new(v[0], v[1], v[2]).length()).fold(0.0, f32::max)
}

/// Song's central claim, stability, in a hurricane on the whole stochastic bush: ten
/// simulated minutes (36,000 steps) of 60 m/s wind with the `gusty` preset's turbulence at
/// 12 m/s keep every particle finite and slower than twice the wind, the pose sound and
/// every leaf's rotation a finite unit quaternion; a minute after the wind stops the bush
/// is back within 1 % of its height of rest and every leaf within 1° of its rest on its
/// segment.
#[test]
fn ten_minutes_of_hurricane_stay_stable_and_recover() {
    let t = tree("stochastic_bush");
    let h = Hsm::new(&t, HsmParams::default()).unwrap();
    let mut wind = storm(60.0);
    for f in &mut wind.fields {
        if let WindField::Turbulence(tu) = f {
            (tu.intensity, tu.mean_speed) = (12.0, 60.0);
        }
    }
    let fw = wind.packed();
    let mut s = h.state_at_rest();
    let rest = s.clone();
    let mut seam = sylva_core::pose::SeamPose::default();
    let mut turned = 0.0f32;
    assert!(t.leaves.len() > 50);
    for k in 0..36_000 {
        h.step_packed(&fw.fields, &fw.waves, &mut s, 1.0 / 60.0);
        if k % 3_000 == 0 || k == 35_999 {
            h.seam(&t, &fw, &s, &mut seam);
            assert_eq!(seam.leaf.len(), t.leaves.len());
            for q in &seam.leaf {
                let q = Quat::from_array(*q);
                assert!(q.is_finite() && (q.length() - 1.0).abs() < 1e-3, "step {k}: a leaf rotation {q}");
                turned = turned.max(2.0 * q.w.abs().min(1.0).acos());
            }
            assert!(s.displacement.iter().all(|p| p.iter().all(|v| v.is_finite())), "step {k}: NaN");
            let v = max_speed(&s);
            assert!(v < 120.0, "step {k}: a particle at {v} m/s");
            if let Err(e) = h.pose(&t, &PackedWind::calm(), &s).check_sound(&t) {
                panic!("step {k}: {e}");
            }
        }
    }
    assert!(s.max_distance(&rest) > 1e-3, "the hurricane moved nothing");
    for _ in 0..3_600 {
        h.step_packed(&[], &[], &mut s, 1.0 / 60.0);
    }
    let d = s.max_distance(&rest);
    assert!(d <= 0.01 * t.height(), "a minute after the hurricane a particle is {d} m from rest");
    assert!(turned > 0.5, "the hurricane turned no leaf ({turned} rad)");
    h.seam(&t, &PackedWind::calm(), &s, &mut seam);
    let leaf = seam.leaf.iter().map(|q| 2.0 * q[3].abs().min(1.0).acos()).fold(0.0, f32::max).to_degrees();
    println!("leaves: at most {:.1}° in the hurricane, {leaf:.3}° a minute after it", turned.to_degrees());
    assert!(leaf <= 1.0, "a minute after the hurricane a leaf is {leaf}° from rest");
}

/// Every preset (its first 600 clusters, grown from the root): a 1,000-step storm stays
/// finite and bounded, and a minute of calm brings it back within 1 % of its height. (The
/// presets run side by side: a layout this small steps on one thread.)
#[test]
fn every_preset_survives_a_storm_and_returns_to_rest() {
    use rayon::prelude::*;
    let fw = storm(40.0).packed();
    let runs: Vec<(bool, f32, f32, f32, f32)> = PRESETS
        .par_iter()
        .map(|p| {
            let t = SpeciesSource::from_preset(p).unwrap().generate(1, &Default::default(), None).unwrap();
            let params = HsmParams::default();
            let layout = HsmLayout::new(&t, &params, Some(600)).unwrap();
            let h = Hsm::from_layout(&t, params, layout);
            let mut s = h.state_at_rest();
            let rest = s.clone();
            let mut peak = 0.0f32;
            for _ in 0..1_000 {
                h.step_packed(&fw.fields, &fw.waves, &mut s, 1.0 / 60.0);
                peak = peak.max(s.max_distance(&rest));
            }
            let finite = s.displacement.iter().all(|p| p.iter().all(|v| v.is_finite()));
            let speed = max_speed(&s);
            // A minute of calm: the structural damping alone (ζ 0.04 of the trunk's mode,
            // a decay time of 1/(ζ ω₀) ≈ 4–7 s), as a tree rings down in still air.
            for _ in 0..3_600 {
                h.step_packed(&[], &[], &mut s, 1.0 / 60.0);
            }
            (finite, speed, peak, s.max_distance(&rest), t.height())
        })
        .collect();
    for (p, &(finite, speed, peak, d, height)) in PRESETS.iter().zip(&runs) {
        assert!(finite, "{}: NaN", p.name);
        assert!(speed < 80.0, "{}: a particle at {speed} m/s", p.name);
        assert!(peak > 1e-3, "{}: the storm moved nothing", p.name);
        println!("{:<16} peak {peak:.3} m, after calm {d:.2e} m (height {height:.1} m)", p.name);
        // Known limit, open in the tracker: the palm's leaflets are long blades on thin
        // rings, so a leaf cluster's rigid fit barely feels its petiole ring and a leaflet
        // turned over by the storm stays turned. It must still be stable (asserted above).
        if p.name != "palm" {
            assert!(d <= 0.01 * height, "{}: {d} m from rest after the calm (height {height} m)", p.name);
        }
    }
}

#[test]
fn hsm_is_identical_on_any_thread_count() {
    let t = tree("quaking_aspen");
    let wind = WindScene::resolve("gusty").unwrap();
    let params = HsmParams::default();
    let layout = HsmLayout::new(&t, &params, Some(3_000)).unwrap();
    let h = Hsm::from_layout(&t, params, layout);
    let run = |n| {
        rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap().install(|| {
            let mut s = h.state_at_rest();
            for _ in 0..60 {
                h.step(&t, &wind.packed(), &mut s, 1.0 / 60.0);
            }
            s
        })
    };
    let one = run(1);
    assert_eq!(one, run(3));
    assert_ne!(one.displacement, h.state_at_rest().displacement);
}

/// The fused particle pass (stages 3 and 4 in one) gives Song's four stages bit for bit.
#[test]
fn fused_particle_stages_match_the_four_stages_exactly() {
    let t = tree("ca_black_oak");
    let wind = WindScene::resolve("gusty").unwrap();
    let four = HsmParams { fused: false, ..Default::default() };
    let fused = HsmParams { fused: true, ..four };
    let layout = HsmLayout::new(&t, &four, Some(2_000)).unwrap();
    let run = |params| {
        let h = Hsm::from_layout(&t, params, layout.clone());
        let mut s = h.state_at_rest();
        for _ in 0..120 {
            h.step(&t, &wind.packed(), &mut s, 1.0 / 60.0);
        }
        s
    };
    let (a, b) = (run(four), run(fused));
    assert_eq!(a.displacement, b.displacement);
    assert_eq!(a.velocity, b.velocity);
    assert_eq!(a.clusters, b.clusters);
    // Only the four-stage path keeps the goal buffer.
    assert_ne!(a.goal, b.goal);
}

/// Every preset with the default clusters and Song's table sizes, then `extra`: each moved
/// by ten frames of gusty wind, then every free particle's displacement jittered by up to
/// 5 cm and its velocity by up to 1 m/s (seeded): states on which the CPU's fast forms must
/// give the bits of the WGSL twins' shapes.
fn jittered_cases(extra: Vec<(String, HsmParams, Option<usize>)>, seed: u64) -> Vec<(String, Hsm, HsmState)> {
    let fw = WindScene::resolve("gusty").unwrap().packed();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut cases: Vec<(String, HsmParams, Option<usize>)> =
        PRESETS.iter().map(|p| (p.name.to_string(), HsmParams::default(), Some(1_500))).collect();
    cases.push(("quaking_aspen".into(), HsmParams::song_tables(), Some(300)));
    cases.extend(extra);
    cases
        .into_iter()
        .map(|(name, params, max)| {
            let t = tree(&name);
            let h = Hsm::from_layout(&t, params, HsmLayout::new(&t, &params, max).unwrap());
            let mut s = h.state_at_rest();
            for _ in 0..10 {
                h.step_packed(&fw.fields, &fw.waves, &mut s, 1.0 / 60.0);
            }
            for (u, v) in s.displacement.iter_mut().zip(&mut s.velocity) {
                if v[3] != FIXED {
                    for c in 0..3 {
                        u[c] += rng.random_range(-0.05..0.05);
                        v[c] += rng.random_range(-1.0..1.0);
                    }
                }
            }
            (name, h, s)
        })
        .collect()
}

/// The CPU's run pass (`hsm_particles_runs`: a ring's or a blade's particles eight to a
/// register, their clusters read once) gives the bits of the per-particle pass that the WGSL
/// twin mirrors, at every SIMD level: every preset with the default clusters (runs of two and
/// four particles, partly filled registers), Song's table sizes (rings of fourteen, blades
/// of 42) and rings that take their leaves' pull (`leaf_reaction = true`: more clusters
/// per ring particle), from states a gusty wind has moved plus random noise on
/// every free particle.
#[test]
fn the_run_pass_gives_the_per_particle_pass_bits() {
    use sylva_core::methods::hsm::kernels::hsm_particles;
    use sylva_core::methods::hsm::runs::{HsmRuns, hsm_particles_runs_at};
    use sylva_core::simd::{Level, detected};
    println!("best SIMD level here: {:?}", detected());
    let fw = WindScene::resolve("gusty").unwrap().packed();
    let reacted = HsmParams { leaf_reaction: true, ..HsmParams::default() };
    for (name, h, mut s) in jittered_cases(vec![("quaking_aspen".into(), reacted, Some(1_500))], 17) {
        let l = &h.layout;
        let runs = HsmRuns::new(l);
        assert!(runs.len() < l.particle_count(), "{name}: no particles share a run");
        let step = h.step_params(s.time + 1.0 / 240.0, 1.0 / 240.0);
        hsm_clusters(&fw.fields, &fw.waves, &l.info, &l.clusters, &l.slots, &s.displacement, step, &mut s.clusters);
        let mut reference = s.clone();
        hsm_particles(
            &l.member_offset,
            &l.member,
            &s.clusters,
            &l.owner,
            step,
            &mut reference.displacement,
            &mut reference.velocity,
        );
        assert_ne!(reference.displacement, s.displacement, "{name}: nothing moved");
        let bits = |a: &[[f32; 4]]| a.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
        for level in [Level::Baseline, Level::Avx2] {
            let mut b = s.clone();
            hsm_particles_runs_at(level, l, &runs, &s.clusters, step, &mut b.displacement, &mut b.velocity);
            assert!(bits(&b.displacement) == bits(&reference.displacement), "{name} {level:?}: displacements differ");
            assert!(bits(&b.velocity) == bits(&reference.velocity), "{name} {level:?}: velocities differ");
        }
    }
}

/// The CPU's stage 1 over groups of slots (`hsm_clusters_groups`: eight slots to a register,
/// lane blocks combined as the workgroup's lanes are) gives the bits of the per-slot stage 1
/// that the WGSL twin mirrors, at every SIMD level: every preset with the default clusters
/// (a few slots each, short groups), Song's table sizes (about 64) and clusters of over 64
/// slots (lanes that take more than one), from states a gusty wind has moved plus random
/// noise on every free particle.
#[test]
fn the_slot_groups_give_the_per_slot_stage_1_bits() {
    use sylva_core::methods::hsm::slot_groups::{HsmSlotGroups, hsm_clusters_groups_at};
    use sylva_core::simd::{Level, detected};
    println!("best SIMD level here: {:?}", detected());
    let fw = WindScene::resolve("gusty").unwrap().packed();
    let wide = HsmParams { rings: 6, ring_size: 20, leaf_particles: 21, ..HsmParams::default() };
    let sixteen = HsmParams { rings: 2, ring_size: 8, leaf_particles: 16, ..HsmParams::default() };
    let extra = vec![("sympodial".into(), wide, Some(200)), ("sympodial".into(), sixteen, Some(200))];
    let mut counts = std::collections::BTreeSet::new();
    for (name, h, s) in jittered_cases(extra, 29) {
        let l = &h.layout;
        let groups = HsmSlotGroups::new(l);
        counts.extend(l.info.iter().map(|i| i.slot_count));
        let step = h.step_params(s.time + 1.0 / 240.0, 1.0 / 240.0);
        let mut reference = s.clusters.clone();
        hsm_clusters(&fw.fields, &fw.waves, &l.info, &l.clusters, &l.slots, &s.displacement, step, &mut reference);
        assert_ne!(reference, s.clusters, "{name}: nothing moved");
        let bits = |a: &[RawHsmClusterState]| bytemuck::cast_slice::<_, u32>(a).to_vec();
        for level in [Level::Baseline, Level::Avx2] {
            let mut b = s.clusters.clone();
            hsm_clusters_groups_at(level, &fw.fields, &fw.waves, l, &groups, &s.displacement, step, &mut b);
            assert!(bits(&b) == bits(&reference), "{name} {level:?}: cluster states differ");
        }
    }
    // The cases reach every way a cluster's slots fill the lanes, in the groups (16 slots and
    // up) and on SSE (fewer).
    println!("slot counts: {counts:?}");
    let any = |p: &dyn Fn(u32) -> bool| counts.iter().any(|&c| p(c));
    assert!(any(&|c| c < 8) && any(&|c| (8..16).contains(&c)), "no small clusters");
    assert!(any(&|c| c == 16) && any(&|c| (17..=32).contains(&c)), "no clusters of 16 to 32 slots");
    assert!(any(&|c| (33..=64).contains(&c)) && any(&|c| c > 64), "no clusters of over 32 slots");
    assert!(any(&|c| c > 16 && c % 8 != 0), "no short last group");
}

/// The layout is Song's linearised tree: parents before children, children lists that
/// point back, shared particles listed under every cluster that holds them, the root ring
/// fixed, and a forest of copies that is the same layout repeated.
#[test]
fn the_layout_links_clusters_head_to_tail() {
    let t = tree("sympodial");
    let params = HsmParams::default();
    let l = HsmLayout::new(&t, &params, None).unwrap();
    assert_eq!(l.cluster_count(), t.segments.len() + t.leaves.len() + l.info.iter().filter(|i| i.kind == 2).count());
    for (c, cl) in l.clusters.iter().enumerate() {
        if cl.parent != u32::MAX && l.info[c].kind != 2 {
            assert!((cl.parent as usize) < c, "cluster {c}: parent after it");
        }
        for &ch in &l.children[cl.child_offset as usize..(cl.child_offset + cl.child_count) as usize] {
            assert_eq!(l.clusters[ch as usize].parent, c as u32);
        }
        // A child segment cluster shares particles with its parent's cluster.
        if cl.parent != u32::MAX && l.info[c].kind == 0 {
            let p = &l.info[cl.parent as usize];
            let mine =
                &l.slots[l.info[c].slot_offset as usize..(l.info[c].slot_offset + l.info[c].slot_count) as usize];
            let theirs = &l.slots[p.slot_offset as usize..(p.slot_offset + p.slot_count) as usize];
            assert!(
                mine.iter().any(|a| theirs.iter().any(|b| a.particle == b.particle)),
                "cluster {c}: no shared particle"
            );
        }
    }
    for (i, w) in l.member_offset.windows(2).enumerate() {
        for m in &l.member[w[0] as usize..w[1] as usize] {
            let c = &l.info[m.cluster as usize];
            let run = &l.slots[c.slot_offset as usize..(c.slot_offset + c.slot_count) as usize];
            assert!(run.iter().any(|s| s.particle == i as u32 && s.q == m.q), "particle {i}: member {m:?}");
        }
    }
    assert_eq!(l.free.iter().filter(|f| **f == 0.0).count(), params.ring_size as usize);
    let forest = l.forest(10, 5.0).unwrap();
    assert_eq!(forest.cluster_count(), 10 * l.cluster_count());
    assert_eq!(forest.particle_count(), 10 * l.particle_count());
    let _ = RawHsmClusterState::rest(&l.clusters[0]);
}

#[test]
fn bad_parameters_are_named() {
    let t = tree("stochastic_bush");
    for (params, field) in [
        (HsmParams { rings: 1, ..Default::default() }, "rings"),
        (HsmParams { ring_size: 2, ..Default::default() }, "ring_size"),
        (HsmParams { beta: 2.0, ..Default::default() }, "beta"),
        (HsmParams { stiffness_scale: f32::NAN, ..Default::default() }, "stiffness_scale"),
        (HsmParams { substeps: 0, ..Default::default() }, "substeps"),
    ] {
        let e = Hsm::new(&t, params).unwrap_err().to_string();
        assert!(e.contains(field), "{e}");
    }
}

/// The state is kept as displacements from rest: fixed particles (velocity w = `FIXED`)
/// stay exactly at zero through a storm, free ones carry their drag factor unchanged, and
/// `positions` is the rest plus the displacement.
#[test]
fn the_state_holds_displacements_and_fixed_particles_never_move() {
    let t = tree("stochastic_bush");
    let h = Hsm::new(&t, HsmParams::default()).unwrap();
    let l = &h.layout;
    let wind = storm(30.0);
    let mut s = h.state_at_rest();
    for _ in 0..240 {
        h.step(&t, &wind.packed(), &mut s, 1.0 / 60.0);
    }
    let positions = h.positions(&s);
    assert_eq!(positions.len(), l.particle_count());
    let mut fixed = 0;
    for (i, p) in positions.iter().enumerate() {
        let (u, v) = (s.displacement[i], s.velocity[i]);
        assert_eq!(u[3], l.mass[i], "particle {i}: mass kept in w");
        if l.free[i] == 0.0 {
            fixed += 1;
            assert_eq!(v[3], FIXED, "particle {i}");
            assert_eq!(&u[..3], &[0.0; 3], "fixed particle {i} moved");
        } else {
            assert_eq!(v[3], l.rest[i][3], "particle {i}: drag factor kept in w");
        }
        let want = Vec3::new(l.rest[i][0] + u[0], l.rest[i][1] + u[1], l.rest[i][2] + u[2]);
        assert_eq!(*p, want);
    }
    assert!(fixed > 0, "the root ring is fixed");
    assert!(s.max_distance(&h.state_at_rest()) > 1e-3, "the storm moved the bush");
}
