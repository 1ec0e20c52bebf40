//! glTF export: files pass the Khronos validator; the skin and animation, read back with
//! the `gltf` crate and applied at frame k, reproduce Sylva's own skinned mesh for frame k
//! (leaves: their attachments exactly, their turn by their leaf joint's);
//! looping clips are seamless; hierarchy attributes, tangents and LODs mean what they say;
//! bad inputs are refused without leaving a file.

use glam::{Mat3, Mat4, Quat, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::export::gltf::{GAME_BUDGET, tangents};
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
    // Every leaf's rotation kept, for the tests that compare leaves one by one.
    let p = BakeParams { seconds, fps: 30.0, looped, blend: 0.5, preroll: 0.5, per_leaf: true, ..Default::default() };
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
    // The game target and its options: quantised, float, with the custom attributes, one
    // level per file (`--lod-files`), static.
    let game = GltfOptions::game(&palm, &GAME_BUDGET);
    write("palm_game_loop.glb", &palm, Some(&looped), game.clone());
    write("palm_game_float.gltf", &palm, Some(&hsm), GltfOptions { quantize: false, ..game.clone() });
    write("palm_game_custom.glb", &palm, Some(&hsm), GltfOptions { custom_attributes: true, ..game.clone() });
    write("palm_game_lod1.glb", &palm, Some(&looped), GltfOptions { lods: vec![game.lods[1]], ..game.clone() });
    write("palm_game_static.glb", &palm, None, game.clone());
    write("palm_game_meshopt.glb", &palm, Some(&looped), GltfOptions { meshopt: true, ..game.clone() });
    write("palm_game_meshopt.gltf", &palm, None, GltfOptions { meshopt: true, ..game.clone() });
    let aspen = tree("quaking_aspen");
    let aspen_clip = clip(&aspen, "skjermo", 0.5, false);
    write("aspen_game.glb", &aspen, Some(&aspen_clip), GltfOptions::game(&aspen, &GAME_BUDGET));
    let zioma = clip(&willow, "zioma", 0.5, false);
    write(
        "lsystem_zioma.gltf",
        &willow,
        Some(&zioma),
        GltfOptions { lods: vec![Lod::film(3, 1, 3, 0.1)], ..Default::default() },
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
// three.js in headless Chromium.

/// `tools/web/check.js`, or `None` (with the reason printed) outside CI when node, the page's
/// npm packages or Chromium are missing. In CI (`CI=true`) a missing piece fails the test.
fn browser_check() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tools/web");
    let node = std::process::Command::new("node").arg("--version").output().is_ok_and(|o| o.status.success());
    let chromium = std::env::var_os("CHROMIUM").map_or_else(|| PathBuf::from("/usr/bin/chromium"), PathBuf::from);
    let why = if !node {
        "node is not installed"
    } else if !dir.join("node_modules/three/package.json").exists()
        || !dir.join("node_modules/puppeteer-core/package.json").exists()
    {
        "the page's packages are not installed (npm ci --prefix tools/web)"
    } else if !chromium.exists() {
        "Chromium is not installed (apt-get install chromium, or set CHROMIUM)"
    } else {
        return Some(dir.join("check.js"));
    };
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("{why}; CI must run the browser check");
    }
    eprintln!("skipping the three.js check in Chromium: {why}");
    None
}

#[test]
fn a_three_js_page_in_headless_chromium_plays_the_clip_with_its_leaves_turning() {
    let t = tree("quaking_aspen");
    let c = clip(&t, "zioma", 1.0, false);
    let opts = GltfOptions { lods: vec![Lod::film(6, 2, 6, 0.5)], ..Default::default() };
    let doc = build_gltf(&t, Some(&c), &opts).unwrap();
    let mut bytes = Vec::new();
    doc.write_glb(&mut bytes).unwrap();
    let Some(script) = browser_check() else { return };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("aspen.glb");
    std::fs::write(&path, &bytes).unwrap();
    let out = std::process::Command::new("node").arg(&script).arg(&path).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let r: serde_json::Value = serde_json::from_str(stdout.trim())
        .unwrap_or_else(|e| panic!("{e}: {stdout}\n{}", String::from_utf8_lossy(&out.stderr)));
    assert!(out.status.success() && r["errors"].as_array().is_some_and(Vec::is_empty), "the page logged errors: {r}");
    assert_eq!(r["ready"], true, "{r}");
    assert_eq!(r["visibleLods"], 1);
    assert_eq!(r["leafJoints"].as_u64(), Some(doc.report.leaf_joints as u64), "three.js finds every leaf joint");
    // Three.js plays the file as the file says: its leaf joints turn as the keys do, and its
    // skinned vertices are the ones read back here.
    let rb = read_back(&bytes);
    let bark = rb.positions.len() - {
        let layout =
            MeshLayout::new(&t, MeshParams { sides: 6, samples: 2, leaf_sides: 6, ..Default::default() }).unwrap();
        let mut layout = layout;
        layout.thin_leaves(0.5, t.seed).unwrap();
        layout.leaf_vertex_count()
    };
    let leaf_nodes: Vec<usize> =
        (0..rb.rest.len()).filter(|n| rb.rotation.contains_key(n) && rb.names[*n].starts_with("leaves_")).collect();
    let probes = r["probes"].as_array().unwrap();
    assert_eq!(probes.len(), 3);
    let tol = 1e-4 * t.height();
    let mut turned = 0.0f64;
    for p in probes {
        let time = p["t"].as_f64().unwrap();
        let k = (time * c.fps as f64).round() as usize;
        assert!((k as f64 / c.fps as f64 - time).abs() < 1e-6, "probes fall on keys");
        let keys: Vec<f64> =
            leaf_nodes.iter().map(|n| rb.rotation[n][k].angle_between(Quat::IDENTITY) as f64).collect();
        let file_rms = (keys.iter().map(|a| a * a).sum::<f64>() / doc.report.leaf_joints as f64).sqrt().to_degrees();
        let browser_rms = p["leafTurnRmsDeg"].as_f64().unwrap();
        assert!(
            (browser_rms - file_rms).abs() < 0.05,
            "t = {time}: three.js turns leaves {browser_rms}° RMS, the keys {file_rms}°"
        );
        turned = turned.max(browser_rms);
        let skinned = rb.skinned(k);
        let vertices = p["vertices"].as_array().unwrap();
        let n = rb.positions.len() - bark;
        for (j, v) in vertices.iter().enumerate() {
            let i = bark + ((j as f64 + 0.5) * n as f64 / vertices.len() as f64) as usize;
            let v =
                Vec3::new(v[0].as_f64().unwrap() as f32, v[1].as_f64().unwrap() as f32, v[2].as_f64().unwrap() as f32);
            assert!(
                v.distance(skinned[i]) <= tol,
                "t = {time}: three.js puts leaf vertex {i} {} m away",
                v.distance(skinned[i])
            );
        }
    }
    assert!(turned >= 5.0, "leaves turn only {turned}° RMS relative to their branch in the browser");
    let changed = r["pixelsChanged"].as_f64().unwrap();
    assert!(changed > 0.01, "the render hardly changes over the clip ({changed} of the pixels)");
    println!(
        "three.js in Chromium ({}): leaves turn up to {turned:.1}° RMS relative to their branch; {:.1} % of the pixels change",
        r["renderer"],
        100.0 * changed
    );
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
    names: Vec<String>,
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
    let names = g.nodes().map(|n| n.name().unwrap_or_default().to_string()).collect();
    ReadBack { positions, joints, weights, skin_nodes, ibm, parent, rest, rotation, translation, custom, names }
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

/// Sylva's own skinned mesh (LOD0 = the default mesh parameters) for frame k, leaves rigid
/// on their segments, and whether each vertex is bark or a leaf's attachment (where the
/// file must agree exactly; the rest of a leaf also turns by its leaf joint).
fn sylva_skinned(t: &Tree, c: &Clip, k: usize) -> (Vec<Vec3>, Vec<bool>) {
    let layout = MeshLayout::new(t, MeshParams::default()).unwrap();
    let skin = SkinLayout::new(&layout);
    let m = skin.skin(&c.joints[k], &c.acc[k], 1);
    let rigid: Vec<bool> = m.tubes.iter().map(|_| true).chain(layout.leaf_uv().iter().map(|uv| uv[1] <= 0.0)).collect();
    assert!(rigid.iter().filter(|r| **r).count() >= m.tubes.len() + layout.leaves.len(), "a base per leaf");
    (m.tubes.iter().chain(&m.leaves).map(|v| Vec3::from_array(v.position)).collect(), rigid)
}

fn check_frames(t: &Tree, c: &Clip, what: &str) {
    let rb = read_back(&glb(t, Some(c), &GltfOptions::default()));
    let tol = 1e-4 * t.height();
    for k in [0, c.frames() / 3, c.frames() - 1] {
        let (ours, rigid) = sylva_skinned(t, c, k);
        let theirs = rb.skinned(k);
        assert_eq!(ours.len(), theirs.len(), "{what}");
        let (worst, at) = ours
            .iter()
            .zip(&theirs)
            .enumerate()
            .filter(|(i, _)| rigid[*i])
            .map(|(i, (a, b))| (a.distance(*b), i))
            .fold((0.0f32, 0), |m, x| if x.0 > m.0 { x } else { m });
        assert!(worst <= tol, "{what}, frame {k}: vertex {at} off by {worst} m (tolerance {tol} m)");
    }
    // The file holds the motion, not the rest pose: frame k moved away from rest.
    let rest = rb.skinned(0);
    let moved = sylva_skinned(t, c, c.frames() - 1)
        .0
        .iter()
        .zip(&rb.positions)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f32::max);
    println!("{what}: the last frame moves a vertex {moved} m (height {} m)", t.height());
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
    let mut c = clip(&t, "hsm", 2.0, false);
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

/// A leaf's frame from three of its vertices: base, tip, and the widest point on +u.
fn leaf_frame(base: Vec3, tip: Vec3, side: Vec3) -> Quat {
    let y = (tip - base).normalize();
    let x = (side - base).reject_from_normalized(y).normalize();
    Quat::from_mat3(&Mat3::from_cols(x, y, x.cross(y)))
}

#[test]
fn leaf_joints_turn_leaves_relative_to_their_segment_in_the_read_back_clip() {
    let t = tree("quaking_aspen");
    let c = clip(&t, "zioma", 1.0, false);
    let opts = GltfOptions { lods: vec![DEFAULT_LODS[0]], ..Default::default() };
    let doc = build_gltf(&t, Some(&c), &opts).unwrap();
    let bearing: std::collections::HashSet<u32> = t.leaves.segment.iter().copied().collect();
    assert_eq!(doc.report.leaf_joints, bearing.len(), "one leaf joint per leaf-bearing segment");
    assert_eq!(doc.report.joints, t.segments.len() + bearing.len());
    let mut bytes = Vec::new();
    doc.write_glb(&mut bytes).unwrap();
    let rb = read_back(&bytes);
    let layout = MeshLayout::new(&t, MeshParams::default()).unwrap();
    let skin = SkinLayout::new(&layout);
    let bark = layout.tube_vertex_count();
    let stride = layout.params.leaf_sides as usize + 1;
    // Per leaf: its base (least v), tip (most v) and widest point on +u, from the rest mesh.
    let leaf_uv = layout.leaf_uv();
    let pick = |l: usize, key: &dyn Fn(&sylva_core::mesh::Uv) -> f32| {
        (l * stride..(l + 1) * stride).max_by(|&a, &b| key(&leaf_uv[a]).total_cmp(&key(&leaf_uv[b]))).unwrap()
    };
    let corners: Vec<[usize; 3]> =
        (0..layout.leaves.len()).map(|l| [pick(l, &|v| -v[1]), pick(l, &|v| v[1]), pick(l, &|v| v[0])]).collect();
    // The per-leaf flutter attribute: swing and twist frequencies above 0, at most 12 Hz.
    let flutter = &rb.custom["LEAF_FLUTTER"];
    assert_eq!(flutter.len(), layout.leaf_vertex_count());
    assert!(flutter.iter().all(|f| f[0] > 0.5 && f[0] <= 12.0 + 1e-3 && f[1] > 0.5 && f[1] <= 12.0 + 1e-3));
    let tol = 1e-4 * t.height();
    let rms = |x: &[f32]| (x.iter().map(|a| a * a).sum::<f32>() / x.len() as f32).sqrt().to_degrees();
    let (mut file, mut own, mut lost) = (Vec::new(), Vec::new(), Vec::new());
    for k in [c.frames() / 2, c.frames() - 1] {
        let rigid = skin.skin(&c.joints[k], &c.acc[k], 1).leaves;
        let turned = skin.skin_with_leaves(&c.joints[k], &c.acc[k], &c.leaves[k], 1).leaves;
        let theirs = &rb.skinned(k)[bark..];
        let p = |m: &[sylva_core::mesh::RawVertex], i: usize| Vec3::from_array(m[i].position);
        for [b, tip, side] in &corners {
            // The attachment stays on its twig.
            let off = theirs[*b].distance(p(&rigid, *b));
            assert!(off <= tol, "a leaf's attachment left its twig by {off} m");
            let q_rigid = leaf_frame(p(&rigid, *b), p(&rigid, *tip), p(&rigid, *side));
            let q_own = leaf_frame(p(&turned, *b), p(&turned, *tip), p(&turned, *side));
            let q_file = leaf_frame(theirs[*b], theirs[*tip], theirs[*side]);
            file.push(q_file.angle_between(q_rigid));
            own.push(q_own.angle_between(q_rigid));
            lost.push(q_file.angle_between(q_own));
        }
    }
    let (file, own, lost) = (rms(&file), rms(&own), rms(&lost));
    println!(
        "aspen, zioma, gusty: leaves turn {file:.1}° RMS relative to their segment in the file, {own:.1}° in Sylva; \
         {lost:.1}° RMS between the two (the per-leaf flutter left to an engine shader)"
    );
    assert!(file >= 5.0, "leaves turn only {file}° RMS relative to their segment in the file");
    // The leaf joints carry the part of the leaves' motion their group shares: the file's
    // leaves are nearer Sylva's own than rigid leaves are.
    assert!(lost < own, "the leaf joints turn leaves away from Sylva's own ({lost}° against {own}°)");
}

#[test]
fn joints_per_stem_move_each_stem_rigidly_about_its_base() {
    let t = tree("palm");
    let c = clip(&t, "akagi", 0.5, false);
    let opts = GltfOptions { joints: JointMode::Stem, ..Default::default() };
    let rb = read_back(&glb(&t, Some(&c), &opts));
    let bearing: std::collections::HashSet<u32> =
        t.leaves.segment.iter().map(|&s| t.segments.stem[s as usize]).collect();
    assert_eq!(rb.skin_nodes.len(), t.stems.len() + bearing.len(), "a leaf joint per leaf-bearing stem");
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
    // Named so that Godot's importer loops it (a name ending in `loop`); a cut clip is not.
    let name = |c: &Clip| build_gltf(&t, Some(c), &GltfOptions::default()).unwrap().root.animations[0].name.clone();
    assert_eq!(name(&looped).as_deref(), Some("wind_loop"));
    assert_eq!(name(&cut).as_deref(), Some("wind"));
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
    let (tube_uv, leaf_uv) = (layout.tube_uv(), layout.leaf_uv());
    for (verts, uv, idx) in [(&m.tubes, &tube_uv, &layout.tube_indices), (&m.leaves, &leaf_uv, &layout.leaf_indices)] {
        for (v, tg) in verts.iter().zip(tangents(verts, uv, idx)) {
            let tv = Vec3::new(tg[0], tg[1], tg[2]);
            assert!((tv.length() - 1.0).abs() < 1e-5);
            assert!(tv.dot(v.normal()).abs() < 1e-4);
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
    assert!(matches!(e, GltfError::TooManyJoints { joints: 310.., limit: 100, .. }), "{e}");
    assert!(e.to_string().contains("joints per stem, or no leaf joints"), "{e}");
    let opts = GltfOptions { max_joints: Some(309), leaf_joints: false, ..Default::default() };
    assert_eq!(write_gltf(&t, Some(&c), &opts, &path).unwrap().joints, 309, "one per segment, no leaf joints");
    // Per stem it fits.
    let opts = GltfOptions { joints: JointMode::Stem, max_joints: Some(100), ..Default::default() };
    let r = write_gltf(&t, Some(&c), &opts, &path).unwrap();
    assert_eq!(r.joints, t.stems.len() + r.leaf_joints);
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
/// Runs `tools/web/check.js` on `bytes` with `args`; its JSON report.
fn check_in_browser(script: &Path, bytes: &[u8], args: &[&str]) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tree.glb");
    std::fs::write(&path, bytes).unwrap();
    let out = std::process::Command::new("node").arg(script).arg(&path).args(args).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let r: serde_json::Value = serde_json::from_str(stdout.trim())
        .unwrap_or_else(|e| panic!("{e}: {stdout}\n{}", String::from_utf8_lossy(&out.stderr)));
    assert!(out.status.success() && r["errors"].as_array().is_some_and(Vec::is_empty), "the page logged errors: {r}");
    assert_eq!(r["ready"], true, "{r}");
    r
}

#[test]
fn the_page_s_wind_shader_sways_a_static_game_export_one_lod_drawn_and_matches_its_golden_image() {
    let t = SpeciesSource::resolve("quaking_aspen").unwrap().generate(1, &Default::default(), None).unwrap();
    let game = GltfOptions::game(&t, &GAME_BUDGET);
    let static_glb = glb(&t, None, &game);
    let c = clip(&t, "zioma", 1.0, false);
    let skinned_glb = glb(&t, Some(&c), &game);
    let Some(script) = browser_check() else { return };
    let dir = tempfile::tempdir().unwrap();
    let shot = dir.path().join("wind.png");
    let shot_arg = shot.to_str().unwrap();
    // The static export under the wind shader: no skeleton, one draw per material of LOD0
    // (the coarser levels, loaded from `MSFT_lod`, stay hidden), pixels that change with
    // time and none with the wind off.
    let r = check_in_browser(&script, &static_glb, &["--size", "320", "--screenshot", shot_arg]);
    assert_eq!(
        (r["mode"].as_str(), r["lods"].as_u64(), r["visibleLods"].as_u64()),
        (Some("wind"), Some(3), Some(1)),
        "{r}"
    );
    assert_eq!(r["windMeshes"], 2, "bark and leaf cards take the wind shader: {r}");
    for p in r["probes"].as_array().unwrap() {
        assert_eq!(p["drawCalls"], 2, "one draw per material of one level: {r}");
    }
    let (moving, still) = (r["pixelsChanged"].as_f64().unwrap(), r["stillPixelsChanged"].as_f64().unwrap());
    assert!(moving > 0.02, "the wind shader hardly moves the tree ({moving} of the pixels change)");
    assert_eq!(still, 0.0, "with the wind off the picture must not change");
    // The skinned game export plays its clip in the same page.
    let r = check_in_browser(&script, &skinned_glb, &["--size", "320"]);
    assert_eq!((r["mode"].as_str(), r["visibleLods"].as_u64()), (Some("clip"), Some(1)), "{r}");
    assert!(r["probes"].as_array().unwrap().iter().all(|p| p["drawCalls"] == 2), "{r}");
    let clip_moving = r["pixelsChanged"].as_f64().unwrap();
    assert!(clip_moving > 0.02, "the clip hardly moves the tree ({clip_moving} of the pixels change)");
    // The same, compressed with `EXT_meshopt_compression`: three.js decodes it and plays it alike.
    let packed = glb(&t, Some(&c), &GltfOptions { meshopt: true, ..game.clone() });
    let m = check_in_browser(&script, &packed, &["--size", "320"]);
    assert_eq!((m["visibleLods"].as_u64(), m["leafJoints"].as_u64()), (Some(1), r["leafJoints"].as_u64()), "{m}");
    assert!(m["probes"].as_array().unwrap().iter().all(|p| p["drawCalls"] == 2), "{m}");
    assert!((m["pixelsChanged"].as_f64().unwrap() - clip_moving).abs() < 1e-3, "meshopt changed the pictures: {m}");
    println!(
        "aspen, game, 320 px: the wind shader changes {moving:.3} of the pixels over 2 s, the clip {clip_moving:.3} over 0.67 s"
    );
    // The wind shader's first frame against its golden image (SwiftShader renders the same
    // pixels run to run; the tolerance allows for another Chromium's rasteriser).
    let golden = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/web_wind_aspen.png");
    let got = image::open(&shot).unwrap().to_rgb8();
    if std::env::var("SYLVA_BLESS").is_ok_and(|v| v == "1") {
        got.save(&golden).unwrap();
        return;
    }
    let want = image::open(&golden)
        .unwrap_or_else(|e| panic!("{}: {e} (SYLVA_BLESS=1 creates it)", golden.display()))
        .to_rgb8();
    assert_eq!(want.dimensions(), got.dimensions());
    let diff: Vec<i32> =
        got.pixels().zip(want.pixels()).map(|(a, b)| (0..3).map(|k| (a[k] as i32 - b[k] as i32).abs()).sum()).collect();
    let mean = diff.iter().sum::<i32>() as f64 / (3 * diff.len()) as f64;
    let share = diff.iter().filter(|&&d| d > 48).count() as f64 / diff.len() as f64;
    println!(
        "wind shader vs golden: mean difference {mean:.2} levels, {:.2} % of pixels differ by more than 48",
        100.0 * share
    );
    if mean > 3.0 || share > 0.02 {
        let actual = golden.with_file_name("web_wind_aspen.actual.png");
        got.save(&actual).unwrap();
        panic!(
            "the wind shader's frame differs from its golden image (mean {mean:.2}, {share:.4} of pixels); wrote {}",
            actual.display()
        );
    }
}

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
