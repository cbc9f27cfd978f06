//! User-named noise terms: an ASD of an observable (a measured magnetic or temperature
//! coupling, for example), or the ASD of an input of the model (a force, a torque, a tilt
//! angle) propagated through the transfer functions, `S_o = |H_o,in|^2 S_in`. Independent of
//! each other and of the other noises: they add in power, as `user`, to the total, each one
//! kept as `user.<name>`.

use super::{Budget, GivenAsd, GivenAsdError, NoiseTerm, TermKind};
use crate::error::TfError;
use crate::model::{Input, Model, Observable};
use crate::tf::{self, Request};

/// What a user term's ASD is of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum UserSource {
    /// The observable itself (its unit/sqrt(Hz)); a term of that observable only.
    Observable(Observable),
    /// An input of the model (N, N m or rad per sqrt(Hz)); a term of every budgeted observable.
    Input(Input),
}

impl UserSource {
    /// The observable's or the input's name.
    pub fn name(self) -> &'static str {
        match self {
            UserSource::Observable(o) => o.name(),
            UserSource::Input(i) => i.name(),
        }
    }

    /// Unit of the ASD: `m/sqrt(Hz)`, `N m/sqrt(Hz)`, ...
    pub fn asd_unit(self) -> String {
        let unit = match self {
            UserSource::Observable(o) => o.unit(),
            UserSource::Input(i) => i.unit(),
        };
        format!("{unit}/sqrt(Hz)")
    }
}

/// A user-named term: its name (a file key, [`super::is_term_name`]), what its ASD is of, and
/// the ASD.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct UserTerm {
    /// The name, stored as `user.<name>`.
    pub name: String,
    /// What the ASD is of.
    pub source: UserSource,
    /// One-sided ASD on its own points.
    pub asd: GivenAsd,
}

/// Why user terms cannot be added.
#[derive(Debug, thiserror::Error)]
pub enum UserTermError {
    /// A given spectrum that does not cover the budget's band.
    #[error("{0}")]
    Coverage(GivenAsdError),
    /// A term of an observable that is not budgeted.
    #[error("user term `{name}` is an ASD of {observable}, which is not budgeted (budgeted: {budgeted})")]
    NotBudgeted {
        /// The term's name.
        name: String,
        /// Its observable.
        observable: &'static str,
        /// The budgeted observables, comma-separated.
        budgeted: String,
    },
    /// The transfer functions of an input could not be evaluated.
    #[error(transparent)]
    Tf(#[from] TfError),
}

/// Refuses user terms whose spectrum does not cover the band `[lo, hi]` (Hz), or that are ASDs
/// of an observable not in `outputs`: what [`add_user_terms`] checks, for a caller that knows
/// the band before computing it.
pub fn check_user_terms(
    terms: &[UserTerm],
    outputs: &[Observable],
    lo: f64,
    hi: f64,
) -> Result<(), UserTermError> {
    for t in terms {
        t.asd
            .check_covers(lo, hi)
            .map_err(UserTermError::Coverage)?;
        if let UserSource::Observable(o) = t.source {
            if !outputs.contains(&o) {
                return Err(UserTermError::NotBudgeted {
                    name: t.name.clone(),
                    observable: o.name(),
                    budgeted: outputs
                        .iter()
                        .map(|o| o.name())
                        .collect::<Vec<_>>()
                        .join(", "),
                });
            }
        }
    }
    Ok(())
}

/// Adds the user terms to every observable of `budget` they apply to: `user` (their sum) and
/// `user.<name>` each, after the terms already there. Refuses a spectrum that does not cover the
/// budget's band and a term of an observable that is not budgeted. The transfer functions of the
/// inputs are evaluated on the budget's grid with the method the planner picks.
pub fn add_user_terms(
    budget: &mut Budget,
    model: &Model,
    terms: &[UserTerm],
) -> Result<(), UserTermError> {
    if terms.is_empty() {
        return Ok(());
    }
    let grid = budget.freqs_hz.clone();
    let outputs: Vec<Observable> = budget.observables.iter().map(|b| b.observable).collect();
    check_user_terms(terms, &outputs, grid[0], grid[grid.len() - 1])?;
    let mut inputs: Vec<Input> = Vec::new();
    for t in terms {
        if let UserSource::Input(i) = t.source {
            if !inputs.contains(&i) {
                inputs.push(i);
            }
        }
    }
    let tf = if inputs.is_empty() {
        None
    } else {
        let request = Request {
            outputs: outputs.clone(),
            inputs,
        };
        let (plan, _) = tf::plan_auto(model, &tf::Scene::over_grid(request, &grid))?;
        Some(tf::evaluate(plan.as_ref(), &grid)?)
    };
    for (o, ob) in budget.observables.iter_mut().enumerate() {
        let mut named = Vec::new();
        for t in terms {
            let given = t.asd.psd_on(&grid);
            let psd = match t.source {
                UserSource::Observable(x) if x == ob.observable => given,
                UserSource::Observable(_) => continue,
                UserSource::Input(i) => {
                    let h = tf.as_ref().expect("evaluated for every input term");
                    let col = h.input_index(i).expect("requested above");
                    (0..grid.len())
                        .map(|k| h.get(k, o, col).norm_sqr() * given[k])
                        .collect()
                }
            };
            named.push(NoiseTerm {
                kind: TermKind::UserNamed(t.name.clone()),
                psd,
            });
        }
        if named.is_empty() {
            continue;
        }
        let mut sum = vec![0.0; grid.len()];
        for t in &named {
            for (s, p) in sum.iter_mut().zip(&t.psd) {
                *s += p;
            }
        }
        ob.terms.push(NoiseTerm {
            kind: TermKind::User,
            psd: sum,
        });
        ob.terms.extend(named);
    }
    Ok(())
}
