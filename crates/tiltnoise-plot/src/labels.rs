//! Display names shared by the figures: observables and tilt axes with Greek letters and
//! Unicode subscripts, and panel titles.

use tiltnoise_core::model::{Observable, TiltAxis};

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
