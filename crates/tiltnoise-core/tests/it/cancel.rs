//! Every long entry point stops with its typed `Cancelled` error once its token is set: set
//! before the call, or set from inside the run (its progress callback) so that the poll inside
//! the loop is what stops it. No timing here: how fast an interrupt stops the command line is
//! measured by `benches/cancel.rs`.

use std::path::PathBuf;
use tiltnoise_core::budget::{budget_from_series, BudgetError, BudgetOptions, CHUNK_SAMPLES};
use tiltnoise_core::cancel::{Cancel, Cancelled};
use tiltnoise_core::coherence::{coherence_from_series, CoherenceError, CoherenceOptions, Record};
use tiltnoise_core::error::TfError;
use tiltnoise_core::fit::{fit, FitConfig, FitError, Measured};
use tiltnoise_core::input::{InputFormat, InputKind, Provenance, Quantity, TiltSeries};
use tiltnoise_core::mc::{self, McConfig, McError};
use tiltnoise_core::model::{Input, Model, Observable, TiltAxis};
use tiltnoise_core::params::Params;
use tiltnoise_core::simulate::driven::{simulate_driven, DrivenConfig, GroundDrive};
use tiltnoise_core::simulate::{
    equal_energy_init, simulate_with_progress, SimConfig, SimError, DEFAULT_MODE_ENERGY_J,
};
use tiltnoise_core::spectral::{
    csd_matrix_cancellable, SpectralError, WelchAccumulator, WelchConfig,
};
use tiltnoise_core::tf::{
    self, eval_grid_threads_cancellable, evaluate_into_cancellable, Destination, Method, Request,
};

fn cancelled() -> Cancel {
    let c = Cancel::new();
    c.cancel();
    c
}

fn model() -> Model {
    Model::new(&Params::table_i()).unwrap()
}

/// A slow sine, as long as asked, on two tilt axes.
fn tilt_series(n: usize) -> TiltSeries {
    let x: Vec<f64> = (0..n).map(|k| 1e-7 * (k as f64 * 1e-3).sin()).collect();
    TiltSeries {
        sample_rate_hz: 10.0,
        axes: vec![TiltAxis::ThetaT, TiltAxis::EtaT],
        data: vec![x.clone(), x],
        translations: Vec::new(),
        sensors: Default::default(),
        provenance: Provenance {
            path: PathBuf::from("(synthetic)"),
            format: InputFormat::Hdf5,
            kind: InputKind::Series,
            quantity: Quantity::Angle,
            axis_map: "theta_t=theta_t,eta_t=eta_t".into(),
            start_time: None,
            notes: Vec::new(),
        },
    }
}

#[test]
fn monte_carlo_stops_between_blocks_of_draws() {
    let p = Params::table_i();
    let cfg = McConfig {
        samples: 20_000,
        threads: 2,
        cancel: cancelled(),
        ..McConfig::default_for(&p)
    };
    assert!(matches!(
        mc::run(&p, &cfg, &|_| {}),
        Err(McError::Cancelled(Cancelled))
    ));
    // Set by the first progress report: the workers' own polls stop them.
    let token = Cancel::new();
    let cfg = McConfig {
        cancel: token.clone(),
        ..cfg
    };
    let e = mc::run(&p, &cfg, &|_| token.cancel()).unwrap_err();
    assert!(matches!(e, McError::Cancelled(Cancelled)), "{e}");
}

#[test]
fn simulation_stops_between_chunks() {
    let model = model();
    let init = equal_energy_init(&model, DEFAULT_MODE_ENERGY_J);
    let token = Cancel::new();
    let cfg = SimConfig {
        duration_s: 1e5,
        cancel: token.clone(),
        ..SimConfig::noiseless()
    };
    let mut calls = 0;
    let e = simulate_with_progress(&model, &init, &cfg, &mut |_, _| {
        calls += 1;
        token.cancel();
    })
    .unwrap_err();
    assert_eq!(e, SimError::Cancelled(Cancelled));
    assert_eq!(
        calls, 1,
        "stopped at the chunk after the one that set the token"
    );
}

#[test]
fn driven_simulation_stops() {
    let n = 1000;
    let drive = GroundDrive {
        step_s: 0.1,
        inputs: vec![Input::Tilt(TiltAxis::ThetaT)],
        samples: vec![(0..n).map(|j| 1e-9 * j as f64).collect()],
    };
    let cfg = DrivenConfig {
        keep_every: 1,
        readout_asd: Vec::new(),
        seed: 0,
        cancel: cancelled(),
    };
    assert_eq!(
        simulate_driven(&model(), &drive, &cfg).unwrap_err(),
        SimError::Cancelled(Cancelled)
    );
}

#[test]
fn welch_stops_before_a_segment() {
    let x: Vec<f64> = (0..4096).map(|k| (k as f64).sin()).collect();
    let cfg = WelchConfig::new(256);
    assert_eq!(
        csd_matrix_cancellable(&[&x, &x], 1.0, &cfg, &cancelled()).unwrap_err(),
        SpectralError::Cancelled(Cancelled)
    );
    let mut acc = WelchAccumulator::new(1, 1.0, &cfg)
        .unwrap()
        .with_cancel(cancelled());
    // Fewer samples than a segment: nothing to poll for yet.
    acc.push(&[&x[..100]]).unwrap();
    assert_eq!(
        acc.push(&[&x[100..]]).unwrap_err(),
        SpectralError::Cancelled(Cancelled)
    );
}

#[test]
fn the_streamed_budget_stops_between_chunks() {
    let model = model();
    let token = Cancel::new();
    let opts = BudgetOptions {
        welch_segment_len: Some(1024),
        cancel: token.clone(),
        ..BudgetOptions::default()
    };
    let mut chunks = 0;
    let e = budget_from_series(
        &model,
        &mut tilt_series(3 * CHUNK_SAMPLES),
        &opts,
        &mut |_, _| {
            chunks += 1;
            token.cancel();
        },
    )
    .unwrap_err();
    assert!(matches!(e, BudgetError::Cancelled(Cancelled)), "{e}");
    assert_eq!(chunks, 1);
}

#[test]
fn grid_evaluation_stops_between_parts() {
    let model = model();
    let plan = tf::plan(&model, &Request::all_tilt(), Method::PoleZero).unwrap();
    let freqs: Vec<f64> = (1..=100_000).map(|k| 1e-3 * k as f64).collect();
    let block = plan.request().outputs.len() * plan.request().inputs.len();
    let mut out = vec![num_complex::Complex64::new(0.0, 0.0); freqs.len() * block];
    for threads in [1, 2] {
        let e = eval_grid_threads_cancellable(
            plan.as_ref(),
            &freqs,
            &mut out,
            threads,
            Destination::Reused,
            &cancelled(),
        )
        .unwrap_err();
        assert!(matches!(e, TfError::Cancelled(Cancelled)), "{e}");
        let mut m = tf::evaluate(plan.as_ref(), &freqs[..10]).unwrap();
        let e = evaluate_into_cancellable(plan.as_ref(), &freqs, threads, &mut m, &cancelled())
            .unwrap_err();
        assert!(matches!(e, TfError::Cancelled(Cancelled)), "{e}");
    }
}

#[test]
fn the_fit_stops() {
    let config = FitConfig {
        cancel: cancelled(),
        ..FitConfig::default()
    };
    let e = fit(&Params::table_i(), &Measured::table_ii(), &config).unwrap_err();
    assert!(matches!(e, FitError::Cancelled(Cancelled)), "{e}");
}

#[test]
fn coherence_stops() {
    let tilt = tilt_series(8192);
    let x = tilt.data[0].clone();
    let tilt_record = Record {
        name: "tilt",
        sample_rate_hz: 10.0,
        start_time: None,
        channels: vec![
            (TiltAxis::ThetaT, &tilt.data[0][..]),
            (TiltAxis::EtaT, &tilt.data[1][..]),
        ],
    };
    let measured = Record {
        name: "measured",
        sample_rate_hz: 10.0,
        start_time: None,
        channels: vec![(Observable::X, &x[..])],
    };
    let opts = CoherenceOptions {
        welch_segment_len: Some(512),
        cancel: cancelled(),
        ..CoherenceOptions::default()
    };
    let e = coherence_from_series(&model(), &tilt_record, &measured, &opts).unwrap_err();
    assert!(
        matches!(
            e,
            CoherenceError::Spectral(SpectralError::Cancelled(Cancelled))
        ),
        "{e}"
    );
}
