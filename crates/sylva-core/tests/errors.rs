//! Bad input gets a clear error naming file, line, column or field — never a panic, a hang
//! or runaway memory.

use sylva_core::generate::lsystem::LSystemError;
use sylva_core::species::{SpeciesError, SpeciesSource};
use sylva_core::{Grammar, GrammarError, LSystemOptions, Limits};

fn syntax(text: &str) -> (usize, usize, String, String) {
    match Grammar::parse(text, "bad.lsys") {
        Err(GrammarError::Syntax { file, line, column, expected, found }) => {
            assert_eq!(file, "bad.lsys");
            (line, column, expected, found)
        }
        other => panic!("expected a syntax error, got {other:?}"),
    }
}

#[test]
fn grammar_errors_name_file_line_column_and_expectation() {
    let (l, c, e, f) = syntax("axiom: A\nA -> F(1,\n");
    assert_eq!((l, c), (2, 10), "{e} / {f}");
    assert!(e.contains("number"), "{e}");
    assert_eq!(f, "end of line");

    let (l, c, e, _) = syntax("axiom: A\nA(x) : x > -> F\n");
    assert_eq!(l, 2);
    assert_eq!(c, 12);
    assert!(e.contains("number"), "{e}");

    let (l, _, e, f) = syntax("axiom: A\nA -> F(undefined_name)\n");
    assert_eq!(l, 2);
    assert!(e.contains("undefined_name"), "{e}");
    assert_eq!(f, "`u`");

    let (l, _, e, _) = syntax("# comment\n\nfrobnicate: 3\naxiom: A\n");
    assert_eq!(l, 3);
    assert!(e.contains("axiom") && e.contains("iterations"), "{e}");

    let (l, _, e, _) = syntax("iterations: 3\n");
    assert_eq!(l, 1);
    assert!(e.contains("axiom"), "{e}");

    let (_, _, e, f) = syntax("axiom: A\nA -> !F\n");
    assert!(e.contains("width"), "{e}");
    assert_eq!(f, "0 parameter(s)");

    let (l, c, _, _) = syntax("axiom: A\nA(x -> F\n");
    assert_eq!((l, c), (2, 5));

    // The Display form carries all of it.
    let msg = Grammar::parse("axiom: A\nA -> F(1,\n", "g.lsys").unwrap_err().to_string();
    assert!(msg.starts_with("g.lsys:2:10: expected"), "{msg}");
}

#[test]
fn grammar_value_errors_name_the_field() {
    let e = Grammar::parse("scale: -1\naxiom: F\n", "g.lsys").unwrap_err();
    assert!(matches!(&e, GrammarError::Value { line: 1, field, .. } if field == "scale"), "{e}");
    let e = Grammar::parse("iterations: 1e9\naxiom: F\n", "g.lsys").unwrap_err();
    assert!(matches!(&e, GrammarError::Limit { limit: "max_iterations", .. }), "{e}");
}

#[test]
fn deep_expressions_hit_the_depth_limit_not_the_stack() {
    let deep = format!("axiom: F({}1{})\n", "(".repeat(5000), ")".repeat(5000));
    let e = Grammar::parse(&deep, "deep.lsys").unwrap_err();
    assert!(matches!(e, GrammarError::Limit { limit: "max_expression_depth", .. }), "{e}");
    let neg = format!("axiom: F({}1)\n", "-".repeat(5000));
    assert!(matches!(Grammar::parse(&neg, "n.lsys").unwrap_err(), GrammarError::Limit { .. }));
}

fn species_err(text: &str) -> SpeciesError {
    SpeciesSource::from_text(text, "bad.toml").unwrap_err()
}

const BASE: &str = include_str!("../../../presets/species/quaking_aspen.toml");

#[test]
fn unknown_toml_key_is_named() {
    let text = BASE.replace("ratio_power = 1.2", "ratio_power = 1.2\nratio_powr = 2");
    match species_err(&text) {
        SpeciesError::Toml { file, line, message, .. } => {
            assert_eq!(file, "bad.toml");
            assert!(message.contains("ratio_powr"), "{message}");
            assert_eq!(text.lines().nth(line - 1).unwrap().trim(), "ratio_powr = 2");
        }
        e => panic!("{e:?}"),
    }
    let text = BASE.replacen("curve_v = 50", "curve_v = 50\nbranchez = 3", 1);
    let msg = species_err(&text).to_string();
    assert!(msg.contains("branchez") && msg.starts_with("bad.toml:"), "{msg}");
}

#[test]
fn out_of_range_values_name_the_field_and_line() {
    let cases = [
        (BASE.replacen("length = 0.3", "length = -0.3", 1), "level[1].length", "length = -0.3"),
        (BASE.replace("levels = 3", "levels = 9"), "levels", "levels = 9"),
        (BASE.replace("ratio = 0.015", "ratio = nan"), "ratio", "ratio = nan"),
        (BASE.replace("scale = 13.0", "scale = inf"), "scale", "scale = inf"),
        (BASE.replacen("curve_res = 5", "curve_res = 0", 1), "level[1].curve_res", "curve_res = 0"),
    ];
    for (text, field, line_text) in cases {
        match species_err(&text) {
            SpeciesError::Field { file, line, field: f, message } => {
                assert_eq!(file, "bad.toml");
                assert_eq!(f, field, "{message}");
                assert_eq!(text.lines().nth(line - 1).unwrap().trim(), line_text, "{field}");
                assert!(species_err(&text).to_string().contains(field));
            }
            e => panic!("{field}: {e:?}"),
        }
    }
}

#[test]
fn wrong_type_and_missing_key_are_reported_with_position() {
    let text = BASE.replace("scale = 13.0", "scale = \"tall\"");
    let msg = species_err(&text).to_string();
    assert!(msg.starts_with("bad.toml:7:"), "{msg}");
    let text = BASE.replace("shape = 7\n", "");
    let msg = species_err(&text).to_string();
    assert!(msg.contains("shape"), "{msg}");
}

#[test]
fn runaway_grammar_stops_at_the_segment_limit() {
    // Doubles every step: 2^40 segments if nothing stopped it.
    let g = Grammar::parse("iterations: 40\naxiom: F\nF -> FF\n", "runaway.lsys").unwrap();
    let limits = Limits { max_segments: 100_000, ..Limits::default() };
    match g.generate(&LSystemOptions { seed: 1, iterations: None, limits }) {
        Err(LSystemError::Limit { source, .. }) => {
            assert_eq!(source.limit, "max_segments");
            assert_eq!(source.value, 100_000);
            assert!(source.to_string().contains("max_segments"));
        }
        other => panic!("{other:?}"),
    }
    // With the default limits (5 million) too, without allocating past them.
    match g.generate(&LSystemOptions { seed: 1, iterations: None, limits: Limits::default() }) {
        Err(LSystemError::Limit { source, .. }) => {
            assert!(source.limit == "max_segments" || source.limit == "max_modules")
        }
        other => panic!("{other:?}"),
    }
    // Growth without F is caught by the module limit.
    let g = Grammar::parse("iterations: 60\naxiom: A\nA -> AA\n", "a.lsys").unwrap();
    let limits = Limits { max_modules: 1 << 16, ..Limits::default() };
    match g.derive(&LSystemOptions { seed: 1, iterations: None, limits }) {
        Err(LSystemError::Limit { source, .. }) => assert_eq!(source.limit, "max_modules"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn weber_penn_beyond_the_limit_stops() {
    let text = BASE.replace("branches = 30\n", "branches = 5000\n").replace("branches = 50\n", "branches = 5000\n");
    let src = SpeciesSource::from_text(&text, "huge.toml").unwrap();
    let limits = Limits { max_segments: 200_000, ..Limits::default() };
    let e = src.generate(1, &limits, None).unwrap_err();
    assert!(e.to_string().contains("max_segments"), "{e}");
}

#[test]
fn turtle_errors_name_the_module() {
    let g = Grammar::parse("axiom: F]F\n", "t.lsys").unwrap();
    let e = g.generate(&LSystemOptions::default()).unwrap_err();
    assert!(matches!(e, LSystemError::Turtle { module: 1, symbol: ']', .. }), "{e}");
    let g = Grammar::parse("axiom: ~F\n", "t.lsys").unwrap();
    let e = g.generate(&LSystemOptions::default()).unwrap_err().to_string();
    assert!(e.contains("leaf") && e.contains("t.lsys"), "{e}");
    let g = Grammar::parse("axiom: F(0-1)\n", "t.lsys").unwrap();
    assert!(g.generate(&LSystemOptions::default()).is_err());
}

#[test]
fn unknown_species_lists_presets() {
    let e = SpeciesSource::resolve("no_such_tree").unwrap_err().to_string();
    assert!(e.contains("no_such_tree") && e.contains("quaking_aspen"), "{e}");
}
