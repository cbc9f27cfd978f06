//! Equivalent input noise: a displacement or angle PSD referred back to the actuation input
//! of the test mass, the figure of merit of free-fall test benches.
//!
//! | observable | equivalent input | unit of the ASD |
//! |---|---|---|
//! | X | acceleration of the test mass along x, `a = F_b.x / m_b` | m s^-2/sqrt(Hz) |
//! | phi, phi_a | torque on the test mass about z, `M_b.z` | N m/sqrt(Hz) |
//!
//! `S_equiv = S_o / |R_o|^2` with `R_X = m_b H_X,F_b.x` (the response of X to an acceleration
//! of the test mass, m per m s^-2) and `R_phi = H_phi,M_b.z`, `R_phi_a = H_phi_a,M_b.z` (rad per
//! N m), all one-sided PSDs. The responses are stored in a budget as a term named
//! `response.<input>` (e.g. `response.F_b.x`, just before `total`) whose "PSD" is `|R_o|^2`:
//! not a noise, excluded from `total`, from the CSV columns and from the drawn traces.

use super::Budget;
use crate::error::TfError;
use crate::model::{ForceInput, Model, Observable};
use crate::tf::{self, Input, Method, Request};

/// Prefix of the budget term that carries `|R_o|^2` (see the module docs).
pub const RESPONSE_PREFIX: &str = "response.";

/// The equivalent input of an observable: `(input, factor, unit, description)`, with
/// `R_o = factor * H_o,input`. `None` for observables without one (Y, Z, theta, eta).
pub fn equivalent_input(
    model: &Model,
    o: Observable,
) -> Option<(ForceInput, f64, &'static str, &'static str)> {
    let m_b = model.params().mass.m_b_kg;
    match o {
        Observable::X => Some((
            ForceInput::from_name("F_b.x").expect("F_b.x is a force input"),
            m_b,
            "m s^-2",
            "acceleration of the test mass along x (F_b.x / m_b)",
        )),
        Observable::Phi | Observable::PhiA => Some((
            ForceInput::from_name("M_b.z").expect("M_b.z is a force input"),
            1.0,
            "N m",
            "torque on the test mass about z (M_b.z)",
        )),
        _ => None,
    }
}

/// Adds the `response.<input>` term (`|R_o|^2`, see the module docs) to every observable of
/// `budget` that has an equivalent input, evaluated with the split method (full relative
/// accuracy on force entries).
pub fn add_equivalent_response(budget: &mut Budget, model: &Model) -> Result<(), TfError> {
    for ob in budget.observables.iter_mut() {
        let Some((input, factor, _, _)) = equivalent_input(model, ob.observable) else {
            continue;
        };
        let request = Request {
            outputs: vec![ob.observable],
            inputs: vec![Input::Force(input)],
        };
        let plan = tf::plan(model, &request, Method::Split).expect("split plans every request");
        let h = tf::evaluate(plan.as_ref(), &budget.freqs_hz)?;
        let psd = (0..h.freqs_hz.len())
            .map(|k| (h.get(k, 0, 0) * factor).norm_sqr())
            .collect();
        // Before `total`, which stays last.
        let at = ob
            .terms
            .iter()
            .position(|t| t.name == "total")
            .unwrap_or(ob.terms.len());
        ob.terms.insert(
            at,
            super::NoiseTerm {
                name: format!("{RESPONSE_PREFIX}{}", input.name()),
                psd,
            },
        );
    }
    Ok(())
}

/// True for a `response.<input>` term (not a noise).
pub fn is_response(name: &str) -> bool {
    name.starts_with(RESPONSE_PREFIX)
}
