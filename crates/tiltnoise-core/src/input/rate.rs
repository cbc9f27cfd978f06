//! Tilt rate to tilt angle, in the frequency domain and exactly.
//!
//! With time dependence `exp(+i w t)`, `w = 2 pi f`, a rate `r = dt/dt` has the Fourier
//! amplitude `R(f) = i w T(f)`, so `T = R / (i w)` at every `f > 0`, and the one-sided
//! cross-spectra of the angles are those of the rates divided by `w^2`:
//! `S^T_ij = conj(R_i / (i w)) R_j / (i w) = S^R_ij / w^2` (the phase factors cancel because all
//! channels of an input have the same quantity). This holds bin by bin up to Nyquist, with no
//! integrator in the time domain (the trapezoid rule's response falls as `x cot x`,
//! `x = pi f / f_s`: 59 % low at 0.4 `f_s`).
//!
//! A Welch estimate of the rate, divided by `w^2`, equals the Welch estimate of the angle the
//! rate came from wherever the angle spectrum is flat across the window's main lobe (two bins
//! either side for the Hann window), for example at a spectral line on a bin. Next to a line at
//! `f_l` the window's leakage is in the rate's units, so it arrives divided by `(2 pi f)^2`
//! instead of `(2 pi f_l)^2`: `(f_l / f)^2` times the angle estimate's leakage. The per-segment
//! constant detrend removes the rate's mean, which for the angle is a linear trend, so a
//! drifting angle leaks less into the lowest bins than the angle series itself would.
//!
//! **DC.** At `f = 0` a rate carries no information about the angle (the angle's constant is
//! lost and the rate's mean is the angle's trend), so the DC bin is **excluded** from every
//! angle spectrum derived from a rate; it is never returned as infinite or NaN. The budget drops
//! the DC bin of angles too (its grid is logarithmic).

use super::Quantity;
use crate::spectral::CrossSpectra;
use num_complex::Complex64;

/// The divisor that turns a one-sided PSD or CSD of `quantity` at `f_hz` into that of the
/// angle: 1 for an angle, `(2 pi f)^2` for a rate at `f > 0`. `None` for a rate at `f = 0`,
/// which carries no angle information (see the module docs).
pub fn angle_psd_divisor(quantity: Quantity, f_hz: f64) -> Option<f64> {
    match quantity {
        Quantity::Angle => Some(1.0),
        Quantity::Rate if f_hz > 0.0 => Some(crate::units::angular(f_hz).powi(2)),
        Quantity::Rate => None,
    }
}

/// Turns the Welch cross-spectral matrices of a mixed set of channels, of which those listed in
/// `rate_channels` are tilt rates, into those of the angles, in place, on every bin `f > 0`:
/// with `a_c = 1 / (i w)` for a rate channel and 1 otherwise, `S_ij -> conj(a_i) a_j S_ij`
/// (`S_ij = conj(X_i) X_j`), so a rate-rate entry is divided by `w^2`, a rate-other entry
/// multiplied by `i / w` (rate first) or `-i / w` (rate second). Exact bin by bin, as
/// the budget's [`super::GroundMap`]; ordinary and multiple coherences are unchanged by it, transfer
/// functions become those from the angle. The DC bin is left as it is: it carries no angle
/// information, and callers must drop it.
pub fn rate_channels_to_angle(spectra: &mut CrossSpectra, rate_channels: &[usize]) {
    let n = spectra.n_channels;
    let is_rate: Vec<bool> = (0..n).map(|c| rate_channels.contains(&c)).collect();
    for (k, &f) in spectra.freqs_hz.iter().enumerate() {
        if f <= 0.0 {
            continue;
        }
        let w = crate::units::angular(f);
        let a = |c: usize| match is_rate[c] {
            true => Complex64::new(0.0, -1.0 / w),
            false => Complex64::new(1.0, 0.0),
        };
        for i in 0..n {
            for j in 0..n {
                if is_rate[i] || is_rate[j] {
                    spectra.data[(k * n + i) * n + j] *= a(i).conj() * a(j);
                }
            }
        }
    }
}

/// The angle series (rad) of a rate series (rad/s) sampled at `sample_rate_hz`, for the
/// commands that need angles in the time domain (`subtract`, a driven `simulate`): integrated
/// in the frequency domain, `T_k = R_k / (i w_k)` on every DFT bin `0 < k < n/2`, exact up to
/// Nyquist with no integrator response. The record is taken as periodic after removing its mean
/// (a zero-mean rate integrates to an angle that returns to its start, so the periodic
/// extension has no jump); the angle's constant is unknown and set to zero mean (DC bin 0), and
/// the Nyquist bin of an even length, whose phase a real rate cannot carry, is set to 0.
pub fn integrate_rate_spectrally(rate: &[f64], sample_rate_hz: f64) -> Vec<f64> {
    let n = rate.len();
    if n < 2 {
        return vec![0.0; n];
    }
    let mut planner = realfft::RealFftPlanner::<f64>::new();
    let forward = planner.plan_fft_forward(n);
    let inverse = planner.plan_fft_inverse(n);
    let mut time = rate.to_vec();
    let mut bins = forward.make_output_vec();
    forward
        .process(&mut time, &mut bins)
        .expect("buffers made by the plan");
    for (k, b) in bins.iter_mut().enumerate() {
        let nyquist = n % 2 == 0 && k == n / 2;
        if k == 0 || nyquist {
            *b = Complex64::new(0.0, 0.0);
        } else {
            let w = crate::units::angular(k as f64 * sample_rate_hz / n as f64);
            // 1 / (i w) = -i / w; the inverse transform is unnormalised.
            *b *= Complex64::new(0.0, -1.0 / (w * n as f64));
        }
    }
    inverse
        .process(&mut bins, &mut time)
        .expect("buffers made by the plan");
    time
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spectral_integration_is_exact_for_bin_sinusoids() {
        // Angle: a sum of sinusoids on DFT bins (periodic in the record, zero mean); rate: its
        // exact derivative. The integral matches to FFT rounding: log2(n) stages of a few eps
        // each (64 eps log2 n, generously), relative to the rate's amplitude sum(a w), which the
        // division by w amplifies by at most 1 / w_min in the angle.
        let (n, fs) = (4096usize, 10.0);
        let lines = [(3usize, 1.0, 0.2), (200, 0.3, 1.1), (2047, 0.05, -0.7)];
        let t = |j: usize| j as f64 / fs;
        let angle: Vec<f64> = (0..n)
            .map(|j| {
                lines
                    .iter()
                    .map(|&(k, a, p)| {
                        a * (std::f64::consts::TAU * k as f64 * t(j) * fs / n as f64 + p).sin()
                    })
                    .sum()
            })
            .collect();
        let rate: Vec<f64> = (0..n)
            .map(|j| {
                lines
                    .iter()
                    .map(|&(k, a, p)| {
                        let w = std::f64::consts::TAU * k as f64 * fs / n as f64;
                        a * w * (w * t(j) + p).cos()
                    })
                    .sum()
            })
            .collect();
        let got = integrate_rate_spectrally(&rate, fs);
        let w = |k: usize| std::f64::consts::TAU * k as f64 * fs / n as f64;
        let rate_amplitude: f64 = lines.iter().map(|&(k, a, _)| a * w(k)).sum();
        let tol = 64.0 * f64::EPSILON * (n as f64).log2() * rate_amplitude / w(lines[0].0);
        let worst = got
            .iter()
            .zip(&angle)
            .map(|(g, a)| (g - a).abs())
            .fold(0.0, f64::max);
        assert!(worst <= tol, "worst {worst:e} > {tol:e}");
    }

    #[test]
    fn mixed_channels_become_angles_with_the_right_phase() {
        // Channel 0: the rate of an angle t = exp(i w t0) -> R = i w T; channel 1: y = 2 T.
        let f = 0.25;
        let w = crate::units::angular(f);
        let t = Complex64::from_polar(1.0, 0.3);
        let x = [Complex64::new(0.0, w) * t, 2.0 * t];
        let mut spectra = CrossSpectra {
            freqs_hz: vec![f],
            n_channels: 2,
            data: (0..4).map(|e| x[e / 2].conj() * x[e % 2]).collect(),
            n_segments: 1,
        };
        rate_channels_to_angle(&mut spectra, &[0]);
        let angle = [t, 2.0 * t];
        for e in 0..4 {
            let want = angle[e / 2].conj() * angle[e % 2];
            let got = spectra.data[e];
            assert!(
                (got - want).norm() <= 4.0 * f64::EPSILON * want.norm(),
                "{e}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn dc_of_a_rate_is_excluded_not_infinite() {
        assert_eq!(angle_psd_divisor(Quantity::Rate, 0.0), None);
        assert_eq!(angle_psd_divisor(Quantity::Angle, 0.0), Some(1.0));
        let one = Complex64::new(1.0, 0.0);
        let spectra = CrossSpectra {
            freqs_hz: vec![0.0, 0.5, 1.0],
            n_channels: 1,
            data: vec![one; 3],
            n_segments: 1,
        };
        let map = |q| {
            crate::input::GroundMap::new(
                &[crate::input::GroundChannel::tilt(
                    crate::model::TiltAxis::ThetaT,
                    q,
                )],
                9.81,
            )
            .unwrap()
        };
        let (f, csd) = map(Quantity::Rate).apply(&spectra);
        assert_eq!(f, vec![0.5, 1.0]);
        let w2 = |f: f64| (std::f64::consts::TAU * f).powi(2);
        assert_eq!(csd, vec![one / w2(0.5), one / w2(1.0)]);
        let (_, csd) = map(Quantity::Angle).apply(&spectra);
        assert_eq!(csd, vec![one, one]);
    }
}
