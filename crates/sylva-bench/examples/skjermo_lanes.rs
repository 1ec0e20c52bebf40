//! Times Skjermo's fast CPU step (sixteen stems per lane group) on the benchmark's binary
//! tree: `cargo run --release -p sylva-core --example skjermo_lanes [ITERATIONS]` (16:
//! 65,535 stems, the default; 18: 262,143). `N=<steps>` sets the number timed (default 400).
//! For profiling the lane kernel alone, without the reference kernel the CLI bench also times.

use std::time::Instant;
use sylva_bench::tables::{BENCH_BINARY_TREE, BENCH_FOUR_SINES};
use sylva_core::methods::Method;
use sylva_core::methods::skjermo::{Skjermo, SkjermoParams};
use sylva_core::wind::WindScene;
use sylva_core::{Grammar, LSystemOptions};

fn main() {
    let iterations: u32 = std::env::args().nth(1).map(|s| s.parse().unwrap()).unwrap_or(16);
    let n: usize = std::env::var("N").map(|s| s.parse().unwrap()).unwrap_or(400);
    let fieldswaves = WindScene::from_toml(BENCH_FOUR_SINES, "four sines").unwrap().packed();
    let grammar = Grammar::parse(BENCH_BINARY_TREE, "binary.lsys").unwrap();
    let tree =
        grammar.generate(&LSystemOptions { seed: 1, iterations: Some(iterations), ..Default::default() }).unwrap();
    let m = Skjermo::new(&tree, SkjermoParams::default());
    let mut state = m.rest_state(&tree);
    for _ in 0..20 {
        m.step_stems(&fieldswaves.fields, &fieldswaves.waves, &mut state, 1.0 / 60.0);
    }
    let t = Instant::now();
    for _ in 0..n {
        m.step_stems(&fieldswaves.fields, &fieldswaves.waves, &mut state, 1.0 / 60.0);
    }
    let s = t.elapsed().as_secs_f64();
    println!("{} stems: {:.0} updates/s", tree.stems.len(), n as f64 / s);
}
