//! What a transfer function is asked for: its inputs (floor tilt and translation, forces,
//! torques) and its outputs (observables). Plain data of the model layer, shared by every evaluator (the
//! transfer-function methods and the double-double reference).

use super::{ForceInput, Observable, TiltAxis, TranslationAxis};

/// An input of a transfer function.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Input {
    /// A floor tilt angle (rad).
    Tilt(TiltAxis),
    /// A floor translation (m).
    Translation(TranslationAxis),
    /// A force (N) or torque (N m) component on one of the bodies.
    Force(ForceInput),
}

impl Input {
    /// Every tilt input, in order theta_t, eta_t, phi_t.
    pub fn all_tilts() -> Vec<Input> {
        TiltAxis::ALL.into_iter().map(Input::Tilt).collect()
    }

    /// Every floor translation, in order x_t, y_t, z_t.
    pub fn all_translations() -> Vec<Input> {
        TranslationAxis::ALL
            .into_iter()
            .map(Input::Translation)
            .collect()
    }

    /// The floor's six motions: the tilt angles, then the translations.
    pub fn all_ground() -> Vec<Input> {
        let mut all = Input::all_tilts();
        all.extend(Input::all_translations());
        all
    }

    /// True for the floor's motions (tilt and translation), false for forces and torques.
    pub fn is_ground(self) -> bool {
        !matches!(self, Input::Force(_))
    }

    /// Name used in files and on the command line (`theta_t`, `x_t`, `F_b.x`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Input::Tilt(t) => t.name(),
            Input::Translation(t) => t.name(),
            Input::Force(f) => f.name(),
        }
    }

    /// SI unit of the input.
    pub fn unit(self) -> &'static str {
        match self {
            Input::Tilt(t) => t.unit(),
            Input::Translation(t) => t.unit(),
            Input::Force(f) => f.unit(),
        }
    }

    /// Parses a name as produced by [`Input::name`].
    pub fn from_name(name: &str) -> Option<Input> {
        TiltAxis::ALL
            .into_iter()
            .find(|t| t.name() == name)
            .map(Input::Tilt)
            .or_else(|| {
                TranslationAxis::ALL
                    .into_iter()
                    .find(|t| t.name() == name)
                    .map(Input::Translation)
            })
            .or_else(|| ForceInput::from_name(name).map(Input::Force))
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

impl Request {
    /// Index of the entry `output` per `input` in a row-major `outputs x inputs` block (the
    /// layout of [`crate::tf::TransferFunction::eval`]), or `None` if the request does not
    /// contain both.
    pub fn index(&self, output: Observable, input: Input) -> Option<usize> {
        let o = self.outputs.iter().position(|&x| x == output)?;
        let i = self.inputs.iter().position(|&x| x == input)?;
        Some(o * self.inputs.len() + i)
    }
}
