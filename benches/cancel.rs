//! How fast a set cancellation token stops each long entry point of the core (goal: within
//! 0.5 s): the token is set from another thread once the call has run for a while, and the
//! time from setting it to the call's return is printed. Run with `cargo bench --bench cancel`;
//! CI only compiles it. Figures and the machine are in scripts/bench/README.md.

use std::time::{Duration, Instant};
use tiltnoise_core::budget::{budget_from_series, BudgetError, BudgetOptions};
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::error::TfError;
use tiltnoise_core::input::{InputFormat, InputKind, Provenance, Quantity, TiltSeries};
use tiltnoise_core::mc::{self, McConfig, McError};
use tiltnoise_core::model::{Model, TiltAxis};
use tiltnoise_core::params::Params;
use tiltnoise_core::simulate::{equal_energy_init, simulate_with_progress, SimConfig, SimError};
use tiltnoise_core::spectral::{csd_matrix_cancellable, SpectralError, WelchConfig};
use tiltnoise_core::tf::{self, Destination, Input, Method, Request};

/// How long each call runs before the token is set.
const RUN_BEFORE_CANCEL: Duration = Duration::from_millis(500);

/// Runs `call` with a fresh token, sets the token after [`RUN_BEFORE_CANCEL`] and prints the
/// time from then to the return of `call`, which must return its `Cancelled` error (`true`).
fn measure(name: &str, call: impl FnOnce(Cancel) -> bool + Send) {
    let token = Cancel::new();
    let setter = token.clone();
    let (stopped, latency) = std::thread::scope(|s| {
        let worker = s.spawn(move || {
            let cancelled = call(token);
            (cancelled, Instant::now())
        });
        std::thread::sleep(RUN_BEFORE_CANCEL);
        let set_at = Instant::now();
        setter.cancel();
        let (cancelled, done) = worker.join().expect("the call does not panic");
        (cancelled, done.saturating_duration_since(set_at))
    });
    assert!(
        stopped,
        "{name}: finished before the token was set; make it longer"
    );
    println!("{name:<58} {:>8.1} ms", latency.as_secs_f64() * 1e3);
}

fn tilt_series(n: usize) -> TiltSeries {
    let x: Vec<f64> = (0..n).map(|k| 1e-7 * (k as f64 * 1e-3).sin()).collect();
    TiltSeries {
        sample_rate_hz: 10.0,
        axes: vec![TiltAxis::ThetaT, TiltAxis::EtaT],
        data: vec![x.clone(), x],
        translations: Vec::new(),
        sensors: Default::default(),
        provenance: Provenance {
            path: "(synthetic)".into(),
            format: InputFormat::Hdf5,
            kind: InputKind::Series,
            quantity: Quantity::Angle,
            axis_map: "theta_t=theta_t,eta_t=eta_t".into(),
            start_time: None,
            notes: Vec::new(),
        },
    }
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let params = Params::table_i();
    let model = Model::new(&params).expect("Table I builds");
    println!("time from setting the token to the return of the call:");
    measure("Monte Carlo, 1e7 draws, 2 threads", |cancel| {
        let cfg = McConfig {
            samples: 10_000_000,
            threads: 2,
            cancel,
            ..McConfig::default_for(&params)
        };
        matches!(mc::run(&params, &cfg, &|_| {}), Err(McError::Cancelled(_)))
    });
    measure("free simulation, 1.6e6 s at 0.1 s (in memory)", |cancel| {
        let cfg = SimConfig {
            duration_s: 1.6e6,
            cancel,
            ..SimConfig::default()
        };
        let init = equal_energy_init(&model, 1e-12);
        matches!(
            simulate_with_progress(&model, &init, &cfg, &mut |_, _| {}),
            Err(SimError::Cancelled(_))
        )
    });
    let series = tilt_series(30 * 86_400 * 10);
    measure(
        "streamed budget, 30 days at 10 Hz, 2 axes (in memory)",
        |cancel| {
            let opts = BudgetOptions {
                cancel,
                ..BudgetOptions::default()
            };
            matches!(
                budget_from_series(&model, &mut series.clone(), &opts, &mut |_, _| {}),
                Err(BudgetError::Cancelled(_))
            )
        },
    );
    measure(
        "Welch cross-spectra, 30 days at 10 Hz, 2 channels",
        |cancel| {
            let cfg = WelchConfig::new(1 << 16).with_overlap(1 << 15);
            let ch = [&series.data[0][..], &series.data[1][..]];
            matches!(
                csd_matrix_cancellable(&ch, 10.0, &cfg, &cancel),
                Err(SpectralError::Cancelled(_))
            )
        },
    );
    let request = Request {
        outputs: vec![tiltnoise_core::model::Observable::X],
        inputs: vec![Input::Tilt(TiltAxis::ThetaT)],
    };
    for (method, threads) in [
        (Method::PoleZero, 1),
        (Method::PoleZero, 2),
        (Method::Direct, 2),
    ] {
        let n = 100_000_000;
        let freqs: Vec<f64> = (0..n).map(|k| 1e-4 + k as f64 * 1e-6).collect();
        let plan = tf::plan(&model, &request, method).expect("plans");
        let mut out = vec![num_complex::Complex64::new(0.0, 0.0); n];
        measure(
            &format!("grid evaluation, 1e8 points, {method:?}, {threads} thread(s)"),
            |cancel| {
                let r = tf::eval_grid_threads_cancellable(
                    plan.as_ref(),
                    &freqs,
                    &mut out,
                    threads,
                    Destination::Reused,
                    &cancel,
                );
                matches!(r, Err(TfError::Cancelled(_)))
            },
        );
    }
}
