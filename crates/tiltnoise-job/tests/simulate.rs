//! The simulate, driven-simulate, visibility and fit jobs: a record streamed in any chunks, to
//! its HDF5 file or held whole gives the same numbers as the library's whole-record path; the
//! file streamed is the record (the visibility job reads it back); options are refused by
//! their keys.

use tiltnoise_core::fit::peaks;
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::params::Params;
use tiltnoise_core::simulate::{
    equal_energy_init, simulate, Excitation, SimConfig, DEFAULT_MODE_ENERGY_J,
};
use tiltnoise_core::spectral::{welch, WelchConfig};
use tiltnoise_job::budget::ReadRequest;
use tiltnoise_job::fit::FitRequest;
use tiltnoise_job::simulate::driven::DrivenRequest;
use tiltnoise_job::simulate::{run, Keep, SimulateRequest, SimulateResult};
use tiltnoise_job::visibility::VisibilityRequest;
use tiltnoise_job::{Cancel, JobError, Outcome};

fn request(model: &Model, chunk_samples: Option<usize>, keep: Keep) -> SimulateRequest<'_> {
    SimulateRequest {
        model,
        duration_s: 4000.0,
        step_s: 0.5,
        excitation: Excitation::EqualEnergy {
            energy_j: DEFAULT_MODE_ENERGY_J,
        },
        readout: vec![(Observable::Phi, 1e-9)],
        seed: 7,
        nperseg: Some(2048),
        chunk_samples,
        keep,
        view: Default::default(),
        invocation: tiltnoise_job::Invocation::default(),
    }
}

fn simulated(req: SimulateRequest<'_>) -> SimulateResult {
    run(&req, &Cancel::never(), &tiltnoise_job::Silent).unwrap()
}

#[test]
fn a_record_streamed_in_any_chunks_or_held_whole_gives_the_librarys_numbers() {
    let model = Model::new(&Params::table_i()).unwrap();
    let held = simulated(request(
        &model,
        None,
        Keep {
            record: true,
            ..Keep::default()
        },
    ));
    let streamed = simulated(request(&model, Some(1000), Keep::default()));
    // The library's whole-record path, from the same start, readout and seed.
    let cfg = SimConfig {
        dt_s: 0.5,
        duration_s: 4000.0,
        readout_asd: vec![(Observable::X, 9e-9), (Observable::Phi, 1e-9)],
        seed: 7,
        ..SimConfig::default()
    };
    let init = equal_energy_init(&model, DEFAULT_MODE_ENERGY_J);
    let whole = simulate(&model, &init, &cfg).unwrap();
    assert_eq!(held.record.as_ref(), Some(&whole));
    assert_eq!(held.readout, cfg.readout_asd, "the default X readout stays");
    let wcfg = WelchConfig::new(2048);
    for (o, asd) in &held.asd.asd {
        let want = welch(whole.observable(*o), 2.0, &wcfg).unwrap().asd();
        assert_eq!(asd, &want, "{}", o.name());
    }
    assert_eq!(streamed.asd, held.asd);
    // Compared as text: the ratios of untestable modes are NaN, which equals nothing.
    assert_eq!(format!("{:?}", streamed.check), format!("{:?}", held.check));
    assert!(streamed.record.is_none(), "a streamed record is not held");
    assert!(held.check.n_tested() > 0, "the resonance check tests modes");
}

#[test]
fn the_streamed_file_is_the_record_and_its_visibilities_are_the_records() {
    let model = Model::new(&Params::table_i()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let h5 = dir.path().join("free.h5");
    let r = simulated(request(
        &model,
        Some(333),
        Keep {
            record: true,
            hdf5: vec![h5.clone()],
            ..Keep::default()
        },
    ));
    assert!(!h5.exists(), "the file appears when it is complete");
    tiltnoise_io::Staging::committed(|s| r.save(s, &h5)).unwrap();
    let vis = tiltnoise_job::visibility::run(
        &VisibilityRequest {
            model: &model,
            measured: h5.clone(),
            invocation: tiltnoise_job::Invocation::default(),
        },
        &Cancel::never(),
        &tiltnoise_job::Silent,
    )
    .unwrap();
    let record = r.record.unwrap();
    let modes = NormalModes::new(&model);
    let expected: [f64; 8] = std::array::from_fn(|k| modes.modes[k].frequency_hz);
    let direct = peaks::measure(
        &record.observables,
        record.fs_hz(),
        &expected,
        &h5.display().to_string(),
        &Cancel::never(),
    )
    .unwrap();
    assert_eq!(vis.measured, direct);
    assert!(!vis.measured.visibilities.items.is_empty());
    let csv = vis.csv();
    assert!(
        csv.starts_with("# mode visibilities measured from "),
        "{csv}"
    );
    assert_eq!(
        csv.lines().filter(|l| !l.starts_with('#')).count(),
        1 + vis.measured.visibilities.items.len()
    );
}

#[test]
fn options_are_refused_by_their_keys() {
    let model = Model::new(&Params::table_i()).unwrap();
    let message = |req| match run(&req, &Cancel::never(), &tiltnoise_job::Silent) {
        Ok(_) => panic!("refused"),
        Err(e) => e.message(),
    };
    let e = message(request(&model, Some(0), Keep::default()));
    assert_eq!(e, "chunk_samples 0: a chunk must hold at least 1 sample");
    let e = message(SimulateRequest {
        nperseg: Some(1 << 20),
        ..request(&model, None, Keep::default())
    });
    assert!(e.contains("shorter than one Welch segment"), "{e}");
    let damped = Params::table_i()
        .with_override("loss.torsion_b_rad=1e-3")
        .unwrap();
    let damped = Model::new(&damped).unwrap();
    let e = message(request(&damped, None, Keep::default()));
    assert!(e.contains("undamped model"), "{e}");
}

/// A CSV record of tilt at 1 Hz, `n` samples.
fn tilt_csv(dir: &std::path::Path, n: usize) -> std::path::PathBuf {
    let path = dir.join("tilt.csv");
    let mut text = String::from("time_s,theta_t,eta_t\n");
    for i in 0..n {
        let t = i as f64;
        let (a, b) = (1e-8 * (0.01 * t).sin(), 1e-8 * (0.023 * t).cos());
        text.push_str(&format!("{t},{a:e},{b:e}\n"));
    }
    std::fs::write(&path, text).unwrap();
    path
}

fn driven(model: &Model, tilt: std::path::PathBuf) -> DrivenRequest<'_> {
    DrivenRequest {
        model,
        tilt,
        read: ReadRequest::default(),
        oversample: 4,
        drive_gain: vec![("eta_t".to_string(), 0.97)],
        drive_delay_s: Some(0.5),
        readout: Vec::new(),
        seed: 1,
        nperseg: Some(256),
        view: Default::default(),
        invocation: tiltnoise_job::Invocation::default(),
    }
}

#[test]
fn a_driven_record_has_the_drives_rate_and_its_spectra() {
    let model = Model::new(&Params::table_i()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let tilt = tilt_csv(dir.path(), 2048);
    let r = tiltnoise_job::simulate::driven::run(
        &driven(&model, tilt.clone()),
        &Cancel::never(),
        &tiltnoise_job::Silent,
    )
    .unwrap();
    assert_eq!((r.record.len(), r.fs_hz), (2048, 1.0));
    let wcfg = WelchConfig::new(256);
    for (o, asd) in &r.asd.asd {
        let want = welch(r.record.observable(*o), 1.0, &wcfg).unwrap().asd();
        assert_eq!(asd, &want, "{}", o.name());
    }
    assert!(r.description.contains("eta_t x 0.97"), "{}", r.description);
    let refused = |req: DrivenRequest<'_>| match tiltnoise_job::simulate::driven::run(
        &req,
        &Cancel::never(),
        &tiltnoise_job::Silent,
    ) {
        Ok(_) => panic!("refused"),
        Err(e) => e.message(),
    };
    let e = refused(DrivenRequest {
        drive_gain: vec![("x_t".to_string(), 1.02)],
        ..driven(&model, tilt.clone())
    });
    assert!(
        e.starts_with("drive_gain x_t=1.02: the record has no input `x_t`; it has "),
        "{e}"
    );
    let e = refused(DrivenRequest {
        drive_delay_s: Some(0.1),
        ..driven(&model, tilt)
    });
    assert!(
        e.starts_with("drive_delay 0.1 s: must be a whole number"),
        "{e}"
    );
}

#[test]
fn a_fit_refuses_a_key_given_twice_and_fits_visibilities_alone() {
    let params = Params::table_i();
    let fit = |free: &[&str], visibility| {
        tiltnoise_job::fit::run(
            &FitRequest {
                params: &params,
                measured: None,
                visibility,
                free: Some(free.iter().map(|k| k.to_string()).collect()),
                bound_sigmas: 1.0,
                prior: false,
                invocation: tiltnoise_job::Invocation::default(),
            },
            &Cancel::never(),
            &tiltnoise_job::Silent,
        )
    };
    match fit(&["mass.m_b_kg", " mass.m_b_kg"], None) {
        Err(JobError::Repeated(r)) => assert_eq!(r.option, OptionKey::FREE),
        other => panic!("a repeated key: {:?}", other.map(|o| o.origin)),
    }
    let table_ii = fit(&["mass.m_b_kg"], None).unwrap();
    assert_eq!(table_ii.origin, "embedded Table II");
    let dir = tempfile::tempdir().unwrap();
    let vis = dir.path().join("vis.csv");
    std::fs::write(
        &vis,
        "mode,observable,reference,ratio,sigma\n4,X,phi,1e-3,1e-4\n",
    )
    .unwrap();
    let alone = fit(&["length.d_m"], Some(vis)).unwrap();
    assert_eq!(alone.origin, "no frequency file");
    assert!(alone.result.modes.is_empty());
    assert_eq!(alone.result.visibilities.len(), 1);
}
