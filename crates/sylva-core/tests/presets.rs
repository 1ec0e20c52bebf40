//! Every shipped preset generates a tree that satisfies the model's invariants, checked here
//! independently of `Tree::validate`.

use glam::Vec3;
use sylva_core::species::{PRESETS, SpeciesSource};
use sylva_core::{NONE, Tree};

/// A stem's Bézier must pass within this fraction of the stem's length of every joint.
/// (Weber–Penn stems with large random curvature, e.g. Sassafras' CurveV = 300°, are the
/// worst case: about 6 %.)
const BEZIER_MAX_REL: f32 = 0.08;
/// ... and within this fraction on average over a tree's stems.
const BEZIER_MEAN_REL: f32 = 0.005;

fn dist_to_segment(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(1e-30)).clamp(0.0, 1.0);
    (a + ab * t - p).length()
}

fn check(t: &Tree, name: &str) {
    let s = &t.segments;
    assert!(!s.is_empty(), "{name}: no segments");
    let height = t.height();
    assert!(height > 0.5, "{name}: height {height}");
    let tol = 1e-4 * height;
    for i in 0..s.len() {
        let p = s.parent[i];
        assert!(p == NONE || (p as usize) < i, "{name}: segment {i} parent {p} not before it");
        for q in [s.orientation[i], s.local_orientation[i]] {
            assert!((q.length() - 1.0).abs() < 1e-4, "{name}: segment {i} quaternion not unit");
        }
        assert!(s.radius_base[i] > 0.0 && s.radius_tip[i] > 0.0, "{name}: radius not positive");
        assert!(s.radius_tip[i] <= s.radius_base[i], "{name}: radius grows within segment {i}");
        assert!(s.length[i] > 0.0 && s.mass[i] > 0.0 && s.stiffness[i] > 0.0);
        if p != NONE {
            let p = p as usize;
            let d = dist_to_segment(s.start[i], s.start[p], s.end(p));
            assert!(d <= tol, "{name}: segment {i} base {d} m from parent (tol {tol})");
            if s.stem[p] == s.stem[i] {
                assert!(s.radius_base[i] <= s.radius_tip[p], "{name}: radius grows along stem at {i}");
            }
            let composed = s.orientation[p] * s.local_orientation[i];
            assert!(composed.dot(s.orientation[i]).abs() > 1.0 - 1e-5, "{name}: local orientation wrong at {i}");
        }
    }
    // Children lists agree with parents.
    for i in 0..s.len() {
        for &c in t.children.of(i) {
            assert_eq!(s.parent[c as usize] as usize, i);
        }
    }
    // Leaves on their segments, unit orientations.
    for k in 0..t.leaves.len() {
        let sg = t.leaves.segment[k] as usize;
        let d = dist_to_segment(t.leaves.position[k], s.start[sg], s.end(sg));
        assert!(d <= tol, "{name}: leaf {k} off its segment by {d}");
        assert!((t.leaves.orientation[k].length() - 1.0).abs() < 1e-4);
    }
    // Béziers reproduce the centrelines.
    let mut mean = 0.0;
    for k in 0..t.stems.len() {
        let first = t.stems.first_segment[k] as usize;
        let n = t.stems.segment_count[k] as usize;
        let b = sylva_core::model::CubicBezier(t.stems.bezier[k]);
        let len = t.stems.length[k];
        let mut worst: f32 = 0.0;
        for j in 0..=n {
            let joint = if j < n { s.start[first + j] } else { s.end(first + n - 1) };
            let d = (0..=256).map(|q| (b.eval(q as f32 / 256.0) - joint).length()).fold(f32::MAX, f32::min);
            worst = worst.max(d);
        }
        assert!(worst <= BEZIER_MAX_REL * len + 1e-3 * len, "{name}: stem {k} Bézier {worst} m off (length {len})");
        mean += worst / len;
    }
    mean /= t.stems.len() as f32;
    assert!(mean <= BEZIER_MEAN_REL, "{name}: mean Bézier error {mean}");
}

#[test]
fn every_preset_generates_a_valid_tree() {
    for p in PRESETS {
        for seed in [1, 2] {
            let t = SpeciesSource::from_preset(p)
                .unwrap()
                .generate(seed, &Default::default(), None)
                .unwrap_or_else(|e| panic!("{}: {e}", p.name));
            t.validate().unwrap_or_else(|e| panic!("{}: {e}", p.name));
            check(&t, p.name);
        }
    }
}

#[test]
fn raw_arrays_mirror_the_model() {
    let t = SpeciesSource::resolve("quaking_aspen").unwrap().generate(3, &Default::default(), None).unwrap();
    let raw = t.raw_segments();
    assert_eq!(raw.len(), t.segments.len());
    assert_eq!(std::mem::size_of_val(&raw[0]), 96);
    for (i, r) in raw.iter().enumerate().step_by(97) {
        assert_eq!(r.parent, t.segments.parent[i]);
        assert_eq!(r.start, t.segments.start[i].to_array());
        assert_eq!(r.child_count, t.children.count[i]);
    }
    let stems = t.raw_stems();
    assert_eq!(stems[5].bezier[2][..3], t.stems.bezier[5][2].to_array());
    let leaves = t.raw_leaves();
    assert_eq!(leaves.len(), t.leaves.len());
    assert_eq!(leaves[10].segment, t.leaves.segment[10]);
    // Casting to bytes works (Pod) and has the expected size.
    assert_eq!(bytemuck::cast_slice::<_, u8>(&raw).len(), 96 * raw.len());
}

#[test]
fn mass_and_stiffness_follow_the_formulas() {
    let t = SpeciesSource::resolve("lombardy_poplar").unwrap().generate(1, &Default::default(), None).unwrap();
    let w = t.wood;
    let s = &t.segments;
    for i in (0..s.len()).step_by(53) {
        let (l, r0, r1) = (s.length[i], s.radius_base[i], s.radius_tip[i]);
        let mass = w.density * std::f32::consts::PI * l * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0;
        let stiff = w.young_modulus * std::f32::consts::PI * r0.powi(4) / 4.0 / l;
        assert!((s.mass[i] - mass).abs() <= 1e-5 * mass);
        assert!((s.stiffness[i] - stiff).abs() <= 1e-4 * stiff);
    }
    // A thick trunk segment is far stiffer than a twig.
    let trunk = s.stiffness[0];
    let twig = s.stiffness[s.len() - 1];
    assert!(trunk > 1e3 * twig);
}

/// Every preset is found by its name and by its display name, in any case, with spaces,
/// hyphens or underscores; other names find nothing.
#[test]
fn presets_are_found_by_name_and_display_name() {
    use sylva_core::species::Preset;
    for p in PRESETS {
        let display = p.display_name();
        assert_ne!(display, "", "{}", p.name);
        for name in [p.name.to_string(), p.name.replace('_', "-"), p.name.to_uppercase(), display.to_string()] {
            assert_eq!(Preset::find(&name).map(|f| f.name), Some(p.name), "`{name}`");
        }
        assert_eq!(Preset::find(&display.replace(' ', "-").to_lowercase()).map(|f| f.name), Some(p.name), "{display}");
    }
    assert_eq!(PRESETS.iter().find(|p| p.name == "quaking_aspen").unwrap().display_name(), "Quaking Aspen");
    for other in ["", "aspen", "quaking__aspen", "quaking_aspen.toml"] {
        assert!(Preset::find(other).is_none(), "`{other}`");
    }
}
