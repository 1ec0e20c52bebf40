//! WGSL checks that need no GPU: every kernel validates with naga, and every `Pod` struct
//! matches its WGSL twin in size and member offsets.

use naga::valid::{Capabilities, ValidationFlags, Validator};
use std::mem::{offset_of, size_of};
use sylva_core::model::{RawLeaf, RawSegment, RawStem};
use sylva_gpu::shaders::{KERNELS, TREE, compose};

fn parse(src: &str, name: &str) -> naga::Module {
    naga::front::wgsl::parse_str(src).unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(src)))
}

#[test]
fn every_kernel_validates_with_naga() {
    assert!(!KERNELS.is_empty());
    for k in KERNELS {
        let (name, src) = (k.name, compose(k.sources));
        let module = parse(&src, name);
        Validator::new(ValidationFlags::all(), Capabilities::all())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&src)));
        assert!(module.entry_points.iter().any(|e| e.name == "main"), "{name} has no `main`");
    }
}

#[test]
fn broken_wgsl_is_caught_without_a_gpu() {
    let src = compose(&[TREE, "fn f() -> f32 { return undefined_thing; }"]);
    assert!(naga::front::wgsl::parse_str(&src).is_err());
}

fn wgsl_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            wgsl_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "wgsl") {
            out.push(path);
        }
    }
}

/// Every WGSL file of the crate (but the renderer's, validated by its own test) is composed
/// into some registered kernel, so naga validates it.
#[test]
fn every_wgsl_file_is_part_of_a_validated_kernel() {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    wgsl_files(&src, &mut files);
    files.retain(|p| !p.starts_with(src.join("render")));
    for path in &files {
        let text = std::fs::read_to_string(path).unwrap();
        assert!(
            KERNELS.iter().any(|k| k.sources.contains(&text.as_str())),
            "{} is in no kernel of shaders::KERNELS, so nothing validates it",
            path.display()
        );
    }
    assert!(files.len() >= 30, "{} WGSL files found", files.len());
}

/// A kernel's name is its own WGSL file's stem (the last source composed) and its CPU
/// twin's function name: the registry keeps the three together.
#[test]
fn every_kernel_is_named_after_its_wgsl_file_and_its_cpu_twin() {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    wgsl_files(&src, &mut files);
    let mut names = std::collections::BTreeSet::new();
    for k in KERNELS {
        assert!(names.insert(k.name), "{} is registered twice", k.name);
        let last = k.sources.last().unwrap();
        let file = files
            .iter()
            .find(|p| std::fs::read_to_string(p).unwrap() == *last)
            .unwrap_or_else(|| panic!("{}: its last source is no file", k.name));
        assert_eq!(file.file_stem().unwrap(), k.name, "{}: composed last from {}", k.name, file.display());
        assert!(k.cpu_twin.starts_with("sylva_core::"), "{}: twin {}", k.name, k.cpu_twin);
        assert_eq!(k.cpu_twin.rsplit("::").next(), Some(k.name), "{}: twin {}", k.name, k.cpu_twin);
        assert_eq!(sylva_gpu::shaders::kernel(k.name), Some(k));
    }
    assert!(sylva_gpu::shaders::kernel("no_such_kernel").is_none());
}

/// (size, [(member, offset)]) of a WGSL struct, from naga's layouter.
fn wgsl_layout_in(src: &str, name: &str) -> (u32, Vec<(String, u32)>) {
    let module = parse(src, name);
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    for (handle, ty) in module.types.iter() {
        if ty.name.as_deref() == Some(name) {
            if let naga::TypeInner::Struct { members, .. } = &ty.inner {
                let size = layouter[handle].size;
                return (size, members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect());
            }
        }
    }
    panic!("no struct {name}");
}

fn check(name: &str, rust_size: usize, rust: &[(&str, usize)]) {
    check_in(TREE, name, rust_size, rust)
}

fn check_in(src: &str, name: &str, rust_size: usize, rust: &[(&str, usize)]) {
    let (size, members) = wgsl_layout_in(src, name);
    assert_eq!(size as usize, rust_size, "{name}: WGSL size {size}, Rust {rust_size}");
    assert_eq!(members.len(), rust.len(), "{name}: member count");
    for ((wname, woff), (rname, roff)) in members.iter().zip(rust) {
        assert_eq!(wname, rname, "{name}: member order");
        assert_eq!(*woff as usize, *roff, "{name}.{wname}: WGSL offset {woff}, Rust {roff}");
    }
}

#[test]
fn pod_structs_match_their_wgsl_twins() {
    check(
        "Segment",
        size_of::<RawSegment>(),
        &[
            ("start", offset_of!(RawSegment, start)),
            ("length", offset_of!(RawSegment, length)),
            ("orientation", offset_of!(RawSegment, orientation)),
            ("local_orientation", offset_of!(RawSegment, local_orientation)),
            ("radius_base", offset_of!(RawSegment, radius_base)),
            ("radius_tip", offset_of!(RawSegment, radius_tip)),
            ("mass", offset_of!(RawSegment, mass)),
            ("stiffness", offset_of!(RawSegment, stiffness)),
            ("parent", offset_of!(RawSegment, parent)),
            ("level", offset_of!(RawSegment, level)),
            ("stem", offset_of!(RawSegment, stem)),
            ("child_offset", offset_of!(RawSegment, child_offset)),
            ("child_count", offset_of!(RawSegment, child_count)),
            ("leaf_offset", offset_of!(RawSegment, leaf_offset)),
            ("leaf_count", offset_of!(RawSegment, leaf_count)),
            ("_pad", offset_of!(RawSegment, _pad)),
        ],
    );
    check(
        "Stem",
        size_of::<RawStem>(),
        &[
            ("bezier", offset_of!(RawStem, bezier)),
            ("parent", offset_of!(RawStem, parent)),
            ("level", offset_of!(RawStem, level)),
            ("first_segment", offset_of!(RawStem, first_segment)),
            ("segment_count", offset_of!(RawStem, segment_count)),
            ("attach", offset_of!(RawStem, attach)),
            ("length", offset_of!(RawStem, length)),
            ("_pad", offset_of!(RawStem, _pad)),
        ],
    );
    check(
        "Leaf",
        size_of::<RawLeaf>(),
        &[
            ("position", offset_of!(RawLeaf, position)),
            ("width", offset_of!(RawLeaf, width)),
            ("orientation", offset_of!(RawLeaf, orientation)),
            ("length", offset_of!(RawLeaf, length)),
            ("segment", offset_of!(RawLeaf, segment)),
            ("shape", offset_of!(RawLeaf, shape)),
            ("index", offset_of!(RawLeaf, index)),
        ],
    );
}

#[test]
fn wind_and_noise_structs_match_their_wgsl_twins() {
    use sylva_core::methods::zioma::trunk::RawBand;
    use sylva_core::wind::raw::{RawField, RawWave};
    use sylva_gpu::shaders::{NOISE, TRUNK_NOISE, WIND};
    let wind = compose(&[NOISE, WIND]);
    check_in(
        &wind,
        "Field",
        size_of::<RawField>(),
        &[
            ("kind", offset_of!(RawField, kind)),
            ("wave_offset", offset_of!(RawField, wave_offset)),
            ("wave_count", offset_of!(RawField, wave_count)),
            ("_pad", offset_of!(RawField, _pad)),
            ("a", offset_of!(RawField, a)),
            ("b", offset_of!(RawField, b)),
            ("c", offset_of!(RawField, c)),
        ],
    );
    check_in(
        &wind,
        "Wave",
        size_of::<RawWave>(),
        &[("dir", offset_of!(RawWave, dir)), ("k", offset_of!(RawWave, k)), ("phase", offset_of!(RawWave, phase))],
    );
    check_in(
        &compose(&[NOISE, TRUNK_NOISE]),
        "Band",
        size_of::<RawBand>(),
        &[
            ("axis", offset_of!(RawBand, axis)),
            ("seed", offset_of!(RawBand, seed)),
            ("frequency", offset_of!(RawBand, frequency)),
            ("amplitude", offset_of!(RawBand, amplitude)),
            ("bias", offset_of!(RawBand, bias)),
            ("_pad", offset_of!(RawBand, _pad)),
        ],
    );
}

#[test]
fn leaf_motion_structs_match_their_wgsl_twins() {
    use sylva_core::leaves::{RawLeafFrame, RawLeafMotion};
    use sylva_gpu::shaders::{LEAVES, NOISE, QUAT};
    let src = compose(&[QUAT, NOISE, LEAVES]);
    check_in(
        &src,
        "LeafFrame",
        size_of::<RawLeafFrame>(),
        &[
            ("time", offset_of!(RawLeafFrame, time)),
            ("strength", offset_of!(RawLeafFrame, strength)),
            ("flutter", offset_of!(RawLeafFrame, flutter)),
            ("zeta", offset_of!(RawLeafFrame, zeta)),
            ("reconfiguration_speed", offset_of!(RawLeafFrame, reconfiguration_speed)),
            ("vogel_exponent", offset_of!(RawLeafFrame, vogel_exponent)),
            ("leaves", offset_of!(RawLeafFrame, leaves)),
            ("twigs", offset_of!(RawLeafFrame, twigs)),
            ("flutter_onset", offset_of!(RawLeafFrame, flutter_onset)),
            ("crown_wind", offset_of!(RawLeafFrame, crown_wind)),
            ("_pad", offset_of!(RawLeafFrame, _pad)),
        ],
    );
    check_in(
        &src,
        "LeafMotion",
        size_of::<RawLeafMotion>(),
        &[
            ("orientation", offset_of!(RawLeafMotion, orientation)),
            ("omega", offset_of!(RawLeafMotion, omega)),
            ("omega_twist", offset_of!(RawLeafMotion, omega_twist)),
            ("compliance", offset_of!(RawLeafMotion, compliance)),
            ("flip_pressure", offset_of!(RawLeafMotion, flip_pressure)),
            ("seed", offset_of!(RawLeafMotion, seed)),
            ("twig", offset_of!(RawLeafMotion, twig)),
            ("segment", offset_of!(RawLeafMotion, segment)),
            ("_pad", offset_of!(RawLeafMotion, _pad)),
        ],
    );
}

#[test]
fn animation_structs_match_their_wgsl_twins() {
    use sylva_core::methods::akagi::{RawAkagiSegment, RawAkagiStep};
    use sylva_core::methods::skjermo::{
        RawSkjermoMode, RawSkjermoState, RawSkjermoStem, RawSkjermoStep, RawSkjermoSway,
    };
    use sylva_core::methods::zioma::{RawZiomaFrame, RawZiomaInstance, RawZiomaRing, RawZiomaStem, RawZiomaTrunk};
    use sylva_gpu::shaders::{AKAGI, NOISE, QUAT, SKJERMO, TREE, WIND, ZIOMA, ZIOMA_ROTATIONS};
    let zioma = compose(&[QUAT, TREE, NOISE, WIND, ZIOMA, ZIOMA_ROTATIONS]);
    check_in(
        ZIOMA,
        "ZiomaTrunk",
        size_of::<RawZiomaTrunk>(),
        &[
            ("crown_centre", offset_of!(RawZiomaTrunk, crown_centre)),
            ("natural_frequency", offset_of!(RawZiomaTrunk, natural_frequency)),
            ("tip_per_pascal", offset_of!(RawZiomaTrunk, tip_per_pascal)),
            ("damping_centre", offset_of!(RawZiomaTrunk, damping_centre)),
            ("lever", offset_of!(RawZiomaTrunk, lever)),
            ("damping_ratio", offset_of!(RawZiomaTrunk, damping_ratio)),
            ("reconfiguration_speed", offset_of!(RawZiomaTrunk, reconfiguration_speed)),
            ("vogel_exponent", offset_of!(RawZiomaTrunk, vogel_exponent)),
            ("time", offset_of!(RawZiomaTrunk, time)),
            ("tree_seed", offset_of!(RawZiomaTrunk, tree_seed)),
            ("lod", offset_of!(RawZiomaTrunk, lod)),
            ("amplitude", offset_of!(RawZiomaTrunk, amplitude)),
            ("max_bend", offset_of!(RawZiomaTrunk, max_bend)),
            ("inertia", offset_of!(RawZiomaTrunk, inertia)),
        ],
    );
    check_in(
        ZIOMA,
        "ZiomaRing",
        size_of::<RawZiomaRing>(),
        &[
            ("bend", offset_of!(RawZiomaRing, bend)),
            ("since", offset_of!(RawZiomaRing, since)),
            ("rate", offset_of!(RawZiomaRing, rate)),
            ("zeta", offset_of!(RawZiomaRing, zeta)),
        ],
    );
    check_in(
        ZIOMA,
        "ZiomaInstance",
        size_of::<RawZiomaInstance>(),
        &[
            ("position", offset_of!(RawZiomaInstance, position)),
            ("yaw", offset_of!(RawZiomaInstance, yaw)),
            ("phase", offset_of!(RawZiomaInstance, phase)),
            ("seed", offset_of!(RawZiomaInstance, seed)),
            ("_pad", offset_of!(RawZiomaInstance, _pad)),
        ],
    );
    check_in(
        &zioma,
        "ZiomaStem",
        size_of::<RawZiomaStem>(),
        &[
            ("base", offset_of!(RawZiomaStem, base)),
            ("drag", offset_of!(RawZiomaStem, drag)),
            ("dir", offset_of!(RawZiomaStem, dir)),
            ("freq", offset_of!(RawZiomaStem, freq)),
            ("parent_axis", offset_of!(RawZiomaStem, parent_axis)),
            ("phase", offset_of!(RawZiomaStem, phase)),
            ("level", offset_of!(RawZiomaStem, level)),
            ("seed", offset_of!(RawZiomaStem, seed)),
            ("length", offset_of!(RawZiomaStem, length)),
            ("_pad", offset_of!(RawZiomaStem, _pad)),
        ],
    );
    check_in(
        &zioma,
        "ZiomaFrame",
        size_of::<RawZiomaFrame>(),
        &[
            ("wind_dir", offset_of!(RawZiomaFrame, wind_dir)),
            ("time", offset_of!(RawZiomaFrame, time)),
            ("trunk", offset_of!(RawZiomaFrame, trunk)),
            ("trunk_rate", offset_of!(RawZiomaFrame, trunk_rate)),
            ("lod", offset_of!(RawZiomaFrame, lod)),
            ("amplitude", offset_of!(RawZiomaFrame, amplitude)),
            ("max_bend", offset_of!(RawZiomaFrame, max_bend)),
            ("inertia", offset_of!(RawZiomaFrame, inertia)),
            ("origin", offset_of!(RawZiomaFrame, origin)),
            ("phase", offset_of!(RawZiomaFrame, phase)),
            ("heading", offset_of!(RawZiomaFrame, heading)),
            ("_pad", offset_of!(RawZiomaFrame, _pad)),
        ],
    );
    check_in(
        AKAGI,
        "AkagiSegment",
        size_of::<RawAkagiSegment>(),
        &[
            ("bark_area", offset_of!(RawAkagiSegment, bark_area)),
            ("leaf_area", offset_of!(RawAkagiSegment, leaf_area)),
            ("inertia", offset_of!(RawAkagiSegment, inertia)),
            ("stiffness", offset_of!(RawAkagiSegment, stiffness)),
            ("damping", offset_of!(RawAkagiSegment, damping)),
            ("air_scale", offset_of!(RawAkagiSegment, air_scale)),
            ("_pad", offset_of!(RawAkagiSegment, _pad)),
        ],
    );
    check_in(
        AKAGI,
        "AkagiStep",
        size_of::<RawAkagiStep>(),
        &[
            ("drag", offset_of!(RawAkagiStep, drag)),
            ("time", offset_of!(RawAkagiStep, time)),
            ("dt", offset_of!(RawAkagiStep, dt)),
            ("reconfiguration_speed", offset_of!(RawAkagiStep, reconfiguration_speed)),
            ("stiffening_angle", offset_of!(RawAkagiStep, stiffening_angle)),
            ("vogel_exponent", offset_of!(RawAkagiStep, vogel_exponent)),
            ("_pad", offset_of!(RawAkagiStep, _pad)),
        ],
    );
    let skjermo = compose(&[QUAT, TREE, SKJERMO]);
    check_in(
        &skjermo,
        "SkjermoStem",
        size_of::<RawSkjermoStem>(),
        &[
            ("rest", offset_of!(RawSkjermoStem, rest)),
            ("local", offset_of!(RawSkjermoStem, local)),
            ("parent", offset_of!(RawSkjermoStem, parent)),
            ("attach", offset_of!(RawSkjermoStem, attach)),
            ("drag", offset_of!(RawSkjermoStem, drag)),
            ("length", offset_of!(RawSkjermoStem, length)),
            ("parent_orient", offset_of!(RawSkjermoStem, parent_orient)),
        ],
    );
    check_in(&skjermo, "SkjermoState", size_of::<RawSkjermoState>(), &[("delta", offset_of!(RawSkjermoState, delta))]);
    check_in(
        &skjermo,
        "SkjermoStep",
        size_of::<RawSkjermoStep>(),
        &[
            ("time", offset_of!(RawSkjermoStep, time)),
            ("exponent", offset_of!(RawSkjermoStep, exponent)),
            ("p2_weight", offset_of!(RawSkjermoStep, p2_weight)),
            ("max_bend", offset_of!(RawSkjermoStep, max_bend)),
            ("dt", offset_of!(RawSkjermoStep, dt)),
            ("dynamics", offset_of!(RawSkjermoStep, dynamics)),
            ("reconfiguration_speed", offset_of!(RawSkjermoStep, reconfiguration_speed)),
            ("vogel_exponent", offset_of!(RawSkjermoStep, vogel_exponent)),
        ],
    );
    check_in(
        &skjermo,
        "SkjermoMode",
        size_of::<RawSkjermoMode>(),
        &[
            ("w2", offset_of!(RawSkjermoMode, w2)),
            ("damping", offset_of!(RawSkjermoMode, damping)),
            ("aero", offset_of!(RawSkjermoMode, aero)),
            ("_pad", offset_of!(RawSkjermoMode, _pad)),
        ],
    );
    check_in(
        &skjermo,
        "SkjermoSway",
        size_of::<RawSkjermoSway>(),
        &[("bend", offset_of!(RawSkjermoSway, bend)), ("rate", offset_of!(RawSkjermoSway, rate))],
    );
}

#[test]
fn hsm_structs_match_their_wgsl_twins() {
    use sylva_core::methods::hsm::{
        RawHsmCluster, RawHsmClusterInfo, RawHsmClusterState, RawHsmLeaf, RawHsmMember, RawHsmSlot, RawHsmStep,
    };
    use sylva_gpu::shaders::{HSM, QUAT};
    let hsm = compose(&[QUAT, HSM]);
    check_in(
        &hsm,
        "HsmClusterInfo",
        size_of::<RawHsmClusterInfo>(),
        &[
            ("kind", offset_of!(RawHsmClusterInfo, kind)),
            ("source", offset_of!(RawHsmClusterInfo, source)),
            ("slot_offset", offset_of!(RawHsmClusterInfo, slot_offset)),
            ("slot_count", offset_of!(RawHsmClusterInfo, slot_count)),
        ],
    );
    check_in(
        &hsm,
        "HsmCluster",
        size_of::<RawHsmCluster>(),
        &[
            ("rest_cm", offset_of!(RawHsmCluster, rest_cm)),
            ("parent", offset_of!(RawHsmCluster, parent)),
            ("child_offset", offset_of!(RawHsmCluster, child_offset)),
            ("child_count", offset_of!(RawHsmCluster, child_count)),
            ("mass", offset_of!(RawHsmCluster, mass)),
            ("aqq_inv", offset_of!(RawHsmCluster, aqq_inv)),
        ],
    );
    check_in(
        &hsm,
        "HsmSlot",
        size_of::<RawHsmSlot>(),
        &[("q", offset_of!(RawHsmSlot, q)), ("particle", offset_of!(RawHsmSlot, particle))],
    );
    check_in(
        &hsm,
        "HsmLeaf",
        size_of::<RawHsmLeaf>(),
        &[
            ("tip", offset_of!(RawHsmLeaf, tip)),
            ("segment", offset_of!(RawHsmLeaf, segment)),
            ("edge", offset_of!(RawHsmLeaf, edge)),
            ("slot_offset", offset_of!(RawHsmLeaf, slot_offset)),
            ("attach", offset_of!(RawHsmLeaf, attach)),
            ("cluster", offset_of!(RawHsmLeaf, cluster)),
            ("ring", offset_of!(RawHsmLeaf, ring)),
            ("blade", offset_of!(RawHsmLeaf, blade)),
            ("strength", offset_of!(RawHsmLeaf, strength)),
            ("_pad", offset_of!(RawHsmLeaf, _pad)),
        ],
    );
    check_in(
        &hsm,
        "HsmMember",
        size_of::<RawHsmMember>(),
        &[("q", offset_of!(RawHsmMember, q)), ("cluster", offset_of!(RawHsmMember, cluster))],
    );
    check_in(
        &hsm,
        "HsmClusterState",
        size_of::<RawHsmClusterState>(),
        &[
            ("cm", offset_of!(RawHsmClusterState, cm)),
            ("rotation", offset_of!(RawHsmClusterState, rotation)),
            ("transform", offset_of!(RawHsmClusterState, transform)),
            ("wind", offset_of!(RawHsmClusterState, wind)),
        ],
    );
    check_in(
        &hsm,
        "HsmStep",
        size_of::<RawHsmStep>(),
        &[
            ("gravity", offset_of!(RawHsmStep, gravity)),
            ("dt", offset_of!(RawHsmStep, dt)),
            ("time", offset_of!(RawHsmStep, time)),
            ("damping", offset_of!(RawHsmStep, damping)),
            ("beta", offset_of!(RawHsmStep, beta)),
            ("polar_iterations", offset_of!(RawHsmStep, polar_iterations)),
            ("clusters", offset_of!(RawHsmStep, clusters)),
            ("particles", offset_of!(RawHsmStep, particles)),
            ("max_children", offset_of!(RawHsmStep, max_children)),
            ("hold", offset_of!(RawHsmStep, hold)),
            ("reconfiguration_speed", offset_of!(RawHsmStep, reconfiguration_speed)),
            ("vogel_exponent", offset_of!(RawHsmStep, vogel_exponent)),
            ("air", offset_of!(RawHsmStep, air)),
            ("sample_wind", offset_of!(RawHsmStep, sample_wind)),
            ("leaf_turbulence", offset_of!(RawHsmStep, leaf_turbulence)),
            ("flutter_onset", offset_of!(RawHsmStep, flutter_onset)),
            ("leaf_zeta", offset_of!(RawHsmStep, leaf_zeta)),
        ],
    );
}

#[test]
fn mesh_structs_match_their_wgsl_twins() {
    use sylva_core::mesh::{RawDetail, RawMeshInfo, RawRing, RawVertex};
    use sylva_gpu::shaders::{MESH, NOISE, VERTEX};
    let src = compose(&[NOISE, MESH, VERTEX]);
    check_in(
        &src,
        "Ring",
        size_of::<RawRing>(),
        &[
            ("segment", offset_of!(RawRing, segment)),
            ("prev", offset_of!(RawRing, prev)),
            ("next", offset_of!(RawRing, next)),
            ("t", offset_of!(RawRing, t)),
            ("v", offset_of!(RawRing, v)),
            ("relief", offset_of!(RawRing, relief)),
            ("stem_seed", offset_of!(RawRing, stem_seed)),
            ("radius", offset_of!(RawRing, radius)),
        ],
    );
    check_in(
        &src,
        "MeshInfo",
        size_of::<RawMeshInfo>(),
        &[
            ("sides", offset_of!(RawMeshInfo, sides)),
            ("rings", offset_of!(RawMeshInfo, rings)),
            ("leaf_sides", offset_of!(RawMeshInfo, leaf_sides)),
            ("leaves", offset_of!(RawMeshInfo, leaves)),
            ("details", offset_of!(RawMeshInfo, details)),
            ("_pad", offset_of!(RawMeshInfo, _pad)),
        ],
    );
    check_in(
        &src,
        "Detail",
        size_of::<RawDetail>(),
        &[
            ("a", offset_of!(RawDetail, a)),
            ("b", offset_of!(RawDetail, b)),
            ("ring", offset_of!(RawDetail, ring)),
            ("t", offset_of!(RawDetail, t)),
            ("scale", offset_of!(RawDetail, scale)),
            ("stem_seed", offset_of!(RawDetail, stem_seed)),
            ("_pad", offset_of!(RawDetail, _pad)),
        ],
    );
    check_in(
        &src,
        "Vertex",
        size_of::<RawVertex>(),
        &[("position", offset_of!(RawVertex, position)), ("normal_oct", offset_of!(RawVertex, normal_oct))],
    );
}

#[test]
fn skin_structs_match_their_wgsl_twins() {
    use sylva_core::mesh::{RawSkin, RawSkinInfo};
    use sylva_gpu::shaders::{MESH, NOISE, QUAT, SKIN_VERTICES, VERTEX};
    let src = compose(&[QUAT, NOISE, MESH, VERTEX, SKIN_VERTICES]);
    check_in(
        &src,
        "Skin",
        size_of::<RawSkin>(),
        &[
            ("bone0", offset_of!(RawSkin, bone0)),
            ("bone1", offset_of!(RawSkin, bone1)),
            ("weight", offset_of!(RawSkin, weight)),
            ("leaf", offset_of!(RawSkin, leaf)),
        ],
    );
    check_in(
        &src,
        "SkinInfo",
        size_of::<RawSkinInfo>(),
        &[
            ("vertices", offset_of!(RawSkinInfo, vertices)),
            ("segments", offset_of!(RawSkinInfo, segments)),
            ("instances", offset_of!(RawSkinInfo, instances)),
            ("first_instance", offset_of!(RawSkinInfo, first_instance)),
        ],
    );
}

#[test]
fn deformer_structs_match_their_wgsl_twins() {
    use sylva_core::mesh::{RawDeformRing, RawDeformShape};
    use sylva_gpu::shaders::{MESH, NOISE, QUAT, SKJERMO, SKJERMO_DEFORM, VERTEX, VERTEX_STAGE};
    let src = compose(&[QUAT, TREE, NOISE, MESH, VERTEX, VERTEX_STAGE, SKJERMO, SKJERMO_DEFORM]);
    check_in(
        &src,
        "DeformShape",
        size_of::<RawDeformShape>(),
        &[
            ("radius", offset_of!(RawDeformShape, radius)),
            ("taper", offset_of!(RawDeformShape, taper)),
            ("flare", offset_of!(RawDeformShape, flare)),
            ("bulges", offset_of!(RawDeformShape, bulges)),
            ("bulge_depth", offset_of!(RawDeformShape, bulge_depth)),
            ("lobes", offset_of!(RawDeformShape, lobes)),
            ("lobe_depth", offset_of!(RawDeformShape, lobe_depth)),
            ("lobe_fade", offset_of!(RawDeformShape, lobe_fade)),
            ("v_floor", offset_of!(RawDeformShape, v_floor)),
            ("_pad", offset_of!(RawDeformShape, _pad)),
        ],
    );
    check_in(
        &src,
        "DeformRing",
        size_of::<RawDeformRing>(),
        &[
            ("stem", offset_of!(RawDeformRing, stem)),
            ("v", offset_of!(RawDeformRing, v)),
            ("tex_v", offset_of!(RawDeformRing, tex_v)),
            ("_pad", offset_of!(RawDeformRing, _pad)),
        ],
    );
}

/// A WGSL module-scope `const NAME: f32 = literal;`, from naga's parse.
fn wgsl_f32_const(src: &str, name: &str) -> f32 {
    let module = parse(src, name);
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no const {name}"));
    match module.global_expressions[c.init] {
        naga::Expression::Literal(naga::Literal::F32(v)) => v,
        ref e => panic!("{name} is not an f32 literal: {e:?}"),
    }
}

/// HSM's tuning constants are written twice, in `cpu/hsm.rs` and in `hsm.wgsl`: the same
/// values on both sides.
#[test]
fn hsm_constants_match_their_cpu_twins() {
    use sylva_core::methods::hsm::kernels::{MAX_WEIGHT, NEWTON_NEAR};
    let src = compose(&[sylva_gpu::shaders::QUAT, sylva_gpu::shaders::HSM]);
    assert_eq!(wgsl_f32_const(&src, "NEWTON_NEAR"), NEWTON_NEAR);
    assert_eq!(wgsl_f32_const(&src, "MAX_WEIGHT"), MAX_WEIGHT);
}
