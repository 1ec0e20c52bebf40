//! Weber–Penn stem counts follow the paper's formulas, checked against a hand calculation
//! from nBranches and ShapeRatio (not against the program's own output):
//!
//! * level 1: `N1 = 1Branches`, child i at offset `base + (L0 − base)(i + ½)/N1`;
//! * level 2 on level-1 stem i: `N2 = 2Branches · (0.2 + 0.8 · (L1/L0)/1Length)`, and with
//!   `L1 = L0 · 1Length · ShapeRatio(shape, (L0 − offset)/(L0 − base))` that is
//!   `2Branches · (0.2 + 0.8 · ShapeRatio)`;
//! * level 3 on level-2 stem j of N2: `N3 = 3Branches · (1 − 0.5 · offset/L1)` with
//!   `offset/L1 = (j + ½)/N2`.
//!
//! Counts round to the nearest whole number.

use sylva_core::species::SpeciesSource;

const SPECIES: &str = r#"
name = "Count check"
shape = 1            # spherical: ShapeRatio = 0.2 + 0.8 sin(π r)
base_size = 0.25
scale = 10.0
scale_v = 0.0
levels = 4
ratio = 0.02
ratio_power = 1.0
leaves = 0

[[level]]
length = 1.0
curve_res = 4

[[level]]
branches = 37
length = 0.4
curve_res = 3
down_angle = 50

[[level]]
branches = 13
length = 0.5
curve_res = 2

[[level]]
branches = 7
length = 0.5
curve_res = 1
"#;

fn spherical(r: f64) -> f64 {
    0.2 + 0.8 * (std::f64::consts::PI * r).sin()
}

#[test]
fn per_level_stem_counts_match_a_hand_calculation() {
    let (b1, b2, b3) = (37.0f64, 13.0f64, 7.0f64);
    let (l0, base) = (10.0f64, 2.5f64);
    let n1 = b1 as usize;
    let mut n2_total = 0usize;
    let mut n3_total = 0usize;
    for i in 0..n1 {
        let offset = base + (l0 - base) * (i as f64 + 0.5) / n1 as f64;
        let sr = spherical((l0 - offset) / (l0 - base));
        let n2 = (b2 * (0.2 + 0.8 * sr)).round() as usize;
        n2_total += n2;
        for j in 0..n2 {
            n3_total += (b3 * (1.0 - 0.5 * (j as f64 + 0.5) / n2 as f64)).round() as usize;
        }
    }
    for seed in [1, 99] {
        let t =
            SpeciesSource::from_text(SPECIES, "count.toml").unwrap().generate(seed, &Default::default(), None).unwrap();
        let s = t.stats();
        assert_eq!(s.stems_per_level, vec![1, n1, n2_total, n3_total], "seed {seed}");
        // Segments follow nCurveRes.
        assert_eq!(s.segments_per_level, vec![4, 3 * n1, 2 * n2_total, n3_total]);
    }
    // The hand calculation is not trivially constant: it depends on the shape.
    assert!(n2_total > 13 * 37 / 2 && n2_total < 13 * 37);
}

#[test]
fn trunk_length_and_radius_follow_scale_and_ratio() {
    let t = SpeciesSource::from_text(SPECIES, "count.toml").unwrap().generate(5, &Default::default(), None).unwrap();
    let trunk_len: f32 = (0..4).map(|i| t.segments.length[i]).sum();
    assert!((trunk_len - 10.0).abs() < 1e-3, "{trunk_len}");
    // radius_trunk = L0 · Ratio · 0Scale = 0.2 m; taper 1 (cone): r(z) = 0.2 (1 − z).
    assert!((t.segments.radius_base[0] - 0.2).abs() < 1e-5);
    assert!((t.segments.radius_base[2] - 0.1).abs() < 1e-5);
    // Level-1 lengths: L0 · 1Length · ShapeRatio at the first child's offset.
    let off = 2.5 + 7.5 * 0.5 / 37.0;
    let want = 10.0 * 0.4 * spherical((10.0 - off) / 7.5);
    assert!((t.stems.length[1] as f64 - want).abs() < 1e-4, "{} vs {want}", t.stems.length[1]);
}

#[test]
fn splits_divide_children_instead_of_multiplying_them() {
    let split = SPECIES.replacen("curve_res = 3", "curve_res = 3\nseg_splits = 1\nsplit_angle = 30", 1);
    let plain =
        SpeciesSource::from_text(SPECIES, "a.toml").unwrap().generate(1, &Default::default(), None).unwrap().stats();
    let t = SpeciesSource::from_text(&split, "b.toml").unwrap().generate(1, &Default::default(), None).unwrap();
    let s = t.stats();
    // Each level-1 stem splits once at each of its two inner joints: 1 + 1 + 2 = 4 stems.
    assert_eq!(s.stems_per_level[1], 37 * 4);
    let ratio = s.stems_per_level[2] as f64 / plain.stems_per_level[2] as f64;
    assert!((0.8..1.25).contains(&ratio), "level-2 count changed by {ratio}");
}

/// A trunk that splits into three at its first joint (`base_splits` 2, eight segments of
/// 1.25 m; radius `0.2 (1 − z)`): Weber–Penn's clones keep the radius there, 0.2 · 0.875 m
/// each; with `split_shares_section` the three share its section, each `1/√3` of it. The
/// trunk's DBH, 1.3 m up and so above the fork, is the three stems' together (`√Σd²`): the
/// unforked trunk's when they share it, `√3` times it when each keeps it.
#[test]
fn a_split_shares_the_section_when_asked_and_the_dbh_sums_the_stems_above_a_fork() {
    let forked =
        SPECIES.replacen("curve_res = 4", "curve_res = 8", 1).replacen("levels = 4", "base_splits = 2\nlevels = 4", 1);
    let grow = |share: bool| {
        let text = if share {
            forked.replacen("levels = 4", "split_shares_section = true\nlevels = 4", 1)
        } else {
            forked.clone()
        };
        SpeciesSource::from_text(&text, "fork.toml").unwrap().generate(1, &Default::default(), None).unwrap()
    };
    let at_fork = 0.2 * 0.875;
    let at_breast = 2.0 * 0.2 * (1.0 - 0.13);
    for (share, each, dbh) in [(false, at_fork, 3f32.sqrt() * at_breast), (true, at_fork / 3f32.sqrt(), at_breast)] {
        let t = grow(share);
        let (st, s) = (&t.stems, &t.segments);
        let trunks: Vec<usize> = (0..st.len()).filter(|&k| st.level[k] == 0).collect();
        assert_eq!(trunks.len(), 3, "sharing {share}: {} trunk stems", trunks.len());
        assert!((s.radius_tip[0] - at_fork).abs() < 1e-5, "sharing {share}: below the fork {}", s.radius_tip[0]);
        for &k in &trunks {
            let first = st.first_segment[k] as usize + if k == 0 { 1 } else { 0 };
            assert!(
                (s.radius_base[first] - each).abs() < 1e-5,
                "sharing {share}: stem {k} {} m, want {each}",
                s.radius_base[first]
            );
        }
        let got = t.dbh().unwrap();
        assert!((got - dbh).abs() < 1e-4, "sharing {share}: DBH {got} m, want {dbh}");
    }
}
