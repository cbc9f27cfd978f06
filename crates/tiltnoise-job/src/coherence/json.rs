//! The JSON of a coherence report (`coherence --format json`), keys in alphabetical order.

use tiltnoise_core::coherence::{AxisEstimate, CoherenceReport, ObservableEstimate};

/// The bins where the multiple coherence of `ob` is above the noise threshold.
pub fn significant_bins(report: &CoherenceReport, ob: &ObservableEstimate) -> Vec<usize> {
    (0..report.freqs_hz.len())
        .filter(|&k| ob.multiple_coherence[k] >= report.multiple_coherence_threshold)
        .collect()
}

/// The bin of the largest finite coherence of `axis`, if any.
pub fn peak_bin(axis: &AxisEstimate) -> Option<usize> {
    (0..axis.coherence.len())
        .filter(|&k| axis.coherence[k].is_finite())
        .max_by(|&i, &j| axis.coherence[i].total_cmp(&axis.coherence[j]))
}

/// The summary as JSON (`--format json`): the numbers the table prints, unrounded; NaN is
/// null.
pub(crate) fn summary_json(report: &CoherenceReport, input_notes: &[String]) -> serde_json::Value {
    use serde_json::json;
    let f = &report.freqs_hz;
    let w = &report.welch;
    let observables: Vec<serde_json::Value> = report
        .observables
        .iter()
        .map(|ob| {
            let significant = significant_bins(report, ob);
            let axes: Vec<serde_json::Value> = ob
                .axes
                .iter()
                .map(|a| {
                    let peak = peak_bin(a);
                    let model_zero = a.model.iter().all(|z| z.norm() == 0.0);
                    let agreement = a.agreement.as_ref().filter(|_| !model_zero).map(|g| {
                        json!({
                            "gain": g.gain(), "gain_sigma": g.sigma,
                            "phase_deg": g.phase_deg(), "phase_sigma_deg": g.phase_sigma_deg(),
                            "n_bins": g.n_bins, "band_hz": [g.band_hz.0, g.band_hz.1],
                            "chi2_per_dof": g.chi2_per_dof,
                        })
                    });
                    json!({
                        "axis": a.axis.name(),
                        "max_coherence": peak.map(|k| a.coherence[k]),
                        "max_coherence_at_hz": peak.map(|k| f[k]),
                        "model_identically_zero": model_zero,
                        "measured_over_model": agreement,
                        "transfer_unit": format!("{}/rad", ob.observable.unit()),
                    })
                })
                .collect();
            json!({
                "observable": ob.observable.name(),
                "unit": ob.observable.unit(),
                "significant_bins": significant.len(),
                "significant_band_hz": significant.first().zip(significant.last())
                    .map(|(&a, &b)| [f[a], f[b]]),
                "expected_from_noise": (1.0 - report.confidence) * f.len() as f64,
                "axes": axes,
            })
        })
        .collect();
    json!({
        "welch": {
            "n_samples": w.n_samples, "sample_rate_hz": w.sample_rate_hz,
            "segment_len": w.segment_len, "overlap": w.overlap,
            "n_segments": w.n_segments, "n_equivalent": w.n_equivalent,
        },
        "bins": f.len(),
        "confidence": report.confidence,
        "coherence_threshold": report.coherence_threshold,
        "multiple_coherence_threshold": report.multiple_coherence_threshold,
        "observables": observables,
        "input_notes": input_notes,
        "notes": report.notes,
    })
}
