//! Generation speed (issue goals, one core): Quaking Aspen skeleton with leaves ≤ 10 ms;
//! an L-system of one million segments derived and interpreted ≤ 1 s.
//!
//! Run: `cargo bench -p sylva-core --bench generate`. Each benchmark runs inside a
//! one-thread rayon pool so the figures are single-core.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;
use sylva_core::species::SpeciesSource;
use sylva_core::{Grammar, LSystemOptions};

/// A binary tree of 2^20 − 1 = 1,048,575 segments after 20 steps (Skjermo's benchmark tree).
use sylva_bench::tables::BENCH_BINARY_TREE as MILLION;

fn one_core<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(f)
}

fn benches(c: &mut Criterion) {
    let aspen = SpeciesSource::resolve("quaking_aspen").unwrap();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let mut g = c.benchmark_group("generate_1core");
    g.bench_function("quaking_aspen", |b| {
        b.iter(|| pool.install(|| black_box(aspen.generate(1, &Default::default(), None).unwrap())))
    });
    g.bench_function("weeping_willow", |b| {
        let w = SpeciesSource::resolve("weeping_willow").unwrap();
        b.iter(|| pool.install(|| black_box(w.generate(1, &Default::default(), None).unwrap())))
    });
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    let grammar = Grammar::parse(MILLION, "million.lsys").unwrap();
    let opts = LSystemOptions { seed: 1, iterations: Some(20), ..Default::default() };
    let t = one_core(|| grammar.generate(&opts).unwrap());
    assert_eq!(t.segments.len(), (1 << 20) - 1);
    g.bench_function("lsystem_1m_segments", |b| {
        b.iter(|| pool.install(|| black_box(grammar.generate(&opts).unwrap())))
    });
    g.bench_function("lsystem_1m_derive_only", |b| {
        b.iter(|| pool.install(|| black_box(grammar.derive(&opts).unwrap())))
    });
    g.finish();
}

criterion_group!(generate, benches);
criterion_main!(generate);
