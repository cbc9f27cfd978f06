//! tiltnoise-core: the numerical core of `tiltnoise`, noise budgets for double torsion pendulums.
//!
//! The 8-degree-of-freedom linear model of the double torsion pendulum PETER (De Marchi et al.,
//! Phys. Rev. D 87, 122006, 2013): mass and stiffness matrices, normal modes, generalized forces
//! and the transfer functions from floor tilt and from forces and torques to the test-mass
//! observables; spectral estimation, typed noise terms and budgets, thermal noise, Monte Carlo,
//! fit and simulation.
//!
//! Data flow is one way: [`params`] -> [`model`] -> [`modes`], [`tf`] -> [`spectral`],
//! [`noise`] -> [`budget`]. This crate reads and writes no files and draws nothing: the
//! readers and writers are in `tiltnoise-io`, the figures in `tiltnoise-plot`, the command line
//! in the `tiltnoise` package. Its dependencies are numerical and serde-level only.
//!
//! Conventions, stated at every boundary: SI units (the unit is part of every parameter key),
//! one-sided spectra (PSD in unit^2/Hz, ASD its square root), complex amplitudes for
//! `e^{+i w t}` time dependence, and the tilt sign of [`model::tilt`] (in which
//! `X -> -eta_t (Z + Z_b + h_c)` as f -> 0).
//!
//! ```
//! use tiltnoise_core::model::{Input, Model, Observable, Request, TiltAxis};
//! use tiltnoise_core::modes::NormalModes;
//! use tiltnoise_core::params::Params;
//! use tiltnoise_core::tf::{plan, Method};
//!
//! let model = Model::new(&Params::table_i())?;
//! // Normal modes (Table II): nu_1 is the crossbar torsion at about 1.3 mHz.
//! let modes = NormalModes::new(&model);
//! assert!((modes.modes[0].frequency_hz - 1.31e-3).abs() < 1e-5);
//! // Tilt transfer functions, named by observable and input (m/rad, rad/rad).
//! let request = Request::all_tilt();
//! let tf = plan(&model, &request, Method::Direct)?;
//! let h = tf.eval(1e-5)?; // Hz
//! let x_per_eta = h[request.index(Observable::X, Input::Tilt(TiltAxis::EtaT)).unwrap()];
//! // Quasi-static limit X -> -eta_t (Z + Z_b + h_c) = -1.664 m/rad.
//! assert!((x_per_eta.re + 1.664).abs() < 1e-6);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
pub mod budget;
pub mod csv_text;
pub mod dd;
pub mod error;
pub mod fit;
pub mod freq;
pub mod input;
pub mod mc;
pub mod methods;
pub mod model;
pub mod modes;
pub mod noise;
pub mod params;
pub mod reference;
pub mod rng;
pub mod simulate;
pub mod spectral;
pub mod tf;
pub mod thermal;
pub mod units;
