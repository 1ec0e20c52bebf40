//! Leaves that move, GPU against CPU: the leaf kernels (`leaf_wind`, `leaf_flutter`), HSM's
//! leaf pose (`hsm_leaf_pose`) and the leaf mesher reading leaf rotations, on random trees,
//! winds, poses and times.

mod common;

use glam::{Quat, Vec3};
use rand::{Rng, SeedableRng};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::leaves::LeafFlutter;
use sylva_core::mesh::{MeshLayout, MeshParams};
use sylva_core::pose::SeamPose;
use sylva_core::species::SpeciesSource;
use sylva_core::wind::{Constant, WindField, WindScene};
use sylva_gpu::kernel::{read_back, upload};
use sylva_gpu::leaves::GpuLeafFlutter;
use sylva_gpu::mesh::GpuMesh;
use sylva_gpu::wind::GpuWind;

fn tree(species: &str, seed: u64, leaves: f64) -> Tree {
    let SpeciesSource::WeberPenn { file, mut params } = SpeciesSource::resolve(species).unwrap() else {
        unreachable!()
    };
    params.scale *= 0.5;
    params.scale_v *= 0.5;
    params.leaves *= leaves;
    SpeciesSource::WeberPenn { file, params }.generate(seed, &Default::default(), None).unwrap()
}

/// A random pose: every segment turned by up to 0.3 rad about a random axis.
fn random_seam(tree: &Tree, rng: &mut rand::rngs::StdRng) -> SeamPose {
    let delta: Vec<[f32; 4]> = (0..tree.segments.len())
        .map(|_| {
            let axis = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            Quat::from_axis_angle(axis.normalize_or(Vec3::X), rng.random_range(0.0..0.3)).to_array()
        })
        .collect();
    SeamPose::from_rotations(tree, &delta)
}

/// A random wind: `gusty` turned and scaled, with a constant of 0–30 m/s on top.
fn random_wind(rng: &mut rand::rngs::StdRng) -> WindScene {
    let mut wind = WindScene::resolve("gusty").unwrap();
    let a: f32 = rng.random_range(0.0..std::f32::consts::TAU);
    wind.fields
        .push(WindField::Constant(Constant { direction: [a.cos(), 0.0, a.sin()], speed: rng.random_range(0.0..30.0) }));
    wind
}

fn angle_between(a: [f32; 4], b: [f32; 4]) -> f32 {
    let d = Quat::from_array(a).dot(Quat::from_array(b)).abs().min(1.0);
    2.0 * d.acos()
}

/// `leaf_wind` + `leaf_flutter` against their CPU twins on three species, random poses,
/// winds (to hurricane strength) and times up to 120 s. Tolerance: 5e-3 rad (0.3°) between
/// the rotations. The leaves' phases `ω t` reach 2·10⁴ rad, where one f32 ulp is 2e-3 rad,
/// and a GPU may fuse `ω t + φ` where the CPU rounds twice: a phase off by an ulp moves a
/// flutter of up to 2 rad peak by up to 4e-3 rad. The lean and the wind agree to ~1e-6;
/// lavapipe measures 1.5e-3 rad.
#[test]
fn leaf_kernels_match_the_cpu() {
    let Some(ctx) = common::gpu() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(28);
    let mut worst = 0.0f32;
    for (species, seed) in [("quaking_aspen", 1), ("sassafras", 2), ("palm", 3)] {
        let t = tree(species, seed, 0.2);
        let flutter = LeafFlutter::new(&t, seed);
        let gpu = GpuLeafFlutter::new(ctx, &flutter).unwrap();
        for _ in 0..3 {
            let wind = random_wind(&mut rng);
            let gw = GpuWind::from_scene(ctx, &wind).unwrap();
            let mut seam = random_seam(&t, &mut rng);
            let time = rng.random_range(0.0..120.0);
            flutter.seam(&gw.packed, time, &mut seam);
            let joints = upload(ctx, "joints", &seam.joints).unwrap();
            let acc = upload(ctx, "acc", &seam.acc).unwrap();
            let out = upload(ctx, "leaf", &vec![[0.0f32; 4]; t.leaves.len()]).unwrap();
            let mut e = ctx.device.create_command_encoder(&Default::default());
            gpu.record(ctx, &mut e, &gw, [&joints, &acc, &out], time);
            ctx.submit([e.finish()]);
            let got: Vec<[f32; 4]> = read_back(ctx, &out, t.leaves.len()).unwrap();
            let moved = seam.leaf.iter().filter(|q| angle_between(**q, [0.0, 0.0, 0.0, 1.0]) > 0.01).count();
            assert!(2 * moved > t.leaves.len(), "{species}: only {moved} of {} leaves turned", t.leaves.len());
            for (l, (g, c)) in got.iter().zip(&seam.leaf).enumerate() {
                let d = angle_between(*g, *c);
                worst = worst.max(d);
                assert!(d <= 5e-3, "{species}: leaf {l} at t = {time}: GPU {g:?}, CPU {c:?} ({d} rad apart)");
            }
        }
    }
    println!("leaf kernels: worst difference {worst:.2e} rad");
}

/// `hsm_leaf_pose` against its CPU twin on random blades (a leaf's shape: tip 3–6 cm out, edge
/// 2–4 cm across it; particles displaced by up to 3 mm a side, turns of up to about 20°), ring
/// and segment rotations; with leaves that have no cluster, have not moved or have strength 0
/// (the identity, exactly on both), one-particle blades and strengths ½ and 2: quaternion
/// components within 1e-5, and 5e-5 where a strength other than 1 scales the angle through
/// the GPU's own atan2, sin and cos (lavapipe: 5.8e-6 at strength 2). Displacements as large as the leaf (an edge turned onto the tip's
/// axis) make the turn ill-conditioned, and fused multiply-adds then move it further (1.7e-5
/// on an NVIDIA H200, 2026-12-04); sylva-core's `ten_minutes_of_hurricane_stay_stable_and_recover`
/// covers such shapes.
#[test]
fn hsm_leaf_pose_matches_the_cpu() {
    use sylva_core::methods::hsm::kernels::hsm_leaf_pose;
    use sylva_core::methods::hsm::{RawHsmClusterState, RawHsmLeaf, RawHsmSlot};
    let Some(ctx) = common::gpu() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    let (segments, clusters, leaves, ring) = (50usize, 80usize, 500usize, 4u32);
    let rot = |rng: &mut rand::rngs::StdRng| {
        let axis = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        Quat::from_axis_angle(axis.normalize_or(Vec3::Y), rng.random_range(0.0..3.0)).to_array()
    };
    let vec = |rng: &mut rand::rngs::StdRng, r: f32| {
        [rng.random_range(-r..r), rng.random_range(-r..r), rng.random_range(-r..r)]
    };
    let mut acc: Vec<[f32; 4]> = (0..segments).map(|_| rot(&mut rng)).collect();
    acc[0] = [0.0, 0.0, 0.0, 1.0];
    let mut state = vec![<RawHsmClusterState as bytemuck::Zeroable>::zeroed(); clusters];
    for s in &mut state {
        s.rotation = rot(&mut rng);
    }
    state[0].rotation = [0.0, 0.0, 0.0, 1.0];
    let (mut slots, mut displacement, mut blades) = (Vec::new(), Vec::new(), Vec::new());
    let mut at_rest = vec![false; leaves];
    for (l, rest) in at_rest.iter_mut().enumerate() {
        let blade = if l % 10 == 3 { 1 } else { 2 };
        *rest = l % 10 == 1;
        // A leaf's shape at rest: a tip 3–6 cm out, an edge 2–4 cm across it.
        let tip = Vec3::from_array(vec(&mut rng, 1.0)).normalize_or(Vec3::Y);
        let across = tip.any_orthonormal_vector();
        let across = Quat::from_axis_angle(tip, rng.random_range(0.0..std::f32::consts::TAU)) * across;
        let lf = RawHsmLeaf {
            tip: (tip * rng.random_range(0.03..0.06)).to_array(),
            segment: if *rest { 0 } else { rng.random_range(0..segments as u32) },
            edge: if blade > 1 { (across * rng.random_range(0.02..0.04)).to_array() } else { [0.0; 3] },
            slot_offset: slots.len() as u32,
            attach: vec(&mut rng, 0.02),
            cluster: if *rest { 0 } else { rng.random_range(0..clusters as u32) },
            ring: if l % 10 == 0 { 0 } else { ring },
            blade,
            strength: [1.0, 1.0, 1.0, 1.0, 1.0, 0.5, 1.0, 2.0, 1.0, 0.0][l % 10],
            _pad: 0,
        };
        // The blade's particles carried by its cluster's rotation, then displaced by a few
        // millimetres: the leaf turns by up to about 20° against its cluster.
        let r = Quat::from_array(state[lf.cluster as usize].rotation);
        let attach = Vec3::from_array(lf.attach);
        let rest_of = |j: u32| match j.checked_sub(ring) {
            Some(0) => attach + Vec3::from_array(lf.tip),
            Some(_) => attach + Vec3::from_array(lf.edge),
            None => Vec3::ZERO,
        };
        for j in 0..ring + blade {
            slots.push(RawHsmSlot { q: [0.0; 3], particle: displacement.len() as u32 });
            let u = if *rest {
                Vec3::ZERO
            } else {
                let x = rest_of(j);
                r * x - x + Vec3::from_array(vec(&mut rng, 0.003))
            };
            displacement.push([u.x, u.y, u.z, 1e-4]);
        }
        blades.push(lf);
    }
    let mut cpu = vec![[0.0f32; 4]; leaves];
    hsm_leaf_pose(&blades, &slots, &displacement, &state, &acc, &mut cpu);
    let buffers = [
        upload(ctx, "leaves", &blades).unwrap(),
        upload(ctx, "slots", &slots).unwrap(),
        upload(ctx, "displacements", &displacement).unwrap(),
        upload(ctx, "state", &state).unwrap(),
        upload(ctx, "acc", &acc).unwrap(),
        upload(ctx, "out", &vec![[0.0f32; 4]; leaves]).unwrap(),
    ];
    let kernel = sylva_gpu::kernel::Kernel::get(ctx, "hsm_leaf_pose");
    let mut e = ctx.device.create_command_encoder(&Default::default());
    kernel.record(ctx, &mut e, &buffers.iter().collect::<Vec<_>>(), leaves as u32);
    ctx.submit([e.finish()]);
    let gpu: Vec<[f32; 4]> = read_back(ctx, &buffers[5], leaves).unwrap();
    let mut worst = 0.0f32;
    for l in 0..leaves {
        if blades[l].ring == 0 || at_rest[l] || blades[l].strength == 0.0 {
            assert_eq!(gpu[l], [0.0, 0.0, 0.0, 1.0], "leaf {l}");
            assert_eq!(cpu[l], [0.0, 0.0, 0.0, 1.0], "leaf {l}");
        } else {
            assert!((Quat::from_array(cpu[l]).length() - 1.0).abs() < 1e-5, "leaf {l}: {:?}", cpu[l]);
        }
        // A strength other than 1 scales the turn's angle through atan2, sin and cos, which a
        // GPU computes with its own approximations.
        let tolerance = if blades[l].strength == 1.0 { 1e-5 } else { 5e-5 };
        for k in 0..4 {
            worst = worst.max((gpu[l][k] - cpu[l][k]).abs());
            assert!(
                (gpu[l][k] - cpu[l][k]).abs() <= tolerance,
                "leaf {l}: GPU {:?}, CPU {:?} (tolerance {tolerance})",
                gpu[l],
                cpu[l]
            );
        }
    }
    println!("hsm_leaf_pose: worst component difference {worst:.2e}");
}

/// The leaf mesher turning leaves by random rotations, GPU against CPU, within the mesh
/// parity's bounds (positions 1e-5 × tree height, normals 1e-3); leaves with the identity
/// mesh exactly as at rest on both.
#[test]
fn meshed_leaves_follow_their_rotations_on_both() {
    let Some(ctx) = common::gpu() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(9);
    let t = Arc::new(tree("quaking_aspen", 4, 0.1));
    let layout = MeshLayout::new(&t, MeshParams::default()).unwrap();
    let mesh = GpuMesh::new(ctx, &layout).unwrap();
    let mut seam = random_seam(&t, &mut rng);
    let rest = layout.mesh_seam(&seam.joints, &seam.acc, &[]);
    seam.leaf = (0..t.leaves.len())
        .map(|l| {
            if l % 3 == 0 {
                [0.0, 0.0, 0.0, 1.0]
            } else {
                Quat::from_axis_angle(
                    Vec3::new(rng.random_range(-1.0..1.0), 1.0, 0.3).normalize(),
                    rng.random_range(0.1..2.0),
                )
                .to_array()
            }
        })
        .collect();
    let cpu = layout.mesh_seam(&seam.joints, &seam.acc, &seam.leaf);
    let mut e = ctx.device.create_command_encoder(&Default::default());
    mesh.record_seam(ctx, &mut e, &seam);
    ctx.submit([e.finish()]);
    let gpu = mesh.read(ctx).unwrap();
    let h = t.height();
    let stride = layout.params.leaf_sides as usize + 1;
    for (k, (a, b)) in gpu.leaves.iter().zip(&cpu.leaves).enumerate() {
        let d = (Vec3::from_array(a.position) - Vec3::from_array(b.position)).length();
        assert!(d <= 1e-5 * h, "leaf vertex {k}: GPU {:?}, CPU {:?}", a.position, b.position);
        let dn = (a.normal() - b.normal()).length();
        assert!(dn <= 1e-3, "leaf vertex {k}: normal {:?} vs {:?}", a.normal(), b.normal());
        let l = layout.leaves[k / stride].index as usize;
        if l % 3 == 0 {
            assert_eq!(b.position, rest.leaves[k].position, "leaf {l} at rest moved on the CPU");
        } else if k % stride > 0 {
            assert_ne!(b.position, rest.leaves[k].position, "leaf {l} did not turn");
        }
    }
}

/// Skinned leaves turned by their rotations: the CPU skin lands every leaf vertex where the
/// leaf mesher puts it (two independent paths, within 1e-5 × tree height), and the GPU skin
/// where the CPU skin does, for three instances sharing the leaves' rotations.
#[test]
fn skinned_leaves_follow_their_rotations() {
    use sylva_core::mesh::SkinLayout;
    use sylva_gpu::mesh::skin::GpuSkin;
    let mut rng = rand::rngs::StdRng::seed_from_u64(13);
    let t = tree("quaking_aspen", 6, 0.1);
    let layout = MeshLayout::new(&t, MeshParams::default()).unwrap();
    let skin = SkinLayout::new(&layout);
    let mut seam = random_seam(&t, &mut rng);
    seam.leaf = (0..t.leaves.len())
        .map(|_| {
            Quat::from_axis_angle(
                Vec3::new(0.3, 1.0, rng.random_range(-1.0..1.0)).normalize(),
                rng.random_range(0.0..2.5),
            )
            .to_array()
        })
        .collect();
    let h = t.height();
    let meshed = layout.mesh_seam(&seam.joints, &seam.acc, &seam.leaf);
    let skinned = skin.skin_with_leaves(&seam.joints, &seam.acc, &seam.leaf, 1);
    let at_rest = skin.skin(&seam.joints, &seam.acc, 1);
    let mut turned = 0;
    for (k, (a, b)) in skinned.leaves.iter().zip(&meshed.leaves).enumerate() {
        let d = (Vec3::from_array(a.position) - Vec3::from_array(b.position)).length();
        assert!(d <= 1e-5 * h, "leaf vertex {k}: skinned {:?}, meshed {:?}", a.position, b.position);
        turned += usize::from(a.position != at_rest.leaves[k].position);
    }
    assert!(2 * turned > skinned.leaves.len(), "only {turned} skinned leaf vertices turned");
    let Some(ctx) = common::gpu() else { return };
    let instances = 3u32;
    let joint: Vec<[f32; 4]> = seam.joints.iter().cycle().take(seam.joints.len() * 3).copied().collect();
    let acc: Vec<[f32; 4]> = seam.acc.iter().cycle().take(seam.acc.len() * 3).copied().collect();
    let cpu = skin.skin_with_leaves(&joint, &acc, &seam.leaf, instances);
    let g = GpuSkin::new(ctx, &layout, &skin, instances).unwrap();
    let (jb, ab, lb) =
        (upload(ctx, "j", &joint).unwrap(), upload(ctx, "a", &acc).unwrap(), upload(ctx, "l", &seam.leaf).unwrap());
    let mut e = ctx.device.create_command_encoder(&Default::default());
    g.record_with_leaves(ctx, &mut e, &jb, &ab, &lb);
    ctx.submit([e.finish()]);
    let gpu = g.read(ctx).unwrap();
    for (k, (a, b)) in gpu.leaves.iter().zip(&cpu.leaves).enumerate() {
        let d = (Vec3::from_array(a.position) - Vec3::from_array(b.position)).length();
        assert!(d <= 1e-5 * h, "skinned leaf vertex {k}: GPU {:?}, CPU {:?}", a.position, b.position);
        let dn = (a.normal() - b.normal()).length();
        assert!(dn <= 1e-3, "skinned leaf vertex {k}: normal {:?} vs {:?}", a.normal(), b.normal());
    }
}
