//! Display names shared by the figures: observables, tilt and translation axes with Greek
//! letters and Unicode subscripts, and panel titles.

use tiltnoise_core::model::{Observable, TiltAxis, TranslationAxis};

/// Display name of an observable (Greek letters, Unicode subscripts).
pub fn observable_symbol(o: Observable) -> &'static str {
    match o {
        Observable::X => "X",
        Observable::Y => "Y",
        Observable::Z => "Z",
        Observable::Theta => "θ",
        Observable::Eta => "η",
        Observable::Phi => "φ",
        Observable::PhiA => "φₐ",
    }
}

/// Panel title of an observable: its symbol and what it is, e.g. `φ: test-mass torsion`.
pub fn observable_title(o: Observable) -> String {
    let what = match o {
        Observable::X => "test-mass displacement along x",
        Observable::Y => "test-mass displacement along y",
        Observable::Z => "test-mass displacement along z",
        Observable::Theta => "test-mass rotation about x",
        Observable::Eta => "test-mass rotation about y",
        Observable::Phi => "test-mass torsion",
        Observable::PhiA => "crossbar torsion",
    };
    format!("{}: {what}", observable_symbol(o))
}

/// Display name of a tilt axis: θₜ, ηₜ or φₜ.
pub fn tilt_symbol(a: TiltAxis) -> &'static str {
    match a {
        TiltAxis::ThetaT => "θₜ",
        TiltAxis::EtaT => "ηₜ",
        TiltAxis::PhiT => "φₜ",
    }
}

/// Display name of a floor-translation axis: xₜ, yₜ or zₜ.
pub fn translation_symbol(a: TranslationAxis) -> &'static str {
    match a {
        TranslationAxis::XT => "xₜ",
        TranslationAxis::YT => "yₜ",
        TranslationAxis::ZT => "zₜ",
    }
}

/// SI prefixes from femto to giga, by exponent.
const SI_PREFIXES: [(i32, &str); 9] = [
    (-15, "f"),
    (-12, "p"),
    (-9, "n"),
    (-6, "µ"),
    (-3, "m"),
    (0, ""),
    (3, "k"),
    (6, "M"),
    (9, "G"),
];

/// A value with an SI prefix for tick labels and prose: `1 mHz`, `500 Hz`, `10 µrad`,
/// `1.3 mHz`, `−100 µrad` (three significant digits at most, trailing zeros dropped, the
/// typographic minus). Zero is `0`; an empty unit gives the bare number with its prefix
/// (`2 k`). Values outside femto..giga keep the nearest prefix.
pub fn si_value(v: f64, unit: &str) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v == 0.0 {
            "0".to_string()
        } else {
            format!("{v}")
        };
    }
    // Round to three significant digits first, so 999.96 reads `1 k`, not `1000`.
    let digits = v.abs().log10().floor() as i32;
    let scale = 10f64.powi(2 - digits);
    let v = (v * scale).round() / scale;
    let e = (v.abs().log10().floor() as i32).div_euclid(3) * 3;
    let (e, prefix) = SI_PREFIXES
        .iter()
        .copied()
        .min_by_key(|(p, _)| (p - e).abs())
        .unwrap_or((0, ""));
    let m = v / 10f64.powi(e);
    let decimals = (2 - m.abs().log10().floor() as i32).max(0) as usize;
    let mut text = format!("{m:.decimals$}");
    if text.contains('.') {
        text = text.trim_end_matches('0').trim_end_matches('.').to_string();
    }
    let text = text.replace('-', "\u{2212}");
    if unit.is_empty() && prefix.is_empty() {
        text
    } else {
        format!("{text} {prefix}{unit}")
    }
}

/// An ASD with an SI prefix and at most 4 significant digits: `9 nm/√Hz`, `1.5 nrad/√Hz`,
/// `20 µrad/√Hz` (legends and captions of every figure that names a readout level).
pub fn si_asd(value: f64, unit: &str) -> String {
    const PREFIXES: [(i32, &str); 7] = [
        (-18, "a"),
        (-15, "f"),
        (-12, "p"),
        (-9, "n"),
        (-6, "µ"),
        (-3, "m"),
        (0, ""),
    ];
    if !(value.is_finite() && value > 0.0) {
        return format!("{} {unit}/√Hz", significant(value, 4));
    }
    let e3 = ((value.log10() + 1e-9).floor() as i32).div_euclid(3) * 3;
    match PREFIXES.iter().find(|(p, _)| *p == e3) {
        Some(&(p, prefix)) => {
            let scaled = value / 10f64.powi(p);
            format!("{} {prefix}{unit}/√Hz", significant(scaled, 4))
        }
        None => format!("{} {unit}/√Hz", significant(value, 4)),
    }
}

/// `v` rounded to `digits` significant digits, without trailing zeros; plain decimal from 1e-3
/// to below 1e6, else scientific (`1.5e-7`).
pub(crate) fn significant(v: f64, digits: i32) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let e = v.abs().log10().floor() as i32;
    let trim = |s: &str| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    if (-3..6).contains(&e) {
        let decimals = (digits - 1 - e).max(0) as usize;
        trim(&format!("{v:.decimals$}"))
    } else {
        let decimals = (digits - 1).max(0) as usize;
        let s = format!("{v:.decimals$e}");
        let (m, x) = s.split_once('e').unwrap_or((&s, "0"));
        format!("{}e{x}", trim(m))
    }
}

/// Whether tick labels of an axis in `unit` can carry the unit with an SI prefix (a plain unit
/// such as `Hz`, `s`, `m`, `rad`; not a ratio or a product).
pub fn si_unit(unit: &str) -> bool {
    !unit.is_empty() && unit.chars().all(|c| c.is_alphabetic())
}

/// The SI prefix (exponent, symbol) for an axis whose largest magnitude is `v`: the axis title
/// then names the prefixed unit (`frequency (mHz)`) and the ticks are plain numbers.
pub fn si_prefix(v: f64) -> (i32, &'static str) {
    if !(v.is_finite() && v != 0.0) {
        return (0, "");
    }
    let e = (v.abs().log10().floor() as i32).div_euclid(3) * 3;
    SI_PREFIXES
        .iter()
        .copied()
        .min_by_key(|(p, _)| (p - e).abs())
        .unwrap_or((0, ""))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn asds_carry_an_si_prefix() {
        assert_eq!(si_asd(9e-9, "m"), "9 nm/√Hz");
        assert_eq!(si_asd(1.5e-9, "rad"), "1.5 nrad/√Hz");
        assert_eq!(si_asd(2e-5, "rad"), "20 µrad/√Hz");
        assert_eq!(si_asd(1e-9, "m"), "1 nm/√Hz");
        assert_eq!(si_asd(3.0, "m"), "3 m/√Hz");
        assert_eq!(si_asd(1.23456e-9, "m"), "1.235 nm/√Hz");
        assert_eq!(si_asd(0.0, "m"), "0 m/√Hz");
    }

    #[test]
    fn si_values_read_as_engineers_write_them() {
        assert_eq!(si_value(1e-3, "Hz"), "1 mHz");
        assert_eq!(si_value(500.0, "Hz"), "500 Hz");
        assert_eq!(si_value(1e-5, "rad"), "10 µrad");
        assert_eq!(si_value(1e-4, "Hz"), "100 µHz");
        assert_eq!(si_value(1.3e-3, "Hz"), "1.3 mHz");
        assert_eq!(si_value(-1e-4, "rad"), "\u{2212}100 µrad");
        assert_eq!(si_value(0.0, "s"), "0");
        assert_eq!(si_value(3500.0, "s"), "3.5 ks");
        assert_eq!(si_value(999.96, "Hz"), "1 kHz");
        assert_eq!(si_value(0.41491, "Hz"), "415 mHz");
        assert_eq!(si_value(30.0, "Hz"), "30 Hz");
        assert_eq!(si_value(1e-20, "m"), "0.00001 fm");
        assert!(si_unit("Hz") && si_unit("rad") && !si_unit("m/rad") && !si_unit(""));
    }
}
