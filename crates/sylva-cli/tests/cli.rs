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

/// The main job (`sylva` with no arguments is `sylva render` on the default scene), made
/// small by overrides: every default tree and method, a GIF and PNG frames.
#[test]
fn render_default_scene_writes_gif_and_frames() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = sylva(
        dir.path(),
        &["render", "--width", "160", "--height", "90", "--seconds", "0.2", "--fps", "10", "--no-mp4"],
    );
    assert!(ok, "{err}\n{out}");
    for m in ["zioma", "akagi", "skjermo", "hsm"] {
        assert!(out.contains(&format!("· {m}")), "{m} missing:\n{out}");
    }
    // The per-frame breakdown, and the GPU's own time for simulation and meshing where the
    // adapter has timestamp queries.
    assert!(out.contains("ms per frame (simulate + mesh recording"), "{out}");
    if sylva_gpu::GpuContext::shared().is_ok_and(|c| c.timestamps) {
        let line = out.lines().find(|l| l.starts_with("GPU time of simulation + meshing")).expect("GPU time line");
        let ms: f64 = line.split(": ").nth(1).and_then(|v| v.split(' ').next()).unwrap().parse().unwrap();
        assert!(ms > 0.0, "{line}");
    }
    let gif = dir.path().join("out/render/sylva.gif");
    let decoder =
        image::codecs::gif::GifDecoder::new(std::io::BufReader::new(std::fs::File::open(&gif).unwrap())).unwrap();
    use image::AnimationDecoder;
    let frames = decoder.into_frames().collect_frames().unwrap();
    assert_eq!(frames.len(), 2);
    assert_eq!(frames[0].buffer().dimensions(), (160, 90));
    for f in 0..2 {
        let png = image::open(dir.path().join(format!("out/render/frames/sylva_{f:04}.png"))).unwrap();
        assert_eq!((png.width(), png.height()), (160, 90));
    }
    let leftovers: Vec<_> = std::fs::read_dir(dir.path().join("out/render"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

const TINY_SCENE: &str = r#"
[output]
dir = "out"
name = "tiny"
width = 64
height = 48
fps = 100
seconds = 20
preroll = 0
sim_rate = 100
mp4 = false
labels = false

[[tree]]
species = "palm"
method = "zioma"
"#;

/// Copies of a stateful-method tree get their own simulations (phase groups): with two
/// groups the copy's pixels change and the tree's stay the same as with one shared
/// simulation.
#[test]
fn render_copies_of_a_stateful_tree_sway_out_of_step() {
    let dir = tempfile::tempdir().unwrap();
    let scene = |groups: u32| {
        format!(
            r#"
[output]
dir = "out{groups}"
name = "pair"
width = 192
height = 96
fps = 10
seconds = 0.1
preroll = 1
sim_rate = 60
mp4 = false
gif = false
labels = false

[camera]
eye = [0.0, 3.0, 14.0]
target = [0.0, 3.0, 0.0]

[sun]
direction = [0.0, 1.0, 0.2]

[[tree]]
species = "palm"
method = "akagi"
backend = "cpu"
position = [-6.0, 0.0, 0.0]
copies = [{{ position = [6.0, 0.0, 0.0] }}]
phase_groups = {groups}
"#
        )
    };
    let mut images = Vec::new();
    for groups in [1, 2] {
        let file = format!("pair{groups}.toml");
        std::fs::write(dir.path().join(&file), scene(groups)).unwrap();
        let (ok, out, err) = sylva(dir.path(), &["render", &file]);
        assert!(ok, "{err}\n{out}");
        assert_eq!(out.contains("in 2 simulations"), groups == 2, "{out}");
        images.push(image::open(dir.path().join(format!("out{groups}/frames/pair_0000.png"))).unwrap().to_rgb8());
    }
    // Mean absolute difference over a band of columns.
    let diff = |x0: u32, x1: u32| {
        let mut sum = 0u64;
        for y in 0..96 {
            for x in x0..x1 {
                let (a, b) = (images[0].get_pixel(x, y), images[1].get_pixel(x, y));
                sum += (0..3).map(|c| a[c].abs_diff(b[c]) as u64).sum::<u64>();
            }
        }
        sum as f64 / ((x1 - x0) * 96 * 3) as f64
    };
    let (tree, copy) = (diff(0, 80), diff(112, 192));
    println!("mean |Δ|: tree {tree:.4}, copy {copy:.4}");
    assert!(copy > 0.05, "the copy did not move differently: {copy}");
    assert!(copy > 10.0 * tree, "tree {tree}, copy {copy}");
}

#[test]
fn render_rejects_bad_scenes_naming_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("unknown.toml"), TINY_SCENE.replace("fps = 100", "fps = 100\nfsp = 3")).unwrap();
    let (ok, _, err) = sylva(dir.path(), &["render", "unknown.toml"]);
    assert!(!ok && err.contains("unknown.toml:8") && err.contains("fsp"), "{err}");
    std::fs::write(dir.path().join("missing.toml"), TINY_SCENE.replace("\"palm\"", "\"baobab\"")).unwrap();
    let (ok, _, err) = sylva(dir.path(), &["render", "missing.toml"]);
    assert!(!ok && err.contains("tree[0].species") && err.contains("baobab"), "{err}");
    let (ok, _, err) = sylva(dir.path(), &["render", "no/such/scene.toml"]);
    assert!(!ok && err.contains("no/such/scene.toml"), "{err}");
    assert!(!dir.path().join("out").exists());
}

/// Signal numbers and the exit status a command stopped by each gives (`128 + n`).
#[cfg(unix)]
const SIGNALS: [(&str, i32); 3] = [("INT", 130), ("TERM", 143), ("HUP", 129)];

/// Every entry under `dir`, recursively (names relative to it).
fn entries(dir: &std::path::Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten() {
            let p = e.unwrap().path();
            out.push(p.strip_prefix(dir).unwrap().to_string_lossy().into_owned());
            if p.is_dir() {
                stack.push(p);
            }
        }
    }
    out
}

/// Sends `signal` to the child once `ready` holds, and returns its exit code and stderr.
#[cfg(unix)]
fn interrupt(mut child: std::process::Child, signal: &str, ready: impl Fn() -> bool) -> (Option<i32>, String) {
    let start = std::time::Instant::now();
    while !ready() {
        assert!(start.elapsed().as_secs() < 300, "SIG{signal}: not ready after 300 s");
        assert!(child.try_wait().unwrap().is_none(), "SIG{signal}: the command ended before it was interrupted");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    assert!(child.try_wait().unwrap().is_none(), "SIG{signal}: the command ended before it was interrupted");
    let killed = Command::new("kill").args([&format!("-{signal}"), &child.id().to_string()]).status().unwrap();
    assert!(killed.success());
    let out = child.wait_with_output().unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

fn spawn(dir: &std::path::Path, args: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_sylva"))
        .current_dir(dir)
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

/// An interrupted render (Ctrl-C, and SIGTERM or SIGHUP from a session manager) stops
/// between frames: no GIF, no frames, no temporary files, exit status 128 + signal.
#[cfg(unix)]
#[test]
fn interrupted_render_leaves_no_partial_output_on_int_term_and_hup() {
    for (signal, code) in SIGNALS {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("tiny.toml"), TINY_SCENE).unwrap();
        let out = dir.path().join("out");
        let child = spawn(dir.path(), &["render", "tiny.toml"]);
        // Three frames are written (to the temporary frames directory) before the signal.
        let third = || entries(&out).iter().any(|e| e.contains(".frames.tmp-") && e.ends_with("tiny_0002.png"));
        let (status, err) = interrupt(child, signal, third);
        assert_eq!(status, Some(code), "SIG{signal}: {err}");
        assert!(err.contains(&format!("SIG{signal}")) && err.contains("stopped"), "SIG{signal}: {err}");
        let left = entries(&out);
        assert!(left.is_empty(), "SIG{signal}: an interrupted render left {left:?}");
    }
}

/// `simulate --csv`, `export` and `bench` stop on each signal with 128 + signal, leaving
/// neither a temporary file nor an output under its final name.
#[cfg(unix)]
#[test]
fn signals_stop_simulate_export_bench_and_wind_with_no_file_left() {
    let long: [(&str, &[&str]); 4] = [
        (
            "simulate",
            &["simulate", "--species", "palm", "--method", "akagi", "--seconds", "100000", "--csv", "out/t.csv"],
        ),
        (
            "export",
            &["export", "--species", "black_tupelo", "--method", "hsm", "--seconds", "20", "--out", "out/t.glb"],
        ),
        ("bench", &["bench", "song-t3", "--backend", "cpu", "--out-dir", "out"]),
        // Four 4,096-component turbulence fields: ≈ 8 s of sampling on two cores.
        ("wind", &["wind", "--scene", "heavy.toml", "--out-dir", "out"]),
    ];
    let turbulence = |seed| {
        format!(
            "[[field]]\nkind = \"turbulence\"\nintensity = 1.2\nbeta = 1.67\nf_min = 0.01\nf_max = 5.0\n\
             components = 4096\nmean_speed = 6.0\nvertical = 0.3\nseed = {seed}\n\n"
        )
    };
    let heavy: String = (0..4).map(turbulence).collect();
    for (name, args) in long {
        for (signal, code) in SIGNALS {
            let dir = tempfile::tempdir().unwrap();
            std::fs::write(dir.path().join("heavy.toml"), &heavy).unwrap();
            let out = dir.path().join("out");
            std::fs::create_dir(&out).unwrap();
            let child = spawn(dir.path(), args);
            let start = std::time::Instant::now();
            // simulate's CSV is open as a temporary file from its first frame; the others
            // are interrupted while they work.
            let ready = || match name {
                "simulate" => entries(&out).iter().any(|e| e.contains(".tmp-")),
                _ => start.elapsed().as_millis() > 1500,
            };
            let (status, err) = interrupt(child, signal, ready);
            assert_eq!(status, Some(code), "{name}, SIG{signal}: {err}");
            assert!(err.contains("stopped"), "{name}, SIG{signal}: {err}");
            let left = entries(&out);
            assert!(left.is_empty(), "{name}, SIG{signal}: left {left:?}");
        }
    }
}

/// Runs `sylva` in a private mount namespace (`unshare -rm`) with a tmpfs mounted at `out`
/// with `options`; returns whether it succeeded, its stderr, and the files left on the
/// tmpfs (listed inside the namespace, where the tmpfs lives). `None` where user namespaces
/// are not available (allowed outside CI only, and said so).
#[cfg(target_os = "linux")]
fn on_tmpfs(dir: &std::path::Path, options: &str, args: &[&str]) -> Option<(bool, String, Vec<String>)> {
    let probe = Command::new("unshare").args(["-rm", "true"]).output();
    if !probe.is_ok_and(|o| o.status.success()) {
        assert!(std::env::var("CI").is_err(), "CI: `unshare -rm` (user namespaces) is needed for the tmpfs tests");
        eprintln!("SKIPPED: no user namespaces (`unshare -rm`) for the tmpfs tests");
        return None;
    }
    std::fs::create_dir_all(dir.join("out")).unwrap();
    let script = r#"opts=$1; shift; mount -t tmpfs -o "$opts" tmpfs out || exit 99; "$@" >/dev/null; rc=$?; find out -type f; exit $rc"#;
    let out = Command::new("unshare")
        .current_dir(dir)
        .args(["-rm", "sh", "-c", script, "sh", options, env!("CARGO_BIN_EXE_sylva")])
        .args(args)
        .output()
        .unwrap();
    assert_ne!(out.status.code(), Some(99), "mounting the tmpfs failed");
    let files = String::from_utf8_lossy(&out.stdout).lines().map(str::to_string).collect();
    Some((out.status.success(), String::from_utf8_lossy(&out.stderr).into_owned(), files))
}

/// A full disk and a read-only directory: a clear error naming the path, a non-zero exit,
/// and no file left, neither a temporary one nor an incomplete one under its final name.
#[cfg(target_os = "linux")]
#[test]
fn full_disk_and_read_only_directory_fail_clearly_and_leave_nothing() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), TINY_SCENE.replace("seconds = 20", "seconds = 1")).unwrap();
    let commands: [(&str, &[&str]); 4] = [
        ("render, GIF and PNG frames", &["render", "tiny.toml", "--out-dir", "out/r"]),
        ("render, GIF only", &["render", "tiny.toml", "--out-dir", "out/r", "--no-png"]),
        ("simulate --csv", &["simulate", "--species", "palm", "--seconds", "30", "--csv", "out/t.csv"]),
        ("export", &["export", "--species", "palm", "--method", "zioma", "--out", "out/t.glb"]),
    ];
    // 24 KiB holds the directories and a few frames, not the rest.
    for (options, expect) in [("size=24k", "No space left"), ("ro", "Read-only")] {
        for (name, args) in commands {
            let Some((ok, err, files)) = on_tmpfs(dir.path(), options, args) else { return };
            assert!(!ok, "{name} on a {options} tmpfs must fail");
            assert!(err.contains(expect) && err.contains("out/"), "{name}, {options}: the error names the path: {err}");
            assert!(!err.contains("panicked"), "{name}, {options}: {err}");
            assert!(files.is_empty(), "{name}, {options}: left {files:?}");
        }
    }
}

#[test]
fn generate_prints_a_summary_and_writes_obj() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) =
        sylva(dir.path(), &["generate", "--species", "ternary", "--seed", "3", "--out", "t.obj", "--threads", "1"]);
    assert!(ok, "{err}");
    for word in [
        "level",
        "segments",
        "stems",
        "leaves",
        "height",
        "crown width",
        "breast height",
        "first mode",
        "memory",
        "wrote t.obj",
    ] {
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

/// The CLI-level cases of the hardening report, each named after what broke: a panic (exit
/// 101), a limit that did not hold, or a message that misled.
#[test]
fn regressions_panics_limits_and_messages() {
    let dir = tempfile::tempdir().unwrap();
    let regressions = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../sylva-core/tests/regressions");
    let input = |name: &str| regressions.join(name).to_string_lossy().into_owned();
    let status = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_sylva")).current_dir(dir.path()).args(args).output().unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    // A tree with no segments panicked in `simulate` for every method; `render` and `export`
    // accepted it.
    let empty = input("tree_with_no_segments.lsys");
    for method in ["zioma", "akagi", "skjermo", "hsm"] {
        let (code, err) = status(&["simulate", "--species", &empty, "--method", method, "--seconds", "0.1"]);
        assert_eq!(code, Some(1), "{method}: {err}");
        assert!(err.contains("no segment"), "{method}: {err}");
    }
    let (code, err) = status(&["export", "--species", &empty, "--out", "e.glb"]);
    assert!(code == Some(1) && err.contains("no segment"), "{err}");
    // Bracket nesting of 255 panicked in `simulate`; NaN clamp bounds in `generate`.
    for (name, cmd) in [("bracket_nesting_255.lsys", "simulate"), ("clamp_with_nan_bounds.lsys", "generate")] {
        let (code, err) = status(&[cmd, "--species", &input(name)]);
        assert_eq!(code, Some(1), "{name}: {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
    // Sides outside 3–64 and runaway thread counts were accepted.
    for args in [["--sides", "0"], ["--sides", "4294967295"], ["--sides", "65"], ["--threads", "100000"]] {
        let (code, err) = status(&["generate", "-o", "-", args[0], args[1]]);
        assert_eq!(code, Some(2), "{args:?}: {err}");
        assert!(err.contains(args[0]) && err.contains("expected") || err.contains("3..=64"), "{args:?}: {err}");
    }
    // /dev/zero slipped past the 1 MiB input limit and read until allocation failed.
    #[cfg(unix)]
    {
        let (code, err) = status(&["generate", "--species", "/dev/zero"]);
        assert!(code == Some(1) && err.contains("/dev/zero") && err.contains("limit"), "{err}");
    }
    // Limit messages were printed twice and named flags that did not exist.
    let (code, err) = status(&["simulate", "--species", "quaking_aspen", "--max-segments", "10"]);
    assert_eq!(code, Some(1), "{err}");
    assert_eq!(err.matches("max_segments").count(), 1, "said once: {err}");
    assert!(err.contains("--max-segments"), "{err}");
    let (code, err) = status(&["generate", "--species", "big.lsys", "--max-modules", "1000"]);
    assert_eq!(code, Some(1), "a missing file: {err}");
    std::fs::write(dir.path().join("big.lsys"), "iterations: 30\naxiom: A\nA -> AA\n").unwrap();
    let (code, err) = status(&["generate", "--species", "big.lsys", "--max-modules", "1000"]);
    assert!(code == Some(1) && err.contains("--max-modules") && err.matches("max_modules").count() == 1, "{err}");
    // A flag's bad value was blamed on the scene file.
    let (code, err) = status(&["render", "--seconds", "1e9"]);
    assert!(code == Some(1) && err.starts_with("Error: --seconds"), "{err}");
    // Scene memory had no bound: 64 weeping willows peaked at 12 GB. The same scene of
    // palms (8,456 segments and leaves each) against a limit of 20,000 stops at the third,
    // before any tree is set up.
    let palms: String = (0..64)
        .map(|k| format!("[[tree]]\nspecies = \"palm\"\nmethod = \"zioma\"\nposition = [{k}.0, 0.0, 0.0]\n"))
        .collect();
    std::fs::write(dir.path().join("palms.toml"), palms).unwrap();
    let (code, err) = status(&["render", "palms.toml", "--seconds", "0.1", "--max-scene-elements", "20000"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("tree[2]") && err.contains("`max_scene_elements` = 20000"), "{err}");
    assert!(err.contains("--max-scene-elements"), "{err}");
}

fn png_size(path: &std::path::Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{} is not a PNG", path.display());
    (u32::from_be_bytes(bytes[16..20].try_into().unwrap()), u32::from_be_bytes(bytes[20..24].try_into().unwrap()))
}

#[test]
fn wind_writes_a_speed_plot_and_a_field_map() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = sylva(dir.path(), &["wind", "--scene", "gusty", "--to", "20", "--out-dir", "plots"]);
    assert!(ok, "{err}");
    assert!(out.contains("wind_speed.png") && out.contains("wind_field.png"), "{out}");
    assert_eq!(png_size(&dir.path().join("plots/wind_speed.png")), (1200, 600));
    assert_eq!(png_size(&dir.path().join("plots/wind_field.png")), (900, 900));
    // A scene from a file.
    std::fs::write(dir.path().join("w.toml"), "[[field]]\nkind = \"constant\"\ndirection = [0, 0, 1]\nspeed = 4\n")
        .unwrap();
    let (ok, _, err) = sylva(dir.path(), &["wind", "--scene", "w.toml", "--out-dir", "w"]);
    assert!(ok, "{err}");
    assert!(dir.path().join("w/wind_field.png").exists());
}

#[test]
fn wind_rejects_bad_input_clearly() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.toml"), "[[field]]\nkind = \"constant\"\nspeed = 4\n").unwrap();
    let (ok, _, err) = sylva(dir.path(), &["wind", "--scene", "bad.toml"]);
    assert!(!ok);
    assert!(err.contains("bad.toml") && err.contains("direction"), "{err}");
    let (ok, _, err) = sylva(dir.path(), &["wind", "--from", "5", "--to", "1"]);
    assert!(!ok && err.contains("--to"), "{err}");
    let (ok, _, err) = sylva(dir.path(), &["wind", "--point", "1,2"]);
    assert!(!ok && err.contains("x,y,z"), "{err}");
    let (ok, _, err) = sylva(dir.path(), &["wind", "--scene", "nowhere"]);
    assert!(!ok && err.contains("gusty"), "{err}");
    assert!(!dir.path().join("out").exists());
}

#[test]
fn wind_on_the_gpu_draws_the_same_field() {
    if sylva_gpu::GpuContext::shared().is_err() {
        assert!(std::env::var("CI").is_err(), "CI requires a GPU adapter");
        eprintln!("skipping: no GPU adapter");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (ok, _, err) =
        sylva(dir.path(), &["wind", "--scene", "blast", "--backend", "gpu", "--time", "2.5", "--out-dir", "g"]);
    assert!(ok, "{err}");
    let (ok, _, err) =
        sylva(dir.path(), &["wind", "--scene", "blast", "--backend", "cpu", "--time", "2.5", "--out-dir", "c"]);
    assert!(ok, "{err}");
    // Identical numbers within the kernels' tolerance draw identical pictures.
    assert_eq!(
        std::fs::read(dir.path().join("g/wind_field.png")).unwrap(),
        std::fs::read(dir.path().join("c/wind_field.png")).unwrap()
    );
}

#[test]
fn simulate_reports_motion_and_writes_a_trajectory() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = sylva(
        dir.path(),
        &[
            "simulate",
            "--species",
            "lombardy_poplar",
            "--seconds",
            "2",
            "--fps",
            "30",
            "--csv",
            "t.csv",
            "--track",
            "0,5",
        ],
    );
    assert!(ok, "{err}");
    assert!(
        out.contains("61 frames") && out.contains("mean tip disp") && out.contains("largest segment-end speed"),
        "{out}"
    );
    let csv = std::fs::read_to_string(dir.path().join("t.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "time_s,segment,level,x,y,z,dx,dy,dz");
    assert_eq!(lines.len(), 1 + 2 * 61);
    // The trunk's root segment turns about its base: its end moves downwind (+x in `gusty`).
    let last: Vec<f32> = lines[lines.len() - 2].split(',').map(|v| v.parse().unwrap()).collect();
    assert_eq!(last[1], 0.0);
    assert!(last[6] > 0.0, "{:?}", last);
    // Still air: nothing moves.
    std::fs::write(dir.path().join("calm.toml"), "").unwrap();
    let (ok, out, err) = sylva(dir.path(), &["simulate", "--wind", "calm.toml", "--seconds", "1", "--fps", "10"]);
    assert!(ok, "{err}");
    assert!(out.contains("largest segment-end speed 0.000 m/s"), "{out}");
}

#[test]
fn simulate_runs_akagi_too() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = sylva(
        dir.path(),
        &["simulate", "--method", "akagi", "--species", "monopodial", "--seconds", "1", "--fps", "30"],
    );
    assert!(ok, "{err}");
    assert!(out.contains("akagi on the CPU") && out.contains("31 frames"), "{out}");
    let (ok, out, err) = sylva(
        dir.path(),
        &["simulate", "--method", "skjermo", "--species", "monopodial", "--seconds", "1", "--fps", "30"],
    );
    assert!(ok, "{err}");
    assert!(out.contains("skjermo on the CPU"), "{out}");
    let (ok, out, err) = sylva(
        dir.path(),
        &["simulate", "--method", "hsm", "--species", "stochastic_bush", "--seconds", "1", "--fps", "30"],
    );
    assert!(ok, "{err}");
    assert!(out.contains("hsm on the CPU") && out.contains("clusters") && !out.contains("speed 0.000"), "{out}");
    let (ok, _, err) = sylva(dir.path(), &["simulate", "--method", "akagi", "--trunk-only"]);
    assert!(!ok && err.contains("--trunk-only"), "{err}");
}

#[test]
fn simulate_rejects_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    for (args, needle) in [
        (vec!["simulate", "--seconds=-1"], "--seconds"),
        (vec!["simulate", "--fps", "0"], "--fps"),
        (vec!["simulate", "--seconds", "1e9", "--fps", "1000"], "limit"),
        (vec!["simulate", "--track", "999999"], "--track"),
        (vec!["simulate", "--method", "magic"], "magic"),
        (vec!["simulate", "--wind", "nowhere.toml"], "nowhere.toml"),
    ] {
        let (ok, _, err) = sylva(dir.path(), &args);
        assert!(!ok, "{args:?} succeeded");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

#[test]
fn simulate_runs_hsm_on_the_gpu() {
    if sylva_gpu::GpuContext::shared().is_err() {
        assert!(std::env::var("CI").is_err(), "CI requires a GPU adapter");
        eprintln!("skipping: no GPU adapter");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let args = ["simulate", "--method", "hsm", "--species", "stochastic_bush", "--seconds", "0.5", "--fps", "30"];
    let (ok, out, err) = sylva(dir.path(), &[&args[..], &["--backend", "gpu"]].concat());
    assert!(ok, "{err}");
    assert!(out.contains("hsm on the GPU") && out.contains("16 frames") && !out.contains("speed 0.000"), "{out}");
}

#[test]
fn bench_quick_writes_complete_tables() {
    let gpu = sylva_gpu::GpuContext::shared().is_ok();
    if !gpu {
        assert!(std::env::var("CI").is_err(), "CI requires a GPU adapter");
        eprintln!("timing the CPU only: no GPU adapter");
    }
    let dir = tempfile::tempdir().unwrap();
    let backend = if gpu { "both" } else { "cpu" };
    let (ok, out, err) = sylva(dir.path(), &["bench", "all", "--quick", "--backend", backend, "--out-dir", "b"]);
    assert!(ok, "{err}");
    assert!(out.contains("copy bandwidth"), "{out}");
    for table in ["song-t2", "song-t3"] {
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join(format!("b/{table}.json"))).unwrap())
                .unwrap();
        assert_eq!(json["table"], table);
        assert!(json["machine"]["cpu_bandwidth"].as_f64().unwrap() > 0.0);
        if gpu && sylva_gpu::GpuContext::shared().unwrap().timestamps {
            // The machine probes: the faster copy is the bandwidth the rows are set against,
            // and a dependent dispatch takes some time, well under a second.
            let m = &json["machine"];
            let (copy, kernel) = (m["gpu_buffer_copy"].as_f64().unwrap(), m["gpu_kernel_copy"].as_f64().unwrap());
            assert!(copy > 0.0 && kernel > 0.0, "{m}");
            assert_eq!(m["gpu_bandwidth"].as_f64().unwrap(), copy.max(kernel), "{m}");
            let dispatch = m["gpu_dispatch"].as_f64().unwrap();
            assert!(dispatch > 0.0 && dispatch < 1.0, "{m}");
            let pass = m["gpu_pass"].as_f64().unwrap();
            assert!(pass > 0.0 && pass < 1.0, "{m}");
            assert!(out.contains("dependent dispatch"), "{out}");
        }
        assert!(json["machine"]["command"].as_str().unwrap().contains("bench all"));
        let rows = json["rows"].as_array().unwrap();
        assert_eq!(rows.len(), 3, "--quick runs the three smallest sizes");
        let mut last = 0;
        for r in rows {
            let particles = r["particles"].as_u64().unwrap();
            assert!(particles > last, "rows grow");
            last = particles;
            assert!(r["bytes_per_step"].as_u64().unwrap() > particles);
            assert!(r["cpu_bytes_per_step"].as_u64().unwrap() > particles);
            let cpu = &r["cpu"];
            assert!(cpu["median"].as_f64().unwrap() > 0.0);
            assert!(cpu["min"].as_f64().unwrap() <= cpu["median"].as_f64().unwrap());
            assert!(cpu["median"].as_f64().unwrap() <= cpu["max"].as_f64().unwrap());
            assert!(cpu["samples"].as_u64().unwrap() >= 3);
            assert_eq!(r["gpu"].is_null(), !gpu);
            // The work model: a substep's two dispatches (stage 1, the fused particle pass),
            // up to 64 substeps to a pass, on bind groups made once; a sample is one
            // submission.
            let commands = &r["gpu_commands"];
            assert_eq!(commands.is_null(), !gpu);
            if gpu {
                let [d, p, b, s] =
                    ["dispatches", "passes", "bind_groups", "submissions"].map(|k| commands[k].as_f64().unwrap());
                assert!(d >= 2.0 && p < 1.0 && p <= d / 2.0 && b == 0.0 && s < 1.0, "{commands}");
            }
        }
        let md = std::fs::read_to_string(dir.path().join(format!("b/{table}.md"))).unwrap();
        assert_eq!(md.lines().filter(|l| l.starts_with("| ")).count(), 2 + 3, "{md}");
        let png = std::fs::read(dir.path().join(format!("b/{table}.png"))).unwrap();
        assert_eq!(&png[..4], b"\x89PNG");
    }
    // Akagi's Table 2: one-thread, all-thread and GPU mesh timings per row.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("b/akagi-t2.json")).unwrap()).unwrap();
    assert_eq!(json["table"], "akagi-t2");
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 3);
    for r in rows {
        assert!(r["triangles"].as_u64().unwrap() >= r["paper_triangles"].as_u64().unwrap());
        for key in ["cpu_one_ms", "cpu_all_ms"] {
            let [m, lo, hi] = [0, 1, 2].map(|i| r[key][i].as_f64().unwrap());
            assert!(lo <= m && m <= hi && m > 0.0, "{key}: {m} ({lo}–{hi})");
        }
        assert_eq!(r["gpu_ms"].is_null(), !gpu);
        // Bark rings, their midpoints and the leaves: three dispatches in one pass.
        if gpu {
            let commands = &r["gpu_commands"];
            assert_eq!(commands["dispatches"].as_f64(), Some(3.0), "{commands}");
            assert_eq!(commands["passes"].as_f64(), Some(1.0), "{commands}");
            assert_eq!(commands["bind_groups"].as_f64(), Some(0.0), "{commands}");
        }
    }
    let md = std::fs::read_to_string(dir.path().join("b/akagi-t2.md")).unwrap();
    assert_eq!(md.lines().filter(|l| l.starts_with("| ")).count(), 2 + 3, "{md}");
    assert_eq!(&std::fs::read(dir.path().join("b/akagi-t2.png")).unwrap()[..4], b"\x89PNG");
    // Zioma's Table 6-1: pose, frame and skinning-only timings for 30, 100 and 256 instances.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("b/zioma-t6-1.json")).unwrap()).unwrap();
    assert_eq!(json["table"], "zioma-t6-1");
    assert_eq!(json["machine"]["gpu_clock"].is_null(), !gpu);
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.iter().map(|r| r["instances"].as_u64().unwrap()).collect::<Vec<_>>(), [30, 100, 256]);
    for r in rows {
        assert_eq!(r["branches"].as_u64().unwrap(), 80 * r["instances"].as_u64().unwrap());
        // The paper's four data columns, SLOD2 (trunk only) cheaper than SLOD3.
        let paper =
            ["paper_dx9_ms", "paper_dx10_ms", "paper_dx10_slod2_ms", "paper_skin_ms"].map(|k| r[k].as_f64().unwrap());
        assert!(paper.iter().all(|&ms| ms > 0.0) && paper[2] < paper[1], "{paper:?}");
        for key in [
            "cpu_pose_ms",
            "cpu_frame_ms",
            "cpu_frame_slod2_ms",
            "cpu_skin_ms",
            "gpu_pose_ms",
            "gpu_frame_ms",
            "gpu_frame_slod2_ms",
            "gpu_skin_ms",
        ] {
            if key.starts_with("gpu") && !gpu {
                assert!(r[key].is_null(), "{key}");
                continue;
            }
            let [m, lo, hi] = [0, 1, 2].map(|i| r[key][i].as_f64().unwrap());
            assert!(lo <= m && m <= hi && m > 0.0, "{key}: {m} ({lo}–{hi})");
        }
        assert!(r["cpu_bandwidth_fraction"].as_f64().unwrap() > 0.0);
        // Pose and skinning of a frame in one submission, on bind groups made once.
        if gpu {
            let commands = &r["gpu_frame_commands"];
            assert_eq!(commands["submissions"].as_f64(), Some(1.0), "{commands}");
            assert_eq!(commands["bind_groups"].as_f64(), Some(0.0), "{commands}");
        }
    }
    let md = std::fs::read_to_string(dir.path().join("b/zioma-t6-1.md")).unwrap();
    assert_eq!(md.lines().filter(|l| l.starts_with("| ")).count(), 2 + 3, "{md}");
    assert_eq!(&std::fs::read(dir.path().join("b/zioma-t6-1.png")).unwrap()[..4], b"\x89PNG");
    // Skjermo's figure: the quick sizes are binary trees of 4,095 and 16,383 stems.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("b/skjermo.json")).unwrap()).unwrap();
    assert_eq!(json["table"], "skjermo");
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.iter().map(|r| r["branches"].as_u64().unwrap()).collect::<Vec<_>>(), [4095, 16383]);
    for r in rows {
        assert!(r["paper_updates_per_s"].is_null(), "the quick sizes have no paper figure");
        for key in ["cpu", "cpu_reference"] {
            assert!(r[key]["median"].as_f64().unwrap() > 0.0, "{key}");
            assert_eq!(r[key]["clock"], "wall clock");
        }
        assert_eq!(r["gpu"].is_null(), !gpu);
        if gpu {
            let clock = r["gpu"]["clock"].as_str().unwrap();
            assert!(clock == "wall clock" || clock == "timestamp queries", "{clock}");
            // One dispatch per update, a sample's updates in one submission.
            let commands = &r["gpu_commands"];
            assert_eq!(commands["dispatches"].as_f64(), Some(1.0), "{commands}");
            assert_eq!(commands["bind_groups"].as_f64(), Some(0.0), "{commands}");
            assert!(commands["submissions"].as_f64().unwrap() < 0.1, "{commands}");
        }
    }
    let md = std::fs::read_to_string(dir.path().join("b/skjermo.md")).unwrap();
    assert_eq!(md.lines().filter(|l| l.starts_with("| ")).count(), 2 + 2, "{md}");
    assert_eq!(&std::fs::read(dir.path().join("b/skjermo.png")).unwrap()[..4], b"\x89PNG");
    let leftovers: Vec<_> = std::fs::read_dir(dir.path().join("b"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    let (ok, _, err) = sylva(dir.path(), &["bench", "song-t2", "--budget", "0"]);
    assert!(!ok && err.contains("--budget"), "{err}");
}

#[test]
fn export_writes_a_looping_glb_and_reports_every_lod() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = sylva(
        dir.path(),
        &[
            "export",
            "--species",
            "palm",
            "--method",
            "akagi",
            "--seconds",
            "1",
            "--fps",
            "20",
            "--loop",
            "--blend",
            "0.25",
            "--target",
            "film",
            "--out",
            "palm.glb",
        ],
    );
    assert!(ok, "{out}\n{err}");
    let bytes = std::fs::read(dir.path().join("palm.glb")).unwrap();
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize, bytes.len(), "GLB length field");
    for lod in ["  0 ", "  1 ", "  2 "] {
        assert!(out.lines().any(|l| l.starts_with(lod)), "LOD row `{lod}` missing:\n{out}");
    }
    assert!(out.contains("21 keys") && out.contains("looping") && out.contains("`wind_loop`"), "{out}");
    // Joints: one per segment and a leaf joint per leaf-bearing segment.
    let joints = |out: &str| -> (usize, usize) {
        let line = out.lines().find(|l| l.contains("skin:")).unwrap_or_else(|| panic!("no skin line:\n{out}"));
        let words: Vec<&str> = line.split_whitespace().collect();
        let n =
            |w: &str| words[words.iter().position(|x| *x == w).unwrap() - 1].trim_start_matches('(').parse().unwrap();
        (n("joints"), n("of"))
    };
    let (all, leaf) = joints(&out);
    assert!(leaf > 0 && all == 309 + leaf, "{out}");
    let (ok, out, err) = sylva(
        dir.path(),
        &[
            "export",
            "--species",
            "palm",
            "--seconds",
            "0.5",
            "--no-leaf-joints",
            "--target",
            "film",
            "--out",
            "rigid.glb",
        ],
    );
    assert!(ok, "{out}\n{err}");
    assert_eq!(joints(&out), (309, 0), "{out}");
    // The game target (the default): within its joint budget, leaf cards, reduced keys, the
    // budget printed; `--lod-files` writes a file per level from one bake.
    let (ok, out, err) = sylva(
        dir.path(),
        &["export", "--species", "palm", "--seconds", "2", "--loop", "--lod-files", "--out", "game.glb"],
    );
    assert!(ok, "{out}\n{err}");
    assert_eq!(out.matches("baked in").count(), 1, "one bake for every file:\n{out}");
    for k in 0..3 {
        assert!(dir.path().join(format!("game_LOD{k}.glb")).exists(), "game_LOD{k}.glb:\n{out}");
    }
    assert!(!dir.path().join("game.glb").exists());
    let (all, leaf) = joints(&out);
    assert!(all <= 256 && leaf > 0, "{out}");
    assert!(out.contains("cards") && out.contains("keys reduced within 0.05°"), "{out}");
    assert!(out.contains("game budget: 256 joints per skin, 50000 / 16000 / 5000 triangles"), "{out}");
    // `--meshopt`: the same file, smaller, requiring the extension.
    let (ok, out, err) = sylva(dir.path(), &["export", "--species", "palm", "--static", "--meshopt", "--out", "m.glb"]);
    assert!(ok, "{out}\n{err}");
    let (ok, _, _) = sylva(dir.path(), &["export", "--species", "palm", "--static", "--out", "p.glb"]);
    assert!(ok);
    let (m, p) = (std::fs::read(dir.path().join("m.glb")).unwrap(), std::fs::read(dir.path().join("p.glb")).unwrap());
    assert!(m.len() < p.len() && m.windows(23).any(|w| w == b"EXT_meshopt_compression"), "{} vs {}", m.len(), p.len());
    // Static .gltf: one JSON file, no skin.
    let (ok, out, err) = sylva(dir.path(), &["export", "--species", "palm", "--static", "--out", "palm.gltf"]);
    assert!(ok, "{out}\n{err}");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("palm.gltf")).unwrap()).unwrap();
    assert!(json.get("skins").is_none() && json.get("animations").is_none());
    assert!(json["buffers"][0]["uri"].as_str().unwrap().starts_with("data:application/octet-stream;base64,"));
}

#[test]
fn export_rejects_bad_input_and_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["--fps", "0"], "`fps` = 0"),
        (&["--seconds", "-2"], "`seconds` = -2"),
        (&["--target", "film", "--max-joints", "10"], "more than the limit of 10"),
        (&["--max-joints", "0"], "`max_joints` = 0"),
        (&["--key-tolerance", "-1"], "`key_tolerance` = -1"),
        (&["--target", "mobile"], "invalid value 'mobile'"),
        (&["--static", "--key-tolerance", "0.1"], "cannot be used with"),
        (&["--joints", "stem", "--max-joints", "10"], "joints (one per stem)"),
        (&["--lod", "8,3,8"], "four values"),
        (&["--lod", "2,3,8,1"], "`sides` = 2"),
        (&["--out", "tree.fbx"], ".glb or .gltf"),
        (&["--out", "/proc/sylva/tree.glb"], "/proc/sylva"),
        (&["--loop", "--seconds", "1", "--blend", "0.9"], "`blend` = 0.9"),
        (&["--static", "--no-leaf-joints"], "cannot be used with"),
        (&["--static", "--loop"], "cannot be used with"),
        (&["--static", "--joints", "stem"], "cannot be used with"),
        (&["--static", "--max-joints", "64"], "cannot be used with"),
    ];
    for (args, expect) in cases {
        let mut all = vec!["export", "--species", "palm"];
        all.extend_from_slice(args);
        for (flag, value) in [("--seconds", "0.5"), ("--fps", "10")] {
            if !args.contains(&flag) {
                all.extend_from_slice(&[flag, value]);
            }
        }
        if !args.contains(&"--out") {
            all.extend_from_slice(&["--out", "tree.glb"]);
        }
        let (ok, out, err) = sylva(dir.path(), &all);
        assert!(!ok, "{args:?} should fail:\n{out}");
        assert!(err.contains(expect), "{args:?}: expected `{expect}` in:\n{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "files left behind: {left:?}");
}

/// The MP4 path without a real ffmpeg: a stand-in `ffmpeg` on PATH answers `-version` and
/// copies its stdin to its output file (the last argument), so the test sees exactly what
/// Sylva pipes — every frame, raw RGBA at the scene's size — and that the file is renamed
/// into place only when complete.
#[test]
fn mp4_pipe_hands_ffmpeg_every_frame_and_renames_when_done() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    let fake = bin.join("ffmpeg");
    std::fs::write(
        &fake,
        "#!/bin/sh\n[ \"$1\" = -version ] && exit 0\nfor last; do :; done\necho \"$@\" > \"$last.args\"\ncat > \"$last\"\n",
    )
    .unwrap();
    std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    let scene = TINY_SCENE.replace("mp4 = false", "mp4 = true").replace("seconds = 20", "seconds = 0.03");
    std::fs::write(dir.path().join("tiny.toml"), scene).unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let out = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .current_dir(dir.path())
        .env("PATH", path)
        .args(["render", "tiny.toml", "--no-png"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mp4 = std::fs::read(dir.path().join("out/tiny.mp4")).unwrap();
    let frames = 3; // seconds × fps frames: 0.03 s at 100 fps, at t = 0, 0.01, 0.02 s
    assert_eq!(mp4.len(), frames * 64 * 48 * 4, "raw RGBA frames piped");
    assert!(mp4.chunks(4).any(|p| p[1] > p[0] + 20), "the frames show green leaves");
    let args = std::fs::read_dir(dir.path().join("out"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.to_string_lossy().ends_with(".args"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .unwrap();
    assert!(args.contains("-s 64x48") && args.contains("-pix_fmt rgba") && args.contains("-r 100"), "{args}");
    let tmp: Vec<_> = std::fs::read_dir(dir.path().join("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp") && !n.ends_with(".args"))
        .collect();
    assert!(tmp.is_empty(), "{tmp:?}");
}

/// A virtual X display (Xvfb) for the viewer's tests, stopped when dropped. `None` (with
/// the reason printed) when Xvfb is not installed, except in CI, where that fails.
struct Xvfb {
    child: std::process::Child,
    display: String,
}

impl Xvfb {
    fn start() -> Option<Self> {
        use std::io::BufRead;
        let spawned = Command::new("Xvfb")
            .args(["-displayfd", "1", "-screen", "0", "1024x768x24", "-nolisten", "tcp"])
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::null())
            .spawn();
        let mut child = match spawned {
            Ok(c) => c,
            Err(e) => {
                assert!(std::env::var("CI").is_err(), "CI requires Xvfb for the viewer tests: {e}");
                eprintln!("skipping: Xvfb is not installed ({e})");
                return None;
            }
        };
        let mut line = String::new();
        std::io::BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
        let n: u32 = line.trim().parse().unwrap_or_else(|_| panic!("Xvfb printed no display number: {line:?}"));
        Some(Self { child, display: format!(":{n}") })
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

const VIEW_SCENE: &str = r#"
wind = "calm.toml"
[output]
fps = 30
sim_rate = 60
[camera]
eye = [0.0, 3.0, 12.0]
target = [0.0, 3.0, 0.0]
[[tree]]
species = "palm"
method = "akagi"
backend = "cpu"
copies = [{ position = [3.0, 0.0, -2.0] }]
"#;

/// The viewer under Xvfb, driven by a script: the frame shows the tree, a blast placed by
/// clicking the ground moves it, a malformed scene on disk shows its error and keeps the
/// last good scene running, and a good edit is picked up.
#[test]
fn viewer_runs_a_scripted_session_under_xvfb() {
    let Some(x) = Xvfb::start() else { return };
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), VIEW_SCENE).unwrap();
    std::fs::write(dir.path().join("calm.toml"), "# still air\n").unwrap();
    std::fs::write(dir.path().join("broken.toml"), VIEW_SCENE.replace("fps = 30", "fps = 30\nfsp = 2")).unwrap();
    let two = format!("{VIEW_SCENE}\n[[tree]]\nspecies = \"palm\"\nmethod = \"zioma\"\nposition = [4.0, 0.0, -3.0]\n");
    std::fs::write(dir.path().join("two.toml"), two).unwrap();
    std::fs::write(
        dir.path().join("script.txt"),
        "frames 5\nreport before.json\nclick 0.55 0.9   # the ground in front of the palm\nframes 30\n\
         report after.json\nscreenshot shot.png\noverwrite-scene broken.toml\nframes 3\nreport broken.json\n\
         overwrite-scene two.toml\nframes 3\nreport two.json\nquit\n",
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .current_dir(dir.path())
        .env("DISPLAY", &x.display)
        .env_remove("WAYLAND_DISPLAY")
        .args(["view", "scene.toml", "--script", "script.txt", "--width", "640", "--height", "400"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}\n{}", String::from_utf8_lossy(&out.stdout));
    let report = |name: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.path().join(name)).unwrap()).unwrap()
    };
    let displacement = |r: &serde_json::Value| r["trees"][0]["displacement_m"].as_f64().unwrap();
    let (before, after) = (report("before.json"), report("after.json"));
    assert_eq!(displacement(&before), 0.0, "still air leaves the tree at rest");
    assert!(displacement(&after) > 1e-3, "the blast did not move the tree: {after}");
    // The copy has its own simulation, whose clock runs ahead of the scene's (its phase):
    // the blast reaches it too.
    let each = after["trees"][0]["simulation_displacements_m"].as_array().unwrap();
    assert_eq!(each.len(), 2, "{after}");
    assert!(each.iter().all(|d| d.as_f64().unwrap() > 1e-3), "a simulation missed the blast: {after}");
    assert_eq!(after["effects"], 1);
    assert!(after["frames"].as_u64().unwrap() > before["frames"].as_u64().unwrap());

    // The tree is in the frame: where the crown stands against the sky, pixels differ from
    // the sky at the same height at the image's edge.
    let shot = image::open(dir.path().join("shot.png")).unwrap().to_rgb8();
    let (w, h) = shot.dimensions();
    assert!(w > 100 && h > 100, "{w}×{h}");
    let mut crown = 0;
    for y in h / 8..h / 2 {
        let edge = shot.get_pixel(1, y);
        for x in w * 3 / 8..w * 5 / 8 {
            let p = shot.get_pixel(x, y);
            if (0..3).map(|c| p[c].abs_diff(edge[c]) as u32).sum::<u32>() > 40 {
                crown += 1;
            }
        }
    }
    assert!(crown > (w * h / 200) as usize, "only {crown} tree pixels against the sky");

    // A malformed scene: the error names the file, line and key; the old scene runs on.
    let broken = report("broken.json");
    let msg = broken["reload_error"].as_str().unwrap_or_else(|| panic!("no reload error: {broken}"));
    assert!(msg.contains("scene.toml") && msg.contains("fsp"), "{msg}");
    assert_eq!(broken["trees"].as_array().unwrap().len(), 1);
    assert!(broken["frames"].as_u64().unwrap() > after["frames"].as_u64().unwrap());
    // A good edit replaces it.
    let two = report("two.json");
    assert!(two["reload_error"].is_null(), "{two}");
    assert_eq!(two["trees"].as_array().unwrap().len(), 2);
}

#[test]
fn viewer_without_a_display_says_so_and_points_to_render() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .current_dir(dir.path())
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .args(["view"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("no display") && err.contains("sylva render"), "{err}");
    // A bad script is reported before any window opens.
    std::fs::write(dir.path().join("s.txt"), "frames 2\nteleport 3\n").unwrap();
    let (ok, _, err) = sylva(dir.path(), &["view", "--script", "s.txt"]);
    assert!(!ok && err.contains("s.txt:2") && err.contains("teleport"), "{err}");
}

#[test]
fn fidelity_quick_measures_each_method_beside_the_field_references() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["fidelity", "--quick", "--species", "quaking_aspen", "--sizes", "0.5,0.7", "--methods", "akagi,zioma"];
    let (ok, out, err) = sylva(dir.path(), &[&args[..], &["--out-dir", "f"]].concat());
    assert!(ok, "{err}");
    assert!(out.contains("Moore & Maguire") && out.contains("| akagi |"), "{out}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("f/fidelity.json")).unwrap()).unwrap();
    let rows = json["runs"].as_array().unwrap();
    assert_eq!(rows.len(), 4, "two sizes × two methods");
    // Neighbours of the first size, per method: the correlation falls from 2 m to 20 m across
    // the wind, and a downwind neighbour follows (a positive lag).
    let near = json["neighbours"].as_array().unwrap();
    assert_eq!(near.len(), 8, "two methods × four distances");
    for m in ["akagi", "zioma"] {
        let mine: Vec<&serde_json::Value> = near.iter().filter(|r| r["method"] == m).collect();
        let across = |k: usize| mine[k]["crosswind"].as_f64().unwrap();
        assert!(across(0) > across(3) && across(0) <= 1.0, "{m}: {mine:?}");
        assert!(mine.iter().all(|r| r["lag"].as_f64().unwrap() > 0.0), "{m}: {mine:?}");
    }
    for r in rows {
        let h = r["height"].as_f64().unwrap();
        assert!(h > 1.0 && r["dbh"].as_f64().unwrap() > 0.0);
        assert_eq!(r["steps"].as_array().unwrap().len(), 4);
        assert!(r["sway_percent"].as_f64().unwrap() > 0.0, "{r}");
        // The aspen's trunk does not fork: its crown is its trunk top.
        assert_eq!((r["leaders"].as_u64(), &r["crown_sway_percent"]), (Some(1), &r["sway_percent"]), "{r}");
        // The beam leans the trunk top further with the aspen's rising side stems' couples.
        let (at_base, rigid) =
            (r["beam_lean_percent"].as_f64().unwrap(), r["beam_rigid_lean_percent"].as_f64().unwrap());
        assert!(at_base > 0.0 && rigid > 1.5 * at_base, "{r}");
        // Its trunk does not fork: the frame's crown is its trunk top, which leans as the rigid beam.
        assert!((r["frame_crown_lean_percent"].as_f64().unwrap() / rigid - 1.0).abs() < 0.03, "{r}");
        if r["method"] == "akagi" {
            // Akagi rings down at its trunk's frequency in still air, the shared beam's, which
            // the whole tree's sway mode as a frame meets within 10 % on the aspen.
            let f = r["frequency"].as_f64().expect("akagi rings after the pluck");
            assert!(f > 0.05 && f < 5.0, "{f}");
            let sway = r["frame_sway_hz"].as_f64().expect("the frame finds a sway mode");
            assert!((sway / f - 1.0).abs() < 0.1 && r["frame_sway_share"].as_f64().unwrap() >= 0.05, "{r}");
        }
    }
    let md = std::fs::read_to_string(dir.path().join("f/fidelity.md")).unwrap();
    assert_eq!(md.lines().filter(|l| l.starts_with("| quaking_aspen")).count(), 4 + 8 + 2, "{md}");
    // Side by side, per tree: the methods' spread, most over least of the rows' sway.
    for size in [0.5, 0.7] {
        let sway: Vec<f64> = rows
            .iter()
            .filter(|r| r["size"].as_f64() == Some(size))
            .map(|r| r["sway_percent"].as_f64().unwrap())
            .collect();
        let spread = sway.iter().cloned().fold(0.0, f64::max) / sway.iter().cloned().fold(f64::MAX, f64::min);
        let line = md.lines().find(|l| l.starts_with(&format!("| quaking_aspen | ×{size} |")) && l.contains(") – "));
        assert!(line.is_some_and(|l| l.contains(&format!("| {spread:.2}× |"))), "{spread:.2}: {md}");
        let tree = rows.iter().find(|r| r["size"].as_f64() == Some(size)).unwrap();
        let beam = format!(
            "| {:.2} / {:.2}; {:.2} |",
            tree["beam_lean_percent"].as_f64().unwrap(),
            tree["beam_rigid_lean_percent"].as_f64().unwrap(),
            tree["frame_crown_lean_percent"].as_f64().unwrap()
        );
        assert!(line.is_some_and(|l| l.contains(&beam)), "{beam}: {md}");
        let sway = format!(
            "| {:.3} ({:.0} %) |",
            tree["frame_sway_hz"].as_f64().unwrap(),
            100.0 * tree["frame_sway_share"].as_f64().unwrap()
        );
        assert!(line.is_some_and(|l| l.contains(&sway)), "{sway}: {md}");
    }
    assert!(md.contains(" of 2 trees: the methods agree within 2×"), "{md}");
    for png in ["frequency.png", "damping.png", "bend.png", "neighbours.png"] {
        assert_eq!(&std::fs::read(dir.path().join("f").join(png)).unwrap()[..4], b"\x89PNG", "{png}");
    }
    // Bad input names the flag.
    let (ok, _, err) = sylva(dir.path(), &["fidelity", "--sizes", "0", "--out-dir", "g"]);
    assert!(!ok && err.contains("--sizes") && err.contains("size factor"), "{err}");
    assert!(!dir.path().join("g").exists());
}

/// Without a GPU driver (Vulkan's loader pointed at nothing, `WGPU_BACKEND=vulkan`), every
/// command that needs the GPU says so, names the fix, exits 1 within 10 s and writes
/// nothing: `simulate --backend gpu`, `render`, `wind --backend gpu`, `bench --backend gpu`
/// and `view` (under Xvfb, so that the window opens and the adapter is what fails).
#[test]
fn without_a_gpu_driver_gpu_commands_fail_clearly_within_10_s_and_write_nothing() {
    let x = Xvfb::start();
    let commands: [&[&str]; 5] = [
        &["simulate", "--species", "palm", "--backend", "gpu", "--seconds", "1", "--csv", "out/t.csv"],
        &["render", "--out-dir", "out"],
        &["wind", "--backend", "gpu", "--out-dir", "out/wind"],
        &["bench", "zioma-t6-1", "--backend", "gpu", "--out-dir", "out"],
        &["view"],
    ];
    for args in commands {
        if args[0] == "view" && x.is_none() {
            continue;
        }
        let dir = tempfile::tempdir().unwrap();
        let mut command = Command::new(env!("CARGO_BIN_EXE_sylva"));
        command
            .current_dir(dir.path())
            .args(args)
            .env("VK_ICD_FILENAMES", "/nonexistent")
            .env("WGPU_BACKEND", "vulkan")
            .env_remove("RUST_BACKTRACE")
            .env_remove("WAYLAND_DISPLAY");
        if let Some(x) = &x {
            command.env("DISPLAY", &x.display);
        }
        let start = std::time::Instant::now();
        let out = command.output().unwrap();
        let took = start.elapsed();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("no GPU adapter found") && err.contains("mesa-vulkan-drivers"), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(took.as_secs_f64() < 10.0, "{args:?} took {took:?}");
        let left = entries(dir.path());
        assert!(left.is_empty(), "{args:?} left {left:?}");
        println!("{:<9} failed in {:.2} s: {}", args[0], took.as_secs_f64(), err.lines().next().unwrap_or(""));
    }
}

/// The rough edges a new user met: a preset by its display name, with hyphens or in any
/// case; the README's preset path from outside the repository; a missing file said to be
/// missing where it was looked for; the method and backend as typed, not Rust's names; a
/// limit's hint naming a flag that exists, once.
#[test]
fn species_names_paths_and_output_read_as_a_user_writes_them() {
    let dir = tempfile::tempdir().unwrap();
    let digest = |out: &str| out.lines().find(|l| l.trim_start().starts_with("digest")).map(str::to_string);
    let (ok, reference, err) = sylva(dir.path(), &["generate", "--species", "quaking_aspen", "--out", "-"]);
    assert!(ok, "{err}");
    for name in ["quaking-aspen", "Quaking_Aspen", "Quaking Aspen", "QUAKING ASPEN"] {
        let (ok, out, err) = sylva(dir.path(), &["generate", "--species", name]);
        assert!(ok, "{name}: {err}");
        assert_eq!(digest(&out), digest(&reference), "{name}: the same tree as quaking_aspen");
        assert!(out.contains("wrote out/quaking_aspen.obj"), "{name}: written under the preset's name: {out}");
    }
    // The README's path, from a directory with no `presets/` in it.
    let (ok, out, err) = sylva(dir.path(), &["generate", "--species", "presets/grammars/ternary.lsys", "--out", "-"]);
    assert!(ok, "{err}");
    let (_, shipped, _) = sylva(dir.path(), &["generate", "--species", "ternary", "--out", "-"]);
    assert_eq!(digest(&out), digest(&shipped));
    let (ok, _, err) = sylva(dir.path(), &["generate", "--species", "nowhere/mine.lsys"]);
    let cwd = dir.path().canonicalize().unwrap();
    assert!(!ok && err.contains("no such file relative to") && err.contains(cwd.to_str().unwrap()), "{err}");
    // Names as typed.
    let (ok, out, err) = sylva(
        dir.path(),
        &["simulate", "--species", "palm", "--method", "akagi", "--backend", "cpu", "--seconds", "0.2"],
    );
    assert!(ok, "{err}");
    assert!(out.contains("akagi on the CPU") && !out.contains("Cpu") && !out.contains("Akagi on"), "{out}");
    // A limit's hint: a flag that exists, said once.
    let (ok, _, err) = sylva(dir.path(), &["generate", "--species", "ternary", "--iterations", "100000"]);
    assert!(!ok && err.matches("--max-iterations").count() == 1, "{err}");
    let (ok, _, err) =
        sylva(dir.path(), &["generate", "--species", "ternary", "--iterations", "3", "--max-iterations", "100000"]);
    assert!(ok, "the flag the hint names exists: {err}");
}

/// Zioma §6.3.1's wind grid from the command line: the shipped `eddies` preset by name from
/// outside the repository, and a user's own grid beside their wind file, read from elsewhere.
#[test]
fn a_wind_grid_moves_trees_from_a_preset_and_from_a_file_beside_the_wind_file() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = sylva(
        dir.path(),
        &["simulate", "--species", "monopodial", "--wind", "eddies", "--seconds", "2", "--fps", "30"],
    );
    assert!(ok, "{err}");
    assert!(!out.contains("largest segment-end speed 0.000 m/s"), "{out}");
    let (ok, out, err) = sylva(dir.path(), &["wind", "--scene", "eddies", "--to", "10", "--out-dir", "plots"]);
    assert!(ok && out.contains("wind_field.png"), "{err}");
    // A 2 × 1 × 2 grid of 6 m/s along +z, only the grid: the wind file names it relatively.
    std::fs::create_dir(dir.path().join("winds")).unwrap();
    let grid = sylva_core::wind::GridData::new([2, 1, 2], 1, vec![[0.0, 0.0, 6.0]; 4]).unwrap();
    std::fs::write(dir.path().join("winds/g.swg"), grid.to_raw()).unwrap();
    let text = "[[field]]\nkind = \"grid\"\nfile = \"g.swg\"\ncell = [10.0, 1.0, 10.0]\n";
    std::fs::write(dir.path().join("winds/w.toml"), text).unwrap();
    let args = ["simulate", "--species", "monopodial", "--wind", "winds/w.toml", "--seconds", "1", "--fps", "30"];
    let (ok, out, err) = sylva(dir.path(), &args);
    assert!(ok, "{err}");
    assert!(!out.contains("largest segment-end speed 0.000 m/s"), "{out}");
    // A grid file that is not there: the wind file's line, the grid and where it was looked for.
    std::fs::remove_file(dir.path().join("winds/g.swg")).unwrap();
    let (ok, _, err) = sylva(dir.path(), &args);
    assert!(!ok);
    assert!(err.contains("winds/w.toml:3: field[0].file: g.swg") && err.contains("looked for winds/g.swg"), "{err}");
}
