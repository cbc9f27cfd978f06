//! The fuzz targets: one function per reader, taking the path of an input file. Each runs its
//! readers under every option set that selects different code, formats every error (a
//! `Display` impl can panic too) and checks what a successful read promises. A reader's error
//! is a correct answer; a panic is the finding.
//!
//! Always checked: frequency grids and files finite, parameters that read back unchanged, and
//! the finiteness policy (`tiltnoise_core::limits::magnitude`): every sample of a series read
//! within `SAMPLES` and its sample rate within `SAMPLE_RATES`, spectra finite with increasing
//! frequencies, measured ASDs within `ASDS`. Checked with `TILTNOISE_FUZZ_STRICT` set: sigmas
//! of measured modes > 0, streamed chunks bit-identical to the in-memory read.
//!
//! Self-contained (std, `tiltnoise-core`, `tiltnoise-io`), so that libFuzzer targets for
//! nightly can compile this file as it is (`docs/robustness.md`).

use std::path::Path;
use tiltnoise_core::freq::parse_spec;
use tiltnoise_core::limits::{Magnitudes, ASDS, SAMPLES, SAMPLE_RATES};
use tiltnoise_core::params::Params;
use tiltnoise_io::input::{
    read_asd_column, read_measured, read_measured_input, read_tilt, read_tilt_series,
    read_tilt_spectra, AxisMap, ChannelScale, GapPolicy, MeasuredInput, Quantity, ReadOptions,
    TiltInput, TiltSeries, TiltSeriesSource, TiltSpectra,
};
use tiltnoise_io::{read_freq_file, read_measured_modes};

/// A reader under fuzzing: its name (also the corpus directory under `tests/fuzz_corpus/`),
/// the extension its input files need, and the function that reads one.
#[derive(Clone, Copy)]
pub struct Target {
    /// Name of the target and of its corpus directory.
    pub name: &'static str,
    /// Extension of the input file (the tilt readers dispatch on it).
    pub ext: &'static str,
    /// Runs the readers on the file; panics on a finding.
    pub read: fn(&Path),
}

/// CSV tilt series and spectra: [`read_tilt`] and the kind-specific readers.
pub const TILT_CSV: Target = Target {
    name: "tilt_csv",
    ext: "csv",
    read: read_tilt_any,
};
/// HDF5 tilt series and spectra, from mutated bytes of valid files.
pub const TILT_H5_BYTES: Target = Target {
    name: "tilt_h5_bytes",
    ext: "h5",
    read: read_hdf5_any,
};
/// HDF5 inputs written with unexpected types, shapes, encodings and links.
pub const H5_STRUCTURED: Target = Target {
    name: "h5_structured",
    ext: "h5",
    read: read_hdf5_any,
};
/// HDF5 time series of the observables (`read_measured_input`), from mutated bytes.
pub const MEASURED_H5_BYTES: Target = Target {
    name: "measured_h5_bytes",
    ext: "h5",
    read: read_hdf5_any,
};
/// Measured spectra and series of the observables, CSV.
pub const MEASURED_CSV: Target = Target {
    name: "measured_csv",
    ext: "csv",
    read: read_measured_csv,
};
/// Measured mode frequencies for the fit.
pub const MEASURED_MODES: Target = Target {
    name: "measured_modes",
    ext: "csv",
    read: read_modes,
};
/// Frequency files of `tf --freq-file`.
pub const FREQ_FILE: Target = Target {
    name: "freq_file",
    ext: "txt",
    read: read_freqs,
};
/// `FLO:N:FHI` specifications of `tf --freq`, one per line.
pub const FREQ_SPEC: Target = Target {
    name: "freq_spec",
    ext: "txt",
    read: parse_specs,
};
/// Parameter files (TOML).
pub const PARAMS_TOML: Target = Target {
    name: "params_toml",
    ext: "toml",
    read: read_params,
};
/// `--set KEY=VALUE` overrides of Table I, one per line, applied in turn.
pub const PARAMS_OVERRIDE: Target = Target {
    name: "params_override",
    ext: "txt",
    read: apply_overrides,
};

/// miniSEED 2 tilt series (the decoder, the merge of records, the channel selection).
pub const MINISEED: Target = Target {
    name: "miniseed",
    ext: "mseed",
    read: read_miniseed,
};

/// Every target.
pub const ALL: [Target; 11] = [
    TILT_CSV,
    TILT_H5_BYTES,
    H5_STRUCTURED,
    MEASURED_H5_BYTES,
    MEASURED_CSV,
    MEASURED_MODES,
    FREQ_FILE,
    FREQ_SPEC,
    PARAMS_TOML,
    PARAMS_OVERRIDE,
    MINISEED,
];

/// Whether the promise checks with open findings run (`TILTNOISE_FUZZ_STRICT` set).
fn strict() -> bool {
    static STRICT: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *STRICT.get_or_init(|| std::env::var_os("TILTNOISE_FUZZ_STRICT").is_some())
}

/// Reader options that take different paths: the defaults; a rate with gap
/// bridging; an explicit axis map with signs.
fn option_sets() -> [ReadOptions; 3] {
    [
        ReadOptions::default(),
        ReadOptions {
            quantity: Some(Quantity::Rate),
            gaps: GapPolicy::Interpolate,
            ..ReadOptions::default()
        },
        ReadOptions {
            axis_map: Some(
                AxisMap::parse("theta_t=-E,eta_t=+N,phi_t=-LJZ").expect("a valid axis map"),
            ),
            quantity: Some(Quantity::Angle),
            ..ReadOptions::default()
        },
    ]
}

/// The text of an error, formatted as the command line would print it.
fn shown<T, E: std::fmt::Display>(r: Result<T, E>) -> Option<T> {
    match r {
        Ok(v) => Some(v),
        Err(e) => {
            std::hint::black_box(e.to_string());
            None
        }
    }
}

fn assert_finite(what: &str, values: impl IntoIterator<Item = f64>) {
    if let Some((i, v)) = values.into_iter().enumerate().find(|(_, v)| !v.is_finite()) {
        panic!("a successful read returned {what}[{i}] = {v}");
    }
}

fn assert_increasing(what: &str, freqs: &[f64]) {
    assert!(
        freqs.len() >= 2,
        "{what}: {} values, at least 2 promised",
        freqs.len()
    );
    assert!(freqs[0] > 0.0, "{what}[0] = {} is not > 0", freqs[0]);
    if let Some(k) = (1..freqs.len()).find(|&k| freqs[k] <= freqs[k - 1]) {
        panic!(
            "{what} not strictly increasing at {k}: {:?}",
            &freqs[k - 1..=k]
        );
    }
}

/// Every value of `values` within `allowed` (the readers' finiteness policy).
fn assert_admitted(what: &str, values: &[f64], allowed: &Magnitudes) {
    if let Some((i, v)) = allowed.first_refused(values) {
        panic!("a successful read returned {what}[{i}] = {v}, outside {allowed:?}");
    }
}

fn check_series(s: &TiltSeries) {
    assert!(
        SAMPLE_RATES.admits(s.sample_rate_hz),
        "sample rate {}",
        s.sample_rate_hz
    );
    assert_eq!(s.data.len(), s.axes.len(), "one channel per axis");
    for (axis, ch) in s.axes.iter().zip(&s.data) {
        assert!(
            ch.len() >= 2 && ch.len() == s.data[0].len(),
            "channel lengths"
        );
        assert_admitted(&format!("series {axis:?}"), ch, &SAMPLES);
    }
}

fn check_spectra(s: &TiltSpectra) {
    assert_increasing("frequency", &s.freqs_hz);
    let n = s.axes.len();
    assert_eq!(s.csd.len(), s.freqs_hz.len() * n * n, "CSD size");
    assert_finite("CSD", s.csd.iter().flat_map(|c| [c.re, c.im]));
}

fn check_tilt(input: &TiltInput) {
    match input {
        TiltInput::Series(s) => check_series(s),
        TiltInput::Spectra(s) => check_spectra(s),
    }
}

fn check_measured(m: &MeasuredInput) {
    match m {
        MeasuredInput::Spectra(s) => {
            assert_increasing("measured frequency", &s.freqs_hz);
            for (o, asd) in &s.asd {
                assert_eq!(asd.len(), s.freqs_hz.len(), "{o:?}: one ASD per frequency");
                assert_admitted(&format!("measured ASD {o:?}"), asd, &ASDS);
            }
        }
        MeasuredInput::Series(s) => {
            assert!(SAMPLE_RATES.admits(s.sample_rate_hz));
            for (o, x) in &s.channels {
                assert!(
                    x.len() >= 2 && x.len() == s.channels[0].1.len(),
                    "{o:?}: lengths"
                );
                assert_admitted(&format!("measured series {o:?}"), x, &SAMPLES);
            }
        }
    }
}

/// The tilt readers on a file of any format; the kind-specific readers with the defaults.
fn read_tilt_any(path: &Path) {
    for opts in option_sets() {
        if let Some(input) = shown(read_tilt(path, &opts)) {
            check_tilt(&input);
        }
    }
    let opts = ReadOptions::default();
    if let Some(s) = shown(read_tilt_series(path, &opts)) {
        check_series(&s);
    }
    if let Some(s) = shown(read_tilt_spectra(path, &opts)) {
        check_spectra(&s);
    }
}

/// The tilt readers on a miniSEED file, and once more with every channel of the seed files
/// scaled (counts need a scale to reach the merge) and gaps bridged.
fn read_miniseed(path: &Path) {
    read_tilt_any(path);
    let scale = ["BJE", "BJN", "BJZ", "BAE"]
        .iter()
        .map(|c| ChannelScale {
            channel: format!("XX.TILT.00.{c}"),
            factor: 1e-9,
        })
        .collect::<Vec<_>>();
    for gaps in [GapPolicy::Reject, GapPolicy::Interpolate] {
        let opts = ReadOptions {
            axis_map: Some(AxisMap::parse("theta_t=-BJE,eta_t=-BJN").expect("a valid axis map")),
            quantity: Some(Quantity::Rate),
            gaps,
            scale: scale.clone(),
            ..ReadOptions::default()
        };
        if let Some(s) = shown(read_tilt_series(path, &opts)) {
            check_series(&s);
        }
    }
}

/// Every HDF5 reader: the tilt readers, streaming against in-memory, the measured series.
fn read_hdf5_any(path: &Path) {
    read_tilt_any(path);
    if strict() {
        for opts in option_sets() {
            streamed_equals_in_memory(path, &opts);
        }
    }
    if let Some(m) = shown(read_measured_input(path)) {
        check_measured(&m);
    }
}

/// When the in-memory read succeeds, the streaming source opens and every chunk, read forward
/// in small pieces and once more backward from the middle, is bit-identical to it.
fn streamed_equals_in_memory(path: &Path, opts: &ReadOptions) {
    let Some(whole) = shown(read_tilt_series(path, opts)) else {
        return;
    };
    let mut src = TiltSeriesSource::open(path, opts)
        .unwrap_or_else(|e| panic!("read_tilt_series succeeded, TiltSeriesSource::open: {e}"));
    let n = src.len();
    assert_eq!(n, whole.len(), "streamed length");
    let step = 5;
    let forward = (0..n).step_by(step).map(|s| (s, step.min(n - s)));
    let backward = [(n / 2, n - n / 2), (0, n / 2)];
    for (start, len) in forward.chain(backward) {
        let chunk = src
            .read_chunk(start, len)
            .unwrap_or_else(|e| panic!("read_all succeeded, read_chunk({start}, {len}): {e}"));
        for (a, (c, w)) in chunk.iter().zip(&whole.data).enumerate() {
            let same = c.len() == len
                && c.iter()
                    .zip(&w[start..start + len])
                    .all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(
                same,
                "axis {a}, chunk ({start}, {len}) differs from read_all"
            );
        }
    }
}

fn read_measured_csv(path: &Path) {
    if let Some(m) = shown(read_measured_input(path)) {
        check_measured(&m);
    }
    if let Some(s) = shown(read_measured(path)) {
        check_measured(&MeasuredInput::Spectra(s));
    }
    // The ASD reader of --readout OBS=FILE and --term reads the same layout, one column.
    for quantity in ["X", "phi", "F_b.x"] {
        if let Some(c) = shown(read_asd_column(path, quantity, "m/sqrt(Hz)")) {
            assert!(c.freqs_hz.len() >= 2 && c.freqs_hz.len() == c.asd.len());
            assert!(c.freqs_hz[0] > 0.0);
            assert!(c
                .freqs_hz
                .windows(2)
                .all(|w| w[1] > w[0] && w[1].is_finite()));
            assert!(
                c.asd.iter().all(|a| a.is_finite() && *a >= 0.0),
                "{:?}",
                c.asd
            );
        }
    }
}

fn read_modes(path: &Path) {
    if let Some(m) = shown(read_measured_modes(path)) {
        assert!(!m.modes.is_empty(), "no modes");
        for mode in &m.modes {
            assert!((1..=8).contains(&mode.mode), "mode {}", mode.mode);
            assert!(mode.frequency_hz.is_finite() && mode.frequency_hz > 0.0);
            assert!(
                !strict() || (mode.sigma_hz.is_finite() && mode.sigma_hz > 0.0),
                "mode {}: sigma {} Hz",
                mode.mode,
                mode.sigma_hz
            );
        }
    }
}

fn read_freqs(path: &Path) {
    if let Some(f) = shown(read_freq_file(path)) {
        assert!(!f.is_empty());
        assert!(f.iter().all(|v| v.is_finite() && *v >= 0.0), "{f:?}");
    }
}

/// The lines of a text input (bytes that are not UTF-8 replaced: command-line arguments are
/// text by the time they reach the library).
fn lines(path: &Path) -> Vec<String> {
    let bytes = std::fs::read(path).expect("the input file was just written");
    String::from_utf8_lossy(&bytes)
        .lines()
        .map(str::to_string)
        .collect()
}

fn parse_specs(path: &Path) {
    for spec in lines(path) {
        if let Some(grid) = shown(parse_spec(&spec)) {
            assert!(!grid.is_empty(), "{spec}: empty grid");
            assert_finite(&format!("grid of {spec}"), grid.iter().copied());
            assert!(grid[0] > 0.0, "{spec}: grid starts at {}", grid[0]);
        }
    }
}

/// A parameter set written by `to_toml` reads back unchanged.
fn check_round_trip(p: &Params) {
    let text = p.to_toml();
    let back = Params::from_toml_str(&text, "to_toml output")
        .unwrap_or_else(|e| panic!("to_toml output does not read back: {e}\n{text}"));
    assert!(back == *p, "to_toml output reads back different:\n{text}");
}

fn read_params(path: &Path) {
    if let Some(p) = shown(tiltnoise_io::read_params(path)) {
        check_round_trip(&p);
    }
}

fn apply_overrides(path: &Path) {
    let mut p = Params::table_i();
    for assignment in lines(path) {
        if let Some(q) = shown(p.with_override(&assignment)) {
            p = q;
        }
    }
    check_round_trip(&p);
}
