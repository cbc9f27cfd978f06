//! Six-component records through `budget`: channels told by their units (`--units`), the
//! inertial seismometer's tilt removed with the record's tilt (or not, when declared
//! corrected), the `tilt`, `translation` and `ground` terms against the transfer functions and
//! the record's own spectrum, and the bad inputs of the units (one line, exit 2, nothing
//! written).

use crate::common;
use crate::tolerances::EPS;

use common::{assert_fails_without_output, tiltnoise};
use tiltnoise_core::model::{Model, Observable, TiltAxis, TranslationAxis};
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::{evaluate, plan, Input, Method, Request};

/// Rounding allowed in a budget's PSD relative to the largest product it sums: a handful of
/// roundings per factor (the channel's quantity, the inertial correction, `conj(H) S H`), the
/// file keeping f64.
const PSD_ROUNDING: f64 = 64.0 * EPS;

/// A record at 1 Hz of a seismometer that saw tilt alone: `LJN` the tilt angle about North
/// (rad; `eta_t = -LJN` by the default map), `LHE` the East acceleration an inertial sensor
/// reports, `a_x + g eta_t` with `a_x = 0`. No units line: the units come with `--units`.
fn tilt_only_record(path: &std::path::Path, g: f64) {
    let mut rng = tiltnoise_core::rng::Rng::stream(17, 0);
    let mut text = String::from("time_s,LJN,LHE\n");
    let mut angle = 0.0;
    for k in 0..8192 {
        // A red tilt: an AR(1) of white noise, about 1e-8 rad.
        angle = 0.99 * angle + 1e-9 * rng.gaussian();
        let eta = -angle;
        text.push_str(&format!("{k},{angle:?},{:?}\n", g * eta));
    }
    std::fs::write(path, text).unwrap();
}

/// The budget's `(frequency_hz, X tilt, X translation, X ground)` PSDs from its HDF5 file.
fn x_terms(h5: &std::path::Path) -> [Vec<f64>; 4] {
    common::disable_hdf5_file_locking();
    let f = hdf5::File::open(h5).unwrap();
    let read = |name: &str| f.dataset(name).unwrap().read_raw::<f64>().unwrap();
    [
        read("frequency_hz"),
        read("X/tilt/psd"),
        read("X/translation/psd"),
        read("X/ground/psd"),
    ]
}

/// The seismometer's reading `g eta_t` is, at low frequency, the pendulum's own: declared
/// corrected, its displacement `-g eta_t / w^2` and the tilt act alike, so the `ground` term is
/// `|H_eta - g H_x / w^2|^2 S_eta` (coherent: about 4 times the tilt's PSD at low frequency,
/// where a quadrature sum would give 2); by default the tilt is removed from it and nothing is
/// left of the translation.
#[test]
fn ground_term_adds_tilt_and_translation_with_their_cross_spectra() {
    let params = Params::table_i();
    let g = params.environment.g_m_per_s2;
    let dir = tempfile::tempdir().unwrap();
    let record = dir.path().join("six.csv");
    tilt_only_record(&record, g);
    let run = |extra: &[&str], stem: &str| {
        let h5 = dir.path().join(format!("{stem}.h5"));
        let csv = dir.path().join(format!("{stem}.csv"));
        let mut args = vec![
            "budget",
            "--tilt",
            record.to_str().unwrap(),
            "--units",
            "LJN=rad",
            "--units",
            "LHE=m/s^2",
            "--nperseg",
            "1024",
            "--at",
            "2e-3,1e-2",
            "--save",
            h5.to_str().unwrap(),
            "--save",
            csv.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let out = tiltnoise(&args);
        assert!(out.status.success(), "{}", common::stderr(&out));
        let stdout = String::from_utf8(out.stdout).unwrap();
        (x_terms(&h5), std::fs::read_to_string(csv).unwrap(), stdout)
    };
    let model = Model::new(&params).unwrap();
    let request = Request {
        outputs: vec![Observable::X],
        inputs: vec![
            Input::Tilt(TiltAxis::EtaT),
            Input::Translation(TranslationAxis::XT),
        ],
    };
    let tf_plan = plan(&model, &request, Method::Direct).unwrap();

    // Declared corrected: x_t is the reported displacement, -g eta_t / w^2.
    let ([freqs, tilt, translation, ground], csv, stdout) = run(&["--corrected", "LHE"], "raw");
    let tf = evaluate(tf_plan.as_ref(), &freqs).unwrap();
    let mut coherent = 0;
    for (k, &f) in freqs.iter().enumerate() {
        let (h_eta, h_x) = (tf.get(k, 0, 0), tf.get(k, 0, 1));
        let c = g / tiltnoise_core::units::angular(f).powi(2);
        let s_eta = tilt[k] / h_eta.norm_sqr();
        let scale = (h_eta.norm() + c * h_x.norm()).powi(2) * s_eta;
        let want_translation = c * c * h_x.norm_sqr() * s_eta;
        let want_ground = (h_eta - c * h_x).norm_sqr() * s_eta;
        assert!(
            (translation[k] - want_translation).abs() <= PSD_ROUNDING * scale,
            "translation at {f} Hz: {} vs {want_translation}",
            translation[k]
        );
        assert!(
            (ground[k] - want_ground).abs() <= PSD_ROUNDING * scale,
            "ground at {f} Hz: {} vs {want_ground}",
            ground[k]
        );
        if ground[k] > tilt[k] + translation[k] {
            coherent += 1;
        }
    }
    // Below the pendulum's modes the two act alike and add in amplitude, not in power.
    assert!(
        ground[0] > 1.9 * (tilt[0] + translation[0]),
        "lowest bin: ground {} tilt {} translation {}",
        ground[0],
        tilt[0],
        translation[0]
    );
    assert!(coherent > 0);
    assert!(
        stdout.contains("ground") && stdout.contains("translation"),
        "{stdout}"
    );
    let header = csv.lines().find(|l| !l.starts_with('#')).unwrap();
    for column in ["X.ground", "X.tilt", "X.translation", "X.total"] {
        assert!(header.split(',').any(|c| c == column), "{column}: {header}");
    }

    // By default the record's tilt is removed from the seismometer: nothing is left of x_t, and
    // the ground term is the tilt's.
    let ([freqs, tilt, translation, ground], _, stdout) = run(&[], "corrected");
    assert!(stdout.contains("the tilt it saw is removed"), "{stdout}");
    for (k, &f) in freqs.iter().enumerate() {
        let (h_eta, h_x) = (tf.get(k, 0, 0), tf.get(k, 0, 1));
        let c = g / tiltnoise_core::units::angular(f).powi(2);
        let s_eta = tilt[k] / h_eta.norm_sqr();
        // The correction cancels `c eta_t` against the reported `-c eta_t`: rounding of the
        // larger of the two, in power.
        let cancelled = c * c * h_x.norm_sqr() * s_eta;
        assert!(
            translation[k] <= PSD_ROUNDING * cancelled,
            "translation at {f} Hz: {} of {cancelled}",
            translation[k]
        );
        let scale = tilt[k] + cancelled;
        assert!(
            (ground[k] - tilt[k]).abs() <= PSD_ROUNDING * scale,
            "ground at {f} Hz: {} vs tilt {}",
            ground[k],
            tilt[k]
        );
    }
}

/// The units' bad inputs: a unit of nothing the floor does, a channel given two units, a
/// translation channel without a unit, a unit that contradicts the file's; and a channel that
/// states no unit whose RMS no floor reaches (a record in microradians read as radians).
#[test]
fn bad_units_are_refused_in_one_line_with_nothing_written() {
    let dir = tempfile::tempdir().unwrap();
    let record = dir.path().join("six.csv");
    tilt_only_record(&record, 9.81);
    let stated = dir.path().join("stated.csv");
    let text = std::fs::read_to_string(&record).unwrap();
    std::fs::write(&stated, format!("# units: LJN=rad, LHE=m/s^2\n{text}")).unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let save = out.join("b.h5");
    let (r, s, save) = (
        record.to_str().unwrap(),
        stated.to_str().unwrap(),
        save.to_str().unwrap(),
    );
    let cases: [(&str, &[&str], &[&str]); 5] = [
        (
            r,
            &["LJN=rad", "LHE=furlong/s"],
            &[
                "--units",
                "`furlong/s`",
                "channel `LHE`",
                "angle, rate, length",
            ],
        ),
        (
            r,
            &["LJN=rad", "LHE=m/s^2", "LHE=m/s"],
            &["--units", "LHE is given twice"],
        ),
        (
            r,
            &["LJN=rad"],
            &[
                "channel `LHE`",
                "feeds x_t",
                "has no unit",
                "--units LHE=m/s^2",
            ],
        ),
        (
            s,
            &["LHE=m/s"],
            &["channel `LHE`", "`m/s^2`", "gives `m/s`", "stated.csv"],
        ),
        (
            r,
            &["LJN=rad", "LHE=rad/s"],
            &["channel `LHE`", "instrument code `H`", "translation"],
        ),
    ];
    for (file, units, needles) in cases {
        let mut args = vec!["budget", "--tilt", file];
        for u in units {
            args.extend(["--units", u]);
        }
        args.extend(["--save", save]);
        assert_fails_without_output(&args, &out, needles);
    }

    // Tilt in microradians with no unit stated: refused, naming the likely unit and the option.
    let micro = dir.path().join("micro.csv");
    let mut text = String::from("time_s,E,N\n");
    let mut rng = tiltnoise_core::rng::Rng::stream(5, 0);
    for k in 0..4096 {
        let (e, n) = (0.3 * rng.gaussian(), 0.2 * rng.gaussian());
        text.push_str(&format!("{k},{e:?},{n:?}\n"));
    }
    std::fs::write(&micro, text).unwrap();
    let m = micro.to_str().unwrap();
    assert_fails_without_output(
        &["budget", "--tilt", m, "--save", save],
        &out,
        &["channel `E`", "states no unit", "urad", "--units E=urad"],
    );
    // Stated, it is read.
    let ok = tiltnoise(&[
        "budget", "--tilt", m, "--units", "E=urad", "--units", "N=urad", "--save", save,
    ]);
    assert!(ok.status.success(), "{}", common::stderr(&ok));
}
