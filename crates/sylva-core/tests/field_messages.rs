//! One bad value per field kind, in every field of a shipped species, scene and wind file:
//! each refusal names the file, the line of the value, the field and what was expected, and
//! quotes the input cut short. Values of a wrong type and non-finite numbers must be refused;
//! out-of-range values (negative, huge, an unknown name) must be refused clearly wherever
//! they are refused.

use std::path::Path;
use sylva_core::scene::Scene;
use sylva_core::species::SpeciesSource;
use sylva_core::wind::WindScene;

/// What kind of value a field holds, from its text in the shipped file.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Float,
    Integer,
    Text,
    Array,
    Bool,
}

fn kind(value: &str) -> Kind {
    match value.as_bytes()[0] {
        b'"' => Kind::Text,
        b'[' => Kind::Array,
        b't' | b'f' => Kind::Bool,
        _ if value.contains(['.', 'e', 'E']) => Kind::Float,
        _ => Kind::Integer,
    }
}

/// Bad values for a kind: (value, whether every field of the kind must refuse it).
fn bad_values(kind: Kind) -> Vec<(String, bool)> {
    let long = format!("\"{}\"", "x".repeat(500));
    let mut v: Vec<(String, bool)> = match kind {
        Kind::Float => vec![
            ("nan".into(), true),
            ("inf".into(), true),
            ("-1e30".into(), false),
            ("1e30".into(), false),
            ("-1.0".into(), false),
        ],
        Kind::Integer => vec![("-7".into(), false), ("99999999999".into(), false), ("2.5".into(), false)],
        Kind::Text => vec![("42".into(), true), ("\"frobnicate\"".into(), false)],
        Kind::Array => vec![
            ("[1.0]".into(), false),
            ("[1.0, 2.0, 3.0, 4.0, 5.0]".into(), false),
            ("[nan, 0.0, 0.0]".into(), true),
            ("[\"a\", 1, 2]".into(), true),
        ],
        Kind::Bool => vec![("2".into(), true)],
    };
    if kind != Kind::Text {
        v.push((long, true));
    }
    v
}

/// Every `key = value` in `text`: (line index, byte range of the value, key). Values inside
/// inline tables (`{ a = 1, b = 2 }`) are found too.
fn fields(text: &str) -> Vec<(usize, std::ops::Range<usize>, String)> {
    let mut out = Vec::new();
    let mut offset = 0;
    for (n, line) in text.split_inclusive('\n').enumerate() {
        let code = line.split('#').next().unwrap();
        let mut from = 0;
        while let Some(eq) = code[from..].find(" = ") {
            let eq = from + eq;
            let key_start = code[..eq].rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).map_or(0, |k| k + 1);
            let key = &code[key_start..eq];
            let start = eq + 3;
            let rest = &code[start..];
            let len = match rest.as_bytes().first() {
                // An array over several lines: its elements are found on their own lines.
                Some(b'[') if !rest.contains(']') => {
                    from = start;
                    continue;
                }
                Some(b'[') => rest.find(']').map_or(rest.len(), |k| k + 1),
                Some(b'"') => rest[1..].find('"').map_or(rest.len(), |k| k + 2),
                Some(b'{') | None => {
                    from = start;
                    continue;
                }
                _ => rest.find([',', '}', '\n', ' ']).unwrap_or(rest.len()),
            };
            if !key.is_empty() {
                out.push((n, offset + start..offset + start + len, key.to_string()));
            }
            from = start + len;
        }
        offset += line.len();
    }
    out
}

/// Words that say what was expected.
const EXPECTATION: [&str; 14] = [
    "expected", "must", "at most", "at least", "outside", "one of", "between", "finite", "positive", "invalid",
    "unknown", "within", "range", "not ",
];

/// Mutates every field of `text` with every bad value of its kind and checks each refusal.
/// Returns (cases tried, refused).
fn check_file(what: &str, text: &str, parse: &dyn Fn(&str) -> Result<(), String>) -> (usize, usize) {
    parse(text).unwrap_or_else(|e| panic!("{what}: the shipped file is refused: {e}"));
    let (mut tried, mut refused) = (0, 0);
    let mut problems = Vec::new();
    for (line, range, key) in fields(text) {
        let original = &text[range.clone()];
        for (bad, must) in bad_values(kind(original)) {
            let mutated = format!("{}{bad}{}", &text[..range.start], &text[range.end..]);
            tried += 1;
            let case = format!("{what}: line {} `{key} = {}`", line + 1, sylva_core::io::cut(&bad));
            match parse(&mutated) {
                Ok(()) if must => problems.push(format!("{case}: accepted")),
                Ok(()) => {}
                Err(e) => {
                    refused += 1;
                    let plain = e.to_lowercase();
                    let mut missing = Vec::new();
                    if !e.contains("case.toml") {
                        missing.push("the file");
                    }
                    if !e.contains(&format!(":{}", line + 1)) {
                        missing.push("the line");
                    }
                    if !e.contains(&key) {
                        missing.push("the field");
                    }
                    if !EXPECTATION.iter().any(|w| plain.contains(w)) {
                        missing.push("what was expected");
                    }
                    if e.chars().count() > 400 {
                        missing.push("a short quote (over 400 characters)");
                    }
                    if !missing.is_empty() {
                        let shown: String = e.chars().take(200).collect();
                        problems.push(format!("{case}: the message lacks {}: {shown}", missing.join(", ")));
                    }
                }
            }
        }
    }
    assert!(problems.is_empty(), "{} problems:\n{}", problems.len(), problems.join("\n"));
    (tried, refused)
}

fn preset(path: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)).unwrap()
}

#[test]
fn species_fields_refuse_bad_values_clearly() {
    let text = preset("presets/species/quaking_aspen.toml");
    let (tried, refused) = check_file("species", &text, &|t| {
        SpeciesSource::parse_species(t, "case.toml").map(|_| ()).map_err(|e| e.to_string())
    });
    println!("species: {tried} bad values, {refused} refused");
}

#[test]
fn scene_fields_refuse_bad_values_clearly() {
    let text = preset("presets/scenes/default.toml");
    let (tried, refused) = check_file("scene", &text, &|t| {
        Scene::from_toml(t, "case.toml", Path::new(".")).map(|_| ()).map_err(|e| e.to_string())
    });
    println!("scene: {tried} bad values, {refused} refused");
}

#[test]
fn wind_fields_refuse_bad_values_clearly() {
    for name in ["gusty", "blast", "eddies"] {
        let text = preset(&format!("presets/wind/{name}.toml"));
        // Beside the presets, so that the eddies' grid file is found.
        let (tried, refused) = check_file(name, &text, &|t| {
            WindScene::from_toml(t, "presets/wind/case.toml").map(|_| ()).map_err(|e| e.to_string())
        });
        println!("wind {name}: {tried} bad values, {refused} refused");
    }
}

/// A fixed-size array with extra elements was read as its first elements without a word
/// (TOML's reader fills `[f32; 3]` from the front); now it is refused at its line.
#[test]
fn an_array_with_extra_elements_is_refused_not_cut() {
    let text = preset("presets/scenes/default.toml").replace("eye = [0.0, 5.0, 40.0]", "eye = [0.0, 5.0, 40.0, 7.0]");
    let e = Scene::from_toml(&text, "case.toml", Path::new(".")).unwrap_err().to_string();
    assert!(e.starts_with("case.toml:16:") && e.contains("camera.eye") && e.contains("4 elements"), "{e}");
    assert!(e.contains("expected 3 elements"), "{e}");
    let text = preset("presets/wind/gusty.toml").replace("origin = [-60.0, 0.0]", "origin = [-60.0, 0.0, 1.0]");
    let line = 1 + text.lines().position(|l| l.starts_with("origin = [-60.0, 0.0, 1.0]")).unwrap();
    let e = WindScene::from_toml(&text, "case.toml").unwrap_err().to_string();
    assert!(e.starts_with(&format!("case.toml:{line}:")) && e.contains("origin") && e.contains("expected 2"), "{e}");
}
