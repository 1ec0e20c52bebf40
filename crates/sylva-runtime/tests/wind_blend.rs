//! Skjermo §5 in a running world: an edit that changes the waves blends the old ones out,
//! then the new ones in, on every phase group's clock, and no tree jumps.

mod common;

use glam::Vec3;
use sylva_core::scene::Scene;
use sylva_core::wind::raw::kind;
use sylva_core::wind::{WindField, WindScene};
use sylva_runtime::World;

/// A palm and a copy in the `gusty` wind without its crown band (whose twitch of the fronds
/// would hide a jump) under `method` on the CPU. Under Zioma (a closed form of the wind) a
/// jump in the wind is a jump in the pose; under Akagi the copy is a phase group whose clock
/// runs ahead of the scene's. The wind file lives as long as the directory returned.
fn world(ctx: &std::sync::Arc<sylva_gpu::GpuContext>, method: &str) -> (World, tempfile::TempDir) {
    let mut wind = WindScene::resolve("gusty").unwrap();
    wind.fields.retain(|f| !matches!(f, WindField::Turbulence(t) if t.f_min >= 1.0));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gusty_air.toml");
    wind.save(&path).unwrap();
    let text = format!(
        "wind = {:?}\n[output]\nsim_rate = 60\n[[tree]]\nspecies = \"palm\"\nmethod = \"{method}\"\n\
         backend = \"cpu\"\ncopies = [{{ position = [6.0, 0.0, -4.0] }}]\n",
        path.display().to_string(),
    );
    let scene = Scene::from_toml(&text, "blend.toml", std::path::Path::new(".")).unwrap();
    (World::new(ctx.clone(), scene).unwrap(), dir)
}

/// The gusty scene with its sums of sines turned 90° and shortened: new waves.
fn turned(base: &WindScene) -> WindScene {
    let mut w = base.clone();
    for f in &mut w.fields {
        if let WindField::SumOfSines(s) = f {
            for wave in &mut s.waves {
                wave.direction_deg += 90.0;
                wave.wavelength *= 0.5;
            }
        }
    }
    w
}

/// Runs `world` 4 s, turns the waves, runs 3 s more; per simulation (phase group), the trunk
/// top's largest move in one step (m) before the edit, while the waves change (the 2 s after
/// it: the old ones blend out, then the new ones in), and once the new ones blow alone.
fn moves_around_an_edit(world: &mut World) -> Vec<(f32, f32, f32)> {
    let ctx = world.ctx().clone();
    let sims = world.trees()[0].simulations().len();
    let mut last: Vec<Option<Vec3>> = vec![None; sims];
    let mut step = |world: &mut World| -> Vec<f32> {
        world.step(1).unwrap();
        let tree = &world.trees()[0];
        let top = tree.tree.segments.len() - 1;
        tree.simulations()
            .iter()
            .zip(&mut last)
            .map(|(sim, last)| {
                let end = sim.pose(&ctx).unwrap().end(&tree.tree, top);
                let moved = last.map_or(0.0, |l| (end - l).length());
                *last = Some(end);
                moved
            })
            .collect()
    };
    let most = |steps: &[Vec<f32>], s: usize| steps.iter().map(|m| m[s]).fold(0.0f32, f32::max);
    let before: Vec<Vec<f32>> = (0..240).map(|_| step(world)).skip(60).collect();
    world
        .edit_wind(|w| {
            w.base = turned(&w.base);
            true
        })
        .unwrap();
    let after: Vec<Vec<f32>> = (0..180).map(|_| step(world)).collect();
    let (changing, settled) = after.split_at(120);
    (0..sims).map(|s| (most(&before, s), most(changing, s), most(settled, s))).collect()
}

#[test]
fn an_edit_of_the_waves_blends_them_out_then_in_on_every_clock_without_a_jump() {
    let Some(ctx) = common::gpu() else { return };
    let (mut blended, _wind) = world(&ctx, "zioma");
    assert_eq!(blended.wind().wave_blend, 1.0);
    let moves = moves_around_an_edit(&mut blended);
    // The new waves are in, blended in from 1 s after the edit (at 4 s); the old ones are
    // gone once their blend was over.
    let (base, blowing) = (&blended.wind().base, blended.wind().blowing());
    assert_eq!(blowing.fields.len(), base.fields.len(), "{blowing:#?}");
    let sines = blowing.fields.iter().find(|f| matches!(f, WindField::SumOfSines(_))).unwrap();
    let (fade_in, fade_out) = sines.fades().unwrap();
    assert!(fade_in.is_some_and(|f| (f.start - 5.0).abs() < 1e-3 && f.duration == 1.0), "{fade_in:?}");
    assert_eq!(fade_out, None);

    let (mut abrupt, _abrupt_wind) = world(&ctx, "zioma");
    abrupt.edit_wind(|w| std::mem::replace(&mut w.wave_blend, 0.0) != 0.0).unwrap();
    let jumps = moves_around_an_edit(&mut abrupt);
    // No step while the waves change is larger than the steps of the old waves or of the new
    // ones alone: the new, shorter waves may move the tree faster, but not at the switch.
    for (s, (&(before, changing, settled), &(abrupt_before, abrupt_changing, abrupt_settled))) in
        moves.iter().zip(&jumps).enumerate()
    {
        println!(
            "phase group {s}: trunk top's largest step {before:.5} m before the edit, {changing:.5} m while \
             the waves blended, {settled:.5} m after; switched at once {abrupt_before:.5} / {abrupt_changing:.5} \
             / {abrupt_settled:.5} m"
        );
        let steady = before.max(settled);
        assert!(changing <= 1.25 * steady, "group {s}: {changing} m in a step while blending, {steady} m steady");
        let abrupt_steady = abrupt_before.max(abrupt_settled);
        assert!(
            abrupt_changing > 2.0 * abrupt_steady,
            "group {s}: switching at once moved the top {abrupt_changing} m, {abrupt_steady} m steady"
        );
    }
}

/// While a blend runs, the outgoing waves are in the wind with their fade-out starting at the
/// edit, on the scene's clock and shifted by its lead on each phase group's; a reload
/// replaces the wind at once.
#[test]
fn the_outgoing_waves_blow_on_every_clock_until_their_blend_is_over() {
    use sylva_runtime::Simulation;
    let Some(ctx) = common::gpu() else { return };
    let (mut world, _wind) = world(&ctx, "akagi");
    assert!(world.trees()[0].has_leads(), "the copy should run ahead of the scene's clock");
    world.preroll(30);
    let at = world.time();
    world
        .edit_wind(|w| {
            w.base = turned(&w.base);
            true
        })
        .unwrap();
    let n = world.wind().base.fields.len();
    let outgoing = world.wind().blowing().fields[n..].to_vec();
    assert_eq!(outgoing.len(), 1, "{:#?}", world.wind().blowing());
    let out = outgoing[0].fades().unwrap().1.unwrap();
    assert!((out.start - at).abs() < 1e-5 && out.duration == 1.0, "{out:?}");
    let mut leads = Vec::new();
    for sim in world.trees()[0].simulations() {
        let Simulation::Cpu(a) = sim else { panic!("a CPU scene") };
        let lead = a.time() - world.time();
        // The packed fade-out start of the outgoing sines (`Fade::envelope`'s third slot).
        let waves = a.wind().fields.iter().filter(|f| [kind::SUM_OF_SINES, kind::TURBULENCE].contains(&f.kind));
        let starts: Vec<f32> = waves.map(|f| f.b[2]).filter(|s| s.abs() < 1e29).collect();
        assert_eq!(starts.len(), 1, "lead {lead} s: {starts:?}");
        assert!(
            (starts[0] - (at + lead)).abs() < 1e-3,
            "lead {lead} s: its blend starts at {} s, the edit at {at} s",
            starts[0]
        );
        leads.push(lead);
    }
    assert!(leads.iter().any(|l| *l > 0.5), "no phase group ahead: {leads:?}");
    world.step(60).unwrap();
    assert_eq!(world.wind().blowing().fields.len(), n + 1, "gone before its blend was over");
    world.step(2).unwrap();
    assert_eq!(world.wind().blowing().fields.len(), n, "still there after its blend");
    let scene = world.scene().clone();
    world
        .edit_wind(|w| {
            w.base = turned(&w.base);
            true
        })
        .unwrap();
    world.set_scene(scene).unwrap();
    assert_eq!(world.wind().blowing(), &world.wind().base, "a reload blends nothing");
}
