//! tiltnoise: noise budgets for double torsion pendulums.
//!
//! The 8-degree-of-freedom linear model of the double torsion pendulum PETER (De Marchi et al.,
//! Phys. Rev. D 87, 122006, 2013): mass and stiffness matrices, normal modes, generalized forces
//! and the transfer functions from floor tilt to the test-mass observables.
//!
//! Data flow is one way: [`params`] -> [`model`] -> [`modes`], [`tf`] -> [`noise`] -> [`io`],
//! [`plot`]; [`cli`] sits on top. Numerical modules never depend on I/O or plotting.
//!
//! ```
//! use tiltnoise::model::{Model, Observable, TiltAxis};
//! use tiltnoise::modes::NormalModes;
//! use tiltnoise::params::Params;
//! use tiltnoise::tf::{plan, Method, Request};
//!
//! let model = Model::new(&Params::table_i())?;
//! // Normal modes (Table II): nu_1 is the crossbar torsion at about 1.3 mHz.
//! let modes = NormalModes::new(&model);
//! assert!((modes.modes[0].frequency_hz - 1.31e-3).abs() < 1e-5);
//! // Tilt transfer functions: H[o * 3 + t], observable o per radian of tilt t.
//! let tf = plan(&model, &Request::all_tilt(), Method::Direct)?;
//! let h = tf.eval(1e-5)?; // Hz
//! let x_per_eta = h[Observable::X.index() * 3 + TiltAxis::EtaT.index()];
//! // Quasi-static limit X -> -eta_t (Z + Z_b + h_c) = -1.664 m/rad.
//! assert!((x_per_eta.re + 1.664).abs() < 1e-6);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
pub mod atomic;
pub mod budget;
pub mod cli;
mod cli_budget;
mod cli_fit;
mod cli_mc;
mod cli_simulate;
mod cli_tf;
pub mod error;
pub mod fit;
pub mod freq;
pub mod input;
pub mod io;
pub mod mc;
pub mod methods;
pub mod model;
pub mod modes;
pub mod noise;
pub mod params;
pub mod plot;
pub mod reference;
pub mod report;
pub mod rng;
pub mod scene;
pub mod simulate;
pub mod spectral;
pub mod tf;
pub mod thermal;
pub mod units;
