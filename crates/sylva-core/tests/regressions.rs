//! Regression tests for inputs that once panicked, succeeded falsely or ran past a limit,
//! each named after what broke. The minimised inputs are in `tests/regressions/`.

use std::path::{Path, PathBuf};
use sylva_core::io::{PendingFile, read_text};
use sylva_core::species::SpeciesSource;
use sylva_core::{Limits, Tree};

fn input(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regressions").join(name)
}

/// Generates a regression input as the CLI does: resolve, then grow.
fn grow(name: &str) -> Result<Tree, String> {
    let path = input(name);
    let arg = path.to_str().unwrap();
    SpeciesSource::resolve(arg).and_then(|s| s.generate(1, &Limits::default(), None)).map_err(|e| e.to_string())
}

fn refused(name: &str, expected: &[&str]) {
    let e = grow(name).expect_err(name);
    assert!(e.contains(name), "the error names the file: {e}");
    for x in expected {
        assert!(e.contains(x), "`{e}` should say `{x}`");
    }
}

#[test]
fn clamp_with_nan_bounds_is_an_error_not_a_panic() {
    // `f64::clamp` panics on NaN bounds; the constant is refused where it is written.
    refused("clamp_with_nan_bounds.lsys", &[":2:", "finite parameter", "NaN"]);
}

#[test]
fn clamp_with_nan_bounds_in_a_derivation_is_an_error_not_a_panic() {
    refused("clamp_with_nan_bounds_in_a_derivation.lsys", &["module 0", "NaN", "finite"]);
}

#[test]
fn tree_with_no_segments_is_refused_with_a_clear_error() {
    refused("tree_with_no_segments.lsys", &["no segment", "at least one"]);
}

#[test]
fn bracket_nesting_255_is_refused_not_wrapped_to_level_0() {
    refused("bracket_nesting_255.lsys", &["256 levels", "at most 255"]);
}

#[test]
fn bracket_nesting_254_keeps_every_level_apart() {
    let text = std::fs::read_to_string(input("bracket_nesting_255.lsys")).unwrap().replace("255", "254");
    let tree = SpeciesSource::from_text(&text, "deep.lsys").unwrap().generate(1, &Limits::default(), None).unwrap();
    assert_eq!(tree.levels, 255);
    let stats = tree.stats();
    assert_eq!(stats.segments_per_level.len(), 255);
    assert!(stats.segments_per_level.iter().all(|&n| n == 1), "one segment per level: {:?}", stats.segments_per_level);
}

#[test]
fn unmatched_open_bracket_is_an_error_as_an_unmatched_close_is() {
    refused("unmatched_open_bracket.lsys", &["`[`", "without a matching `]`", "module 3"]);
}

#[test]
fn every_regression_input_has_a_test() {
    let src = include_str!("regressions.rs");
    for e in std::fs::read_dir(input("")).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(src.contains(&format!("\"{name}\"")), "{name} has no regression test");
    }
}

#[cfg(unix)]
#[test]
fn dev_zero_as_a_species_stops_at_the_input_limit() {
    let e = read_text(Path::new("/dev/zero")).unwrap_err();
    assert!(e.contains("1048576 byte limit"), "{e}");
    let e = SpeciesSource::resolve("/dev/zero").unwrap_err().to_string();
    assert!(e.starts_with("/dev/zero") && e.contains("limit"), "{e}");
}

#[test]
fn bad_utf8_is_reported_with_its_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.lsys");
    std::fs::write(&path, b"name: x\naxiom: F\xffF\n").unwrap();
    let e = read_text(&path).unwrap_err();
    assert!(e.contains("line 2, column 9") && e.contains("UTF-8"), "{e}");
}

#[test]
fn an_empty_output_is_never_committed_under_its_final_name() {
    // A full disk under an encoder that drops its write errors leaves an empty temporary file.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.gif");
    let p = PendingFile::new(&path).unwrap();
    drop(p.create().unwrap());
    let e = p.commit().unwrap_err();
    assert!(e.to_string().contains("empty"), "{e}");
    assert!(!path.exists());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "the temporary file is removed");
}

#[test]
fn limit_errors_name_a_flag_that_exists() {
    let limits = Limits { max_segments: 10, ..Limits::default() };
    let e = SpeciesSource::resolve("quaking_aspen").unwrap().generate(1, &limits, None).unwrap_err().to_string();
    assert!(e.contains("--max-segments"), "{e}");
    let grammar = "iterations: 5000\naxiom: F\n";
    let e = SpeciesSource::from_text(grammar, "g.lsys").unwrap_err().to_string();
    assert!(e.contains("max_iterations") && e.contains("--max-iterations"), "{e}");
    // The flag the message names raises the limit that the file is parsed with.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("g.lsys");
    std::fs::write(&path, grammar).unwrap();
    let arg = path.to_str().unwrap();
    assert!(SpeciesSource::resolve(arg).is_err());
    assert!(SpeciesSource::resolve_with(arg, &Limits { max_iterations: 10_000, ..Limits::default() }).is_ok());
}

#[test]
fn a_million_character_unknown_key_is_not_echoed_whole() {
    let text = format!("name = \"x\"\n{} = 1\n", "k".repeat(1_000_000));
    let e = SpeciesSource::from_text(&text, "long.toml").unwrap_err().to_string();
    assert!(e.starts_with("long.toml:2:1:") && e.contains("(1000000 characters)"), "{}", &e[..e.len().min(300)]);
    assert!(!e.contains(&"k".repeat(100)) && e.len() < 1000, "{} bytes: {e}", e.len());
}

#[test]
fn a_huge_float_is_not_printed_as_309_digits() {
    let e = SpeciesSource::from_text("name = \"x\"\nshape = 1.797e308\n", "big.toml").unwrap_err().to_string();
    assert!(e.contains("1.797e308") && e.len() < 200, "{e}");
}

#[test]
fn toml_errors_that_named_no_key_name_it() {
    let e = SpeciesSource::from_text("name = \"x\"\nname = \"y\"\n", "dup.toml").unwrap_err().to_string();
    assert!(e.contains("dup.toml:2") && e.contains("duplicate key") && e.contains("`name`"), "{e}");
    let wind = "[[field]]\nkind = \"constant\"\nspeed = { a = 1 }\ndirection = [1.0, 0.0, 0.0]\n";
    let e = sylva_core::wind::WindScene::from_toml(wind, "w.toml").unwrap_err().to_string();
    assert!(e.contains("w.toml:3") && e.contains("`speed`"), "{e}");
}

#[test]
fn wind_range_errors_name_the_line() {
    let wind = "[[field]]\nkind = \"constant\"\ndirection = [1.0, 0.0, 0.0]\nspeed = 1e9\n";
    let e = sylva_core::wind::WindScene::from_toml(wind, "w.toml").unwrap_err().to_string();
    assert!(e.starts_with("w.toml:4: field[0].speed") && e.contains("outside"), "{e}");
}

/// Degenerate trees the hardening report asked about: one segment and no leaf (`axiom: F`),
/// a Weber–Penn trunk with no branch level and no leaf (`levels = 1`, `leaves = 0`), and a
/// grammar whose branches skip a level (a level-2 stem straight on the trunk is impossible
/// in a grammar, so levels 0 and 1 with leaves only on the trunk). Every method steps them
/// through 2 s of gusty wind: the pose stays finite and the tip moves.
#[test]
fn degenerate_trees_simulate_in_every_method() {
    use std::sync::Arc;
    use sylva_core::methods::{MethodOptions, akagi, hsm, skjermo, zioma};
    let one =
        SpeciesSource::from_text("name: one\naxiom: F\n", "one.lsys").unwrap().generate(1, &Limits::default(), None);
    let palm =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/species/palm.toml")).unwrap();
    // Too many [[level]] tables for `levels = 1` are refused at the first of them.
    let e = SpeciesSource::from_text(&palm.replace("levels = 2", "levels = 1"), "trunk.toml").unwrap_err().to_string();
    let first = palm.lines().position(|l| l.starts_with("[[level]]")).unwrap() + 1;
    assert!(e.starts_with(&format!("trunk.toml:{first}:")) && e.contains("3 [[level]] tables"), "{e}");
    // The trunk's [[level]] table and the one placing leaves: the third is dropped.
    let third = palm.match_indices("[[level]]").nth(2).unwrap().0;
    let text = palm[..third].replace("levels = 2", "levels = 1").replace("leaves = ", "leaves = 0 #");
    let trunk = SpeciesSource::from_text(&text, "trunk.toml").unwrap().generate(1, &Limits::default(), None);
    let leaf_on_trunk =
        SpeciesSource::from_text("name: l\naxiom: F[+F]FL\n", "l.lsys").unwrap().generate(1, &Limits::default(), None);
    let wind = Arc::new(sylva_core::wind::WindScene::resolve("gusty").unwrap().packed());
    for (name, tree) in [("one segment", one), ("trunk only", trunk), ("leaf on the trunk", leaf_on_trunk)] {
        let tree = Arc::new(tree.unwrap_or_else(|e| panic!("{name}: {e}")));
        assert!(!tree.segments.is_empty(), "{name}");
        let options = MethodOptions::seeded(1);
        for mut animator in [
            zioma::animator(tree.clone(), &options).unwrap(),
            akagi::animator(tree.clone(), &options).unwrap(),
            skjermo::animator(tree.clone(), &options).unwrap(),
            hsm::animator(tree.clone(), &options).unwrap(),
        ] {
            animator.set_wind(wind.clone());
            let rest = animator.pose();
            animator.advance(1.0 / 60.0, 120);
            let pose = animator.pose();
            let method = animator.name();
            assert!(pose.start.iter().all(|p| p.is_finite()), "{name}, {method}: finite joints");
            assert!(pose.orientation.iter().all(|q| q.is_finite()), "{name}, {method}: finite rotations");
            // The last segment's direction (chord ≈ angle; acos cannot resolve 1e-5 rad in f32)
            // or its joint: a bare trunk barely moves, but it moves.
            let n = tree.segments.len() - 1;
            let turned = (pose.orientation[n] * glam::Vec3::Y - rest.orientation[n] * glam::Vec3::Y).length();
            let shift = (pose.start[n] - rest.start[n]).length();
            println!("{name}, {method}: {} segments, tip turned {turned:.2e} rad, moved {shift:.2e} m", n + 1);
            assert!(turned > 1e-6 || shift > 1e-6, "{name}, {method}: the tip stayed still in 2 s of gusty wind");
        }
    }
}
