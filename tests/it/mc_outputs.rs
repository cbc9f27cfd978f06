//! `tiltnoise mc` with an error model from the parameter file's `[uncertainty]` table, and its
//! outputs: the spread follows first-order propagation of the file's error bars (computed
//! independently by finite differences of `NormalModes`), uniform and Gaussian errors give the
//! same spread, HDF5 reads back, figures are written, and bad input fails cleanly.

use crate::common;

use common::{assert_fails_without_output, str_attr, strs_dataset, tiltnoise};
use tiltnoise_core::mc::{run, uncertainties, Distribution, McConfig, McResult};
use tiltnoise_core::model::Model;
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::{Params, TABLE_I_TOML};

/// Central-difference step (relative) of the reference derivatives: truncation ~h^2 (1e-10),
/// rounding ~1e-15 / h (1e-10) relative to the frequency.
const FD_STEP: f64 = 1e-5;

/// Rounding of a mode frequency by the eigenvalue solvers, relative: eps times the block's
/// condition, below 1e-12 here; 1e-10 leaves a margin of 100.
const ROUNDING_REL: f64 = 1e-10;

/// Smallest first-order spread (relative to the frequency) compared with the Monte Carlo. The
/// central difference turns the solvers' rounding (ROUNDING_REL) into an error of
/// `ROUNDING_REL rel_sigma / (2 FD_STEP)` = 5e-8 relative at rel_sigma = 1 %; above 1e-5 that is
/// under 0.5 % of the compared spread. Below it a mode counts as (almost) unmoved.
const RESOLVABLE_REL: f64 = 1e-5;

/// Allowed deviation of a Monte Carlo statistic, in standard errors: a 5-sigma event has
/// probability 6e-7, so a failure means a real discrepancy, not bad luck.
const N_SE: f64 = 5.0;

/// The Table I file with an `[uncertainty]` table in which every default error is 0 except
/// `key`, which gets `rel_sigma` with `distribution`.
fn only_one_uncertain(key: &str, rel_sigma: f64, distribution: &str) -> String {
    let mut text = format!("{TABLE_I_TOML}\n[uncertainty]\n");
    for u in uncertainties(&Params::table_i()) {
        if u.key != key && u.rel_sigma > 0.0 {
            text.push_str(&format!("\"{}\" = {{ rel_sigma = 0 }}\n", u.key));
        }
    }
    text.push_str(&format!(
        "\"{key}\" = {{ rel_sigma = {rel_sigma:?}, distribution = \"{distribution}\" }}\n"
    ));
    text
}

fn nominal_hz(p: &Params) -> Vec<f64> {
    NormalModes::new(&Model::new(p).unwrap()).frequencies_hz()
}

/// First-order standard deviation of each mode, `|d f / d p| p rel_sigma`, by central
/// differences of the full eigen-decomposition (not the Monte Carlo's eigenvalue path).
/// Also whether each mode moves at all (bit-level).
fn first_order_std_hz(p: &Params, key: &str, rel_sigma: f64) -> ([f64; 8], [bool; 8]) {
    let (up, down) = (
        modes_at(p, key, 1.0 + FD_STEP),
        modes_at(p, key, 1.0 - FD_STEP),
    );
    let mut std = [0.0; 8];
    let mut moves = [false; 8];
    for k in 0..8 {
        std[k] = ((up[k] - down[k]) / (2.0 * FD_STEP) * rel_sigma).abs();
        moves[k] = up[k] != down[k];
    }
    (std, moves)
}

/// The mode frequencies with parameter `key` multiplied by `factor`.
fn modes_at(p: &Params, key: &str, factor: f64) -> Vec<f64> {
    let value = p.fields().iter().find(|f| f.key == key).unwrap().value;
    nominal_hz(
        &p.with_override(&format!("{key}={:?}", value * factor))
            .unwrap(),
    )
}

fn run_file(text: &str, samples: usize, seed: u64) -> (Params, McResult) {
    let p = Params::from_toml_str(text, "test.toml").unwrap();
    let cfg = McConfig {
        samples,
        seed,
        threads: 2,
        ..McConfig::default_for(&p)
    };
    let r = run(&p, &cfg, &|_| {}).unwrap();
    (p, r)
}

/// Relative standard error of a sample standard deviation of `n` draws of a distribution with
/// kurtosis `kurtosis` (3 Gaussian, 9/5 uniform): sqrt((kurtosis - 1) / (4 n)).
fn rel_se_of_std(n: usize, kurtosis: f64) -> f64 {
    ((kurtosis - 1.0) / (4.0 * n as f64)).sqrt()
}

#[test]
fn one_file_set_error_moves_only_its_modes_by_first_order_propagation() {
    const N: usize = 20_000;
    // Small enough that the second-order (nonlinear) change of the std, O(rel_sigma^2) relative,
    // stays far below the statistical tolerance (~2.5 %).
    const REL_SIGMA: f64 = 0.01;
    // (key, number of modes it leaves exactly unchanged): a spring constant enters one 4x4
    // block of the stiffness matrix, a length enters every block.
    for (key, unmoved) in [
        ("torsion.k_b_n_m_per_rad", 4),
        ("bouncing.kappa_b_n_per_m", 4),
        ("length.z_b_m", 0),
    ] {
        let (p, r) = run_file(&only_one_uncertain(key, REL_SIGMA, "gaussian"), N, 11);
        assert_eq!(r.rejected, 0);
        let (lin, moves) = first_order_std_hz(&p, key, REL_SIGMA);
        let nominal = nominal_hz(&p);
        let tol = N_SE * rel_se_of_std(N, 3.0);
        println!("{key}, {} % Gaussian, N = {N}:", REL_SIGMA * 100.0);
        for k in 0..8 {
            println!(
                "  nu_{}: first order {:.4e} Hz, MC {:.4e} Hz",
                k + 1,
                lin[k],
                r.std_hz[k]
            );
            if moves[k] && lin[k] > RESOLVABLE_REL * nominal[k] {
                let ratio = r.std_hz[k] / lin[k];
                assert!(
                    (ratio - 1.0).abs() <= tol,
                    "{key}, nu_{}: MC std {:e} vs first order {:e} (ratio {ratio}, tol {tol})",
                    k + 1,
                    r.std_hz[k],
                    lin[k]
                );
            } else if moves[k] {
                // Same block, but coupled at rounding level only.
                assert!(
                    r.std_hz[k] <= RESOLVABLE_REL * nominal[k],
                    "{key}, nu_{}",
                    k + 1
                );
            } else {
                // A mode in another block: its matrices are bit-identical in every draw.
                assert_eq!(r.std_hz[k], 0.0, "{key}, nu_{}", k + 1);
            }
        }
        assert_eq!(moves.iter().filter(|&&m| !m).count(), unmoved, "{key}");
    }
}

#[test]
fn uniform_and_gaussian_errors_give_the_same_spread() {
    const N: usize = 20_000;
    const REL_SIGMA: f64 = 0.01;
    const KEY: &str = "torsion.k_b_n_m_per_rad";
    let (p, g) = run_file(&only_one_uncertain(KEY, REL_SIGMA, "gaussian"), N, 3);
    let (_, u) = run_file(&only_one_uncertain(KEY, REL_SIGMA, "uniform"), N, 4);
    let (se_g, se_u) = (rel_se_of_std(N, 3.0), rel_se_of_std(N, 1.8));
    let (lin, _) = first_order_std_hz(&p, KEY, REL_SIGMA);
    // Where the ends of the uniform range, p (1 +/- sqrt(3) rel_sigma), put each mode.
    let ends = [
        modes_at(&p, KEY, 1.0 - 3f64.sqrt() * REL_SIGMA),
        modes_at(&p, KEY, 1.0 + 3f64.sqrt() * REL_SIGMA),
    ];
    let nominal = nominal_hz(&p);
    let mut compared = 0;
    for k in (0..8).filter(|&k| lin[k] > RESOLVABLE_REL * nominal[k]) {
        compared += 1;
        let ratio = u.std_hz[k] / g.std_hz[k];
        let tol = N_SE * (se_g * se_g + se_u * se_u).sqrt();
        println!(
            "nu_{}: Gaussian {:.4e} Hz, uniform {:.4e} Hz, ratio {ratio:.4} (tol {tol:.4})",
            k + 1,
            g.std_hz[k],
            u.std_hz[k]
        );
        assert!((ratio - 1.0).abs() <= tol, "nu_{}: ratio {ratio}", k + 1);
        assert!(
            (u.std_hz[k] / lin[k] - 1.0).abs() <= N_SE * se_u,
            "nu_{}: uniform std {} vs first order {}",
            k + 1,
            u.std_hz[k],
            lin[k]
        );
        // The shape differs: the frequency is monotonic in p over the range, so uniform draws
        // stay between the frequencies at its ends (up to rounding); Gaussian ones do not
        // (P(|z| > sqrt 3) = 8 % per draw).
        let (lo, hi) = (ends[0][k].min(ends[1][k]), ends[0][k].max(ends[1][k]));
        let slack = ROUNDING_REL * nominal[k];
        let outside = |r: &McResult| {
            r.freqs_hz
                .iter()
                .filter(|f| f[k] < lo - slack || f[k] > hi + slack)
                .count()
        };
        println!(
            "  outside [{lo:.6e}, {hi:.6e}] Hz: uniform {}, Gaussian {} of {N}",
            outside(&u),
            outside(&g)
        );
        assert_eq!(outside(&u), 0, "nu_{}", k + 1);
        assert!(outside(&g) > N / 20, "nu_{}", k + 1);
    }
    assert!(compared >= 1);
}

/// Mean and sample standard deviation (n - 1) of column `k`, two-pass.
fn mean_std(rows: &ndarray::Array2<f64>, k: usize) -> (f64, f64) {
    let col = rows.column(k);
    let n = col.len() as f64;
    let mean = col.sum() / n;
    let var = col.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
    (mean, var.sqrt())
}

#[test]
fn hdf5_png_svg_round_trip() {
    common::disable_hdf5_file_locking();
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("p.toml");
    let text = format!(
        "{TABLE_I_TOML}\n[uncertainty]\n\"mass.m_a_kg\" = {{ rel_sigma = 0.03, distribution = \
         \"uniform\" }}\n\"length.h_m\" = {{ rel_sigma = 0.0 }}\n"
    );
    std::fs::write(&params, &text).unwrap();
    let (h5, png, svg) = (
        dir.path().join("mc.h5"),
        dir.path().join("mc.png"),
        dir.path().join("mc.svg"),
    );
    let out = tiltnoise(&[
        "--params",
        params.to_str().unwrap(),
        "mc",
        "--samples",
        "3000",
        "--seed",
        "9",
        "--save",
        h5.to_str().unwrap(),
        "--save",
        png.to_str().unwrap(),
        "--save",
        svg.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));

    let p = Params::from_toml_str(&text, "p.toml").unwrap();
    let cfg = McConfig {
        samples: 3000,
        seed: 9,
        ..McConfig::default_for(&p)
    };
    let lib = run(&p, &cfg, &|_| {}).unwrap();

    let f = hdf5::File::open(&h5).unwrap();
    assert_eq!(str_attr(&f, "schema"), "tiltnoise.mc");
    assert_eq!(
        f.attr("schema_version")
            .unwrap()
            .read_scalar::<i64>()
            .unwrap(),
        tiltnoise_io::SCHEMA_VERSION_MC
    );
    let int = |name: &str| f.attr(name).unwrap().read_scalar::<i64>().unwrap();
    assert_eq!(f.attr("seed").unwrap().read_scalar::<u64>().unwrap(), 9);
    assert_eq!(int("samples"), 3000);
    assert_eq!(int("rejected") + int("accepted"), 3000);
    assert!(str_attr(&f, "created_by").contains("mc --samples 3000"));
    assert!(str_attr(&f, "rejected_draws").starts_with("excluded"));
    // The stored parameter set, error model included, reads back to the one used.
    let stored = Params::from_toml_str(&str_attr(&f, "parameters_toml"), "stored").unwrap();
    assert_eq!(stored, p);

    let draws = f.dataset("draws_hz").unwrap().read_2d::<f64>().unwrap();
    assert_eq!(draws.ncols(), 8);
    assert_eq!(draws.nrows() as i64, int("accepted"));
    let index = f.dataset("sample_index").unwrap().read_1d::<i64>().unwrap();
    assert_eq!(index.len(), draws.nrows());
    assert!(index.windows(2).into_iter().all(|w| w[0] < w[1]));
    let read = |name: &str| f.dataset(name).unwrap().read_1d::<f64>().unwrap().to_vec();
    let (mean, std, nominal) = (read("mean_hz"), read("std_hz"), read("nominal_hz"));
    assert_eq!(nominal, nominal_hz(&p));
    // Recomputed from the stored draws: the same sums in another order, so they agree to
    // rounding, a few ulps times the number of draws at most.
    let rel = 3000.0 * f64::EPSILON;
    for k in 0..8 {
        let (m, s) = mean_std(&draws, k);
        common::assert_close("mean_hz", &format!("nu_{}", k + 1), mean[k], m, rel, 0.0);
        common::assert_close(
            "std_hz",
            &format!("nu_{}", k + 1),
            std[k],
            s,
            1e3 * rel,
            0.0,
        );
        // And the command's draws are the library's for the same seed and file.
        assert_eq!(mean[k], lib.mean_hz[k]);
        assert_eq!(std[k], lib.std_hz[k]);
        assert!(std[k] > 0.0);
    }
    for (row, want) in draws.rows().into_iter().zip(&lib.freqs_hz) {
        assert_eq!(row.to_vec(), want.to_vec());
    }

    let g = f.group("uncertainty").unwrap();
    let keys = strs_dataset(&g, "key");
    let dists = strs_dataset(&g, "distribution");
    let sigma = g.dataset("rel_sigma").unwrap().read_1d::<f64>().unwrap();
    let want = uncertainties(&p);
    assert_eq!(keys.len(), want.len());
    for (i, u) in want.iter().enumerate() {
        assert_eq!(
            (&keys[i], sigma[i], dists[i].as_str()),
            (&u.key, u.rel_sigma, u.distribution.name())
        );
    }
    let i = keys.iter().position(|k| k == "mass.m_a_kg").unwrap();
    assert_eq!((sigma[i], dists[i].as_str()), (0.03, "uniform"));
    assert_eq!(want[i].distribution, Distribution::Uniform);

    let png_bytes = std::fs::read(&png).unwrap();
    assert_eq!(&png_bytes[..8], b"\x89PNG\r\n\x1a\n");
    let svg_text = std::fs::read_to_string(&svg).unwrap();
    assert!(svg_text.contains("<svg") && svg_text.contains("frequency (Hz)"));
    // One panel per mode.
    for k in ["ν₁", "ν₈"] {
        assert!(svg_text.contains(k), "{k}");
    }
}

#[test]
fn bad_input_fails_with_code_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let (h5, png) = (out.join("mc.h5"), out.join("mc.png"));
    let cases: [(&str, &[&str]); 6] = [
        (
            "\"mass.m_c_kg\" = { rel_sigma = 0.01 }",
            &["mass.m_c_kg", "unknown parameter key", "mass.m_a_kg"],
        ),
        (
            "\"mass.m_a_kg\" = { rel_sigma = -0.02 }",
            &["mass.m_a_kg", "-0.02", ">= 0"],
        ),
        (
            "\"torsion.k_b_n_m_per_rad\" = { rel_sigma = 0.3 }",
            &["torsion.k_b_n_m_per_rad", "0.3", "non-physical", "< 0.2500"],
        ),
        (
            "\"torsion.k_b_n_m_per_rad\" = { rel_sigma = 0.6, distribution = \"uniform\" }",
            &["torsion.k_b_n_m_per_rad", "0.6", "non-physical", "< 0.5774"],
        ),
        (
            "\"mass.m_a_kg\" = { rel_sigma = 0.01, distribution = \"normal\" }",
            &["mass.m_a_kg", "normal", "gaussian, uniform"],
        ),
        (
            "\"mass.m_a_kg\" = { rel_sigma = \"3 %\" }",
            &["mass.m_a_kg", "3 %", "not a number"],
        ),
    ];
    for (i, (entry, needles)) in cases.iter().enumerate() {
        let params = dir.path().join(format!("bad{i}.toml"));
        std::fs::write(&params, format!("{TABLE_I_TOML}\n[uncertainty]\n{entry}\n")).unwrap();
        let mut all = needles.to_vec();
        let name = params.to_str().unwrap();
        all.push(name);
        assert_fails_without_output(
            &[
                "--params",
                name,
                "mc",
                "--samples",
                "100",
                "--save",
                h5.to_str().unwrap(),
                "--save",
                png.to_str().unwrap(),
            ],
            &out,
            &all,
        );
    }
    // Sample counts: zero is refused by the library, a negative one by the parser.
    assert_fails_without_output(
        &["mc", "--samples", "0", "--save", h5.to_str().unwrap()],
        &out,
        &["samples = 0"],
    );
    let o = tiltnoise(&["mc", "--samples=-5", "--save", h5.to_str().unwrap()]);
    let err = common::stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--samples") && err.contains("-5"), "{err}");
    // An output format mc cannot write is refused before computing.
    let csv = out.join("mc.csv");
    assert_fails_without_output(
        &[
            "mc",
            "--save",
            h5.to_str().unwrap(),
            "--save",
            csv.to_str().unwrap(),
        ],
        &out,
        &["mc.csv", ".h5, .hdf5, .png, .svg"],
    );
    assert!(common::listing(&out).is_empty());
}
