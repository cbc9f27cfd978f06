//! The budget job: one opening of the input (an HDF5 series streamed, with results identical
//! to the series read whole), options checked against the kind of input before any
//! computation, every error rendered in either front end's spelling.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use tiltnoise_core::budget::option_checks::InputKind;
use tiltnoise_core::budget::BudgetError;
use tiltnoise_core::input::{GapPolicy, InputMeta, TiltInput};
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::params::Params;
use tiltnoise_io::input::{read_tilt, ReadOptions};
use tiltnoise_job::budget::{run, BudgetRequest, ReadRequest, TiltSource, WelchRequest};
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
            option: "gaps",
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
