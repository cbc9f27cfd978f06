//! The witness's own noise estimated from co-located instruments recording the same inputs:
//! two (a huddle test) or three (a three-cornered hat).
//!
//! Instrument `i` records `x_i = g_i t + m_i`: the same floor motion `t` through its own gain
//! `g_i` (the witness's `g_1 = 1`), plus its own noise `m_i`, independent of `t` and of the
//! others' noise; the instruments are assumed to share their response otherwise (no relative
//! delay or filter). With `S_ij = <conj(x_i) x_j> = conj(g_i) g_j S_tt` for `i != j`:
//!
//! * **Huddle** (two instruments): the relative gain `g = g_2` is not separable from `S_tt`
//!   without an assumption on the noises; with `N_2 = r^2 N_1` (`r` stated, 1 by default: equal
//!   noise) each bin gives `|g|` as the positive root of
//!   `|S_12| g^2 + (r^2 S_11 - S_22) g - r^2 |S_12| = 0`, its sign that of `Re S_12`; the gain
//!   is the median over the bins where the two are coherent (`|S_12|^2 / (S_11 S_22) >= 0.9`).
//!   Then `N_1 = PSD(x_1 - x_2 / g) / (1 + r^2 / g^2)`: the difference removes the floor motion
//!   whatever its spectrum (R. Sleeman, A. van Wettum and J. Trampert, Bull. Seismol. Soc. Am.
//!   96, 258 (2006), for the two- and three-instrument methods; J. R. Evans et al., the
//!   "huddle test").
//! * **Three-cornered hat** (three instruments): the gains follow without assumption,
//!   `g_2 = Re(S_23 / S_13)`, `g_3 = Re(S_32 / S_12)` (medians over the coherent bins), and with
//!   the differences `P_ij = PSD(x_i / g_i - x_j / g_j)`, `N_1 = (P_12 + P_13 - P_23) / 2`.
//!
//! The noise PSD is estimated on the Welch grid, smoothed over neighbouring bins
//! ([`super::weighting::smooth`]) and floored at a small fraction of the witness PSD; its
//! relative uncertainty (1 sigma of the ASD) is half the relative standard error of the
//! smoothed PSD, the median over the bins where the noise is at least a tenth of the
//! witness's PSD (where it matters). A residual gain error `e` leaks `e^2 S_tt` into the
//! difference: negligible where the gain is known to 1e-2 and `S_tt / N < 1e2`.

use super::weighting::smooth;
use super::SubtractError;
use crate::model::Input;
use crate::noise::GivenAsd;
use crate::noise::{NoiseLevel, WitnessNoise};
use crate::spectral::{csd_matrix, welch, WelchConfig};

/// Coherence above which two instruments count as recording the same floor motion, for their
/// relative gains.
pub const GAIN_COHERENCE: f64 = 0.9;
/// Floor of the estimated noise PSD, relative to the witness's PSD.
pub const NOISE_FLOOR_REL: f64 = 1e-6;

// The largest noise ratio is derived from the floor (limits::MAX_NOISE_RATIO): its square is
// the reciprocal of the floor.
const _: () = {
    let hi = crate::limits::MAX_NOISE_RATIO;
    let floor = hi * hi * NOISE_FLOOR_REL;
    assert!(floor > 1.0 - 1e-12 && floor < 1.0 + 1e-12);
};

/// The magnitude of the relative gain `g` of a huddle in one bin: the positive root of
/// `a g^2 + (r^2 s11 - s22) g - r^2 a = 0` (module docs; `a = |S_12| > 0`, `s11`, `s22` the
/// two PSDs, `r` the noise ratio), computed without cancellation or overflow: for `r <= 1`
/// the root of the larger magnitude is formed without a difference of nearly equal terms
/// (`2 r^2 a / (b + hypot(b, 2 r a))` when `b >= 0`, `(hypot(b, 2 r a) - b) / (2 a)` when
/// not), and for `r > 1` the equation is that of `1 / g` with `s11` and `s22` swapped and
/// `1 / r` (substitute `g = 1 / h` and divide by `r^2`), so `r^2` never exceeds 1.
pub fn huddle_gain(s11: f64, s22: f64, a: f64, r: f64) -> f64 {
    if r > 1.0 {
        return 1.0 / huddle_gain(s22, s11, a, 1.0 / r);
    }
    let b = r * r * s11 - s22;
    let h = b.hypot(2.0 * r * a);
    if b >= 0.0 {
        2.0 * r * r * a / (b + h)
    } else {
        (h - b) / (2.0 * a)
    }
}

/// How a noise level was estimated.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Method {
    /// Two instruments; the other's gain relative to the witness and its stated noise ratio.
    Huddle {
        /// `g_2`.
        relative_gain: f64,
        /// `r = sqrt(N_2 / N_1)`, as stated (1: equal noise assumed).
        noise_ratio: f64,
    },
    /// Three instruments; the others' gains relative to the witness.
    ThreeCorneredHat {
        /// `g_2`, `g_3`.
        relative_gains: [f64; 2],
    },
}

/// The estimated noise of one witness input.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ColocatedEstimate {
    /// The noise, as the fit and the weighting use it.
    pub noise: WitnessNoise,
    /// How it was estimated.
    pub method: Method,
    /// Welch bins where the instruments were coherent enough for their gains.
    pub gain_bins: usize,
}

/// Estimates the noise of `input`'s witness series `x1` from the co-located series `others`
/// (one or two; same rate `fs_hz`, same length, aligned), with the stated noise ratio
/// `noise_ratio` of a huddle, on Welch segments of `segment_len`.
///
/// # Errors
///
/// No bin where the instruments are coherent (they do not record the same motion, or not at
/// this gain), or a Welch estimate that fails.
pub fn estimate(
    input: Input,
    x1: &[f64],
    others: &[&[f64]],
    fs_hz: f64,
    segment_len: usize,
    noise_ratio: f64,
) -> Result<ColocatedEstimate, SubtractError> {
    let cfg = WelchConfig::new(segment_len);
    let mut chans: Vec<&[f64]> = vec![x1];
    chans.extend(others);
    let m = csd_matrix(&chans, fs_hz, &cfg)?;
    let n = m.n_channels;
    let n_eff = crate::spectral::confidence::equivalent_averages(&cfg, m.n_segments);
    let coherent = |i: usize, j: usize, k: usize| {
        let s = m.get(k, i, j);
        let (a, b) = (m.get(k, i, i).re, m.get(k, j, j).re);
        a > 0.0 && b > 0.0 && s.norm_sqr() / (a * b) >= GAIN_COHERENCE
    };
    let bins: Vec<usize> = (1..m.n_freqs())
        .filter(|&k| (0..n).all(|i| (i + 1..n).all(|j| coherent(i, j, k))))
        .collect();
    if bins.is_empty() {
        return Err(SubtractError::Config(
            format!(
                "the co-located records of {} are nowhere coherent with the witness (coherence \
             below {GAIN_COHERENCE} at every frequency): they do not record the same motion; \
             check their axis maps and start times",
                input.name()
            )
            .into(),
        ));
    }
    let (gains, method) = match others.len() {
        1 => {
            let mut g: Vec<f64> = bins
                .iter()
                .map(|&k| {
                    let (s11, s22, s12) = (m.get(k, 0, 0).re, m.get(k, 1, 1).re, m.get(k, 0, 1));
                    huddle_gain(s11, s22, s12.norm(), noise_ratio) * s12.re.signum()
                })
                .collect();
            let g = median(&mut g);
            (
                vec![g],
                Method::Huddle {
                    relative_gain: g,
                    noise_ratio,
                },
            )
        }
        _ => {
            let ratio = |num: (usize, usize), den: (usize, usize)| {
                let mut v: Vec<f64> = bins
                    .iter()
                    .map(|&k| (m.get(k, num.0, num.1) / m.get(k, den.0, den.1)).re)
                    .collect();
                median(&mut v)
            };
            let (g2, g3) = (ratio((1, 2), (0, 2)), ratio((2, 1), (0, 1)));
            (
                vec![g2, g3],
                Method::ThreeCorneredHat {
                    relative_gains: [g2, g3],
                },
            )
        }
    };
    // PSDs of the gain-corrected differences.
    let scaled: Vec<Vec<f64>> = others
        .iter()
        .zip(&gains)
        .map(|(x, g)| x.iter().map(|v| v / g).collect())
        .collect();
    let diff_psd = |a: &[f64], b: &[f64]| -> Result<Vec<f64>, SubtractError> {
        let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
        Ok(welch(&d, fs_hz, &cfg)?.psd)
    };
    // The raw noise estimate per bin and the variance of one bin's estimate relative to its
    // square over that of a single PSD (Isserlis: the differences share the noises).
    let (raw, variance_factor): (Vec<f64>, Vec<f64>) = match &method {
        Method::Huddle { noise_ratio, .. } => {
            let g = gains[0];
            let share = 1.0 + noise_ratio * noise_ratio / (g * g);
            let d = diff_psd(x1, &scaled[0])?;
            (d.iter().map(|p| p / share).collect(), vec![1.0; d.len()])
        }
        Method::ThreeCorneredHat { .. } => {
            let (p12, p13, p23) = (
                diff_psd(x1, &scaled[0])?,
                diff_psd(x1, &scaled[1])?,
                diff_psd(&scaled[0], &scaled[1])?,
            );
            (0..p12.len())
                .map(|k| {
                    let n1 = 0.5 * (p12[k] + p13[k] - p23[k]);
                    let (n2, n3) = (p12[k] - n1, p13[k] - n1);
                    // Var(N1) = N1^2 [1 + (N1 N2 + N1 N3 + N2 N3) / (2 N1^2)] / n.
                    let factor = if n1 > 0.0 {
                        1.0 + (n1 * n2 + n1 * n3 + n2 * n3).max(0.0) / (2.0 * n1 * n1)
                    } else {
                        f64::INFINITY
                    };
                    (n1, factor)
                })
                .unzip()
        }
    };
    let freqs = &m.freqs_hz[1..];
    let smoothed = smooth(freqs, &raw[1..], 0);
    let factor = smooth(freqs, &variance_factor[1..], 0);
    let witness_psd = m.psd(0);
    let psd: Vec<f64> = smoothed
        .iter()
        .zip(&witness_psd[1..])
        .map(|(p, w)| p.max(NOISE_FLOOR_REL * w))
        .collect();
    let adjacent = super::stats::bin_variance_factor(segment_len, 1);
    let mut rel: Vec<f64> = (0..freqs.len())
        .filter(|&i| psd[i] >= 0.1 * witness_psd[i + 1] && factor[i].is_finite())
        .map(|i| {
            let window = super::weighting::smoothing_window(freqs, i, 0).len().max(1) as f64;
            0.5 * (factor[i] * adjacent / (n_eff * window)).sqrt()
        })
        .collect();
    let rel = if rel.is_empty() {
        0.0
    } else {
        median(&mut rel)
    };
    let asd: Vec<f64> = psd.iter().map(|p| p.sqrt()).collect();
    let curve = GivenAsd::new(
        freqs.to_vec(),
        asd,
        &format!("co-located records of {}", input.name()),
    )
    .map_err(|e| SubtractError::Config(e.0))?;
    Ok(ColocatedEstimate {
        noise: WitnessNoise {
            input,
            level: NoiseLevel::Curve(curve),
            rel,
        },
        method,
        gain_bins: bins.len(),
    })
}

/// Estimates the noise of every input of `witness` that the co-located records `colocated`
/// (one or two) also record, on their common stretch with the witness (aligned by start
/// times), with the stated huddle noise ratios `ratios` (input, `r`; 1 when not stated).
///
/// # Errors
///
/// A co-located record that does not share the witness's rate or overlap it, an input
/// recorded by more than two co-located records, a common stretch shorter than four Welch
/// segments, and the errors of [`estimate`]; each message names the co-located record.
pub fn estimate_all(
    witness: &super::WitnessRecord,
    colocated: &[super::WitnessRecord],
    ratios: &[(Input, f64)],
    segment_len: usize,
) -> Result<Vec<ColocatedEstimate>, SubtractError> {
    let n_w = witness.data.first().map_or(0, Vec::len);
    // The witness's samples that every co-located record covers.
    let mut first = 0;
    let mut end = n_w;
    let mut starts = Vec::with_capacity(colocated.len());
    for (c, rec) in colocated.iter().enumerate() {
        let n_c = rec.data.first().map_or(0, Vec::len);
        let a = super::align(
            (witness.fs_hz, n_w, witness.start),
            (rec.fs_hz, n_c, rec.start),
        )
        .map_err(|e| {
            SubtractError::Config(
                format!(
                    "co-located record {}: {}",
                    c + 1,
                    e.to_string()
                        .replace("measured record", "co-located record")
                )
                .into(),
            )
        })?;
        first = first.max(a.witness_first);
        end = end.min(a.witness_first + a.len);
        starts.push(a.measured_first as i64 - a.witness_first as i64);
    }
    if end < first + 4 * segment_len {
        return Err(SubtractError::Config(
            format!(
                "the co-located records and the witness share {} samples: at least 4 Welch \
             segments of {segment_len} are needed to estimate the witness noise",
                end.saturating_sub(first)
            )
            .into(),
        ));
    }
    let mut out = Vec::new();
    for (a, &input) in witness.inputs.iter().enumerate() {
        let others: Vec<&[f64]> = colocated
            .iter()
            .zip(&starts)
            .filter_map(|(rec, &shift)| {
                let i = rec.inputs.iter().position(|&x| x == input)?;
                let from = (first as i64 + shift) as usize;
                Some(&rec.data[i][from..from + (end - first)])
            })
            .collect();
        if others.is_empty() {
            continue;
        }
        if others.len() > 2 {
            return Err(SubtractError::Config(
                format!(
                    "{} is recorded by {} co-located records: give one (a huddle) or two (a \
                 three-cornered hat)",
                    input.name(),
                    others.len()
                )
                .into(),
            ));
        }
        let ratio = ratios
            .iter()
            .find(|(i, _)| *i == input)
            .map_or(1.0, |r| r.1);
        out.push(estimate(
            input,
            &witness.data[a][first..end],
            &others,
            witness.fs_hz,
            segment_len,
            ratio,
        )?);
    }
    Ok(out)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::TiltAxis;
    use crate::rng::Rng;

    /// A floor motion of red spectrum seen by instruments with gains and white noises; the
    /// estimated noise of the first, averaged over 0.1-0.45 Hz (where it is at least a tenth of
    /// the record), within 3 of its stated uncertainties of the truth, and the gains to 1e-2.
    fn instruments(gains: &[f64], noises: &[f64], n: usize) -> Vec<Vec<f64>> {
        let mut rng = Rng::stream(3, 1);
        // A random walk, high-passed by a leaky integrator: PSD ~ 1/f^2 above 1e-3 Hz.
        let mut t = vec![0.0; n];
        for i in 1..n {
            t[i] = 0.994 * t[i - 1] + rng.gaussian();
        }
        gains
            .iter()
            .zip(noises)
            .enumerate()
            .map(|(i, (&g, &s))| {
                let mut r = Rng::stream(4, i as u64);
                t.iter().map(|v| g * v + s * r.gaussian()).collect()
            })
            .collect()
    }

    /// The huddle's gain against the quadratic's root in double-double arithmetic (the
    /// textbook formula, whose cancellation costs about 1e-12 relative at the ends of the
    /// ratio's range: far below double-double's 1e-32), over the whole range of ratios and
    /// of PSDs: finite, positive, within a few eps of the reference, and between the two
    /// regression gains `a / s11` and `s22 / a`.
    #[test]
    fn huddle_gain_is_the_root_without_cancellation_over_the_whole_range() {
        use crate::dd::Dd;
        let hi = crate::limits::MAX_NOISE_RATIO;
        let ratios = [
            0.0, 5e-324, 1e-300, 1e-3, 3e-3, 0.1, 0.9, 1.0, 1.1, 10.0, 333.0, hi,
        ];
        let psds = crate::limits::PSDS;
        for scale in [psds.smallest, 1e-20, 1.0, 1e30, psds.largest] {
            // Coherence 0.95 and 0.9 between records of gains 1 and 1.3 and 0.7.
            for (s11, s22, coherence) in [(1.0, 1.69, 0.95), (1.0, 0.49, 0.9), (2.0, 2.0, 1.0)] {
                let (s11, s22) = (s11 * scale, s22 * scale);
                let a = (coherence * s11 * s22).sqrt();
                for r in ratios {
                    let g = huddle_gain(s11, s22, a, r);
                    let (ad, rd) = (Dd::from(a), Dd::from(r));
                    let r2 = rd * rd;
                    let b = r2 * s11 - Dd::from(s22);
                    let disc = b * b + r2 * ad * ad * 4.0;
                    let want = ((disc.sqrt() - b) / (ad * 2.0)).to_f64();
                    assert!(
                        g.is_finite() && g > 0.0 && (g / want - 1.0).abs() <= 8.0 * f64::EPSILON,
                        "s11 {s11:e}, s22 {s22:e}, r {r}: {g:e} vs {want:e}"
                    );
                    let (low, high) = (a / s11, s22 / a);
                    assert!(g >= low * (1.0 - 4.0 * f64::EPSILON), "{g} < {low}");
                    assert!(g <= high * (1.0 + 4.0 * f64::EPSILON), "{g} > {high}");
                }
            }
        }
    }

    #[test]
    fn huddle_and_three_cornered_hat_recover_the_noise() {
        let n = 1 << 17;
        let input = Input::Tilt(TiltAxis::EtaT);
        // White noise of standard deviation s at 1 Hz: one-sided PSD 2 s^2.
        for (gains, noises) in [
            (vec![1.0, 1.05], vec![0.3, 0.3]),
            (vec![1.0, 0.95, 1.1], vec![0.3, 0.5, 0.2]),
        ] {
            let x = instruments(&gains, &noises, n);
            let others: Vec<&[f64]> = x[1..].iter().map(Vec::as_slice).collect();
            let e = estimate(input, &x[0], &others, 1.0, 1024, 1.0).unwrap();
            match &e.method {
                Method::Huddle { relative_gain, .. } => {
                    assert!((relative_gain - gains[1]).abs() < 1e-2, "{relative_gain}")
                }
                Method::ThreeCorneredHat { relative_gains } => {
                    for (g, t) in relative_gains.iter().zip(&gains[1..]) {
                        assert!((g - t).abs() < 1e-2, "{g} vs {t}");
                    }
                }
            }
            let NoiseLevel::Curve(c) = &e.noise.level else {
                panic!("a curve")
            };
            let truth = 2.0 * noises[0] * noises[0];
            let grid: Vec<f64> = (100..=450).map(|k| k as f64 * 1e-3).collect();
            let psd = c.psd_on(&grid);
            let mean = psd.iter().map(|p| (p / truth).sqrt()).sum::<f64>() / psd.len() as f64;
            assert!(
                (mean - 1.0).abs() < 3.0 * e.noise.rel && e.noise.rel < 0.05,
                "{:?}: ASD off by {} (stated {})",
                e.method,
                mean - 1.0,
                e.noise.rel
            );
        }
    }
}
