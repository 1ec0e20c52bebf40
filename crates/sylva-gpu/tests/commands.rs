//! The commands each GPU method records per step, as counted on the context
//! ([`sylva_gpu::GpuContext::counts`]): bind groups made once, a step's dispatches in one
//! compute pass, a frame's steps in one submission. One test in this binary, so that the
//! counts on the shared device are this test's alone.

mod common;

use std::sync::Arc;
use sylva_core::methods::hsm::{Hsm, HsmParams};
use sylva_core::methods::skjermo::{Skjermo, SkjermoParams};
use sylva_core::methods::zioma::{Zioma, ZiomaParams};
use sylva_core::species::SpeciesSource;
use sylva_core::wind::WindScene;
use sylva_gpu::methods::GpuAnimator;
use sylva_gpu::methods::hsm::{GpuHsm, SUBSTEPS_PER_PASS};
use sylva_gpu::methods::skjermo::{GpuSkjermo, STEPS_PER_PASS};
use sylva_gpu::methods::zioma::GpuZioma;
use sylva_gpu::wind::GpuWind;
use sylva_gpu::{GpuContext, GpuCounts};

/// What `f` records and submits (waits for the GPU before and after).
fn counted(ctx: &GpuContext, f: impl FnOnce()) -> GpuCounts {
    ctx.wait().unwrap();
    let before = ctx.counts();
    f();
    ctx.wait().unwrap();
    ctx.counts() - before
}

#[test]
fn steps_record_their_dispatches_in_one_pass_on_bind_groups_made_once() {
    let Some(ctx) = common::gpu() else { return };
    let tree =
        Arc::new(SpeciesSource::resolve("quaking_aspen").unwrap().generate(3, &Default::default(), None).unwrap());
    let wind = WindScene::resolve("gusty").unwrap();
    let gpu_wind = GpuWind::from_scene(ctx, &wind).unwrap();
    let calm = GpuWind::calm(ctx).unwrap();
    let dt = 1.0 / 60.0;

    // HSM: every substep is stage 1 and the fused particle pass, up to SUBSTEPS_PER_PASS
    // substeps in one pass (each reading its own slot of parameters); the pose (cluster
    // rotations, joints, leaves) is written once per submission, in a pass of its own.
    let hsm = Arc::new(Hsm::new(&tree, HsmParams::default()).unwrap());
    assert!(hsm.params.fused);
    let substeps = hsm.substeps(dt) as u64;
    let per_pass = SUBSTEPS_PER_PASS as u64;
    let mut g = GpuHsm::new(ctx, Some(tree.clone()), hsm, &gpu_wind).unwrap();
    let first = counted(ctx, || g.advance_steps(ctx, dt, 1));
    assert_eq!(first.bind_groups, 2 * per_pass, "each slot binds its two kernels, once: {first:?}");
    let frames = 4;
    let c = counted(ctx, || g.advance_steps(ctx, dt, frames));
    let pose = first.dispatches - 2 * substeps;
    let all = substeps * frames as u64;
    assert_eq!(c.submissions, 1, "{c:?}");
    assert_eq!(c.bind_groups, 0, "bind groups made once: {c:?}");
    assert_eq!(c.dispatches, 2 * all + pose, "{c:?}");
    assert_eq!(c.passes, all.div_ceil(per_pass) + 1, "substeps share a pass, the pose's dispatches too: {c:?}");
    println!("HSM, {substeps} substeps per step, {frames} steps in one call: {c:?}");
    // A new wind binds again, once.
    g.set_wind(&calm);
    let c = counted(ctx, || g.advance_steps(ctx, dt, 2));
    assert_eq!(c.bind_groups, 2 * per_pass, "stage 1 and the particle pass bound to the new wind: {c:?}");

    // Skjermo: a frame's steps in one submission, one dispatch each, up to STEPS_PER_PASS
    // of them in one pass (each reading its own slot of parameters), the pose once; every
    // slot's two steps (from either state buffer) bound on first use.
    let m = Skjermo::new(&tree, SkjermoParams::default());
    let mut g = GpuSkjermo::new(ctx, tree.clone(), &m, &gpu_wind).unwrap();
    let first = counted(ctx, || g.advance_steps(ctx, dt, 1, true));
    assert!(first.bind_groups >= 2 * STEPS_PER_PASS as u64, "{first:?}");
    let one = counted(ctx, || g.advance_steps(ctx, dt, 1, true));
    let five = counted(ctx, || g.advance_steps(ctx, dt, 5, true));
    let more = counted(ctx, || g.advance_steps(ctx, dt, STEPS_PER_PASS + 1, true));
    assert_eq!((one.submissions, five.submissions, more.submissions), (1, 1, 1), "{one:?} {five:?}");
    assert_eq!(five.dispatches, one.dispatches + 4, "one dispatch per further step: {one:?} {five:?}");
    assert_eq!(five.passes, one.passes, "five steps in the pass of one: {one:?} {five:?}");
    assert_eq!(more.passes, one.passes + 1, "a pass per {STEPS_PER_PASS} steps: {one:?} {more:?}");
    assert_eq!((one.bind_groups, five.bind_groups, more.bind_groups), (0, 0, 0), "{one:?} {five:?} {more:?}");
    println!("Skjermo, one step: {one:?}; five steps: {five:?}; {} steps: {more:?}", STEPS_PER_PASS + 1);

    // Zioma: the rotations, the pose and the leaves each in one pass on bind groups made
    // once; meshing the pose is one pass, and binds again only for other pose buffers.
    let mut g = GpuZioma::new(ctx, tree.clone(), Zioma::new(&tree, ZiomaParams::default()), &gpu_wind).unwrap();
    counted(ctx, || g.submit(ctx, 0.5));
    let c = counted(ctx, || g.submit(ctx, 0.6));
    assert_eq!((c.submissions, c.bind_groups), (1, 0), "{c:?}");
    assert!(c.passes <= 3 && c.dispatches >= 3, "{c:?}");
    println!("Zioma, one frame: {c:?}");
    let layout = sylva_core::mesh::MeshLayout::new(&tree, Default::default()).unwrap();
    let mesh = sylva_gpu::mesh::GpuMesh::new(ctx, &layout).unwrap();
    let record = |pose: &sylva_gpu::pose::GpuPose| {
        let mut e = ctx.device.create_command_encoder(&Default::default());
        mesh.record_with_leaves(ctx, &mut e, pose.joints_buffer(), pose.acc_buffer(), pose.leaf_buffer());
        ctx.submit([e.finish()]);
    };
    let kernels = [layout.rings.len(), layout.details.len(), layout.leaves.len()].iter().filter(|&&n| n > 0).count();
    let kernels = kernels as u64;
    assert!(kernels >= 2, "bark and leaves");
    let first = counted(ctx, || record(g.pose_buffers()));
    let again = counted(ctx, || record(g.pose_buffers()));
    assert_eq!((first.passes, first.dispatches, first.bind_groups), (1, kernels, kernels), "{first:?}");
    assert_eq!((again.passes, again.dispatches, again.bind_groups), (1, kernels, 0), "{again:?}");
    let other = GpuZioma::new(ctx, tree.clone(), Zioma::new(&tree, ZiomaParams::default()), &gpu_wind).unwrap();
    let rebound = counted(ctx, || record(other.pose_buffers()));
    assert_eq!(rebound.bind_groups, kernels, "other pose buffers bind again: {rebound:?}");
}
