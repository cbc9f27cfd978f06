//! The budget job: the floor's motion (a file, opened once, an HDF5 series streamed from it;
//! or a series the caller holds), the readout, user terms, witness noise, the measured record
//! and the frequencies to read the budget at, to a [`BudgetOutcome`]: the
//! [`BudgetReport`](tiltnoise_core::noise::BudgetReport) with the input's provenance and the
//! run's, its files, figure and summary.

mod arrays;
mod outcome;
mod summary;

pub use arrays::{array_input, ArrayError, ArrayOptions, ArrayRecord, ARRAYS_FORMAT, ARRAYS_PATH};
pub use outcome::{BudgetOutcome, SaveOptions, OUTPUT_KINDS};
pub use summary::asd_rel_std;

use crate::error::{shown_path, JobError};
use crate::given::{self, ReadoutItem, TermItem, WitnessItem};
use crate::outcome::Invocation;
use crate::progress::Progress;
use std::path::{Path, PathBuf};
use tiltnoise_core::budget::option_checks::InputKind;
use tiltnoise_core::budget::{
    budget_from_series, budget_from_spectra, BudgetError, BudgetOptions, SummaryRequest,
    DEFAULT_BAND_FRACTION,
};
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::error::Num;
use tiltnoise_core::freq;
use tiltnoise_core::input::{
    AxisMap, ChannelScale, ChannelUnit, GapPolicy, InputMeta, Quantity, ReadOptions, SeriesSource,
};
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::option_key::{Message, OptionKey};
use tiltnoise_core::repeats::refuse_repeats;
use tiltnoise_core::spectral::Averaging;
use tiltnoise_io::input::{add_measured_file, open_tilt, OpenedTilt};

/// How to read a file of the floor's motion; `None` and empty take the file's own statements,
/// else the documented defaults (`docs/input_formats.md`).
#[derive(Debug, Clone, Default)]
pub struct ReadRequest {
    /// The axis map.
    pub axis_map: Option<AxisMap>,
    /// The quantity of the tilt channels.
    pub quantity: Option<Quantity>,
    /// Units of channels the file does not state.
    pub units: Vec<ChannelUnit>,
    /// Translation channels whose tilt part is removed already.
    pub corrected: Vec<String>,
    /// Tilt channels read by a pendulum tiltmeter.
    pub pendulum_tiltmeter: Vec<String>,
    /// Non-finite samples of a series (default: reject).
    pub gaps: Option<GapPolicy>,
    /// Factors of source channels of a series.
    pub scale: Vec<ChannelScale>,
}

impl ReadRequest {
    /// The readers' options.
    pub(crate) fn options(&self) -> ReadOptions {
        ReadOptions {
            axis_map: self.axis_map.clone(),
            quantity: self.quantity,
            units: self.units.clone(),
            corrected: self.corrected.clone(),
            pendulum: self.pendulum_tiltmeter.clone(),
            gaps: self.gaps.unwrap_or_default(),
            scale: self.scale.clone(),
        }
    }
}

/// The floor's motion of a budget.
pub enum TiltSource<'a> {
    /// A file (HDF5, CSV, miniSEED; series or spectra), read as `read` says.
    File {
        /// The file (an HDF5 file may carry an object address, `FILE.h5:/group`).
        path: PathBuf,
        /// How to read it.
        read: ReadRequest,
    },
    /// Arrays the caller holds, described ([`ArrayRecord::new`]); their samples are checked
    /// (gaps, magnitudes, units) before the options.
    Arrays(ArrayRecord),
    /// A series the caller holds, already checked and in SI units, and what is known of it.
    Series {
        /// The series.
        source: &'a mut (dyn SeriesSource + Send),
        /// Its provenance, as the budget files keep it.
        input: InputMeta,
    },
}

/// The Welch and segment options of a series.
#[derive(Debug, Clone, Copy, Default)]
pub struct WelchRequest {
    /// Welch segment length (default: `tiltnoise_core::budget::default_segment_len`).
    pub nperseg: Option<usize>,
    /// Overlap as a fraction of the segment (default 0.5).
    pub overlap: Option<f64>,
    /// Mean (default) or median averaging.
    pub averaging: Option<Averaging>,
    /// Length (s) of the segments of the percentile band.
    pub segment_duration_s: Option<f64>,
    /// Percentiles of the band across segments (default 10, 90); needs segments.
    pub percentiles: Option<(f64, f64)>,
}

/// A noise budget to compute.
pub struct BudgetRequest<'a> {
    /// The model.
    pub model: &'a Model,
    /// The floor's motion.
    pub tilt: TiltSource<'a>,
    /// Welch and segment options (series only).
    pub welch: WelchRequest,
    /// The model grid of spectra input (Hz; default `freq::default_grid`).
    pub freq_hz: Option<Vec<f64>>,
    /// The observables budgeted (default X, phi, phi_a).
    pub observables: Option<Vec<Observable>>,
    /// Readout noise, over the default on X, in order.
    pub readout: Vec<ReadoutItem>,
    /// User-named terms.
    pub terms: Vec<TermItem>,
    /// Own noise of the instruments that recorded inputs of the floor (shown, not added).
    pub witness_noise: Vec<WitnessItem>,
    /// A measured record of the observables (adds `measured` and `residual`).
    pub measured: Option<PathBuf>,
    /// Frequencies (Hz) to read the budget at; given ones must lie in its band (default:
    /// `DEFAULT_SUMMARY_FREQS_HZ`, left out with a note where they do not).
    pub at_hz: Option<Vec<f64>>,
    /// Half-width of the band of the Welch band means, relative (default 0.1).
    pub at_band: Option<f64>,
    /// Who asked, for the provenance.
    pub invocation: Invocation,
}

impl BudgetRequest<'_> {
    /// The files the job reads besides the parameter file, each with the option (snake case)
    /// that names it: what no output of the run may replace.
    pub fn input_files(&self) -> Vec<(&'static str, &Path)> {
        let mut files = Vec::new();
        if let TiltSource::File { path, .. } = &self.tilt {
            files.push(("tilt", path.as_path()));
        }
        files.extend(self.measured.as_deref().map(|p| ("measured", p)));
        for r in &self.readout {
            if let given::AsdSpec::File(p) = &r.asd {
                files.push(("readout", p.as_path()));
            }
        }
        files.extend(self.terms.iter().map(|t| ("term", t.file.as_path())));
        for w in &self.witness_noise {
            if let given::AsdSpec::File(p) = &w.asd {
                files.push(("witness_noise", p.as_path()));
            }
        }
        files
    }

    /// The options of a time series that were given, in the order they are reported.
    fn series_options_given(&self) -> Vec<OptionKey> {
        let w = &self.welch;
        let mut given = vec![
            (OptionKey::NPERSEG, w.nperseg.is_some()),
            (OptionKey::OVERLAP, w.overlap.is_some()),
            (OptionKey::AVERAGE, w.averaging.is_some()),
            (OptionKey::SEGMENT_DURATION, w.segment_duration_s.is_some()),
        ];
        if let TiltSource::File { read, .. } = &self.tilt {
            given.extend([
                (OptionKey::GAPS, read.gaps.is_some()),
                (OptionKey::SCALE, !read.scale.is_empty()),
                (OptionKey::UNITS, !read.units.is_empty()),
                (OptionKey::CORRECTED, !read.corrected.is_empty()),
                (
                    OptionKey::PENDULUM_TILTMETER,
                    !read.pendulum_tiltmeter.is_empty(),
                ),
            ]);
        }
        given
            .into_iter()
            .filter_map(|(name, g)| g.then_some(name))
            .collect()
    }
}

/// The `at` and `at_band` request: given frequencies are refused when the budget cannot be
/// read there; the default ones are left out with a note.
fn summary(at_hz: Option<&[f64]>, at_band: Option<f64>) -> Result<SummaryRequest, JobError> {
    let mut req = SummaryRequest {
        band_fraction: at_band.unwrap_or(DEFAULT_BAND_FRACTION),
        ..SummaryRequest::default()
    };
    if let Some(f) = at_hz {
        refuse_repeats(OptionKey::AT, "frequency", f, |f| Num(*f).to_string())
            .map_err(JobError::Repeated)?;
        req.strict = true;
        req.freqs_hz = f.to_vec();
    }
    req.validate().map_err(|e| {
        let option = match at_band {
            Some(_) => OptionKey::AT_BAND,
            None => OptionKey::AT,
        };
        JobError::option(option, None, Message::shown(e))
    })?;
    Ok(req)
}

/// The budget's options from the request, every given file read and checked.
fn options(req: &BudgetRequest<'_>, cancel: &Cancel) -> Result<BudgetOptions, JobError> {
    let defaults = BudgetOptions::default();
    let w = &req.welch;
    if let Some((lower, upper)) = w.percentiles {
        if w.segment_duration_s.is_none() {
            return Err(JobError::PercentilesNeedSegments);
        }
        if !(0.0 <= lower && lower < upper && upper <= 100.0) {
            return Err(JobError::Percentiles { lower, upper });
        }
    }
    let outputs = req.observables.clone().unwrap_or(defaults.outputs);
    Ok(BudgetOptions {
        welch_segment_len: w.nperseg,
        welch_overlap_fraction: w.overlap.unwrap_or(defaults.welch_overlap_fraction),
        averaging: w.averaging.unwrap_or(defaults.averaging),
        segment_duration_s: w.segment_duration_s,
        percentiles: w.percentiles.unwrap_or(defaults.percentiles),
        readout: given::readout(&req.readout, &outputs)?,
        user_terms: given::terms(&req.terms, &outputs)?,
        witness_noise: given::witness_noise(&req.witness_noise)?,
        spectra_grid_hz: Vec::new(),
        summary: summary(req.at_hz.as_deref(), req.at_band)?,
        cancel: cancel.clone(),
        outputs,
    })
}

/// Refuses the first option given in `given` that does not apply to what `path` holds.
fn refuse(given: &[OptionKey], holds: InputKind, path: &str) -> Result<(), JobError> {
    match given.first() {
        Some(&option) => Err(JobError::NotForInput {
            option,
            holds,
            path: path.to_string(),
        }),
        None => Ok(()),
    }
}

/// Runs the budget: checks the options, reads every given file, opens the floor's motion
/// once (an HDF5 series is streamed, `progress` told the samples processed), computes the
/// budget, checks the witness noise against the record's inputs and adds the measured record.
/// The request is taken whole: a series it holds is read, not copied.
///
/// # Errors
///
/// A [`JobError`] naming the option, file or key that failed; `Budget` wrapping
/// `BudgetError::Cancelled` when `cancel` was set.
pub fn run(
    req: BudgetRequest<'_>,
    cancel: &Cancel,
    progress: &dyn Progress,
) -> Result<BudgetOutcome, JobError> {
    let result = budget(req, cancel, &mut |done, total| progress.report(done, total));
    progress.finish();
    result
}

/// [`run`], `progress(done, total)` called with the samples processed.
fn budget(
    req: BudgetRequest<'_>,
    cancel: &Cancel,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<BudgetOutcome, JobError> {
    // Arrays are checked as they are handed over, before the options (a file is read after).
    let mut req = req;
    if let TiltSource::Arrays(record) = &mut req.tilt {
        record.check_samples(cancel)?;
    }
    let mut opts = options(&req, cancel)?;
    let series_given = req.series_options_given();
    let spectra_given: Vec<OptionKey> = req.freq_hz.iter().map(|_| OptionKey::FREQ).collect();
    let model = req.model;
    let (report, input) = match req.tilt {
        TiltSource::File { path, read } => {
            let shown = shown_path(&path);
            match open_tilt(&path, &read.options())? {
                OpenedTilt::Streamed(mut source) => {
                    refuse(&spectra_given, InputKind::Series, &shown)?;
                    let input = InputMeta::from(source.provenance());
                    (
                        budget_from_series(model, &mut source, &opts, progress),
                        input,
                    )
                }
                OpenedTilt::Series(mut series) => {
                    refuse(&spectra_given, InputKind::Series, &shown)?;
                    let input = InputMeta::from(&series.provenance);
                    (
                        budget_from_series(model, &mut series, &opts, progress),
                        input,
                    )
                }
                OpenedTilt::Spectra(spectra) => {
                    refuse(&series_given, InputKind::Spectra, &shown)?;
                    opts.spectra_grid_hz = req.freq_hz.unwrap_or_else(|| freq::default_grid(model));
                    let input = InputMeta::from(&spectra.provenance);
                    (budget_from_spectra(model, &spectra, &opts), input)
                }
            }
        }
        TiltSource::Arrays(record) => {
            let (mut series, input) = record.into_series();
            refuse(&spectra_given, InputKind::Series, &input.path)?;
            (
                budget_from_series(model, &mut series, &opts, progress),
                input,
            )
        }
        TiltSource::Series { source, input } => {
            refuse(&spectra_given, InputKind::Series, &input.path)?;
            (budget_from_series(model, source, &opts, progress), input)
        }
    };
    let mut report = report.map_err(|source| JobError::Budget {
        path: input.path.clone(),
        source: Box::new(source),
    })?;
    for x in &opts.witness_noise {
        if !report.inputs.contains(&x.input) {
            return Err(JobError::option(
                OptionKey::WITNESS_NOISE,
                Some(x.input.name()),
                format!(
                    "the record {} has no input {}; it has {}",
                    input.path,
                    x.input.name(),
                    report
                        .inputs
                        .iter()
                        .map(|a| a.name())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
    }
    if let Some(path) = &req.measured {
        add_measured_file(&mut report, path).map_err(|e| match e {
            BudgetError::Input(e) => JobError::from(e),
            other => JobError::option(
                OptionKey::MEASURED,
                Some(&shown_path(path)),
                Message::shown(other),
            ),
        })?;
    }
    let provenance = req
        .invocation
        .provenance(model.params(), Some(&NormalModes::new(model)));
    Ok(BudgetOutcome::new(report, input, provenance))
}
