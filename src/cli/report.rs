//! Text and JSON renderings of results for the terminal (tables, summaries). Sits above the
//! numerics: it reads `modes` and `tf`, and nothing numeric depends on it.

use std::fmt::Write;
use tiltnoise_core::model::{Coord, Model, Observable, TiltAxis, TranslationAxis};
use tiltnoise_core::modes::{NormalModes, RATIO_THRESHOLD};
use tiltnoise_core::tf::{self, Input, Method, Request};

use tiltnoise_job::modes::DOMINANT_SHARE;

/// A frequency with an SI prefix chosen for reading: `1.310 mHz`, `0.4149 Hz`.
pub fn format_hz(f: f64) -> String {
    if f < 1.0 && f > 0.0 && f < 0.1 {
        format!("{:.4} mHz", f * 1e3)
    } else {
        format!("{:.4} Hz", f)
    }
}

/// The Table II-like table of normal modes.
pub fn modes_table(modes: &NormalModes) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<5} {:>12} {:>10}  {:<16} {:<34} seen by",
        "mode", "frequency", "Q", "block", "dominant coordinates (energy share)"
    );
    for (k, m) in modes.modes.iter().enumerate() {
        let dominant = m
            .dominant_coords(DOMINANT_SHARE)
            .iter()
            .map(|(c, share)| format!("{} {:.2}", c.name(), share))
            .collect::<Vec<_>>()
            .join(", ");
        let seen = modes
            .observables_seeing(k)
            .iter()
            .map(|o| o.name())
            .collect::<Vec<_>>()
            .join(" ");
        let _ = writeln!(
            s,
            "nu_{:<3} {:>12} {:>10}  {:<16} {:<34} {}",
            m.index,
            format_hz(m.frequency_hz),
            format_q(m.quality_factor),
            m.block_name(),
            dominant,
            seen
        );
    }
    s
}

/// The `modes` command's report: the modes table; the rest configuration of a pendulum as
/// built; every mode's amplitude ratios (each observable over the largest of its unit group in
/// that mode) with the observables above [`RATIO_THRESHOLD`], and for a pendulum as built the
/// overlap with the symmetric mode that labels it.
pub fn modes_report(model: &Model, modes: &NormalModes) -> String {
    let mut s = modes_table(modes);
    let as_built = !model.is_symmetric();
    if as_built {
        let rest = model.rest_configuration();
        let _ = writeln!(
            s,
            "\nrest configuration (equilibrium of the exact potential; test-mass angles \
             relative to the crossbar):"
        );
        let list: Vec<String> = Coord::ALL
            .iter()
            .map(|c| format!("{} {:+.6e} {}", c.name(), rest[c.index()], c.unit()))
            .collect();
        let _ = writeln!(s, "  {}", list[..4].join(", "));
        let _ = writeln!(s, "  {}", list[4..].join(", "));
    }
    let _ = writeln!(
        s,
        "\namplitude ratios: each observable over the largest of its unit group (X, Y, Z in m; \
         theta, eta, phi, phi_a in rad) in the same mode; seen above {RATIO_THRESHOLD:e}:"
    );
    let _ = write!(s, "{:<5}", "mode");
    if as_built {
        let _ = write!(s, " {:>9}", "overlap");
    }
    for o in Observable::ALL {
        let _ = write!(s, " {:>10}", o.name());
    }
    let _ = writeln!(s, "  seen above");
    for (k, m) in modes.modes.iter().enumerate() {
        let _ = write!(s, "nu_{:<2}", m.index);
        if as_built {
            let _ = write!(s, " {:>9.6}", m.overlap);
        }
        for o in Observable::ALL {
            let r = modes.ratio[k][o.index()];
            // An exact zero (the other block of a decoupled model) reads as one.
            let _ = if r == 0.0 {
                write!(s, " {:>10}", "0")
            } else {
                write!(s, " {r:>+10.3e}")
            };
        }
        let seen: Vec<&str> = modes
            .observables_above_ratio(k)
            .iter()
            .map(|o| o.name())
            .collect();
        let _ = writeln!(s, "  {}", seen.join(" "));
    }
    s
}

/// A quality factor for the table: `inf` when undamped, else 4 significant digits.
pub fn format_q(q: f64) -> String {
    if q.is_infinite() {
        "inf".into()
    } else if (1e-2..1e6).contains(&q) {
        // 4 significant digits.
        let decimals = (3 - q.log10().floor() as i32).max(0) as usize;
        format!("{q:.decimals$}")
    } else {
        format!("{q:.3e}")
    }
}

/// The quasi-static (f = 0) tilt response next to the paper's stated limits.
pub fn static_limits(model: &Model) -> String {
    let plan =
        tf::plan(model, &Request::all_tilt(), Method::Direct).expect("direct plans every request");
    let h = plan
        .eval(0.0)
        .expect("K is positive definite: f = 0 is never singular");
    let lever = model.derived().lever_m;
    let entry = |o: Observable, t: TiltAxis| h[o.index() * 3 + t.index()].re;
    let mut s = String::from("quasi-static tilt response (f = 0):\n");
    for (o, t, expected, label) in [
        (Observable::X, TiltAxis::EtaT, -lever, "-(Z+Z_b+h_c)"),
        (Observable::Y, TiltAxis::ThetaT, lever, "+(Z+Z_b+h_c)"),
    ] {
        let _ = writeln!(
            s,
            "  {}/{} = {:+.6} m/rad   (paper: {} = {:+.6} m/rad)",
            o.name(),
            Input::Tilt(t).name(),
            entry(o, t),
            label,
            expected
        );
    }
    s
}

/// The response per unit floor acceleration as f -> 0 for each translation (its real part),
/// next to the equivalence principle's values: x_t acts as the tilt eta_t = a_x / g, y_t as
/// theta_t = -a_y / g, z_t as a change of g (each fibre stretched by the extra weight it
/// carries).
pub fn translation_limits(model: &Model) -> String {
    let limit = tiltnoise_core::model::translation::acceleration_limit(model);
    let observe = |o: Observable, a: TranslationAxis| limit[(o.index(), a.index())].re;
    let p = model.params();
    let g = p.environment.g_m_per_s2;
    let lever = model.derived().lever_m;
    let (m_a, m_b) = (p.mass.m_a_kg, p.mass.m_b_kg);
    let hooke = -((m_a + m_b) / p.bouncing.kappa_a_n_per_m + m_b / p.bouncing.kappa_b_n_per_m);
    let mut s = String::from(
        "floor translation per unit floor acceleration a = -w^2 u (f -> 0; equivalence principle):\n",
    );
    for (o, a, expected, label) in [
        (
            Observable::X,
            TranslationAxis::XT,
            -lever / g,
            "X/eta_t / g",
        ),
        (
            Observable::Y,
            TranslationAxis::YT,
            -lever / g,
            "-Y/theta_t / g",
        ),
        (
            Observable::Z,
            TranslationAxis::ZT,
            hooke,
            "-((m_a+m_b)/kappa_a + m_b/kappa_b)",
        ),
    ] {
        let _ = writeln!(
            s,
            "  {}/{} / (-w^2) = {:+.6e} s^2   ({label} = {expected:+.6e} s^2)",
            o.name(),
            a.name(),
            observe(o, a),
        );
    }
    s
}

/// Asserts that the JSON `text` lists the keys of every object in alphabetical order, the order
/// of the JSON reports (and of a `serde_json::Value`, whose objects are sorted maps); returns
/// the parsed value.
#[cfg(test)]
pub(crate) fn assert_keys_sorted(text: &str) -> serde_json::Value {
    let value: serde_json::Value = serde_json::from_str(text).unwrap();
    assert_eq!(text, serde_json::to_string_pretty(&value).unwrap());
    value
}
