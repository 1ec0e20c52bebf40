//! Scene files: the default scene is valid; bad scenes fail with the file, line and field.

use std::path::Path;
use sylva_core::scene::{MethodName, Scene, SceneError};
use sylva_core::species::SpeciesSource;

#[test]
fn the_default_scene_has_every_method_and_resolves() {
    let s = Scene::default_scene();
    for m in [MethodName::Zioma, MethodName::Akagi, MethodName::Skjermo, MethodName::Hsm] {
        assert!(s.trees.iter().any(|t| t.method == m), "no tree uses {m:?}");
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

    let method = GOOD.replace("\"akagi\"", "\"wobble\"");
    let msg = Scene::from_toml(&method, "s.toml", Path::new(".")).unwrap_err().to_string();
    assert!(msg.contains("s.toml:11") && msg.contains("wobble") && msg.contains("zioma"), "{msg}");

    let fps = GOOD.replace("fps = 10", "fps = -3");
    let msg = Scene::from_toml(&fps, "s.toml", Path::new(".")).unwrap_err().to_string();
    assert!(msg.contains("s.toml:6") && msg.contains("output.fps") && msg.contains("-3"), "{msg}");

    let scale = format!("{GOOD}scale = 0\n");
    let msg = Scene::from_toml(&scale, "s.toml", Path::new(".")).unwrap_err().to_string();
    assert!(msg.contains("s.toml:12") && msg.contains("tree[0].scale"), "{msg}");

    let none = GOOD.split("[[tree]]").next().unwrap();
    let msg = Scene::from_toml(none, "s.toml", Path::new(".")).unwrap_err().to_string();
    assert!(msg.contains("tree"), "{msg}");

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
