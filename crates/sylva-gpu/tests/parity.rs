//! CPU vs GPU: kernels agree with their CPU twins on random inputs.

mod common;

use glam::{Quat, Vec3};
use rand::{Rng, SeedableRng};
use sylva_core::model::RawSegment;
use sylva_core::species::SpeciesSource;

/// End points agree within 2e-6 of the segment's scale (|start| + length): both sides do
/// the same f32 operations, but the GPU may fuse multiply-adds.
const ENDS_REL_TOL: f32 = 2e-6;

fn compare(segments: &[RawSegment], max_groups_x: Option<u32>) -> f32 {
    let ctx = common::gpu().expect("checked by caller");
    let mut kernel = sylva_gpu::pose::segment_ends::kernel(ctx);
    if let Some(m) = max_groups_x {
        kernel = kernel.with_max_groups_x(m);
    }
    let gpu = sylva_gpu::pose::segment_ends::segment_ends_with(ctx, kernel, segments).unwrap();
    let mut cpu = vec![[0.0f32; 4]; segments.len()];
    sylva_core::pose::segment_ends::segment_ends(segments, &mut cpu);
    let mut worst: f32 = 0.0;
    for (i, s) in segments.iter().enumerate() {
        let scale = Vec3::from_array(s.start).length() + s.length + 1e-3;
        let d = (Vec3::from_slice(&gpu[i][..3]) - Vec3::from_slice(&cpu[i][..3])).length() / scale;
        assert!(d <= ENDS_REL_TOL, "segment {i}: GPU {:?} CPU {:?}", gpu[i], cpu[i]);
        assert_eq!(gpu[i][3], 1.0);
        worst = worst.max(d);
    }
    worst
}

#[test]
fn segment_ends_match_on_random_segments() {
    if common::gpu().is_none() {
        return;
    }
    let mut rng = rand::rngs::StdRng::seed_from_u64(0x5E6);
    let n = 300_000;
    let segments: Vec<RawSegment> = (0..n)
        .map(|_| {
            let axis = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
                .normalize_or(Vec3::Y);
            let q = Quat::from_axis_angle(axis, rng.random_range(-3.2..3.2));
            RawSegment {
                start: [rng.random_range(-50.0..50.0), rng.random_range(0.0..40.0), rng.random_range(-50.0..50.0)],
                length: rng.random_range(0.0..5.0),
                orientation: q.to_array(),
                ..bytemuck::Zeroable::zeroed()
            }
        })
        .collect();
    let worst = compare(&segments, None);
    println!("segment_ends: {n} random segments, worst relative difference {worst:e}");
    // The same with at most 1,000 workgroups in x: the dispatch spills into y (5 rows, the
    // last partly idle) and every element is still written exactly once.
    compare(&segments, Some(1_000));
}

#[test]
fn segment_ends_match_on_a_generated_tree() {
    if common::gpu().is_none() {
        return;
    }
    let tree = SpeciesSource::resolve("black_tupelo").unwrap().generate(4, &Default::default(), None).unwrap();
    compare(&tree.raw_segments(), None);
    // And the GPU ends are the model's own ends.
    let ctx = common::gpu().unwrap();
    let gpu = sylva_gpu::pose::segment_ends::segment_ends(ctx, &tree.raw_segments()).unwrap();
    for i in (0..tree.segments.len()).step_by(31) {
        assert!((Vec3::from_slice(&gpu[i][..3]) - tree.segments.end(i)).length() < 1e-4);
    }
}

#[test]
fn adapter_is_reported() {
    let Some(ctx) = common::gpu() else { return };
    let s = ctx.summary.to_string();
    assert!(!ctx.summary.name.is_empty(), "{s}");
    println!("adapter: {s}");
}

#[test]
fn oversized_input_is_a_clear_error() {
    let Some(ctx) = common::gpu() else { return };
    let limit = ctx.device.limits().max_storage_buffer_binding_size as usize;
    let n = limit / std::mem::size_of::<RawSegment>() + 1;
    if n > 3_000_000 {
        return; // A device with a huge binding limit: nothing to provoke cheaply.
    }
    let segments = vec![RawSegment { orientation: [0.0, 0.0, 0.0, 1.0], ..bytemuck::Zeroable::zeroed() }; n];
    let e = sylva_gpu::pose::segment_ends::segment_ends(ctx, &segments).unwrap_err().to_string();
    assert!(e.contains("segments") && e.contains("limit"), "{e}");
}
