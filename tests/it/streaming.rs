//! Long runs written as they are computed: `simulate` (the record chunk by chunk) and `tf`
//! (the grid block by block) give the numbers of the one-shot computation whatever the chunk
//! or block size, and a run that fails or is interrupted part-way leaves no file (the
//! interrupt itself is tested in `process.rs`).

use crate::common::{self, listing, tiltnoise};
use tiltnoise_core::model::{Coord, Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::Params;
use tiltnoise_core::simulate::{equal_energy_init, simulate, SimConfig, DEFAULT_MODE_ENERGY_J};
use tiltnoise_core::spectral::{welch, WelchConfig};
use tiltnoise_core::tf::{self, Method, Request};

fn ok(args: &[&str]) -> String {
    let out = tiltnoise(args);
    assert!(out.status.success(), "{args:?}: {}", common::stderr(&out));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn read_f64(file: &hdf5::File, name: &str) -> Vec<f64> {
    file.dataset(name).unwrap().read_raw::<f64>().unwrap()
}

fn same_bits(what: &str, got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert_eq!(g.to_bits(), w.to_bits(), "{what}[{i}]: {g} vs {w}");
    }
}

/// Chunks of 7 samples (every HDF5 chunk and Welch segment boundary crossed many times) give
/// the series, coordinates and ASDs of the library's one-shot `simulate` and `welch`, bit for
/// bit; so does the default chunk size.
#[test]
fn a_simulation_written_in_chunks_is_the_one_shot_record() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let run = |chunk: &str, name: &str| {
        let (h5, csv) = (d.join(format!("{name}.h5")), d.join(format!("{name}.csv")));
        let mut args = vec![
            "simulate",
            "--duration",
            "3000.3",
            "--readout",
            "theta=1e-9",
            "--seed",
            "3",
            "--nperseg",
            "1024",
            "--with-coordinates",
            "--save",
            h5.to_str().unwrap(),
            "--save",
            csv.to_str().unwrap(),
        ];
        if !chunk.is_empty() {
            args.extend(["--chunk-samples", chunk]);
        }
        ok(&args);
        (
            h5,
            without_command_line(&std::fs::read_to_string(&csv).unwrap()),
        )
    };
    let (small, small_csv) = run("7", "small");
    let (default, default_csv) = run("", "default");
    assert_eq!(small_csv, default_csv, "ASD CSV depends on the chunk size");

    let model = Model::new(&Params::table_i()).unwrap();
    let cfg = SimConfig {
        dt_s: 0.1,
        duration_s: 3000.3,
        readout_asd: vec![(Observable::X, 9e-9), (Observable::Theta, 1e-9)],
        seed: 3,
        ..SimConfig::default()
    };
    let init = equal_energy_init(&model, DEFAULT_MODE_ENERGY_J);
    let sim = simulate(&model, &init, &cfg).unwrap();
    let wcfg = WelchConfig::new(1024);
    for path in [&small, &default] {
        let file = hdf5::File::open(path).unwrap();
        for (o, x) in &sim.observables {
            same_bits(o.name(), &read_f64(&file, o.name()), x);
            let asd = welch(x, sim.fs_hz(), &wcfg).unwrap().asd();
            same_bits(
                &format!("asd/{}", o.name()),
                &read_f64(&file, &format!("asd/{}", o.name())),
                &asd,
            );
        }
        for c in Coord::ALL {
            let name = format!("coordinates/{}", c.name());
            same_bits(&name, &read_f64(&file, &name), &sim.coordinate(c.index()));
        }
        let ds = file.dataset("X").unwrap();
        assert_eq!(ds.chunk(), Some(vec![1 << 16]), "a chunked dataset");
    }
    // Without --with-coordinates only the observables are written.
    let h5 = d.join("plain.h5");
    ok(&[
        "simulate",
        "--duration",
        "600",
        "--save",
        h5.to_str().unwrap(),
    ]);
    let file = hdf5::File::open(&h5).unwrap();
    assert!(
        file.group("coordinates").is_err(),
        "coordinates not asked for"
    );
    assert_eq!(read_f64(&file, "X").len(), 6000);
}

/// `--with-coordinates` without an HDF5 output, and a chunk of no sample, are refused.
#[test]
fn streaming_options_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("a.csv");
    common::assert_fails_without_output(
        &[
            "simulate",
            "--with-coordinates",
            "--save",
            csv.to_str().unwrap(),
        ],
        dir.path(),
        &["--with-coordinates: the coordinates go to an HDF5 file"],
    );
    common::assert_fails_without_output(
        &["simulate", "--chunk-samples", "0"],
        dir.path(),
        &["--chunk-samples 0: a chunk must hold at least 1 sample"],
    );
    common::assert_fails_without_output(
        &["tf", "--block-freqs", "0"],
        dir.path(),
        &["--block-freqs 0: a block must hold at least 1 frequency"],
    );
}

/// Blocks of 10 frequencies give the library's one-shot `evaluate` in the HDF5 file, and the
/// CSV text of the one-shot path (taken when a figure is drawn) in the file and on standard
/// output.
#[test]
fn transfer_functions_written_in_blocks_are_the_one_shot_matrix() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let spec = "1e-3:997:10";
    let p = |name: &str| d.join(name).to_str().unwrap().to_string();
    let base = ["tf", "--freq", spec, "--method", "direct"];
    let with = |extra: &[&str]| -> String {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        ok(&args)
    };
    with(&[
        "--block-freqs",
        "10",
        "--save",
        &p("blocks.h5"),
        "--save",
        &p("blocks.csv"),
    ]);
    with(&["--save", &p("whole.csv"), "--save", &p("whole.png")]);
    let stdout = with(&["--block-freqs", "3"]);
    let blocks = without_command_line(&std::fs::read_to_string(d.join("blocks.csv")).unwrap());
    assert_eq!(
        blocks,
        without_command_line(&std::fs::read_to_string(d.join("whole.csv")).unwrap())
    );
    assert_eq!(without_command_line(&stdout), blocks);

    let model = Model::new(&Params::table_i()).unwrap();
    let plan = tf::plan(&model, &Request::all_tilt(), Method::Direct).unwrap();
    let freqs = tiltnoise_core::freq::parse_spec(spec).unwrap();
    let want = tf::evaluate(plan.as_ref(), &freqs).unwrap();
    let file = hdf5::File::open(d.join("blocks.h5")).unwrap();
    same_bits("frequency_hz", &read_f64(&file, "frequency_hz"), &freqs);
    let got = file
        .dataset("transfer")
        .unwrap()
        .read_raw::<num_complex::Complex64>()
        .unwrap();
    assert_eq!(got, want.dense_values());
    let modes = NormalModes::new(&model);
    same_bits(
        "modes/frequency_hz",
        &read_f64(&file, "modes/frequency_hz"),
        &modes.frequencies_hz(),
    );
}

/// A grid that fails part-way (an exact undamped resonance after the first blocks are
/// written) exits with 2 and leaves none of its outputs, temporary files included.
#[test]
fn a_grid_failing_after_its_first_blocks_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = Model::new(&Params::table_i()).unwrap();
    let nu_4 = NormalModes::new(&model).modes[3].frequency_hz;
    let mut text = String::new();
    for k in 1..=40 {
        text.push_str(&format!("{}\n", 1e-3 * k as f64));
    }
    text.push_str(&format!("{}\n", tiltnoise_io::format_f64(nu_4)));
    let freq_file = d.join("freqs.txt");
    std::fs::write(&freq_file, text).unwrap();
    let out_dir = d.join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let (h5, csv) = (out_dir.join("tf.h5"), out_dir.join("tf.csv"));
    common::assert_fails_without_output(
        &[
            "tf",
            "--freq-file",
            freq_file.to_str().unwrap(),
            "--method",
            "direct",
            "--block-freqs",
            "8",
            "--save",
            h5.to_str().unwrap(),
            "--save",
            csv.to_str().unwrap(),
        ],
        &out_dir,
        &["singular"],
    );
    assert!(listing(&out_dir).is_empty());
}

/// A CSV output without its `# created_by:` line (the command line, which differs between the
/// runs compared).
fn without_command_line(text: &str) -> String {
    text.lines()
        .filter(|l| !l.starts_with("# created_by:"))
        .map(|l| format!("{l}\n"))
        .collect()
}
