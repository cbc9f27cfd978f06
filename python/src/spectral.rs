//! `tiltnoise.welch` and `tiltnoise.csd`: the library's Welch estimates, with the signature and
//! the scaling of `scipy.signal.welch` and `scipy.signal.csd` (periodic Hann window, one-sided
//! density).

use crate::args::kw;
use crate::arrays::{self, Size};
use crate::errors::{value_error, PyResultExt};
use crate::interrupt;
use numpy::{Complex64, PyArray1};
use pyo3::prelude::*;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::error::Num;
use tiltnoise_core::limits::{MAX_SERIES_SAMPLES, SAMPLES, SAMPLE_RATES, SERIES_BYTES_PER_SAMPLE};
use tiltnoise_core::spectral::{self, Averaging, Detrend, WelchConfig};

/// `(f, Pxx)` or `(f, Pxy)`: frequencies (Hz) and one-sided densities, as scipy returns them.
type Spectrum<'py, T> = PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<T>>)>;

/// Series at least this long are estimated under [`interrupt::watch`] (a millisecond or more
/// of work; shorter ones end before an interrupt could matter).
const WATCHED_SAMPLES: usize = 1 << 16;

/// The size of a series held in memory ([`MAX_SERIES_SAMPLES`]).
pub const SERIES: Size = Size {
    limit: MAX_SERIES_SAMPLES,
    unit: "samples",
    bytes_each: SERIES_BYTES_PER_SAMPLE,
};

/// The sample rate argument `fs` (Hz), within
/// [`SAMPLE_RATES`](tiltnoise_core::limits::SAMPLE_RATES).
pub fn check_fs(fs: f64) -> PyResult<()> {
    if SAMPLE_RATES.admits(fs) {
        return Ok(());
    }
    Err(value_error(format!(
        "fs = {} Hz is not allowed: the sample rate must be {} (the spectra would leave the \
         range of f64; see docs/limits.md)",
        Num(fs),
        SAMPLE_RATES.allowed("Hz")
    )))
}

/// A series `what` for a spectral estimate: its size checked before the copy, every value
/// finite and within [`SAMPLES`] (in the series' own unit).
fn checked_series(what: &str, arg: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let x = arrays::series(what, arg, SERIES)?;
    arrays::check_values(what, &x, &SAMPLES, &format!("in the unit of {what}"))?;
    Ok(x)
}

/// [`spectral::welch`] polling `cancel` before each segment.
pub fn welch_cancellable(
    x: &[f64],
    fs: f64,
    cfg: &WelchConfig,
    cancel: &Cancel,
) -> Result<spectral::Psd, spectral::SpectralError> {
    let m = spectral::csd_matrix_cancellable(&[x], fs, cfg, cancel)?;
    Ok(spectral::Psd {
        psd: m.psd(0),
        freqs_hz: m.freqs_hz,
        n_segments: m.n_segments,
    })
}

/// `average` as on the command line's `budget --average`.
pub fn averaging(average: &str) -> PyResult<Averaging> {
    match average {
        "mean" => Ok(Averaging::Mean),
        "median" => Ok(Averaging::Median),
        other => Err(value_error(format!(
            "average {other:?} is not allowed: must be \"mean\" or \"median\""
        ))),
    }
}

/// The Welch configuration of scipy's arguments (`detrend` `None`: `"constant"`), the
/// sample rate `fs` checked.
fn config(
    fs: f64,
    window: &str,
    nperseg: usize,
    noverlap: Option<usize>,
    detrend: Option<&Bound<'_, PyAny>>,
    average: &str,
) -> PyResult<WelchConfig> {
    if window != "hann" {
        return Err(value_error(format!(
            "window {window:?} is not allowed: tiltnoise's Welch uses the periodic Hann \
             window, \"hann\" (scipy's default)"
        )));
    }
    let detrend = match detrend {
        None => Detrend::Constant,
        Some(d) => detrend_of(d)?,
    };
    let cfg = WelchConfig::new(nperseg)
        .with_overlap(noverlap.unwrap_or(nperseg / 2))
        .with_averaging(averaging(average)?)
        .with_detrend(detrend);
    cfg.validate().py()?;
    check_fs(fs)?;
    Ok(cfg)
}

/// `detrend`: `"constant"` or `False`.
fn detrend_of(detrend: &Bound<'_, PyAny>) -> PyResult<Detrend> {
    Ok(match detrend.extract::<String>() {
        Ok(s) if s == "constant" => Detrend::Constant,
        _ if detrend.is_instance_of::<pyo3::types::PyBool>() && !detrend.is_truthy()? => {
            Detrend::None
        }
        _ => {
            return Err(value_error(format!(
                "detrend {detrend} is not allowed: must be \"constant\" (scipy's default) or False"
            )))
        }
    })
}

/// One-sided power spectral density of ``x`` by Welch's method, as
/// ``scipy.signal.welch(x, fs, window="hann", nperseg, noverlap, detrend, average=average)``
/// with ``scaling="density"`` and ``return_onesided=True``: the same frequencies and values.
///
/// Returns ``(f, Pxx)``: frequencies ``k fs / nperseg`` (Hz) for ``k = 0 .. nperseg // 2``,
/// equal to scipy's bit for bit (rounded as ``numpy.fft.rfftfreq(nperseg, 1 / fs)``),
/// and the PSD in ``unit**2/Hz`` for ``x`` in ``unit`` (its integral over ``0 .. fs/2`` is
/// the variance). Unlike scipy, a series shorter than ``nperseg`` raises ``ValueError``
/// instead of shortening the segment. ``average`` is ``"mean"`` or ``"median"`` (with
/// scipy's bias correction); ``detrend`` is ``"constant"`` or ``False``.
#[pyfunction]
#[pyo3(signature = (x, fs=1.0, window=String::from("hann"), nperseg=256, noverlap=None, detrend=None, average=String::from("mean")), text_signature = "(x, fs=1.0, window='hann', nperseg=256, noverlap=None, detrend=None, average='mean')")]
#[allow(clippy::too_many_arguments)]
pub fn welch<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = kw::fs)] fs: f64,
    #[pyo3(from_py_with = kw::window)] window: String,
    #[pyo3(from_py_with = kw::nperseg)] nperseg: usize,
    #[pyo3(from_py_with = kw::noverlap)] noverlap: Option<usize>,
    detrend: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = kw::average)] average: String,
) -> Spectrum<'py, f64> {
    let cfg = config(fs, &window, nperseg, noverlap, detrend, &average)?;
    let x = checked_series("x", x)?;
    let cancel = Cancel::new();
    let long = x.len() >= WATCHED_SAMPLES;
    let psd = interrupt::watch_if(py, long, &cancel, || {
        welch_cancellable(&x, fs, &cfg, &cancel).py()
    })?;
    Ok((
        PyArray1::from_vec(py, psd.freqs_hz),
        PyArray1::from_vec(py, psd.psd),
    ))
}

/// One-sided cross spectral density ``<conj(X) Y>`` of ``x`` and ``y`` by Welch's method, as
/// ``scipy.signal.csd(x, y, fs, window="hann", nperseg, noverlap, detrend, average=average)``
/// with ``scaling="density"``: the same frequencies and values.
///
/// Returns ``(f, Pxy)``, ``Pxy`` complex in ``unit_x unit_y/Hz``; if ``y`` is ``x`` delayed by
/// ``tau``, ``angle(Pxy) = -2 pi f tau``. ``x`` and ``y`` must have the same length (scipy
/// zero-pads the shorter one).
#[pyfunction]
#[pyo3(signature = (x, y, fs=1.0, window=String::from("hann"), nperseg=256, noverlap=None, detrend=None, average=String::from("mean")), text_signature = "(x, y, fs=1.0, window='hann', nperseg=256, noverlap=None, detrend=None, average='mean')")]
#[allow(clippy::too_many_arguments)]
pub fn csd<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    y: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = kw::fs)] fs: f64,
    #[pyo3(from_py_with = kw::window)] window: String,
    #[pyo3(from_py_with = kw::nperseg)] nperseg: usize,
    #[pyo3(from_py_with = kw::noverlap)] noverlap: Option<usize>,
    detrend: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = kw::average)] average: String,
) -> Spectrum<'py, Complex64> {
    let cfg = config(fs, &window, nperseg, noverlap, detrend, &average)?;
    let (x, y) = (checked_series("x", x)?, checked_series("y", y)?);
    let cancel = Cancel::new();
    let long = x.len() >= WATCHED_SAMPLES;
    let m = interrupt::watch_if(py, long, &cancel, || {
        spectral::csd_matrix_cancellable(&[&x, &y], fs, &cfg, &cancel).py()
    })?;
    Ok((
        PyArray1::from_slice(py, &m.freqs_hz),
        PyArray1::from_vec(py, m.csd(0, 1)),
    ))
}
