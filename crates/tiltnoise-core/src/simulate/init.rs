//! A simulation run as a user asks for it, checked once for every front end (the command
//! line's `tiltnoise simulate` and the Python package's `Model.simulate`): the sampling
//! (`duration`, `step`, the Welch segment of the ASDs) and the initial state (the kick test,
//! given coordinates and rates, or equal energy in every mode), with messages that name the
//! option as the caller spells it ([`OptionKey`]).

use super::{check_initial_state, check_samples, equal_energy_init, kick_x, InitialState};
use crate::error::{Num, Shown};
use crate::limits::MIN_SAMPLE;
use crate::model::{Coord, Model, Observable};
use crate::option_key::OptionKey;
use crate::options::OptionError;
use crate::repeats::{list_entries, refuse_repeated_keys};
use std::fmt::Write as _;

/// The smallest Welch segment of a simulation's ASDs (samples).
pub const MIN_SIM_NPERSEG: usize = 16;

/// How the motion starts.
#[derive(Debug, Clone, PartialEq)]
pub enum Excitation {
    /// The paper's kick test: the test mass displaced statically along X by `x_m` metres (a
    /// static force on the test mass along x), released from rest ([`kick_x`]).
    KickX {
        /// The displacement of X (m), finite and non-zero.
        x_m: f64,
    },
    /// Given coordinates and rates in crate order (rad and m; rad/s and m/s).
    Given {
        /// Coordinates.
        q: [f64; 8],
        /// Velocities.
        qdot: [f64; 8],
    },
    /// The same energy in each of the eight modes ([`equal_energy_init`]).
    EqualEnergy {
        /// Energy per mode (J), finite and > 0.
        energy_j: f64,
    },
}

/// Sets coordinate `name` of `out` to `value` (SI units; `rate`: a velocity) for the option
/// `option`, whose item `item` is shown in messages; refuses an unknown name and a value that
/// is not finite.
pub fn set_coordinate(
    option: OptionKey,
    item: &str,
    name: &str,
    value: f64,
    rate: bool,
    out: &mut [f64; 8],
) -> Result<(), OptionError> {
    let c = coordinate(option, item, name)?;
    let unit = match rate {
        true => format!("{}/s", c.unit()),
        false => c.unit().to_string(),
    };
    if !value.is_finite() {
        return Err(OptionError::Conflict(crate::message!(
            "{option} {}: {value} {unit} is not allowed: must be finite",
            Shown(item).to_string()
        )));
    }
    out[c.index()] = value;
    Ok(())
}

/// The coordinate named `name` (crate names: `theta_a` .. `delta_b`).
fn coordinate(option: OptionKey, item: &str, name: &str) -> Result<Coord, OptionError> {
    Coord::ALL
        .into_iter()
        .find(|c| c.name() == name)
        .ok_or_else(|| {
            let names: Vec<&str> = Coord::ALL.iter().map(|c| c.name()).collect();
            OptionError::Conflict(crate::message!(
                "{option} {}: unknown coordinate `{}`; allowed: {}",
                Shown(item).to_string(),
                Shown(name).to_string(),
                names.join(", ")
            ))
        })
}

/// Parses `COORD=VALUE,...` lists (the command line's repeatable `--init`, `--init-rate`)
/// into `out`, SI units; unlisted coordinates keep their value.
pub fn parse_coordinates<S: AsRef<str>>(
    option: OptionKey,
    items: &[S],
    rate: bool,
    out: &mut [f64; 8],
) -> Result<(), OptionError> {
    let entries = list_entries(items);
    refuse_repeated_keys(option, "coordinate", &entries)?;
    for entry in entries {
        let (name, value) = entry.split_once('=').ok_or_else(|| {
            OptionError::Conflict(crate::message!(
                "{option} {}: expected COORD=VALUE, e.g. phi_b=0.01",
                Shown(entry).to_string()
            ))
        })?;
        // The name is checked first, as it comes first in the item.
        coordinate(option, entry, name.trim())?;
        let v: f64 = value.trim().parse().map_err(|_| {
            OptionError::Conflict(crate::message!(
                "{option} {}: `{}` is not a number",
                Shown(entry).to_string(),
                Shown(value.trim()).to_string()
            ))
        })?;
        set_coordinate(option, entry, name.trim(), v, rate, out)?;
    }
    Ok(())
}

/// The initial state of `excitation` on `model` and a description of where it came from.
/// Every coordinate and rate is 0 or at least [`MIN_SAMPLE`] in magnitude: a smaller one
/// would give observables whose spectra underflow (the error names the option and value).
pub fn initial_state(
    model: &Model,
    excitation: &Excitation,
) -> Result<(InitialState, String), OptionError> {
    let (init, text) = excitation_state(model, excitation)?;
    let option = match *excitation {
        Excitation::KickX { x_m } => crate::message!("{}", OptionKey::KICK_X.given(Num(x_m))),
        Excitation::EqualEnergy { energy_j } => {
            crate::message!("{}", OptionKey::MODE_ENERGY.given(Num(energy_j)))
        }
        Excitation::Given { .. } => {
            crate::message!("{}/{}", OptionKey::INIT, OptionKey::INIT_RATE)
        }
    };
    for c in Coord::ALL {
        for (what, value, unit) in [
            ("value", init.q[c.index()], c.unit().to_string()),
            ("rate", init.qdot[c.index()], format!("{}/s", c.unit())),
        ] {
            if value != 0.0 && value.abs() < MIN_SAMPLE {
                let option = option.clone();
                return Err(OptionError::Conflict(crate::message!(
                    "{option}: the initial {what} of {} would be {} {unit}, nonzero and \
                     smaller than {MIN_SAMPLE:e} in magnitude: the spectra of the motion would \
                     underflow f64 (see docs/limits.md)",
                    c.name(),
                    Num(value)
                )));
            }
        }
    }
    Ok((init, text))
}

/// [`initial_state`] before the check of the smallest magnitudes.
fn excitation_state(
    model: &Model,
    excitation: &Excitation,
) -> Result<(InitialState, String), OptionError> {
    match *excitation {
        Excitation::KickX { x_m: x } => {
            let option = OptionKey::KICK_X;
            if !(x.is_finite() && x != 0.0) {
                return Err(OptionError::Conflict(crate::message!(
                    "{option} {x}: the displacement (m) must be finite and non-zero"
                )));
            }
            let init = kick_x(model, x);
            if init.q.iter().any(|v| !v.is_finite()) {
                return Err(OptionError::Conflict(crate::message!(
                    "{option} {x}: X does not respond statically to a force on the test mass \
                     along x for these parameters, so the kick is undefined"
                )));
            }
            if let Err(e) = check_initial_state(&init) {
                return Err(OptionError::Conflict(crate::message!(
                    "{option} {} m: the static deflection it starts from is outside the \
                     linear model ({e})",
                    Num(x)
                )));
            }
            Ok((
                init,
                format!("kick: static X displacement of {x:e} m released from rest"),
            ))
        }
        Excitation::Given { q, qdot } => {
            if q.iter().chain(&qdot).all(|&v| v == 0.0) {
                return Err(OptionError::Conflict(crate::message!(
                    "{}/{}: every coordinate and rate is 0: nothing moves",
                    OptionKey::INIT,
                    OptionKey::INIT_RATE
                )));
            }
            let mut text = String::from("given:");
            for c in Coord::ALL {
                let (q, v) = (q[c.index()], qdot[c.index()]);
                if q != 0.0 || v != 0.0 {
                    let _ = write!(
                        text,
                        " {}={q:e} {}, rate {v:e} {}/s;",
                        c.name(),
                        c.unit(),
                        c.unit()
                    );
                }
            }
            Ok((
                InitialState { q, qdot },
                text.trim_end_matches(';').to_string(),
            ))
        }
        Excitation::EqualEnergy { energy_j: e } => {
            if !(e.is_finite() && e > 0.0) {
                return Err(OptionError::Conflict(crate::message!(
                    "{} {e}: the energy per mode (J) must be finite and > 0",
                    OptionKey::MODE_ENERGY
                )));
            }
            Ok((
                equal_energy_init(model, e),
                format!("equal energy {e:e} J in each of the 8 modes, phases 0.7 + 1.3·k rad for mode k = 0..7"),
            ))
        }
    }
}

/// Default Welch segment of a simulation's ASDs: the largest power of two <= n / 3 (at least
/// 5 half-overlapping segments), at least 2 and at most [`MAX_DEFAULT_SIM_NPERSEG`].
pub fn default_sim_nperseg(n_samples: usize) -> usize {
    let third = (n_samples / 3).max(2);
    (1 << third.ilog2()).min(MAX_DEFAULT_SIM_NPERSEG)
}

/// Longest default Welch segment of a simulation: 2^18 samples (7.3 h at 0.1 s, bins of
/// 38 uHz, 500 times finer than the closest pair of modes, nu_1 and nu_2, is wide). A segment
/// is held per observable while a long record streams through the Welch accumulators, so the
/// default stops growing with the record there (at 2^18, about 70 MB for the seven); a longer
/// record averages more segments instead. Records up to 9 days at 0.1 s keep the uncapped
/// default (2^17 for the paper's 12 h).
pub const MAX_DEFAULT_SIM_NPERSEG: usize = 1 << 18;

/// The number of samples of `duration_s` at `step_s` and the Welch segment (`nperseg`, or
/// [`default_sim_nperseg`]), checked: a finite positive step and duration, at least two
/// samples and not more than the limits allow (those of a record held whole, or, when
/// `streamed`, of one that streams chunk by chunk: [`super::stream::check_streamed_samples`]),
/// a segment of at least [`MIN_SIM_NPERSEG`] samples that fits into the record.
pub fn check_sampling(
    duration_s: f64,
    step_s: f64,
    nperseg: Option<usize>,
    streamed: bool,
) -> Result<(usize, usize), OptionError> {
    let (step, duration) = (OptionKey::STEP, OptionKey::DURATION);
    if !(step_s.is_finite() && step_s > 0.0) {
        return Err(OptionError::Conflict(crate::message!(
            "{step} {step_s}: the sampling step (s) must be finite and > 0"
        )));
    }
    if !(duration_s.is_finite() && duration_s > 0.0) {
        return Err(OptionError::Conflict(crate::message!(
            "{duration} {duration_s}: the duration (s) must be finite and > 0"
        )));
    }
    let n_f = (duration_s / step_s * (1.0 + 1e-9)).floor();
    if n_f < 2.0 {
        return Err(OptionError::Conflict(crate::message!(
            "{duration} {duration_s} s at {step} {step_s} s gives {n_f} sample(s): at least 2 \
             are needed"
        )));
    }
    let what = || {
        crate::message!(
            "{duration} {} s at {step} {} s",
            Num(duration_s),
            Num(step_s)
        )
    };
    match streamed {
        true => super::stream::check_streamed_samples(what, n_f)?,
        false => check_samples(what, n_f)?,
    }
    let n = n_f as usize;
    let seg = nperseg.unwrap_or_else(|| default_sim_nperseg(n));
    let option = OptionKey::NPERSEG;
    if seg < MIN_SIM_NPERSEG {
        return Err(OptionError::Conflict(crate::message!(
            "{option} {seg}: the Welch segment must have at least {MIN_SIM_NPERSEG} samples"
        )));
    }
    if seg > n {
        return Err(OptionError::Conflict(crate::message!(
            "{duration} {} s at {step} {} s gives {n} samples, shorter than one Welch segment \
             ({option} {seg} = {} s): lengthen {duration} or lower {option}",
            Num(duration_s),
            Num(step_s),
            Num(seg as f64 * step_s)
        )));
    }
    Ok((n, seg))
}

/// The readout of a run as text: `X 9e-9 m/sqrt(Hz) (others noiseless)`, or `none`.
pub fn readout_text(readout: &[(Observable, f64)]) -> String {
    if readout.is_empty() {
        return "none".to_string();
    }
    readout
        .iter()
        .map(|(o, a)| format!("{} {a:e} {}/sqrt(Hz)", o.name(), o.unit()))
        .collect::<Vec<_>>()
        .join(", ")
        + " (others noiseless)"
}

/// One sentence on a run: samples, step, initial state, readout and seed (the caption of its
/// figures and the description of its files).
pub fn describe_run(
    (n_samples, dt_s): (usize, f64),
    init_source: &str,
    readout: &[(Observable, f64)],
    seed: u64,
) -> String {
    format!(
        "{n_samples} samples at {dt_s} s ({} s), exact modal propagation of the undamped \
         model; initial state: {init_source}; readout: {}; seed {seed}.",
        n_samples as f64 * dt_s,
        readout_text(readout),
    )
}

/// The description a saved simulation carries, so that it is never taken for a measurement.
pub fn record_description(run: &str) -> String {
    format!("SIMULATED free motion of the double torsion pendulum model (not a measurement). {run}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;

    #[test]
    fn coordinates_parse_and_are_refused_by_name() {
        let mut q = [0.0; 8];
        parse_coordinates(
            OptionKey::INIT,
            &["theta_a=1e-5, phi_b=0.01", ""],
            false,
            &mut q,
        )
        .unwrap();
        assert_eq!((q[0], q[6]), (1e-5, 0.01));
        let mut q = [0.0; 8];
        let cases = [
            ("phi_b", "init phi_b: expected COORD=VALUE, e.g. phi_b=0.01"),
            ("phi_c=1", "init phi_c=1: unknown coordinate `phi_c`; allowed: theta_a, eta_a, phi_a, delta_a, theta_b, eta_b, phi_b, delta_b"),
            ("phi_b=x", "init phi_b=x: `x` is not a number"),
            ("phi_b=inf", "init phi_b=inf: inf rad is not allowed: must be finite"),
            ("phi_b=1,phi_b=2", "init: phi_b is given twice; name each coordinate once"),
        ];
        for (item, want) in cases {
            let e = parse_coordinates(OptionKey::INIT, &[item], false, &mut q).unwrap_err();
            assert_eq!(e.to_string(), want);
        }
        let e =
            parse_coordinates(OptionKey::INIT_RATE, &["delta_b=nan"], true, &mut q).unwrap_err();
        assert_eq!(
            e.to_string(),
            "init_rate delta_b=nan: NaN m/s is not allowed: must be finite"
        );
    }

    #[test]
    fn initial_states_and_their_refusals() {
        let model = Model::new(&Params::table_i()).unwrap();
        let (init, text) = initial_state(&model, &Excitation::KickX { x_m: 1e-6 }).unwrap();
        assert!(init.qdot.iter().all(|&v| v == 0.0) && text.starts_with("kick:"));
        let e = initial_state(&model, &Excitation::KickX { x_m: 0.0 });
        assert_eq!(
            e.unwrap_err().to_string(),
            "kick_x 0: the displacement (m) must be finite and non-zero"
        );
        let e = initial_state(&model, &Excitation::KickX { x_m: 10.0 });
        assert!(e
            .unwrap_err()
            .to_string()
            .starts_with("kick_x 10 m: the static deflection"));
        let zero = Excitation::Given {
            q: [0.0; 8],
            qdot: [0.0; 8],
        };
        assert_eq!(
            initial_state(&model, &zero).unwrap_err().to_string(),
            "init/init_rate: every coordinate and rate is 0: nothing moves"
        );
        let mut q = [0.0; 8];
        q[6] = 0.01;
        let (_, text) = initial_state(&model, &Excitation::Given { q, qdot: [0.0; 8] }).unwrap();
        assert_eq!(text, "given: phi_b=1e-2 rad, rate 0e0 rad/s");
        let e = initial_state(&model, &Excitation::EqualEnergy { energy_j: -1.0 });
        assert_eq!(
            e.unwrap_err().to_string(),
            "mode_energy -1: the energy per mode (J) must be finite and > 0"
        );
    }

    #[test]
    fn sampling_is_checked() {
        assert_eq!(
            check_sampling(43_200.0, 0.1, None, false).unwrap(),
            (432_000, 1 << 17)
        );
        let cases = [
            (
                1.0,
                0.0,
                None,
                "step 0: the sampling step (s) must be finite and > 0",
            ),
            (
                -1.0,
                0.1,
                None,
                "duration -1: the duration (s) must be finite and > 0",
            ),
            (
                0.1,
                0.1,
                None,
                "duration 0.1 s at step 0.1 s gives 1 sample(s): at least 2 are needed",
            ),
            (
                100.0,
                0.1,
                Some(8),
                "nperseg 8: the Welch segment must have at least 16 samples",
            ),
        ];
        for (d, s, n, want) in cases {
            assert_eq!(
                check_sampling(d, s, n, false).unwrap_err().to_string(),
                want
            );
        }
        let e = check_sampling(10.0, 0.1, Some(128), false).unwrap_err();
        assert_eq!(
            e.to_string(),
            "duration 10 s at step 0.1 s gives 100 samples, shorter than one Welch segment \
             (nperseg 128 = 12.8 s): lengthen duration or lower nperseg"
        );
    }
}
