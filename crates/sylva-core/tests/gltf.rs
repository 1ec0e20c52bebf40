//! glTF export: files pass the Khronos validator; the skin and animation, read back with
//! the `gltf` crate and applied at frame k, reproduce Sylva's own skinned mesh for frame k;
//! looping clips are seamless; hierarchy attributes, tangents and LODs mean what they say;
//! bad inputs are refused without leaving a file.

use glam::{Mat4, Quat, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::export::gltf::tangents;
use sylva_core::export::{
    BakeError, BakeParams, Clip, DEFAULT_LODS, GltfError, GltfOptions, JointMode, Lod, bake, build_gltf, write_gltf,
};
use sylva_core::mesh::{MeshLayout, MeshParams, SkinLayout};
use sylva_core::methods::{Animator, MethodOptions, akagi, hsm, skjermo, zioma};
use sylva_core::species::SpeciesSource;
use sylva_core::wind::WindScene;

fn tree(name: &str) -> Tree {
    SpeciesSource::resolve(name).unwrap().generate(2, &Default::default(), None).unwrap()
}

fn gusty() -> WindScene {
    WindScene::resolve("gusty").unwrap()
}

/// `method` on `t` at rest, seed 1.
fn animator(t: &Tree, method: &str) -> Box<dyn Animator> {
    let build = match method {
        "zioma" => zioma::animator,
        "akagi" => akagi::animator,
        "skjermo" => skjermo::animator,
        "hsm" => hsm::animator,
        m => panic!("no method {m}"),
    };
    build(Arc::new(t.clone()), &MethodOptions::seeded(1)).unwrap()
}

fn clip(t: &Tree, method: &str, seconds: f32, looped: bool) -> Clip {
    let p = BakeParams { seconds, fps: 30.0, looped, blend: 0.5, preroll: 0.5, ..Default::default() };
    bake(animator(t, method).as_mut(), &gusty(), &p, &mut |_, _| {}).unwrap()
}

fn glb(t: &Tree, c: Option<&Clip>, opts: &GltfOptions) -> Vec<u8> {
    let doc = build_gltf(t, c, opts).unwrap();
    let mut out = Vec::new();
    doc.write_glb(&mut out).unwrap();
    out
}

// ---------------------------------------------------------------------------------------
// The Khronos validator.

/// The validator script, or `None` (with the reason printed) outside CI when it is not
/// installed. In CI (`CI=true`) a missing validator fails the test.
fn validator() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tools/gltf-validator");
    let installed = dir.join("node_modules/gltf-validator/package.json").exists();
    let node = std::process::Command::new("node").arg("--version").output().is_ok_and(|o| o.status.success());
    if installed && node {
        return Some(dir.join("validate.js"));
    }
    let why = if node {
        "the glTF validator is not installed (npm ci --prefix tools/gltf-validator)"
    } else {
        "node is not installed"
    };
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("{why}; CI must run the validator");
    }
    eprintln!("skipping the Khronos validator: {why}");
    None
}

#[test]
fn every_kind_of_export_passes_the_khronos_validator_with_no_errors_or_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let palm = tree("palm");
    let willow = tree("monopodial");
    let mut files = Vec::new();
    let mut write = |name: &str, t: &Tree, c: Option<&Clip>, opts: GltfOptions| {
        let path = dir.path().join(name);
        write_gltf(t, c, &opts, &path).unwrap();
        files.push(path);
    };
    let looped = clip(&palm, "akagi", 1.5, true);
    write("palm_akagi_loop.glb", &palm, Some(&looped), GltfOptions::default());
    write("palm_akagi_loop.gltf", &palm, Some(&looped), GltfOptions::default());
    let hsm = clip(&palm, "hsm", 0.5, false);
    write("palm_hsm_stems.glb", &palm, Some(&hsm), GltfOptions { joints: JointMode::Stem, ..Default::default() });
    write("palm_static.glb", &palm, None, GltfOptions::default());
    let zioma = clip(&willow, "zioma", 0.5, false);
    write(
        "lsystem_zioma.gltf",
        &willow,
        Some(&zioma),
        GltfOptions { lods: vec![Lod { sides: 3, samples: 1, leaf_sides: 3, leaf_keep: 0.1 }], ..Default::default() },
    );
    let Some(script) = validator() else { return };
    let out = std::process::Command::new("node").arg(&script).args(&files).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let reports: Vec<serde_json::Value> =
        stdout.lines().map(|l| serde_json::from_str(l).expect("one JSON report per line")).collect();
    assert_eq!(reports.len(), files.len(), "validator output: {stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    for r in &reports {
        assert_eq!(r["errors"], 0, "{r}");
        assert_eq!(r["warnings"], 0, "{r}");
    }
    assert!(out.status.success(), "{stdout}");
}

// ---------------------------------------------------------------------------------------
// Reading the file back.

/// A glb read back: for LOD0, rest positions, joints and weights; the skin's joint nodes
/// and inverse bind matrices; node rest transforms and parents; animation keys per node.
struct ReadBack {
    positions: Vec<Vec3>,
    joints: Vec<[u16; 4]>,
    weights: Vec<[f32; 4]>,
    skin_nodes: Vec<usize>,
    ibm: Vec<Mat4>,
    parent: Vec<Option<usize>>,
    rest: Vec<(Vec3, Quat)>,
    rotation: HashMap<usize, Vec<Quat>>,
    translation: HashMap<usize, Vec<Vec3>>,
    custom: HashMap<String, Vec<Vec<f32>>>,
}

fn read_back(bytes: &[u8]) -> ReadBack {
    let g = gltf::Gltf::from_slice(bytes).unwrap();
    let blob = g.blob.clone().unwrap();
    let buf = |b: gltf::Buffer<'_>| -> Option<&[u8]> { (b.index() == 0).then_some(&blob[..]) };
    let mesh = g.meshes().next().unwrap();
    let (mut positions, mut joints, mut weights) = (Vec::new(), Vec::new(), Vec::new());
    let mut custom: HashMap<String, Vec<Vec<f32>>> = HashMap::new();
    for p in mesh.primitives() {
        let r = p.reader(buf);
        positions.extend(r.read_positions().unwrap().map(Vec3::from_array));
        if let Some(j) = r.read_joints(0) {
            joints.extend(j.into_u16());
            weights.extend(r.read_weights(0).unwrap().into_f32());
        }
        for (sem, acc) in p.attributes() {
            if let gltf::Semantic::Extras(name) = sem {
                let view = acc.view().unwrap();
                let start = view.offset() + acc.offset();
                let n = acc.dimensions().multiplicity();
                let data: &[f32] = bytemuck::cast_slice(&blob[start..start + acc.count() * n * 4]);
                custom.entry(name).or_default().extend(data.chunks(n).map(<[f32]>::to_vec));
            }
        }
    }
    let nodes = g.nodes().count();
    let mut parent = vec![None; nodes];
    let mut rest = Vec::with_capacity(nodes);
    for n in g.nodes() {
        for c in n.children() {
            parent[c.index()] = Some(n.index());
        }
        let (t, r, _) = n.transform().decomposed();
        rest.push((Vec3::from_array(t), Quat::from_array(r)));
    }
    let (mut skin_nodes, mut ibm) = (Vec::new(), Vec::new());
    if let Some(skin) = g.skins().next() {
        skin_nodes = skin.joints().map(|j| j.index()).collect();
        ibm = skin.reader(buf).read_inverse_bind_matrices().unwrap().map(|m| Mat4::from_cols_array_2d(&m)).collect();
    }
    let (mut rotation, mut translation) = (HashMap::new(), HashMap::new());
    for a in g.animations() {
        for ch in a.channels() {
            let node = ch.target().node().index();
            match ch.reader(buf).read_outputs().unwrap() {
                gltf::animation::util::ReadOutputs::Rotations(r) => {
                    rotation.insert(node, r.into_f32().map(Quat::from_array).collect());
                }
                gltf::animation::util::ReadOutputs::Translations(t) => {
                    translation.insert(node, t.map(Vec3::from_array).collect());
                }
                _ => panic!("only rotation and translation channels are written"),
            }
        }
    }
    ReadBack { positions, joints, weights, skin_nodes, ibm, parent, rest, rotation, translation, custom }
}

impl ReadBack {
    /// World matrix of every node at key `k`.
    fn world(&self, k: usize) -> Vec<Mat4> {
        let n = self.rest.len();
        let local: Vec<Mat4> = (0..n)
            .map(|i| {
                let t = self.translation.get(&i).map_or(self.rest[i].0, |v| v[k]);
                let r = self.rotation.get(&i).map_or(self.rest[i].1, |v| v[k]);
                Mat4::from_rotation_translation(r, t)
            })
            .collect();
        (0..n)
            .map(|mut i| {
                let mut m = local[i];
                while let Some(p) = self.parent[i] {
                    m = local[p] * m;
                    i = p;
                }
                m
            })
            .collect()
    }

    /// glTF skinning at key `k`: Σ wᵢ · world(jointᵢ) · IBMᵢ · p.
    fn skinned(&self, k: usize) -> Vec<Vec3> {
        let world = self.world(k);
        let joint: Vec<Mat4> = self.skin_nodes.iter().zip(&self.ibm).map(|(&n, ibm)| world[n] * *ibm).collect();
        self.positions
            .iter()
            .zip(self.joints.iter().zip(&self.weights))
            .map(|(p, (j, w))| (0..4).map(|i| w[i] * joint[j[i] as usize].transform_point3(*p)).sum())
            .collect()
    }
}

/// Sylva's own skinned mesh (LOD0 = the default mesh parameters) for frame k.
fn sylva_skinned(t: &Tree, c: &Clip, k: usize) -> Vec<Vec3> {
    let layout = MeshLayout::new(t, MeshParams::default()).unwrap();
    let skin = SkinLayout::new(&layout);
    let m = skin.skin(&c.joints[k], &c.acc[k], 1);
    m.tubes.iter().chain(&m.leaves).map(|v| Vec3::from_array(v.position)).collect()
}

fn check_frames(t: &Tree, c: &Clip, what: &str) {
    let rb = read_back(&glb(t, Some(c), &GltfOptions::default()));
    let tol = 1e-4 * t.height();
    for k in [0, c.frames() / 3, c.frames() - 1] {
        let ours = sylva_skinned(t, c, k);
        let theirs = rb.skinned(k);
        assert_eq!(ours.len(), theirs.len(), "{what}");
        let (worst, at) = ours
            .iter()
            .zip(&theirs)
            .enumerate()
            .map(|(i, (a, b))| (a.distance(*b), i))
            .fold((0.0f32, 0), |m, x| if x.0 > m.0 { x } else { m });
        assert!(worst <= tol, "{what}, frame {k}: vertex {at} off by {worst} m (tolerance {tol} m)");
    }
    // The file holds the motion, not the rest pose: frame k moved away from rest.
    let rest = rb.skinned(0);
    let moved =
        sylva_skinned(t, c, c.frames() - 1).iter().zip(&rb.positions).map(|(a, b)| a.distance(*b)).fold(0.0, f32::max);
    assert!(moved > 1e-3 * t.height(), "{what}: the clip does not move the tree ({moved} m)");
    assert_eq!(rest.len(), rb.positions.len());
}

/// Number of translation channels in the document's animation.
fn translation_channels(doc: &sylva_core::export::GltfDocument) -> usize {
    use gltf::json::{animation::Property, validation::Checked};
    doc.root.animations[0]
        .channels
        .iter()
        .filter(|ch| matches!(ch.target.path, Checked::Valid(Property::Translation)))
        .count()
}

#[test]
fn skin_and_animation_read_back_reproduce_sylvas_mesh_at_frame_k_rotation_channels() {
    // Akagi keeps segments attached by forward kinematics: rotation channels only.
    let t = tree("palm");
    let c = clip(&t, "akagi", 1.0, false);
    let doc = build_gltf(&t, Some(&c), &GltfOptions::default()).unwrap();
    let translations = translation_channels(&doc);
    assert_eq!(translations, 0, "forward kinematics needs no translation channels");
    check_frames(&t, &c, "palm, Akagi");
}

#[test]
fn skin_and_animation_read_back_reproduce_sylvas_mesh_at_frame_k_with_translations() {
    // The four methods pose by forward kinematics; a clip whose joints leave their parents
    // (cluster centres, a stretchy method) needs translation channels. Make one from an HSM
    // clip by moving every joint off its parent's by a few millimetres, differently per frame.
    let t = tree("palm");
    let mut c = clip(&t, "hsm", 0.5, false);
    for (f, frame) in c.joints.iter_mut().enumerate() {
        for (i, j) in frame.iter_mut().enumerate() {
            let phase = (i * 7 + f * 3) as f32 * 0.37;
            j[0] += 0.004 * phase.sin();
            j[1] += 0.003 * phase.cos();
        }
    }
    let doc = build_gltf(&t, Some(&c), &GltfOptions::default()).unwrap();
    let translations = translation_channels(&doc);
    assert_eq!(translations, t.segments.len(), "every joint moved off its parent");
    check_frames(&t, &c, "palm, HSM with joints moved");
}

#[test]
fn joints_per_stem_move_each_stem_rigidly_about_its_base() {
    let t = tree("palm");
    let c = clip(&t, "akagi", 0.5, false);
    let opts = GltfOptions { joints: JointMode::Stem, ..Default::default() };
    let rb = read_back(&glb(&t, Some(&c), &opts));
    assert_eq!(rb.skin_nodes.len(), t.stems.len());
    let layout = MeshLayout::new(&t, MeshParams::default()).unwrap();
    let stride = layout.params.sides as usize + 1;
    let k = c.frames() - 1;
    let skinned = rb.skinned(k);
    let tol = 1e-4 * t.height();
    for (r, ring) in layout.rings.iter().enumerate() {
        let stem = t.segments.stem[ring.segment as usize] as usize;
        let first = t.stems.first_segment[stem] as usize;
        let d = Quat::from_array(c.acc[k][first]);
        let j = Vec3::from_slice(&c.joints[k][first][..3]);
        let ring_vertices = r * stride..(r + 1) * stride;
        for (p, s) in rb.positions[ring_vertices.clone()].iter().zip(&skinned[ring_vertices]) {
            let expect = j + d * (*p - t.segments.start[first]);
            assert!(s.distance(expect) <= tol, "ring {r}: {} m off", s.distance(expect));
        }
    }
}

#[test]
fn looping_clip_is_seamless_in_pose_and_angular_velocity() {
    let t = tree("palm");
    let fps = 30.0;
    let looped = clip(&t, "akagi", 3.0, true);
    let cut = clip(&t, "akagi", 3.0, false);
    let rb = read_back(&glb(&t, Some(&looped), &GltfOptions::default()));
    let n = looped.frames() - 1;
    assert_eq!(n, 90);
    assert!(!rb.rotation.is_empty());
    // Pose at the last key equals the first within 1e-5.
    // Rotations compared by components (q and −q are the same rotation): f32 `acos` in
    // `angle_between` cannot resolve angles this small.
    let qdist = |a: Quat, b: Quat| (a - b).length().min((a + b).length());
    for (node, keys) in &rb.rotation {
        let d = qdist(keys[n], keys[0]);
        assert!(d <= 1e-5, "node {node}: last rotation key {d} from the first");
    }
    for (node, keys) in &rb.translation {
        assert!(keys[n].distance(keys[0]) <= 1e-5 * t.height(), "node {node}");
    }
    // Angular velocity (vector, rad/s) between consecutive keys.
    let omega = |a: Quat, b: Quat| {
        let d = b * a.conjugate();
        let d = if d.w < 0.0 { -d } else { d };
        let (axis, angle) = d.to_axis_angle();
        axis * angle * fps
    };
    // The bound: across the seam (key n−1 → n, then on from key 0 → 1) the angular velocity
    // changes by no more than 1.5 × the largest change between consecutive keys inside the
    // clip, + 0.01 rad/s.
    let mut checked = 0;
    for (node, keys) in &rb.rotation {
        let w: Vec<Vec3> = (0..n).map(|k| omega(keys[k], keys[k + 1])).collect();
        let inside = w.windows(2).map(|p| (p[1] - p[0]).length()).fold(0.0, f32::max);
        let seam = (w[0] - w[n - 1]).length();
        assert!(seam <= 1.5 * inside + 0.01, "node {node}: seam changes ω by {seam} rad/s, inside at most {inside}");
        checked += 1;
    }
    assert!(checked > 100);
    // Without the cross-fade the ends do not meet: the test above would see a jump.
    let (ra, _) = sylva_core::export::bake::local_transforms(&t, &cut.joints[0], &cut.acc[0]);
    let (rb_, _) = sylva_core::export::bake::local_transforms(&t, &cut.joints[n], &cut.acc[n]);
    let gap = ra.iter().zip(&rb_).map(|(a, b)| qdist(*a, *b)).fold(0.0, f32::max);
    assert!(gap > 1e-3, "the wind must move the palm for the loop test to mean anything ({gap} rad)");
}

// ---------------------------------------------------------------------------------------
// What the attributes mean.

#[test]
fn hierarchy_attributes_tangents_and_static_export_mean_what_the_docs_say() {
    let t = tree("palm");
    let doc = build_gltf(&t, None, &GltfOptions::default()).unwrap();
    assert!(doc.root.skins.is_empty() && doc.root.animations.is_empty(), "a static export has no skin or animation");
    let mut bytes = Vec::new();
    doc.write_glb(&mut bytes).unwrap();
    let rb = read_back(&bytes);
    let layout = MeshLayout::new(&t, MeshParams::default()).unwrap();
    let bark = layout.tube_vertex_count();
    assert_eq!(rb.positions.len(), bark + layout.leaf_vertex_count());
    let pivot = &rb.custom["PIVOT"];
    let axis = &rb.custom["BRANCH_AXIS"];
    let depth = &rb.custom["HIERARCHY_DEPTH"];
    let parent = &rb.custom["PARENT_PIVOT"];
    let phase = &rb.custom["PHASE"];
    let v3 = |x: &Vec<f32>| Vec3::new(x[0], x[1], x[2]);
    for (k, r) in layout.rings.iter().enumerate() {
        let i = k * (layout.params.sides as usize + 1);
        let stem = t.segments.stem[r.segment as usize] as usize;
        let base = t.segments.start[t.stems.first_segment[stem] as usize];
        assert_eq!(v3(&pivot[i]), base, "bark pivot is the stem's base");
        assert_eq!(depth[i][0], t.stems.level[stem] as f32);
        assert!((v3(&axis[i]).length() - 1.0).abs() < 1e-5);
        // A bark vertex lies within its stem's length (and radius) of its pivot, along the axis.
        let along = (rb.positions[i] - base).dot(v3(&axis[i]));
        assert!(along > -0.5 && along <= t.stems.length[stem] * 1.05 + 0.5, "along {along}");
        let ps = t.stems.parent[stem];
        let expect =
            if ps == sylva_core::NONE { base } else { t.segments.start[t.stems.first_segment[ps as usize] as usize] };
        assert_eq!(v3(&parent[i]), expect);
        assert!((0.0..1.0).contains(&phase[i][0]));
    }
    let leaf_stride = layout.params.leaf_sides as usize + 1;
    for (l, leaf) in layout.leaves.iter().enumerate() {
        let i = bark + l * leaf_stride;
        assert_eq!(v3(&pivot[i]), Vec3::from_array(leaf.position), "a leaf's pivot is its attachment point");
        let stem = t.segments.stem[leaf.segment as usize] as usize;
        assert_eq!(depth[i][0], t.stems.level[stem] as f32 + 1.0);
        // Every vertex of a leaf shares its element data.
        assert_eq!(phase[i], phase[i + leaf_stride - 1]);
    }
    // Tangents: unit, orthogonal to the normal, handedness ±1.
    let m = layout.mesh(&t, &sylva_core::pose::Pose::rest(&t));
    for (verts, idx) in [(&m.tubes, &layout.tube_indices), (&m.leaves, &layout.leaf_indices)] {
        for (v, tg) in verts.iter().zip(tangents(verts, idx)) {
            let tv = Vec3::new(tg[0], tg[1], tg[2]);
            assert!((tv.length() - 1.0).abs() < 1e-5);
            assert!(tv.dot(Vec3::from_array(v.normal)).abs() < 1e-4);
            assert!(tg[3] == 1.0 || tg[3] == -1.0);
        }
    }
}

#[test]
fn levels_of_detail_shrink_and_keep_the_leaf_area() {
    let t = tree("quaking_aspen");
    let doc = build_gltf(&t, None, &GltfOptions::default()).unwrap();
    let l = &doc.report.lods;
    assert_eq!(l.len(), DEFAULT_LODS.len());
    assert_eq!(doc.root.meshes.len(), 3);
    assert!(l[0].triangles > 2 * l[1].triangles && l[1].triangles > 2 * l[2].triangles, "{l:?}");
    assert!(l.windows(2).all(|w| w[0].bytes > w[1].bytes));
    let area = |keep: f32| {
        let mut layout = MeshLayout::new(&t, MeshParams::default()).unwrap();
        layout.thin_leaves(keep, t.seed).unwrap();
        (layout.leaves.len(), layout.leaves.iter().map(|x| x.width * x.length).sum::<f32>())
    };
    let (n_all, a_all) = area(1.0);
    for keep in [0.5, 0.25] {
        let (n, a) = area(keep);
        let frac = n as f32 / n_all as f32;
        assert!((frac - keep).abs() < 0.03, "kept {frac}, asked {keep}");
        assert!((a / a_all - 1.0).abs() < 0.05, "leaf area changed by {}", a / a_all - 1.0);
    }
    assert_eq!(l[1].leaves, area(0.5).0);
}

#[test]
fn the_same_inputs_give_the_same_bytes() {
    let t = tree("palm");
    let c1 = clip(&t, "zioma", 1.5, true);
    let c2 = clip(&t, "zioma", 1.5, true);
    assert_eq!(glb(&t, Some(&c1), &GltfOptions::default()), glb(&t, Some(&c2), &GltfOptions::default()));
}

// ---------------------------------------------------------------------------------------
// Bad inputs.

#[test]
fn bad_inputs_are_refused_by_name_and_leave_no_file() {
    let t = tree("palm");
    let wind = gusty();
    let bad = |p: BakeParams| bake(animator(&t, "zioma").as_mut(), &wind, &p, &mut |_, _| {}).unwrap_err();
    let field = |e: BakeError| match e {
        BakeError::Param { field, .. } => field,
        e => panic!("expected a parameter error, got {e}"),
    };
    assert_eq!(field(bad(BakeParams { fps: 0.0, ..Default::default() })), "fps");
    assert_eq!(field(bad(BakeParams { seconds: -1.0, ..Default::default() })), "seconds");
    assert_eq!(field(bad(BakeParams { seconds: f32::NAN, ..Default::default() })), "seconds");
    assert_eq!(field(bad(BakeParams { looped: true, blend: 0.0, ..Default::default() })), "blend");
    assert_eq!(field(bad(BakeParams { looped: true, blend: 9.0, ..Default::default() })), "blend");
    assert!(matches!(
        bad(BakeParams { seconds: 3600.0, fps: 240.0, sim_rate: 240.0, ..Default::default() }),
        BakeError::TooLarge { .. }
    ));

    let c = clip(&t, "zioma", 0.2, false);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tree.glb");
    let e = write_gltf(&t, Some(&c), &GltfOptions { max_joints: Some(100), ..Default::default() }, &path).unwrap_err();
    assert!(matches!(e, GltfError::TooManyJoints { joints: 309, limit: 100, .. }), "{e}");
    assert!(e.to_string().contains("joints per stem"), "{e}");
    // Per stem it fits.
    let opts = GltfOptions { joints: JointMode::Stem, max_joints: Some(100), ..Default::default() };
    assert_eq!(write_gltf(&t, Some(&c), &opts, &path).unwrap().joints, t.stems.len());
    std::fs::remove_file(&path).unwrap();
    // Unwritable: a directory that does not exist.
    let missing = dir.path().join("no/such/dir/tree.glb");
    let e = write_gltf(&t, Some(&c), &GltfOptions::default(), &missing).unwrap_err();
    assert!(matches!(e, GltfError::Io { .. }) && e.to_string().contains("no/such/dir"), "{e}");
    let e = write_gltf(&t, None, &GltfOptions::default(), &dir.path().join("tree.fbx")).unwrap_err();
    assert!(e.to_string().contains(".glb or .gltf"), "{e}");
    let e = build_gltf(&t, None, &GltfOptions { lods: vec![], ..Default::default() }).unwrap_err();
    assert!(e.to_string().contains("lods"), "{e}");
    let lod = Lod { sides: 2, ..DEFAULT_LODS[0] };
    let e = build_gltf(&t, None, &GltfOptions { lods: vec![lod], ..Default::default() }).unwrap_err();
    assert!(e.to_string().contains("sides"), "{e}");
    let other = tree("quaking_aspen");
    assert!(matches!(build_gltf(&other, Some(&c), &GltfOptions::default()), Err(GltfError::ClipMismatch { .. })));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "nothing left behind");
}

/// The leaf material's texture follows the tree's leaf shape (Weber–Penn `LeafShape`): read
/// back from the file, its alpha is the outline `LeafShape::contains` draws, it clamps to its
/// clear border, and the leaves' texture coordinates stay within a few hundredths of it.
#[test]
fn the_leaf_texture_follows_the_tree_s_leaf_shape() {
    use sylva_core::model::LeafShape;
    let base = tree("quaking_aspen");
    let mut coverage = Vec::new();
    for shape in [LeafShape::Disc, LeafShape::Star, LeafShape::Needle] {
        let t = Tree { leaf_shape: shape, ..base.clone() };
        let bytes = glb(&t, None, &GltfOptions::default());
        let g = gltf::Gltf::from_slice(&bytes).unwrap();
        let blob = g.blob.clone().unwrap();
        let leaf = g.materials().find(|m| m.name().is_some_and(|n| n.contains("leaf"))).expect("a leaf material");
        let info = leaf.pbr_metallic_roughness().base_color_texture().expect("a leaf texture");
        let tex = info.texture();
        assert_eq!(tex.sampler().wrap_s(), gltf::texture::WrappingMode::ClampToEdge);
        let gltf::image::Source::View { view, .. } = tex.source().source() else { panic!("embedded") };
        let png = &blob[view.offset()..view.offset() + view.length()];
        let img = image::load_from_memory(png).unwrap().to_rgba8();
        let n = img.width() as f32;
        let (mut agree, mut total, mut opaque) = (0usize, 0usize, 0usize);
        for (x, y, p) in img.enumerate_pixels() {
            let (u, v) = ((x as f32 + 0.5) / n, (y as f32 + 0.5) / n);
            let inside = shape.contains(u, v);
            let near = [(-1.5, 0.0), (1.5, 0.0), (0.0, -1.5), (0.0, 1.5)]
                .iter()
                .any(|(du, dv)| shape.contains(u + du / n, v + dv / n) != inside);
            opaque += (p[3] > 127) as usize;
            if !near && x > 0 && y > 0 && x + 1 < img.width() && y + 1 < img.height() {
                total += 1;
                agree += ((p[3] == 255) == inside) as usize;
            }
        }
        assert_eq!(agree, total, "{}: the exported alpha is not the outline", shape.name());
        coverage.push(opaque);
        // The leaves' TEXCOORD_0 reach at most 0.15 past the square.
        let leaf_prim = g.meshes().next().unwrap().primitives().find(|p| p.material().index() == leaf.index()).unwrap();
        let buf = |b: gltf::Buffer<'_>| -> Option<&[u8]> { (b.index() == 0).then_some(&blob[..]) };
        let uvs: Vec<[f32; 2]> = leaf_prim.reader(buf).read_tex_coords(0).unwrap().into_f32().collect();
        assert!(uvs.iter().flatten().all(|c| (-0.15..=1.15).contains(c)), "{}", shape.name());
    }
    // Distinct textures: the disc, the star and the needle cover different areas.
    assert!(coverage[0] != coverage[1] && coverage[2] * 4 < coverage[0], "{coverage:?}");
}
