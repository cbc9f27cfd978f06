//! Mode visibilities measured from a recorded free motion (or ring-down): the peak of each
//! mode in each channel, as a complex amplitude, and the signed ratio of two channels' peaks
//! with its error. What `tiltnoise visibility` writes for `fit --visibility`.
//!
//! # Method
//!
//! Each channel (mean removed) is multiplied by a Hann window, `X_c(f) = sum_n w_n x_n
//! e^{-2 pi i f n / fs}`. For mode `nu_k`, expected at `f_k` (the model's frequency):
//!
//! * **Where to look.** Between the geometric midpoints to the neighbouring modes' expected
//!   frequencies, and within [`SEARCH_FRACTION`] of `f_k`; the record must resolve that
//!   interval by at least [`MIN_BINS`] bins of `1 / T`, or the mode is skipped as unresolved.
//! * **Noise.** Per channel, the noise power per bin near the mode: the median of `|X_c|^2`
//!   over the bins of the zero-padded FFT within an octave of `f_k` (inside `(0, fs/2)`), away
//!   from every mode's expected frequency (aliased into `0..fs/2` for a mode above it, which is
//!   itself skipped) by [`EXCLUDE_BINS`] bins of `1 / T`, divided by
//!   `ln 2` (the median of an exponential distribution: a complex Gaussian's `|N|^2`).
//! * **Peak.** The frequency maximizing `sum_c |X_c(f)|^2 / noise_c` (every channel weighted
//!   by its own noise): the largest bin of the zero-padded FFT in the interval, refined by a
//!   golden-section search on the direct sum within one padded bin.
//! * **Amplitudes.** Each channel's complex amplitudes of all the peaks at once: the windowed
//!   transforms at the peak frequencies are a linear combination of the sinusoids' amplitudes
//!   through the window's transform, solved exactly (`joint_amplitudes`), so that a mode's
//!   amplitude carries no leakage from a strong neighbour (a Hann side lobe 39 bins out is a
//!   few 1e-6 of it, which is the whole signal of a weakly visible mode).
//! * **Ratios.** For each unit group present (X, Y, Z in m; theta, eta, phi, phi_a in rad) the
//!   reference is the channel with the largest `|X_c|` (as [`crate::modes::Mode::reference_for`]),
//!   if its signal-to-noise ratio `|X_c| / sqrt(noise_c)` is at least [`MIN_SNR`]; the ratio
//!   of every other channel of the group is `rho = Re(X_c conj(X_r)) / |X_r|^2` (the signed
//!   ratio: a real mode shape makes the phases 0 or pi apart, and the real part is the
//!   projection on the reference's phase), and its error, to first order in the noises `N_c`,
//!   `N_r` of the two channels (independent), `sigma^2 = (noise_c + rho^2 noise_r) / (2
//!   |X_r|^2)`. A channel that does not see the mode gives a ratio consistent with 0: a
//!   measurement too (an upper limit on the offsets that would light it).
//!
//! Damping does not change a ratio (both channels ring down together); a ratio of a mode that
//! two modes share within the resolution does. Pure numerics: depends on `model`, `fit`.

use super::measured::SigmaSource;
use super::visibility::{MeasuredVisibility, Visibilities};
use super::FitError;
use crate::cancel::Cancel;
use crate::model::Observable;
use num_complex::Complex64;

/// The smallest signal-to-noise ratio (amplitude) of a reference peak: below it the ratio's
/// first-order error is no longer small (its bias is of order `1 / SNR^2`).
pub const MIN_SNR: f64 = 10.0;

/// The search interval around a mode's expected frequency, as a fraction of it (the offsets
/// move frequencies by parts in 1e4, a parameter's error bar by a few per cent).
pub const SEARCH_FRACTION: f64 = 0.1;

/// The fewest resolution bins (`1 / T`) a mode's search interval must span.
pub const MIN_BINS: f64 = 8.0;

/// Bins of `1 / T` around every mode's expected frequency left out of the noise estimate: the
/// Hann window's main lobe is 2 bins wide each side, its side lobes fall as `1 / f^3`.
pub const EXCLUDE_BINS: f64 = 16.0;

/// The fewest samples of a record.
pub const MIN_SAMPLES: usize = 64;

/// Zero padding of the FFT that locates the peaks (the peak bin is then within a quarter of a
/// resolution bin of the maximum, which the golden-section search refines).
const PADDING: usize = 2;

/// One mode's peak in the record.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ModePeak {
    /// Label of the mode (nu_k).
    pub mode: usize,
    /// The model's frequency it was looked for at (Hz).
    pub expected_hz: f64,
    /// The peak's frequency in the record (Hz).
    pub frequency_hz: f64,
    /// Per channel of the record (its order): amplitude signal-to-noise ratio at the peak.
    pub snr: Vec<f64>,
}

/// The visibilities of a record and the peaks they were read from.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RecordVisibilities {
    /// The ratios (origin: the record's name).
    pub visibilities: Visibilities,
    /// Each mode found, with its peak.
    pub peaks: Vec<ModePeak>,
    /// Each mode skipped, with the reason.
    pub skipped: Vec<(usize, String)>,
}

/// Measures the visibilities of the modes expected at `expected_hz` (Hz, by label: entry `k`
/// is nu_(k+1)) in the record `channels` sampled at `fs_hz` (module docs). `origin` names the
/// record.
///
/// # Errors
///
/// [`FitError::Visibility`] for a record too short ([`MIN_SAMPLES`]), channels of different
/// lengths, a non-finite sample, or no mode found; [`FitError::Cancelled`].
pub fn measure(
    channels: &[(Observable, Vec<f64>)],
    fs_hz: f64,
    expected_hz: &[f64; 8],
    origin: &str,
    cancel: &Cancel,
) -> Result<RecordVisibilities, FitError> {
    let fail = |message: String| FitError::Visibility {
        origin: origin.to_string(),
        message,
    };
    let n = checked_length(channels, fs_hz).map_err(fail)?;
    let record = Record::new(channels, fs_hz, expected_hz, n);
    let mut order: Vec<usize> = (0..8).collect();
    order.sort_by(|&a, &b| expected_hz[a].total_cmp(&expected_hz[b]));
    let mut items = Vec::new();
    let mut peaks = Vec::new();
    let mut skipped = Vec::new();
    let mut candidates: Vec<(usize, f64)> = Vec::new();
    for (rank, &k) in order.iter().enumerate() {
        cancel.check()?;
        match record.locate_peak(expected_hz, &order, rank) {
            Ok(f_peak) => candidates.push((k, f_peak)),
            Err(why) => skipped.push((k + 1, why)),
        }
    }
    // Every channel's complex amplitude of every mode at once, free of the other modes'
    // leakage (module docs).
    let nus: Vec<f64> = candidates.iter().map(|(_, f)| f / fs_hz).collect();
    let solve = joint_amplitudes(&record.windowed, &nus, n);
    // The noise once the peaks are gone: the strong modes' side lobes would otherwise count as
    // noise near them (the torsion modes' in every channel at a few mHz).
    let residual_spectra: Vec<Vec<f64>> = record
        .windowed
        .iter()
        .zip(&solve)
        .map(|(y, a)| padded_power(&without_sinusoids(y, &nus, a)))
        .collect();
    for (j, (k, f_peak)) in candidates.into_iter().enumerate() {
        cancel.check()?;
        let noise: Vec<f64> = residual_spectra
            .iter()
            .map(|p| record.noise_power(p, expected_hz[k]))
            .collect();
        let amplitude: Vec<Complex64> = solve.iter().map(|a| a[j]).collect();
        let snr: Vec<f64> = amplitude
            .iter()
            .zip(&noise)
            .map(|(a, v)| a.norm() / v.sqrt())
            .collect();
        let peak = Peak {
            mode: k + 1,
            amplitude: &amplitude,
            noise: &noise,
            snr: &snr,
        };
        if peak.push_ratios(channels, &mut items) {
            peaks.push(ModePeak {
                mode: k + 1,
                expected_hz: expected_hz[k],
                frequency_hz: f_peak,
                snr,
            });
        } else {
            skipped.push((
                k + 1,
                format!(
                    "no channel group has a peak with signal-to-noise ratio >= {MIN_SNR} (largest \
                     {:.1})",
                    snr.iter().fold(0.0f64, |m, &s| m.max(s))
                ),
            ));
        }
    }
    if items.is_empty() {
        return Err(fail(format!(
            "no mode has a peak with signal-to-noise ratio >= {MIN_SNR} in two channels of one \
             unit; {}",
            skipped
                .iter()
                .map(|(k, why)| format!("nu_{k}: {why}"))
                .collect::<Vec<_>>()
                .join("; ")
        )));
    }
    items.sort_by_key(|v| (v.mode, v.observable.index(), v.reference.index()));
    peaks.sort_by_key(|p| p.mode);
    skipped.sort_by_key(|s| s.0);
    Ok(RecordVisibilities {
        visibilities: Visibilities {
            items,
            origin: origin.to_string(),
        },
        peaks,
        skipped,
    })
}

/// The channels' common length, or what is wrong with the record.
fn checked_length(channels: &[(Observable, Vec<f64>)], fs_hz: f64) -> Result<usize, String> {
    let n = channels.first().map_or(0, |(_, x)| x.len());
    if n < MIN_SAMPLES {
        return Err(format!(
            "{n} samples; a record of at least {MIN_SAMPLES} is needed"
        ));
    }
    if let Some((o, x)) = channels.iter().find(|(_, x)| x.len() != n) {
        return Err(format!(
            "channel {} has {} samples, the first {n}",
            o.name(),
            x.len()
        ));
    }
    if let Some((o, _)) = channels
        .iter()
        .find(|(_, x)| x.iter().any(|v| !v.is_finite()))
    {
        return Err(format!(
            "channel {} has a non-finite sample; fill or cut the gap first",
            o.name()
        ));
    }
    if !(fs_hz.is_finite() && fs_hz > 0.0) {
        return Err(format!("sample rate {fs_hz} Hz; must be finite and > 0"));
    }
    Ok(n)
}

/// The windowed channels of a record and their padded power spectra.
struct Record {
    windowed: Vec<Vec<f64>>,
    spectra: Vec<Vec<f64>>,
    fs_hz: f64,
    padded_df: f64,
    resolution: f64,
    /// Where each mode appears in the sampled record: above fs/2 it aliases (the bounce modes
    /// of a record sampled at a few Hz), and is left out of the noise estimates there too.
    aliased: [f64; 8],
}

impl Record {
    fn new(
        channels: &[(Observable, Vec<f64>)],
        fs_hz: f64,
        expected_hz: &[f64; 8],
        n: usize,
    ) -> Self {
        let windowed: Vec<Vec<f64>> = channels.iter().map(|(_, x)| hann_windowed(x)).collect();
        let spectra: Vec<Vec<f64>> = windowed.iter().map(|y| padded_power(y)).collect();
        let aliased: [f64; 8] = std::array::from_fn(|k| {
            let r = expected_hz[k].rem_euclid(fs_hz);
            r.min(fs_hz - r)
        });
        Self {
            windowed,
            spectra,
            fs_hz,
            padded_df: fs_hz / (PADDING * n) as f64,
            resolution: fs_hz / n as f64,
            aliased,
        }
    }

    /// [`noise_power`] of spectrum `p` near `f_k`.
    fn noise_power(&self, p: &[f64], f_k: f64) -> f64 {
        noise_power(
            p,
            self.padded_df,
            f_k,
            &self.aliased,
            self.resolution,
            self.fs_hz,
        )
    }

    /// The peak frequency (Hz) of mode `order[rank]` (module docs), or why it is skipped.
    fn locate_peak(
        &self,
        expected_hz: &[f64; 8],
        order: &[usize],
        rank: usize,
    ) -> Result<f64, String> {
        let (fs_hz, padded_df, resolution) = (self.fs_hz, self.padded_df, self.resolution);
        let k = order[rank];
        let f_k = expected_hz[k];
        if f_k >= 0.5 * fs_hz {
            return Err(format!(
                "above the Nyquist frequency {:.6e} Hz of the record (aliased to {:.6e} Hz)",
                0.5 * fs_hz,
                self.aliased[k]
            ));
        }
        let below = rank.checked_sub(1).map(|r| expected_hz[order[r]]);
        let above = order.get(rank + 1).map(|&j| expected_hz[j]);
        let lo = below
            .map_or(0.0, |b| (b * f_k).sqrt())
            .max(f_k * (1.0 - SEARCH_FRACTION));
        let hi = above
            .map_or(f64::INFINITY, |a| (a * f_k).sqrt())
            .min(f_k * (1.0 + SEARCH_FRACTION))
            .min(0.5 * fs_hz);
        if (hi - lo) < MIN_BINS * resolution {
            return Err(format!(
                "not resolved: the search interval {lo:.6e}..{hi:.6e} Hz spans {:.1} bins of \
                 1/T = {resolution:.3e} Hz (at least {MIN_BINS} needed: a longer record)",
                (hi - lo) / resolution
            ));
        }
        let noise: Vec<f64> = self
            .spectra
            .iter()
            .map(|p| self.noise_power(p, f_k))
            .collect();
        if noise.iter().any(|&v| v.is_nan() || v <= 0.0) {
            return Err(
                "no noise-only bins within an octave of it to estimate the noise from".into(),
            );
        }
        let score = |f: f64| -> f64 {
            self.windowed
                .iter()
                .zip(&noise)
                .map(|(y, v)| dft(y, f / fs_hz).norm_sqr() / v)
                .sum()
        };
        let (b_lo, b_hi) = (
            (lo / padded_df).ceil() as usize,
            ((hi / padded_df).floor() as usize).min(self.spectra[0].len() - 1),
        );
        let best_bin = (b_lo..=b_hi)
            .max_by(|&a, &b| {
                let s = |i: usize| {
                    self.spectra
                        .iter()
                        .zip(&noise)
                        .map(|(p, v)| p[i] / v)
                        .sum::<f64>()
                };
                s(a).total_cmp(&s(b))
            })
            .expect("a non-empty interval");
        Ok(golden_max(
            score,
            (best_bin as f64 - 1.0) * padded_df,
            (best_bin as f64 + 1.0) * padded_df,
        ))
    }
}

/// One mode's joint amplitudes in every channel, with the channels' noise at it.
struct Peak<'a> {
    mode: usize,
    amplitude: &'a [Complex64],
    noise: &'a [f64],
    snr: &'a [f64],
}

impl Peak<'_> {
    /// Pushes the ratios of every unit group whose reference is seen well enough; whether any
    /// group was.
    fn push_ratios(
        &self,
        channels: &[(Observable, Vec<f64>)],
        items: &mut Vec<MeasuredVisibility>,
    ) -> bool {
        let (amplitude, noise, snr) = (self.amplitude, self.noise, self.snr);
        let mut found = false;
        for group in [
            &[Observable::X, Observable::Y, Observable::Z][..],
            &[
                Observable::Theta,
                Observable::Eta,
                Observable::Phi,
                Observable::PhiA,
            ],
        ] {
            let members: Vec<usize> = (0..channels.len())
                .filter(|&c| group.contains(&channels[c].0))
                .collect();
            let Some(&r) = members
                .iter()
                .max_by(|&&a, &&b| amplitude[a].norm().total_cmp(&amplitude[b].norm()))
            else {
                continue;
            };
            if snr[r] < MIN_SNR {
                continue;
            }
            found = true;
            let a_r = amplitude[r];
            for &c in members.iter().filter(|&&c| c != r) {
                let rho = (amplitude[c] * a_r.conj()).re / a_r.norm_sqr();
                let sigma = ((noise[c] + rho * rho * noise[r]) / (2.0 * a_r.norm_sqr())).sqrt();
                items.push(MeasuredVisibility {
                    mode: self.mode,
                    observable: channels[c].0,
                    reference: channels[r].0,
                    ratio: rho,
                    sigma,
                    sigma_source: SigmaSource::File,
                });
            }
        }
        found
    }
}

/// `(x - mean) w` with the symmetric Hann window `w_n = sin^2(pi n / (N - 1))`.
fn hann_windowed(x: &[f64]) -> Vec<f64> {
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let centred: Vec<f64> = x.iter().map(|v| v - mean).collect();
    hann_windowed_raw(&centred)
}

/// `sum_n w_n e^{-2 pi i mu n}`: the Hann window's transform at normalized frequency `mu`
/// (`n` samples).
fn window_transform(n: usize, mu: f64) -> Complex64 {
    let ones = vec![1.0; n];
    dft(&hann_windowed_raw(&ones), mu)
}

/// The Hann window itself, `w_n x_n` without removing the mean.
fn hann_windowed_raw(x: &[f64]) -> Vec<f64> {
    let d = (x.len() - 1) as f64;
    x.iter()
        .enumerate()
        .map(|(i, &v)| v * (std::f64::consts::PI * i as f64 / d).sin().powi(2))
        .collect()
}

/// The complex amplitude of each sinusoid at `nus` (normalized frequencies) in each windowed
/// channel, as the channel's windowed transform at its own frequency would give it alone
/// (scaled by `W(0)`): the real sinusoids `x_n = sum_k (a_k e^{2 pi i nu_k n} + c.c.)` have
/// `X(nu_j) = sum_k (a_k W(nu_j - nu_k) + conj(a_k) W(nu_j + nu_k))`, a real linear system
/// in `(Re a, Im a)` solved for every channel with one factorization. A lone mode's amplitude
/// is then its transform at the peak; a mode next to a strong one loses that one's leakage
/// (the Hann window's side lobe 39 bins out, a few 1e-6 of the neighbour, is the nu_3/nu_4
/// pair's and the nu_1/nu_2 pair's in a 12 h record).
fn joint_amplitudes(windowed: &[Vec<f64>], nus: &[f64], n: usize) -> Vec<Vec<Complex64>> {
    let k = nus.len();
    if k == 0 {
        return vec![Vec::new(); windowed.len()];
    }
    let w0 = window_transform(n, 0.0);
    let mut m = nalgebra::DMatrix::<f64>::zeros(2 * k, 2 * k);
    for (j, &nu_j) in nus.iter().enumerate() {
        for (l, &nu_l) in nus.iter().enumerate() {
            let (minus, plus) = (
                window_transform(n, nu_j - nu_l) / w0,
                window_transform(n, nu_j + nu_l) / w0,
            );
            let (sum, diff) = (minus + plus, minus - plus);
            m[(j, l)] = sum.re;
            m[(j, k + l)] = -diff.im;
            m[(k + j, l)] = sum.im;
            m[(k + j, k + l)] = diff.re;
        }
    }
    let lu = m.lu();
    windowed
        .iter()
        .map(|y| {
            let x: Vec<Complex64> = nus.iter().map(|&nu| dft(y, nu)).collect();
            let rhs =
                nalgebra::DVector::from_fn(2 * k, |i, _| if i < k { x[i].re } else { x[i - k].im });
            match lu.solve(&rhs) {
                Some(a) => (0..k).map(|i| Complex64::new(a[i], a[k + i])).collect(),
                // Two peaks within a bin of each other: no separation, each its own transform.
                None => x,
            }
        })
        .collect()
}

/// The windowed channel `y` without the sinusoids of amplitudes `a` (as [`joint_amplitudes`]
/// gives them, scaled by `W(0)`) at `nus`.
fn without_sinusoids(y: &[f64], nus: &[f64], a: &[Complex64]) -> Vec<f64> {
    let w0 = window_transform(y.len(), 0.0).re;
    let d = (y.len() - 1) as f64;
    y.iter()
        .enumerate()
        .map(|(i, &v)| {
            let w = (std::f64::consts::PI * i as f64 / d).sin().powi(2);
            let x: f64 = nus
                .iter()
                .zip(a)
                .map(|(&nu, &amp)| {
                    let phase = std::f64::consts::TAU * (nu * i as f64).fract();
                    2.0 * (amp / w0 * Complex64::from_polar(1.0, phase)).re
                })
                .sum();
            v - w * x
        })
        .collect()
}

/// `|FFT|^2` of `y` zero-padded to [`PADDING`] times its length, bins `0 ..= P/2`.
fn padded_power(y: &[f64]) -> Vec<f64> {
    let len = PADDING * y.len();
    let mut input = y.to_vec();
    input.resize(len, 0.0);
    let mut planner = realfft::RealFftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(len);
    let mut out = fft.make_output_vec();
    fft.process(&mut input, &mut out)
        .expect("buffers of the planned length");
    out.iter().map(|z| z.norm_sqr()).collect()
}

/// `sum_n y_n e^{-2 pi i nu n}` at the normalized frequency `nu = f / fs`, by a recurrence on
/// the unit phasor, restarted from its exact value every 1024 steps (the recurrence's rounding
/// drifts by about `eps` per step).
fn dft(y: &[f64], nu: f64) -> Complex64 {
    let step = Complex64::from_polar(1.0, -std::f64::consts::TAU * nu);
    let mut phasor = Complex64::new(1.0, 0.0);
    let mut acc = Complex64::new(0.0, 0.0);
    for (i, &v) in y.iter().enumerate() {
        if i % 1024 == 0 {
            phasor = Complex64::from_polar(1.0, -std::f64::consts::TAU * (nu * i as f64).fract());
        }
        acc += phasor * v;
        phasor *= step;
    }
    acc
}

/// The noise power per bin of channel spectrum `p` near `f_k`, away from every mode's
/// frequency in the record `seen_hz` (module docs).
fn noise_power(
    p: &[f64],
    padded_df: f64,
    f_k: f64,
    seen_hz: &[f64; 8],
    resolution: f64,
    fs_hz: f64,
) -> f64 {
    let (lo, hi) = (f_k / 2.0, (2.0 * f_k).min(0.5 * fs_hz));
    let mut values: Vec<f64> = (0..p.len())
        .filter_map(|i| {
            let f = i as f64 * padded_df;
            let clear = seen_hz
                .iter()
                .all(|&e| (f - e).abs() > EXCLUDE_BINS * resolution);
            (f > 0.0 && f >= lo && f <= hi && clear).then_some(p[i])
        })
        .collect();
    if values.is_empty() {
        return 0.0;
    }
    let mid = values.len() / 2;
    let (_, median, _) = values.select_nth_unstable_by(mid, f64::total_cmp);
    *median / std::f64::consts::LN_2
}

/// The maximum of a unimodal `f` on `[a, b]` by golden-section search, to a millionth of the
/// interval (a peak's frequency to a millionth of a bin: the amplitudes' error from it is of
/// order 1e-12, and common to the channels, so it cancels in a ratio).
fn golden_max(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    let tol = 1e-6 * (b - a);
    while (b - a) > tol {
        if fc > fd {
            b = d;
            (d, fd) = (c, fc);
            c = b - r * (b - a);
            fc = f(c);
        } else {
            a = c;
            (c, fc) = (d, fd);
            d = a + r * (b - a);
            fd = f(d);
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two channels carrying the same two sinusoids in known signed proportions, one of them
    /// noisy: the ratios come back to within a few of their own sigmas, the signs right.
    #[test]
    fn ratios_of_two_tones() {
        let fs = 10.0;
        let n = 1 << 15;
        let (f1, f2) = (0.0731, 0.4113);
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut gauss = || {
            // Box-Muller on a xorshift generator: a deterministic test.
            let mut u = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            let (a, b) = (u().max(1e-300), u());
            (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
        };
        let tone =
            |f: f64, i: usize, ph: f64| (std::f64::consts::TAU * f * i as f64 / fs + ph).cos();
        let x: Vec<f64> = (0..n)
            .map(|i| 1.0 * tone(f1, i, 0.3) + 0.5 * tone(f2, i, 1.1) + 1e-3 * gauss())
            .collect();
        let y: Vec<f64> = (0..n)
            .map(|i| -2e-2 * tone(f1, i, 0.3) + 3.0 * 0.5 * tone(f2, i, 1.1) + 1e-3 * gauss())
            .collect();
        let mut expected = [f1, f2, 1.0, 1.3, 1.6, 2.0, 2.5, 3.0];
        expected[0] *= 1.0005;
        let out = measure(
            &[(Observable::X, x), (Observable::Y, y)],
            fs,
            &expected,
            "tones",
            &Cancel::never(),
        )
        .unwrap();
        let find = |mode: usize| {
            out.visibilities
                .items
                .iter()
                .find(|v| v.mode == mode)
                .unwrap()
                .clone()
        };
        let (v1, v2) = (find(1), find(2));
        // nu_1: Y/X = -0.02; nu_2: X is the weaker, so the reference is Y: X/Y = 1/3.
        assert_eq!(
            (v1.observable, v1.reference),
            (Observable::Y, Observable::X)
        );
        assert_eq!(
            (v2.observable, v2.reference),
            (Observable::X, Observable::Y)
        );
        for (v, want) in [(v1, -2e-2), (v2, 1.0 / 3.0)] {
            assert!(
                (v.ratio - want).abs() <= 5.0 * v.sigma && v.sigma < 1e-3,
                "nu_{}: {} +/- {} vs {want}",
                v.mode,
                v.ratio,
                v.sigma
            );
        }
        assert_eq!(out.skipped.len(), 6, "{:?}", out.skipped);
    }
}
