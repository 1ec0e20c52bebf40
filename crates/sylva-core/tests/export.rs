//! OBJ export and atomic writes.

use sylva_core::export::{ObjOptions, write_obj};
use sylva_core::io::write_atomic;
use sylva_core::species::SpeciesSource;

#[test]
fn obj_has_a_ring_per_joint_and_a_quad_per_leaf() {
    let dir = tempfile::tempdir().unwrap();
    let t = SpeciesSource::resolve("palm").unwrap().generate(1, &Default::default(), None).unwrap();
    let path = dir.path().join("palm.obj");
    let (v, f) = write_obj(&t, &path, ObjOptions { sides: 5, leaves: true }).unwrap();
    let joints = t.segments.len() + t.stems.len();
    assert_eq!(v, joints * 5 + 4 * t.leaves.len());
    assert_eq!(f, t.segments.len() * 5 * 2 + 4 * t.leaves.len());
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("v ")).count(), v);
    // Every face index refers to an existing vertex.
    for l in text.lines().filter(|l| l.starts_with("f ")) {
        for i in l.split_whitespace().skip(1) {
            let i: usize = i.parse().unwrap();
            assert!(i >= 1 && i <= v);
        }
    }
}

#[test]
fn failed_writes_leave_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.obj");
    std::fs::write(&path, "old").unwrap();
    let r = write_atomic(&path, |w| {
        w.write_all(b"partial")?;
        Err(std::io::Error::other("disk full"))
    });
    assert!(r.is_err());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "temporary file left behind");
    // A missing directory is an error, not a panic.
    let t = SpeciesSource::resolve("ternary").unwrap().generate(1, &Default::default(), None).unwrap();
    assert!(write_obj(&t, &dir.path().join("missing/dir/t.obj"), ObjOptions::default()).is_err());
}
