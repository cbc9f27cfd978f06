//! Stage benchmarks of the tilt-noise budget on an in-memory input: one hour of 3-channel tilt
//! at 10 Hz (36 000 samples per axis), Welch segments of 2^14 samples (the `tiltnoise budget
//! --nperseg 16384` setting), so the frequency grid has the same 8192 bins (DC dropped) as the
//! 12-hour whole-process comparison in `scripts/bench/compare_budget.py`.
//!
//! Groups:
//! * `welch`: `spectral::csd_matrix`, the full 3x3 cross-spectral matrix, on 1 hour and on 12
//!   hours (throughput in samples per channel; the 1-hour point is dominated by the per-call
//!   setup of window and FFT plan, the 12-hour point by the per-segment work);
//! * `tf`: `tf::plan` + `tf::evaluate` with `Method::Direct`, outputs X, phi, phi_a from the
//!   three tilt inputs, on the Welch grid without DC (throughput in frequencies);
//! * `tilt_budget`: `noise::ground_budget` of the three tilt inputs on that grid (throughput in
//!   frequencies);
//! * `budget_from_series`: the whole library job on a `TiltSeries` in memory (Welch -> TF ->
//!   budget), once for the whole record and once split into two half-hour segments (per-segment
//!   Welch accumulators, tilt PSD and percentile band).
//!
//! Run with `cargo bench --bench budget`; CI only builds it (`cargo bench --no-run`). Sample
//! sizes are small on purpose (2-core shared machine); read ratios, not absolute times.

use std::hint::black_box;
use std::path::PathBuf;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use tiltnoise_core::budget::{budget_from_series, BudgetOptions};
use tiltnoise_core::input::{InputFormat, InputKind, Provenance, Quantity, TiltSeries};
use tiltnoise_core::model::{Model, Observable, TiltAxis};
use tiltnoise_core::noise::{ground_budget, GroundCsd, Readout};
use tiltnoise_core::params::Params;
use tiltnoise_core::spectral::{csd_matrix, CrossSpectra, WelchConfig};
use tiltnoise_core::tf::{self, Input, Method, Request, TransferMatrix};

const FS_HZ: f64 = 10.0;
const N_SAMPLES: usize = 3600 * 10;
const NPERSEG: usize = 1 << 14;

/// Deterministic red, correlated 3-axis tilt (rad): LCG uniform noise -> first-order low-pass
/// (pole 0.9995) plus a white floor, mixed so that the axes are correlated; constant offsets.
/// The same recipe as `scripts/bench/make_inputs.py`, not the same numbers.
fn tilt_channels(n: usize) -> Vec<Vec<f64>> {
    let mut state = 0x2024_0301_u64;
    let mut uniform = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let pole = 0.9995;
    let mut red = [0.0f64; 3];
    let mix = [[1.0, 0.0, 0.0], [0.55, 0.85, 0.0], [0.05, 0.10, 0.30]];
    let offset = [3.0e-6, -1.2e-6, 4.0e-7];
    let mut out: Vec<Vec<f64>> = (0..3).map(|_| Vec::with_capacity(n)).collect();
    for _ in 0..n {
        let mut src = [0.0; 3];
        for (r, s) in red.iter_mut().zip(src.iter_mut()) {
            *r = pole * *r + 5.2e-11 * uniform();
            *s = *r + 7e-11 * uniform();
        }
        for (c, ch) in out.iter_mut().enumerate() {
            ch.push(offset[c] + (0..3).map(|k| mix[c][k] * src[k]).sum::<f64>());
        }
    }
    out
}

fn series(data: Vec<Vec<f64>>) -> TiltSeries {
    TiltSeries {
        sample_rate_hz: FS_HZ,
        axes: TiltAxis::ALL.to_vec(),
        data,
        translations: Vec::new(),
        sensors: Default::default(),
        provenance: Provenance {
            path: PathBuf::from("bench:memory"),
            format: InputFormat::Hdf5,
            kind: InputKind::Series,
            quantity: Quantity::Angle,
            axis_map: "theta_t=theta_t,eta_t=eta_t,phi_t=phi_t".into(),
            start_time: None,
            notes: Vec::new(),
        },
    }
}

fn request() -> Request {
    Request {
        outputs: vec![Observable::X, Observable::Phi, Observable::PhiA],
        inputs: Input::all_tilts(),
    }
}

fn welch_cfg() -> WelchConfig {
    WelchConfig::new(NPERSEG)
}

fn welch_matrix(data: &[Vec<f64>]) -> CrossSpectra {
    let views: Vec<&[f64]> = data.iter().map(Vec::as_slice).collect();
    csd_matrix(&views, FS_HZ, &welch_cfg()).expect("Welch of the bench series")
}

fn transfer(model: &Model, grid: &[f64]) -> TransferMatrix {
    let plan = tf::plan(model, &request(), Method::Direct).expect("direct plans every request");
    tf::evaluate(plan.as_ref(), grid).expect("no resonance on the Welch grid")
}

fn stages(c: &mut Criterion) {
    let model = Model::new(&Params::table_i()).expect("Table I is valid");
    let data = tilt_channels(N_SAMPLES);
    let spectra = welch_matrix(&data);
    let grid = spectra.freqs_hz[1..].to_vec();
    let n = spectra.n_channels;
    let tf = transfer(&model, &grid);
    let inputs = Input::all_tilts();

    let mut g = c.benchmark_group("welch");
    g.sample_size(10).warm_up_time(Duration::from_millis(500));
    g.measurement_time(Duration::from_secs(2));
    g.throughput(Throughput::Elements(N_SAMPLES as u64));
    g.bench_function("csd_matrix_3ch_1h_nperseg16384", |b| {
        b.iter(|| welch_matrix(black_box(&data)))
    });
    // 12 hours (the whole-process comparison's input length): with 51 instead of 3 segments the
    // per-call setup (window, FFT plan, buffers) is amortized; the difference between the two
    // points separates setup from per-segment cost.
    let long = tilt_channels(12 * N_SAMPLES);
    g.throughput(Throughput::Elements(long[0].len() as u64));
    g.bench_function("csd_matrix_3ch_12h_nperseg16384", |b| {
        b.iter(|| welch_matrix(black_box(&long)))
    });
    drop(long);
    g.finish();

    let mut g = c.benchmark_group("tf");
    g.sample_size(10).warm_up_time(Duration::from_millis(500));
    g.measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Elements(grid.len() as u64));
    g.bench_function("direct_plan_evaluate_3x3_8192f", |b| {
        b.iter(|| transfer(black_box(&model), black_box(&grid)))
    });
    g.finish();

    let mut g = c.benchmark_group("tilt_budget");
    g.sample_size(10).warm_up_time(Duration::from_millis(500));
    g.measurement_time(Duration::from_secs(2));
    g.throughput(Throughput::Elements(grid.len() as u64));
    let readout = Readout::default();
    g.bench_function("3obs_3axes_8192f", |b| {
        b.iter(|| {
            ground_budget(
                black_box(&tf),
                &GroundCsd {
                    inputs: &inputs,
                    csd: black_box(&spectra.data[n * n..]),
                },
                &readout,
            )
        })
    });
    g.finish();

    let mut g = c.benchmark_group("budget_from_series");
    g.sample_size(10).warm_up_time(Duration::from_millis(500));
    g.measurement_time(Duration::from_secs(4));
    g.throughput(Throughput::Elements(N_SAMPLES as u64));
    let input = series(data.clone());
    for (name, segment_duration_s) in [("whole_1h", None), ("1h_in_2_segments", Some(1800.0))] {
        let opts = BudgetOptions {
            welch_segment_len: Some(NPERSEG),
            segment_duration_s,
            ..BudgetOptions::default()
        };
        g.bench_function(name, |b| {
            b.iter_batched(
                || input.clone(),
                |mut s| budget_from_series(&model, &mut s, &opts, &mut |_, _| {}).expect("budget"),
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, stages);
criterion_main!(benches);
