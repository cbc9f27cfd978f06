//! The budget read at chosen frequencies: the chi-squared degrees of freedom of a Welch band
//! mean against closed forms, and the tilt term at `f` against its definition, the transfer
//! functions at exactly `f` applied to the mean cross-spectral matrix of the band.

use crate::tolerances::{DOF_REL, TARGET_REL};
use num_complex::Complex64;
use std::path::PathBuf;
use tiltnoise_core::budget::{
    add_measured, budget_from_series, series_psds, BudgetError, BudgetOptions, SummaryRequest,
};
use tiltnoise_core::input::{InputFormat, InputKind, Provenance, Quantity, TiltSeries};
use tiltnoise_core::model::{Model, Observable, TiltAxis};
use tiltnoise_core::noise::{Evaluation, TermKind};
use tiltnoise_core::params::Params;
use tiltnoise_core::spectral::{band_dof, csd_matrix, WelchConfig};
use tiltnoise_core::tf::{evaluate, plan, Input, Method, Request};

#[test]
fn degrees_of_freedom_match_the_closed_forms() {
    let n = 1024;
    let hann50 = WelchConfig::new(n);
    let close = |got: Option<f64>, want: f64, what: &str| {
        let got = got.unwrap();
        assert!(
            (got - want).abs() <= DOF_REL * want,
            "{what}: {got} vs {want}"
        );
    };
    // One bin of one segment: a chi-squared with 2 degrees of freedom.
    close(band_dof(&hann50, 1, 1), 2.0, "1 segment, 1 bin");
    // Disjoint segments are independent: 2 K.
    let disjoint = WelchConfig::new(n).with_overlap(0);
    close(band_dof(&disjoint, 7, 1), 14.0, "7 disjoint segments");
    // Periodic Hann, 50 % overlap: rho = 1/6 between neighbours, nu = 36 K^2 / (19 K - 1)
    // (Percival and Walden 1993, eq. 292c).
    for k in [2usize, 5, 41] {
        let k_f = k as f64;
        let want = 36.0 * k_f * k_f / (19.0 * k_f - 1.0);
        close(band_dof(&hann50, k, 1), want, &format!("{k} Hann segments"));
    }
    // Adjacent bins of one Hann periodogram: rho = -2/3 one bin apart, 1/6 two bins apart, 0
    // beyond (the DFT of w^2 = 3/8 - cos/2 + cos(2 .)/8, normalised by 3/8).
    for m in [2usize, 3, 10] {
        let m_f = m as f64;
        let pairs = m_f + 2.0 * (m_f - 1.0) * 4.0 / 9.0 + 2.0 * (m_f - 2.0).max(0.0) / 36.0;
        close(
            band_dof(&hann50, 1, m),
            2.0 * m_f * m_f / pairs,
            &format!("{m} bins"),
        );
    }
    assert_eq!(
        band_dof(
            &hann50.with_averaging(tiltnoise_core::spectral::Averaging::Median),
            9,
            3
        ),
        None,
        "a median's distribution is not a scaled chi-squared of this form"
    );
}

const FS_HZ: f64 = 1.0;
const SEG: usize = 1024;

fn noise(n: usize, seed: u64) -> Vec<f64> {
    let mut x = seed.max(1);
    (0..n)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x as f64 / u64::MAX as f64 - 0.5) * 1e-8
        })
        .collect()
}

fn series(data: Vec<Vec<f64>>) -> TiltSeries {
    TiltSeries {
        sample_rate_hz: FS_HZ,
        axes: vec![TiltAxis::ThetaT, TiltAxis::EtaT],
        data,
        translations: Vec::new(),
        sensors: Default::default(),
        provenance: Provenance {
            path: PathBuf::from("(synthetic)"),
            format: InputFormat::Hdf5,
            kind: InputKind::Series,
            quantity: Quantity::Angle,
            axis_map: "theta_t=theta_t,eta_t=eta_t".into(),
            start_time: None,
            notes: Vec::new(),
        },
    }
}

#[test]
fn tilt_at_f_is_the_exact_transfer_function_on_the_band_mean_cross_spectra() {
    // Correlated axes, so that the cross-spectra matter.
    let (a, b) = (noise(40 * SEG, 3), noise(40 * SEG, 4));
    let eta: Vec<f64> = a.iter().zip(&b).map(|(x, y)| 0.6 * x + 0.8 * y).collect();
    let model = Model::new(&Params::table_i()).unwrap();
    let req = SummaryRequest {
        freqs_hz: vec![2e-3, 0.05],
        band_fraction: 0.2,
        strict: true,
    };
    let opts = BudgetOptions {
        welch_segment_len: Some(SEG),
        outputs: vec![Observable::X, Observable::Phi, Observable::Y],
        summary: req.clone(),
        ..BudgetOptions::default()
    };
    let report = budget_from_series(
        &model,
        &mut series(vec![a.clone(), eta.clone()]),
        &opts,
        &mut |_, _| {},
    )
    .unwrap();
    // Independently: the Welch matrices, their mean over the band, the transfer functions of
    // the direct method at exactly f.
    let m = csd_matrix(&[&a, &eta], FS_HZ, &WelchConfig::new(SEG)).unwrap();
    let (grid, csd) = two_tilt_axes(Quantity::Angle).apply(&m);
    for at in &report.summary {
        let f = at.freq_hz;
        let bins: Vec<usize> = (0..grid.len())
            .filter(|&k| grid[k] >= f * 0.8 && grid[k] <= f * 1.2)
            .collect();
        let mut s = [Complex64::new(0.0, 0.0); 4];
        for &k in &bins {
            for (x, y) in s.iter_mut().zip(&csd[4 * k..4 * k + 4]) {
                *x += y / bins.len() as f64;
            }
        }
        let request = Request {
            outputs: opts.outputs.clone(),
            inputs: vec![Input::Tilt(TiltAxis::ThetaT), Input::Tilt(TiltAxis::EtaT)],
        };
        let h = evaluate(
            plan(&model, &request, Method::Direct).unwrap().as_ref(),
            &[f],
        )
        .unwrap();
        for (o, obs) in opts.outputs.iter().enumerate() {
            let hv = [h.get(0, o, 0), h.get(0, o, 1)];
            let mut want = 0.0;
            let mut scale = 0.0;
            for i in 0..2 {
                for j in 0..2 {
                    want += (hv[i].conj() * s[2 * i + j] * hv[j]).re;
                    scale += hv[i].norm() * s[2 * i + j].norm() * hv[j].norm();
                }
            }
            let got = at.observable(*obs).unwrap().term(&TermKind::Tilt).unwrap();
            // The transfer functions meet TARGET_REL (auto) against the direct method's own
            // error, far smaller; the quadratic form carries each twice, relative to the sum
            // of the magnitudes of its terms (cancellation between correlated axes).
            assert!(
                (got.psd - want).abs() <= 4.0 * TARGET_REL * scale,
                "{} tilt at {f} Hz: {} vs {want}",
                obs.name(),
                got.psd
            );
            let Evaluation::BandMean(band) = &got.evaluation else {
                panic!("a series' tilt is a band mean")
            };
            assert_eq!(band.n_bins, bins.len());
            assert_eq!(band.first_bin_hz, grid[bins[0]]);
            assert_eq!(
                band.dof,
                band_dof(&WelchConfig::new(SEG), m.n_segments, bins.len())
            );
            // The readout is exact and the one of the grid.
            if let Some(r) = at.observable(*obs).unwrap().term(&TermKind::Readout) {
                assert_eq!(r.evaluation, Evaluation::Exact);
                assert_eq!(r.psd, 9e-9 * 9e-9);
            }
        }
    }
    assert_eq!(report.summary.len(), 2);

    // A frequency the budget cannot be read at: refused when asked for, else left out.
    for (freqs, band_fraction, why) in [
        (vec![1e-4], 0.1, "outside the budget's band"),
        (vec![2e-3], 0.01, "no Welch bin in"),
    ] {
        let mut opts = opts.clone();
        opts.summary = SummaryRequest {
            freqs_hz: freqs,
            band_fraction,
            strict: true,
        };
        let mut s = series(vec![a.clone(), eta.clone()]);
        match budget_from_series(&model, &mut s, &opts, &mut |_, _| {}) {
            Err(BudgetError::Config(e)) => assert!(e.to_string().contains(why), "{e}"),
            other => panic!("expected a refusal, got {:?}", other.map(|r| r.summary)),
        }
        opts.summary.strict = false;
        let r = budget_from_series(&model, &mut s, &opts, &mut |_, _| {}).unwrap();
        assert!(r.summary.is_empty());
        assert!(r
            .notes
            .iter()
            .any(|n| n.contains("left out") && n.contains(why)));
    }
}

#[test]
fn measured_series_is_a_band_mean_of_its_own_bins() {
    let (a, b) = (noise(40 * SEG, 7), noise(40 * SEG, 8));
    let model = Model::new(&Params::table_i()).unwrap();
    let opts = BudgetOptions {
        welch_segment_len: Some(SEG),
        summary: SummaryRequest {
            freqs_hz: vec![0.02, 0.3],
            band_fraction: 0.1,
            strict: true,
        },
        ..BudgetOptions::default()
    };
    let mut report =
        budget_from_series(&model, &mut series(vec![a, b]), &opts, &mut |_, _| {}).unwrap();
    // A measured X at twice the rate, 30 segments' worth.
    let x = noise(60 * SEG, 9);
    let measured = series_psds(&[(Observable::X, x)], 2.0 * FS_HZ, &report.source).unwrap();
    let (cfg, n_seg) = measured.welch.unwrap();
    add_measured(&mut report, &measured, "m.h5");
    for at in &report.summary {
        let (lo, hi) = at.band_hz;
        let f = &measured.freqs_hz;
        let bins: Vec<usize> = (0..f.len()).filter(|&k| f[k] >= lo && f[k] <= hi).collect();
        let psd = &measured.psds[0].1;
        let want = bins.iter().map(|&k| psd[k]).sum::<f64>() / bins.len() as f64;
        let x = at.observable(Observable::X).unwrap();
        let got = x.term(&TermKind::Measured).unwrap();
        // The same sum in the same order.
        assert_eq!(got.psd, want, "at {} Hz", at.freq_hz);
        let Evaluation::BandMean(band) = &got.evaluation else {
            panic!("a measured series is a band mean")
        };
        assert_eq!(band.dof, band_dof(&cfg, n_seg, bins.len()));
        assert!(band.dof.is_some());
        assert!(at
            .observable(Observable::Phi)
            .unwrap()
            .term(&TermKind::Measured)
            .is_none());
    }
}

/// The map of a record of theta_t and eta_t in `quantity`: the budget's conversion of their
/// Welch cross-spectra to the angles'.
fn two_tilt_axes(quantity: Quantity) -> tiltnoise_core::input::GroundMap {
    use tiltnoise_core::input::{GroundChannel, GroundMap};
    let channels = [
        GroundChannel::tilt(TiltAxis::ThetaT, quantity),
        GroundChannel::tilt(TiltAxis::EtaT, quantity),
    ];
    GroundMap::new(&channels, 9.81).expect("rotation sensors alone")
}
