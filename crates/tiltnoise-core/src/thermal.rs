//! Thermal noise of the dissipative elements from the fluctuation-dissipation theorem.
//!
//! Every dissipative element `e` of the model ([`Model::dissipative_elements`]) is a source of
//! a fluctuating generalized force with the **one-sided** PSD matrix
//!
//! ```text
//! S_Q,e(f) = 4 k_B T Im(K_e) / w      (structural, 1/f)      or      4 k_B T C_e  (viscous, white)
//! ```
//!
//! (N^2/Hz, (N m)^2/Hz or mixed, by coordinate pair), `w = 2 pi f`, with the element's imaginary
//! stiffness `Im(K_e)` or damping matrix `C_e`. Propagated through the dynamic compliance
//! `H = (K_c + i w C - w^2 M)^-1` and the observation row `c` of an observable,
//! `S_x,e = c H S_Q,e H^H c^T`, one-sided, in (observable unit)^2/Hz. The elements are
//! independent, so their PSDs add.
//!
//! # Evaluation with relative accuracy
//!
//! The FDT in its textbook form, `S_x = 4 k_B T |Im H_xx| / w` with `H_xx = c^T H c` (the
//! response of x to its own conjugate force), takes the imaginary part of a complex number
//! whose real part is larger by `1 / phi`: it loses `log10(1/phi)` digits and gives no split
//! per element. Here every element's matrix is kept as a sum of rank-one terms
//! `sum_j w_j v_j v_j^T` ([`crate::model::DissipativeElement`]), and since the dynamic
//! stiffness `D` is complex symmetric, `c^T H v_j = y^T v_j` with `D y = c`:
//!
//! ```text
//! S_x,e = (4 k_B T / w or 4 k_B T) sum_j w_j |y^T v_j|^2,
//! ```
//!
//! a sum of non-negative terms, each with the relative accuracy of the solve. The solve is the
//! direct method's equilibrated 8x8 LU ([`crate::tf::Direct`]): normwise relative error
//! `n eps cond(D_s)` (n = 8) on `y`, where `cond(D_s)` of the equilibrated matrix measures the
//! closeness to a resonance (at most `1 / SINGULAR_RCOND`; 1e2 .. 1e4 on a budget grid away
//! from the modes, the inverse of the modal loss angle on a damped mode). The sum of the
//! elements equals `4 k_B T |Im H_xx| / w` exactly (`Im D^-1 = -D^-1 Im(D) D^-H`), which
//! the `tiltnoise` package's `tests/it/thermal.rs` checks.
//!
//! Pure numerics: depends on `model` and `tf`.

use crate::error::{FreqError, TfError};
use crate::model::{DampingKind, Model, Observable};
use crate::tf::{Direct, Request};
use crate::units::angular;
use nalgebra::SVector;
use num_complex::Complex64;

/// Boltzmann constant (J/K), exact in the 2019 SI.
pub const BOLTZMANN_J_PER_K: f64 = 1.380649e-23;

/// The thermal noise of one element in every observable.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementNoise {
    /// The element's name (`torsion_b`, `swing_a`, `bouncing_b_viscous`, ...).
    pub name: String,
    /// Structural or viscous.
    pub kind: DampingKind,
    /// One-sided PSD per observable, `psd[o][k]` at `freqs_hz[k]`, (observable unit)^2/Hz.
    pub psd: Vec<Vec<f64>>,
}

/// Thermal noise of every dissipative element on a frequency grid.
#[derive(Debug, Clone, PartialEq)]
pub struct ThermalNoise {
    /// Frequencies (Hz), all > 0.
    pub freqs_hz: Vec<f64>,
    /// The observables, in the order of [`ElementNoise::psd`].
    pub outputs: Vec<Observable>,
    /// Temperature (K).
    pub temperature_k: f64,
    /// One entry per dissipative element; empty for an undamped model.
    pub elements: Vec<ElementNoise>,
}

impl ThermalNoise {
    /// Sum over the elements: the thermal PSD of output `o` (position in `outputs`),
    /// one-sided, (observable unit)^2/Hz.
    pub fn total_psd(&self, o: usize) -> Vec<f64> {
        (0..self.freqs_hz.len())
            .map(|k| self.elements.iter().map(|e| e.psd[o][k]).sum())
            .collect()
    }
}

/// The generalized-force PSD coefficient of an element kind at `w`: `4 k_B T / w`
/// (structural, multiplies `Im(K_e)`) or `4 k_B T` (viscous, multiplies `C_e`); one-sided.
pub fn force_psd_coefficient(kind: DampingKind, temperature_k: f64, omega_rad_s: f64) -> f64 {
    let four_kt = 4.0 * BOLTZMANN_J_PER_K * temperature_k;
    match kind {
        DampingKind::Structural => four_kt / omega_rad_s,
        DampingKind::Viscous => four_kt,
    }
}

/// Thermal noise of every dissipative element of `model` in `outputs` at `freqs_hz`
/// (each > 0 and finite), at the model's temperature (`environment.temperature_k`).
///
/// # Errors
/// [`TfError::Freq`] for a frequency that is not finite and > 0 (structural thermal noise
/// diverges as 1/f at f = 0); [`TfError::Singular`] on an undamped resonance.
pub fn thermal_noise(
    model: &Model,
    outputs: &[Observable],
    freqs_hz: &[f64],
) -> Result<ThermalNoise, TfError> {
    let temperature_k = model.params().environment.temperature_k;
    let elements = model.dissipative_elements();
    let n_f = freqs_hz.len();
    let mut noise: Vec<ElementNoise> = elements
        .iter()
        .map(|e| ElementNoise {
            name: e.name.clone(),
            kind: e.kind,
            psd: vec![vec![0.0; n_f]; outputs.len()],
        })
        .collect();
    if !elements.is_empty() {
        let direct = Direct::new(
            model,
            Request {
                outputs: Vec::new(),
                inputs: Vec::new(),
            },
        );
        let rows: Vec<SVector<Complex64, 8>> = outputs
            .iter()
            .map(|o| {
                model
                    .observation()
                    .row(o.index())
                    .transpose()
                    .map(Complex64::from)
            })
            .collect();
        let mut y = rows.clone();
        for (k, &f) in freqs_hz.iter().enumerate() {
            if !(f.is_finite() && f > 0.0) {
                return Err(FreqError::Spec {
                    origin: format!("thermal noise at {f} Hz").into(),
                    message: "frequency must be finite and > 0 (structural thermal noise \
                              diverges as 1/f at 0 Hz)"
                        .into(),
                }
                .into());
            }
            y.clone_from_slice(&rows);
            direct.solve_generalized(f, &mut y)?;
            let w = angular(f);
            for (element, out) in elements.iter().zip(noise.iter_mut()) {
                let coef = force_psd_coefficient(element.kind, temperature_k, w);
                for (o, y_o) in y.iter().enumerate() {
                    let sum: f64 = element
                        .terms
                        .iter()
                        .map(|(weight, v)| {
                            let a: Complex64 = (0..8).map(|i| y_o[i] * v[i]).sum();
                            weight * a.norm_sqr()
                        })
                        .sum();
                    out.psd[o][k] = coef * sum;
                }
            }
        }
    }
    Ok(ThermalNoise {
        freqs_hz: freqs_hz.to_vec(),
        outputs: outputs.to_vec(),
        temperature_k,
        elements: noise,
    })
}

/// `H_xx = c^T (K_c + i w C - w^2 M)^-1 c`: the response of observable `o` to its own
/// conjugate generalized force `c^T F` (unit: observable unit per conjugate force, e.g. m/N for
/// X), for the FDT identity `sum_e S_x,e = 4 k_B T |Im H_xx| / w`.
pub fn conjugate_response(
    model: &Model,
    o: Observable,
    freq_hz: f64,
) -> Result<Complex64, TfError> {
    let direct = Direct::new(
        model,
        Request {
            outputs: Vec::new(),
            inputs: Vec::new(),
        },
    );
    let c: SVector<Complex64, 8> = model
        .observation()
        .row(o.index())
        .transpose()
        .map(Complex64::from);
    let mut y = [c];
    direct.solve_generalized(freq_hz, &mut y)?;
    Ok((0..8).map(|i| y[0][i] * c[i]).sum())
}
