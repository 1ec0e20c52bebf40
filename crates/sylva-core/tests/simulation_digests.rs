//! Pinned CPU simulations: 600 steps (10 s at 60 Hz) of every method on two presets in the
//! `gusty` wind, hashed every 100 steps (the method's whole state and the pose it gives).
//! A change here means every animation a user bakes or renders has changed; a refactor must
//! leave these bits alone. If a change of the dynamics is intended, run with
//! `SYLVA_BLESS=1` to print the new values and update `simulation_digests.txt`.

use sha2::{Digest, Sha256};
use sylva_core::Tree;
use sylva_core::animate::Pose;
use sylva_core::animate::akagi::{Akagi, AkagiParams};
use sylva_core::animate::hsm::{Hsm, HsmParams};
use sylva_core::animate::skjermo::{Skjermo, SkjermoParams};
use sylva_core::animate::zioma::{Zioma, ZiomaParams};
use sylva_core::species::SpeciesSource;
use sylva_core::wind::WindScene;

const STEPS: usize = 600;
const DT: f32 = 1.0 / 60.0;

fn hash_pose(h: &mut Sha256, pose: &Pose) {
    for p in &pose.start {
        h.update(bytemuck::cast_slice(&p.to_array()));
    }
    for q in &pose.orientation {
        h.update(bytemuck::cast_slice(&q.to_array()));
    }
    if let Some(b) = &pose.bezier {
        for c in b {
            for p in c {
                h.update(bytemuck::cast_slice(&p.to_array()));
            }
        }
    }
}

/// Runs `method` on `tree` and returns the digest of its states and poses every 100 steps.
fn run(tree: &Tree, method: &str) -> String {
    let (fields, waves) = WindScene::resolve("gusty").unwrap().pack();
    let mut h = Sha256::new();
    match method {
        "zioma" => {
            let m = Zioma::new(tree, ZiomaParams { seed: 5, ..Default::default() });
            let mut t = 0.0f32;
            for k in 1..=STEPS {
                t += DT;
                if k % 100 == 0 {
                    h.update(bytemuck::cast_slice(&m.rotations_packed(tree, &fields, &waves, t)));
                    hash_pose(&mut h, &m.pose_packed(tree, &fields, &waves, t));
                }
            }
        }
        "akagi" => {
            let m = Akagi::new(tree, AkagiParams::default());
            let mut s = m.rest_state(tree);
            for k in 1..=STEPS {
                m.step(tree, &fields, &waves, &mut s, DT);
                if k % 100 == 0 {
                    h.update(bytemuck::cast_slice(&s.theta));
                    h.update(bytemuck::cast_slice(&s.omega));
                    h.update(bytemuck::cast_slice(&s.acc));
                    h.update(s.time.to_le_bytes());
                    hash_pose(&mut h, &s.pose);
                }
            }
        }
        "skjermo" => {
            let m = Skjermo::new(tree, SkjermoParams::default());
            let mut s = m.rest_state(tree);
            for k in 1..=STEPS {
                m.step(tree, &fields, &waves, &mut s, DT);
                if k % 100 == 0 {
                    h.update(bytemuck::cast_slice(&s.stems));
                    h.update(s.time.to_le_bytes());
                    hash_pose(&mut h, &s.pose);
                }
            }
        }
        "hsm" => {
            let m = Hsm::new(tree, HsmParams::default()).unwrap();
            let mut s = m.rest_state();
            for k in 1..=STEPS {
                m.step(&fields, &waves, &mut s, DT);
                if k % 100 == 0 {
                    h.update(bytemuck::cast_slice(&s.displacement));
                    h.update(bytemuck::cast_slice(&s.velocity));
                    h.update(bytemuck::cast_slice(&s.clusters));
                    h.update(s.time.to_le_bytes());
                    hash_pose(&mut h, &m.pose(tree, &s));
                }
            }
        }
        other => panic!("unknown method {other}"),
    }
    format!("{:x}", h.finalize())
}

#[test]
fn cpu_simulations_match_their_pinned_digests_on_1_and_3_threads() {
    let pinned = include_str!("simulation_digests.txt");
    let bless = std::env::var("SYLVA_BLESS").is_ok();
    let mut checked = 0;
    for line in pinned.lines().filter(|l| !l.trim().is_empty() && !l.starts_with('#')) {
        let mut it = line.split_whitespace();
        let (preset, seed, method, want) = (
            it.next().unwrap(),
            it.next().unwrap().parse::<u64>().unwrap(),
            it.next().unwrap(),
            it.next().unwrap(),
        );
        let tree = SpeciesSource::resolve(preset).unwrap().generate(seed, &Default::default(), None).unwrap();
        let mut got = Vec::new();
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            got.push(pool.install(|| run(&tree, method)));
        }
        assert_eq!(got[0], got[1], "{preset} {method}: the simulation depends on the thread count");
        if bless {
            println!("{preset} {seed} {method} {}", got[0]);
        } else {
            assert_eq!(got[0], want, "{preset} seed {seed} {method}: the simulation changed (see the module docs)");
        }
        checked += 1;
    }
    assert_eq!(checked, 8, "two presets × four methods");
}
