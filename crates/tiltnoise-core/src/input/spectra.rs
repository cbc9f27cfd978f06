//! [`TiltSpectra`]: one-sided tilt cross-spectral densities and their log-log interpolation.

use super::Provenance;
use crate::limits::SPECTRUM_FREQUENCIES;
use crate::model::TiltAxis;
use num_complex::Complex64;

/// Relative tolerance of the Hermitian and Cauchy-Schwarz checks of an input CSD matrix:
/// `|S_ij - conj(S_ji)| <= CSD_RTOL * sqrt(S_ii S_jj)`, `|S_ij| <= (1 + CSD_RTOL)
/// sqrt(S_ii S_jj)` and `|Im S_ii| <= CSD_RTOL * S_ii`.
///
/// Derivation: an estimator that forms `S_ij` and `S_ji` separately (e.g. Welch averages of
/// `conj(X_i) X_j` and `conj(X_j) X_i`) makes each with at most a few hundred roundings, each
/// off by at most `eps` relative to `|X_i||X_j|`, whose average is bounded by
/// `sqrt(S_ii S_jj)` (Cauchy-Schwarz); 1024 roundings of `eps = 2.2e-16` give `2.3e-13`. Any
/// larger asymmetry is not rounding but an inconsistent file.
pub const CSD_RTOL: f64 = 1024.0 * f64::EPSILON;

/// One-sided tilt spectra: the cross-spectral density matrix at each frequency.
#[derive(Debug, Clone, PartialEq)]
pub struct TiltSpectra {
    /// Frequencies (Hz), finite, > 0, strictly increasing, at least 2.
    pub freqs_hz: Vec<f64>,
    /// The axes, in canonical order (theta_t, eta_t, phi_t).
    pub axes: Vec<TiltAxis>,
    /// One-sided CSD of the tilt angle `t` (rad²/Hz), row-major `[f][i][j]`
    /// (`csd[(k * n + i) * n + j]`, `n = axes.len()`). Hermitian at each frequency; the
    /// diagonal is the real PSD `S_ii >= 0`. Convention as in [`crate::spectral`]:
    /// `S_ij = conj(X_i) X_j`.
    pub csd: Vec<Complex64>,
    /// Where it came from.
    pub provenance: Provenance,
}

impl TiltSpectra {
    /// Number of frequencies.
    pub fn len(&self) -> usize {
        self.freqs_hz.len()
    }

    /// Whether there are no frequencies.
    pub fn is_empty(&self) -> bool {
        self.freqs_hz.is_empty()
    }

    /// `[f_min, f_max]` of the data (Hz).
    pub fn band_hz(&self) -> (f64, f64) {
        (
            self.freqs_hz.first().copied().unwrap_or(f64::NAN),
            self.freqs_hz.last().copied().unwrap_or(f64::NAN),
        )
    }

    /// `S_ij` at frequency index `k` (rad²/Hz).
    pub fn csd_at(&self, k: usize, i: usize, j: usize) -> Complex64 {
        let n = self.axes.len();
        self.csd[(k * n + i) * n + j]
    }

    /// The PSD of `axis` (rad²/Hz) at every frequency, if present.
    pub fn psd(&self, axis: TiltAxis) -> Option<Vec<f64>> {
        let i = self.axes.iter().position(|&a| a == axis)?;
        Some((0..self.len()).map(|k| self.csd_at(k, i, i).re).collect())
    }

    /// The ASD of `axis` (rad/sqrt(Hz)) at every frequency, if present.
    pub fn asd(&self, axis: TiltAxis) -> Option<Vec<f64>> {
        self.psd(axis)
            .map(|p| p.into_iter().map(f64::sqrt).collect())
    }

    /// Interpolates onto the grid points inside the data band.
    ///
    /// Returns the grid restricted to `[f_min, f_max]` of the data (points outside, and
    /// non-finite points, are dropped; the order of the grid is kept) and the spectra on it.
    /// The caller reports the restriction when the returned grid is shorter than `grid_hz`; the
    /// returned provenance gets a note then, and [`TiltSpectra::band_hz`] of `self` gives the
    /// data band.
    ///
    /// Method, with `t = ln(f / f_k) / ln(f_{k+1} / f_k)` between neighbouring data
    /// frequencies `f_k < f < f_{k+1}`:
    ///
    /// * diagonal PSDs linearly in `ln f`-`ln S`: `S = S_k (S_{k+1}/S_k)^t`, exact for any
    ///   power law; if either neighbour is 0, linearly in `S`: `S = S_k + t (S_{k+1} - S_k)`;
    /// * off-diagonal entries through the complex coherence `g_ij = S_ij / sqrt(S_ii S_jj)`
    ///   (0 where a PSD is 0), interpolated linearly in `ln f` (`g = g_k + t (g_{k+1} - g_k)`)
    ///   and rescaled by the interpolated `sqrt(S_ii S_jj)`; `S_ji = conj(S_ij)`. So `|g| <= 1`
    ///   is preserved and uncorrelated axes stay uncorrelated.
    ///
    /// A grid point equal to a data frequency gets the data values exactly.
    pub fn interpolate_loglog(&self, grid_hz: &[f64]) -> (Vec<f64>, TiltSpectra) {
        let (f_min, f_max) = self.band_hz();
        let grid: Vec<f64> = grid_hz
            .iter()
            .copied()
            .filter(|f| f.is_finite() && *f >= f_min && *f <= f_max)
            .collect();
        let n = self.axes.len();
        let mut csd = Vec::with_capacity(grid.len() * n * n);
        let mut row = vec![Complex64::new(0.0, 0.0); n * n];
        for &f in &grid {
            let k = self.freqs_hz.partition_point(|&x| x < f);
            if self.freqs_hz[k] == f {
                csd.extend_from_slice(&self.csd[k * n * n..(k + 1) * n * n]);
                continue;
            }
            let (lo, hi) = (k - 1, k);
            let t = (f / self.freqs_hz[lo]).ln() / (self.freqs_hz[hi] / self.freqs_hz[lo]).ln();
            for i in 0..n {
                let (s0, s1) = (self.csd_at(lo, i, i).re, self.csd_at(hi, i, i).re);
                let s = if s0 > 0.0 && s1 > 0.0 {
                    s0 * (t * (s1 / s0).ln()).exp()
                } else {
                    s0 + t * (s1 - s0)
                };
                row[i * n + i] = Complex64::new(s, 0.0);
            }
            for i in 0..n {
                for j in i + 1..n {
                    let coh = |k: usize| {
                        let d = (self.csd_at(k, i, i).re * self.csd_at(k, j, j).re).sqrt();
                        if d > 0.0 {
                            self.csd_at(k, i, j) / d
                        } else {
                            Complex64::new(0.0, 0.0)
                        }
                    };
                    let (g0, g1) = (coh(lo), coh(hi));
                    let g = g0 + (g1 - g0) * t;
                    let scale = (row[i * n + i].re * row[j * n + j].re).sqrt();
                    row[i * n + j] = g * scale;
                    row[j * n + i] = (g * scale).conj();
                }
            }
            csd.extend_from_slice(&row);
        }
        let mut provenance = self.provenance.clone();
        if grid.len() < grid_hz.len() {
            let finite = || grid_hz.iter().copied().filter(|f| f.is_finite());
            let lo = finite().fold(f64::INFINITY, f64::min);
            let hi = finite().fold(f64::NEG_INFINITY, f64::max);
            provenance.notes.push(format!(
                "frequency grid restricted to the data band [{f_min}, {f_max}] Hz: {} of {} \
                 points kept (requested {lo} .. {hi} Hz)",
                grid.len(),
                grid_hz.len()
            ));
        }
        let out = TiltSpectra {
            freqs_hz: grid.clone(),
            axes: self.axes.clone(),
            csd,
            provenance,
        };
        (grid, out)
    }
}

/// What is wrong with the frequency `f_hz` of a spectrum read from a file, coming after
/// `previous` (if any): outside [`SPECTRUM_FREQUENCIES`] or not greater than `previous`. The
/// text is what is allowed, for [`super::InputError::Frequency`]; `None` if `f_hz` is allowed.
pub fn frequency_refusal(f_hz: f64, previous: Option<f64>) -> Option<String> {
    if !SPECTRUM_FREQUENCIES.admits(f_hz) {
        return Some(format!(
            "{} (a rate spectrum is divided by (2 pi f)^2; see docs/limits.md)",
            SPECTRUM_FREQUENCIES.allowed("Hz")
        ));
    }
    match previous {
        Some(p) if f_hz <= p => Some(format!(
            "strictly increasing: greater than the previous {p:?} Hz"
        )),
        _ => None,
    }
}

/// Refuses a CSD matrix (`[f][i][j]`, as in [`TiltSpectra::csd`]) with a non-finite entry:
/// finite inputs can still overflow on squaring or on the division of a rate spectrum.
pub fn check_csd_finite(
    path: &std::path::Path,
    freqs_hz: &[f64],
    axes: &[TiltAxis],
    csd: &[Complex64],
) -> Result<(), super::InputError> {
    let n = axes.len();
    let Some(at) = csd
        .iter()
        .position(|z| !(z.re.is_finite() && z.im.is_finite()))
    else {
        return Ok(());
    };
    let (k, i, j) = (at / (n * n), at / n % n, at % n);
    let z = csd[at];
    Err(super::InputError::SpectrumOverflow {
        path: path.to_path_buf(),
        entry: format!("S({}, {})", axes[i].name(), axes[j].name()),
        freq_hz: freqs_hz[k],
        value: if z.re.is_finite() { z.im } else { z.re },
    })
}

/// Builds the output CSD in canonical axis order from a source CSD `src(k, a, b)` indexed by
/// source channel: `S_ij = s_i s_j src(k, a_i, a_j)`, divided by `(2 pi f)^2` for a rate
/// ([`super::rate`]).
///
/// # Panics
///
/// For a rate at a frequency `<= 0` (the readers refuse such frequencies before calling).
pub fn assemble(
    freqs_hz: &[f64],
    channels: &[super::axis_map::Mapped],
    quantity: super::Quantity,
    src: impl Fn(usize, usize, usize) -> Complex64,
) -> Vec<Complex64> {
    let n = channels.len();
    let mut csd = Vec::with_capacity(freqs_hz.len() * n * n);
    for (k, &f) in freqs_hz.iter().enumerate() {
        let w2 = super::rate::angle_psd_divisor(quantity, f)
            .expect("the readers refuse frequencies <= 0 before assembling");
        for a in channels {
            for b in channels {
                let s = a.sign.factor() * b.sign.factor();
                csd.push(src(k, a.index, b.index) * s / w2);
            }
        }
    }
    csd
}
