//! The subtract job: the record of the floor's motion (the witness, tilt and translation
//! channels), records of co-located instruments beside it and the measured record of the
//! observables, each read once; the coupling fitted, the tilt part predicted and removed
//! ([`tiltnoise_core::subtract`]), every number of the result checked finite, and the metadata
//! the cleaned record is written with.

use crate::budget::ReadRequest;
use crate::error::{shown_path, JobError};
use crate::given::{witness_noise, AsdSpec, WitnessItem};
use crate::outcome::Invocation;
use crate::progress::Progress;
use std::path::{Path, PathBuf};
use std::time::Duration;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::error::Num;
use tiltnoise_core::input::{GroundMap, InputMeta, Provenance, Sensors, TiltSeries};
use tiltnoise_core::limits::{admits_noise_ratio, allowed_noise_ratios};
use tiltnoise_core::model::{Input, Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options;
use tiltnoise_core::repeats::refuse_repeats;
use tiltnoise_core::subtract::{
    subtract, MeasuredRecord, StartTime, Status, SubtractConfig, SubtractResult, WitnessNoise,
    WitnessRecord,
};
use tiltnoise_io::input::{
    parse_start_time, read_measured_input, read_tilt, utc_text, MeasuredInput, TiltInput,
};
use tiltnoise_io::SubtractMeta;
use tiltnoise_plot::View;

mod error;
pub mod figure;
pub mod outputs;
pub mod report;

pub use error::{RunFailure, SubtractFailure};

/// A subtraction to run.
pub struct SubtractRequest<'a> {
    /// The model (its parameters are the nominal values of the fit).
    pub model: &'a Model,
    /// The record of the floor's motion (HDF5, CSV or miniSEED time series).
    pub tilt: PathBuf,
    /// How to read it and every co-located record.
    pub read: ReadRequest,
    /// The measured record of the observables (HDF5 as `simulate` writes it, or CSV).
    pub measured: PathBuf,
    /// The observables to use, each in the measured record (default: all of its channels).
    pub observables: Option<Vec<Observable>>,
    /// Records of one or two instruments beside the witness (a huddle test, a three-cornered
    /// hat).
    pub colocated: Vec<PathBuf>,
    /// Huddle test: the co-located instrument's noise ASD over the witness's, per input.
    pub colocated_ratio: Vec<(Input, f64)>,
    /// The stated own noise of the witness, per input.
    pub witness_noise: Vec<WitnessItem>,
    /// White readout ASD of measured observables (unit/sqrt(Hz)).
    pub readout_asd: Vec<(Observable, f64)>,
    /// Parameter-file keys fitted besides the gains and the delay.
    pub fit: Vec<String>,
    /// Fit band (Hz) (default: chosen from the records).
    pub band_hz: Option<(f64, f64)>,
    /// Band (Hz) of the residual summaries.
    pub report_band_hz: (f64, f64),
    /// Welch segment length (default: chosen from the overlap).
    pub nperseg: Option<usize>,
    /// Fraction of the overlap held out at its end, in (0, 0.5].
    pub holdout: f64,
    /// Largest delay between the records to search (s) (default: 5 % of a segment).
    pub max_delay_s: Option<f64>,
    /// Who asked for the run (the provenance of its files).
    pub invocation: Invocation,
    /// The figure's limits, size and resolution (`.png`/`.svg` outputs).
    pub figure: View,
}

impl SubtractRequest<'_> {
    /// The files the job reads, each with the option (snake case) that names it.
    pub fn input_files(&self) -> Vec<(&'static str, &Path)> {
        let mut files: Vec<(&'static str, &Path)> =
            vec![("tilt", &self.tilt), ("measured", &self.measured)];
        files.extend(self.witness_noise.iter().filter_map(|w| match &w.asd {
            AsdSpec::File(p) => Some(("witness_noise", p.as_path())),
            AsdSpec::White(_) => None,
        }));
        files.extend(self.colocated.iter().map(|p| ("colocated", p.as_path())));
        files
    }
}

/// A subtraction and what its outputs are written with.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct SubtractOutcome {
    /// The fit, the cleaned record and the residual checks.
    pub result: SubtractResult,
    /// The witness noise as stated (the co-located estimates are in the result).
    pub witness_noise: Vec<WitnessNoise>,
    /// The witness record's path, as given.
    pub tilt_path: String,
    /// The notes of reading the witness record.
    pub input_notes: Vec<String>,
    /// The metadata of the cleaned record (its `run` is the provenance).
    pub meta: SubtractMeta,
    /// The figure's limits, size and resolution (not kept in a saved state: the default).
    #[serde(skip)]
    pub figure: View,
}

/// A witness record as the subtraction takes it: one series per input, each the input's
/// displacement (rad, m), with the provenance of the file it came from.
struct Witness {
    inputs: Vec<Input>,
    data: Vec<Vec<f64>>,
    sample_rate_hz: f64,
    provenance: Provenance,
}

impl Witness {
    /// The record's channels as displacements. A record of tilt alone keeps its angles (a rate
    /// integrated as `budget`'s series are); with translation channels, or sensors declared
    /// other than the default, every channel goes through the floor's [`GroundMap`]: velocity
    /// and acceleration integrated to displacement in the frequency domain, an inertial
    /// seismometer's tilt part removed with the record's tilt (`x_t = u - g II(eta_t)`,
    /// `y_t = u + g II(theta_t)`), a pendulum tiltmeter's translation part with the record's
    /// translation.
    fn from_series(series: TiltSeries, g_m_per_s2: f64) -> Result<Witness, String> {
        if series.translations.is_empty() && series.sensors == Sensors::default() {
            let series = series.into_angle();
            return Ok(Witness {
                inputs: series.axes.iter().map(|&a| Input::Tilt(a)).collect(),
                data: series.data,
                sample_rate_hz: series.sample_rate_hz,
                provenance: series.provenance,
            });
        }
        let map = GroundMap::new(&series.channels(), g_m_per_s2)?;
        let channel_data: Vec<Vec<f64>> =
            series.channel_data().iter().map(|c| c.to_vec()).collect();
        let data = map.displacements(&channel_data, series.sample_rate_hz);
        let mut provenance = series.provenance;
        provenance
            .notes
            .retain(|note| !note.starts_with("rate to angle"));
        provenance.notes.extend(map.series_note());
        provenance.notes.extend(map.notes().iter().cloned());
        Ok(Witness {
            inputs: map.inputs(),
            data,
            sample_rate_hz: series.sample_rate_hz,
            provenance,
        })
    }

    /// Reads the record of the floor's motion `path`, named by `option`.
    fn read(
        option: OptionKey,
        path: &Path,
        req: &SubtractRequest<'_>,
    ) -> Result<Witness, JobError> {
        match read_tilt(path, &req.read.options())? {
            TiltInput::Series(s) => {
                Witness::from_series(s, req.model.params().environment.g_m_per_s2).map_err(
                    |problem| {
                        failure(SubtractFailure::Channels {
                            option,
                            path: shown_path(path),
                            problem,
                        })
                    },
                )
            }
            TiltInput::Spectra(_) => Err(failure(SubtractFailure::WitnessSpectra {
                option,
                path: shown_path(path),
            })),
        }
    }
}

fn failure(f: SubtractFailure) -> JobError {
    JobError::Subtract(Box::new(f))
}

/// Refuses a band that is not finite with `0 < FLO < FHI` (Hz).
fn check_band(option: OptionKey, band: (f64, f64)) -> Result<(), JobError> {
    let (lo, hi) = band;
    if lo.is_finite() && hi.is_finite() && 0.0 < lo && lo < hi {
        return Ok(());
    }
    Err(JobError::option_pair(
        option,
        band,
        "must be finite with 0 < FLO < FHI (Hz)",
    ))
}

/// The options the records are not needed for: the bands, the co-located records and their
/// noise ratios (each a floor input once, finite and > 0), the fitted keys (each once), the
/// readout (each observable once).
fn check_options(req: &SubtractRequest<'_>) -> Result<(), JobError> {
    if let Some(band) = req.band_hz {
        check_band(OptionKey::BAND, band)?;
    }
    check_band(OptionKey::REPORT_BAND, req.report_band_hz)?;
    if req.colocated.len() > 2 {
        return Err(failure(SubtractFailure::TooManyColocated(
            req.colocated.len(),
        )));
    }
    for &(input, r) in &req.colocated_ratio {
        let item = format!("{}={}", input.name(), Num(r));
        options::floor_input(OptionKey::COLOCATED_RATIO, &item, input.name())
            .map_err(|e| JobError::Refused(Box::new(e)))?;
        if !admits_noise_ratio(r) {
            return Err(JobError::option(
                OptionKey::COLOCATED_RATIO,
                Some(&item),
                format!(
                    "the ratio of noise ASDs is not allowed: must be {} (above it the \
                     huddle's estimate no longer depends on it; see docs/subtract.md)",
                    allowed_noise_ratios()
                ),
            ));
        }
    }
    let ratio_inputs: Vec<Input> = req.colocated_ratio.iter().map(|x| x.0).collect();
    refuse_repeats(OptionKey::COLOCATED_RATIO, "input", &ratio_inputs, |i| {
        i.name().to_string()
    })
    .map_err(JobError::Repeated)?;
    if !req.colocated_ratio.is_empty() && req.colocated.len() != 1 {
        return Err(failure(SubtractFailure::RatioNeedsOneColocated));
    }
    refuse_repeats(OptionKey::FIT, "parameter key", &req.fit, |k| k.clone())
        .map_err(JobError::Repeated)?;
    let readout: Vec<Observable> = req.readout_asd.iter().map(|x| x.0).collect();
    refuse_repeats(OptionKey::READOUT, "observable", &readout, |o| {
        o.name().to_string()
    })
    .map_err(JobError::Repeated)
}

/// Refuses a noise ratio of an input that the witness or the (one) co-located record does
/// not record: it would estimate nothing.
fn check_ratio_inputs(
    req: &SubtractRequest<'_>,
    witness: &Witness,
    colocated: &[Witness],
) -> Result<(), JobError> {
    let records = std::iter::once((OptionKey::TILT, &req.tilt, witness)).chain(
        colocated
            .iter()
            .zip(&req.colocated)
            .map(|(w, p)| (OptionKey::COLOCATED, p, w)),
    );
    for (option, path, record) in records {
        if let Some(&(input, r)) = req
            .colocated_ratio
            .iter()
            .find(|(i, _)| !record.inputs.contains(i))
        {
            return Err(failure(SubtractFailure::RatioUnrecorded {
                item: format!("{}={}", input.name(), Num(r)),
                input: input.name().to_string(),
                option,
                path: shown_path(path),
                present: record.inputs.iter().map(|i| i.name().to_string()).collect(),
            }));
        }
    }
    Ok(())
}

fn start_of(
    option: OptionKey,
    path: &Path,
    start: &Option<String>,
) -> Result<Option<StartTime>, JobError> {
    start
        .as_deref()
        .map(|s| {
            parse_start_time(s)
                .map(|t| {
                    let ns = t.as_nanosecond();
                    StartTime {
                        unix_s: ns.div_euclid(1_000_000_000) as i64,
                        frac_s: ns.rem_euclid(1_000_000_000) as f64 * 1e-9,
                    }
                })
                .ok_or_else(|| {
                    failure(SubtractFailure::StartTime {
                        option,
                        path: shown_path(path),
                        value: s.to_string(),
                    })
                })
        })
        .transpose()
}

/// The channels of the measured record named by `observables` (all when `None`).
fn select_observables(
    path: &Path,
    observables: Option<&[Observable]>,
    channels: Vec<(Observable, Vec<f64>)>,
) -> Result<Vec<(Observable, Vec<f64>)>, JobError> {
    for (i, (o, _)) in channels.iter().enumerate() {
        if channels[..i].iter().any(|(x, _)| x == o) {
            return Err(failure(SubtractFailure::RepeatedChannel {
                path: shown_path(path),
                observable: *o,
            }));
        }
    }
    let Some(wanted) = observables else {
        return Ok(channels);
    };
    if let Some(&missing) = wanted.iter().find(|o| !channels.iter().any(|c| c.0 == **o)) {
        return Err(failure(SubtractFailure::MissingChannel {
            path: shown_path(path),
            observable: missing,
            present: channels.iter().map(|c| c.0).collect(),
        }));
    }
    Ok(channels
        .into_iter()
        .filter(|c| wanted.contains(&c.0))
        .collect())
}

/// Runs the subtraction: checks the options, reads every record once, fits and removes the
/// tilt part, and checks that every number of the result is finite.
///
/// # Errors
///
/// A [`JobError`] naming the option or file that failed; `Subtract` for records the
/// subtraction refuses and for a result that is not finite; `Cancelled` when `cancel` was
/// set (the subtraction polls it between its stages, in its spectra and across the
/// prediction's bins). The stages are few and long: `progress` is only told that the run is
/// over.
pub fn run(
    req: &SubtractRequest<'_>,
    cancel: &Cancel,
    progress: &dyn Progress,
) -> Result<SubtractOutcome, JobError> {
    let outcome = subtract_records(req, cancel);
    progress.finish();
    outcome
}

fn subtract_records(
    req: &SubtractRequest<'_>,
    cancel: &Cancel,
) -> Result<SubtractOutcome, JobError> {
    let stage = || cancel.check().map_err(|_| JobError::Cancelled);
    check_options(req)?;
    let cfg = SubtractConfig {
        segment_len: req.nperseg,
        holdout_fraction: req.holdout,
        keys: req.fit.clone(),
        fit_band_hz: req.band_hz,
        max_delay_s: req.max_delay_s,
        witness_noise: witness_noise(&req.witness_noise)?,
        colocated_noise_ratio: req.colocated_ratio.clone(),
        readout_asd: req.readout_asd.clone(),
        report_band_hz: req.report_band_hz,
        cancel: cancel.clone(),
    };
    stage()?;
    let series = Witness::read(OptionKey::TILT, &req.tilt, req)?;
    let colocated_series = req
        .colocated
        .iter()
        .map(|p| Witness::read(OptionKey::COLOCATED, p, req))
        .collect::<Result<Vec<_>, _>>()?;
    check_ratio_inputs(req, &series, &colocated_series)?;
    stage()?;
    let measured = match read_measured_input(&req.measured)? {
        MeasuredInput::Series(m) => m,
        MeasuredInput::Spectra(_) => {
            return Err(failure(SubtractFailure::MeasuredSpectra(shown_path(
                &req.measured,
            ))))
        }
    };
    let channels =
        select_observables(&req.measured, req.observables.as_deref(), measured.channels)?;
    let tilt_start = start_of(OptionKey::TILT, &req.tilt, &series.provenance.start_time)?;
    let measured_start = start_of(OptionKey::MEASURED, &req.measured, &measured.start_time)?;
    let colocated = colocated_series
        .iter()
        .zip(&req.colocated)
        .map(|(s, path)| {
            Ok(WitnessRecord {
                fs_hz: s.sample_rate_hz,
                inputs: &s.inputs,
                data: &s.data,
                start: start_of(OptionKey::COLOCATED, path, &s.provenance.start_time)?,
            })
        })
        .collect::<Result<Vec<_>, JobError>>()?;
    stage()?;
    let failed = |reason| {
        failure(SubtractFailure::Run {
            tilt: shown_path(&req.tilt),
            measured: shown_path(&req.measured),
            reason,
        })
    };
    let params = req.model.params();
    let result = subtract(
        params,
        &WitnessRecord {
            fs_hz: series.sample_rate_hz,
            inputs: &series.inputs,
            data: &series.data,
            start: tilt_start,
        },
        &colocated,
        &MeasuredRecord {
            fs_hz: measured.sample_rate_hz,
            channels: &channels,
            start: measured_start,
        },
        &cfg,
    )
    .map_err(|e| match cancel.is_cancelled() {
        true => JobError::Cancelled,
        false => failed(RunFailure::Refused(e)),
    })?;
    check_finite(&result).map_err(failed)?;
    stage()?;
    let skipped =
        Duration::from_secs_f64(result.alignment.measured_first as f64 / result.alignment.fs_hz);
    let overlap_start = measured
        .start_time
        .as_deref()
        .and_then(parse_start_time)
        .and_then(|t| t.checked_add(skipped).ok())
        .map(utc_text);
    let meta = SubtractMeta {
        run: req
            .invocation
            .provenance(params, Some(&NormalModes::new(req.model))),
        tilt: InputMeta::from(&series.provenance),
        measured_path: shown_path(&req.measured),
        start_time: overlap_start,
    };
    Ok(SubtractOutcome {
        result,
        witness_noise: cfg.witness_noise,
        tilt_path: shown_path(&req.tilt),
        input_notes: series.provenance.notes,
        meta,
        figure: req.figure.clone(),
    })
}

/// Every number the run reports or writes must be finite, except the uncertainty of a
/// parameter the data do not constrain at all (reported as not available).
fn check_finite(r: &SubtractResult) -> Result<(), RunFailure> {
    for e in &r.fit.estimates {
        if !e.value.is_finite() || (e.status != Status::NotConstrained && !e.sigma.is_finite()) {
            return Err(RunFailure::Estimate {
                name: e.name.clone(),
                value: e.value,
                sigma: e.sigma,
            });
        }
    }
    if !(r.fit.chi2.is_finite() && r.fit.sigma_factor.is_finite()) {
        return Err(RunFailure::Chi2(r.fit.chi2));
    }
    for res in &r.residuals {
        let b = &res.band;
        let readout = b.cleaned_to_readout.map_or([0.0; 2], |(x, s)| [x, s]);
        let values = [
            ("measured", b.measured_asd),
            ("predicted", b.predicted_asd),
            ("cleaned", b.cleaned_asd),
            ("Wiener residual", b.wiener_asd),
            ("coherence limit", b.expected_asd),
            ("cleaned / coherence limit", b.cleaned_to_expected.0),
            ("its sigma", b.cleaned_to_expected.1),
            ("cleaned / readout", readout[0]),
            ("its sigma", readout[1]),
        ];
        if let Some((what, value)) = values.into_iter().find(|(_, v)| !v.is_finite()) {
            return Err(RunFailure::Band {
                what,
                observable: res.observable,
                value,
            });
        }
    }
    check_derived_finite(r)?;
    for (o, x) in r.cleaned.iter().chain(&r.prediction.series) {
        if let Some((index, &value)) = x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(RunFailure::Sample {
                observable: *o,
                index,
                value,
            });
        }
    }
    Ok(())
}

/// The first value of `values` that is not finite, as a [`RunFailure::Value`] naming `what`
/// and the index (`bin` of a spectrum, `band` of a band check).
fn first_nonfinite(what: impl Fn(usize) -> String, values: &[f64]) -> Result<(), RunFailure> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(k) => Err(RunFailure::Value {
            what: what(k),
            value: values[k],
        }),
        None => Ok(()),
    }
}

/// The numbers of the result besides the fit and the records: the co-located estimates (the
/// relative gains and the stated uncertainty), the witness noise used, the band checks and
/// the held-out spectra.
fn check_derived_finite(r: &SubtractResult) -> Result<(), RunFailure> {
    use tiltnoise_core::subtract::colocated::Method;
    for e in &r.colocated {
        let input = e.noise.input.name();
        let gains = match &e.method {
            Method::Huddle { relative_gain, .. } => vec![*relative_gain],
            Method::ThreeCorneredHat { relative_gains } => relative_gains.to_vec(),
        };
        first_nonfinite(
            |k| format!("relative gain of co-located record {} of {input}", k + 1),
            &gains,
        )?;
        first_nonfinite(
            |_| format!("relative uncertainty of the co-located noise estimate of {input}"),
            &[e.noise.rel],
        )?;
    }
    for (input, psd) in &r.witness_noise_psd {
        first_nonfinite(
            |k| format!("witness noise PSD of {} at bin {k}", input.name()),
            psd,
        )?;
    }
    for (o, check) in &r.bands {
        let o = o.name();
        first_nonfinite(
            |_| format!("cleaned / raw variance of {o}"),
            &[check.variance_ratio],
        )?;
        for (j, b) in check.bands.iter().enumerate() {
            first_nonfinite(
                |_| format!("band check of {o} (band {j} from {} Hz)", Num(b.lo_hz)),
                &[
                    b.raw_psd,
                    b.expected_psd,
                    b.cleaned_psd,
                    b.witness_limited_psd,
                    b.ratio,
                    b.sigma,
                    b.limit,
                ],
            )?;
        }
    }
    for s in &r.residuals {
        let o = s.observable.name();
        let spectra = [
            ("measured", &s.measured_psd),
            ("predicted", &s.predicted_psd),
            ("cleaned", &s.cleaned_psd),
            ("Wiener residual", &s.wiener_psd),
            ("coherence-limit", &s.expected_psd),
            ("witness-limited", &s.witness_limited_psd),
        ];
        for (name, psd) in spectra {
            first_nonfinite(|k| format!("held-out {name} PSD of {o} at bin {k}"), psd)?;
        }
        for (input, psd) in s.witness_limited_by_input.iter().enumerate() {
            first_nonfinite(
                |k| {
                    format!(
                        "witness-limited PSD of {o} by input {} at bin {k}",
                        input + 1
                    )
                },
                psd,
            )?;
        }
        first_nonfinite(
            |_| format!("Wiener training excess of {o}"),
            &[s.wiener_training_excess],
        )?;
    }
    Ok(())
}
