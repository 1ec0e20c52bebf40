//! The `sylva` binary end to end.

use std::process::Command;

fn sylva(dir: &std::path::Path, args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_sylva")).current_dir(dir).args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn presets_lists_every_shipped_preset() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = sylva(dir.path(), &["presets"]);
    assert!(ok, "{err}");
    for p in sylva_core::species::PRESETS {
        assert!(out.contains(p.name), "{} missing:\n{out}", p.name);
    }
    assert!(out.contains("Quaking Aspen") && out.contains("Monopodial tree"));
    assert!(!out.contains("invalid"));
}

#[test]
fn no_arguments_runs_the_default_job() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = sylva(dir.path(), &[]);
    assert!(ok, "{err}");
    assert!(out.contains("Quaking Aspen") && out.contains("segments"), "{out}");
    let obj = std::fs::read_to_string(dir.path().join("out/quaking_aspen.obj")).unwrap();
    assert!(obj.lines().filter(|l| l.starts_with("f ")).count() > 10_000);
}

#[test]
fn generate_prints_a_summary_and_writes_obj() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) =
        sylva(dir.path(), &["generate", "--species", "ternary", "--seed", "3", "--out", "t.obj", "--threads", "1"]);
    assert!(ok, "{err}");
    for word in ["level", "segments", "stems", "leaves", "height", "crown width", "memory", "wrote t.obj"] {
        assert!(out.contains(word), "{word} missing:\n{out}");
    }
    assert!(dir.path().join("t.obj").exists());
    // A grammar file from disk, with --iterations.
    std::fs::write(dir.path().join("g.lsys"), "axiom: A\nA -> F[+A][-A]\n").unwrap();
    let (ok, out, err) = sylva(dir.path(), &["generate", "-s", "g.lsys", "--iterations", "4", "-o", "-"]);
    assert!(ok, "{err}");
    assert!(out.contains("   15 "), "2^4 − 1 = 15 segments expected:\n{out}");
}

#[test]
fn bad_input_gives_a_located_error_and_no_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.lsys"), "axiom: A\nA -> F(1,\n").unwrap();
    let (ok, _, err) = sylva(dir.path(), &["generate", "-s", "bad.lsys", "-o", "bad.obj"]);
    assert!(!ok);
    assert!(err.contains("bad.lsys:2:10: expected"), "{err}");
    assert!(!dir.path().join("bad.obj").exists());

    std::fs::write(dir.path().join("bad.toml"), "name = \"x\"\nshape = 1\nflavour = 3\n").unwrap();
    let (ok, _, err) = sylva(dir.path(), &["generate", "-s", "bad.toml"]);
    assert!(!ok);
    assert!(err.contains("bad.toml:3") && err.contains("flavour"), "{err}");

    let (ok, _, err) = sylva(dir.path(), &["generate", "-s", "monopodial", "--max-segments", "100", "-o", "m.obj"]);
    assert!(!ok);
    assert!(err.contains("max_segments") && err.contains("100"), "{err}");
    assert!(!dir.path().join("m.obj").exists());

    let (ok, _, err) = sylva(dir.path(), &["generate", "-s", "nope"]);
    assert!(!ok);
    assert!(err.contains("nope") && err.contains("weeping_willow"), "{err}");
}
