//! Output writers: bit-exact round trips through HDF5 and CSV, the documented layout, and the
//! atomicity guarantees (nothing left behind on failure, existing files never clobbered).

use crate::common;

use common::{listing, str_attr, strs_attr, strs_dataset};
use num_complex::Complex64;
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::model::Model;
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::{evaluate, plan, Method, Request, TransferMatrix};
use tiltnoise_io::{write_tf_csv, write_tf_hdf5, OutputKind, RunMeta, Staging, TOOL_VERSION};
use tiltnoise_job::tf::save as save_tf;

fn freqs() -> Vec<f64> {
    // 0 Hz, then log-spaced 1e-4 .. 10 Hz (irrational-looking values), then a few exact ones.
    let mut f = vec![0.0];
    f.extend((0..40).map(|k| 10f64.powf(-4.0 + 5.0 * k as f64 / 39.0)));
    f.extend([0.5, 1.0, 3.0]);
    f
}

fn table_i_tf(freqs: &[f64]) -> TransferMatrix {
    let model = Model::new(&Params::table_i()).unwrap();
    evaluate(
        &*plan(&model, &Request::all_tilt(), Method::Direct).unwrap(),
        freqs,
    )
    .unwrap()
}

fn meta() -> RunMeta {
    RunMeta {
        tool_version: TOOL_VERSION.to_string(),
        params_toml: Params::table_i().to_toml(),
        command_line: "tiltnoise tf --out tf.h5 --freq 1e-4:40:10 (ünïcode ok)".to_string(),
        modes: vec![(1, 0.0123), (2, 0.5), (8, 17.25)],
    }
}

#[test]
fn hdf5_round_trip_is_bit_exact_and_self_describing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tf.h5");
    let tf = table_i_tf(&freqs());
    let meta = meta();
    Staging::committed(|s| save_tf(s, &path, &tf, &meta, &Default::default())).unwrap();
    assert_eq!(
        listing(dir.path()),
        vec![path.clone()],
        "no temporary file left"
    );

    let file = hdf5::File::open(&path).unwrap();
    assert_eq!(str_attr(&file, "schema"), "tiltnoise.tf");
    let version = file.attr("schema_version").unwrap();
    assert!(matches!(
        version.dtype().unwrap().to_descriptor().unwrap(),
        hdf5::types::TypeDescriptor::Integer(_)
    ));
    assert_eq!(
        version.read_scalar::<i64>().unwrap(),
        tiltnoise_io::SCHEMA_VERSION_TF
    );
    assert_eq!(str_attr(&file, "tool_version"), env!("CARGO_PKG_VERSION"));
    assert_eq!(str_attr(&file, "created_by"), meta.command_line);
    assert_eq!(str_attr(&file, "method"), "direct");
    let toml_text = str_attr(&file, "parameters_toml");
    assert_eq!(toml_text, meta.params_toml);
    assert_eq!(
        Params::from_toml_str(&toml_text, "file").unwrap(),
        Params::table_i(),
        "the stored parameter set reads back"
    );
    assert_eq!(
        str_attr(&file, "sign_convention"),
        "tilt t = small right-handed rotation taking the floor frame to the inertial frame; \
         X -> -eta_t (Z+Z_b+h_c), Y -> +theta_t (Z+Z_b+h_c) as f -> 0"
    );
    assert_eq!(str_attr(&file, "time_dependence"), "exp(+i w t)");

    let f = file.dataset("frequency_hz").unwrap();
    assert_eq!(str_attr(&f, "unit"), "Hz");
    let f = f.read_1d::<f64>().unwrap();
    assert_eq!(f.len(), tf.freqs_hz.len());
    for (a, b) in f.iter().zip(&tf.freqs_hz) {
        assert_eq!(a.to_bits(), b.to_bits());
    }

    let outputs = ["X", "Y", "Z", "theta", "eta", "phi", "phi_a"];
    let inputs = ["theta_t", "eta_t", "phi_t"];
    let h = file.dataset("transfer").unwrap();
    assert_eq!(h.shape(), vec![tf.freqs_hz.len(), 7, 3]);
    assert_eq!(strs_attr(&h, "outputs"), outputs);
    assert_eq!(strs_attr(&h, "inputs"), inputs);
    let units = strs_attr(&h, "unit");
    assert_eq!(units.len(), 21);
    assert_eq!(&units[..3], ["m/rad"; 3]);
    assert_eq!(&units[9..12], ["rad/rad"; 3]);
    for o in 0..7 {
        for i in 0..3 {
            assert_eq!(units[o * 3 + i], tf.unit(o, i));
        }
    }
    let values = h.read::<Complex64, ndarray::Ix3>().unwrap();
    let mut zeros = 0;
    for k in 0..tf.freqs_hz.len() {
        for o in 0..7 {
            for i in 0..3 {
                let (a, b) = (values[[k, o, i]], tf.get(k, o, i));
                assert_eq!(a.re.to_bits(), b.re.to_bits(), "re at ({k},{o},{i})");
                assert_eq!(a.im.to_bits(), b.im.to_bits(), "im at ({k},{o},{i})");
                zeros += usize::from(b.re == 0.0) + usize::from(b.im == 0.0);
            }
        }
    }
    assert!(zeros > 0, "the decoupled blocks give exact zeros");

    assert_eq!(strs_dataset(&file, "outputs"), outputs);
    assert_eq!(strs_dataset(&file, "inputs"), inputs);
    assert_eq!(
        strs_dataset(&file, "output_units"),
        ["m", "m", "m", "rad", "rad", "rad", "rad"]
    );
    assert_eq!(strs_dataset(&file, "input_units"), ["rad"; 3]);

    let idx = file.dataset("modes/index").unwrap();
    assert!(matches!(
        idx.dtype().unwrap().to_descriptor().unwrap(),
        hdf5::types::TypeDescriptor::Integer(hdf5::types::IntSize::U8)
    ));
    assert_eq!(idx.read_1d::<i64>().unwrap().to_vec(), [1, 2, 8]);
    let mf = file.dataset("modes/frequency_hz").unwrap();
    assert_eq!(str_attr(&mf, "unit"), "Hz");
    assert_eq!(mf.read_1d::<f64>().unwrap().to_vec(), [0.0123, 0.5, 17.25]);
}

#[test]
fn hdf5_without_modes_has_no_modes_group() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tf.hdf5");
    let meta = RunMeta {
        modes: vec![],
        ..meta()
    };
    Staging::committed(|s| write_tf_hdf5(s, &path, &table_i_tf(&[0.1, 1.0]), &meta)).unwrap();
    let file = hdf5::File::open(&path).unwrap();
    assert!(file.group("modes").is_err());
    assert_eq!(file.dataset("transfer").unwrap().shape(), vec![2, 7, 3]);
}

#[test]
fn csv_round_trip_is_bit_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tf.csv");
    let tf = table_i_tf(&freqs());
    Staging::committed(|s| save_tf(s, &path, &tf, &meta(), &Default::default())).unwrap();
    assert_eq!(
        listing(dir.path()),
        vec![path.clone()],
        "no temporary file left"
    );

    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.ends_with('\n'));
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header = lines.next().unwrap();
    assert!(header.starts_with(
        "frequency_hz,X.theta_t.re,X.theta_t.im,X.eta_t.re,X.eta_t.im,X.phi_t.re,X.phi_t.im,\
         Y.theta_t.re,Y.theta_t.im,"
    ));
    assert!(header.ends_with(",phi_a.phi_t.re,phi_a.phi_t.im"));
    let mut expected = vec!["frequency_hz".to_string()];
    for o in &tf.outputs {
        for i in &tf.inputs {
            for part in ["re", "im"] {
                expected.push(format!("{}.{}.{part}", o.name(), i.name()));
            }
        }
    }
    assert_eq!(header.split(',').collect::<Vec<_>>(), expected);

    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), tf.freqs_hz.len());
    let mut zeros = 0;
    for (k, row) in rows.iter().enumerate() {
        let cells: Vec<&str> = row.split(',').collect();
        assert_eq!(cells.len(), 1 + 2 * 21, "row {k}");
        let parse = |s: &str| -> f64 {
            assert!(!s.contains(' '), "no padding: {s:?}");
            s.parse().unwrap()
        };
        assert_eq!(parse(cells[0]).to_bits(), tf.freqs_hz[k].to_bits());
        for o in 0..7 {
            for i in 0..3 {
                let h = tf.get(k, o, i);
                let c = 1 + 2 * (o * 3 + i);
                for (cell, want) in [(cells[c], h.re), (cells[c + 1], h.im)] {
                    assert_eq!(parse(cell).to_bits(), want.to_bits(), "{cell} vs {want:e}");
                    if want == 0.0 {
                        zeros += 1;
                        assert!(cell == "0" || cell == "-0", "zero written as {cell}");
                    }
                }
            }
        }
    }
    assert!(zeros > 0, "the decoupled blocks give exact zeros");
    assert!(rows[0].starts_with("0,"), "0 Hz is written as 0");
}

#[test]
fn extension_picks_the_format_case_insensitively() {
    for (name, kind) in [
        ("a.h5", OutputKind::Hdf5),
        ("a.HDF5", OutputKind::Hdf5),
        ("dir.x/a.H5", OutputKind::Hdf5),
        ("a.Csv", OutputKind::Csv),
        ("a.png", OutputKind::Png),
        ("a.SVG", OutputKind::Svg),
    ] {
        assert_eq!(
            OutputKind::from_path(Path::new(name)).unwrap(),
            kind,
            "{name}"
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tf.H5");
    Staging::committed(|s| save_tf(s, &path, &table_i_tf(&[1.0]), &meta(), &Default::default()))
        .unwrap();
    assert!(hdf5::File::open(&path).is_ok());
}

#[test]
fn unknown_extension_is_rejected_naming_the_allowed_ones() {
    let dir = tempfile::tempdir().unwrap();
    let tf = table_i_tf(&[1.0]);
    for name in ["tf.xyz", "tf", "tf.h5.bak"] {
        let path = dir.path().join(name);
        let err = Staging::committed(|s| save_tf(s, &path, &tf, &meta(), &Default::default()))
            .unwrap_err();
        match &err {
            OutputError::UnknownFormat { path: p, allowed } => {
                assert_eq!(p, &path);
                for ext in [".h5", ".hdf5", ".csv", ".png", ".svg"] {
                    assert!(allowed.contains(ext), "{allowed}");
                }
            }
            other => panic!("expected UnknownFormat, got {other:?}"),
        }
        let msg = err.to_string();
        assert!(msg.contains(&path.display().to_string()), "{msg}");
        assert!(msg.contains(".h5") && msg.contains(".csv"), "{msg}");
    }
    assert!(listing(dir.path()).is_empty(), "nothing written");
}

#[test]
fn missing_directory_is_an_error_naming_the_path_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let tf = table_i_tf(&[1.0]);
    for name in ["tf.h5", "tf.csv"] {
        let path = dir.path().join("no_such_dir").join(name);
        let err = Staging::committed(|s| save_tf(s, &path, &tf, &meta(), &Default::default()))
            .unwrap_err();
        match &err {
            OutputError::Write { path: p, message } => {
                assert_eq!(p, &path);
                let message = message.to_string();
                #[cfg(unix)]
                assert!(message.contains("No such file or directory"), "{message}");
                assert!(!message.contains(".tmp"), "no temporary name: {message}");
            }
            other => panic!("expected Write, got {other:?}"),
        }
        assert!(err.to_string().contains(&path.display().to_string()));
        assert!(!path.exists());
    }
    assert!(listing(dir.path()).is_empty(), "nothing written");
}

#[test]
fn overwriting_an_existing_file_works() {
    let dir = tempfile::tempdir().unwrap();
    let (tf1, tf2) = (table_i_tf(&[0.1, 1.0, 10.0]), table_i_tf(&[2.0]));
    let h5 = dir.path().join("tf.h5");
    let csv = dir.path().join("tf.csv");
    for tf in [&tf1, &tf2] {
        Staging::committed(|s| save_tf(s, &h5, tf, &meta(), &Default::default())).unwrap();
        Staging::committed(|s| save_tf(s, &csv, tf, &meta(), &Default::default())).unwrap();
    }
    let file = hdf5::File::open(&h5).unwrap();
    assert_eq!(
        file.dataset("frequency_hz")
            .unwrap()
            .read_1d::<f64>()
            .unwrap()
            .to_vec(),
        [2.0]
    );
    drop(file);
    let text = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(text.lines().filter(|l| !l.starts_with('#')).count(), 2);
    assert!(text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .nth(1)
        .unwrap()
        .starts_with("2,"));
    assert_eq!(listing(dir.path()), vec![csv, h5]);
}

#[test]
fn failed_write_does_not_clobber_an_existing_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tf.h5");
    std::fs::write(&path, b"precious").unwrap();

    // A closure that fails after writing into its file, in a staging directory of its own
    // beside the target.
    let mut seen = None;
    let stage = Staging::new();
    let err = stage
        .write(&path, |temp| {
            let staging = temp.parent().unwrap();
            assert_eq!(staging.parent(), Some(dir.path()), "beside the target");
            let name = staging.file_name().unwrap().to_str().unwrap();
            assert!(
                name.starts_with(".tf.h5.") && name.ends_with(".tmp"),
                "{name}"
            );
            assert_eq!(temp.file_name().unwrap(), "tf.h5", "the target's name");
            assert!(!temp.exists(), "created by the writer");
            seen = Some(staging.to_path_buf());
            std::fs::write(temp, b"half-written").unwrap();
            Err("boom".to_string())
        })
        .unwrap_err();
    match err {
        OutputError::Write { path: p, message } => {
            assert_eq!(p, path);
            assert_eq!(message, "boom".into());
        }
        other => panic!("expected Write, got {other:?}"),
    }
    assert!(!seen.unwrap().exists(), "staging directory removed");
    assert_eq!(std::fs::read(&path).unwrap(), b"precious");

    // A real writer failing (inconsistent matrix) leaves the old file alone too.
    let mut bad = table_i_tf(&[1.0, 2.0]);
    bad.freqs_hz.push(3.0);
    let err = Staging::committed(|s| write_tf_hdf5(s, &path, &bad, &meta())).unwrap_err();
    assert!(matches!(err, OutputError::Write { .. }), "{err:?}");
    assert_eq!(std::fs::read(&path).unwrap(), b"precious");
    assert_eq!(listing(dir.path()), vec![path.clone()]);

    // And without an existing file, a failure leaves nothing.
    let csv = dir.path().join("new.csv");
    assert!(stage.write(&csv, |_| Err("no".into())).is_err());
    assert_eq!(stage.commit().unwrap(), Vec::<std::path::PathBuf>::new());
    assert_eq!(listing(dir.path()), vec![path]);
}

#[test]
fn csv_writer_can_be_called_directly() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("direct.csv");
    Staging::committed(|s| {
        write_tf_csv(
            s,
            &path,
            &table_i_tf(&[1.0]),
            &tiltnoise_io::RunMeta::default(),
        )
    })
    .unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    // The `#` lines, the header and one line per frequency.
    assert_eq!(text.lines().filter(|l| !l.starts_with('#')).count(), 2);
    assert_eq!(listing(dir.path()), vec![path]);
}

#[test]
fn figures_are_dispatched_to_the_plot_module() {
    let dir = tempfile::tempdir().unwrap();
    let tf = table_i_tf(&freqs()[1..]);
    let svg = dir.path().join("tf.SVG");
    let png = dir.path().join("tf.png");
    Staging::committed(|s| save_tf(s, &svg, &tf, &meta(), &Default::default())).unwrap();
    Staging::committed(|s| save_tf(s, &png, &tf, &meta(), &Default::default())).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("<svg"), "an SVG document");
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "a PNG image");
    assert_eq!(listing(dir.path()), vec![svg, png]);
}
