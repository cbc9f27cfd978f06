//! Double-double arithmetic ([`Dd`], [`CDd`]: about 32 significant digits) and the model's
//! matrices written in it from the paper's formulas ([`matrices`]).
//!
//! Shared by the double-double reference evaluator ([`crate::reference`], the oracle of every
//! method's accuracy) and the pole-zero method ([`crate::tf::PoleZero`], which finds its poles
//! and zeros in double-double). Neither depends on the other. This module depends on nothing
//! but [`crate::params`] and the formulas of M and K ([`crate::appendix`]); the matrices of the pendulum as built are the exact kinematics in
//! double-double ([`crate::geometry::dd_matrices`]).

mod complex;
pub mod matrices;
mod real;

pub use complex::CDd;
pub use real::{fast_two_sum, two_prod, two_sum, Dd, DD_EPS, PI_HI, PI_LO};
