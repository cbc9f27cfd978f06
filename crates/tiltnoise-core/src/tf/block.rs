//! The block-reduced method: the direct method's equilibrated LU, on the 4x4 blocks the request
//! needs instead of the full 8x8.
//!
//! The model splits exactly into [`Block::SwingYBounce`] and [`Block::SwingXTorsion`] (M, K, the
//! force matrix, the tilt forcing and the observation matrix are all block diagonal in this
//! split). A block is needed when some input of the request forces it (a nonzero row of that
//! input's forcing column on the block's coordinates) and some output reads it (a nonzero entry
//! of the output's observation row there): theta_t forces only the first block, eta_t and phi_t
//! only the second; X, eta, phi, phi_a read only the second, Y, Z, theta only the first.
//!
//! Per frequency each needed block gets one LU of its equilibrated dynamic stiffness, with the
//! direct method's singularity check ([`super::SINGULAR_RCOND`]) applied to that block only: a
//! resonance of a block the request does not need is not a singularity of the request. Entries
//! across blocks are never computed and are exactly 0.0. Within a block the elimination performs
//! the same floating-point operations as the direct method's 8x8 LU (whose multipliers across
//! blocks are exactly zero), so the results agree with it to the last bit or nearly so.

use super::direct::{forcing_columns, omega_sq, with_viscous, EquilibratedLu};
use super::{Method, Request, TransferFunction};
use crate::error::TfError;
use crate::model::{Block, Coord, Model};
use nalgebra::{Matrix4, RowVector4, Vector4};
use num_complex::Complex64;

/// Plan of the block-reduced method.
pub struct BlockReduced {
    request: Request,
    systems: Vec<BlockSystem>,
}

/// One decoupled block's share of a request, in the block's coordinates ([`Block::coords`]).
struct BlockSystem {
    stiffness: Matrix4<Complex64>,
    /// Viscous damping matrix of the block, if any.
    damping: Option<Matrix4<f64>>,
    mass: Matrix4<f64>,
    /// Inputs that force the block: column in the request, rows of G0 and of G2.
    inputs: Vec<(usize, Vector4<f64>, Vector4<f64>)>,
    /// Outputs that read the block: row in the request, observation row.
    outputs: Vec<(usize, RowVector4<f64>)>,
}

/// The block systems of `request`. Blocks no input forces, or no output reads, are left out.
fn block_systems(model: &Model, request: &Request) -> Vec<BlockSystem> {
    let (forcing0, forcing2) = forcing_columns(model, &request.inputs);
    let stiffness = model.stiffness_complex();
    let observation = model.observation();
    Block::ALL
        .into_iter()
        .filter_map(|block| {
            let idx = block.coords().map(Coord::index);
            let inputs: Vec<_> = (0..request.inputs.len())
                .map(|col| {
                    let g0 = Vector4::from_fn(|r, _| forcing0[(idx[r], col)]);
                    let g2 = Vector4::from_fn(|r, _| forcing2[(idx[r], col)]);
                    (col, g0, g2)
                })
                .filter(|(_, g0, g2)| g0.iter().chain(g2.iter()).any(|&v| v != 0.0))
                .collect();
            let outputs: Vec<_> = request
                .outputs
                .iter()
                .enumerate()
                .map(|(row, o)| {
                    (
                        row,
                        RowVector4::from_fn(|_, c| observation[(o.index(), idx[c])]),
                    )
                })
                .filter(|(_, c)| c.iter().any(|&v| v != 0.0))
                .collect();
            (!inputs.is_empty() && !outputs.is_empty()).then(|| BlockSystem {
                stiffness: Matrix4::from_fn(|r, c| stiffness[(idx[r], idx[c])]),
                damping: model
                    .has_viscous()
                    .then(|| Model::block_of(model.damping(), block)),
                mass: Model::block_of(model.mass(), block),
                inputs,
                outputs,
            })
        })
        .collect()
}

impl BlockSystem {
    /// Adds this block's contribution to the row-major `outputs x n_in` matrix `out`.
    fn accumulate(
        &self,
        w2: f64,
        freq_hz: f64,
        n_in: usize,
        out: &mut [Complex64],
    ) -> Result<(), TfError> {
        let lu = match &self.damping {
            Some(c) => {
                let k = with_viscous(&self.stiffness, c, w2.sqrt());
                EquilibratedLu::factor(&k, &self.mass, w2, freq_hz)?
            }
            None => EquilibratedLu::factor(&self.stiffness, &self.mass, w2, freq_hz)?,
        };
        for (col, g0, g2) in &self.inputs {
            let mut y = Vector4::from_fn(|r, _| Complex64::from(g0[r] + w2 * g2[r]));
            lu.solve_mut(&mut y)?;
            for (row, c) in &self.outputs {
                out[row * n_in + col] += (0..4).map(|k| y[k] * c[k]).sum::<Complex64>();
            }
        }
        Ok(())
    }
}

impl BlockReduced {
    /// Prepares the blocks `request` needs.
    pub fn new(model: &Model, request: Request) -> BlockReduced {
        let systems = block_systems(model, &request);
        BlockReduced { request, systems }
    }
}

impl TransferFunction for BlockReduced {
    fn method(&self) -> Method {
        Method::Block
    }

    fn request(&self) -> &Request {
        &self.request
    }

    fn eval_into(&self, freq_hz: f64, out: &mut [Complex64]) -> Result<(), TfError> {
        let w2 = omega_sq(freq_hz)?;
        out.fill(Complex64::new(0.0, 0.0));
        for system in &self.systems {
            system.accumulate(w2, freq_hz, self.request.inputs.len(), out)?;
        }
        Ok(())
    }
}
