//! Figures written to files: `tiltnoise-plot` returns the bytes and the command line's output
//! dispatch (`src/cli/output.rs`) writes them atomically. A failure names the file and leaves
//! nothing behind; an existing file is replaced only by a complete figure.

use crate::common::listing;
use crate::output::save_image;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::model::{Model, Request};
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::{evaluate, plan, Method, TransferMatrix};
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
        let err = save_image(&path, |format| tf_figure(&tf, format)).unwrap_err();
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
        let err = save_image(&path, |_| panic!("{name}: drawn")).unwrap_err();
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
        let err = save_image(&path, |_| Err(DrawError("deliberate".to_string()))).unwrap_err();
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
    save_image(&path, |format| tf_figure(&tf, format)).unwrap();
    assert!(std::fs::read_to_string(&path).unwrap().starts_with("<svg"));
    assert_eq!(listing(dir.path()), vec![path]);
}
