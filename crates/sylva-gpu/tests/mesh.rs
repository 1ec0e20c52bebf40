//! Per-frame meshing: GPU (`mesh_tubes.wgsl`, `mesh_leaves.wgsl`) vs the CPU reference on
//! every preset and random poses, and meshing straight from a GPU method's pose buffers.

mod common;

use glam::{Quat, Vec3};
use rand::{Rng, SeedableRng};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::mesh::{MeshFrame, MeshLayout, MeshParams};
use sylva_core::methods::Method;
use sylva_core::methods::zioma::{Zioma, ZiomaParams};
use sylva_core::pose::Pose;
use sylva_core::species::{PRESETS, SpeciesSource};
use sylva_core::wind::WindScene;
use sylva_gpu::mesh::GpuMesh;
use sylva_gpu::methods::GpuAnimator;
use sylva_gpu::methods::zioma::GpuZioma;
use sylva_gpu::wind::GpuWind;

fn random_pose(t: &Tree, rng: &mut rand::rngs::StdRng) -> Pose {
    let delta: Vec<[f32; 4]> = (0..t.segments.len())
        .map(|_| {
            let axis = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            Quat::from_axis_angle(axis.normalize_or(Vec3::X), rng.random_range(-0.2..0.2)).to_array()
        })
        .collect();
    Pose::from_rotations(t, &delta)
}

/// The bounds: same counts, positions within 1e-5 × tree height, normals within
/// 1e-3 (texture coordinates are one static stream, made from the layout for both).
/// Returns the worst position difference / height.
fn compare(t: &Tree, cpu: &MeshFrame, gpu: &MeshFrame, what: &str) -> f32 {
    let h = t.height();
    assert_eq!(cpu.tubes.len(), gpu.tubes.len(), "{what}: bark vertex count");
    assert_eq!(cpu.leaves.len(), gpu.leaves.len(), "{what}: leaf vertex count");
    let mut worst = 0.0f32;
    for (k, (a, b)) in cpu.tubes.iter().zip(&gpu.tubes).chain(cpu.leaves.iter().zip(&gpu.leaves)).enumerate() {
        let d = (Vec3::from_array(a.position) - Vec3::from_array(b.position)).length();
        worst = worst.max(d / h);
        assert!(d <= 1e-5 * h, "{what}: vertex {k} {:?} vs {:?}", a.position, b.position);
        let dn = (a.normal() - b.normal()).length();
        assert!(dn <= 1e-3, "{what}: vertex {k} normal {:?} vs {:?}", a.normal(), b.normal());
    }
    worst
}

#[test]
fn gpu_mesh_matches_cpu_on_every_preset_and_random_poses() {
    let Some(ctx) = common::gpu() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(2026);
    for (k, preset) in PRESETS.iter().enumerate() {
        let t = SpeciesSource::resolve(preset.name).unwrap().generate(2, &Default::default(), None).unwrap();
        // Presets alternate between polygons of up to 8 sides, whose runs the kernels stage
        // in workgroup memory (`vertex_stage.wgsl`), and larger ones, written directly.
        let (sides, leaf_sides) = if k % 2 == 0 { (5..9, 4..9) } else { (9..12, 9..13) };
        let params = MeshParams {
            sides: rng.random_range(sides),
            samples: rng.random_range(1..4),
            leaf_sides: rng.random_range(leaf_sides),
            ..Default::default()
        };
        let layout = MeshLayout::new(&t, params).unwrap();
        let gpu = GpuMesh::new(ctx, &layout).unwrap();
        let pose = random_pose(&t, &mut rng);
        let worst = compare(&t, &layout.mesh(&t, &pose), &gpu.mesh(ctx, &t, &pose).unwrap(), preset.name);
        println!(
            "mesh {}: {} vertices, worst {worst:.1e} × height",
            preset.name,
            layout.tube_vertex_count() + layout.leaf_vertex_count()
        );
    }
}

/// Every leaf outline (row `shape` of the rim table both twins read), on random poses and
/// polygon sizes, within the same bounds.
#[test]
fn every_leaf_shape_meshes_alike_on_cpu_and_gpu() {
    let Some(ctx) = common::gpu() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(2027);
    let base = SpeciesSource::resolve("sassafras").unwrap().generate(3, &Default::default(), None).unwrap();
    for shape in sylva_core::model::LeafShape::ALL {
        let t = Tree { leaf_shape: shape, ..base.clone() };
        let params = MeshParams { leaf_sides: rng.random_range(3..24), ..Default::default() };
        let layout = MeshLayout::new(&t, params).unwrap();
        let gpu = GpuMesh::new(ctx, &layout).unwrap();
        let pose = random_pose(&t, &mut rng);
        let cpu = layout.mesh(&t, &pose);
        let worst = compare(&t, &cpu, &gpu.mesh(ctx, &t, &pose).unwrap(), shape.name());
        // The outline reaches the rim: the polar shapes' rims differ from the disc's ellipse.
        let rim = layout.leaf_uv().iter().map(|v| (v[0] - 0.5).abs()).fold(0.0f32, f32::max);
        println!(
            "leaf shape {:<6} ({} sides): widest rim {:.3}, worst {worst:.1e} × height",
            shape.name(),
            params.leaf_sides,
            rim
        );
    }
}

#[test]
fn gpu_mesh_reads_a_gpu_methods_pose_without_a_round_trip() {
    let Some(ctx) = common::gpu() else { return };
    let t = SpeciesSource::resolve("sassafras").unwrap().generate(4, &Default::default(), None).unwrap();
    let wind = WindScene::resolve("gusty").unwrap();
    let method = Zioma::new(&t, ZiomaParams::default());
    let mut g =
        GpuZioma::new(ctx, Arc::new(t.clone()), method.clone(), &GpuWind::from_scene(ctx, &wind).unwrap()).unwrap();
    let layout = MeshLayout::new(&t, MeshParams::default()).unwrap();
    let mesh = GpuMesh::new(ctx, &layout).unwrap();
    for time in [0.7f32, 3.1] {
        g.submit(ctx, time);
        let mut e = ctx.device.create_command_encoder(&Default::default());
        mesh.record(ctx, &mut e, g.pose_buffers().joints_buffer(), g.pose_buffers().acc_buffer());
        ctx.submit([e.finish()]);
        let on_gpu = mesh.read(ctx).unwrap();
        let pose = g.pose_buffers().read(ctx).unwrap();
        let worst = compare(&t, &layout.mesh(&t, &pose), &on_gpu, &format!("zioma t = {time}"));
        println!("zioma t = {time}: worst {worst:.1e} × height");
        // The wind moved it: not the rest mesh.
        let rest = layout.mesh(&t, &Pose::rest(&t));
        assert!(rest.tubes.iter().zip(&on_gpu.tubes).any(|(a, b)| a.position != b.position));
    }
}

#[test]
fn gpu_skinning_matches_cpu_for_many_instances() {
    use sylva_core::mesh::SkinLayout;
    use sylva_gpu::mesh::skin::GpuSkin;
    let Some(ctx) = common::gpu() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(77);
    let t = SpeciesSource::resolve("quaking_aspen").unwrap().generate(1, &Default::default(), None).unwrap();
    let layout = MeshLayout::new(&t, MeshParams::default()).unwrap();
    let skin = SkinLayout::new(&layout);
    let instances = 5u32;
    let (mut joint, mut acc) = (Vec::new(), Vec::new());
    for _ in 0..instances {
        let (j, a) = sylva_core::pose::pose_buffers(&t, &random_pose(&t, &mut rng));
        joint.extend(j);
        acc.extend(a);
    }
    let cpu = skin.skin(&joint, &acc, instances);
    let (jb, ab) =
        (sylva_gpu::kernel::upload(ctx, "j", &joint).unwrap(), sylva_gpu::kernel::upload(ctx, "a", &acc).unwrap());
    // One batch, then batches of two (the split that keeps large forests under the
    // binding limit): the same vertices either way.
    for (max_batch, batches) in [(u32::MAX, 1), (2, 3)] {
        let g = GpuSkin::with_max_batch(ctx, &layout, &skin, instances, max_batch).unwrap();
        assert_eq!(g.batch_count(), batches);
        assert_eq!(g.draw_items(&jb).iter().map(|d| d.instance_count).sum::<u32>(), instances);
        let mut e = ctx.device.create_command_encoder(&Default::default());
        g.record(ctx, &mut e, &jb, &ab);
        ctx.submit([e.finish()]);
        let gpu = g.read(ctx).unwrap();
        let worst = compare(&t, &cpu, &gpu, "skinning");
        println!("skinning {instances} aspens in {batches} batch(es): worst {worst:.1e} × height");
    }
}

/// Skjermo's deformer: GPU vs CPU on every preset, on curves bent by a few seconds of wind
/// (CPU Skjermo steps), with random grid resolutions.
#[test]
fn gpu_deformer_matches_cpu_on_every_preset() {
    use sylva_core::mesh::{DeformLayout, DeformerParams, RawVertex};
    use sylva_core::methods::skjermo::{Skjermo, SkjermoParams};
    use sylva_gpu::mesh::deform::GpuDeform;
    let Some(ctx) = common::gpu() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(31);
    let wind = WindScene::resolve("gusty").unwrap();
    let fieldswaves = wind.packed();
    for (k, preset) in PRESETS.iter().enumerate() {
        let t = SpeciesSource::resolve(preset.name).unwrap().generate(2, &Default::default(), None).unwrap();
        // Staged rings (up to 8 sides) and rings written directly, alternately.
        let params = DeformerParams {
            sides: rng.random_range(if k % 2 == 0 { 5..9 } else { 9..12 }),
            rows_per_segment: rng.random_range(1..4),
            bulges: rng.random_range(0.0..4.0),
            bulge_depth: rng.random_range(0.0..0.1),
            ..DeformerParams::for_tree(&t)
        };
        let layout = DeformLayout::new(&t, params).unwrap();
        let m = Skjermo::new(&t, SkjermoParams::default());
        let mut state = m.rest_state(&t);
        for _ in 0..rng.random_range(10..40) {
            m.step(&t, &fieldswaves, &mut state, 1.0 / 30.0);
        }
        let mut cpu = vec![bytemuck::Zeroable::zeroed(); layout.vertex_count()];
        sylva_core::mesh::skjermo_deform(
            &layout.info(),
            &layout.rings,
            &layout.shapes,
            &m.stems,
            &state.stems,
            &mut cpu,
        );
        let gpu: Vec<RawVertex> = GpuDeform::new(ctx, &layout, &m.stems).unwrap().deform(ctx, &state.stems).unwrap();
        let frame = |v: Vec<RawVertex>| MeshFrame { tubes: v, leaves: Vec::new() };
        let worst = compare(&t, &frame(cpu), &frame(gpu), &format!("deformer {}", preset.name));
        println!("deformer {}: {} vertices, worst {worst:.1e} × height", preset.name, layout.vertex_count());
    }
}

/// `oct_encode` / `oct_decode` in `vertex.wgsl` against their CPU twins on random unit
/// vectors, the axes and the octahedron's fold: each snorm16 component within one step
/// (WGSL's division may differ from the CPU's by an ulp before rounding), decoding within
/// 1e-6.
#[test]
fn octahedral_normals_match_their_cpu_twin() {
    use sylva_core::mesh::{oct_decode, oct_encode};
    use sylva_gpu::kernel::{output, read_back, upload};
    let Some(ctx) = common::gpu() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    let mut normals: Vec<Vec3> =
        [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z, Vec3::new(1.0, 1.0, -1e-7)]
            .into_iter()
            .chain((0..4096).map(|_| {
                Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
            }))
            .map(|n| n.normalize_or(Vec3::Z))
            .collect();
    normals.push(Vec3::ZERO);
    let cpu_bits: Vec<u32> = normals.iter().map(|&n| oct_encode(n)).collect();
    let src = format!(
        "{}
@group(0) @binding(0) var<storage, read> normal: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> bits: array<u32>;
@group(0) @binding(2) var<storage, read_write> encoded: array<u32>;
@group(0) @binding(3) var<storage, read_write> decoded: array<vec4<f32>>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {{
    let i = gid.x;
    if (i < arrayLength(&bits)) {{
        encoded[i] = oct_encode(normal[i].xyz);
        decoded[i] = vec4<f32>(oct_decode(bits[i]), 0.0);
    }}
}}",
        sylva_gpu::shaders::VERTEX
    );
    let module = ctx.device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("oct twin"),
        source: wgpu::ShaderSource::Wgsl(src.into()),
    });
    let pipeline = ctx.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("oct twin"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let n = normals.len();
    let padded: Vec<[f32; 4]> = normals.iter().map(|v| v.extend(0.0).to_array()).collect();
    let buffers = [
        upload(ctx, "normals", &padded).unwrap(),
        upload(ctx, "bits", &cpu_bits).unwrap(),
        output::<u32>(ctx, "encoded", n).unwrap(),
        output::<[f32; 4]>(ctx, "decoded", n).unwrap(),
    ];
    let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("oct twin"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &std::array::from_fn::<_, 4, _>(|i| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: buffers[i].as_entire_binding(),
        }),
    });
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(n.div_ceil(64) as u32, 1, 1);
    }
    ctx.submit([encoder.finish()]);
    let encoded: Vec<u32> = read_back(ctx, &buffers[2], n).unwrap();
    let decoded: Vec<[f32; 4]> = read_back(ctx, &buffers[3], n).unwrap();
    let component = |b: u32, k: u32| ((b >> (16 * k)) & 0xffff) as u16 as i16 as i32;
    for i in 0..n {
        for k in 0..2 {
            let (g, c) = (component(encoded[i], k), component(cpu_bits[i], k));
            assert!((g - c).abs() <= 1, "normal {i} {:?}: component {k} GPU {g} vs CPU {c}", normals[i]);
        }
        let d = (Vec3::from_slice(&decoded[i][..3]) - oct_decode(cpu_bits[i])).length();
        assert!(d <= 1e-6, "normal {i}: decoded {:?} vs {:?}", decoded[i], oct_decode(cpu_bits[i]));
    }
}

/// The bark and leaf kernels write the same vertices bit for bit whether their runs go
/// through workgroup memory or straight out (`GpuMesh::set_staged`), on a tree with partial
/// workgroups of rings and leaves.
#[test]
fn staged_and_direct_runs_write_the_same_bits() {
    let Some(ctx) = common::gpu() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(2031);
    let t = SpeciesSource::resolve("quaking_aspen").unwrap().generate(4, &Default::default(), None).unwrap();
    let layout = MeshLayout::new(&t, MeshParams::default()).unwrap();
    assert!(layout.rings.len() % 64 != 0 || layout.leaves.len() % 64 != 0, "a partial workgroup");
    let pose = random_pose(&t, &mut rng);
    let mut gpu = GpuMesh::new(ctx, &layout).unwrap();
    assert!(gpu.staged());
    let staged = gpu.mesh(ctx, &t, &pose).unwrap();
    gpu.set_staged(ctx, false);
    let direct = gpu.mesh(ctx, &t, &pose).unwrap();
    assert!(staged.tubes == direct.tubes && staged.leaves == direct.leaves, "staged and direct runs differ");
    compare(&t, &layout.mesh(&t, &pose), &staged, "staged");
}
