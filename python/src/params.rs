//! `tiltnoise.Params`: a validated, immutable parameter set (the command line's `--params FILE`
//! and `--set KEY=VALUE`).

use crate::args::kw;
use crate::errors::{InputFileError, IntoPyErr, PyResultExt};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple};
use std::path::PathBuf;
use tiltnoise_core::error::ParamError;
use tiltnoise_core::params::Params;

/// A validated parameter set of the double torsion pendulum, SI units, the unit in every key.
///
/// ``Params()`` is Table I of De Marchi et al. (2013) with the assumptions the paper does not
/// state (``length.h_m``, ``environment.g_m_per_s2``, ``environment.temperature_k``) and loss
/// angles of 0. A ``Params`` is immutable: :meth:`set` and :meth:`update` return a new,
/// validated set, so a ``Params`` in hand is always physical and can be shared freely.
///
/// Keys are the command line's (``tiltnoise --set length.h_m=1.5``, the TOML file of
/// ``tiltnoise params``); :meth:`keys` lists them with value, unit and allowed range.
#[pyclass(name = "Params", module = "tiltnoise", frozen, eq)]
#[derive(Clone, serde::Serialize, serde::Deserialize)]
pub struct PyParams {
    pub inner: Params,
    /// The parameter file the set was read from (and derived from by `set`, `update`), which
    /// no file saved from results of these parameters may replace.
    pub file: Option<PathBuf>,
}

/// Equal parameter sets are equal wherever they were read from.
impl PartialEq for PyParams {
    fn eq(&self, other: &Self) -> bool {
        self.inner == other.inner
    }
}

impl PyParams {
    /// A parameter set read from no file.
    pub fn unread(inner: Params) -> PyParams {
        PyParams { inner, file: None }
    }

    /// The parameters of `params`, or Table I when `None`.
    pub fn or_table_i(params: Option<&PyParams>) -> Params {
        params.map_or_else(Params::table_i, |p| p.inner.clone())
    }
}

/// How [`PyParams::from_toml`] reads its argument: a path (`os.PathLike`, or a `str` without
/// `=` or a line break) or TOML text.
fn toml_source(arg: &Bound<'_, PyAny>) -> PyResult<Result<PathBuf, String>> {
    if let Ok(s) = arg.cast::<PyString>() {
        let s = s.to_cow()?;
        return Ok(if s.contains(['=', '\n']) {
            Err(s.to_string())
        } else {
            Ok(PathBuf::from(s.as_ref()))
        });
    }
    crate::args::path_of(arg).map(Ok).ok_or_else(|| {
        crate::args::type_error(
            "source",
            arg,
            "a path (str or os.PathLike) or TOML text (str)",
        )
    })
}

#[pymethods]
impl PyParams {
    /// Table I (the command line's default parameter set).
    #[new]
    fn new() -> Self {
        PyParams::unread(Params::table_i())
    }

    /// Reads and validates a parameter set in TOML (the format of ``tiltnoise params``).
    ///
    /// ``source`` is a path (``str`` or ``os.PathLike``) or the TOML text itself: a ``str``
    /// containing ``=`` or a line break is text, any other ``str`` a path.
    ///
    /// Raises ``FileNotFoundError`` / ``OSError`` if the file cannot be read,
    /// :class:`InputFileError` (an ``OSError``) if the file is not a valid parameter set, and
    /// ``ValueError`` if the text is not; the message names the key, the value, the unit and
    /// what is allowed, as on the command line.
    #[staticmethod]
    fn from_toml(source: &Bound<'_, PyAny>) -> PyResult<Self> {
        match toml_source(source)? {
            Ok(path) => {
                let inner = tiltnoise_job::params::read(&path).map_err(|e| match e {
                    ParamError::Read { .. } => e.into_py_err(),
                    other => InputFileError::new_err(crate::errors::shown(&other)),
                })?;
                Ok(PyParams {
                    inner,
                    file: Some(path),
                })
            }
            Err(text) => Ok(PyParams::unread(
                Params::from_toml_str(&text, "TOML text").py()?,
            )),
        }
    }

    /// The parameter set as TOML (units in the keys); it reads back unchanged with
    /// :meth:`from_toml`.
    fn to_toml(&self) -> String {
        self.inner.to_toml()
    }

    /// A new parameter set with one value changed (``tiltnoise --set KEY=VALUE``), validated.
    ///
    /// ``key`` is a dotted key such as ``"length.h_m"``, ``value`` in the key's SI unit.
    /// Raises ``ValueError`` naming the key for an unknown key or a value outside the allowed
    /// range. ``self`` is not changed.
    fn set(
        &self,
        #[pyo3(from_py_with = kw::key)] key: String,
        #[pyo3(from_py_with = kw::value)] value: f64,
    ) -> PyResult<Self> {
        Ok(PyParams {
            inner: self.inner.with_override(&assignment(&key, value)).py()?,
            file: self.file.clone(),
        })
    }

    /// A new parameter set with several values changed, e.g.
    /// ``p.update({"length.h_m": 1.5, "loss.torsion_b_rad": 1e-3})``; each as :meth:`set`.
    fn update(
        &self,
        #[pyo3(from_py_with = kw::values)] values: Vec<(String, f64)>,
    ) -> PyResult<Self> {
        let mut inner = self.inner.clone();
        for (key, value) in &values {
            inner = inner.with_override(&assignment(key, *value)).py()?;
        }
        Ok(PyParams {
            inner,
            file: self.file.clone(),
        })
    }

    /// The value of one key, e.g. ``p.get("length.h_m")`` (m). ``KeyError`` for an unknown key.
    fn get(&self, #[pyo3(from_py_with = kw::key)] key: String) -> PyResult<f64> {
        self.inner
            .fields()
            .iter()
            .find(|f| f.key == key)
            .map(|f| f.value)
            .ok_or_else(|| {
                pyo3::exceptions::PyKeyError::new_err(format!(
                    "unknown key `{key}`; allowed keys: {}",
                    self.key_names().join(", ")
                ))
            })
    }

    /// Every parameter in file order as ``(key, value, unit, allowed)``: the dotted key, its
    /// value, its SI unit and the rule its values must follow.
    fn keys(&self) -> Vec<(&'static str, f64, &'static str, &'static str)> {
        self.inner
            .fields()
            .iter()
            .map(|f| (f.key, f.value, f.unit, f.allowed.describe()))
            .collect()
    }

    /// ``{key: value}`` for every parameter, in file order.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for f in self.inner.fields() {
            d.set_item(f.key, f.value)?;
        }
        Ok(d)
    }

    fn __repr__(&self) -> String {
        self.describe()
    }
    /// Pickles as its TOML text.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let from_toml = py.get_type::<PyParams>().getattr("from_toml")?;
        let args = PyTuple::new(py, [slf.get().inner.to_toml()])?;
        Ok((from_toml, args))
    }
}

impl PyParams {
    /// `Params(Table I)`, or the keys that differ from Table I.
    pub fn describe(&self) -> String {
        let table_i = Params::table_i();
        let nominal = table_i.fields();
        let changed: Vec<String> = self
            .inner
            .fields()
            .iter()
            .zip(&nominal)
            .filter(|(f, t)| f.value.to_bits() != t.value.to_bits())
            .map(|(f, _)| format!("{}={:?}", f.key, f.value))
            .collect();
        let extra = if self.inner.uncertainty != table_i.uncertainty {
            " with its own [uncertainty] table"
        } else {
            ""
        };
        match changed.is_empty() {
            true => format!("Params(Table I{extra})"),
            false => format!("Params(Table I with {}{extra})", changed.join(", ")),
        }
    }

    fn key_names(&self) -> Vec<&'static str> {
        self.inner.fields().iter().map(|f| f.key).collect()
    }
}

/// The `KEY=VALUE` of `--set`, with the value written so that it parses back to the same `f64`.
fn assignment(key: &str, value: f64) -> String {
    format!("{key}={value:?}")
}
