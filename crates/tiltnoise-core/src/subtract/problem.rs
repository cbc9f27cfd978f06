//! The residuals of the coupling fit, their Jacobian and their instruments (see
//! [`super::estimate`] for the estimator): per frequency bin and observable,
//! `r = s - (S - S_mm) G(theta)`, whitened by its covariance `S_bar S_ee / n_eff` (the smoothed
//! witness spectrum and residual PSD); the instruments are the Jacobian with `S` replaced by
//! `S_bar`; the priors (noise scales, keys the data do not constrain) follow as extra rows.

use super::parameters::{Kind, Param, KEY_STEP_REL};
use super::stats::{hann_delay_factor, hann_delay_factor_slope};
use super::weighting::{smooth, weighting};
use super::SubtractError;
use crate::fit::jacobian::with_value;
use crate::model::{Model, Request};
use crate::params::Params;
use crate::tf::plan;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::TAU;

/// Smallest residual PSD used as a weight, relative to the measured PSD: the rounding floor of
/// the spectra, so that a noiseless channel cannot get an infinite weight.
pub const S_EE_FLOOR: f64 = 1e-12;

/// The witnesses' spectra at one frequency of the fit grid (shared by every observable).
pub(crate) struct GridBin {
    /// `S = <conj(w_a) w_b>` of this bin.
    pub sww: DMatrix<Complex64>,
    /// `S` smoothed from the neighbouring bins.
    pub sbar: DMatrix<Complex64>,
    /// The witnesses' noise PSDs at the nominal levels.
    pub noise: Vec<f64>,
}

/// The spectra of one bin of one observable.
pub(crate) struct Bin {
    /// Index into the fit grid.
    pub grid: usize,
    /// `s_a = <conj(w_a) y>`.
    pub s: DVector<Complex64>,
    /// `S_yy`.
    pub syy: f64,
    /// Residual PSD `S_ee` used as the weight.
    pub see: f64,
    /// Inverse square root of the covariance of the residual's real and imaginary parts
    /// (`[re_0, im_0, re_1, ...]`), see [`whitener`].
    pub whitener: DMatrix<f64>,
}

/// The inverse square root of the covariance of `[Re r_a, Im r_a]_a` for the residual
/// `r = s - (S - S_mm) G`, averaged over `n_eff` effective segments, for Gaussian data
/// (Isserlis' theorem): its covariance is `Gamma = S S_ee / n_eff` and, because the witness
/// noise is in both `w` and `e = y - G^T w`, its pseudo-covariance is `C = c c^T / n_eff` with
/// `c_a = <conj(w_a) e> = -S_mm,a G_a` (rank one, `None`: 0). `C` makes the residual's scatter
/// larger along `G` (a witness-noise PSD estimated high or low scales the whole cross spectrum)
/// than across it (the phase, hence the delay, is better determined).
pub(crate) fn whitener(
    s: &DMatrix<Complex64>,
    see: f64,
    n_eff: f64,
    c: Option<&DVector<Complex64>>,
) -> DMatrix<f64> {
    let q = s.nrows();
    let gamma = s * Complex64::new(see / n_eff, 0.0);
    let pseudo = c.map_or_else(
        || DMatrix::zeros(q, q),
        |c| c * c.transpose() / Complex64::new(n_eff, 0.0),
    );
    let mut cov = DMatrix::<f64>::zeros(2 * q, 2 * q);
    for a in 0..q {
        for b in 0..q {
            let (g, p) = (gamma[(a, b)], pseudo[(a, b)]);
            cov[(2 * a, 2 * b)] = 0.5 * (g.re + p.re);
            cov[(2 * a + 1, 2 * b + 1)] = 0.5 * (g.re - p.re);
            cov[(2 * a, 2 * b + 1)] = 0.5 * (p.im - g.im);
            cov[(2 * a + 1, 2 * b)] = 0.5 * (p.im + g.im);
        }
    }
    let eig = cov.symmetric_eigen();
    let top = eig.eigenvalues.max();
    let mut w = DMatrix::<f64>::zeros(2 * q, 2 * q);
    for l in 0..2 * q {
        // A direction without variance (a dead witness) carries no residual.
        let e = eig.eigenvalues[l];
        if e > top * crate::fit::RANK_TOL {
            let v = eig.eigenvectors.column(l);
            w += v * v.transpose() / e.sqrt();
        }
    }
    w
}

/// `[re_0, im_0, re_1, im_1, ...]` of a complex vector.
pub(crate) fn real_parts(z: &DVector<Complex64>) -> DVector<f64> {
    DVector::from_fn(2 * z.len(), |i, _| {
        if i % 2 == 0 {
            z[i / 2].re
        } else {
            z[i / 2].im
        }
    })
}

/// Residuals, Jacobian and instruments at one parameter point (columns: the free parameters,
/// in units of their box half-widths).
pub(crate) struct Evaluation {
    /// Whitened residuals: the data rows, then one row per prior.
    pub r: DVector<f64>,
    /// `dr/du`.
    pub jac: DMatrix<f64>,
    /// The instruments: `dr/du` with the bin's own witness spectrum replaced by the smoothed
    /// one.
    pub inst: DMatrix<f64>,
}

/// Everything the residuals need.
pub(crate) struct Problem<'a> {
    pub base: &'a Params,
    pub request: Request,
    pub n_in: usize,
    pub freqs: Vec<f64>,
    /// The witnesses' spectra per fit frequency (`None`: singular, not used).
    pub grid: Vec<Option<GridBin>>,
    /// Per observable (its index in the request's outputs), its bins.
    pub bins: Vec<(usize, Vec<Bin>)>,
    pub params: Vec<Param>,
    pub n_eff: f64,
    pub segment_s: f64,
    pub fraction_s: f64,
}

/// Transfer functions `[freq][output][input]` of `params` on `freqs`.
pub(crate) fn transfer(
    params: &Params,
    request: &Request,
    freqs: &[f64],
) -> Result<Vec<Complex64>, SubtractError> {
    let model = Model::new(params).map_err(|e| SubtractError::Params(e.to_string()))?;
    let tf = plan(&model, request, super::method_for(&model))
        .map_err(|e| SubtractError::Plan(e.to_string()))?;
    let block = request.outputs.len() * request.inputs.len();
    let mut out = vec![Complex64::new(0.0, 0.0); freqs.len() * block];
    tf.eval_grid_into(freqs, &mut out)?;
    Ok(out)
}

/// `<|y - F^T w|^2>` from the spectra: `S_yy - 2 Re(sum_a F_a conj(s_a)) + F^H S F`.
pub(crate) fn residual_psd(
    syy: f64,
    s: &DVector<Complex64>,
    sww: &DMatrix<Complex64>,
    f: &DVector<Complex64>,
) -> f64 {
    let cross: Complex64 = f.iter().zip(s.iter()).map(|(f, s)| f * s.conj()).sum();
    let quad = (f.adjoint() * sww * f)[(0, 0)].re;
    syy - 2.0 * cross.re + quad
}

/// Coherence-limited residual PSD `S_yy - s^H S^-1 s` (the Wiener residual of the same data),
/// or `None` when `S` is singular.
pub(crate) fn coherence_residual(
    syy: f64,
    s: &DVector<Complex64>,
    sww: &DMatrix<Complex64>,
) -> Option<f64> {
    let w = sww.clone().lu().solve(s)?;
    Some(residual_psd(syy, s, sww, &w))
}

/// Whether a Hermitian positive semi-definite matrix is numerically regular: its smallest
/// eigenvalue above [`crate::fit::RANK_TOL`] of its largest (not dependent or dead witnesses).
pub(crate) fn regular(m: &DMatrix<Complex64>) -> bool {
    let eig = m.clone().symmetric_eigenvalues();
    let (lo, hi) = (eig.min(), eig.max());
    hi.is_finite() && hi > 0.0 && lo > hi * crate::fit::RANK_TOL
}

impl Evaluation {
    /// The data rows alone (the first `data_rows`): what the data say without the priors.
    pub fn data_only(&self, data_rows: usize) -> Evaluation {
        Evaluation {
            r: self.r.rows(0, data_rows).into_owned(),
            jac: self.jac.rows(0, data_rows).into_owned(),
            inst: self.inst.rows(0, data_rows).into_owned(),
        }
    }
}

impl Problem<'_> {
    /// The gains (witness order) and the delay behind the aligned samples,
    /// `tau - fraction_s` (s), at internal values `theta`.
    pub fn coupling_at(&self, theta: &[f64]) -> (Vec<f64>, f64) {
        let mut gains = vec![1.0; self.n_in];
        let mut tau = 0.0;
        for (p, &v) in self.params.iter().zip(theta) {
            match p.kind {
                Kind::Gain(a) => gains[a] = v.exp(),
                Kind::Delay => tau = v,
                _ => {}
            }
        }
        (gains, tau - self.fraction_s)
    }

    /// The factors on the witnesses' noise PSDs at internal values `theta`.
    pub fn noise_factors(&self, theta: &[f64]) -> Vec<f64> {
        let mut k = vec![1.0; self.n_in];
        for (p, &v) in self.params.iter().zip(theta) {
            if let Kind::NoiseScale(input) = p.kind {
                k[input] = (2.0 * v).exp();
            }
        }
        k
    }

    /// The parameter set at internal values `theta` (keys only).
    pub fn params_at(&self, theta: &[f64]) -> Result<Params, SubtractError> {
        let mut p = self.base.clone();
        for (par, &v) in self.params.iter().zip(theta) {
            if let Kind::Key(key) = &par.kind {
                p = with_value(&p, key, v).map_err(|e| SubtractError::Params(e.to_string()))?;
            }
        }
        Ok(p)
    }

    /// The noise PSDs of every fit frequency times `factors`, as diagonal matrices, and the
    /// smoothed witness spectra minus them with negative eigenvalues removed
    /// ([`super::weighting`]).
    fn corrected(&self, factors: &[f64]) -> Vec<Option<(DMatrix<Complex64>, DMatrix<Complex64>)>> {
        self.grid
            .iter()
            .map(|g| {
                g.as_ref().map(|g| {
                    let noise: Vec<f64> = g.noise.iter().zip(factors).map(|(m, k)| m * k).collect();
                    let smm = DMatrix::from_fn(self.n_in, self.n_in, |a, b| {
                        Complex64::new(if a == b { noise[a] } else { 0.0 }, 0.0)
                    });
                    let stt = &g.sbar * weighting(&g.sbar, &noise, 1.0).at;
                    (smm, stt)
                })
            })
            .collect()
    }

    /// The coupling `G` of every bin at `theta` with the transfer functions `h` of the fit
    /// grid: `[observable][bin]`.
    fn couplings(&self, theta: &[f64], h: &[Complex64]) -> Vec<Vec<DVector<Complex64>>> {
        let block = self.request.outputs.len() * self.n_in;
        let (gains, tau_eff) = self.coupling_at(theta);
        let rho = hann_delay_factor(tau_eff / self.segment_s);
        self.bins
            .iter()
            .map(|(o, bins)| {
                bins.iter()
                    .map(|bin| {
                        let f = self.freqs[bin.grid];
                        let phase = Complex64::from_polar(rho, -TAU * f * tau_eff);
                        let hrow = &h[bin.grid * block + o * self.n_in..][..self.n_in];
                        DVector::from_fn(self.n_in, |a, _| hrow[a] * gains[a] * phase)
                    })
                    .collect()
            })
            .collect()
    }

    /// Residuals, Jacobian and instruments at internal values `theta`, columns `free`.
    pub fn evaluate(&self, theta: &[f64], free: &[usize]) -> Result<Evaluation, SubtractError> {
        let params = self.params_at(theta)?;
        let h = transfer(&params, &self.request, &self.freqs)?;
        // dH/dp per free key, central differences.
        let mut dh: Vec<Option<Vec<Complex64>>> = vec![None; self.params.len()];
        for &j in free {
            if let Kind::Key(key) = &self.params[j].kind {
                let p = theta[j];
                // An assembly offset's nominal is 0: its step is relative to its scale.
                let step = KEY_STEP_REL * p.abs().max(self.params[j].scale);
                let at = |v: f64| -> Result<Vec<Complex64>, SubtractError> {
                    let q = with_value(&params, key, v)
                        .map_err(|e| SubtractError::Params(e.to_string()))?;
                    transfer(&q, &self.request, &self.freqs)
                };
                let (hp, hm) = (at(p + step)?, at(p - step)?);
                dh[j] = Some(
                    hp.iter()
                        .zip(&hm)
                        .map(|(a, b)| (a - b) / (2.0 * step))
                        .collect(),
                );
            }
        }
        let factors = self.noise_factors(theta);
        let corrected = self.corrected(&factors);
        let couplings = self.couplings(theta, &h);
        let priors: Vec<usize> = (0..self.params.len())
            .filter(|&j| self.params[j].prior.is_some())
            .collect();
        let data_rows = self.data_rows();
        let rows = data_rows + priors.len();
        let mut r = DVector::zeros(rows);
        let mut jac = DMatrix::zeros(rows, free.len());
        let mut inst = DMatrix::zeros(rows, free.len());
        let (gains, tau_eff) = self.coupling_at(theta);
        let x = tau_eff / self.segment_s;
        let rho = hann_delay_factor(x);
        let drho_dtau = hann_delay_factor_slope(x) / self.segment_s;
        let block = self.request.outputs.len() * self.n_in;
        let mut row = 0;
        let zero = Complex64::new(0.0, 0.0);
        for ((o, bins), gs) in self.bins.iter().zip(&couplings) {
            for (bin, g) in bins.iter().zip(gs) {
                let f = self.freqs[bin.grid];
                let w = TAU * f;
                let phase = Complex64::from_polar(rho, -w * tau_eff);
                let gb = self.grid[bin.grid]
                    .as_ref()
                    .expect("bins on usable frequencies");
                let (smm, stt) = corrected[bin.grid]
                    .as_ref()
                    .expect("bins on usable frequencies");
                let v = &bin.whitener;
                let sc = &gb.sww - smm;
                let res = v * real_parts(&(&bin.s - &sc * g));
                for (jj, &j) in free.iter().enumerate() {
                    let par = &self.params[j];
                    let dg = match &par.kind {
                        Kind::Gain(a) => {
                            let mut d = DVector::from_element(self.n_in, zero);
                            d[*a] = g[*a];
                            Some(d)
                        }
                        Kind::Delay => Some(g * Complex64::new(drho_dtau / rho, -w)),
                        Kind::Key(_) => {
                            let dh = dh[j].as_ref().expect("computed for every free key");
                            let drow = &dh[bin.grid * block + o * self.n_in..][..self.n_in];
                            Some(DVector::from_fn(self.n_in, |a, _| {
                                drow[a] * gains[a] * phase
                            }))
                        }
                        Kind::NoiseScale(_) => None,
                    };
                    let (dr, z) = match (dg, &par.kind) {
                        (Some(dg), _) => (
                            -(v * real_parts(&(&sc * &dg))),
                            -(v * real_parts(&(stt * &dg))),
                        ),
                        (None, Kind::NoiseScale(input)) => {
                            // r depends on the noise PSD m s^2 through + m s^2 G: d/d(ln s).
                            let mut d = DVector::from_element(self.n_in, zero);
                            d[*input] = smm[(*input, *input)] * g[*input] * 2.0;
                            let dr = v * real_parts(&d);
                            (dr.clone(), dr)
                        }
                        (None, _) => unreachable!("only noise scales have no dG"),
                    };
                    for i in 0..2 * self.n_in {
                        jac[(row + i, jj)] = dr[i] * par.half_width;
                        inst[(row + i, jj)] = z[i] * par.half_width;
                    }
                }
                for i in 0..2 * self.n_in {
                    r[row + i] = res[i];
                }
                row += 2 * self.n_in;
            }
        }
        for (i, &j) in priors.iter().enumerate() {
            let p = &self.params[j];
            let sigma = p.prior.expect("filtered to priors");
            r[data_rows + i] = (theta[j] - p.nominal) / sigma;
            if let Some(jj) = free.iter().position(|&f| f == j) {
                jac[(data_rows + i, jj)] = p.half_width / sigma;
                inst[(data_rows + i, jj)] = p.half_width / sigma;
            }
        }
        Ok(Evaluation { r, jac, inst })
    }

    /// Rows of whitened data residuals (the prior rows follow them).
    pub fn data_rows(&self) -> usize {
        self.bins.iter().map(|(_, b)| b.len()).sum::<usize>() * 2 * self.n_in
    }

    /// Sets every bin's weight `S_ee = <|y - G^T w|^2>` from the fit at `theta`: the witness
    /// noise part `G^H S_mm G` from the model, the rest (readout and whatever else the record
    /// holds) from the residual of the fit, smoothed over the neighbouring fit bins, so that
    /// the weights are smooth and nearly independent of the bin they weigh.
    pub fn reweight(&mut self, theta: &[f64]) -> Result<(), SubtractError> {
        let params = self.params_at(theta)?;
        let h = transfer(&params, &self.request, &self.freqs)?;
        let couplings = self.couplings(theta, &h);
        let factors = self.noise_factors(theta);
        let grid = &self.grid;
        for ((_, bins), gs) in self.bins.iter_mut().zip(&couplings) {
            let mut witness = Vec::with_capacity(bins.len());
            let mut rest = Vec::with_capacity(bins.len());
            for (bin, g) in bins.iter().zip(gs) {
                let gb = grid[bin.grid].as_ref().expect("bins on usable frequencies");
                let part: f64 = (0..g.len())
                    .map(|a| g[a].norm_sqr() * gb.noise[a] * factors[a])
                    .sum();
                witness.push(part);
                rest.push(residual_psd(bin.syy, &bin.s, &gb.sww, g) - part);
            }
            let freqs: Vec<f64> = bins.iter().map(|b| self.freqs[b.grid]).collect();
            let rest = smooth(&freqs, &rest, 0);
            for (((bin, part), rest), g) in bins.iter_mut().zip(witness).zip(rest).zip(gs) {
                bin.see = rest.max(S_EE_FLOOR * bin.syy) + part;
                let gb = grid[bin.grid].as_ref().expect("bins on usable frequencies");
                let c = DVector::from_fn(g.len(), |a, _| -g[a] * gb.noise[a] * factors[a]);
                bin.whitener = whitener(&gb.sbar, bin.see, self.n_eff, Some(&c));
            }
        }
        Ok(())
    }
}

/// The covariance of the instrumental-variable estimate in `u`:
/// `B^-1 Z^T D Z B^-T` with `B = Z^T J`, `D` the variance of the whitened residuals (1, the
/// first `data_rows` rows multiplied by `data_factor^2`: the bin correlation and the Birge
/// ratio widen the data's variance, not the priors'). Returns `sqrt(diag)` and the correlation
/// matrix; a parameter in the numerical null space of `B` gets an infinite sigma.
pub(crate) fn covariance(
    e: &Evaluation,
    data_rows: usize,
    data_factor: f64,
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let cols = e.jac.ncols();
    if cols == 0 {
        return (Vec::new(), Vec::new());
    }
    let b = e.inst.transpose() * &e.jac;
    let mut scaled = e.inst.clone();
    for i in 0..data_rows.min(scaled.nrows()) {
        for j in 0..cols {
            scaled[(i, j)] *= data_factor;
        }
    }
    let mid = scaled.transpose() * &scaled;
    let svd = b.svd(true, true);
    let (u, v_t) = (svd.u.expect("requested"), svd.v_t.expect("requested"));
    let s_max = svd.singular_values.max();
    let mut null = vec![false; cols];
    // B^-1 = V S^-1 U^T over the non-null directions.
    let mut b_inv = DMatrix::<f64>::zeros(cols, cols);
    for (i, &s) in svd.singular_values.iter().enumerate() {
        if s <= s_max * crate::fit::RANK_TOL || s == 0.0 {
            for j in 0..cols {
                if v_t[(i, j)].abs() > crate::fit::RANK_TOL {
                    null[j] = true;
                }
            }
            continue;
        }
        for a in 0..cols {
            for c in 0..cols {
                b_inv[(a, c)] += v_t[(i, a)] * u[(c, i)] / s;
            }
        }
    }
    let cov = &b_inv * mid * b_inv.transpose();
    let sigma: Vec<f64> = (0..cols)
        .map(|j| {
            if null[j] {
                f64::INFINITY
            } else {
                cov[(j, j)].sqrt()
            }
        })
        .collect();
    let corr = (0..cols)
        .map(|a| {
            (0..cols)
                .map(|b| {
                    if null[a] || null[b] {
                        f64::NAN
                    } else {
                        cov[(a, b)] / (sigma[a] * sigma[b])
                    }
                })
                .collect()
        })
        .collect();
    (sigma, corr)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// The covariance and pseudo-covariance of the fit's residual `r = <conj(w) e> + S_mm G`
    /// (`e = y - G w`) over `n` independent complex Gaussian averages, by Monte Carlo against
    /// the closed form the fit whitens with: `Gamma = S_ww S_ee / n`, `C = (S_mm G)^2 / n`.
    /// The whitened real and imaginary parts have unit variance and no correlation, within the
    /// Monte Carlo error (3 sigma of 20000 draws, about 0.03); without `C` they would not
    /// (here the variances would be 1.27 and 0.73).
    #[test]
    fn residual_covariance_includes_the_witness_noise_pseudo_covariance() {
        let (stt, smm, snn, n) = (2.0, 1.0, 0.5, 12usize);
        let g = Complex64::from_polar(1.5, 0.7);
        let mut rng = Rng::stream(11, 0);
        let mut cn = |var: f64| {
            let s = (var / 2.0).sqrt();
            Complex64::new(s * rng.gaussian(), s * rng.gaussian())
        };
        let sww = DMatrix::from_element(1, 1, Complex64::new(stt + smm, 0.0));
        let see = snn + g.norm_sqr() * smm;
        let c = DVector::from_element(1, -(g * smm));
        let w = whitener(&sww, see, n as f64, Some(&c));
        let draws = 20_000;
        let mut m = DMatrix::<f64>::zeros(2, 2);
        for _ in 0..draws {
            let mut r = Complex64::new(0.0, 0.0);
            for _ in 0..n {
                let t = cn(stt);
                let (mm, nn) = (cn(smm), cn(snn));
                let wv = t + mm;
                let y = g * t + nn;
                r += wv.conj() * (y - g * wv);
            }
            r = r / n as f64 + g * smm;
            let z = &w * real_parts(&DVector::from_element(1, r));
            m += &z * z.transpose() / draws as f64;
        }
        for i in 0..2 {
            for j in 0..2 {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((m[(i, j)] - want).abs() < 0.03, "{m}");
            }
        }
    }
}
