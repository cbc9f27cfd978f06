//! The jobs' outcomes against the command line: `json()` is the document `--format json`
//! prints, byte for byte, and `save` writes the files `--save` writes, given the command line's
//! invocation (the provenance records it).

use crate::coherence_cli::inputs;
use crate::common::{self, tiltnoise};
use serde_json::Value;
use std::path::Path;
use tiltnoise_core::model::Model;
use tiltnoise_core::params::Params;
use tiltnoise_job::budget::ReadRequest;
use tiltnoise_job::coherence::CoherenceRequest;
use tiltnoise_job::files::Staging;
use tiltnoise_job::{Cancel, Invocation, Outcome, Silent};

/// The invocation of the binary run with `args`, as its provenance records it.
fn invocation_of(args: &[&str]) -> Invocation {
    let mut all = vec![env!("CARGO_BIN_EXE_tiltnoise")];
    all.extend(args);
    Invocation {
        command_line: all.join(" "),
    }
}

/// Standard output of a run that succeeds.
fn stdout_of(args: &[&str]) -> String {
    let out = tiltnoise(args);
    assert!(out.status.success(), "{args:?}: {}", common::stderr(&out));
    String::from_utf8(out.stdout).unwrap()
}

/// The JSON text the command line prints for `value`.
fn printed(value: &Value) -> String {
    serde_json::to_string_pretty(value).unwrap() + "\n"
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn model() -> Model {
    Model::new(&Params::table_i()).unwrap()
}

#[test]
fn modes_and_params_print_their_jobs_outcome() {
    let model = model();
    let req = tiltnoise_job::modes::ModesRequest {
        model: &model,
        invocation: Invocation::default(),
    };
    let modes = tiltnoise_job::modes::run(&req, &Cancel::never(), &Silent).unwrap();
    assert_eq!(
        stdout_of(&["modes", "--format", "json"]),
        printed(&modes.json())
    );
    let req = tiltnoise_job::params::ParamsRequest {
        params: Params::table_i(),
        invocation: Invocation::default(),
    };
    let params = tiltnoise_job::params::run(&req, &Cancel::never(), &Silent).unwrap();
    assert_eq!(stdout_of(&["params"]), params.toml());
}

#[test]
fn the_methods_json_is_the_jobs_but_for_the_measured_times() {
    let spec = "1e-3:20:10";
    let text = stdout_of(&["methods", "--freq", spec, "--format", "json"]);
    let mut cli: Value = serde_json::from_str(&text).unwrap();
    // What the command line printed is the pretty form of its value (so equal values print
    // equal text).
    assert_eq!(text, printed(&cli));
    let model = model();
    let req = tiltnoise_job::methods::MethodsRequest {
        model: &model,
        grid_hz: tiltnoise_core::freq::parse_spec(spec).unwrap(),
        inputs: None,
        grid_spec: spec.into(),
        view: Default::default(),
        invocation: Invocation::default(),
    };
    let mut job = tiltnoise_job::methods::run(&req, &Cancel::never(), &Silent)
        .unwrap()
        .json();
    // The times per point are measured anew by every run.
    for v in [&mut cli, &mut job] {
        for m in v["methods"].as_array_mut().unwrap() {
            assert!(
                m["ns_per_point"].is_number() || m["unusable"].is_string(),
                "{m}"
            );
            m["ns_per_point"] = Value::Null;
        }
    }
    assert_eq!(cli, job);
}

#[test]
fn the_tf_outcome_saves_and_prints_what_the_command_line_does() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let freq = "1e-3:40:10";
    let (csv, h5, png) = (d.join("cli.csv"), d.join("cli.h5"), d.join("cli.png"));
    // A figure: the whole matrix saved by its outcome.
    let args = [
        "tf",
        "--freq",
        freq,
        "--save",
        s(&csv),
        "--save",
        s(&h5),
        "--save",
        s(&png),
    ];
    stdout_of(&args);
    let model = model();
    let req = tiltnoise_job::tf::TfRequest {
        model: &model,
        request: tiltnoise_core::tf::Request::all_tilt(),
        grid: tiltnoise_job::tf::FreqGrid::Log(
            tiltnoise_core::freq::parse_log_spec(freq, usize::MAX).unwrap(),
        ),
        per: tiltnoise_core::ground::GroundQuantity::Displacement,
        method: None,
        rel_tol: None,
        block_freqs: None,
        figure: Some(png.clone()),
        figure_options: tiltnoise_job::tf::figure_options(
            &model,
            tiltnoise_job::tf::FIGURE5_OBSERVABLES.to_vec(),
            false,
            // The caption names the option that picks the panels as the command line does.
            tiltnoise::option_style::rendered(
                &tiltnoise_core::option_key::OptionKey::DRAWN_OBSERVABLES,
            ),
        ),
        invocation: invocation_of(&args),
    };
    let outcome = tiltnoise_job::tf::run(&req, &Cancel::never(), &Silent).unwrap();
    let stage = Staging::new();
    for n in ["job.csv", "job.h5", "job.png"] {
        outcome.save(&stage, &d.join(n)).unwrap();
    }
    stage.commit().unwrap();
    let bytes = |p: &Path| std::fs::read(p).unwrap();
    assert_eq!(bytes(&csv), bytes(&d.join("job.csv")));
    // The figure is the command line's, pixel for pixel: its caption names the option that
    // picks the panels in the spelling the request was given.
    assert_eq!(
        decode_png(&bytes(&png)),
        decode_png(&bytes(&d.join("job.png")))
    );
    let read = |p: &Path| {
        let f = hdf5::File::open(p).unwrap();
        let names = f.member_names().unwrap();
        let read = |n: &str| {
            f.dataset(n)
                .unwrap()
                .read_raw::<num_complex::Complex64>()
                .unwrap()
        };
        let freqs = f
            .dataset("frequency_hz")
            .unwrap()
            .read_raw::<f64>()
            .unwrap();
        (
            names,
            freqs,
            read("transfer"),
            common::str_attr(&f, "created_by"),
        )
    };
    assert_eq!(read(&h5), read(&d.join("job.h5")));
    // Streamed (no figure): the same CSV file; on standard output, the same text.
    let streamed = d.join("streamed.csv");
    let args = ["tf", "--freq", freq, "--save", s(&streamed)];
    stdout_of(&args);
    let whole = Staging::new();
    let mut req = req;
    req.figure = None;
    req.invocation = invocation_of(&args);
    let outcome = tiltnoise_job::tf::run(&req, &Cancel::never(), &Silent).unwrap();
    outcome.save(&whole, &d.join("whole.csv")).unwrap();
    whole.commit().unwrap();
    assert_eq!(bytes(&streamed), bytes(&d.join("whole.csv")));
    let args = ["tf", "--freq", freq];
    req.invocation = invocation_of(&args);
    let outcome = tiltnoise_job::tf::run(&req, &Cancel::never(), &Silent).unwrap();
    let whole = Staging::new();
    outcome.save(&whole, &d.join("stdout.csv")).unwrap();
    whole.commit().unwrap();
    assert_eq!(stdout_of(&args).into_bytes(), bytes(&d.join("stdout.csv")));
    // JSON: the streamed document is the outcome's.
    let text = stdout_of(&["tf", "--freq", freq, "--format", "json"]);
    let cli: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(cli, outcome.json());
}

#[test]
fn the_coherence_outcome_saves_and_prints_what_the_command_line_does() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (tilt, measured) = inputs(d, 1.0, "2024-03-20T00:00:00Z");
    let (csv, png) = (d.join("cli.csv"), d.join("cli.png"));
    let args = [
        "coherence",
        "--tilt",
        s(&tilt),
        "--measured",
        s(&measured),
        "--nperseg",
        "1024",
        "--format",
        "json",
        "--save",
        s(&csv),
        "--save",
        s(&png),
    ];
    let text = stdout_of(&args);
    let model = model();
    let req = CoherenceRequest {
        model: &model,
        tilt: tilt.clone(),
        read: ReadRequest::default(),
        measured: measured.clone(),
        observables: None,
        nperseg: Some(1024),
        overlap: None,
        confidence: None,
        fit_band_hz: None,
        view: Default::default(),
        invocation: invocation_of(&args),
    };
    let outcome = tiltnoise_job::coherence::run(&req, &Cancel::never(), &Silent).unwrap();
    assert_eq!(text, printed(&outcome.json()));
    let stage = Staging::new();
    for n in ["job.csv", "job.png"] {
        outcome.save(&stage, &d.join(n)).unwrap();
    }
    stage.commit().unwrap();
    let bytes = |p: &Path| std::fs::read(p).unwrap();
    assert_eq!(bytes(&csv), bytes(&d.join("job.csv")));
    // The figure is the command line's but for its caption, which names the option that picks
    // the panels as the running front end spells it (`--plot-observables` there,
    // `drawn_observables` here, where no front end's style is installed): the same image size,
    // and the same pixels above the caption's last line.
    let (cli_png, job_png) = (
        decode_png(&bytes(&png)),
        decode_png(&bytes(&d.join("job.png"))),
    );
    assert_eq!((cli_png.0, cli_png.1), (job_png.0, job_png.1));
    // The caption's last line (`Not drawn ...`) starts below row 740 of the 1000-row figure.
    let row_bytes = cli_png.2.len() / cli_png.1 as usize;
    let above_caption_end = 740 * row_bytes;
    assert_eq!(
        cli_png.2[..above_caption_end],
        job_png.2[..above_caption_end]
    );
    assert_eq!(outcome.csv().into_bytes(), bytes(&csv));
}

/// Width, height and RGB(A) bytes of a PNG.
fn decode_png(bytes: &[u8]) -> (u32, u32, Vec<u8>) {
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}
