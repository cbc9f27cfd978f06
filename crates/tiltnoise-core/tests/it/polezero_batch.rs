//! The pole-zero method's grid evaluation (`eval_grid_into`, chunks of frequencies in vector
//! lanes) against its point-by-point evaluation (`eval_into`) and against its own factored
//! form evaluated in double-double.
//!
//! * Batch = per point, bit for bit, on grids with f = 0, points at 1e-9 and 1e-6 relative from
//!   every pole and zero, points up to 1e5 Hz, every grid length up to three chunks (short
//!   last chunks) and every offset; also on two and three threads ([`eval_grid_threads`]).
//!   Undamped, damped, tilt, force and floor-translation requests. The same values in the plan's compact layout
//!   ([`evaluate`], [`evaluate_into`] on 1 to 3 threads, into a reused matrix), whose stored
//!   entries are exactly those the plan has factors for.
//! * The batch values against `gain s^p prod(z_j - s) / prod(lambda_k - s)` in double-double
//!   (the plan's own factors, at the same `s`): within the rounding bound of the f64 product
//!   form (derived below), structural zeros exactly 0.0.
//! * Errors: an exact undamped pole anywhere in a chunk (first lane, middle, last, a short last
//!   chunk, the other thread's half) gives the per-point path's error, the first in grid order,
//!   with the same frequency and rcond; likewise a negative, NaN or infinite frequency.

use crate::common;
use crate::tolerances::U;

use num_complex::Complex64;
use tiltnoise_core::error::TfError;
use tiltnoise_core::model::{ForceInput, Model, Observable};
use tiltnoise_core::params::Params;
use tiltnoise_core::reference::{CDd, Dd};
use tiltnoise_core::tf::{
    eval_grid_threads, evaluate, evaluate_into, plan, Destination, Input, Method, PoleZero,
    Request, TransferFunction,
};

const LOSS: f64 = 1e-3;

fn damped() -> Params {
    common::with_torsion_and_bouncing_loss(Params::table_i(), LOSS)
}

fn force_request() -> Request {
    let forces = [
        "F_a.x", "F_b.x", "F_b.y", "F_b.z", "M_a.z", "M_b.x", "M_b.y", "M_b.z",
    ];
    Request {
        outputs: Observable::ALL.to_vec(),
        inputs: forces
            .iter()
            .map(|n| Input::Force(ForceInput::from_name(n).unwrap()))
            .collect(),
    }
}

/// The coupled 8x8 system of a pendulum as built: the test mass's centre of mass 1 mm off
/// along x (some entries have complex zeros, in conjugate pairs).
fn as_built(p: Params) -> Params {
    p.with_override("asymmetry.tm_com_x_m=1e-3").unwrap()
}

/// (name, params, request).
fn cases() -> Vec<(&'static str, Params, Request)> {
    vec![
        ("Table I, tilt", Params::table_i(), Request::all_tilt()),
        ("Table I, loss 1e-3, tilt", damped(), Request::all_tilt()),
        ("Table I, forces", Params::table_i(), force_request()),
        ("Table I, loss 1e-3, forces", damped(), force_request()),
        (
            "Table I, translation",
            Params::table_i(),
            translation_request(),
        ),
        (
            "Table I, loss 1e-3, translation",
            damped(),
            translation_request(),
        ),
        (
            "as built, tilt",
            as_built(Params::table_i()),
            Request::all_tilt(),
        ),
        (
            "as built, loss 1e-3, forces",
            as_built(damped()),
            force_request(),
        ),
        (
            "as built, loss 1e-3, translation",
            as_built(damped()),
            translation_request(),
        ),
    ]
}

fn translation_request() -> Request {
    Request {
        outputs: Observable::ALL.to_vec(),
        inputs: Input::all_translations(),
    }
}

fn hz(s: f64) -> f64 {
    s.sqrt() / std::f64::consts::TAU
}

/// `s = w^2` as the kernel forms it from a frequency.
fn omega_sq(f: f64) -> f64 {
    (std::f64::consts::TAU * f).powi(2)
}

/// f = 0, a log grid 1e-6 .. 1e5 Hz, and points 1e-9 and 1e-6 relative from every pole and zero
/// of the undamped Table I (poles and zeros of the damped model lie within 1e-3 of these).
fn hard_grid() -> Vec<f64> {
    let n = 1500;
    let mut f: Vec<f64> = (0..=n)
        .map(|k| 1e-6 * 1e11_f64.powf(k as f64 / n as f64))
        .collect();
    f.push(0.0);
    for r in [Request::all_tilt(), force_request(), translation_request()] {
        for e in PoleZero::factors(&Params::table_i(), &r) {
            for z in e.poles.iter().chain(&e.zeros) {
                let f0 = hz(z.abs_f64());
                for rel in [1e-9, 1e-6] {
                    f.extend([f0 * (1.0 - rel), f0 * (1.0 + rel)]);
                }
            }
        }
    }
    f.sort_by(f64::total_cmp);
    f.dedup();
    f
}

fn per_point(tf: &dyn TransferFunction, freqs: &[f64]) -> Result<Vec<Complex64>, TfError> {
    let mut out = Vec::new();
    for &f in freqs {
        out.extend(tf.eval(f)?);
    }
    Ok(out)
}

fn batch(
    tf: &dyn TransferFunction,
    freqs: &[f64],
    threads: usize,
) -> Result<Vec<Complex64>, TfError> {
    let r = tf.request();
    let mut out =
        vec![Complex64::new(f64::NAN, f64::NAN); freqs.len() * r.outputs.len() * r.inputs.len()];
    eval_grid_threads(tf, freqs, &mut out, threads, Destination::Reused)?;
    Ok(out)
}

fn assert_bit_identical(
    name: &str,
    r: &Request,
    freqs: &[f64],
    got: &[Complex64],
    want: &[Complex64],
) {
    let nv = r.outputs.len() * r.inputs.len();
    assert_eq!(got.len(), want.len(), "{name}");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            g.re.to_bits() == w.re.to_bits() && g.im.to_bits() == w.im.to_bits(),
            "{name}: {}/{} at {} Hz: batch {g} vs per point {w}",
            r.outputs[(k % nv) / r.inputs.len()].name(),
            r.inputs[k % r.inputs.len()].name(),
            freqs[k / nv]
        );
    }
}

#[test]
fn batch_equals_per_point_bit_for_bit() {
    let freqs = hard_grid();
    for (name, params, request) in cases() {
        let model = Model::new(&params).unwrap();
        let tf = plan(&model, &request, Method::PoleZero).unwrap();
        let want = per_point(tf.as_ref(), &freqs).unwrap();
        for threads in [1, 2, 3] {
            let got = batch(tf.as_ref(), &freqs, threads).unwrap();
            assert_bit_identical(
                &format!("{name}, {threads} threads"),
                &request,
                &freqs,
                &got,
                &want,
            );
        }
        // The plan's own layout (structural zeros not stored, real values when every block
        // is real): the same values bit for bit, on 1, 2 and 3 threads, into a fresh matrix
        // and into a reused one that held another request on a longer grid.
        let m = evaluate(tf.as_ref(), &freqs).unwrap();
        assert_layout_matches_structure(name, &params, &request, &m);
        assert_bit_identical(
            &format!("{name}, evaluate"),
            &request,
            &freqs,
            &m.dense_values(),
            &want,
        );
        let other = plan(&model, &Request::all_tilt(), Method::Direct).unwrap();
        let long: Vec<f64> = freqs.iter().chain(&freqs).copied().collect();
        for threads in [1, 2, 3] {
            let mut reused = evaluate(other.as_ref(), &long).unwrap();
            evaluate_into(tf.as_ref(), &freqs, threads, &mut reused).unwrap();
            assert_eq!(reused, m, "{name}, evaluate_into on {threads} threads");
        }
        // Every length up to three chunks of 8 and every offset: full and short chunks, each
        // point in every lane.
        let nv = request.outputs.len() * request.inputs.len();
        let sub = &freqs[freqs.len() / 2..];
        for len in 1..=25 {
            for start in 0..8 {
                let f = &sub[start..start + len];
                let got = batch(tf.as_ref(), f, 1).unwrap();
                let w = &want[(freqs.len() / 2 + start) * nv..(freqs.len() / 2 + start + len) * nv];
                assert_bit_identical(
                    &format!("{name}, {len} points from {start}"),
                    &request,
                    f,
                    &got,
                    w,
                );
            }
        }
    }
}

/// The layout of a pole-zero matrix: an entry is stored exactly when the plan has factors for
/// it (some block reaches it), and the layout is real exactly when every factor is real.
fn assert_layout_matches_structure(
    name: &str,
    params: &Params,
    request: &Request,
    m: &tiltnoise_core::tf::TransferMatrix,
) {
    let factors = PoleZero::factors(params, request);
    let ni = request.inputs.len();
    let layout = m.layout();
    assert_eq!(layout.n_entries(), request.outputs.len() * ni, "{name}");
    for entry in 0..layout.n_entries() {
        let has = factors.iter().any(|f| f.output * ni + f.input == entry);
        assert_eq!(
            layout.is_structural_zero(entry),
            !has,
            "{name}: entry {entry}"
        );
    }
    // Real arithmetic: undamped, real gains, and zeros real or, in the coupled system (no
    // block), in conjugate pairs.
    let real = factors.iter().all(|f| {
        f.gain.im.is_zero()
            && f.poles.iter().all(|p| p.im.is_zero())
            && f.zeros
                .iter()
                .all(|z| z.im.is_zero() || (f.block.is_none() && f.zeros.contains(&z.conj())))
    });
    assert_eq!(layout.is_real(), real, "{name}");
}

/// Table I's 7x3 tilt matrix in the pole-zero layout: 11 of the 21 entries stored, real (88
/// bytes per frequency against 336 dense); damped: the same 11, complex.
#[test]
fn tilt_layout_of_table_i() {
    for (params, real) in [(Params::table_i(), true), (damped(), false)] {
        let model = Model::new(&params).unwrap();
        let tf = plan(&model, &Request::all_tilt(), Method::PoleZero).unwrap();
        let layout = tf.layout();
        assert_eq!(layout.n_stored(), 11);
        assert_eq!(layout.is_real(), real);
        assert_eq!(layout.n_planes(), if real { 11 } else { 22 });
        // The structural zeros are those of the model's block structure: X, eta, phi, phi_a
        // from theta_t; Y, Z, theta from eta_t and phi_t.
        let zeros: Vec<String> = (0..21)
            .filter(|&e| layout.is_structural_zero(e))
            .map(|e| {
                let r = tf.request();
                format!("{}/{}", r.outputs[e / 3].name(), r.inputs[e % 3].name())
            })
            .collect();
        assert_eq!(
            zeros,
            [
                "X/theta_t",
                "Y/eta_t",
                "Y/phi_t",
                "Z/eta_t",
                "Z/phi_t",
                "theta/eta_t",
                "theta/phi_t",
                "eta/theta_t",
                "phi/theta_t",
                "phi_a/theta_t"
            ]
        );
    }
}

/// Rounding bound of the f64 product form, relative, at `s` (the double-double value uses
/// the same `s`, so only the kernel's arithmetic is measured). Each factor `1 - s / z` carries
/// the roundings of `1 / z`, of the product with `s`, of the sum and of its product into the
/// entry, `4 u` relative to `s / z`, i.e. `4 u (1 + |z| / |z - s|)` relative to the factor;
/// each `lambda - s` the rounding of `lambda` to f64, of the difference and of the product,
/// `3 u (1 + |lambda| / |lambda - s|)`; the gain (with `prod z`), the reciprocal, the
/// final product and the addition into the zeroed output `4 u`. A complex product's relative
/// error is at most `sqrt(5) u` against `u` for a real one, and a complex sum's `sqrt(2) u`:
/// a factor 3 covers both. A factor 2 over the first-order sum covers the second-order terms
/// and the few entries that receive two blocks' contributions.
///
/// The coupled system's real arithmetic takes its zeros two by two, `1 + c1 s + c2 s^2`
/// with `c1`, `c2` and `s^2` rounded (see the kernel): its absolute error is at most
/// `4 u (1 + |c1 s| + |c2| s^2) + u |q|`, and `1 + |c1 s| + |c2| s^2 <= (1 + |s / z_1|)
/// (1 + |s / z_2|)` (real or conjugate zeros), so relative to the pair it is at most
/// `4 u g_1 g_2 + u` with `g = (1 + |s / z|) / |1 - s / z|`. Whatever the pairing,
/// `sum over pairs g_1 g_2 <= (sum_j g_j)^2 / 2`, which is added for an entry of the coupled
/// system.
pub(crate) fn product_form_bound(
    e: &tiltnoise_core::tf::EntryFactors,
    s: f64,
    complex: bool,
) -> f64 {
    let sd = CDd::real(Dd::from(s));
    let zeros: f64 = e
        .zeros
        .iter()
        .map(|z| 4.0 * (1.0 + z.abs_f64() / (*z - sd).abs_f64()))
        .sum();
    let poles: f64 = e
        .poles
        .iter()
        .map(|l| 3.0 * (1.0 + l.abs_f64() / (*l - sd).abs_f64()))
        .sum();
    let pairs = if e.block.is_none() {
        let g: f64 = e
            .zeros
            .iter()
            .map(|z| (1.0 + s / z.abs_f64()) / (CDd::real(Dd::ONE) - sd / *z).abs_f64())
            .sum();
        4.0 * g * g / 2.0
    } else {
        0.0
    };
    let power = 2.0 * e.power as f64;
    let arith = if complex { 3.0 } else { 1.0 };
    2.0 * arith * U * (4.0 + power + zeros + poles + pairs)
}

#[test]
fn batch_matches_the_double_double_product_form() {
    let freqs = hard_grid();
    for (name, params, request) in cases() {
        let model = Model::new(&params).unwrap();
        let tf = plan(&model, &request, Method::PoleZero).unwrap();
        let h = batch(tf.as_ref(), &freqs, 1).unwrap();
        let factors = PoleZero::factors(&params, &request);
        let complex = name.contains("loss")
            || factors
                .iter()
                .any(|e| !e.gain.im.is_zero() || e.zeros.iter().any(|z| !z.im.is_zero()));
        let (ni, nv) = (
            request.inputs.len(),
            request.outputs.len() * request.inputs.len(),
        );
        let mut worst = (0.0, String::new());
        for (k, &f) in freqs.iter().enumerate() {
            let s = omega_sq(f);
            let sd = CDd::real(Dd::from(s));
            let mut want = vec![CDd::ZERO; nv];
            let mut bound = vec![0.0_f64; nv];
            for e in &factors {
                let mut v = e.gain;
                for _ in 0..e.power {
                    v = v * sd;
                }
                for z in &e.zeros {
                    v = v * (*z - sd);
                }
                for l in &e.poles {
                    v = v / (*l - sd);
                }
                let at = e.output * ni + e.input;
                want[at] += v;
                bound[at] = bound[at].max(product_form_bound(e, s, complex));
            }
            for at in 0..nv {
                let got = h[k * nv + at];
                let entry = format!(
                    "{}/{} at {f} Hz",
                    request.outputs[at / ni].name(),
                    request.inputs[at % ni].name()
                );
                if bound[at] == 0.0 {
                    assert_eq!(
                        got,
                        Complex64::new(0.0, 0.0),
                        "{name}: structural zero {entry}"
                    );
                    continue;
                }
                let w = want[at];
                if w.is_zero() {
                    // s^p at s = 0: the kernel's factor s is an exact 0 too.
                    assert_eq!(got, Complex64::new(0.0, 0.0), "{name}: {entry}");
                    continue;
                }
                let err = (CDd::from_c64(got) - w).abs_f64() / w.abs_f64();
                assert!(
                    err <= bound[at],
                    "{name}: {entry}: batch {got} vs double-double {}: rel err {err:e} > bound {:e}",
                    w.to_c64(),
                    bound[at]
                );
                let ratio = err / bound[at];
                if ratio > worst.0 {
                    worst = (ratio, entry);
                }
            }
        }
        println!("{name}: worst error / bound {:.2e} ({})", worst.0, worst.1);
    }
}

/// The (frequency, rcond) of a singular error, or the message of any other.
fn describe(e: &TfError) -> String {
    match e {
        TfError::Singular { freq_hz, rcond } => {
            format!("singular {:x} {:x}", freq_hz.to_bits(), rcond.to_bits())
        }
        other => other.to_string(),
    }
}

fn assert_same_error(name: &str, tf: &dyn TransferFunction, freqs: &[f64]) {
    let Err(want) = per_point(tf, freqs) else {
        panic!("{name}: the grid has no bad point");
    };
    for threads in [1, 2, 3] {
        let Err(got) = batch(tf, freqs, threads) else {
            panic!("{name}, {threads} threads: the batch path must fail too");
        };
        assert_eq!(
            describe(&got),
            describe(&want),
            "{name}, {threads} threads: {got} vs {want}"
        );
    }
    let Err(got) = evaluate(tf, freqs) else {
        panic!("{name}: evaluate must fail too");
    };
    assert_eq!(
        describe(&got),
        describe(&want),
        "{name}, evaluate: {got} vs {want}"
    );
    let mut m = evaluate(tf, &[1e-3]).unwrap();
    for threads in [1, 2, 3] {
        let Err(got) = evaluate_into(tf, freqs, threads, &mut m) else {
            panic!("{name}, {threads} threads: evaluate_into must fail too");
        };
        assert_eq!(
            describe(&got),
            describe(&want),
            "{name}, evaluate_into on {threads} threads: {got} vs {want}"
        );
    }
}

#[test]
fn singular_and_invalid_points_give_the_per_point_error() {
    let params = Params::table_i();
    let request = Request::all_tilt();
    let model = Model::new(&params).unwrap();
    let tf = plan(&model, &request, Method::PoleZero).unwrap();
    let factors = PoleZero::factors(&params, &request);
    let mut poles_hz: Vec<f64> = factors
        .iter()
        .flat_map(|e| e.poles.iter().map(|p| hz(p.re.to_f64())))
        .collect();
    poles_hz.sort_by(f64::total_cmp);
    poles_hz.dedup();
    let singular: Vec<f64> = poles_hz
        .iter()
        .copied()
        .filter(|&f| matches!(tf.eval(f), Err(TfError::Singular { .. })))
        .collect();
    assert!(
        singular.len() >= 4,
        "exact pole frequencies found: {singular:?}"
    );
    let base: Vec<f64> = (0..40).map(|k| 1e-3 * 1.3_f64.powi(k)).collect();
    for &pole in &singular {
        for at in [0, 3, 7, 8, 9, 20, 39] {
            let mut f = base.clone();
            f[at] = pole;
            assert_same_error(&format!("pole {pole} Hz at index {at}"), tf.as_ref(), &f);
            // Two bad points: the first in grid order is reported.
            let mut f2 = f.clone();
            f2[(at + 13) % 40] = if pole == singular[0] {
                singular[1]
            } else {
                singular[0]
            };
            assert_same_error(
                &format!("poles at {at} and {}", (at + 13) % 40),
                tf.as_ref(),
                &f2,
            );
        }
        // A short last chunk.
        let mut f = base[..19].to_vec();
        f[18] = pole;
        assert_same_error(&format!("pole {pole} Hz last of 19"), tf.as_ref(), &f);
    }
    for bad in [-1.0, f64::NAN, f64::INFINITY, (-0.0_f64).next_down()] {
        for at in [0, 5, 8, 39] {
            let mut f = base.clone();
            f[at] = bad;
            assert_same_error(&format!("{bad} Hz at index {at}"), tf.as_ref(), &f);
        }
    }
    // The damped model has no singular point: the same grid evaluates.
    let dtf = plan(&Model::new(&damped()).unwrap(), &request, Method::PoleZero).unwrap();
    let mut f = base.clone();
    f.extend(&singular);
    assert!(batch(dtf.as_ref(), &f, 2).is_ok());
}

#[test]
fn threads_split_any_method_like_one_thread() {
    let params = Params::table_i();
    let request = Request::all_tilt();
    let model = Model::new(&params).unwrap();
    let freqs = hard_grid();
    let tf = plan(&model, &request, Method::Split).unwrap();
    let want = per_point(tf.as_ref(), &freqs).unwrap();
    for threads in [0, 1, 2, 5] {
        let got = batch(tf.as_ref(), &freqs, threads).unwrap();
        assert_bit_identical(
            &format!("split, {threads} threads"),
            &request,
            &freqs,
            &got,
            &want,
        );
    }
}

/// A value that overflows `f64` (at a frequency far beyond any physical one, where `w^2` is
/// infinite) is [`TfError::NotFinite`] at the first such frequency in grid order, on every
/// path and thread count, never a NaN or an infinity in the output: the pole-zero kernel
/// checks its chunks in cache, the default `eval_grid_into` each point.
#[test]
fn overflowing_values_are_an_error_at_the_first_such_frequency() {
    let model = Model::new(&Params::table_i()).unwrap();
    let base: Vec<f64> = (0..40).map(|k| 1e-3 * 1.3_f64.powi(k)).collect();
    let (huge, huger) = (1e200, 1e250);
    for method in [Method::PoleZero, Method::Direct] {
        let tf = plan(&model, &Request::all_tilt(), method).unwrap();
        assert!(
            matches!(
                evaluate(tf.as_ref(), &[huge]),
                Err(TfError::NotFinite { .. })
            ),
            "{}: {huge} Hz must overflow",
            method.name()
        );
        for at in [0, 5, 8, 21, 39] {
            let mut f = base.clone();
            f[at] = huge;
            f[(at + 13) % 40] = huger;
            let first = if at < (at + 13) % 40 { huge } else { huger };
            for threads in [1, 2, 3] {
                match batch(tf.as_ref(), &f, threads) {
                    Err(TfError::NotFinite { freq_hz }) => assert_eq!(
                        freq_hz,
                        first,
                        "{}, {threads} threads, index {at}",
                        method.name()
                    ),
                    other => panic!(
                        "{}, {threads} threads, index {at}: expected NotFinite at {first} Hz, \
                         got {other:?}",
                        method.name()
                    ),
                }
            }
            match evaluate(tf.as_ref(), &f) {
                Err(TfError::NotFinite { freq_hz }) => assert_eq!(freq_hz, first),
                other => panic!("{}, evaluate: {other:?}", method.name()),
            }
        }
    }
}
