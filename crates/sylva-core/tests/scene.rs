//! Scene files: the default scene is valid; bad scenes fail with the file, line and field.

use std::path::Path;
use sylva_core::scene::{Scene, SceneError};
use sylva_core::species::SpeciesSource;

#[test]
fn the_default_scene_has_every_method_and_resolves() {
    let s = Scene::default_scene();
    for m in ["zioma", "akagi", "skjermo", "hsm"] {
        assert!(s.trees.iter().any(|t| t.method == m), "no tree uses {m}");
    }
    for t in &s.trees {
        SpeciesSource::resolve(&t.species).unwrap();
    }
    assert!(s.trees.iter().any(|t| !t.copies.is_empty()), "no instanced copies");
    assert!(s.frames() >= 2);
}

const GOOD: &str = r#"
wind = "gusty"
[output]
width = 64
height = 48
fps = 10
seconds = 0.2

[[tree]]
species = "palm"
method = "akagi"
"#;

#[test]
fn a_minimal_scene_takes_defaults() {
    let s = Scene::from_toml(GOOD, "good.toml", Path::new(".")).unwrap();
    assert_eq!(s.frames(), 2);
    assert_eq!(s.trees[0].seed, 1);
    assert_eq!(s.camera.fov_deg, 45.0);
}

#[test]
fn unknown_keys_and_bad_values_name_file_line_and_field() {
    let unknown = GOOD.replace("fps = 10", "fps = 10\nframerate = 3");
    let e = Scene::from_toml(&unknown, "s.toml", Path::new(".")).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, SceneError::Toml { line: 7, .. }), "{msg}");
    assert!(msg.starts_with("s.toml:7:") && msg.contains("framerate"), "{msg}");

    // A method the registry does not know: located when the world checks the names.
    let method = GOOD.replace("\"akagi\"", "\"wobble\"");
    let scene = Scene::from_toml(&method, "s.toml", Path::new(".")).unwrap();
    let msg = scene.check_methods(&["zioma", "akagi", "skjermo", "hsm"]).unwrap_err().to_string();
    assert!(msg.contains("s.toml:11") && msg.contains("wobble") && msg.contains("zioma"), "{msg}");
    let method = GOOD.replace("\"akagi\"", "\"Not A Name\"");
    let msg = Scene::from_toml(&method, "s.toml", Path::new(".")).unwrap_err().to_string();
    assert!(msg.contains("s.toml:11") && msg.contains("tree[0].method"), "{msg}");

    let fps = GOOD.replace("fps = 10", "fps = -3");
    let msg = Scene::from_toml(&fps, "s.toml", Path::new(".")).unwrap_err().to_string();
    assert!(msg.contains("s.toml:6") && msg.contains("output.fps") && msg.contains("-3"), "{msg}");

    let scale = format!("{GOOD}scale = 0\n");
    let msg = Scene::from_toml(&scale, "s.toml", Path::new(".")).unwrap_err().to_string();
    assert!(msg.contains("s.toml:12") && msg.contains("tree[0].scale"), "{msg}");

    let none = GOOD.split("[[tree]]").next().unwrap();
    let msg = Scene::from_toml(none, "s.toml", Path::new(".")).unwrap_err().to_string();
    assert!(msg.contains("tree"), "{msg}");

    let groups = format!("{GOOD}phase_groups = 0\n");
    let msg = Scene::from_toml(&groups, "s.toml", Path::new(".")).unwrap_err().to_string();
    assert!(msg.contains("s.toml:12") && msg.contains("tree[0].phase_groups") && msg.contains("1 to 16"), "{msg}");

    let frames = GOOD.replace("seconds = 0.2", "seconds = 100000");
    let msg = Scene::from_toml(&frames, "s.toml", Path::new(".")).unwrap_err().to_string();
    assert!(msg.contains("output.seconds") && msg.contains("10,000 frames"), "{msg}");
}

#[test]
fn an_unreadable_scene_names_its_path() {
    let e = Scene::load(Path::new("/nonexistent/dir/scene.toml")).unwrap_err();
    assert!(matches!(e, SceneError::Io { .. }));
    assert!(e.to_string().contains("/nonexistent/dir/scene.toml"), "{e}");
}

#[test]
fn relative_species_paths_resolve_against_the_scene_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/species/palm.toml"),
        dir.path().join("my_palm.toml"),
    )
    .unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, GOOD.replace("\"palm\"", "\"my_palm.toml\"")).unwrap();
    let s = Scene::load(&path).unwrap();
    let resolved = s.resolve_path(&s.trees[0].species);
    assert_eq!(Path::new(&resolved), dir.path().join("my_palm.toml"));
    SpeciesSource::resolve(&resolved).unwrap();
}

/// Copies of a stateful-method tree are dealt among independent simulations that start at
/// different points of the wind; Zioma's copies stay one group (their phase is per instance).
#[test]
fn copies_are_dealt_among_phase_groups_with_distinct_offsets() {
    let copies: String = (0..9).map(|k| format!("{{ position = [{}, 0, -20] }}", 5 * k)).collect::<Vec<_>>().join(", ");
    let text = format!("{GOOD}copies = [{copies}]\n");
    let s = Scene::from_toml(&text, "s.toml", Path::new(".")).unwrap();
    let t = &s.trees[0];
    assert_eq!(t.phase_groups, 4, "default");
    let groups = t.phase_groups(false);
    assert_eq!(groups.len(), 4);
    assert_eq!(groups[0].offset_s, 0.0, "the tree itself keeps the scene's clock");
    assert!(groups[0].members.contains(&0));
    let mut seen: Vec<usize> = groups.iter().flat_map(|g| g.members.clone()).collect();
    seen.sort();
    assert_eq!(seen, (0..10).collect::<Vec<_>>(), "every instance in exactly one group");
    let sizes: Vec<usize> = groups.iter().map(|g| g.members.len()).collect();
    assert!(sizes.iter().max().unwrap() - sizes.iter().min().unwrap() <= 1, "{sizes:?}");
    let mut offsets: Vec<f32> = groups.iter().map(|g| g.offset_s).collect();
    assert!(offsets.iter().all(|&o| (0.0..sylva_core::scene::PHASE_SPAN_S).contains(&o)), "{offsets:?}");
    offsets.sort_by(f32::total_cmp);
    assert!(offsets.windows(2).all(|w| w[1] - w[0] > 0.5), "offsets too close: {offsets:?}");

    // Fewer instances than groups: one simulation per instance.
    let two = format!("{GOOD}copies = [{{ position = [5, 0, 0] }}]\n");
    let s = Scene::from_toml(&two, "s.toml", Path::new(".")).unwrap();
    assert_eq!(s.trees[0].phase_groups(false).len(), 2);
    // One group asked for: every copy shares the tree's simulation.
    let one = format!("{text}phase_groups = 1\n");
    let s = Scene::from_toml(&one, "s.toml", Path::new(".")).unwrap();
    assert_eq!(
        s.trees[0].phase_groups(false),
        [sylva_core::scene::PhaseGroup { offset_s: 0.0, members: (0..10).collect() }]
    );
    // A method that poses every instance (Zioma): one group whatever is asked.
    let zioma = text.replace("\"akagi\"", "\"zioma\"");
    let s = Scene::from_toml(&zioma, "s.toml", Path::new(".")).unwrap();
    assert_eq!(s.trees[0].phase_groups(true).len(), 1);
}

/// Saving a scene (the viewer's "save") writes TOML that reads back to the same scene.
#[test]
fn a_scene_saved_as_toml_reads_back_equal() {
    let s = Scene::default_scene();
    let text = s.to_toml();
    let back = Scene::from_toml(&text, &s.file, Path::new(".")).unwrap();
    assert_eq!(back, s, "{text}");
}

/// A tree's `leaf_motion` sets leaf-motion fields over the species'; an unknown field or a
/// value out of range names the file, the line and `tree[0].leaf_motion`.
#[test]
fn leaf_motion_in_a_scene_is_checked_and_located() {
    let good =
        GOOD.replace("method = \"akagi\"", "method = \"akagi\"\nleaf_motion = { strength = 0.5, flutter_deg = 20.0 }");
    let s = Scene::from_toml(&good, "s.toml", Path::new(".")).unwrap();
    let table = s.trees[0].leaf_motion.as_ref().unwrap();
    let m = sylva_core::leaves::LeafMotion::default().with_table(table).unwrap();
    assert_eq!((m.strength, m.flutter_deg), (0.5, 20.0));
    assert_eq!(m.petiole_ratio, sylva_core::leaves::LeafMotion::default().petiole_ratio);
    for (bad, what) in
        [("strength = -1.0", "strength"), ("wobble = 1.0", "wobble"), ("flip_speed = \"fast\"", "flip_speed")]
    {
        let text = GOOD.replace("method = \"akagi\"", &format!("method = \"akagi\"\nleaf_motion = {{ {bad} }}"));
        let msg = Scene::from_toml(&text, "s.toml", Path::new(".")).unwrap_err().to_string();
        assert!(msg.contains("s.toml:12") && msg.contains("tree[0].leaf_motion") && msg.contains(what), "{bad}: {msg}");
    }
}
