//! Tilt subtraction end to end on a synthetic record (`synthetic.rs`).

use crate::synthetic::{make, Spec};
use tiltnoise_core::params::Params;
use tiltnoise_core::subtract::{subtract, MeasuredRecord, StartTime, SubtractConfig, TiltRecord};

#[test]
fn explore() {
    let spec = Spec::verification();
    let t0 = std::time::Instant::now();
    let rec = make(&spec);
    eprintln!("generated in {:?}", t0.elapsed());
    let t0 = std::time::Instant::now();
    let res = subtract(
        &Params::table_i(),
        &TiltRecord {
            fs_hz: 1.0,
            axes: &rec.axes,
            data: &rec.tilt,
            start: Some(StartTime {
                unix_s: 0,
                frac_s: 0.0,
            }),
        },
        &MeasuredRecord {
            fs_hz: 1.0,
            channels: &rec.measured,
            start: Some(StartTime {
                unix_s: 0,
                frac_s: 0.0,
            }),
        },
        &SubtractConfig {
            keys: vec!["length.h_m".into()],
            readout_asd: spec.readout.clone(),
            ..SubtractConfig::default()
        },
    )
    .unwrap();
    eprintln!("subtracted in {:?}", t0.elapsed());
    for e in &res.fit.estimates {
        eprintln!(
            "{:<14} {:>12.6} +- {:>10.3e}  {:?}",
            e.name, e.value, e.sigma, e.status
        );
    }
    eprintln!(
        "chi2 {} dof {} factor {} band {:?} bins {:?} it {} stop {:?}",
        res.fit.chi2,
        res.fit.dof,
        res.fit.sigma_factor,
        res.fit.band_hz,
        res.fit.bins,
        res.fit.iterations,
        res.fit.stop
    );
    for n in &res.notes {
        eprintln!("note: {n}");
    }
    for r in &res.residuals {
        eprintln!("{:?}", r.band);
    }
}

#[test]
fn explore_pulls() {
    for seed in 1..7 {
        let mut spec = Spec::verification();
        spec.seed = seed;
        spec.n = 1 << 15;
        let rec = make(&spec);
        let res = subtract(
            &Params::table_i(),
            &TiltRecord {
                fs_hz: 1.0,
                axes: &rec.axes,
                data: &rec.tilt,
                start: None,
            },
            &MeasuredRecord {
                fs_hz: 1.0,
                channels: &rec.measured,
                start: None,
            },
            &SubtractConfig {
                keys: vec!["length.h_m".into()],
                readout_asd: spec.readout.clone(),
                ..SubtractConfig::default()
            },
        )
        .unwrap();
        let truth = [1.03, 0.97, 2.3, 2.5];
        let pulls: Vec<String> = res
            .fit
            .estimates
            .iter()
            .zip(truth)
            .map(|(e, t)| format!("{:+.2}", (e.value - t) / e.sigma))
            .collect();
        eprintln!(
            "seed {seed}: pulls {} chi2/dof {:.3}",
            pulls.join(" "),
            res.fit.chi2 / res.fit.dof as f64
        );
    }
}
