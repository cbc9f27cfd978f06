//! Helpers shared by the integration tests of every crate: paths inside the repository, JSON
//! fixtures, a named-tolerance comparison, the damped test model, and synthetic records made
//! through the model's transfer functions. The command line's test binary includes this file
//! too (`tests/it/common.rs`), so it depends on `tiltnoise-core` (and its `realfft` and
//! `num-complex`) and the standard library only.
// Each test binary uses a different subset of these helpers.
#![allow(dead_code)]

use std::path::PathBuf;
use tiltnoise_core::params::Params;

/// A path inside the repository (`crate::REPO_ROOT` is the repository root of the test binary
/// that includes this file).
pub fn repo(rel: &str) -> PathBuf {
    PathBuf::from(crate::REPO_ROOT).join(rel)
}

/// Reads a JSON fixture.
pub fn json(rel: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(repo(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
    serde_json::from_str(&text).unwrap()
}

/// A JSON array of numbers.
pub fn floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

/// `|got - want| <= rel * |want| + abs`, with a message naming what and where.
pub fn assert_close(what: &str, at: &str, got: f64, want: f64, rel: f64, abs: f64) {
    let tol = rel * want.abs() + abs;
    assert!(
        (got - want).abs() <= tol,
        "{what} at {at}: got {got:e}, want {want:e} (|diff| {:e} > tol {tol:e})",
        (got - want).abs()
    );
}

/// `p` with loss angle `loss_rad` on both torsions and both bouncings (the damped test model
/// of the transfer-function tests).
pub fn with_torsion_and_bouncing_loss(p: Params, loss_rad: f64) -> Params {
    let mut p = p;
    for key in [
        "torsion_a_rad",
        "torsion_b_rad",
        "bouncing_a_rad",
        "bouncing_b_rad",
    ] {
        p = p.with_override(&format!("loss.{key}={loss_rad}")).unwrap();
    }
    p
}

/// Coloured Gaussian noise: white noise through `y[n] = a y[n-1] + x[n]`, after a burn-in of
/// 200 samples.
pub fn coloured(rng: &mut tiltnoise_core::rng::Rng, n: usize, a: f64) -> Vec<f64> {
    let mut y = 0.0;
    (0..n + 200)
        .map(|_| {
            y = a * y + rng.gaussian();
            y
        })
        .skip(200)
        .collect()
}

/// `x` filtered through `h(f)` on the circular grid of the whole record (exact for a periodic
/// record): `IFFT(h(f_k) FFT(x))` with `h` of the `exp(+i w t)` convention, DC set to 0.
pub fn filter_circular(x: &[f64], fs: f64, h: impl Fn(f64) -> num_complex::Complex64) -> Vec<f64> {
    let n = x.len();
    let mut planner = realfft::RealFftPlanner::<f64>::new();
    let mut input = x.to_vec();
    let forward = planner.plan_fft_forward(n);
    let mut spectrum = forward.make_output_vec();
    forward.process(&mut input, &mut spectrum).unwrap();
    for (k, z) in spectrum.iter_mut().enumerate() {
        let f = k as f64 * fs / n as f64;
        *z = if k == 0 {
            num_complex::Complex64::new(0.0, 0.0)
        } else {
            *z * h(f) / n as f64
        };
    }
    if n % 2 == 0 {
        let last = spectrum.len() - 1;
        spectrum[last].im = 0.0;
    }
    let mut out = vec![0.0; n];
    planner
        .plan_fft_inverse(n)
        .process(&mut spectrum, &mut out)
        .unwrap();
    out
}

/// Two-axis tilt at 1 Hz (rad; theta_t and eta_t correlated, red spectra of about 1e-8
/// rad/sqrt(Hz) at 10 mHz) and the model's response in `outputs` to `gain` times it, sampled
/// `advance_s` late (`y(t_k + advance_s)`), plus white readout noise of one-sided ASD
/// `readout[o]` (unit/sqrt(Hz)). Deterministic for a `seed`.
pub fn through_model(
    model: &tiltnoise_core::model::Model,
    n: usize,
    outputs: &[tiltnoise_core::model::Observable],
    readout: &[f64],
    gain: f64,
    advance_s: f64,
    seed: u64,
) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    use tiltnoise_core::model::{Input, Request, TiltAxis};
    let fs = 1.0;
    let mut rng = tiltnoise_core::rng::Rng::stream(seed, 0);
    let common = coloured(&mut rng, n, 0.95);
    let own = coloured(&mut rng, n, 0.95);
    let eta: Vec<f64> = common.iter().map(|v| 1e-8 * v).collect();
    let theta: Vec<f64> = common
        .iter()
        .zip(&own)
        .map(|(c, o)| 1e-8 * (0.4 * c + o))
        .collect();
    let grid: Vec<f64> = (1..=n / 2).map(|k| k as f64 * fs / n as f64).collect();
    let request = Request {
        outputs: outputs.to_vec(),
        inputs: vec![Input::Tilt(TiltAxis::ThetaT), Input::Tilt(TiltAxis::EtaT)],
    };
    let plan =
        tiltnoise_core::tf::plan(model, &request, tiltnoise_core::tf::Method::PoleZero).unwrap();
    let h = tiltnoise_core::tf::evaluate(plan.as_ref(), &grid).unwrap();
    let measured = (0..outputs.len())
        .map(|o| {
            let at = |f: f64, i: usize| {
                let k = (f * n as f64 / fs).round() as usize;
                let advance = num_complex::Complex64::from_polar(
                    1.0,
                    2.0 * std::f64::consts::PI * f * advance_s,
                );
                gain * h.get(k - 1, o, i) * advance
            };
            let from_theta = filter_circular(&theta, fs, |f| at(f, 0));
            let from_eta = filter_circular(&eta, fs, |f| at(f, 1));
            let sigma = readout[o] * (fs / 2.0).sqrt();
            (0..n)
                .map(|k| from_theta[k] + from_eta[k] + sigma * rng.gaussian())
                .collect()
        })
        .collect();
    (vec![theta, eta], measured)
}
