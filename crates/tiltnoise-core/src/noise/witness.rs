//! The own noise of a witness instrument (a tiltmeter recording a floor input of the model):
//! a one-sided ASD in the input's unit per sqrt(Hz), white or a spectrum on its own frequency
//! points, with its relative uncertainty (1 sigma of the ASD). `subtract` weights its
//! prediction and its fit with it; a budget shows it projected through the model,
//! `|H_o,in|^2 S_nn` ([`add_witness_noise`]), beside the tilt term and not in the total: the
//! tilt term, computed from the witness record, already contains it.

use super::{Budget, GivenAsdError, NoiseTerm, TermKind};
use crate::error::TfError;
use crate::model::{Input, Model, Observable};
use crate::noise::GivenAsd;
use crate::option_key::{Message, OptionKey};
use crate::tf::{self, Request};

/// Largest relative uncertainty of a witness noise level accepted (1 sigma of the ASD).
pub const MAX_NOISE_REL: f64 = 1.0;

/// A noise level: white, or a spectrum read log-log between its points and never beyond.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum NoiseLevel {
    /// White, one-sided ASD (unit/sqrt(Hz)).
    White(f64),
    /// A spectrum (unit/sqrt(Hz)).
    Curve(GivenAsd),
}

/// The noise of one witness input.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WitnessNoise {
    /// The model input the witness records.
    pub input: Input,
    /// Its noise.
    pub level: NoiseLevel,
    /// Relative uncertainty (1 sigma) of the ASD; 0 when exact.
    pub rel: f64,
}

impl WitnessNoise {
    /// Checks the level and its uncertainty; `what` names the option in the message.
    ///
    /// # Errors
    ///
    /// A white level that is not finite and >= 0, or an uncertainty outside
    /// `[0, MAX_NOISE_REL]`, naming the input and the value.
    pub fn check(&self, what: OptionKey) -> Result<(), Message> {
        match self.problem() {
            Some(problem) => Err(crate::message!("{what} {}: {problem}", self.input.name())),
            None => Ok(()),
        }
    }

    /// What is wrong with the level or its uncertainty ([`WitnessNoise::check`] without the
    /// option and the input), if anything.
    pub fn problem(&self) -> Option<String> {
        if let NoiseLevel::White(asd) = self.level {
            if !crate::limits::ASDS.admits(asd) {
                return Some(format!(
                    "the ASD {} {}/sqrt(Hz) is not allowed: must be {} (see docs/limits.md)",
                    crate::error::Num(asd),
                    self.input.unit(),
                    crate::limits::ASDS.allowed(&format!("{}/sqrt(Hz)", self.input.unit()))
                ));
            }
        }
        if !(self.rel.is_finite() && (0.0..=MAX_NOISE_REL).contains(&self.rel)) {
            return Some(format!(
                "the relative uncertainty {} is not allowed: must be finite, in \
                 [0, {MAX_NOISE_REL}] (1 sigma of the ASD, e.g. 0.1 for 10 %)",
                self.rel
            ));
        }
        None
    }

    /// The one-sided PSD (unit^2/Hz) on `freqs_hz`.
    ///
    /// # Errors
    ///
    /// A spectrum that does not cover `[freqs_hz[0], freqs_hz[last]]`.
    pub fn psd_on(&self, freqs_hz: &[f64]) -> Result<Vec<f64>, String> {
        match &self.level {
            NoiseLevel::White(asd) => Ok(vec![asd * asd; freqs_hz.len()]),
            NoiseLevel::Curve(curve) => {
                let (lo, hi) = (freqs_hz[0], freqs_hz[freqs_hz.len() - 1]);
                let (a, b) = curve.band_hz();
                if lo < a || hi > b {
                    return Err(format!(
                        "{}: the spectrum covers {a:e} .. {b:e} Hz, the band it is needed in is \
                         {lo:e} .. {hi:e} Hz; a given spectrum is never extrapolated: give one \
                         that covers the band",
                        curve.origin()
                    ));
                }
                Ok(curve.psd_on(freqs_hz))
            }
        }
    }
}

/// Refuses a witness noise spectrum that does not cover the band `[lo, hi]` (Hz).
pub fn check_witness_noise(noise: &[WitnessNoise], lo: f64, hi: f64) -> Result<(), GivenAsdError> {
    noise.iter().try_for_each(|x| match &x.level {
        NoiseLevel::White(_) => Ok(()),
        NoiseLevel::Curve(c) => c.check_covers(lo, hi),
    })
}

/// Adds the witness noise projected through the model, `witness_noise = sum_in |H_o,in|^2
/// S_nn,in` (the instruments' noises independent), to every observable of `budget`, after the
/// terms already there; nothing without witness noise. Not part of the total.
///
/// # Errors
///
/// A spectrum that does not cover the budget's band; transfer functions that cannot be
/// evaluated.
pub fn add_witness_noise(
    budget: &mut Budget,
    model: &Model,
    noise: &[WitnessNoise],
) -> Result<(), WitnessNoiseError> {
    if noise.is_empty() {
        return Ok(());
    }
    let grid = budget.freqs_hz.clone();
    check_witness_noise(noise, grid[0], grid[grid.len() - 1])
        .map_err(WitnessNoiseError::Coverage)?;
    let outputs: Vec<Observable> = budget.observables.iter().map(|b| b.observable).collect();
    let request = Request {
        outputs,
        inputs: noise.iter().map(|x| x.input).collect(),
    };
    let (plan, _) = tf::plan_auto(model, &tf::Scene::over_grid(request, &grid))?;
    let h = tf::evaluate(plan.as_ref(), &grid)?;
    let psd: Vec<Vec<f64>> = noise
        .iter()
        .map(|x| x.psd_on(&grid).expect("covers the band: checked above"))
        .collect();
    for (o, ob) in budget.observables.iter_mut().enumerate() {
        let total = (0..grid.len())
            .map(|k| {
                psd.iter()
                    .enumerate()
                    .map(|(i, p)| h.get(k, o, i).norm_sqr() * p[k])
                    .sum()
            })
            .collect();
        ob.terms.push(NoiseTerm {
            kind: TermKind::WitnessNoise,
            psd: total,
        });
    }
    Ok(())
}

/// Why the witness-noise term cannot be added.
#[derive(Debug, thiserror::Error)]
pub enum WitnessNoiseError {
    /// A spectrum that does not cover the budget's band.
    #[error("{0}")]
    Coverage(GivenAsdError),
    /// The transfer functions could not be evaluated.
    #[error(transparent)]
    Tf(#[from] TfError),
}
