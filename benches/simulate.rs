//! Free-motion simulation (target: 12 h of all 8 DoF at 0.1 s in at most 0.2 s), and the default
//! run's Welch ASDs of the seven observables. Run with `cargo bench --bench simulate`; the CLI end
//! to end is timed with hyperfine (docs/simulate.md).

use criterion::{criterion_group, criterion_main, Criterion};
use tiltnoise_core::model::Model;
use tiltnoise_core::params::Params;
use tiltnoise_core::simulate::{equal_energy_init, simulate, SimConfig, DEFAULT_MODE_ENERGY_J};
use tiltnoise_core::spectral::{welch, WelchConfig};

fn simulate_12_hours(c: &mut Criterion) {
    let model = Model::new(&Params::table_i()).expect("Table I is valid");
    let init = equal_energy_init(&model, DEFAULT_MODE_ENERGY_J);
    let cfg = SimConfig::default();
    let mut group = c.benchmark_group("simulate");
    group.sample_size(20);
    group.bench_function("12 h at 0.1 s, 8 DoF + 7 observables + X readout", |b| {
        b.iter(|| simulate(&model, &init, &cfg).expect("default run"))
    });
    let sim = simulate(&model, &init, &cfg).expect("default run");
    let wcfg = WelchConfig::new(1 << 17);
    group.bench_function("Welch ASDs of 7 observables (2^17 segment)", |b| {
        b.iter(|| {
            sim.observables
                .iter()
                .map(|(_, x)| welch(x, sim.fs_hz(), &wcfg).expect("long enough").psd[1])
                .sum::<f64>()
        })
    });
    group.finish();
}

criterion_group!(benches, simulate_12_hours);
criterion_main!(benches);
