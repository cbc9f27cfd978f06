//! The finiteness policy: the magnitudes a value may have where it enters the program (a
//! sample of a record, a spectrum value of a file, a sample rate, a frequency of a spectrum,
//! a readout or witness-noise level, a calibration gain), checked by every reader and by the
//! Python package before anything is computed. A value outside its range is refused, naming
//! the file, channel, index and value; the results are then finite and normal by
//! construction, and no later stage has to guess which input made a number infinite or zero.
//!
//! **Zero is always allowed** where the quantity can be zero (a sample, an ASD): exact zeros
//! are structural (a channel that does not move, a term that vanishes by symmetry) and stay
//! zeros. A *nonzero* value below the smallest magnitude is refused: its square or fourth
//! power would underflow, and a spectrum that reads 0 where the truth is 1e-310 is silently
//! wrong.
//!
//! # Why these bounds
//!
//! Everything the program derives from a value is at most its fourth power (a PSD is a square,
//! a coherence, a least-squares fit or a decomposition of a cross-spectral matrix multiplies
//! two PSDs) times counts and rates within the other limits. With samples `x`, sample rates
//! `fs` and Welch segments of `L <= 2^32` samples ([`super::MAX_STREAMED_SAMPLES`]):
//!
//! * a segment's PSD is at most `(4/3) x^2 L / fs`; for `|x| <= 1e40`, `fs >= 1e-6 Hz` that is
//!   `5.7e95`, and a rate turned into an angle is divided by `(2 pi f)^2` with `f >= fs / L`:
//!   `2.7e125`. Its square is `7e250` and a sum of 10^8 of them `7e258`, below `f64::MAX`
//!   (`1.8e308`);
//! * the smallest nonzero contribution of one sample to a PSD bin is about
//!   `(x w)^2 / (fs sum w^2)`, with the Hann window's smallest nonzero weight `w` of about
//!   `(pi / L)^2`: for `|x| >= 1e-40` and `fs <= 2e6 Hz`, `8.9e-133`, whose square `7.9e-265` is
//!   still normal (above `f64::MIN_POSITIVE`, `2.2e-308`);
//! * an ASD `a` of a file is a PSD `a^2`, divided by `(2 pi f)^2` for a rate, with `1e-9 Hz <=
//!   f <= 1e6 Hz`: for `1e-40 <= a <= 1e40` the PSD stays within `2.5e-94 .. 2.5e96`, and its
//!   square within `6e-188 .. 6e192`.
//!
//! No physical tilt, displacement, angle or rate comes within twenty orders of magnitude of
//! either end, so a value outside is a wrong unit, a wrong scale factor or a damaged file.
//! The bounds are checked at compile time below against these derivations.

use super::MAX_FREQUENCY_HZ;
use std::fmt;

/// Largest magnitude of a sample of a time series, in its SI unit (rad, rad/s, m) after the
/// file's unit and the scale factor are applied.
pub const MAX_SAMPLE: f64 = 1e40;

/// Smallest magnitude of a nonzero sample (0 itself is allowed).
pub const MIN_SAMPLE: f64 = 1e-40;

/// Largest amplitude spectral density (a spectrum file, a readout or witness-noise level), in
/// its unit per sqrt(Hz).
pub const MAX_ASD: f64 = 1e40;

/// Smallest nonzero amplitude spectral density (0 itself is allowed).
pub const MIN_ASD: f64 = 1e-40;

/// Lowest sample rate of a time series (Hz): one sample in 11.6 days.
pub const MIN_SAMPLE_RATE_HZ: f64 = 1e-6;

/// Highest sample rate of a time series (Hz): its Nyquist frequency is the highest frequency
/// the model is evaluated at ([`MAX_FREQUENCY_HZ`]).
pub const MAX_SAMPLE_RATE_HZ: f64 = 2.0 * MAX_FREQUENCY_HZ;

/// Lowest frequency of a spectrum read from a file (Hz): a period of 32 years. A rate spectrum
/// is divided by `(2 pi f)^2` there.
pub const MIN_SPECTRUM_FREQUENCY_HZ: f64 = 1e-9;

/// Smallest and largest magnitude of a nonzero calibration gain (`simulate --drive-gain`): a
/// tiltmeter off by six orders of magnitude either way is a wrong unit, not a calibration.
pub const GAIN_RANGE: (f64, f64) = (1e-6, 1e6);

/// Largest ratio `r` of a co-located instrument's noise ASD to the witness's
/// (`subtract --colocated-ratio`, a huddle test); every ratio from 0 (a noiseless co-located
/// instrument) to it is allowed. The witness's noise is estimated as
/// `N_1 = PSD(x_1 - x_2 / g) / (1 + r^2 / g^2)`, floored at `1e-6` of the witness's PSD
/// (`subtract::colocated::NOISE_FLOOR_REL`); the relative gain `g` of two instruments
/// recording the same motion in the same unit is near 1. Where the two are coherent enough
/// for the gain (coherence >= 0.9) the difference's PSD is below a ninth of the witness's, so
/// for `r / |g| >= 1e3 = 1 / sqrt(1e-6)` the estimate is the floor whatever the records hold
/// (the witness's noise is hidden under the other's): a larger ratio tells nothing, and is a
/// PSD ratio given for an ASD ratio, or a unit slip. A small ratio is a true statement (a much
/// quieter co-located instrument): below `1e-3` the estimate is that of a noiseless one to
/// within the floor, and the gain is computed without cancellation down to 0.
pub const MAX_NOISE_RATIO: f64 = 1e3;

/// Whether `r` is an allowed noise ratio of a huddle test: from 0 to [`MAX_NOISE_RATIO`]
/// (NaN is not).
pub fn admits_noise_ratio(r: f64) -> bool {
    (0.0..=MAX_NOISE_RATIO).contains(&r)
}

/// The allowed noise ratios of a huddle test, for messages: `from 0 to 1e3`.
pub fn allowed_noise_ratios() -> String {
    format!("from 0 to {MAX_NOISE_RATIO:e}")
}

/// Smallest and largest nonzero absolute error bar of an `[asymmetry]` offset in a parameter
/// file's `[uncertainty]` table (`sigma`, in m or rad; 0 keeps the offset exact). An offset
/// displaces a position of the model, whose bodies are at least 1 mm long: below
/// `f64::EPSILON x 1 mm = 2.2e-19 m` (and `2.2e-16 rad` of a rotation) the error bar is below
/// the rounding of the positions it moves, and the fit's scaled variable `(p - p0) / sigma`
/// and its covariance `sigma^2 (J^T J)^-1` lose their meaning (and, at `1e-310`, their
/// finiteness). Above it: an offset is bounded by a tenth of its body (bodies below 10 m) or
/// 0.1 rad ([`crate::params::Asymmetry::limits`]), so a sigma above 1 puts every Monte Carlo
/// draw and both edges of the fit's box outside the bound.
pub const OFFSET_SIGMA_RANGE: (f64, f64) = (1e-20, 1.0);

/// Smallest and largest error `sigma` of a measured visibility (`fit --visibility`, the ratio
/// of a mode's components in two observables, `|ratio| <= 1e6`,
/// `fit::visibility::MAX_RATIO`). Above `2e6`, the whole range of ratios, a row measures
/// nothing. Below `1e-40` nothing is measured either (a ratio of two amplitudes each at least
/// [`MIN_SAMPLE`] in magnitude); within the range a residual `(model - ratio) / sigma` is at
/// most `2e46` for a model ratio within the same range, its square `4e92`, and `chi^2` over
/// a file's rows and the normal equations of the fit (error bars of at most 1,
/// [`OFFSET_SIGMA_RANGE`]) stay finite with a margin of 10^200.
pub const VISIBILITY_SIGMA_RANGE: (f64, f64) = (1e-40, 2e6);

/// Longest Welch segment the bounds above are derived for.
const MAX_SEGMENT: f64 = super::MAX_STREAMED_SAMPLES as f64;

// The derivations of the module docs, as checks of the constants.
const _: () = {
    let pi2 = 2.0 * std::f64::consts::PI;
    // Largest PSD of a segment, and of a rate turned into an angle at the lowest bin.
    let psd = 4.0 / 3.0 * MAX_SAMPLE * MAX_SAMPLE * MAX_SEGMENT / MIN_SAMPLE_RATE_HZ;
    let lowest = pi2 * MIN_SAMPLE_RATE_HZ / MAX_SEGMENT;
    let angle = psd / (lowest * lowest);
    assert!(angle * angle * 1e8 < f64::MAX / 1e40);
    // Smallest nonzero contribution of one sample, Hann weight (pi / L)^2.
    let w = (std::f64::consts::PI / MAX_SEGMENT) * (std::f64::consts::PI / MAX_SEGMENT);
    let sum_w2 = 3.0 / 8.0 * MAX_SEGMENT;
    let least = MIN_SAMPLE * w * MIN_SAMPLE * w / (MAX_SAMPLE_RATE_HZ * sum_w2);
    assert!(least * least > f64::MIN_POSITIVE * 1e40);
    // Spectra of files, a rate at the lowest and highest frequency.
    let low = pi2 * MIN_SPECTRUM_FREQUENCY_HZ;
    let high = pi2 * MAX_FREQUENCY_HZ;
    let top = MAX_ASD * MAX_ASD / (low * low);
    let bottom = MIN_ASD * MIN_ASD / (high * high);
    assert!(top * top * 1e8 < f64::MAX / 1e40);
    assert!(bottom * bottom > f64::MIN_POSITIVE * 1e40);
    // An offset's smallest error bar is below the rounding of a 1 mm position.
    assert!(OFFSET_SIGMA_RANGE.0 < f64::EPSILON * 1e-3);
    // The largest residual of a visibility, squared, summed over a file's rows (at most one
    // per two bytes) and multiplied by the squared largest error bar, stays finite.
    let residual = 2.0 * 1e6 / VISIBILITY_SIGMA_RANGE.0;
    let rows = (super::MAX_SETTINGS_FILE_BYTES / 2) as f64;
    assert!(residual * residual * rows * OFFSET_SIGMA_RANGE.1 < f64::MAX / 1e200);
    // PSDS are the squares of ASDS, to the rounding of the products.
    let eps = 4.0 * f64::EPSILON;
    let (lo, hi) = (
        MIN_ASD * MIN_ASD / PSDS.smallest,
        MAX_ASD * MAX_ASD / PSDS.largest,
    );
    assert!(lo > 1.0 - eps && lo < 1.0 + eps && hi > 1.0 - eps && hi < 1.0 + eps);
};

/// The values a kind of quantity may take: zero (if allowed), or a magnitude from `smallest`
/// to `largest`, of either sign or positive only. NaN and the infinities never.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Magnitudes {
    /// Smallest magnitude of a nonzero value.
    pub smallest: f64,
    /// Largest magnitude.
    pub largest: f64,
    /// Whether negative values are allowed.
    pub signed: bool,
    /// Whether exactly zero is allowed.
    pub zero: bool,
}

/// Samples of a time series ([`MIN_SAMPLE`], [`MAX_SAMPLE`]).
pub const SAMPLES: Magnitudes = Magnitudes {
    smallest: MIN_SAMPLE,
    largest: MAX_SAMPLE,
    signed: true,
    zero: true,
};

/// Amplitude spectral densities ([`MIN_ASD`], [`MAX_ASD`]).
pub const ASDS: Magnitudes = Magnitudes {
    smallest: MIN_ASD,
    largest: MAX_ASD,
    signed: false,
    zero: true,
};

/// Power spectral densities and the magnitudes of cross-spectral densities: the squares of
/// [`ASDS`] (written out, so that messages show `1e-80`, not the rounded product).
pub const PSDS: Magnitudes = Magnitudes {
    smallest: 1e-80,
    largest: 1e80,
    signed: false,
    zero: true,
};

/// Sample rates of time series ([`MIN_SAMPLE_RATE_HZ`], [`MAX_SAMPLE_RATE_HZ`]).
pub const SAMPLE_RATES: Magnitudes = Magnitudes {
    smallest: MIN_SAMPLE_RATE_HZ,
    largest: MAX_SAMPLE_RATE_HZ,
    signed: false,
    zero: false,
};

/// Frequencies of spectra read from files ([`MIN_SPECTRUM_FREQUENCY_HZ`],
/// [`MAX_FREQUENCY_HZ`]).
pub const SPECTRUM_FREQUENCIES: Magnitudes = Magnitudes {
    smallest: MIN_SPECTRUM_FREQUENCY_HZ,
    largest: MAX_FREQUENCY_HZ,
    signed: false,
    zero: false,
};

/// Calibration gains ([`GAIN_RANGE`]).
pub const GAINS: Magnitudes = Magnitudes {
    smallest: GAIN_RANGE.0,
    largest: GAIN_RANGE.1,
    signed: true,
    zero: true,
};

/// Absolute error bars of `[asymmetry]` offsets ([`OFFSET_SIGMA_RANGE`]); 0 (exact) allowed.
pub const OFFSET_SIGMAS: Magnitudes = Magnitudes {
    smallest: OFFSET_SIGMA_RANGE.0,
    largest: OFFSET_SIGMA_RANGE.1,
    signed: false,
    zero: true,
};

/// Errors of measured visibilities ([`VISIBILITY_SIGMA_RANGE`]).
pub const VISIBILITY_SIGMAS: Magnitudes = Magnitudes {
    smallest: VISIBILITY_SIGMA_RANGE.0,
    largest: VISIBILITY_SIGMA_RANGE.1,
    signed: false,
    zero: false,
};

impl Magnitudes {
    /// Whether `value` is allowed.
    pub fn admits(&self, value: f64) -> bool {
        if value == 0.0 {
            return self.zero;
        }
        if value < 0.0 && !self.signed {
            return false;
        }
        // NaN fails both comparisons.
        let a = value.abs();
        a >= self.smallest && a <= self.largest
    }

    /// The first value of `values` that is not allowed, with its index.
    pub fn first_refused(&self, values: &[f64]) -> Option<(usize, f64)> {
        values
            .iter()
            .position(|&v| !self.admits(v))
            .map(|i| (i, values[i]))
    }

    /// What is allowed, in `unit`, for messages: `0 or a magnitude from 1e-40 to 1e40 rad`,
    /// `from 1e-6 to 2e6 Hz`.
    pub fn allowed<'a>(&'a self, unit: &'a str) -> Allowed<'a> {
        Allowed { m: self, unit }
    }
}

/// [`Magnitudes::allowed`], displayed.
#[derive(Debug, Clone, Copy)]
pub struct Allowed<'a> {
    m: &'a Magnitudes,
    unit: &'a str,
}

impl fmt::Display for Allowed<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let m = self.m;
        let range = format!("{:e} to {:e} {}", m.smallest, m.largest, self.unit);
        let range = range.trim_end();
        match (m.zero, m.signed) {
            (true, true) => write!(f, "0 or a magnitude from {range}"),
            (true, false) => write!(f, "0 or a value from {range}"),
            (false, true) => write!(f, "a magnitude from {range}"),
            (false, false) => write!(f, "from {range}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zeros_stay_and_nonzero_values_need_their_range() {
        for v in [0.0, -0.0, 1e-40, -1e-40, 1.0, 1e40, -1e40] {
            assert!(SAMPLES.admits(v), "{v}");
        }
        for v in [
            1e-41,
            -9.9e-41,
            1.01e40,
            f64::MAX,
            5e-324,
            f64::NAN,
            f64::INFINITY,
        ] {
            assert!(!SAMPLES.admits(v), "{v}");
        }
        assert!(ASDS.admits(0.0) && !ASDS.admits(-1e-9) && ASDS.admits(1e-9));
        assert!(!SAMPLE_RATES.admits(0.0) && !SAMPLE_RATES.admits(-1.0));
        assert!(SAMPLE_RATES.admits(1.0) && SAMPLE_RATES.admits(2e6));
        assert!(!SAMPLE_RATES.admits(2.1e6) && !SAMPLE_RATES.admits(1e308));
        assert_eq!(PSDS.smallest, 1e-80);
        assert_eq!(
            SAMPLES.first_refused(&[0.0, 1.0, 1e308, f64::NAN]),
            Some((2, 1e308))
        );
        assert_eq!(SAMPLES.first_refused(&[0.0, 1.0]), None);
    }

    #[test]
    fn what_is_allowed_reads_as_a_range() {
        assert_eq!(
            SAMPLES.allowed("rad").to_string(),
            "0 or a magnitude from 1e-40 to 1e40 rad"
        );
        assert_eq!(
            ASDS.allowed("m/sqrt(Hz)").to_string(),
            "0 or a value from 1e-40 to 1e40 m/sqrt(Hz)"
        );
        assert_eq!(
            SAMPLE_RATES.allowed("Hz").to_string(),
            "from 1e-6 to 2e6 Hz"
        );
        assert_eq!(
            GAINS.allowed("").to_string(),
            "0 or a magnitude from 1e-6 to 1e6"
        );
    }

    /// The derivation of the module docs with the numbers written out: the extremes of a PSD
    /// computed from samples at the bounds, and of its square, are finite and normal.
    #[test]
    fn the_extremes_of_the_derivation_are_finite_and_normal() {
        let l = MAX_SEGMENT;
        let psd = 4.0 / 3.0 * MAX_SAMPLE.powi(2) * l / MIN_SAMPLE_RATE_HZ;
        assert!((psd / 5.7e95 - 1.0).abs() < 0.01, "{psd:e}");
        let angle = psd / (2.0 * std::f64::consts::PI * MIN_SAMPLE_RATE_HZ / l).powi(2);
        assert!((angle / 2.7e125 - 1.0).abs() < 0.02, "{angle:e}");
        assert!((angle * angle * 1e8).is_finite());
        let w = (std::f64::consts::PI / l).powi(2);
        let least = (MIN_SAMPLE * w).powi(2) / (MAX_SAMPLE_RATE_HZ * 3.0 / 8.0 * l);
        assert!((least / 8.9e-133 - 1.0).abs() < 0.01, "{least:e}");
        assert!((least * least).is_normal());
    }
}
