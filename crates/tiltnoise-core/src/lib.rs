//! tiltnoise-core: the numerical core of `tiltnoise`, noise budgets for double torsion pendulums.
//!
//! The 8-degree-of-freedom linear model of the double torsion pendulum PETER (De Marchi et al.,
//! Phys. Rev. D 87, 122006, 2013): mass and stiffness matrices, normal modes, generalized forces
//! and the transfer functions from the floor's tilt and translation and from forces and torques
//! to the test-mass observables; spectral estimation, typed noise terms and budgets, thermal noise, Monte Carlo,
//! fit and simulation.
//!
//! Data flow is one way: [`params`] -> [`model`] -> [`modes`], [`tf`] -> [`spectral`],
//! [`noise`] -> [`budget`]. This crate reads and writes no files and draws nothing: the
//! readers and writers are in `tiltnoise-io`, the figures in `tiltnoise-plot`, the command line
//! in the `tiltnoise` package. Its dependencies are numerical and serde-level only.
//!
//! Conventions, stated at every boundary: SI units (the unit is part of every parameter key),
//! one-sided spectra (PSD in unit^2/Hz, ASD its square root), complex amplitudes for
//! `e^{+i w t}` time dependence, the tilt sign of [`model::tilt`] (in which
//! `X -> -eta_t (Z + Z_b + h_c)` as f -> 0), and the floor translation of [`model::translation`]
//! (the floor's displacement along the lab axes, the crossbar arm along y; per unit floor
//! acceleration it acts as the tilt `eta_t = a_x / g`, `theta_t = -a_y / g` as f -> 0).
//!
//! Normal modes, and transfer functions named by observable and input (the planner picks the
//! cheapest method within 1e-9 of the double-double reference):
//!
//! ```
//! use tiltnoise_core::model::{Input, Model, Observable, Request, TiltAxis};
//! use tiltnoise_core::modes::NormalModes;
//! use tiltnoise_core::params::Params;
//! use tiltnoise_core::tf::{evaluate, plan_auto, Scene};
//!
//! let mut params = Params::table_i();
//! params.length.h_m = 1.5; // the assumed height of the suspension point above the tilt axis (m)
//! let model = Model::new(&params)?;
//! // Normal modes (Table II): nu_1 is the crossbar torsion at about 1.3 mHz.
//! let modes = NormalModes::new(&model);
//! assert!((modes.modes[0].frequency_hz - 1.31e-3).abs() < 1e-5);
//!
//! let eta_t = Input::Tilt(TiltAxis::EtaT);
//! let request = Request { outputs: vec![Observable::X, Observable::Phi], inputs: vec![eta_t] };
//! let freqs_hz: Vec<f64> = (0..200).map(|k| 1e-4 * 10f64.powf(k as f64 / 40.0)).collect();
//! let (tf, choice) = plan_auto(&model, &Scene::over_grid(request, &freqs_hz))?;
//! let h = evaluate(tf.as_ref(), &freqs_hz)?; // complex amplitudes, e^{+i w t}
//! let x = h.output_index(Observable::X).unwrap();
//! let eta = h.input_index(eta_t).unwrap();
//! println!("{}: X/eta_t at {} Hz = {} m/rad", choice.method.name(), h.freqs_hz[0], h.get(0, x, eta));
//! // Quasi-static limit X -> -eta_t (Z + Z_b + h_c) = -1.664 m/rad, whatever h is.
//! assert!((h.get(0, x, eta).re + 1.664).abs() < 1e-3);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
pub mod align;
pub mod appendix;
pub mod budget;
pub mod cancel;
pub mod coherence;
pub mod csv_text;
pub mod dd;
pub mod error;
pub mod fit;
pub mod freq;
pub mod geometry;
pub mod ground;
pub mod input;
pub mod limits;
pub mod mc;
pub mod methods;
pub mod model;
pub mod modes;
pub mod noise;
mod num_text;
pub mod option_key;
pub mod options;
pub mod params;
pub mod reference;
pub mod repeats;
pub mod rng;
pub mod simulate;
pub mod spectral;
pub mod subtract;
pub mod tf;
pub mod thermal;
pub mod units;
