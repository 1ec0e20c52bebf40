//! How far hierarchical shape matching bends each preset against Akagi's beam model in the
//! same wind: the largest distance of any segment end from rest over 10 s of `gusty`
//! (sampled every 0.1 s), whole trees, HSM at its default 240 Hz (one substep per 1/240 s
//! step). Also the share of the segment clusters' mass whose rate `k` is above `1/h²`,
//! where HSM cannot hold the wood's stiffness (see `sylva_core::methods::hsm::kernels::MAX_WEIGHT`).
//!
//! `cargo run --release -p sylva-core --example hsm_bending` (`SPECIES=` one preset or file;
//! `WIND=` a preset or TOML file; `HZ=` HSM's rate, default 240, 960 for 16 substeps per
//! frame at 60 frames/s). Several minutes for all presets on two cores.

use sylva_core::methods::Method;
use sylva_core::methods::akagi::{Akagi, AkagiParams, max_tip_displacement};
use sylva_core::methods::hsm::{Hsm, HsmParams, kind};
use sylva_core::species::{PRESETS, SpeciesSource};
use sylva_core::wind::{PackedWind, WindScene};

fn main() {
    let wind = WindScene::resolve(&std::env::var("WIND").unwrap_or("gusty".into())).expect("wind");
    let fw = wind.packed();
    let names: Vec<String> = match std::env::var("SPECIES") {
        Ok(s) => vec![s],
        Err(_) => PRESETS.iter().map(|p| p.name.to_string()).collect(),
    };
    let hz: usize = std::env::var("HZ").ok().and_then(|s| s.parse().ok()).unwrap_or(240).max(10);
    let dt = 1.0f32 / hz as f32;
    let steps = 10 * hz;
    println!("| species | height, m | segment mass with k h² > 1 | HSM, m | Akagi, m | HSM / Akagi |");
    println!("| --- | ---: | ---: | ---: | ---: | ---: |");
    for name in names {
        let t = SpeciesSource::resolve(&name).expect("species").generate(1, &Default::default(), None).expect("tree");
        let h = Hsm::new(&t, HsmParams { substeps: 1, ..Default::default() }).expect("hsm");
        let (mut stiff, mut total) = (0.0f64, 0.0f64);
        for (c, info) in h.layout.clusters.iter().zip(&h.layout.info) {
            if info.kind == kind::SEGMENT {
                total += c.mass as f64;
                if c.rest_cm[3] * dt * dt > 1.0 {
                    stiff += c.mass as f64;
                }
            }
        }
        let mut s = h.state_at_rest();
        let mut hsm = 0.0f32;
        let a = Akagi::new(&t, AkagiParams::default());
        let mut sa = a.rest_state(&t);
        let mut akagi = 0.0f32;
        for k in 0..steps {
            h.step_packed(&fw.fields, &fw.waves, &mut s, dt);
            a.step(&t, &fw, &mut sa, dt);
            if k % (hz / 10) == 0 {
                hsm = hsm.max(max_tip_displacement(&t, &h.pose(&t, &PackedWind::calm(), &s)));
                akagi = akagi.max(max_tip_displacement(&t, &sa.pose));
            }
        }
        println!(
            "| {name} | {:.2} | {:.0} % | {hsm:.3} | {akagi:.3} | {:.1} |",
            t.height(),
            100.0 * stiff / total.max(1e-30),
            hsm / akagi.max(1e-30)
        );
    }
}
