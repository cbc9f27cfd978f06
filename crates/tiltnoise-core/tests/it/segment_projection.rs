//! The per-segment budget of a record of six channels (tilt angles, and the floor's
//! acceleration, velocity and displacement as inertial sensors read them, so that the ground
//! map's factors and corrections all act): each budget segment's PSD of the total's ground term,
//! formed by projecting every Welch segment's spectra on the transfer functions, against the
//! same segment budgeted alone as a whole record (its cross-spectral matrix carried through the
//! map and propagated), within the rounding bound of the two roads.

use crate::tolerances::{EPS, F32_U, PROJECTION_C};
use num_complex::Complex64;
use std::path::PathBuf;
use tiltnoise_core::budget::{budget_from_series, BudgetOptions};
use tiltnoise_core::ground::GroundQuantity;
use tiltnoise_core::input::{
    GroundMap, InputFormat, InputKind, Provenance, Quantity, TiltSeries, TranslationChannel,
};
use tiltnoise_core::model::{Model, Observable, TiltAxis, TranslationAxis};
use tiltnoise_core::noise::TermKind;
use tiltnoise_core::params::Params;
use tiltnoise_core::spectral::{csd_matrix, WelchConfig};
use tiltnoise_core::tf::{evaluate, plan_auto, Input, Request, Scene};

const FS_HZ: f64 = 4.0;
const WELCH: usize = 256;
/// Samples per budget segment: 6 half-overlapping Welch segments.
const SEGMENT: usize = 1000;
const N_SEGMENTS: usize = 2;

fn noise(n: usize, seed: u64) -> Vec<f64> {
    let mut x = seed.max(1);
    (0..n)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as f64 / u64::MAX as f64 - 0.5
        })
        .collect()
}

/// Correlated tilts (rad) and the floor's motion along x (acceleration), y (velocity) and z
/// (displacement), the horizontal ones read by seismometers that sense the tilt too (`g t`
/// dominates x, so the correction is a difference of nearly equal terms).
fn record(range: std::ops::Range<usize>) -> TiltSeries {
    let n = N_SEGMENTS * SEGMENT;
    let white: Vec<Vec<f64>> = (0..6).map(|s| noise(n, 11 + s)).collect();
    let at = |c: usize| -> Vec<f64> { white[c][range.clone()].to_vec() };
    let theta: Vec<f64> = at(0).iter().map(|v| 3e-9 * v).collect();
    let eta: Vec<f64> = at(0)
        .iter()
        .zip(at(1))
        .map(|(a, b)| 1e-9 * (0.6 * a + 0.8 * b))
        .collect();
    let phi: Vec<f64> = at(2).iter().map(|v| 5e-10 * v).collect();
    let g = 9.81;
    let x: Vec<f64> = at(3)
        .iter()
        .zip(&eta)
        .map(|(a, e)| 1e-10 * a + g * e)
        .collect();
    let y: Vec<f64> = at(4)
        .iter()
        .zip(&theta)
        .map(|(a, t)| 2e-9 * a - g * t * 0.01)
        .collect();
    let z: Vec<f64> = at(5).iter().map(|v| 1e-9 * v).collect();
    let channel = |axis, quantity, data| TranslationChannel {
        axis,
        quantity,
        data,
    };
    TiltSeries {
        sample_rate_hz: FS_HZ,
        axes: vec![TiltAxis::ThetaT, TiltAxis::EtaT, TiltAxis::PhiT],
        data: vec![theta, eta, phi],
        translations: vec![
            channel(TranslationAxis::XT, GroundQuantity::Acceleration, x),
            channel(TranslationAxis::YT, GroundQuantity::Velocity, y),
            channel(TranslationAxis::ZT, GroundQuantity::Displacement, z),
        ],
        sensors: Default::default(),
        provenance: Provenance {
            path: PathBuf::from("(synthetic)"),
            format: InputFormat::Hdf5,
            kind: InputKind::Series,
            quantity: Quantity::Angle,
            axis_map: "theta_t=theta_t,eta_t=eta_t,phi_t=phi_t".into(),
            start_time: None,
            notes: Vec::new(),
        },
    }
}

/// The bound `B^2` of one segment's record at every bin above DC, for output `o`: `B = sum_c
/// |g|_c sqrt(S_cc)`, `|g|_c = sum_i |H_o,i| |G_i,c|` with `G_i` the map's weights of input `i`
/// alone.
fn bound_sq(model: &Model, series: &TiltSeries, cfg: &WelchConfig, o: Observable) -> Vec<f64> {
    let channels = series.channels();
    let map = GroundMap::new(&channels, model.params().environment.g_m_per_s2).unwrap();
    let inputs: Vec<Input> = map.inputs();
    let mut views: Vec<&[f64]> = series.data.iter().map(Vec::as_slice).collect();
    views.extend(series.translations.iter().map(|t| t.data.as_slice()));
    let s = csd_matrix(&views, FS_HZ, cfg).unwrap();
    let grid = &s.freqs_hz[1..];
    let request = Request {
        outputs: vec![o],
        inputs: inputs.clone(),
    };
    let (plan, _) = plan_auto(model, &Scene::over_grid(request, grid)).unwrap();
    let tf = evaluate(plan.as_ref(), grid).unwrap();
    let n = inputs.len();
    grid.iter()
        .enumerate()
        .map(|(k, &f)| {
            let mut g_abs = vec![0.0; n];
            for (i, &input) in inputs.iter().enumerate() {
                let mut unit = vec![Complex64::new(0.0, 0.0); n];
                unit[i] = Complex64::new(1.0, 0.0);
                map.channel_weights(f, &mut unit);
                let h = tf.get(k, 0, tf.input_index(input).unwrap()).norm();
                for (a, u) in g_abs.iter_mut().zip(&unit) {
                    *a += h * u.norm();
                }
            }
            let b: f64 = (0..n)
                .map(|c| g_abs[c] * s.get(k + 1, c, c).re.sqrt())
                .sum();
            b * b
        })
        .collect()
}

#[test]
fn a_projected_segment_is_the_segment_budgeted_alone() {
    let model = Model::new(&Params::table_i()).unwrap();
    let outputs = vec![Observable::X, Observable::Phi, Observable::PhiA];
    let base = BudgetOptions {
        outputs: outputs.clone(),
        welch_segment_len: Some(WELCH),
        ..BudgetOptions::default()
    };
    let cfg = WelchConfig::new(WELCH).with_overlap(WELCH / 2);
    let whole = budget_from_series(
        &model,
        &mut record(0..N_SEGMENTS * SEGMENT),
        &BudgetOptions {
            segment_duration_s: Some(SEGMENT as f64 / FS_HZ),
            percentiles: (0.0, 100.0),
            ..base.clone()
        },
        &mut |_, _| {},
    )
    .unwrap();
    let n_seg = cfg.n_segments(SEGMENT) as f64;
    let gamma = PROJECTION_C * (36.0 + n_seg) * EPS;
    let alone: Vec<_> = (0..N_SEGMENTS)
        .map(|s| {
            let mut piece = record(s * SEGMENT..(s + 1) * SEGMENT);
            let r = budget_from_series(&model, &mut piece, &base, &mut |_, _| {}).unwrap();
            (r, piece)
        })
        .collect();
    let mut worst: f64 = 0.0;
    for (o, band) in &whole.segment_bands {
        assert_eq!(band.term, TermKind::Ground);
        assert_eq!(band.n_segments, N_SEGMENTS);
        let each: Vec<(&[f64], Vec<f64>)> = alone
            .iter()
            .map(|(r, piece)| {
                let ob = r.budget.observables.iter().find(|b| b.observable == *o);
                let psd = ob.unwrap().term(&TermKind::Ground).unwrap().psd.as_slice();
                (psd, bound_sq(&model, piece, &cfg, *o))
            })
            .collect();
        for k in 0..band.lower.len() {
            let values: Vec<f64> = each.iter().map(|(p, _)| p[k]).collect();
            let b2 = each.iter().map(|(_, b)| b[k]).fold(0.0, f64::max);
            let (lo, hi) = values
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(l, h), &v| (l.min(v), h.max(v)));
            assert!(lo > 0.0, "{o:?} bin {k}: a segment without power");
            for (got, want) in [(band.lower[k], lo), (band.upper[k], hi)] {
                let tol = gamma * b2 + F32_U * want;
                let err = (got - want).abs();
                assert!(
                    err <= tol,
                    "{o:?} bin {k}: {got:e} vs {want:e} (error {err:e}, allowed {tol:e})"
                );
                worst = worst.max((err - F32_U * want).max(0.0) / (EPS * b2));
            }
        }
    }
    eprintln!("worst error beyond the f32 rounding: {worst:.3} eps B^2");
}
