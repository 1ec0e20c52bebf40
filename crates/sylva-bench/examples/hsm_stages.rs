//! Times each stage of hierarchical shape matching on the CPU at Song's largest Table 2 size
//! (4,975 clusters of Quaking Aspen), or `C` copies of it: `cargo run --release -p sylva-core
//! --example hsm_stages [C]`; `WIND=<preset or file>` picks the wind (default `gusty`),
//! `N=<steps>` the number timed (default 50), `ONLY=clusters|fused` times that stage alone
//! (its data then stays in cache between steps, which the full step does not allow), and
//! `ONLY=step` whole steps, four-stage against fused, `ONLY=runs` the fused pass per particle
//! against the CPU's run pass (and checks that they agree bit for bit), `ONLY=groups` stage 1
//! per slot against the CPU's groups of slots (checking the bits too), `ONLY=digest` prints a
//! digest of the state after `N` more steps; `DEFAULT=1` uses the default clusters instead of
//! Song's sizes.

use std::time::Instant;
use sylva_core::methods::hsm::kernels::*;
use sylva_core::methods::hsm::*;
use sylva_core::species::SpeciesSource;
use sylva_core::wind::WindScene;
fn main() {
    let tree = SpeciesSource::resolve("quaking_aspen").unwrap().generate(1, &Default::default(), None).unwrap();
    // `DEFAULT=1`: the default clusters (rings of four, two-particle blades) instead of Song's.
    let params = if std::env::var_os("DEFAULT").is_some() { HsmParams::default() } else { HsmParams::song_tables() };
    let copies: usize = std::env::args().nth(1).map(|s| s.parse().unwrap()).unwrap_or(1);
    let one = HsmLayout::new(&tree, &params, Some(4975)).unwrap();
    let l = if copies > 1 { one.forest(copies, 30.0).unwrap() } else { one };
    let h = Hsm::from_layout(&tree, params, l);
    let l = &h.layout;
    let fw = WindScene::resolve(&std::env::var("WIND").unwrap_or("gusty".into())).unwrap().packed();
    let mut st = h.state_at_rest();
    let n: usize = std::env::var("N").map(|s| s.parse().unwrap()).unwrap_or(50);
    let only = std::env::var("ONLY").unwrap_or_default();
    for _ in 0..20 {
        h.step_packed(&fw.fields, &fw.waves, &mut st, 1.0 / 60.0);
    }

    if only == "digest" {
        // A digest of the state after `N` steps, to check that a change keeps the bits.
        for _ in 0..n {
            h.step_packed(&fw.fields, &fw.waves, &mut st, 1.0 / 60.0);
        }
        let mut d = 0u64;
        for x in st.displacement.iter().chain(&st.velocity).flatten() {
            d = (d ^ x.to_bits() as u64).wrapping_mul(0x100_0000_01b3);
        }
        println!("state digest after {} steps: {d:016x}", n + 20);
        return;
    }
    if only == "step" {
        // Whole steps (`Hsm::step`), four-stage and fused, alternating.
        let four = Hsm::from_layout(&tree, HsmParams { fused: false, ..params }, l.clone());
        let fused = Hsm::from_layout(&tree, HsmParams { fused: true, ..params }, l.clone());
        let (mut ta, mut tb) = (0.0, 0.0);
        for _ in 0..n {
            let t = Instant::now();
            four.step_packed(&fw.fields, &fw.waves, &mut st, 1.0 / 60.0);
            ta += t.elapsed().as_secs_f64();
            let t = Instant::now();
            fused.step_packed(&fw.fields, &fw.waves, &mut st, 1.0 / 60.0);
            tb += t.elapsed().as_secs_f64();
        }
        println!("Hsm::step: four-stage {:.1} steps/s, fused {:.1}", n as f64 / ta, n as f64 / tb);
        return;
    }
    let step = h.step_params(1.0, 1.0 / 60.0);
    if only == "groups" {
        // Stage 1 in the WGSL twin's shape against the CPU's groups of slots, from the same
        // state; the results must agree bit for bit.
        let groups = sylva_core::methods::hsm::slot_groups::HsmSlotGroups::new(l);
        let (mut a, mut b) = (st.clusters.clone(), st.clusters.clone());
        let (mut ta, mut tb) = (0.0, 0.0);
        let mut same = true;
        for _ in 0..n {
            let t = Instant::now();
            hsm_clusters(&fw.fields, &fw.waves, &l.info, &l.clusters, &l.slots, &st.displacement, step, &mut a);
            ta += t.elapsed().as_secs_f64();
            let t = Instant::now();
            sylva_core::methods::hsm::slot_groups::hsm_clusters_groups(
                &fw.fields,
                &fw.waves,
                l,
                &groups,
                &st.displacement,
                step,
                &mut b,
            );
            tb += t.elapsed().as_secs_f64();
            same &= bytemuck::cast_slice::<_, u32>(&a) == bytemuck::cast_slice::<_, u32>(&b);
        }
        println!("{} groups for {} slots; identical bits: {same}", groups.len(), l.slots.len());
        println!("per slot {:.3} ms, groups {:.3} ms", ta / n as f64 * 1e3, tb / n as f64 * 1e3);
        return;
    }
    if only == "runs" {
        // The fused pass per particle (the WGSL twin's shape) against the CPU's run pass, from
        // the same state; the results must agree bit for bit.
        let runs = sylva_core::methods::hsm::runs::HsmRuns::new(l);
        hsm_clusters(&fw.fields, &fw.waves, &l.info, &l.clusters, &l.slots, &st.displacement, step, &mut st.clusters);
        let (mut a, mut b) = (st.clone(), st.clone());
        let (mut ta, mut tb) = (0.0, 0.0);
        for _ in 0..n {
            let t = Instant::now();
            hsm_particles(
                &l.member_offset,
                &l.member,
                &a.clusters,
                &l.owner,
                step,
                &mut a.displacement,
                &mut a.velocity,
            );
            ta += t.elapsed().as_secs_f64();
            let t = Instant::now();
            sylva_core::methods::hsm::runs::hsm_particles_runs(
                l,
                &runs,
                &b.clusters,
                step,
                &mut b.displacement,
                &mut b.velocity,
            );
            tb += t.elapsed().as_secs_f64();
        }
        let same = a
            .displacement
            .iter()
            .flatten()
            .zip(b.displacement.iter().flatten())
            .all(|(x, y)| x.to_bits() == y.to_bits())
            && a.velocity.iter().flatten().zip(b.velocity.iter().flatten()).all(|(x, y)| x.to_bits() == y.to_bits());
        let np = l.particle_count() as f64;
        println!("{} runs for {} particles; identical bits: {same}", runs.len(), np);
        println!("per particle {:.3} ms, runs {:.3} ms", ta / n as f64 * 1e3, tb / n as f64 * 1e3);
        return;
    }
    let (mut t1, mut t3, mut t4, mut tf) = (0.0, 0.0, 0.0, 0.0);
    let timed = |acc: &mut f64, run: &mut dyn FnMut()| {
        let t = Instant::now();
        run();
        *acc += t.elapsed().as_secs_f64();
    };
    for _ in 0..n {
        if only != "fused" {
            timed(&mut t1, &mut || {
                hsm_clusters(
                    &fw.fields,
                    &fw.waves,
                    &l.info,
                    &l.clusters,
                    &l.slots,
                    &st.displacement,
                    step,
                    &mut st.clusters,
                )
            });
        }
        if only.is_empty() {
            timed(&mut t3, &mut || hsm_goals(&l.member_offset, &l.member, &st.clusters, &mut st.goal));
            timed(&mut t4, &mut || {
                hsm_integrate(&l.owner, &st.clusters, &st.goal, step, &mut st.displacement, &mut st.velocity)
            });
        }
        if only != "clusters" {
            timed(&mut tf, &mut || {
                hsm_particles(
                    &l.member_offset,
                    &l.member,
                    &st.clusters,
                    &l.owner,
                    step,
                    &mut st.displacement,
                    &mut st.velocity,
                )
            });
        }
    }
    let np = l.particle_count() as f64;
    println!("clusters {} particles {} slots {} members {}", l.cluster_count(), np, l.slots.len(), l.member.len());
    for (name, t) in [("clusters", t1), ("goals", t3), ("integrate", t4), ("fused", tf)] {
        println!("{name:>10}: {:.3} ms/step, {:.2} ns/particle", t / n as f64 * 1e3, t / n as f64 / np * 1e9);
    }
    println!("four-stage {:.1} steps/s, fused {:.1}", n as f64 / (t1 + t3 + t4), n as f64 / (t1 + tf));
}
