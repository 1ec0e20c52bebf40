//! Mutation fuzzing on stable Rust, one target per input parser and the tree builder: each
//! target mutates a corpus (the shipped presets, `tests/fuzz/<target>/` and the regression
//! inputs) for a time box and fails on any panic, or on an input that takes longer than
//! [`SLOW`] (a hang). A failing input is written to `target/fuzz-crashes/` and quoted.
//!
//! Time box per target: `SYLVA_FUZZ_SECONDS` (default 10 s; CI runs the default). A longer
//! run: `SYLVA_FUZZ_SECONDS=600 cargo test --release -p sylva-core --test fuzz -- --nocapture`.
//! `SYLVA_FUZZ_SEED` picks the mutation sequence (default 1).

use glam::{DQuat, DVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use sylva_core::model::{LeafDraft, SegmentDraft, StemDraft, TreeBuilder};
use sylva_core::scene::Scene;
use sylva_core::species::{PRESETS, PresetKind, SpeciesSource};
use sylva_core::wind::WindScene;
use sylva_core::{Limits, WoodProperties};

/// Longest an input may take (a debug build, one shared core) before it counts as a hang.
const SLOW: Duration = Duration::from_secs(10);

/// Tight limits: every input stays small, so many run in the time box.
fn limits() -> Limits {
    Limits {
        max_segments: 20_000,
        max_leaves: 20_000,
        max_modules: 200_000,
        max_parameters: 400_000,
        max_iterations: 12,
        ..Limits::default()
    }
}

fn budget() -> Duration {
    let s = std::env::var("SYLVA_FUZZ_SECONDS").ok().and_then(|v| v.parse::<f64>().ok()).unwrap_or(10.0);
    Duration::from_secs_f64(s.clamp(0.1, 86_400.0))
}

fn dir(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// Files of a folder (sorted, so the corpus is the same on every machine).
fn files(folder: &Path, ext: &str) -> Vec<Vec<u8>> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(folder)
        .into_iter()
        .flatten()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    paths.sort();
    paths.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

/// Tokens that broke parsers before, or that sit on a boundary.
const TOKENS: &[&str] = &[
    "0/0",
    "1/0",
    "-1/0",
    "1e308",
    "1.797e308",
    "-0",
    "nan",
    "inf",
    "4294967295",
    "-1",
    "0",
    "255",
    "1e-45",
    "[",
    "]",
    "(",
    ")",
    ",",
    "=",
    "\n",
    "\"",
    "{",
    "}",
    "[[tree]]",
    "[[field]]",
    "F",
    "A",
    "->",
    ":",
    "clamp(1,x/x,x/x)",
    "x/x",
    "#",
    "\\u0000",
    "ÿ",
];

/// One to four mutations: flip, insert, delete, duplicate, splice and token insertions.
fn mutate(rng: &mut ChaCha8Rng, corpus: &[Vec<u8>]) -> Vec<u8> {
    let mut v = corpus[rng.random_range(0..corpus.len())].clone();
    for _ in 0..rng.random_range(1..=4) {
        let n = v.len();
        let at = if n == 0 { 0 } else { rng.random_range(0..=n) };
        match rng.random_range(0..7) {
            0 if n > 0 => {
                let i = rng.random_range(0..n);
                v[i] ^= 1 << rng.random_range(0..8);
            }
            1 => v.insert(at, rng.random()),
            2 if n > 0 => {
                let len = rng.random_range(1..=n.min(16));
                let i = rng.random_range(0..=n - len);
                v.drain(i..i + len);
            }
            3 if n > 0 => {
                let len = rng.random_range(1..=n.min(64));
                let i = rng.random_range(0..=n - len);
                let piece = v[i..i + len].to_vec();
                let j = rng.random_range(0..=n);
                v.splice(j..j, piece);
            }
            4 => {
                let other = &corpus[rng.random_range(0..corpus.len())];
                if !other.is_empty() {
                    let i = rng.random_range(0..other.len());
                    let len = rng.random_range(1..=(other.len() - i).min(200));
                    v.splice(at..at, other[i..i + len].iter().copied());
                }
            }
            _ => {
                // Replace a number (or insert) with a boundary token.
                let t = TOKENS[rng.random_range(0..TOKENS.len())].as_bytes();
                let start = (0..n).find(|&i| i >= at && v[i].is_ascii_digit());
                match start {
                    Some(s) => {
                        let e = (s..n).find(|&i| !(v[i].is_ascii_digit() || v[i] == b'.')).unwrap_or(n);
                        v.splice(s..e, t.iter().copied());
                    }
                    None => {
                        v.splice(at..at, t.iter().copied());
                    }
                }
            }
        }
    }
    v.truncate(64 << 10);
    v
}

/// Runs `target` on mutated inputs for the time box; fails on a panic or a hang.
/// `target` returns how far an input got: 0 refused as text, 1 parsed, 2 built (a tree, a
/// checked scene or wind).
fn fuzz(name: &str, corpus: Vec<Vec<u8>>, target: impl Fn(&[u8]) -> usize) {
    assert!(!corpus.is_empty(), "{name}: empty corpus");
    let seed = std::env::var("SYLVA_FUZZ_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(1u64);
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ name.len() as u64);
    let (start, budget) = (Instant::now(), budget());
    let mut inputs = 0usize;
    let mut slowest = Duration::ZERO;
    let mut reached = [0usize; 3];
    // The corpus as it is first, then mutations.
    let mut pending: Vec<Vec<u8>> = corpus.clone();
    while start.elapsed() < budget || !pending.is_empty() {
        let input = pending.pop().unwrap_or_else(|| mutate(&mut rng, &corpus));
        let t0 = Instant::now();
        let outcome = catch_unwind(AssertUnwindSafe(|| target(&input)));
        let took = t0.elapsed();
        if let Ok(stage) = outcome {
            reached[stage.min(2)] += 1;
        }
        slowest = slowest.max(took);
        inputs += 1;
        if outcome.is_err() || took > SLOW {
            let out = dir("../../target/fuzz-crashes");
            std::fs::create_dir_all(&out).unwrap();
            let file = out.join(format!("{name}-{inputs}.txt"));
            std::fs::write(&file, &input).unwrap();
            let what = if outcome.is_err() { "panicked".to_string() } else { format!("took {took:?} (a hang)") };
            panic!(
                "fuzz {name}: input {inputs} {what}; written to {}:\n{}",
                file.display(),
                String::from_utf8_lossy(&input[..input.len().min(2000)])
            );
        }
    }
    println!(
        "fuzz {name}: {inputs} inputs in {:.1} s ({} refused, {} parsed only, {} built), 0 panics, 0 hangs, slowest {slowest:?}",
        start.elapsed().as_secs_f64(),
        reached[0],
        reached[1],
        reached[2]
    );
    assert!(reached[2] > 0, "{name}: no input got through; the corpus or the mutations are broken");
}

fn presets(kind: PresetKind) -> Vec<Vec<u8>> {
    PRESETS.iter().filter(|p| p.kind == kind).map(|p| p.text.as_bytes().to_vec()).collect()
}

#[test]
fn fuzz_grammar_parser_and_derivation() {
    let mut corpus = presets(PresetKind::Grammar);
    corpus.extend(files(&dir("tests/regressions"), "lsys"));
    corpus.extend(files(&dir("tests/fuzz/grammar"), "lsys"));
    fuzz("grammar", corpus, |bytes| {
        let Ok(text) = std::str::from_utf8(bytes) else { return 0 };
        let Ok(g) = sylva_core::Grammar::parse_with_limits(text, "fuzz.lsys", &limits()) else { return 0 };
        let opts = sylva_core::LSystemOptions { seed: 1, iterations: None, limits: limits() };
        let Ok(tree) = g.generate(&opts) else { return 1 };
        assert!(tree.segments.len() <= limits().max_segments);
        tree.validate().expect("a generated tree is valid");
        2
    });
}

#[test]
fn fuzz_species_parser_and_generator() {
    let mut corpus = presets(PresetKind::Species);
    corpus.extend(files(&dir("tests/fuzz/species"), "toml"));
    fuzz("species", corpus, |bytes| {
        let Ok(text) = std::str::from_utf8(bytes) else { return 0 };
        let Ok(params) = SpeciesSource::parse_species(text, "fuzz.toml") else { return 0 };
        let Ok(tree) = params.generate(1, &limits()) else { return 1 };
        tree.validate().expect("a generated tree is valid");
        2
    });
}

#[test]
fn fuzz_scene_parser() {
    let mut corpus = vec![sylva_core::scene::DEFAULT_SCENE.as_bytes().to_vec()];
    corpus.extend(files(&dir("tests/fuzz/scene"), "toml"));
    fuzz("scene", corpus, |bytes| {
        let Ok(text) = std::str::from_utf8(bytes) else { return 0 };
        let Ok(scene) = Scene::from_toml(text, "fuzz.toml", Path::new(".")) else { return 0 };
        if scene.check().is_err() {
            return 1;
        }
        assert!(scene.frames() <= sylva_core::scene::MAX_FRAMES);
        2
    });
}

#[test]
fn fuzz_wind_parser_and_sampler() {
    let mut corpus = files(&dir("../../presets/wind"), "toml");
    corpus.extend(files(&dir("tests/fuzz/wind"), "toml"));
    fuzz("wind", corpus, |bytes| {
        let Ok(text) = std::str::from_utf8(bytes) else { return 0 };
        let Ok(wind) = WindScene::from_toml(text, "fuzz.toml") else { return 0 };
        for k in 0..8 {
            let v = wind.sample(Vec3::new(k as f32 * 7.0 - 20.0, 5.0, 3.0), k as f32 * 1.7);
            assert!(v.is_finite(), "a checked wind samples finite: {v}");
        }
        2
    });
}

/// The builder and validator on drafts made from the input's bytes: any index, any value
/// (NaN, infinite, negative, huge). `build` must refuse or build a valid tree, never panic.
#[test]
fn fuzz_tree_builder_and_validator() {
    let mut corpus: Vec<Vec<u8>> =
        (0..8u8).map(|k| (0..64u8).map(|i| i.wrapping_mul(7).wrapping_add(k)).collect()).collect();
    corpus.extend(files(&dir("tests/fuzz/builder"), "bin"));
    fuzz("builder", corpus, |bytes| {
        let mut it = bytes.iter().copied().cycle();
        let mut next = move || it.next().unwrap_or(0);
        let value = |b: u8| match b % 8 {
            0 => f64::NAN,
            1 => f64::INFINITY,
            2 => -1.0,
            3 => 0.0,
            4 => 1e300,
            _ => b as f64 / 25.0,
        };
        let n_stems = 1 + (next() % 6) as usize;
        let n_segments = (next() % 24) as usize;
        let mut b = TreeBuilder::default();
        for k in 0..n_stems {
            let parent =
                (k > 0 && next() % 4 != 0).then(|| ((next() % 8) as usize, (next() % 8) as usize, value(next())));
            b.stems.push(StemDraft { parent, level: next() % 4, segments: 0, last: u32::MAX });
        }
        let mut y = 0.0;
        for _ in 0..n_segments {
            let stem = (next() % (n_stems as u8 + 1)) as usize;
            let start = if next() % 5 == 0 { DVec3::new(value(next()), y, 0.0) } else { DVec3::new(0.0, y, 0.0) };
            y += value(next());
            let end = DVec3::new(0.0, y, value(next()) * 0.01);
            let frame = if next() % 7 == 0 { DQuat::from_xyzw(value(next()), 0.0, 0.0, 0.0) } else { DQuat::IDENTITY };
            b.segments.push(SegmentDraft {
                stem: stem as u32,
                start,
                end,
                frame,
                radius_base: value(next()),
                radius_tip: value(next()),
            });
            if let Some(s) = b.stems.get_mut(stem) {
                s.segments += 1;
                s.last = b.segments.len() as u32 - 1;
            }
        }
        for _ in 0..next() % 4 {
            b.leaves.push(LeafDraft {
                stem: (next() % 8) as usize,
                segment: (next() % 8) as usize,
                position: DVec3::new(0.0, value(next()), 0.0),
                orientation: DQuat::IDENTITY,
                width: value(next()),
                length: value(next()),
            });
        }
        match b.build("fuzz", 1, WoodProperties::default()) {
            Ok(tree) => {
                tree.validate().expect("a built tree is valid");
                2
            }
            Err(_) => 1,
        }
    });
}
