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
use crate::tf::{self, Input, Request};

/// Prefix of the budget term that carries `|R_o|^2` (see the module docs).
pub const RESPONSE_PREFIX: &str = "response.";

/// The equivalent input of an observable: `(input, factor, unit, description)`, with
/// `R_o = factor * H_o,input`. `None` for observables without one (Y, Z, theta, eta).
pub fn equivalent_input(
    model: &Model,
    o: Observable,
) -> Option<(ForceInput, f64, &'static str, &'static str)> {
    let (input, unit, what) = equivalent_quantity(o)?;
    let factor = match o {
        Observable::X => model.params().mass.m_b_kg,
        _ => 1.0,
    };
    Some((input, factor, unit, what))
}

/// The equivalent input of an observable, its unit and a description (see the module docs).
fn equivalent_quantity(o: Observable) -> Option<(ForceInput, &'static str, &'static str)> {
    match o {
        Observable::X => Some((
            ForceInput::from_name("F_b.x").expect("F_b.x is a force input"),
            "m s^-2",
            "acceleration of the test mass along x (F_b.x / m_b)",
        )),
        Observable::Phi | Observable::PhiA => Some((
            ForceInput::from_name("M_b.z").expect("M_b.z is a force input"),
            "N m",
            "torque on the test mass about z (M_b.z)",
        )),
        _ => None,
    }
}

/// An observable's noise terms referred to its equivalent input: what the budget files store
/// (HDF5 `/<OBS>/equivalent`, CSV `OBS.equivalent.TERM` columns).
pub struct Referred<'a> {
    /// The input's name (`F_b.x`, `M_b.z`).
    pub input: &'static str,
    /// Unit of the input (`m s^-2`, `N m`); the PSDs are in unit^2/Hz.
    pub unit: &'static str,
    /// What the input is.
    pub quantity: &'static str,
    /// `|R_o|^2` at each frequency ((observable unit / input unit)^2).
    pub response_psd: &'a [f64],
    /// Every noise term but `measured` and `residual` (which are not referred), in budget
    /// order: `(name, S_o / |R_o|^2)`, one-sided PSD in unit^2/Hz.
    pub terms: Vec<(&'a str, Vec<f64>)>,
}

/// The terms of `ob` referred to its equivalent input, if it has one and the budget carries
/// its response (the `response.<input>` term of [`add_equivalent_response`]).
pub fn referred_terms(ob: &super::ObservableBudget) -> Option<Referred<'_>> {
    let (input, unit, quantity) = equivalent_quantity(ob.observable)?;
    let response = ob
        .terms
        .iter()
        .find(|t| t.name == format!("{RESPONSE_PREFIX}{}", input.name()))?;
    let terms = ob
        .terms
        .iter()
        .filter(|t| !is_response(&t.name) && t.name != "measured" && t.name != "residual")
        .map(|t| {
            let psd = t.psd.iter().zip(&response.psd).map(|(p, r)| p / r);
            (t.name.as_str(), psd.collect())
        })
        .collect();
    Some(Referred {
        input: input.name(),
        unit,
        quantity,
        response_psd: &response.psd,
        terms,
    })
}

/// Adds the `response.<input>` term (`|R_o|^2`, see the module docs) to every observable of
/// `budget` that has an equivalent input, evaluated with the method the planner picks.
pub fn add_equivalent_response(budget: &mut Budget, model: &Model) -> Result<(), TfError> {
    for ob in budget.observables.iter_mut() {
        let Some((input, factor, _, _)) = equivalent_input(model, ob.observable) else {
            continue;
        };
        let request = Request {
            outputs: vec![ob.observable],
            inputs: vec![Input::Force(input)],
        };
        let (plan, _) = tf::plan_auto(model, &tf::Scene::over_grid(request, &budget.freqs_hz))?;
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
