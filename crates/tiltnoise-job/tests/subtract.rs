//! The subtract job: the options the records are not needed for are refused before any file
//! is opened, each error naming its option by key (a front end spells it), and a cancelled
//! run returns the job's `Cancelled` error and no result.

use std::path::PathBuf;
use tiltnoise_core::model::{Input, Model, Observable};
use tiltnoise_core::params::Params;
use tiltnoise_job::budget::ReadRequest;
use tiltnoise_job::subtract::{run, SubtractRequest};
use tiltnoise_job::{Cancel, JobError};

/// A request on files that do not exist: an option refused before the records are read says
/// so, and any other outcome names the missing file.
fn request(model: &Model) -> SubtractRequest<'_> {
    SubtractRequest {
        model,
        tilt: PathBuf::from("no-such-tilt.h5"),
        read: ReadRequest::default(),
        measured: PathBuf::from("no-such-measured.csv"),
        observables: None,
        colocated: Vec::new(),
        colocated_ratio: Vec::new(),
        witness_noise: Vec::new(),
        readout_asd: Vec::new(),
        fit: Vec::new(),
        band_hz: None,
        report_band_hz: (3e-3, 3e-2),
        nperseg: None,
        holdout: 0.25,
        max_delay_s: None,
        invocation: tiltnoise_job::Invocation::default(),
        figure: tiltnoise_job::figures::View::default(),
    }
}

/// A change of the request that makes one option wrong.
type Change = Box<dyn Fn(&mut SubtractRequest)>;

fn message(req: SubtractRequest<'_>) -> String {
    match run(&req, &Cancel::never(), &tiltnoise_job::Silent) {
        Ok(_) => panic!("the request ran"),
        Err(e) => e.message(),
    }
}

#[test]
fn options_are_refused_by_key_before_any_file_is_read() {
    let model = Model::new(&Params::table_i()).unwrap();
    let cases: Vec<(Change, &str)> = vec![
        (
            Box::new(|r| r.band_hz = Some((3e-2, 3e-3))),
            "band (0.03, 0.003): must be finite with 0 < FLO < FHI (Hz)",
        ),
        (
            Box::new(|r| r.report_band_hz = (0.0, 3e-2)),
            "report_band (0, 0.03): must be finite with 0 < FLO < FHI (Hz)",
        ),
        (
            Box::new(|r| r.band_hz = Some((f64::NAN, 1.0))),
            "band (NaN, 1): must be finite",
        ),
        (
            Box::new(|r| r.colocated = vec![PathBuf::from("a"); 3]),
            "colocated is given 3 times",
        ),
        (
            Box::new(|r| {
                r.colocated = vec![PathBuf::from("a")];
                r.colocated_ratio = vec![(Input::from_name("F_b.x").unwrap(), 2.0)];
            }),
            "colocated_ratio F_b.x=2: `F_b.x` is not a floor input of the model",
        ),
        (
            Box::new(|r| {
                r.colocated = vec![PathBuf::from("a")];
                r.colocated_ratio = vec![(Input::from_name("eta_t").unwrap(), -1.0)];
            }),
            "colocated_ratio eta_t=-1: the ratio of noise ASDs is not allowed: must be from \
             0 to 1e3",
        ),
        (
            Box::new(|r| {
                r.colocated = vec![PathBuf::from("a")];
                r.colocated_ratio = vec![(Input::from_name("eta_t").unwrap(), 1e150)];
            }),
            "colocated_ratio eta_t=1e150: the ratio of noise ASDs is not allowed: must be from \
             0 to 1e3",
        ),
        (
            Box::new(|r| {
                let eta = Input::from_name("eta_t").unwrap();
                r.colocated = vec![PathBuf::from("a")];
                r.colocated_ratio = vec![(eta, 1.5), (eta, 2.0)];
            }),
            "colocated_ratio: eta_t is given twice",
        ),
        (
            Box::new(|r| r.colocated_ratio = vec![(Input::from_name("eta_t").unwrap(), 2.0)]),
            "colocated_ratio applies to a huddle test: give exactly one colocated record",
        ),
        (
            Box::new(|r| r.fit = vec!["length.h_m".into(), "length.h_m".into()]),
            "fit: length.h_m is given twice",
        ),
        (
            Box::new(|r| r.readout_asd = vec![(Observable::X, 1e-9), (Observable::X, 2e-9)]),
            "readout: X is given twice",
        ),
    ];
    for (change, expected) in cases {
        let mut req = request(&model);
        change(&mut req);
        let m = message(req);
        assert!(
            m.starts_with(expected),
            "{m:?} does not start with {expected:?}"
        );
        assert!(
            !m.contains("no-such"),
            "{m}: a file was read before the options were checked"
        );
    }
    // Options that pass reach the files.
    assert!(message(request(&model)).contains("no-such-tilt.h5"));
}

#[test]
fn a_cancelled_run_returns_cancelled() {
    let model = Model::new(&Params::table_i()).unwrap();
    let cancel = Cancel::new();
    cancel.cancel();
    let e = run(&request(&model), &cancel, &tiltnoise_job::Silent)
        .map(|_| ())
        .unwrap_err();
    assert!(matches!(e, JobError::Cancelled), "{e:?}");
}
