//! Monte Carlo of the normal modes (target: 1e5 samples in at most 5 s on two cores).
//! Run with `cargo bench --bench mc`; CI only compiles it.

use criterion::{criterion_group, criterion_main, Criterion};
use tiltnoise_core::mc::{run, McConfig};
use tiltnoise_core::params::Params;

fn mc_1e5_samples(c: &mut Criterion) {
    let params = Params::table_i();
    let mut group = c.benchmark_group("mc");
    group.sample_size(10);
    for threads in [1, 2] {
        let cfg = McConfig {
            samples: 100_000,
            seed: 1,
            threads,
            ..McConfig::default_for(&params)
        };
        group.bench_function(format!("1e5 samples, {threads} thread(s)"), |b| {
            b.iter(|| run(&params, &cfg, &|_| {}).expect("default config runs"))
        });
    }
    group.finish();
}

criterion_group!(benches, mc_1e5_samples);
criterion_main!(benches);
