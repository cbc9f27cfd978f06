//! `tiltnoise.welch` and `tiltnoise.csd`: the library's Welch estimates, with the signature and
//! the scaling of `scipy.signal.welch` and `scipy.signal.csd` (periodic Hann window, one-sided
//! density).

use crate::errors::{value_error, PyResultExt};
use numpy::{Complex64, PyArray1, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use tiltnoise_core::spectral::{self, Averaging, Detrend, WelchConfig};

/// `(f, Pxx)` or `(f, Pxy)`: frequencies (Hz) and one-sided densities, as scipy returns them.
type Spectrum<'py, T> = PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<T>>)>;

/// A 1-D series of `f64` from any array-like, named `what` in errors.
pub fn series(what: &str, arg: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let np = arg.py().import("numpy")?;
    let array = np
        .call_method1("asarray", (arg, "float64"))
        .map_err(|e| value_error(format!("{what}: not an array of numbers ({e})")))?
        .cast_into::<PyArrayDyn<f64>>()?;
    if array.ndim() != 1 {
        return Err(value_error(format!(
            "{what}: expected a 1-D series, got an array of shape {:?}",
            array.shape()
        )));
    }
    Ok(array.readonly().as_array().iter().copied().collect())
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

/// The Welch configuration of scipy's arguments.
fn config(
    window: &str,
    nperseg: usize,
    noverlap: Option<usize>,
    detrend: &Bound<'_, PyAny>,
    average: &str,
) -> PyResult<WelchConfig> {
    if window != "hann" {
        return Err(value_error(format!(
            "window {window:?} is not allowed: tiltnoise's Welch uses the periodic Hann \
             window, \"hann\" (scipy's default)"
        )));
    }
    let detrend = match detrend.extract::<String>() {
        Ok(s) if s == "constant" => Detrend::Constant,
        _ if detrend.is_instance_of::<pyo3::types::PyBool>() && !detrend.is_truthy()? => {
            Detrend::None
        }
        _ => {
            return Err(value_error(format!(
                "detrend {detrend} is not allowed: must be \"constant\" (scipy's default) or False"
            )))
        }
    };
    let cfg = WelchConfig::new(nperseg)
        .with_overlap(noverlap.unwrap_or(nperseg / 2))
        .with_averaging(averaging(average)?)
        .with_detrend(detrend);
    cfg.validate().py()?;
    Ok(cfg)
}

/// One-sided power spectral density of ``x`` by Welch's method, as
/// ``scipy.signal.welch(x, fs, window="hann", nperseg, noverlap, detrend, average=average)``
/// with ``scaling="density"`` and ``return_onesided=True``: the same frequencies and values.
///
/// Returns ``(f, Pxx)``: frequencies ``k fs / nperseg`` (Hz) for ``k = 0 .. nperseg // 2``
/// and the PSD in ``unit**2/Hz`` for ``x`` in ``unit`` (its integral over ``0 .. fs/2`` is
/// the variance). Unlike scipy, a series shorter than ``nperseg`` raises ``ValueError``
/// instead of shortening the segment. ``average`` is ``"mean"`` or ``"median"`` (with
/// scipy's bias correction); ``detrend`` is ``"constant"`` or ``False``.
#[pyfunction]
#[pyo3(signature = (x, fs=1.0, window="hann", nperseg=256, noverlap=None, detrend=None, average="mean"))]
#[allow(clippy::too_many_arguments)]
pub fn welch<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    fs: f64,
    window: &str,
    nperseg: usize,
    noverlap: Option<usize>,
    detrend: Option<&Bound<'py, PyAny>>,
    average: &str,
) -> Spectrum<'py, f64> {
    let constant = pyo3::types::PyString::new(py, "constant").into_any();
    let cfg = config(
        window,
        nperseg,
        noverlap,
        detrend.unwrap_or(&constant),
        average,
    )?;
    let x = series("x", x)?;
    let psd = py.detach(|| spectral::welch(&x, fs, &cfg)).py()?;
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
#[pyo3(signature = (x, y, fs=1.0, window="hann", nperseg=256, noverlap=None, detrend=None, average="mean"))]
#[allow(clippy::too_many_arguments)]
pub fn csd<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    y: &Bound<'py, PyAny>,
    fs: f64,
    window: &str,
    nperseg: usize,
    noverlap: Option<usize>,
    detrend: Option<&Bound<'py, PyAny>>,
    average: &str,
) -> Spectrum<'py, Complex64> {
    let constant = pyo3::types::PyString::new(py, "constant").into_any();
    let cfg = config(
        window,
        nperseg,
        noverlap,
        detrend.unwrap_or(&constant),
        average,
    )?;
    let (x, y) = (series("x", x)?, series("y", y)?);
    let c = py.detach(|| spectral::csd(&x, &y, fs, &cfg)).py()?;
    Ok((
        PyArray1::from_vec(py, c.freqs_hz),
        PyArray1::from_vec(py, c.csd),
    ))
}
