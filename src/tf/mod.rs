//! Transfer functions from inputs (tilt angles, forces, torques) to observables.
//!
//! `H(w) = C (K_c - w^2 M)^-1 G(w)`, with `K_c` the complex stiffness (loss angles), `G` the
//! tilt forcing `G0 + w^2 G2` (columns per tilt angle, see [`crate::model::tilt`]) or the
//! zeroth-order force matrix (columns per force/torque component). Units of an entry: the
//! observable's unit per the input's unit (m/rad, rad/rad, m/N, rad/(N m), ...). The response
//! is the complex amplitude for `e^{+i w t}` time dependence.
//!
//! Methods are plain data ([`Method`]); [`plan`] builds a [`TransferFunction`] that does the
//! per-model work once and then evaluates cheaply at many frequencies
//! (RustFFT's recipe/plan pattern). The direct LU method is the oracle for the others.

mod direct;

use crate::error::TfError;
use crate::model::{ForceInput, Model, Observable, TiltAxis};
use num_complex::Complex64;

pub use direct::{Direct, SINGULAR_RCOND};

/// An input of a transfer function.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Input {
    /// A floor tilt angle (rad).
    Tilt(TiltAxis),
    /// A force (N) or torque (N m) component on one of the bodies.
    Force(ForceInput),
}

impl Input {
    /// Every tilt input, in order theta_t, eta_t, phi_t.
    pub fn all_tilts() -> Vec<Input> {
        TiltAxis::ALL.into_iter().map(Input::Tilt).collect()
    }

    /// Name used in files and on the command line (`theta_t`, `F_b.x`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Input::Tilt(t) => t.name(),
            Input::Force(f) => f.name(),
        }
    }

    /// SI unit of the input.
    pub fn unit(self) -> &'static str {
        match self {
            Input::Tilt(t) => t.unit(),
            Input::Force(f) => f.unit(),
        }
    }

    /// Parses a name as produced by [`Input::name`].
    pub fn from_name(name: &str) -> Option<Input> {
        TiltAxis::ALL
            .into_iter()
            .find(|t| t.name() == name)
            .map(Input::Tilt)
            .or_else(|| ForceInput::from_name(name).map(Input::Force))
    }
}

/// Evaluation methods. Plain data: the planner turns one into a [`TransferFunction`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// Per-frequency LU of the full 8x8 dynamic stiffness, with equilibration and a condition
    /// check. Slow and obviously correct: the oracle for the other methods.
    Direct,
}

impl Method {
    /// Name used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            Method::Direct => "direct",
        }
    }
}

/// What to compute: which observables respond to which inputs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Request {
    /// Rows of the transfer matrix.
    pub outputs: Vec<Observable>,
    /// Columns of the transfer matrix.
    pub inputs: Vec<Input>,
}

impl Request {
    /// All 7 observables from the 3 tilt angles.
    pub fn all_tilt() -> Request {
        Request {
            outputs: Observable::ALL.to_vec(),
            inputs: Input::all_tilts(),
        }
    }
}

/// A planned transfer function: evaluates the `outputs x inputs` matrix at one frequency.
pub trait TransferFunction: Send + Sync {
    /// The method behind this plan.
    fn method(&self) -> Method;

    /// What the plan computes.
    fn request(&self) -> &Request;

    /// Writes `H(f)` row-major (`out[o * n_inputs + i]`) into `out`, whose length must be
    /// `outputs.len() * inputs.len()`. `freq_hz` must be finite and >= 0.
    fn eval_into(&self, freq_hz: f64, out: &mut [Complex64]) -> Result<(), TfError>;

    /// Allocating convenience wrapper around [`TransferFunction::eval_into`].
    fn eval(&self, freq_hz: f64) -> Result<Vec<Complex64>, TfError> {
        let r = self.request();
        let mut out = vec![Complex64::new(0.0, 0.0); r.outputs.len() * r.inputs.len()];
        self.eval_into(freq_hz, &mut out)?;
        Ok(out)
    }
}

/// Builds the plan for `method` (factorizations and forcing matrices prepared once).
pub fn plan(model: &Model, request: &Request, method: Method) -> Box<dyn TransferFunction> {
    match method {
        Method::Direct => Box::new(Direct::new(model, request.clone())),
    }
}

/// Transfer functions on a frequency grid.
#[derive(Debug, Clone, PartialEq)]
pub struct TransferMatrix {
    /// Frequencies (Hz).
    pub freqs_hz: Vec<f64>,
    /// Row labels.
    pub outputs: Vec<Observable>,
    /// Column labels.
    pub inputs: Vec<Input>,
    /// Values, `[freq][output][input]` row-major; see [`TransferMatrix::get`].
    pub values: Vec<Complex64>,
    /// The method that produced the values.
    pub method: Method,
}

impl TransferMatrix {
    /// `H_{o,i}(f_k)`.
    pub fn get(&self, k: usize, o: usize, i: usize) -> Complex64 {
        let (no, ni) = (self.outputs.len(), self.inputs.len());
        self.values[(k * no + o) * ni + i]
    }

    /// Unit of entry (o, i): output unit per input unit.
    pub fn unit(&self, o: usize, i: usize) -> String {
        let input = self.inputs[i].unit();
        if input.contains(' ') {
            format!("{}/({input})", self.outputs[o].unit())
        } else {
            format!("{}/{input}", self.outputs[o].unit())
        }
    }

    /// Position of an observable among the rows.
    pub fn output_index(&self, o: Observable) -> Option<usize> {
        self.outputs.iter().position(|&x| x == o)
    }

    /// Position of an input among the columns.
    pub fn input_index(&self, i: Input) -> Option<usize> {
        self.inputs.iter().position(|&x| x == i)
    }
}

/// Evaluates a plan on every frequency of a grid. Stops at the first singular frequency.
pub fn evaluate(tf: &dyn TransferFunction, freqs_hz: &[f64]) -> Result<TransferMatrix, TfError> {
    let r = tf.request();
    let block = r.outputs.len() * r.inputs.len();
    let mut values = vec![Complex64::new(0.0, 0.0); block * freqs_hz.len()];
    for (&f, out) in freqs_hz.iter().zip(values.chunks_exact_mut(block.max(1))) {
        tf.eval_into(f, out)?;
    }
    Ok(TransferMatrix {
        freqs_hz: freqs_hz.to_vec(),
        outputs: r.outputs.clone(),
        inputs: r.inputs.clone(),
        values,
        method: tf.method(),
    })
}
