//! The report of a subtraction as `subtract --format json` prints it and a `.json` output
//! holds it (`docs/subtract.md`): the alignment, the fit, the held-out residuals, the checks
//! of the cleaned record against the raw one and the witness noise, for both front ends.

use crate::subtract::SubtractOutcome;
use serde::Serialize;
use std::path::Path;
use tiltnoise_core::subtract::{Method, NoiseLevel};
use tiltnoise_io::{OutputError, Staging};

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

// Keys in alphabetical order (fields declared in that order), as every JSON report of the tool.

/// The report of a subtraction: every number of the table, for programs.
#[derive(Debug, Clone, Serialize)]
pub struct SubtractReport {
    alignment: AlignmentJson,
    bands: Vec<BandCheckJson>,
    estimates: Vec<EstimateJson>,
    fit: FitJson,
    measured: String,
    notes: Vec<String>,
    residuals: Vec<ResidualJson>,
    tilt: String,
    witness_noise: Vec<NoiseJson>,
}

#[derive(Debug, Clone, Serialize)]
struct BandCheckJson {
    bands: Vec<BandJson>,
    left_raw: bool,
    observable: &'static str,
    unit: String,
    variance_ratio: f64,
}

#[derive(Debug, Clone, Serialize)]
struct BandJson {
    band_hz: [f64; 2],
    bins: usize,
    cleaned_asd: f64,
    expected_asd: f64,
    left_raw: bool,
    limit: f64,
    ratio: f64,
    raw_asd: f64,
    sigma: f64,
    witness_limited_asd: f64,
}

#[derive(Debug, Clone, Serialize)]
struct NoiseJson {
    asd: Option<f64>,
    file: Option<String>,
    fitted_scale: f64,
    input: &'static str,
    method: &'static str,
    rel: f64,
    relative_gains: Vec<f64>,
    unit: String,
}

#[derive(Debug, Clone, Serialize)]
struct AlignmentJson {
    fraction_s: f64,
    holdout_samples: usize,
    measured_first_sample: usize,
    note: String,
    overlap_start_time: Option<String>,
    sample_rate_hz: f64,
    samples: usize,
    segment_len: usize,
    start_offset_s: Option<f64>,
    tilt_first_sample: usize,
    training_samples: usize,
}

#[derive(Debug, Clone, Serialize)]
struct EstimateJson {
    lower: f64,
    name: String,
    nominal: f64,
    prior_sigma: Option<f64>,
    scale: f64,
    sigma: Option<f64>,
    status: &'static str,
    unit: String,
    upper: f64,
    value: f64,
}

#[derive(Debug, Clone, Serialize)]
struct FitJson {
    band_hz: [f64; 2],
    bins: std::collections::BTreeMap<&'static str, usize>,
    chi2: f64,
    coherent_top_hz: Option<f64>,
    dof: usize,
    fitted: Vec<String>,
    iterations: usize,
    max_delay_s: f64,
    sigma_factor: f64,
    stop: &'static str,
    witness_bias: std::collections::BTreeMap<&'static str, f64>,
}

#[derive(Debug, Clone, Serialize)]
struct ResidualJson {
    band_hz: [f64; 2],
    bins: usize,
    below_coherence_bound: bool,
    cleaned_asd: f64,
    cleaned_to_expected: [f64; 2],
    cleaned_to_readout: Option<[f64; 2]>,
    expected_asd: f64,
    measured_asd: f64,
    observable: &'static str,
    predicted_asd: f64,
    psd_rel_sigma: f64,
    readout_asd: Option<f64>,
    unit: String,
    wiener_asd: f64,
    wiener_corrected_asd: f64,
    wiener_training_excess: f64,
    witness_limited_asd: f64,
}

/// The upper edge of a band as reported: the last band reaches the Nyquist frequency.
pub fn band_top(hi: f64, fs_hz: f64) -> f64 {
    hi.min(fs_hz / 2.0)
}

impl SubtractOutcome {
    /// The report, as `subtract --format json` prints it and `--save report.json` writes it
    /// (the schema in `docs/subtract.md`).
    pub fn report(&self) -> SubtractReport {
        report(self)
    }
}

impl SubtractReport {
    /// The report as pretty-printed JSON, one line per key, without a final newline.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a report of numbers and strings serializes")
    }

    /// Writes the report (`.json`, with a final newline) as one of the outputs of `stage`.
    ///
    /// # Errors
    ///
    /// An [`OutputError`] naming `path` when it cannot be written.
    pub fn write(&self, stage: &Staging, path: &Path) -> Result<(), OutputError> {
        let text = self.to_json() + "\n";
        stage.write(path, |tmp| {
            std::fs::write(tmp, text.as_bytes()).map_err(|e| e.to_string())
        })
    }
}

fn report(o: &SubtractOutcome) -> SubtractReport {
    let r = &o.result;
    let noise = &o.witness_noise;
    let start = &o.meta.start_time;
    let a = &r.alignment;
    let fs = a.fs_hz;
    SubtractReport {
        bands: r
            .bands
            .iter()
            .map(|(o, c)| BandCheckJson {
                bands: c
                    .bands
                    .iter()
                    .map(|b| BandJson {
                        band_hz: [b.lo_hz, band_top(b.hi_hz, fs)],
                        bins: b.bins,
                        cleaned_asd: b.cleaned_psd.sqrt(),
                        expected_asd: b.expected_psd.sqrt(),
                        left_raw: b.left_raw,
                        limit: b.limit,
                        ratio: b.ratio,
                        raw_asd: b.raw_psd.sqrt(),
                        sigma: b.sigma,
                        witness_limited_asd: b.witness_limited_psd.sqrt(),
                    })
                    .collect(),
                left_raw: c.left_raw,
                observable: o.name(),
                unit: format!("{}/sqrt(Hz)", o.unit()),
                variance_ratio: c.variance_ratio,
            })
            .collect(),
        witness_noise: noise
            .iter()
            .map(|x| (x, None))
            .chain(r.colocated.iter().map(|e| (&e.noise, Some(&e.method))))
            .map(|(x, method)| {
                let a = r
                    .witness_noise_psd
                    .iter()
                    .position(|(i, _)| *i == x.input)
                    .expect("every stated noise belongs to a witness input");
                let (asd, file) = match &x.level {
                    NoiseLevel::White(v) => (Some(*v), None),
                    NoiseLevel::Curve(c) => (None, Some(c.origin().to_string())),
                };
                let (method, relative_gains) = match method {
                    None => ("given", Vec::new()),
                    Some(Method::Huddle { relative_gain, .. }) => ("huddle", vec![*relative_gain]),
                    Some(Method::ThreeCorneredHat { relative_gains }) => {
                        ("three-cornered hat", relative_gains.to_vec())
                    }
                };
                NoiseJson {
                    asd,
                    file,
                    fitted_scale: r.fit.noise_factors[a].sqrt(),
                    input: x.input.name(),
                    method,
                    rel: x.rel,
                    relative_gains,
                    unit: format!("{}/sqrt(Hz)", x.input.unit()),
                }
            })
            .collect(),
        alignment: AlignmentJson {
            fraction_s: a.fraction_s,
            holdout_samples: r.n_holdout,
            measured_first_sample: a.measured_first,
            note: a.note.clone(),
            overlap_start_time: start.clone(),
            sample_rate_hz: a.fs_hz,
            samples: a.len,
            segment_len: r.segment_len,
            start_offset_s: a.start_offset_s,
            tilt_first_sample: a.witness_first,
            training_samples: r.n_train,
        },
        estimates: r
            .fit
            .estimates
            .iter()
            .map(|e| EstimateJson {
                lower: e.bounds.0,
                name: e.name.clone(),
                nominal: e.nominal,
                prior_sigma: e.prior_sigma,
                scale: e.scale,
                sigma: finite(e.sigma),
                status: e.status.name(),
                unit: e.unit.clone(),
                upper: e.bounds.1,
                value: e.value,
            })
            .collect(),
        fit: FitJson {
            band_hz: [r.fit.band_hz.0, r.fit.band_hz.1],
            bins: r.fit.bins.iter().map(|(o, n)| (o.name(), *n)).collect(),
            chi2: r.fit.chi2,
            coherent_top_hz: r.fit.coherent_top_hz,
            dof: r.fit.dof,
            fitted: r.fit.fitted.clone(),
            iterations: r.fit.iterations,
            max_delay_s: r.max_delay_s,
            sigma_factor: r.fit.sigma_factor,
            stop: r.fit.stop.describe(),
            witness_bias: r
                .witness_noise_psd
                .iter()
                .map(|(i, _)| i.name())
                .zip(r.fit.witness_bias.iter().copied())
                .collect(),
        },
        measured: o.meta.measured_path.clone(),
        notes: r.notes.clone(),
        residuals: r
            .residuals
            .iter()
            .map(|s| {
                let b = &s.band;
                ResidualJson {
                    band_hz: [b.band_hz.0, b.band_hz.1],
                    bins: b.bins,
                    below_coherence_bound: b.below_coherence_bound,
                    cleaned_asd: b.cleaned_asd,
                    cleaned_to_expected: [b.cleaned_to_expected.0, b.cleaned_to_expected.1],
                    cleaned_to_readout: b.cleaned_to_readout.map(|(x, s)| [x, s]),
                    expected_asd: b.expected_asd,
                    measured_asd: b.measured_asd,
                    observable: s.observable.name(),
                    predicted_asd: b.predicted_asd,
                    psd_rel_sigma: b.psd_rel_sigma,
                    readout_asd: s.readout_asd,
                    unit: format!("{}/sqrt(Hz)", s.observable.unit()),
                    wiener_asd: b.wiener_asd,
                    wiener_corrected_asd: b.wiener_corrected_asd,
                    wiener_training_excess: s.wiener_training_excess,
                    witness_limited_asd: b.witness_limited_asd,
                }
            })
            .collect(),
        tilt: o.tilt_path.clone(),
    }
}
