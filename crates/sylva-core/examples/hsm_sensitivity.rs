//! How far two CPU runs of hierarchical shape matching drift apart when one of them is
//! disturbed: by a velocity perturbation of `EPS` m/s at the start (default 1e-7), and with
//! `NOISE=1` also by one ulp on every particle's x every step, as a GPU that rounds
//! differently would. Prints, per preset, the largest particle distance (× tree height) after
//! 1, 2, 4, … steps. A result that stays the same however small `EPS` is means a jump (a
//! threshold) somewhere in the step; a smooth step gives differences that scale with it.
//!
//! `cargo run --release -p sylva-core --example hsm_sensitivity` (`WIND=` a preset or TOML
//! file, `STEPS=` default 1000; each tree cut to its first 150 clusters, as the GPU parity
//! test does).

use sylva_core::methods::hsm::{Hsm, HsmLayout, HsmParams};
use sylva_core::species::{PRESETS, SpeciesSource};
use sylva_core::wind::WindScene;

fn env<T: std::str::FromStr>(key: &str, default: T) -> T {
    std::env::var(key).ok().and_then(|s| s.parse().ok()).unwrap_or(default)
}

fn main() {
    let wind = WindScene::resolve(&env("WIND", "gusty".to_string())).expect("wind");
    let steps: usize = env("STEPS", 1000);
    let eps: f32 = env("EPS", 1e-7);
    let noise = std::env::var("NOISE").is_ok();
    let fw = wind.packed();
    let dt = 1.0 / 240.0;
    for p in PRESETS {
        let t = SpeciesSource::from_preset(p).unwrap().generate(1, &Default::default(), None).unwrap();
        let params = HsmParams { substeps: 1, ..Default::default() };
        let h = Hsm::from_layout(&t, params, HsmLayout::new(&t, &params, Some(150)).unwrap());
        let mut a = h.state_at_rest();
        let mut b = h.state_at_rest();
        // A fixed pseudo-random number in [−0.5, 0.5) per particle (and step).
        let hash = |i: usize, k: usize| {
            ((i as u32 ^ (k as u32).wrapping_mul(0x9E37_79B9)).wrapping_mul(2_654_435_761) >> 8) as f32
                / (1u32 << 24) as f32
                - 0.5
        };
        for (i, v) in b.velocity.iter_mut().enumerate() {
            if v[3] >= 0.0 {
                v[0] += eps * hash(i, 0);
                v[1] -= 0.5 * eps * hash(i, 0);
            }
        }
        let height = t.height();
        let mut line = String::new();
        for k in 1..=steps {
            h.step_packed(&fw.fields, &fw.waves, &mut a, dt);
            h.step_packed(&fw.fields, &fw.waves, &mut b, dt);
            if noise {
                for (i, x) in b.displacement.iter_mut().enumerate() {
                    x[0] *= 1.0 + hash(i, k).signum() * f32::EPSILON;
                }
            }
            if k.is_power_of_two() || k == steps {
                line += &format!(" {k}:{:.1e}", a.max_distance(&b) / height);
            }
        }
        let moved = a.max_distance(&h.state_at_rest()) / height;
        println!("{:<16} moved {moved:.2} × height | {line}", p.name);
    }
}
