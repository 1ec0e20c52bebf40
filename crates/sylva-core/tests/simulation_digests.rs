//! Pinned CPU simulations: 600 steps (10 s at 60 Hz) of every method on two presets in the
//! `gusty` wind, hashed every 100 steps (the method's whole state and the pose it gives).
//! A change here means every animation a user bakes or renders has changed; a refactor must
//! leave these bits alone. If a change of the dynamics is intended, run with
//! `SYLVA_BLESS=1` to print the new values and update `simulation_digests.txt`.

use sha2::{Digest, Sha256};
use sylva_core::Tree;
use sylva_core::methods::Method;
use sylva_core::methods::akagi::{Akagi, AkagiParams};
use sylva_core::methods::hsm::{Hsm, HsmParams};
use sylva_core::methods::skjermo::{Skjermo, SkjermoParams};
use sylva_core::methods::zioma::{Zioma, ZiomaParams};
use sylva_core::pose::Pose;
use sylva_core::species::SpeciesSource;
use sylva_core::wind::{PackedWind, WindScene};

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

/// Steps `m` 600 times through the seam, hashing `extra(state)` (the state's arrays and
/// time) and the pose every 100.
fn run<M: Method>(m: &M, tree: &Tree, wind: &PackedWind, h: &mut Sha256, extra: impl Fn(&M::State, &mut Sha256)) {
    let mut s = m.rest_state(tree);
    for k in 1..=STEPS {
        m.step(tree, wind, &mut s, DT);
        if k % 100 == 0 {
            extra(&s, h);
            hash_pose(h, &m.pose(tree, wind, &s));
        }
    }
}

/// Runs `method` on `tree` and returns the digest of its states and poses every 100 steps.
fn digest(tree: &Tree, method: &str) -> String {
    let wind = WindScene::resolve("gusty").unwrap().packed();
    let mut h = Sha256::new();
    match method {
        "zioma" => {
            let m = Zioma::new(tree, ZiomaParams { seed: 5, ..Default::default() });
            run(&m, tree, &wind, &mut h, |s, h| {
                h.update(bytemuck::cast_slice(&m.rotations_packed(tree, &wind.fields, &wind.waves, s.time)))
            });
        }
        "akagi" => run(&Akagi::new(tree, AkagiParams::default()), tree, &wind, &mut h, |s, h| {
            h.update(bytemuck::cast_slice(&s.theta));
            h.update(bytemuck::cast_slice(&s.omega));
            h.update(bytemuck::cast_slice(&s.acc));
            h.update(s.time.to_le_bytes());
        }),
        "skjermo" => run(&Skjermo::new(tree, SkjermoParams::default()), tree, &wind, &mut h, |s, h| {
            h.update(bytemuck::cast_slice(&s.stems));
            h.update(s.time.to_le_bytes());
        }),
        "hsm" => run(&Hsm::new(tree, HsmParams::default()).unwrap(), tree, &wind, &mut h, |s, h| {
            h.update(bytemuck::cast_slice(&s.displacement));
            h.update(bytemuck::cast_slice(&s.velocity));
            h.update(bytemuck::cast_slice(&s.clusters));
            h.update(s.time.to_le_bytes());
        }),
        other => panic!("unknown method {other}"),
    }
    format!("{:x}", h.finalize())
}

/// Checks the pinned line of `preset` and `method`: the same digest on one thread and on
/// three, and the pinned one (or, with `SYLVA_BLESS`, prints it).
fn check(preset: &str, method: &str) {
    let pinned = include_str!("simulation_digests.txt");
    let line = pinned
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| l.split_whitespace().collect::<Vec<_>>())
        .find(|f| f[0] == preset && f[2] == method)
        .unwrap_or_else(|| panic!("simulation_digests.txt has no line for {preset} {method}"));
    let (seed, want) = (line[1].parse::<u64>().unwrap(), line[3]);
    let tree = SpeciesSource::resolve(preset).unwrap().generate(seed, &Default::default(), None).unwrap();
    let mut got = Vec::new();
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        got.push(pool.install(|| digest(&tree, method)));
    }
    assert_eq!(got[0], got[1], "{preset} {method}: the simulation depends on the thread count");
    if std::env::var("SYLVA_BLESS").is_ok() {
        println!("{preset} {seed} {method} {}", got[0]);
    } else {
        assert_eq!(got[0], want, "{preset} seed {seed} {method}: the simulation changed (see the module docs)");
    }
}

/// One test per pinned line (two presets × four methods), so that the harness runs them
/// side by side.
macro_rules! pinned {
    ($($name:ident: $preset:literal $method:literal;)*) => {$(
        #[test]
        fn $name() {
            check($preset, $method);
        }
    )*};
}

pinned! {
    palm_zioma_matches_its_digest_on_1_and_3_threads: "palm" "zioma";
    palm_akagi_matches_its_digest_on_1_and_3_threads: "palm" "akagi";
    palm_skjermo_matches_its_digest_on_1_and_3_threads: "palm" "skjermo";
    palm_hsm_matches_its_digest_on_1_and_3_threads: "palm" "hsm";
    sympodial_zioma_matches_its_digest_on_1_and_3_threads: "sympodial" "zioma";
    sympodial_akagi_matches_its_digest_on_1_and_3_threads: "sympodial" "akagi";
    sympodial_skjermo_matches_its_digest_on_1_and_3_threads: "sympodial" "skjermo";
    sympodial_hsm_matches_its_digest_on_1_and_3_threads: "sympodial" "hsm";
}

/// Every pinned line has its test above.
#[test]
fn every_pinned_line_is_checked() {
    let lines = include_str!("simulation_digests.txt").lines().filter(|l| !l.trim().is_empty() && !l.starts_with('#'));
    assert_eq!(lines.count(), 8, "two presets × four methods: add a test for a new line");
}
