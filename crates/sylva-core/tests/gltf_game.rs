//! The game target: every shipped preset within the budget (joints, triangles per level,
//! bytes of a 10 s loop), printed; the quantised skin and the reduced keys read back within
//! the error they state; only the finest level in the scene with `MSFT_lod` naming the rest;
//! the hierarchy packed in `TEXCOORD_1…3` decoding to the custom attributes; leaf cards
//! carrying the crown's leaf area.

use glam::{Mat4, Quat, Vec3};
use std::collections::HashMap;
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::export::gltf::{
    CARD_TRIANGLES, GAME_BUDGET, KEY_TOLERANCE_DEG, PHASE_MAX, bark_triangles, octahedral_decode,
};
use sylva_core::export::{BakeParams, Clip, GltfOptions, bake, build_gltf};
use sylva_core::methods::{MethodOptions, zioma};
use sylva_core::species::{PRESETS, SpeciesSource};
use sylva_core::wind::WindScene;

fn tree(name: &str) -> Tree {
    SpeciesSource::resolve(name).unwrap().generate(1, &Default::default(), None).unwrap()
}

/// A Zioma clip of `t` in gusty wind (Zioma is the exporter's default method).
fn clip(t: &Tree, seconds: f32, looped: bool) -> Clip {
    let mut anim = zioma::animator(Arc::new(t.clone()), &MethodOptions::seeded(1)).unwrap();
    let p = BakeParams { seconds, fps: 30.0, looped, blend: 1.0, preroll: 1.0, ..Default::default() };
    bake(anim.as_mut(), &WindScene::resolve("gusty").unwrap(), &p, &mut |_, _| {}).unwrap()
}

/// The angle between two rotations, degrees: `2 asin |(a⁻¹ b).xyz|`, exact for small angles
/// (where f32 `acos` of the dot product is not).
fn turn_deg(a: Quat, b: Quat) -> f32 {
    let d = a.conjugate() * b;
    (2.0 * d.xyz().length().min(1.0).asin()).to_degrees()
}

/// The angle between two vectors, rad: `atan2(|a × b|, a · b)`, exact for small angles.
fn angle(a: Vec3, b: Vec3) -> f32 {
    a.cross(b).length().atan2(a.dot(b))
}

fn glb(t: &Tree, c: Option<&Clip>, opts: &GltfOptions) -> Vec<u8> {
    let doc = build_gltf(t, c, opts).unwrap();
    let mut out = Vec::new();
    doc.write_glb(&mut out).unwrap();
    out
}

/// A file read back: the finest level's vertices and skin, the nodes and the clip's
/// channels (their own key times each).
struct File {
    json: serde_json::Value,
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    joints: Vec<[u16; 4]>,
    weights: Vec<[f32; 4]>,
    texcoords: [Vec<[f32; 2]>; 4],
    custom: HashMap<String, Vec<Vec<f32>>>,
    skin_nodes: Vec<usize>,
    ibm: Vec<Mat4>,
    parent: Vec<Option<usize>>,
    rest: Vec<(Vec3, Quat)>,
    rotation: HashMap<usize, (Vec<f32>, Vec<Quat>)>,
}

/// `v` as an f32 vector: normalised integers mapped to −1…1 / 0…1 by glTF's rules.
fn component(bytes: &[u8], ty: u64, normalized: bool) -> f32 {
    let s = |x: f32, max: f32| if normalized { (x / max).max(-1.0) } else { x };
    match ty {
        5120 => s(bytes[0] as i8 as f32, 127.0),
        5121 => s(bytes[0] as f32, 255.0),
        5122 => s(i16::from_le_bytes([bytes[0], bytes[1]]) as f32, 32767.0),
        5123 => s(u16::from_le_bytes([bytes[0], bytes[1]]) as f32, 65535.0),
        5126 => f32::from_le_bytes(bytes[..4].try_into().unwrap()),
        _ => panic!("component type {ty}"),
    }
}

fn read(bytes: &[u8]) -> File {
    // `KHR_mesh_quantization` is required in game files; the `gltf` crate does not list it.
    let g = gltf::Gltf::from_slice_without_validation(bytes).unwrap();
    let blob = g.blob.clone().unwrap();
    let json: serde_json::Value = serde_json::from_slice(&gltf::binary::Glb::from_slice(bytes).unwrap().json).unwrap();
    let acc = |i: usize| -> Vec<Vec<f32>> {
        let a = &json["accessors"][i];
        let v = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
        let ty = a["componentType"].as_u64().unwrap();
        let size = match ty {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            _ => 4,
        };
        let n = match a["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            "MAT4" => 16,
            t => panic!("{t}"),
        };
        let stride = v["byteStride"].as_u64().map_or(size * n, |s| s as usize);
        let start = v["byteOffset"].as_u64().unwrap_or(0) as usize + a["byteOffset"].as_u64().unwrap_or(0) as usize;
        let normalized = a["normalized"].as_bool().unwrap_or(false);
        (0..a["count"].as_u64().unwrap() as usize)
            .map(|e| (0..n).map(|c| component(&blob[start + e * stride + c * size..], ty, normalized)).collect())
            .collect()
    };
    let mut f = File {
        json: json.clone(),
        positions: Vec::new(),
        normals: Vec::new(),
        joints: Vec::new(),
        weights: Vec::new(),
        texcoords: Default::default(),
        custom: HashMap::new(),
        skin_nodes: Vec::new(),
        ibm: Vec::new(),
        parent: vec![None; g.nodes().count()],
        rest: Vec::new(),
        rotation: HashMap::new(),
    };
    for p in json["meshes"][0]["primitives"].as_array().unwrap() {
        for (name, index) in p["attributes"].as_object().unwrap() {
            let data = acc(index.as_u64().unwrap() as usize);
            let v3 = |d: &[Vec<f32>]| d.iter().map(|x| Vec3::from_slice(x)).collect::<Vec<_>>();
            match name.as_str() {
                "POSITION" => f.positions.extend(v3(&data)),
                "NORMAL" => f.normals.extend(v3(&data)),
                "JOINTS_0" => f.joints.extend(data.iter().map(|x| std::array::from_fn(|k| x[k] as u16))),
                "WEIGHTS_0" => f.weights.extend(data.iter().map(|x| std::array::from_fn(|k| x[k]))),
                "TANGENT" => {}
                t if t.starts_with("TEXCOORD_") => {
                    let k: usize = t[9..].parse().unwrap();
                    f.texcoords[k].extend(data.iter().map(|x| [x[0], x[1]]));
                }
                t => f.custom.entry(t.trim_start_matches('_').to_string()).or_default().extend(data),
            }
        }
    }
    for n in g.nodes() {
        for c in n.children() {
            f.parent[c.index()] = Some(n.index());
        }
        let (t, r, _) = n.transform().decomposed();
        f.rest.push((Vec3::from_array(t), Quat::from_array(r)));
    }
    if let Some(skin) = json["skins"].get(0) {
        f.skin_nodes = skin["joints"].as_array().unwrap().iter().map(|j| j.as_u64().unwrap() as usize).collect();
        f.ibm = acc(skin["inverseBindMatrices"].as_u64().unwrap() as usize)
            .iter()
            .map(|m| Mat4::from_cols_slice(m))
            .collect();
    }
    if let Some(a) = json["animations"].get(0) {
        for ch in a["channels"].as_array().unwrap() {
            assert_eq!(ch["target"]["path"], "rotation", "the methods' clips need rotations only");
            let s = &a["samplers"][ch["sampler"].as_u64().unwrap() as usize];
            let times = acc(s["input"].as_u64().unwrap() as usize).iter().map(|t| t[0]).collect();
            let q = acc(s["output"].as_u64().unwrap() as usize).iter().map(|q| Quat::from_slice(q)).collect();
            f.rotation.insert(ch["target"]["node"].as_u64().unwrap() as usize, (times, q));
        }
    }
    f
}

impl File {
    /// A node's rotation at time `t`: glTF's linear interpolation (slerp) between keys.
    fn rotation_at(&self, node: usize, t: f32) -> Quat {
        let Some((times, q)) = self.rotation.get(&node) else { return self.rest[node].1 };
        let k = times.partition_point(|&x| x <= t).clamp(1, times.len() - 1);
        let w = ((t - times[k - 1]) / (times[k] - times[k - 1])).clamp(0.0, 1.0);
        q[k - 1].slerp(q[k], w)
    }

    /// glTF skinning at time `t`: Σ wᵢ · world(jointᵢ) · IBMᵢ · p, the vertex's joints'
    /// positions of it alongside.
    fn skinned(&self, t: f32) -> Vec<(Vec3, Vec<Vec3>)> {
        let n = self.rest.len();
        let local: Vec<Mat4> =
            (0..n).map(|i| Mat4::from_rotation_translation(self.rotation_at(i, t), self.rest[i].0)).collect();
        let world: Vec<Mat4> = (0..n)
            .map(|mut i| {
                let mut m = local[i];
                while let Some(p) = self.parent[i] {
                    m = local[p] * m;
                    i = p;
                }
                m
            })
            .collect();
        let joint: Vec<Mat4> = self.skin_nodes.iter().zip(&self.ibm).map(|(&n, ibm)| world[n] * *ibm).collect();
        self.positions
            .iter()
            .zip(self.joints.iter().zip(&self.weights))
            .map(|(p, (j, w))| {
                let each: Vec<Vec3> =
                    (0..4).filter(|&i| w[i] > 0.0).map(|i| joint[j[i] as usize].transform_point3(*p)).collect();
                ((0..4).map(|i| w[i] * joint[j[i] as usize].transform_point3(*p)).sum(), each)
            })
            .collect()
    }
}

#[test]
fn the_game_target_meets_its_budget_for_every_shipped_preset() {
    let b = GAME_BUDGET;
    println!(
        "game budget: {} joints, {:?} triangles per level, {} MiB for a 10 s loop at 30 fps",
        b.joints,
        b.triangles,
        b.bytes >> 20
    );
    println!("{:<18} {:>6} {:>8} {:>8} {:>8} {:>9} {:>6}", "preset", "joints", "LOD0", "LOD1", "LOD2", "MiB", "keys");
    for p in PRESETS {
        let t = tree(p.name);
        let c = clip(&t, 10.0, true);
        let opts = GltfOptions::game(&t, &b);
        let doc = build_gltf(&t, Some(&c), &opts).unwrap();
        let mut bytes = Vec::new();
        doc.write_glb(&mut bytes).unwrap();
        let r = &doc.report;
        let tris: Vec<usize> = r.lods.iter().map(|l| l.triangles).collect();
        println!(
            "{:<18} {:>6} {:>8} {:>8} {:>8} {:>9.2} {:>5.0}%",
            p.name,
            r.joints,
            tris[0],
            tris[1],
            tris[2],
            bytes.len() as f64 / (1 << 20) as f64,
            100.0 * r.keys as f64 / (r.frames * r.channels).max(1) as f64
        );
        assert!(r.joints <= b.joints, "{}: {} joints", p.name, r.joints);
        for (k, (&n, &limit)) in tris.iter().zip(&b.triangles).enumerate() {
            assert!(n <= limit, "{}: LOD{k} has {n} triangles, more than {limit}", p.name);
        }
        assert!(bytes.len() as u64 <= b.bytes, "{}: {} bytes", p.name, bytes.len());
        assert!(r.frames == 301 && r.channels > 0, "{}: a 10 s clip at 30 fps", p.name);
    }
}

#[test]
fn the_quantised_skin_reads_back_within_its_weight_rounding() {
    let t = tree("quaking_aspen");
    let c = clip(&t, 1.0, false);
    let exact = GltfOptions { quantize: false, key_tolerance_deg: 0.0, ..GltfOptions::game(&t, &GAME_BUDGET) };
    let quantised = GltfOptions { quantize: true, ..exact.clone() };
    let (f, q) = (read(&glb(&t, Some(&c), &exact)), read(&glb(&t, Some(&c), &quantised)));
    assert_eq!(f.positions, q.positions, "positions stay f32");
    assert!(q.json["extensionsRequired"].as_array().unwrap().iter().any(|e| e == "KHR_mesh_quantization"));
    // Normals: i8, within half a step of 1/127 per component.
    let worst_n = f.normals.iter().zip(&q.normals).map(|(a, b)| angle(*a, *b)).fold(0.0, f32::max);
    assert!(worst_n < 0.012, "normals turned by {worst_n} rad");
    // Skinning: a weight rounded to 1/255 moves a vertex by at most half a step of the
    // distance between the places its joints take it.
    let h = t.height();
    let mut worst = 0.0f32;
    for k in [c.frames() / 2, c.frames() - 1] {
        let time = k as f32 / c.fps;
        for ((a, each), (b, _)) in f.skinned(time).iter().zip(&q.skinned(time)) {
            let spread = each.iter().flat_map(|x| each.iter().map(move |y| x.distance(*y))).fold(0.0, f32::max);
            let bound = 0.5 / 255.0 * spread + 1e-5 * h;
            assert!(a.distance(*b) <= bound, "a vertex moved {} m, more than {bound}", a.distance(*b));
            worst = worst.max(a.distance(*b) / h);
        }
    }
    println!(
        "aspen, game: quantised skin within {worst:.1e} × height of the float one; normals within {worst_n:.4} rad"
    );
}

#[test]
fn the_budget_skin_moves_its_joints_segments_as_sylva_skins_them() {
    use sylva_core::mesh::{MeshLayout, MeshParams, SkinLayout};
    let t = tree("quaking_aspen");
    let c = clip(&t, 1.0, false);
    let game = GltfOptions { quantize: false, key_tolerance_deg: 0.0, ..GltfOptions::game(&t, &GAME_BUDGET) };
    let f = read(&glb(&t, Some(&c), &game));
    // The segments that head a joint (`segment_N`); every other one rides with its parent's.
    let heads: std::collections::HashSet<u32> = f.json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|n| n["name"].as_str()?.strip_prefix("segment_")?.parse().ok())
        .collect();
    assert!(heads.len() < t.segments.len() && heads.len() >= 64, "{} heads", heads.len());
    let lod = game.lods[0];
    let params = MeshParams {
        sides: lod.sides,
        samples: lod.samples,
        leaf_sides: lod.leaf_sides,
        min_stem_radius: lod.min_radius,
        subdivide_min_edge: f32::INFINITY,
        ..MeshParams::default()
    };
    let skin = SkinLayout::new(&MeshLayout::new(&t, params).unwrap());
    // Bark vertices bound only to heads: the file's skinning is Sylva's own, to f32 rounding.
    let h = t.height();
    let (mut checked, mut worst) = (0, 0.0f32);
    for k in [c.frames() / 2, c.frames() - 1] {
        let ours = skin.skin(&c.joints[k], &c.acc[k], 1).tubes;
        let theirs = f.skinned(k as f32 / c.fps);
        for (i, s) in skin.tube_skin.iter().enumerate() {
            if heads.contains(&s.bone0) && (s.weight == 0.0 || heads.contains(&s.bone1)) {
                let d = theirs[i].0.distance(Vec3::from_array(ours[i].position));
                worst = worst.max(d / h);
                checked += 1;
            }
        }
    }
    println!(
        "aspen, game skin: {checked} bark vertices on head segments within {worst:.1e} × height of Sylva's skinning"
    );
    assert!(checked > 1000 && worst < 1e-5, "{checked} vertices, worst {worst} × height");
}

#[test]
fn reduced_keys_stay_within_the_stated_angle() {
    let t = tree("quaking_aspen");
    let c = clip(&t, 4.0, true);
    let game = GltfOptions::game(&t, &GAME_BUDGET);
    let full = read(&glb(&t, Some(&c), &GltfOptions { key_tolerance_deg: 0.0, ..game.clone() }));
    let reduced = read(&glb(&t, Some(&c), &game));
    let (all, kept): (usize, usize) = full
        .rotation
        .keys()
        .map(|n| (full.rotation[n].0.len(), reduced.rotation[n].0.len()))
        .fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    let mut worst = 0.0f32;
    for (node, (times, q)) in &full.rotation {
        let r = &reduced.rotation[node];
        assert_eq!((r.0[0], r.0.last()), (0.0, times.last()), "the first and last keys stay");
        for (&time, want) in times.iter().zip(q) {
            worst = worst.max(turn_deg(reduced.rotation_at(*node, time), *want));
        }
    }
    let h = t.height();
    let drift = (0..c.frames())
        .step_by(7)
        .flat_map(|k| {
            let time = k as f32 / c.fps;
            full.skinned(time).into_iter().zip(reduced.skinned(time)).map(|(a, b)| a.0.distance(b.0))
        })
        .fold(0.0, f32::max);
    println!(
        "aspen, game, 4 s loop: {kept} of {all} keys kept ({:.0} %), worst {worst:.4}° from the full keys \
         (tolerance {KEY_TOLERANCE_DEG}°), vertices within {:.2e} × height",
        100.0 * kept as f32 / all as f32,
        drift / h
    );
    assert!(kept < all, "no key was dropped");
    assert!(worst <= KEY_TOLERANCE_DEG + 1e-3, "a joint left its full keys by {worst}°");
}

#[test]
fn only_the_finest_level_is_in_the_scene_and_msft_lod_names_the_others() {
    let t = tree("palm");
    let c = clip(&t, 0.5, false);
    for (what, c) in [("static", None), ("skinned", Some(&c))] {
        let f = read(&glb(&t, c, &GltfOptions::game(&t, &GAME_BUDGET)));
        let j = &f.json;
        let scene: Vec<u64> = j["scenes"][0]["nodes"].as_array().unwrap().iter().map(|n| n.as_u64().unwrap()).collect();
        let meshes: Vec<u64> =
            scene.iter().copied().filter(|&n| j["nodes"][n as usize].get("mesh").is_some()).collect();
        assert_eq!(meshes.len(), 1, "{what}: one mesh node in the scene");
        let lod0 = &j["nodes"][meshes[0] as usize];
        assert!(lod0["name"].as_str().unwrap().ends_with("_LOD0"), "{what}");
        let ids = lod0["extensions"]["MSFT_lod"]["ids"].as_array().unwrap();
        assert_eq!(ids.len(), 2, "{what}");
        for (k, id) in ids.iter().enumerate() {
            let n = &j["nodes"][id.as_u64().unwrap() as usize];
            assert!(n["name"].as_str().unwrap().ends_with(&format!("_LOD{}", k + 1)), "{what}");
            assert!(!scene.contains(&id.as_u64().unwrap()), "{what}: LOD{} is not in the scene", k + 1);
            assert_eq!(n.get("skin").is_some(), c.is_some(), "{what}: every level bound to the skin");
        }
        let cover: Vec<f64> =
            lod0["extras"]["MSFT_screencoverage"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        assert!(cover.len() == 3 && cover.windows(2).all(|w| w[0] > w[1] && w[1] > 0.0), "{what}: {cover:?}");
        assert!(j["extensionsUsed"].as_array().unwrap().iter().any(|e| e == "MSFT_lod"));
    }
}

#[test]
fn the_packed_hierarchy_decodes_to_the_custom_attributes() {
    let t = tree("quaking_aspen");
    let near = 1e-6 * t.height();
    for quantize in [false, true] {
        let opts = GltfOptions { custom_attributes: true, quantize, ..GltfOptions::game(&t, &GAME_BUDGET) };
        let f = read(&glb(&t, None, &opts));
        let (t1, t2, t3) = (&f.texcoords[1], &f.texcoords[2], &f.texcoords[3]);
        let n = f.positions.len();
        assert!(t1.len() == n && t2.len() == n && t3.len() == n);
        let (pivot, axis, depth, phase) =
            (&f.custom["PIVOT"], &f.custom["BRANCH_AXIS"], &f.custom["HIERARCHY_DEPTH"], &f.custom["PHASE"]);
        let mut worst_axis = 0.0f32;
        for v in 0..n {
            assert_eq!(t1[v][0].floor(), depth[v][0], "depth of vertex {v}");
            assert!((t1[v][0].fract() - phase[v][0].min(PHASE_MAX)).abs() < 1e-4, "phase of vertex {v}");
            let p = Vec3::new(t2[v][0], t1[v][1], t2[v][1]);
            assert!(p.distance(Vec3::from_slice(&pivot[v])) < near, "pivot of vertex {v}");
            let a = octahedral_decode(t3[v]);
            worst_axis = worst_axis.max(angle(a, Vec3::from_slice(&axis[v])));
        }
        let limit = if quantize { 2e-4 } else { 1e-5 };
        assert!(worst_axis < limit, "axis decoded {worst_axis} rad off (quantised: {quantize})");
    }
    // Without `custom_attributes` only the standard channels are written.
    let f = read(&glb(&t, None, &GltfOptions::game(&t, &GAME_BUDGET)));
    assert!(f.custom.is_empty(), "{:?}", f.custom.keys());
}

#[test]
fn game_levels_leave_thin_stems_to_leaf_cards_that_keep_the_leaf_area() {
    let t = tree("quaking_aspen");
    let opts = GltfOptions::game(&t, &GAME_BUDGET);
    let doc = build_gltf(&t, None, &opts).unwrap();
    for (k, l) in doc.report.lods.iter().enumerate() {
        let bark = bark_triangles(&t, l.lod.sides, l.lod.samples, l.lod.min_radius);
        assert_eq!(l.triangles, bark + l.leaves * CARD_TRIANGLES, "LOD{k}: bark and two triangles per card");
        assert!(l.lod.min_radius > 0.0 && bark > 0, "LOD{k}: the thinnest twigs go, the trunk stays");
    }
    // The cards of LOD0, read back: squares whose four half-side blades hold the leaf area
    // of every leaf's blade box (w × l), the thinned ones' included.
    let mut bytes = Vec::new();
    doc.write_glb(&mut bytes).unwrap();
    let f = read(&bytes);
    let cards = doc.report.lods[0].leaves;
    let corners = &f.positions[f.positions.len() - 4 * cards..];
    let card_area: f32 = corners.chunks(4).map(|c| (c[1] - c[0]).cross(c[3] - c[0]).length()).sum();
    let square = corners.chunks(4).all(|c| ((c[1] - c[0]).length() / (c[3] - c[0]).length() - 1.0).abs() < 1e-3);
    let blade_boxes: f32 = t.leaves.width.iter().zip(&t.leaves.length).map(|(w, l)| w * l).sum();
    let ratio = card_area / blade_boxes;
    println!("aspen LOD0: {cards} cards for {} leaves carry {ratio:.3} of their blade area", t.leaves.len());
    assert!(square, "cards are square");
    assert!((0.9..1.1).contains(&ratio), "LOD0's cards carry {ratio:.3} of the leaf area");
    // A film export keeps every stem and leaf.
    let film = build_gltf(&t, None, &GltfOptions::film()).unwrap().report;
    assert_eq!((film.lods[0].leaves, film.lods[0].lod.min_radius), (t.leaves.len(), 0.0));
}

#[test]
fn mikktspace_tangents_follow_u_across_a_card_and_around_a_stem() {
    use sylva_core::export::gltf::tangents;
    use sylva_core::mesh::RawVertex;
    // A card in the x–y plane facing +z, u along +x and v along +y: tangent +x, w +1
    // (the bitangent n × t = +y, along v).
    let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let card = corners.map(|[x, y]| RawVertex::new(glam::Vec3::new(x, y, 0.0), glam::Vec3::Z));
    for t in tangents(&card, &corners, &[0, 1, 2, 0, 2, 3]) {
        assert!(Vec3::from_slice(&t[..3]).distance(Vec3::X) < 1e-6 && t[3] == 1.0, "{t:?}");
    }
    // Mirrored in u: the tangent flips with the texture, the handedness too.
    let mirrored = corners.map(|[u, v]| [1.0 - u, v]);
    for t in tangents(&card, &mirrored, &[0, 1, 2, 0, 2, 3]) {
        assert!(Vec3::from_slice(&t[..3]).distance(-Vec3::X) < 1e-6 && t[3] == -1.0, "{t:?}");
    }
    // A game export's bark: u runs around the stem, so tangents lie across its axis.
    let t = tree("lombardy_poplar");
    let layout = sylva_core::mesh::MeshLayout::new(&t, Default::default()).unwrap();
    let rest = layout.mesh(&t, &sylva_core::pose::Pose::rest(&t));
    let n =
        (t.stems.segment_count[0] as usize * layout.params.samples as usize + 1) * (layout.params.sides as usize + 1);
    let axis = (t.segments.end(t.stems.segment_count[0] as usize - 1) - t.segments.start[0]).normalize();
    let tg = tangents(&rest.tubes, &layout.tube_uv(), &layout.tube_indices);
    let worst = tg[..n].iter().map(|g| Vec3::from_slice(&g[..3]).dot(axis).abs()).fold(0.0, f32::max);
    assert!(worst < 0.2, "a trunk tangent leans {worst} along the trunk");
}

/// `encoded` (a meshopt vertex stream of `count` elements of `stride` bytes) decoded.
fn decode_attributes(encoded: &[u8], count: usize, stride: usize) -> Vec<u8> {
    macro_rules! words {
        ($k:literal) => {{
            let v: Vec<[u32; $k]> = ::meshopt::decode_vertex_buffer(encoded, count).unwrap();
            v.iter().flat_map(|e| e.iter().flat_map(|w| w.to_le_bytes())).collect()
        }};
    }
    match stride {
        4 => words!(1),
        8 => words!(2),
        12 => words!(3),
        16 => words!(4),
        20 => words!(5),
        24 => words!(6),
        28 => words!(7),
        32 => words!(8),
        64 => words!(16),
        s => panic!("stride {s}"),
    }
}

#[test]
fn meshopt_compressed_views_decode_to_the_uncompressed_bytes() {
    let t = tree("palm");
    let c = clip(&t, 2.0, true);
    let game = GltfOptions::game(&t, &GAME_BUDGET);
    let plain = glb(&t, Some(&c), &game);
    let packed = glb(&t, Some(&c), &GltfOptions { meshopt: true, ..game });
    let json = |b: &[u8]| -> (serde_json::Value, Vec<u8>) {
        let g = gltf::binary::Glb::from_slice(b).unwrap();
        (serde_json::from_slice(&g.json).unwrap(), g.bin.unwrap().into_owned())
    };
    let ((pj, pb), (mj, mb)) = (json(&plain), json(&packed));
    assert!(mj["extensionsRequired"].as_array().unwrap().iter().any(|e| e == "EXT_meshopt_compression"));
    assert_eq!(mj["buffers"][1]["extensions"]["EXT_meshopt_compression"]["fallback"], true);
    assert!(mj["buffers"][1].get("uri").is_none(), "the fallback buffer holds no data");
    let views = pj["bufferViews"].as_array().unwrap();
    assert_eq!(views.len(), mj["bufferViews"].as_array().unwrap().len());
    let (mut compressed, mut same) = (0, 0);
    for (i, v) in views.iter().enumerate() {
        let at = |v: &serde_json::Value, k: &str| v[k].as_u64().unwrap_or(0) as usize;
        let want = &pb[at(v, "byteOffset")..at(v, "byteOffset") + at(v, "byteLength")];
        let m = &mj["bufferViews"][i];
        let Some(e) = m["extensions"].get("EXT_meshopt_compression") else {
            // Images stay as they are, in the file's buffer.
            assert_eq!(at(m, "buffer"), 0);
            assert_eq!(&mb[at(m, "byteOffset")..at(m, "byteOffset") + at(m, "byteLength")], want, "view {i}");
            same += 1;
            continue;
        };
        assert_eq!((at(m, "buffer"), at(m, "byteLength")), (1, want.len()), "view {i} stands in the fallback");
        let data = &mb[at(e, "byteOffset")..at(e, "byteOffset") + at(e, "byteLength")];
        let (count, stride) = (at(e, "count"), at(e, "byteStride"));
        let got: Vec<u8> = match e["mode"].as_str().unwrap() {
            "ATTRIBUTES" => {
                assert_eq!(::meshopt::decode_vertex_version(data), Some(0), "EXT_ allows vertex codec 0 only");
                decode_attributes(data, count, stride)
            }
            "TRIANGLES" if stride == 2 => ::meshopt::decode_index_buffer::<u16>(data, count)
                .unwrap()
                .iter()
                .flat_map(|i| i.to_le_bytes())
                .collect(),
            "TRIANGLES" => ::meshopt::decode_index_buffer::<u32>(data, count)
                .unwrap()
                .iter()
                .flat_map(|i| i.to_le_bytes())
                .collect(),
            m => panic!("mode {m}"),
        };
        assert_eq!(got, want, "view {i} decodes to its uncompressed bytes");
        compressed += 1;
    }
    println!(
        "palm, game, 2 s loop: {compressed} views compressed, {same} images kept; {:.2} MiB → {:.2} MiB",
        plain.len() as f64 / (1 << 20) as f64,
        packed.len() as f64 / (1 << 20) as f64
    );
    assert!(compressed > 10 && packed.len() < plain.len() * 3 / 4, "{} → {} bytes", plain.len(), packed.len());
}
