//! Figures written to files: `tiltnoise-plot` returns the bytes and the job layer's
//! `save_image` (every outcome's figures) writes them atomically. A failure names the file and leaves
//! nothing behind; an existing file is replaced only by a complete figure.

use crate::common::listing;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::model::{Model, Request};
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::{evaluate, plan, Method, TransferMatrix};
use tiltnoise_job::save_image;
use tiltnoise_plot::{tf_figure, DrawError};

/// Table I, all tilt inputs, at a few frequencies off the undamped resonances.
fn table_i_tf() -> TransferMatrix {
    let model = Model::new(&Params::table_i()).unwrap();
    let tf = plan(&model, &Request::all_tilt(), Method::Direct).unwrap();
    evaluate(tf.as_ref(), &[1e-3, 0.1, 10.0]).unwrap()
}

#[test]
fn missing_directory_is_an_error_and_leaves_nothing() {
    let tf = table_i_tf();
    let dir = tempfile::tempdir().unwrap();
    for name in ["fig.png", "fig.svg"] {
        let path = dir.path().join("no-such-dir").join(name);
        let err = tiltnoise_io::Staging::committed(|s| {
            save_image(s, &path, |format| tf_figure(&tf, format))
        })
        .unwrap_err();
        match &err {
            OutputError::Write { path: p, .. } => assert_eq!(p, &path),
            other => panic!("unexpected error {other:?}"),
        }
        assert!(err.to_string().contains("no-such-dir"), "{err}");
        assert!(!path.exists());
    }
    assert!(!dir.path().join("no-such-dir").exists());
}

#[test]
fn unknown_extension_is_rejected_before_drawing() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["fig.pdf", "fig"] {
        let path = dir.path().join(name);
        let err =
            tiltnoise_io::Staging::committed(|s| save_image(s, &path, |_| panic!("{name}: drawn")))
                .unwrap_err();
        assert!(matches!(err, OutputError::UnknownFormat { .. }), "{err:?}");
        assert!(!path.exists());
    }
}

#[test]
fn drawing_error_leaves_existing_target_untouched() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["old.png", "old.svg"] {
        let path = dir.path().join(name);
        std::fs::write(&path, b"previous").unwrap();
        let err = tiltnoise_io::Staging::committed(|s| {
            save_image(s, &path, |_| {
                Err(DrawError("deliberate".to_string().into()))
            })
        })
        .unwrap_err();
        assert!(err.to_string().contains("deliberate"), "{err}");
        assert!(err.to_string().contains(name), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), b"previous");
    }
    assert_eq!(
        listing(dir.path()),
        vec![dir.path().join("old.png"), dir.path().join("old.svg")]
    );
}

#[test]
fn overwrite_replaces_target() {
    let tf = table_i_tf();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fig.svg");
    std::fs::write(&path, b"previous").unwrap();
    tiltnoise_io::Staging::committed(|s| save_image(s, &path, |format| tf_figure(&tf, format)))
        .unwrap();
    assert!(std::fs::read_to_string(&path).unwrap().starts_with("<svg"));
    assert_eq!(listing(dir.path()), vec![path]);
}

/// The figure options of the command line: every requested observable drawn, phase panels,
/// limits, size and resolution; bad values refused in one line before anything is computed.
mod options {
    use crate::common::{assert_fails_without_output, listing, tiltnoise};

    /// Width and height of a PNG file's IHDR.
    fn png_size(bytes: &[u8]) -> (u32, u32) {
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
        let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
        (w, h)
    }

    #[test]
    fn tf_draws_every_requested_observable_with_phase() {
        let dir = tempfile::tempdir().unwrap();
        let svg = dir.path().join("x.svg");
        let out = tiltnoise(&[
            "tf",
            "--freq",
            "1e-3:40:1",
            "--observables",
            "Y,Z,theta,eta",
            "--phase",
            "--save",
            svg.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(0), "{out:?}");
        let text = std::fs::read_to_string(&svg).unwrap();
        for panel in [
            "|Y / tilt|",
            "|Z / tilt|",
            "|θ / tilt|",
            "|η / tilt|",
            "arg(Y / tilt)",
        ] {
            assert!(text.contains(panel), "{panel} missing");
        }
        assert!(text.contains("1 mHz"), "SI tick labels");
    }

    #[test]
    fn size_dpi_and_limits_shape_the_png() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("x.png");
        let out = tiltnoise(&[
            "tf",
            "--freq",
            "1e-3:40:1",
            "--size",
            "800x600",
            "--dpi",
            "150",
            "--xlim",
            "2e-3,0.5",
            "--ylim",
            "1e-6,1e3",
            "--save",
            png.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(0), "{out:?}");
        assert_eq!(png_size(&std::fs::read(&png).unwrap()), (1200, 900));
    }

    #[test]
    fn bad_figure_options_fail_in_one_line_and_write_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("x.png");
        let png = png.to_str().unwrap();
        for (args, needles) in [
            (vec!["--xlim", "1,0.1"], vec!["--xlim 1,0.1", "0 < LO < HI"]),
            (vec!["--ylim", "0,1"], vec!["--ylim 0,1", "0 < LO < HI"]),
            (
                vec!["--xlim", "a,1"],
                vec!["--xlim", "`a` is not a finite number"],
            ),
            (
                vec!["--size", "50x50"],
                vec!["--size 50x50", "200 to 10000"],
            ),
            (vec!["--dpi", "0"], vec!["--dpi 0", "30 to 600"]),
            (
                vec!["--size", "10000x10000", "--dpi", "600"],
                vec!["too large"],
            ),
            (
                vec!["--observables", "X", "--plot-observables", "phi"],
                vec!["--plot-observables", "phi", "--observables"],
            ),
        ] {
            let mut all = vec!["tf", "--freq", "1e-3:10:1"];
            all.extend(args);
            all.extend(["--save", png]);
            assert_fails_without_output(&all, dir.path(), &needles);
        }
        assert!(listing(dir.path()).is_empty());
    }

    /// A tilt record `tilt.h5` (theta_t, eta_t: white noise of about 1e-8 rad, 1 Hz, 2^13
    /// samples) and the pendulum's response to it, `pendulum.h5`, written by `simulate --tilt`:
    /// the inputs of `coherence` and `subtract`.
    fn tilt_and_response(dir: &std::path::Path) -> (String, String) {
        use hdf5::types::VarLenUnicode;
        let n = 1 << 13;
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut noise = || {
            // xorshift64: uniform in [-1, 1) scaled to 1e-8 rad.
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            ((state >> 11) as f64 / (1u64 << 52) as f64 - 1.0) * 1e-8
        };
        let theta: Vec<f64> = (0..n).map(|_| noise()).collect();
        let eta: Vec<f64> = (0..n).map(|_| noise()).collect();
        let tilt = dir.join("tilt.h5");
        let file = hdf5::File::create(&tilt).unwrap();
        file.new_attr::<f64>()
            .create("sample_rate_hz")
            .unwrap()
            .write_scalar(&1.0)
            .unwrap();
        let text = |s: &str| s.parse::<VarLenUnicode>().unwrap();
        for (name, value) in [
            ("schema", "tiltnoise.tilt_series"),
            ("start_time", "2024-03-20T00:00:00Z"),
        ] {
            file.new_attr::<VarLenUnicode>()
                .create(name)
                .unwrap()
                .write_scalar(&text(value))
                .unwrap();
        }
        for (name, data) in [("theta_t", &theta), ("eta_t", &eta)] {
            let ds = file
                .new_dataset_builder()
                .with_data(data)
                .create(name)
                .unwrap();
            ds.new_attr::<VarLenUnicode>()
                .create("units")
                .unwrap()
                .write_scalar(&text("rad"))
                .unwrap();
        }
        drop(file);
        let pendulum = dir.join("pendulum.h5");
        let (tilt, pendulum) = (
            tilt.to_str().unwrap().to_string(),
            pendulum.to_str().unwrap().to_string(),
        );
        let out = tiltnoise(&["simulate", "--tilt", &tilt, "--save", &pendulum]);
        assert_eq!(out.status.code(), Some(0), "{out:?}");
        (tilt, pendulum)
    }

    /// Every command that draws, with its inputs and the flag that saves its figure; the
    /// figure's path is appended. `spectra`: its figures have frequency axes (--xlim, --ylim).
    fn drawing_commands(tilt: &str, pendulum: &str) -> Vec<(Vec<String>, bool)> {
        let owned = |v: &[&str]| v.iter().map(|a| a.to_string()).collect::<Vec<_>>();
        vec![
            (owned(&["tf", "--freq", "1e-3:40:1", "--save"]), true),
            (owned(&["budget", "--tilt", tilt, "--save"]), true),
            (
                owned(&[
                    "coherence",
                    "--tilt",
                    tilt,
                    "--measured",
                    pendulum,
                    "--save",
                ]),
                true,
            ),
            (
                owned(&["subtract", "--tilt", tilt, "--measured", pendulum, "--save"]),
                true,
            ),
            (owned(&["simulate", "--duration", "3600", "--save"]), true),
            (
                owned(&["simulate", "--duration", "3600", "--save-time"]),
                false,
            ),
            (owned(&["mc", "--samples", "200", "--save"]), false),
            (owned(&["methods", "--freq", "1e-3:20:1", "--save"]), false),
        ]
    }

    #[test]
    fn every_drawing_command_takes_the_figure_options() {
        let dir = tempfile::tempdir().unwrap();
        let (tilt, pendulum) = tilt_and_response(dir.path());
        let out_dir = dir.path().join("out");
        std::fs::create_dir(&out_dir).unwrap();
        for (i, (command, spectra)) in drawing_commands(&tilt, &pendulum).iter().enumerate() {
            let png = out_dir.join(format!("{i}.png"));
            let mut args: Vec<&str> = command.iter().map(String::as_str).collect();
            args.extend([png.to_str().unwrap(), "--size", "640x480", "--dpi", "50"]);
            if *spectra {
                args.extend(["--xlim", "2e-3:0.2", "--ylim", "1e-15:1e-3"]);
            }
            let out = tiltnoise(&args);
            assert_eq!(out.status.code(), Some(0), "{args:?}: {out:?}");
            // 640 x 480 at 100 dpi drawn at 50 dpi.
            assert_eq!(
                png_size(&std::fs::read(&png).unwrap()),
                (320, 240),
                "{args:?}"
            );
            // Bad values: one line, exit 2, no file.
            let bad = out_dir.join(format!("bad{i}.png"));
            let base: Vec<&str> = command
                .iter()
                .map(String::as_str)
                .chain([bad.to_str().unwrap()])
                .collect();
            let mut cases = vec![
                (
                    vec!["--size", "50x50"],
                    vec!["--size 50x50", "200 to 10000"],
                ),
                (vec!["--dpi", "nan"], vec!["--dpi NaN", "30 to 600"]),
                (
                    vec!["--size", "10000x10000", "--dpi", "600"],
                    vec!["too large"],
                ),
            ];
            if *spectra {
                cases.push((vec!["--xlim", "1:0.1"], vec!["--xlim 1:0.1", "0 < LO < HI"]));
                cases.push((vec!["--ylim", "0,1"], vec!["--ylim 0,1", "0 < LO < HI"]));
            } else if command[0] != "simulate" {
                // Their axes follow the results: the options are not theirs (nor in their help).
                cases.push((
                    vec!["--xlim", "1e-3:1"],
                    vec!["unexpected argument", "--xlim"],
                ));
            }
            for (extra, needles) in cases {
                let mut all = base.clone();
                all.extend(extra);
                assert_fails_without_output(&all, &out_dir, &needles);
            }
        }
    }

    #[test]
    fn damped_caption_does_not_claim_no_losses_and_long_captions_wrap() {
        let dir = tempfile::tempdir().unwrap();
        let svg = dir.path().join("d.svg");
        let out = tiltnoise(&[
            "--set",
            "loss.torsion_b_rad=1e-3",
            "tf",
            "--freq",
            "1e-3:40:1",
            "--input",
            "tilt,forces",
            "--observables",
            "X",
            "--save",
            svg.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(0), "{out:?}");
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(!text.contains("Without loss angles"));
        assert!(
            text.contains("With the damping"),
            "the damped caption is missing"
        );
        // The last words of the caption are drawn (the caption is not cut).
        assert!(text.contains("frequency grid") || text.contains("resolves them."));
    }
}
