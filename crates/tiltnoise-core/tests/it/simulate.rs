//! Exact free-motion simulation (src/simulate/): stability against explicit integrators,
//! exactness against closed form and matrix exponential, spectra vs the observability table,
//! the X kick, errors and timing.

use crate::tolerances::EPS;
use nalgebra::SMatrix;
use tiltnoise_core::model::{Model, Observable, Vec8};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::Params;
use tiltnoise_core::simulate::resonance::{check_resonances, Presence, PEAK_FACTOR};
use tiltnoise_core::simulate::{
    aliased_frequency_hz, kick_x, simulate, InitialState, ModalPropagator, SimConfig, SimError,
};
use tiltnoise_core::simulate::{equal_energy_init, DEFAULT_MODE_ENERGY_J};
use tiltnoise_core::spectral::{welch, WelchConfig};

fn model() -> Model {
    Model::new(&Params::table_i()).unwrap()
}

/// Generic initial conditions exciting all eight modes.
fn generic_init() -> InitialState {
    InitialState {
        q: [2e-5, -3e-5, 4e-4, 1e-8, -2.5e-5, 1.5e-5, -3e-4, -2e-8],
        qdot: [1e-5, 2e-5, -1e-6, 3e-7, -1e-5, 2e-5, 5e-7, 2e-7],
    }
}

fn energy(m: &SMatrix<f64, 8, 8>, k: &SMatrix<f64, 8, 8>, q: &Vec8, qd: &Vec8) -> f64 {
    0.5 * (qd.transpose() * m * qd)[(0, 0)] + 0.5 * (q.transpose() * k * q)[(0, 0)]
}

#[test]
fn explicit_integrators_blow_up_exact_propagation_does_not() {
    let model = model();
    let modes = NormalModes::new(&model);
    let (m, k) = (*model.mass(), model.stiffness());
    let minv_k = m.try_inverse().unwrap() * k;
    let dt = 0.1;
    for idx in [6usize, 7] {
        let mode = &modes.modes[idx];
        let w = mode.omega_sq.sqrt();
        println!(
            "nu_{} = {:.4} Hz: w dt = {:.3} (leapfrog needs < 2)",
            mode.index,
            mode.frequency_hz,
            w * dt
        );
        assert!(w * dt > 2.0);
        let q0 = mode.shape * 1e-6;
        let e0 = energy(&m, &k, &q0, &Vec8::zeros());
        // Forward Euler.
        let (mut q, mut qd) = (q0, Vec8::zeros());
        let mut euler_steps = None;
        for n in 1..=100 {
            let acc = -(minv_k * q);
            q += qd * dt;
            qd += acc * dt;
            if energy(&m, &k, &q, &qd) > 1e6 * e0 {
                euler_steps = Some(n);
                break;
            }
        }
        // Leapfrog (kick-drift-kick, symplectic).
        let (mut q, mut qd) = (q0, Vec8::zeros());
        let mut leapfrog_steps = None;
        for n in 1..=100 {
            qd -= (minv_k * q) * (0.5 * dt);
            q += qd * dt;
            qd -= (minv_k * q) * (0.5 * dt);
            if energy(&m, &k, &q, &qd) > 1e6 * e0 {
                leapfrog_steps = Some(n);
                break;
            }
        }
        println!(
            "  energy x1e6 after: forward Euler {euler_steps:?} steps, leapfrog {leapfrog_steps:?} steps"
        );
        assert!(euler_steps.is_some() && leapfrog_steps.is_some());
    }

    // Exact modal propagation over 12 h: each modal energy conserved to rounding. Per step the
    // rotation by the rounded (c, s) changes the squared norm by at most |c^2 + s^2 - 1| <= 2 eps
    // plus the rounding of two products and a sum per component (<= 2 eps relative each, twice
    // for the square): bound 8 eps per step, 8 N eps over N steps.
    let n_steps = 432_000u64;
    let mut p = ModalPropagator::new(&model, &generic_init(), dt).unwrap();
    let e0 = p.modal_energy();
    for _ in 0..n_steps {
        p.step();
    }
    let e1 = p.modal_energy();
    let bound = 8.0 * n_steps as f64 * EPS;
    let worst = (0..8)
        .map(|k| ((e1[k] - e0[k]) / e0[k]).abs())
        .fold(0.0, f64::max);
    println!("exact propagation, 432000 steps: worst modal energy change {worst:.2e} (bound {bound:.2e})");
    assert!(worst <= bound);
}

/// Closed-form modal solution at step n, evaluated directly (independently of the library's
/// recurrence): a_k(t) = a_k0 cos(w t) + adot_k0 / w sin(w t), q = V a.
fn closed_form(model: &Model, init: &InitialState, t: f64) -> ([f64; 8], Vec<f64>) {
    let modes = NormalModes::new(model);
    let m = model.mass();
    let (mq, mqd) = (m * Vec8::from(init.q), m * Vec8::from(init.qdot));
    let mut q = Vec8::zeros();
    let mut amp = Vec::new();
    for mode in &modes.modes {
        let w = mode.omega_sq.sqrt();
        let (a0, b0) = (mode.shape.dot(&mq), mode.shape.dot(&mqd) / w);
        q += mode.shape * (a0 * (w * t).cos() + b0 * (w * t).sin());
        amp.push(a0.hypot(b0));
    }
    (std::array::from_fn(|i| q[i]), amp)
}

#[test]
fn simulation_matches_closed_form_and_long_run_drift_is_bounded() {
    let model = model();
    let modes = NormalModes::new(&model);
    let init = generic_init();
    let cfg = SimConfig::noiseless();
    let sim = simulate(&model, &init, &cfg).unwrap();
    assert_eq!(sim.len(), 432_000);
    for n in [0usize, 1, 10, 1000, 100_000, 431_999] {
        let t = n as f64 * cfg.dt_s;
        let (q_ref, amp) = closed_form(&model, &init, t);
        for (i, &qr) in q_ref.iter().enumerate() {
            // Per mode: recurrence drift <= 8 eps per step (amplitude and phase), plus the
            // rounding of the rotation angle fl(w dt) accumulated over n steps and of w t in the
            // direct evaluation (each <= eps w t), plus a few eps for the reconstruction.
            let tol: f64 = modes
                .modes
                .iter()
                .zip(&amp)
                .map(|(mode, a)| {
                    let w = mode.omega_sq.sqrt();
                    mode.shape[i].abs()
                        * a
                        * (8.0 * n as f64 * EPS + 2.0 * EPS * w * t + 16.0 * EPS)
                })
                .sum();
            let err = (sim.q[n][i] - qr).abs();
            assert!(err <= tol, "n {n} coord {i}: err {err:e} tol {tol:e}");
            if n == 431_999 && i == 3 {
                println!("t = {t} s, delta_a: |sim - closed form| = {err:.2e} (tol {tol:.2e}, value {:.3e})", qr);
            }
        }
    }

    // Drift of the recurrence alone, against a direct evaluation of cos/sin at the same total
    // angle n fl(w dt), formed exactly with a two-product so the reference has O(eps) error.
    let dt = 0.1;
    let mut p = ModalPropagator::new(&model, &init, dt).unwrap();
    let n = 432_000u64;
    for _ in 0..n {
        p.step();
    }
    let (u, v) = p.modal_state();
    let (u0, v0) = p.initial_modal_state();
    let mut worst: f64 = 0.0;
    for k in 0..8 {
        let theta = p.omega()[k] * dt;
        let hi = n as f64 * theta;
        let lo = (n as f64).mul_add(theta, -hi);
        let (s, c) = hi.sin_cos();
        let (cr, sr) = (c - lo * s, s + lo * c);
        let (ur, vr) = (u0[k] * cr + v0[k] * sr, v0[k] * cr - u0[k] * sr);
        let amp = u0[k].hypot(v0[k]);
        let e = ((u[k] - ur).hypot(v[k] - vr)) / amp;
        worst = worst.max(e);
    }
    let bound = 8.0 * n as f64 * EPS;
    println!(
        "recurrence drift over {n} steps: {worst:.2e} relative (sqrt(N) eps = {:.2e}, bound 8 N eps = {bound:.2e})",
        (n as f64).sqrt() * EPS
    );
    assert!(worst <= bound);
}

type M16 = SMatrix<f64, 16, 16>;

/// exp(A) by scaling and squaring with a degree-24 Taylor polynomial (||A / 2^s||_1 <= 1/2, so
/// the truncation term is below 0.5^25 / 25! ~ 2e-33).
fn expm(a: &M16) -> M16 {
    let norm = a
        .lp_norm(1)
        .max((0..16).map(|c| a.column(c).lp_norm(1)).fold(0.0, f64::max));
    let s = if norm > 0.5 {
        (norm / 0.5).log2().ceil() as i32
    } else {
        0
    };
    let b = a / 2f64.powi(s);
    let mut term = M16::identity();
    let mut sum = M16::identity();
    for j in 1..=24 {
        term = term * b / j as f64;
        sum += term;
    }
    for _ in 0..s {
        sum = sum * sum;
    }
    sum
}

#[test]
fn simulation_matches_matrix_exponential_at_10_s() {
    let model = model();
    let init = generic_init();
    let (m, k) = (*model.mass(), model.stiffness());
    let minv_k = m.try_inverse().unwrap() * k;
    let mut a = M16::zeros();
    for i in 0..8 {
        a[(i, 8 + i)] = 1.0;
        for j in 0..8 {
            a[(8 + i, j)] = -minv_k[(i, j)];
        }
    }
    let t = 10.0;
    let e = expm(&(a * t));
    let y0 =
        nalgebra::SVector::<f64, 16>::from_fn(
            |i, _| if i < 8 { init.q[i] } else { init.qdot[i - 8] },
        );
    let y = e * y0;
    let cfg = SimConfig {
        duration_s: 10.1,
        ..SimConfig::noiseless()
    };
    let sim = simulate(&model, &init, &cfg).unwrap();
    assert_eq!(sim.len(), 101);
    let q_sim = sim.q[100];
    // Scale of each coordinate over the run, so angles and elongations are compared on their own
    // footing.
    let scale: Vec<f64> = (0..8)
        .map(|i| sim.q.iter().map(|q| q[i].abs()).fold(0.0, f64::max))
        .collect();
    let worst = (0..8)
        .map(|i| (q_sim[i] - y[i]).abs() / scale[i])
        .fold(0.0, f64::max);
    // Scaling and squaring in f64: s squarings of an approximation with relative error ~eps each
    // amplify the error to about eps ||A t||_1 (Higham, Functions of Matrices, ch. 10), times the
    // conditioning of the mode basis in mixed units, which we bound by 100.
    let at_norm = (0..16)
        .map(|c| (a * t).column(c).lp_norm(1))
        .fold(0.0, f64::max);
    let tol = 100.0 * EPS * at_norm;
    println!("expm at t = 10 s: ||A t||_1 = {at_norm:.3e}, worst relative difference {worst:.2e} (tol {tol:.2e})");
    assert!(worst <= tol);
}

/// Equal modal amplitude `a` (mass-normalized units, sqrt(kg m^2) or sqrt(kg) m) in every mode,
/// with assorted phases: the spectral peak heights are then proportional to the observable
/// amplitudes `C v_k` the observability table is built from.
fn equal_modal_init(model: &Model, a: f64) -> InitialState {
    let modes = NormalModes::new(model);
    let mut q = Vec8::zeros();
    let mut qd = Vec8::zeros();
    for (k, mode) in modes.modes.iter().enumerate() {
        let phase = 0.7 + 1.3 * k as f64;
        q += mode.shape * (a * phase.cos());
        qd += mode.shape * (a * mode.omega_sq.sqrt() * phase.sin());
    }
    InitialState {
        q: std::array::from_fn(|i| q[i]),
        qdot: std::array::from_fn(|i| qd[i]),
    }
}

/// Bin nearest to `f` on a Welch grid of spacing `df`.
fn bin(f: f64, df: f64) -> usize {
    (f / df).round() as usize
}

/// A resonance peak near bin `k0`: the largest local maximum of `asd` within +/- 2 bins (the
/// Hann main lobe) and its ratio to the median of the neighbourhood 8 to 40 bins away on both
/// sides (DC and bin 1 excluded). Returns `(peak height, ratio)`, `(0, 0)` without a local max.
fn peak(asd: &[f64], k0: usize) -> (f64, f64) {
    let mut best: f64 = 0.0;
    for k in k0.saturating_sub(2).max(1)..=(k0 + 2).min(asd.len() - 2) {
        if asd[k] > 0.0 && asd[k] >= asd[k - 1] && asd[k] >= asd[k + 1] {
            best = best.max(asd[k]);
        }
    }
    let mut nb: Vec<f64> = (k0.saturating_sub(40)..k0.saturating_sub(7))
        .chain(k0 + 8..(k0 + 41).min(asd.len()))
        .filter(|&k| k >= 2)
        .map(|k| asd[k])
        .collect();
    nb.sort_by(f64::total_cmp);
    let median = nb[nb.len() / 2];
    if best == 0.0 {
        (0.0, 0.0)
    } else {
        (best, best / median)
    }
}

#[test]
fn spectra_show_exactly_the_modes_of_the_observability_table() {
    let model = model();
    let modes = NormalModes::new(&model);
    let init = equal_modal_init(&model, 1e-5);
    let sim = simulate(&model, &init, &SimConfig::noiseless()).unwrap();
    let fs = sim.fs_hz();
    // 2^17-sample segments (3.6 h, df = 76 uHz): nu_1 = 1.31 mHz and nu_2 = 2.20 mHz fall 12
    // bins apart, nu_3 and nu_4 (different blocks) 12 bins apart. The 7.74 and 10.81 Hz bouncing
    // modes are above Nyquist (5 Hz) and are looked for at their aliases 2.26 and 0.81 Hz.
    let cfg = WelchConfig::new(1 << 17);
    for o in Observable::ALL {
        let psd = welch(sim.observable(o), fs, &cfg).unwrap();
        let df = psd.freqs_hz[1];
        let asd = psd.asd();
        let peaks: Vec<(f64, f64)> = modes
            .modes
            .iter()
            .map(|m| peak(&asd, bin(aliased_frequency_hz(m.frequency_hz, fs), df)))
            .collect();
        let highest = peaks
            .iter()
            .filter(|p| p.1 > PEAK_FACTOR)
            .map(|p| p.0)
            .fold(0.0, f64::max);
        for (k, mode) in modes.modes.iter().enumerate() {
            let (height, ratio) = peaks[k];
            let rel = height / highest;
            let visible = modes.visible[k][o.index()];
            let structural = mode
                .block
                .expect("the symmetric pendulum is decoupled")
                .coords()
                .iter()
                .all(|c| model.observation()[(o.index(), c.index())] == 0.0);
            println!(
                "{:>5} nu_{}: peak/neighbours {:9.2e}, height rel. to channel max {:8.1e}, table: {}{}",
                o.name(),
                mode.index,
                ratio,
                rel,
                if visible { "seen" } else { "not seen" },
                if structural { " (structural zero)" } else { "" }
            );
            if structural {
                assert!(!visible);
                assert_eq!(mode.observable_amplitude[o.index()], 0.0);
                assert!(
                    ratio < PEAK_FACTOR,
                    "{} nu_{}: spurious peak",
                    o.name(),
                    mode.index
                );
            } else if visible {
                // Seen: a peak, at least the table's 1e-3 of the channel's largest (times the
                // Hann scalloping loss, at worst 0.85 at half a bin; ASD heights are
                // proportional to |C v_k| with equal modal amplitudes).
                assert!(
                    ratio > PEAK_FACTOR,
                    "{} nu_{}: no peak",
                    o.name(),
                    mode.index
                );
                assert!(rel >= 0.85 * tiltnoise_core::modes::VISIBILITY_THRESHOLD);
            } else {
                // Not seen within the block: either no peak or one below the threshold.
                assert!(
                    ratio < PEAK_FACTOR || rel < tiltnoise_core::modes::VISIBILITY_THRESHOLD / 0.85,
                    "{} nu_{}: peak {rel:e} of the channel max",
                    o.name(),
                    mode.index
                );
            }
        }
    }
}

#[test]
fn readout_noise_sets_the_floor_far_from_the_modes() {
    let model = model();
    let init = equal_modal_init(&model, 1e-6);
    let cfg = SimConfig::default();
    assert_eq!(cfg.readout_asd, vec![(Observable::X, 9e-9)]);
    let sim = simulate(&model, &init, &cfg).unwrap();
    let clean = simulate(&model, &init, &SimConfig::noiseless()).unwrap();
    // Same seed, same series; another seed, another series.
    let again = simulate(&model, &init, &cfg).unwrap();
    assert_eq!(
        sim.observable(Observable::X),
        again.observable(Observable::X)
    );
    let other = simulate(
        &model,
        &init,
        &SimConfig {
            seed: 1,
            ..cfg.clone()
        },
    )
    .unwrap();
    assert_ne!(
        sim.observable(Observable::X),
        other.observable(Observable::X)
    );
    // Only X is noisy.
    for o in Observable::ALL.into_iter().skip(1) {
        assert_eq!(sim.observable(o), clean.observable(o));
    }
    assert_eq!(sim.q, clean.q);

    // Per-sample variance a^2 fs / 2, within 5 standard errors sqrt(2 / N).
    let a = 9e-9;
    let fs = sim.fs_hz();
    let noise: Vec<f64> = sim
        .observable(Observable::X)
        .iter()
        .zip(clean.observable(Observable::X))
        .map(|(x, c)| x - c)
        .collect();
    let n = noise.len() as f64;
    let var = noise.iter().map(|x| x * x).sum::<f64>() / n;
    let expected_var = a * a * fs / 2.0;
    println!(
        "noise variance / (a^2 fs / 2) = {:.5} (5 sigma = {:.5})",
        var / expected_var,
        5.0 * (2.0 / n).sqrt()
    );
    assert!((var / expected_var - 1.0).abs() < 5.0 * (2.0 / n).sqrt());

    // Welch ASD of X with 2^15-sample segments (25 of them) over 3 - 4.5 Hz, far from X's
    // resonances (<= 0.62 Hz; the bouncing modes X does not see): equals the readout ASD.
    let psd = welch(
        sim.observable(Observable::X),
        fs,
        &WelchConfig::new(1 << 15),
    )
    .unwrap();
    let band: Vec<f64> = psd
        .freqs_hz
        .iter()
        .zip(&psd.psd)
        .filter(|(f, _)| (3.0..=4.5).contains(*f))
        .map(|(_, p)| *p)
        .collect();
    let b = band.len() as f64;
    let mean = band.iter().sum::<f64>() / b;
    let sd = (band.iter().map(|p| (p - mean).powi(2)).sum::<f64>() / (b - 1.0)).sqrt();
    // Standard error of the band mean: the bins' own scatter over sqrt(B / 2) (adjacent Hann
    // bins are correlated, so count only every other bin as independent).
    let se = sd / (b / 2.0).sqrt();
    let ratio = mean / (a * a);
    println!(
        "X ASD over 3-4.5 Hz: {:.4e} m/sqrt(Hz) vs readout {a:e} (PSD ratio {ratio:.4}, per-bin scatter {:.3}, 5 s.e. {:.4}, {} segments)",
        mean.sqrt(),
        sd / mean,
        5.0 * se / (a * a),
        psd.n_segments
    );
    assert!((ratio - 1.0).abs() < 5.0 * se / (a * a));
    // Per-bin scatter of a mean of K segments: about 1/sqrt(K) (slightly above with overlap).
    assert!(sd / mean < 1.5 / (psd.n_segments as f64).sqrt());
}

#[test]
fn kick_along_x_rings_at_nu_1_and_nu_2() {
    let model = model();
    let modes = NormalModes::new(&model);
    let init = kick_x(&model, 1e-4);
    assert_eq!(init.qdot, [0.0; 8]);
    let c = model.observation();
    let x0 = (c.row(Observable::X.index()) * Vec8::from(init.q))[(0, 0)];
    assert!((x0 - 1e-4).abs() <= 4.0 * EPS * 1e-4, "X(0) = {x0:e}");
    let sim = simulate(&model, &init, &SimConfig::noiseless()).unwrap();
    let x = sim.observable(Observable::X);
    let phi = sim.observable(Observable::Phi);
    assert!((x[0] - 1e-4).abs() <= 4.0 * EPS * 1e-4);
    // A force along x moves only the swing-x + torsion block: Y, Z, theta stay exactly 0.
    for o in [Observable::Y, Observable::Z, Observable::Theta] {
        assert!(sim.observable(o).iter().all(|&v| v == 0.0));
    }
    let (xmin, xmax) = x
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    let (pmin, pmax) = phi
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    println!("kick X = 1e-4 m: phi(0) = {:.3e} rad, X in [{xmin:.3e}, {xmax:.3e}] m, phi in [{pmin:.3e}, {pmax:.3e}] rad", phi[0]);
    let fs = sim.fs_hz();
    let cfg = WelchConfig::new(1 << 17);
    for (name, series) in [("X", x), ("phi", phi)] {
        let psd = welch(series, fs, &cfg).unwrap();
        let asd = psd.asd();
        let df = psd.freqs_hz[1];
        for k in [0usize, 1] {
            let (h, r) = peak(&asd, bin(modes.modes[k].frequency_hz, df));
            println!(
                "  {name}: nu_{} peak {h:.3e}, peak/neighbours {r:.2e}",
                k + 1
            );
            assert!(r > PEAK_FACTOR, "{name} does not ring at nu_{}", k + 1);
        }
    }
    // Torsion dominates phi: the largest value of the phi spectrum is at nu_1 or nu_2.
    let psd = welch(phi, fs, &cfg).unwrap();
    let kmax = (1..psd.psd.len())
        .max_by(|&a, &b| psd.psd[a].total_cmp(&psd.psd[b]))
        .unwrap();
    let fmax = psd.freqs_hz[kmax];
    println!("  phi spectrum maximum at {fmax:.4e} Hz");
    assert!(modes.modes[..2]
        .iter()
        .any(|m| (m.frequency_hz - fmax).abs() <= 2.0 * psd.freqs_hz[1]));
}

#[test]
fn invalid_settings_are_refused_with_the_value() {
    let model = model();
    let init = generic_init();
    let run = |cfg: SimConfig| simulate(&model, &init, &cfg).unwrap_err();
    let base = SimConfig::noiseless();
    let e = run(SimConfig {
        dt_s: 0.0,
        ..base.clone()
    });
    assert!(
        matches!(e, SimError::InvalidStep { .. }) && e.to_string().contains("dt = 0 s"),
        "{e}"
    );
    let e = run(SimConfig {
        dt_s: f64::NAN,
        ..base.clone()
    });
    assert!(matches!(e, SimError::InvalidStep { .. }), "{e}");
    let e = run(SimConfig {
        duration_s: -1.0,
        ..base.clone()
    });
    assert!(
        e.to_string().contains("-1") && e.to_string().contains("> 0"),
        "{e}"
    );
    let e = run(SimConfig {
        duration_s: f64::INFINITY,
        ..base.clone()
    });
    assert!(matches!(e, SimError::InvalidDuration { .. }), "{e}");
    let e = run(SimConfig {
        duration_s: 0.15,
        ..base.clone()
    });
    assert!(
        matches!(e, SimError::TooFewSamples { .. }) && e.to_string().contains("at least 2"),
        "{e}"
    );
    let e = run(SimConfig {
        dt_s: 1e-6,
        duration_s: 1e4,
        ..base.clone()
    });
    assert!(
        matches!(e, SimError::TooLarge(_))
            && e.to_string().contains("dt = 1e-6 s: ")
            && e.to_string()
                .contains("samples, more than the 16777216 allowed"),
        "{e}"
    );
    let e = run(SimConfig {
        readout_asd: vec![(Observable::Phi, -1.0)],
        ..base.clone()
    });
    assert!(
        e.to_string().contains("phi") && e.to_string().contains(">= 0"),
        "{e}"
    );
    let mut bad = init;
    bad.qdot[5] = f64::NAN;
    let e = simulate(&model, &bad, &base).unwrap_err();
    assert!(
        matches!(e, SimError::InitialOutOfRange { .. })
            && e.to_string().contains("initial rate of eta_b = NaN"),
        "{e}"
    );
    let mut far = init;
    far.q[2] = 1e300;
    let e = simulate(&model, &far, &base).unwrap_err();
    assert!(
        e.to_string().contains("initial value of phi_a = 1e300 rad"),
        "{e}"
    );
    let mut p = Params::table_i();
    p.loss.torsion_b_rad = 1e-3;
    let damped = Model::new(&p).unwrap();
    let e = simulate(&damped, &init, &base).unwrap_err();
    assert_eq!(e, SimError::Damped);
    println!(
        "example messages: {}",
        run(SimConfig {
            duration_s: 0.15,
            ..base
        })
    );
}

/// The default run of `tiltnoise simulate` (equal energy per mode, 12 h at 0.1 s, X readout
/// 9 nm/sqrt(Hz), Welch 2^17): modal amplitudes and the PSDs of the seven channels.
fn default_run() -> (
    NormalModes,
    [f64; 8],
    Vec<(Observable, tiltnoise_core::spectral::Psd)>,
) {
    let model = model();
    let init = equal_energy_init(&model, DEFAULT_MODE_ENERGY_J);
    let cfg = SimConfig::default();
    let sim = simulate(&model, &init, &cfg).unwrap();
    let p = ModalPropagator::new(&model, &init, cfg.dt_s).unwrap();
    // Equal energy in every mode. The modal decomposition of q = sum_k v_k a_k mixes the modes
    // of a block only through rounding: a relative error of a few eps times the ratio of the
    // largest modal amplitude in the block to this one (at most 1e5 here, torsion vs bouncing
    // are in different blocks; swing vs bounce within one), squared for the energy.
    let e = p.modal_energy();
    let (u0, v0) = p.initial_modal_state();
    let amp: [f64; 8] = std::array::from_fn(|k| u0[k].hypot(v0[k]));
    let a_max = amp.iter().copied().fold(0.0, f64::max);
    for k in 0..8 {
        let tol = 2.0 * 16.0 * EPS * a_max / amp[k];
        assert!(
            (e[k] / DEFAULT_MODE_ENERGY_J - 1.0).abs() <= tol,
            "nu_{}: energy {:e} (tol {tol:e})",
            k + 1,
            e[k]
        );
    }
    let wcfg = WelchConfig::new(1 << 17);
    let psds = sim
        .observables
        .iter()
        .map(|(o, x)| (*o, welch(x, sim.fs_hz(), &wcfg).unwrap()))
        .collect();
    (NormalModes::new(&model), amp, psds)
}

#[test]
fn resonance_check_agrees_with_the_table_on_the_default_run() {
    let (modes, amp, psds) = default_run();
    let readout = SimConfig::default().readout_asd;
    let check = check_resonances(&modes, &amp, &psds, 10.0, 1 << 17, &readout);
    print!("{}", check.table());
    for c in &check.channels {
        for m in &c.modes {
            println!(
                "{:>5} nu_{}: table {:>8} ratio {:8.2e} | spectrum {:>8} ratio {:8.2e}, peak/floor {:8.2e}",
                c.observable.name(),
                m.mode_index,
                if m.table_seen { "seen" } else { "not seen" },
                m.table_ratio,
                m.spectrum.name(),
                m.spectrum_ratio,
                m.peak_ratio
            );
        }
    }
    // Every (channel, mode) pair is testable in the default run, and all agree.
    assert_eq!(check.n_tested(), 56);
    assert!(check.all_agree(), "{:?}", check.disagreements());
    // The threshold matters: within a block some modes the table does not see show genuine
    // peaks (well above the local floor) that are below 1e-3 of the channel's largest, as the
    // table's own ratio says.
    let tiny_peaks: Vec<_> = check
        .channels
        .iter()
        .flat_map(|c| c.modes.iter().map(move |m| (c.observable, m)))
        .filter(|(_, m)| !m.table_seen && m.table_ratio > 0.0 && m.peak_ratio > PEAK_FACTOR)
        .collect();
    assert!(!tiny_peaks.is_empty());
    for (o, m) in &tiny_peaks {
        assert_eq!(
            m.spectrum,
            Presence::NotSeen,
            "{} nu_{}",
            o.name(),
            m.mode_index
        );
        assert!(m.spectrum_ratio < tiltnoise_core::modes::VISIBILITY_THRESHOLD);
    }
}

#[test]
fn resonance_check_reports_a_wrong_table() {
    let (mut modes, amp, psds) = default_run();
    let readout = SimConfig::default().readout_asd;
    // Claim that X does not see nu_6 and that Y sees nu_1: both must be reported.
    modes.visible[5][Observable::X.index()] = false;
    modes.visible[0][Observable::Y.index()] = true;
    let check = check_resonances(&modes, &amp, &psds, 10.0, 1 << 17, &readout);
    let mut d = check.disagreements();
    d.sort_by_key(|(o, k)| (o.index(), *k));
    assert_eq!(d, vec![(Observable::X, 6), (Observable::Y, 1)]);
    assert!(check.table().contains("DISAGREES: X nu_6"));
}

/// Readout on several observables (one given twice), with the record's length odd so that a
/// block of normals starts in the middle of a Box-Muller pair.
fn noisy_config() -> SimConfig {
    SimConfig {
        dt_s: 0.1,
        duration_s: 100.1,
        readout_asd: vec![
            (Observable::X, 9e-9),
            (Observable::Phi, 0.0),
            (Observable::Theta, 1e-9),
            (Observable::X, 2e-9),
            (Observable::PhiA, 3e-10),
        ],
        seed: 11,
        ..SimConfig::default()
    }
}

/// The readout noise is the `j`-th block of `n` normals of stream 0 for the `j`-th noisy entry,
/// added entry after entry: drawn here sequentially, independently of the library's skipping.
#[test]
fn readout_noise_is_one_block_of_the_seed_stream_per_noisy_entry() {
    let model = model();
    let init = generic_init();
    let cfg = noisy_config();
    let noisy = simulate(&model, &init, &cfg).unwrap();
    let clean = simulate(
        &model,
        &init,
        &SimConfig {
            readout_asd: Vec::new(),
            ..cfg.clone()
        },
    )
    .unwrap();
    let n = clean.len();
    assert_eq!(
        n % 2,
        1,
        "an odd length puts a block boundary inside a pair"
    );
    let mut expected: Vec<Vec<f64>> = clean.observables.iter().map(|(_, x)| x.clone()).collect();
    let mut rng = tiltnoise_core::rng::Rng::stream(cfg.seed, 0);
    for &(o, asd) in &cfg.readout_asd {
        if asd == 0.0 {
            continue;
        }
        let sigma = asd * (0.5 / cfg.dt_s).sqrt();
        for x in &mut expected[o.index()] {
            *x += sigma * rng.gaussian();
        }
    }
    for ((o, got), want) in noisy.observables.iter().zip(&expected) {
        for (i, (g, w)) in got.iter().zip(want).enumerate() {
            assert_eq!(
                g.to_bits(),
                w.to_bits(),
                "{} sample {i}: {g} vs {w}",
                o.name()
            );
        }
    }
}

/// Chunks of any length, crossing every boundary, give the one-shot record bit for bit.
#[test]
fn chunks_equal_the_whole_record() {
    use tiltnoise_core::simulate::stream::{FreeMotion, SimChunk};
    let model = model();
    let init = generic_init();
    let cfg = noisy_config();
    let whole = simulate(&model, &init, &cfg).unwrap();
    for (max_len, keep) in [
        (1, true),
        (7, false),
        (64, true),
        (1000, false),
        (5000, true),
    ] {
        let mut motion = FreeMotion::new(&model, &init, &cfg, keep).unwrap();
        assert_eq!(motion.len(), whole.len());
        let mut chunk = SimChunk::default();
        let mut at = 0;
        while motion.next_chunk(max_len, &mut chunk) {
            assert_eq!(chunk.start, at);
            assert!(chunk.len() <= max_len);
            for (o, x) in &whole.observables {
                let part = &x[at..at + chunk.len()];
                let got = chunk.observable(*o);
                assert!(
                    part.iter()
                        .zip(got)
                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                    "{} in the chunk at {at} of at most {max_len}",
                    o.name()
                );
            }
            match keep {
                true => assert_eq!(chunk.q, whole.q[at..at + chunk.len()]),
                false => assert!(chunk.q.is_empty()),
            }
            at += chunk.len();
        }
        assert_eq!(at, whole.len());
        assert!(chunk.is_empty());
    }
}
