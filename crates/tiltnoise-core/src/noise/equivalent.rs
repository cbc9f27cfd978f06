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
//! N m), all one-sided PSDs. A budget carries `|R_o|^2` as the [`Calibration`] of the
//! observable (not as a noise term), in the spirit of pygwinc's `Calibration`: applied to a
//! budget by [`referred_terms`], it turns a displacement or angle budget into an acceleration or
//! torque budget.

use super::{Budget, Component};
use crate::error::TfError;
use crate::model::{ForceInput, Model, Observable};
use crate::tf::{self, Input, Request};

/// The calibration of an observable's budget to its equivalent input (see the module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Calibration {
    /// The equivalent input (`F_b.x` for X, `M_b.z` for phi and phi_a).
    pub input: ForceInput,
    /// `|R_o|^2` on the budget's grid ((observable unit / input unit)^2).
    pub response_psd: Vec<f64>,
}

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
    /// Every model term (not `measured` or `residual`, which are not referred) in budget order,
    /// then the total: `(component, S_o / |R_o|^2)`, one-sided PSD in unit^2/Hz.
    pub terms: Vec<(Component, Vec<f64>)>,
}

/// The terms of `ob` referred to its equivalent input, if it has one and the budget carries
/// its [`Calibration`] ([`add_equivalent_response`]).
pub fn referred_terms(ob: &super::ObservableBudget) -> Option<Referred<'_>> {
    let (_, unit, quantity) = equivalent_quantity(ob.observable)?;
    let calibration = ob.calibration.as_ref()?;
    let response = &calibration.response_psd;
    let refer = |psd: &[f64]| psd.iter().zip(response).map(|(p, r)| p / r).collect();
    let mut terms: Vec<(Component, Vec<f64>)> = ob
        .terms
        .iter()
        .filter(|t| t.kind.is_model())
        .map(|t| (Component::Term(t.kind.clone()), refer(&t.psd)))
        .collect();
    terms.push((Component::Total, refer(&ob.total())));
    Some(Referred {
        input: calibration.input.name(),
        unit,
        quantity,
        response_psd: response,
        terms,
    })
}

/// Attaches the [`Calibration`] (`|R_o|^2`, see the module docs) to every observable of
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
        let response_psd = (0..h.freqs_hz.len())
            .map(|k| (h.get(k, 0, 0) * factor).norm_sqr())
            .collect();
        ob.calibration = Some(Calibration {
            input,
            response_psd,
        });
    }
    Ok(())
}
