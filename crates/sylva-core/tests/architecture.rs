//! The core's folders depend on one another without circles, and no engine source file
//! grows past 700 lines.
//!
//! A node is a top-level module of `src/` (`model`, `wind`, `pose`, `mesh`, …), except that
//! each method folder under `src/methods/` is a node of its own (`methods/hsm`, …): a
//! method may use the shared modules, never another method, and no shared module may reach
//! back into the methods except the stages that consume a method's own output (meshing,
//! export). An edge is any `crate::x` path in a file's code (comments are skipped).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn src() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The node a file of `src/` belongs to.
fn node_of(rel: &Path) -> String {
    let parts: Vec<String> = rel.iter().map(|c| c.to_string_lossy().trim_end_matches(".rs").to_string()).collect();
    match parts.as_slice() {
        [m, method, ..] if m == "methods" && parts.len() > 2 => format!("methods/{method}"),
        [first, ..] => first.clone(),
        [] => unreachable!(),
    }
}

/// The node a `crate::a::b` path names.
fn node_of_path(a: &str, b: Option<&str>) -> String {
    match (a, b) {
        ("methods", Some(m)) if m.chars().next().is_some_and(|c| c.is_lowercase()) => format!("methods/{m}"),
        _ => a.to_string(),
    }
}

fn edges() -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in files {
        let rel = f.strip_prefix(src()).unwrap().to_path_buf();
        let from = node_of(&rel);
        let text = std::fs::read_to_string(&f).unwrap();
        for line in text.lines() {
            let code = line.split("//").next().unwrap_or("");
            let mut rest = code;
            while let Some(i) = rest.find("crate::") {
                rest = &rest[i + "crate::".len()..];
                let words: Vec<&str> = rest
                    .split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                    .next()
                    .unwrap_or("")
                    .split("::")
                    .collect();
                let to = node_of_path(words[0], words.get(1).copied());
                if !to.is_empty() && to != from {
                    graph.entry(from.clone()).or_default().insert(to);
                }
            }
        }
        graph.entry(from).or_default();
    }
    graph
}

/// A cycle through `start`, if any (depth-first search).
fn cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        stack.push(n.to_string());
        for m in graph.get(n).into_iter().flatten() {
            match state.get(m.as_str()).copied().unwrap_or(0) {
                1 => {
                    let at = stack.iter().position(|s| s == m).unwrap();
                    let mut c = stack[at..].to_vec();
                    c.push(m.clone());
                    return Some(c);
                }
                0 => {
                    if let Some(c) = visit(m, graph, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if state.get(n.as_str()).copied().unwrap_or(0) == 0 {
            let mut stack = Vec::new();
            if let Some(c) = visit(n, graph, &mut state, &mut stack) {
                return Some(c);
            }
        }
    }
    None
}

#[test]
fn the_core_folders_form_no_circle() {
    let graph = edges();
    // The search finds circles: a graph with one planted is caught.
    let mut planted = graph.clone();
    planted.entry("model".into()).or_default().insert("export".into());
    assert!(cycle(&planted).is_some(), "the cycle search misses a planted circle model → export → … → model");
    if let Some(c) = cycle(&graph) {
        panic!("the core's folders import in a circle: {}", c.join(" → "));
    }
    // A method folder never uses another method.
    for (from, to) in &graph {
        if from.starts_with("methods/") {
            for t in to {
                assert!(!t.starts_with("methods/"), "{from} uses {t}: methods share code through the shared modules");
            }
        }
    }
    assert!(graph.len() >= 10, "nodes found: {:?}", graph.keys());
}

#[test]
fn no_core_source_file_passes_700_lines() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    for f in files {
        let n = std::fs::read_to_string(&f).unwrap().lines().count();
        assert!(n <= 700, "{}: {n} lines (at most 700: split it by concept)", f.display());
    }
}
