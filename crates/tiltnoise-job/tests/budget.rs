//! The budget job: one opening of the input (an HDF5 series streamed, with results identical
//! to the series read whole), options checked against the kind of input before any
//! computation, every error rendered in either front end's spelling.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use tiltnoise_core::budget::option_checks::InputKind;
use tiltnoise_core::budget::BudgetError;
use tiltnoise_core::input::{GapPolicy, InputMeta, TiltInput, TiltSeries};
use tiltnoise_core::model::{Input, Model, Observable, TiltAxis, TranslationAxis};
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::params::Params;
use tiltnoise_io::input::{read_tilt, ReadOptions};
use tiltnoise_job::budget::{
    run, ArrayOptions, ArrayRecord, BudgetRequest, ReadRequest, TiltSource, WelchRequest,
    ARRAYS_FORMAT, ARRAYS_PATH,
};
use tiltnoise_job::{AsdSpec, Cancel, Invocation, JobError, Progress, ReadoutItem, Silent};

/// The last progress reported.
#[derive(Default)]
struct Last(AtomicU64);

impl Progress for Last {
    fn report(&self, done: u64, _total: u64) {
        self.0.store(done, Ordering::Relaxed);
    }
}

fn tilt_data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tilt_data")
        .join(name)
}

fn request<'a>(model: &'a Model, tilt: TiltSource<'a>) -> BudgetRequest<'a> {
    BudgetRequest {
        model,
        tilt,
        welch: WelchRequest {
            nperseg: Some(4096),
            ..WelchRequest::default()
        },
        freq_hz: None,
        observables: None,
        readout: Vec::new(),
        terms: Vec::new(),
        witness_noise: Vec::new(),
        measured: None,
        at_hz: None,
        at_band: None,
        invocation: Invocation::default(),
    }
}

fn file<'a>(path: PathBuf) -> TiltSource<'a> {
    TiltSource::File {
        path,
        read: ReadRequest::default(),
    }
}

#[test]
fn a_streamed_hdf5_series_gives_the_budget_of_the_series_read_whole() {
    let model = Model::new(&Params::table_i()).unwrap();
    let path = tilt_data("lab_tilt_24h.h5");
    let done = Last::default();
    let streamed = run(request(&model, file(path.clone())), &Cancel::never(), &done).unwrap();
    assert!(
        done.0.load(Ordering::Relaxed) > 0,
        "the streamed run reports its progress"
    );
    let TiltInput::Series(mut series) = read_tilt(&path, &ReadOptions::default()).unwrap() else {
        panic!("{} holds a series", path.display());
    };
    let input = InputMeta::from(&series.provenance);
    let tilt = TiltSource::Series {
        source: &mut series,
        input,
    };
    let whole = run(request(&model, tilt), &Cancel::never(), &Silent).unwrap();
    // The same samples through the same arithmetic: equal to the last bit.
    assert_eq!(streamed.report.budget, whole.report.budget);
    assert_eq!(streamed.input, whole.input);
}

#[test]
fn options_of_the_other_kind_of_input_are_refused_in_each_spelling() {
    let model = Model::new(&Params::table_i()).unwrap();
    let spectra = tilt_data("peterson_tilt_asd.csv");
    let mut req = request(&model, file(spectra.clone()));
    req.tilt = TiltSource::File {
        path: spectra.clone(),
        read: ReadRequest {
            gaps: Some(GapPolicy::Interpolate),
            ..ReadRequest::default()
        },
    };
    req.welch = WelchRequest::default();
    let e = run(req, &Cancel::never(), &Silent).unwrap_err();
    assert!(matches!(
        e,
        JobError::NotForInput {
            option: OptionKey::GAPS,
            holds: InputKind::Spectra,
            ..
        }
    ));
    assert_eq!(
        e.message(),
        format!(
            "gaps applies to time-series input, and {} holds spectra; leave it out (the model \
             grid of spectra input is set with freq)",
            spectra.display()
        )
    );
    let mut req = request(&model, file(tilt_data("lab_tilt_24h.h5")));
    req.freq_hz = Some(vec![1e-3, 1e-2]);
    let e = run(req, &Cancel::never(), &Silent).unwrap_err();
    assert!(e.message().starts_with("freq applies to spectra input"));
}

#[test]
fn options_are_checked_before_any_file_is_opened() {
    let model = Model::new(&Params::table_i()).unwrap();
    let missing = PathBuf::from("no/such/tilt.h5");
    let mut req = request(&model, file(missing.clone()));
    req.welch.percentiles = Some((5.0, 95.0));
    let e = run(req, &Cancel::never(), &Silent).unwrap_err();
    assert!(matches!(e, JobError::PercentilesNeedSegments), "{e}");
    assert!(e
        .message()
        .starts_with("percentiles applies to the per-segment band and needs segment_duration"));

    let mut req = request(&model, file(missing.clone()));
    req.readout = vec![ReadoutItem {
        observable: Observable::Y,
        asd: AsdSpec::White(1e-9),
    }];
    let e = run(req, &Cancel::never(), &Silent).unwrap_err();
    assert_eq!(
        e.message(),
        "readout Y=1e-9: Y is not budgeted; allowed: X, phi, phi_a (add it with observables)"
    );

    let mut req = request(&model, file(missing));
    req.at_hz = Some(vec![1e-3, 1e-3]);
    let e = run(req, &Cancel::never(), &Silent).unwrap_err();
    assert!(e.message().starts_with("at: "), "{}", e.message());
}

#[test]
fn a_cancelled_run_returns_no_budget() {
    let model = Model::new(&Params::table_i()).unwrap();
    let cancel = Cancel::new();
    cancel.cancel();
    let e = run(
        request(&model, file(tilt_data("lab_tilt_24h.h5"))),
        &cancel,
        &Silent,
    )
    .unwrap_err();
    assert!(
        matches!(&e, JobError::Budget { source, .. } if matches!(**source, BudgetError::Cancelled(_))),
        "{e}"
    );
}

/// The tilt channels of `series` as the arrays a caller holds, last input first.
fn arrays_of(series: &TiltSeries) -> Vec<(Input, Vec<f64>)> {
    let mut channels: Vec<(Input, Vec<f64>)> = series
        .axes
        .iter()
        .zip(&series.data)
        .map(|(a, d)| (Input::Tilt(*a), d.clone()))
        .collect();
    channels.reverse();
    channels
}

#[test]
fn arrays_give_the_budget_of_the_same_samples_read_from_a_file() {
    let model = Model::new(&Params::table_i()).unwrap();
    let path = tilt_data("lab_tilt_24h.h5");
    let TiltInput::Series(mut series) = read_tilt(&path, &ReadOptions::default()).unwrap() else {
        panic!("{} holds a series", path.display());
    };
    let options = ArrayOptions {
        quantity: series.quantity(),
        ..ArrayOptions::default()
    };
    let record = ArrayRecord::new(series.sample_rate_hz, arrays_of(&series), options).unwrap();
    let arrays = run(
        request(&model, TiltSource::Arrays(record)),
        &Cancel::never(),
        &Silent,
    )
    .unwrap();
    let input = InputMeta::from(&series.provenance);
    let tilt = TiltSource::Series {
        source: &mut series,
        input,
    };
    let file = run(request(&model, tilt), &Cancel::never(), &Silent).unwrap();
    // The same samples (unit factor 1, no gap) through the same arithmetic: equal to the bit.
    assert_eq!(arrays.report.budget, file.report.budget);
    assert_eq!(arrays.input.path, ARRAYS_PATH);
    assert_eq!(arrays.input.format, ARRAYS_FORMAT);
    let names: Vec<&str> = file.report.inputs.iter().map(|i| i.name()).collect();
    assert_eq!(
        arrays.report.inputs, file.report.inputs,
        "the inputs in canonical order ({names:?})"
    );
    assert!(
        arrays.input.notes.last().unwrap().starts_with("units: "),
        "the units' note closes the provenance: {:?}",
        arrays.input.notes
    );
}

#[test]
fn a_non_finite_sample_of_arrays_is_refused_by_input_and_index_unless_bridged() {
    let model = Model::new(&Params::table_i()).unwrap();
    let n = 1 << 14;
    let mut eta: Vec<f64> = (0..n).map(|k| 1e-9 * ((k as f64) * 0.37).sin()).collect();
    eta[100] = f64::NAN;
    let channels = vec![(Input::Tilt(TiltAxis::EtaT), eta)];
    let refused = ArrayRecord::new(10.0, channels.clone(), ArrayOptions::default()).unwrap();
    let e = run(
        request(&model, TiltSource::Arrays(refused)),
        &Cancel::never(),
        &Silent,
    )
    .unwrap_err();
    assert!(matches!(e, JobError::Arrays(_)), "{e:?}");
    assert!(
        e.message().starts_with("tilt[\"eta_t\"][100] is NaN rad"),
        "{}",
        e.message()
    );
    let options = ArrayOptions {
        gaps: GapPolicy::Interpolate,
        ..ArrayOptions::default()
    };
    let bridged = ArrayRecord::new(10.0, channels, options).unwrap();
    let done = run(
        request(&model, TiltSource::Arrays(bridged)),
        &Cancel::never(),
        &Silent,
    )
    .unwrap();
    assert!(
        done.input.notes.iter().any(|n| n.contains("eta_t")),
        "the bridged gap is noted: {:?}",
        done.input.notes
    );
}

#[test]
fn arrays_that_describe_no_record_are_refused_before_any_computation() {
    let samples = vec![0.0; 64];
    let e = ArrayRecord::new(10.0, Vec::new(), ArrayOptions::default()).unwrap_err();
    assert!(
        e.message().starts_with("tilt: no input given"),
        "{}",
        e.message()
    );
    let translation = vec![(Input::Translation(TranslationAxis::XT), samples.clone())];
    let e = ArrayRecord::new(10.0, translation, ArrayOptions::default()).unwrap_err();
    assert!(
        e.message().contains("the translation x_t has no unit"),
        "{}",
        e.message()
    );
    let unequal = vec![
        (Input::Tilt(TiltAxis::ThetaT), samples.clone()),
        (Input::Tilt(TiltAxis::EtaT), samples[..32].to_vec()),
    ];
    let e = ArrayRecord::new(10.0, unequal, ArrayOptions::default()).unwrap_err();
    assert!(
        e.message()
            .contains("theta_t has 64 samples but eta_t has 32"),
        "{}",
        e.message()
    );
    // A rate outside the documented range, whatever the channels: named with its key.
    let tilt = vec![(Input::Tilt(TiltAxis::EtaT), samples.clone())];
    for fs in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e300] {
        let e = ArrayRecord::new(fs, tilt.clone(), ArrayOptions::default()).unwrap_err();
        assert!(
            e.message().starts_with("fs = ") && e.message().contains("Hz is not allowed"),
            "{fs}: {}",
            e.message()
        );
    }
}
