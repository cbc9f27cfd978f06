//! What the estimation refuses at its entry, before any spectrum is decomposed: a record with a
//! non-finite sample or spectrum value (the readers refuse such samples; a library caller may
//! not, and a decomposition of a matrix holding NaN panics or returns garbage), and a channel
//! with no power above DC (all zero or constant), which makes every bin unusable and must be
//! named rather than blamed on the band.

use super::SubtractError;
use crate::error::Num;
use crate::model::{Input, Observable};
use crate::option_key::OptionKey;
use crate::spectral::CrossSpectra;

/// The names of the witness's inputs and then of the measured observables, for messages:
/// `eta_t of the tilt record`, `X of the measured record`.
pub(super) fn channel_names(inputs: &[Input], outputs: &[Observable]) -> Vec<String> {
    inputs
        .iter()
        .map(|a| format!("{} of the tilt record", a.name()))
        .chain(
            outputs
                .iter()
                .map(|o| format!("{} of the measured record", o.name())),
        )
        .collect()
}

/// Refuses a channel with a non-finite sample or without power (every sample equal: no power
/// above DC once the Welch segments are detrended), naming it: `names` names the tilt series
/// `w` and then the measured series `y`, each over the overlap.
pub(super) fn check_channels(
    names: &[String],
    w: &[&[f64]],
    y: &[&[f64]],
) -> Result<(), SubtractError> {
    for (name, samples) in names.iter().zip(w.iter().chain(y)) {
        if let Some(k) = samples.iter().position(|v| !v.is_finite()) {
            return Err(SubtractError::Record(
                format!(
                    "{name} has the non-finite sample {} at index {k} of the overlap; allowed: \
                 finite samples (the estimation decomposes their spectra)",
                    Num(samples[k])
                )
                .into(),
            ));
        }
        if let Some(&first) = samples.first() {
            if samples.iter().all(|&v| v == first) {
                let what = match first == 0.0 {
                    true => "is zero at every sample".to_string(),
                    false => format!("is constant ({}) at every sample", Num(first)),
                };
                let name = name.clone();
                return Err(SubtractError::Record(crate::message!(
                    "{name} {what} of the overlap: a dead channel has no power to fit or \
                     subtract; leave it out ({}, {}) or check the record",
                    OptionKey::OBSERVABLES,
                    OptionKey::AXES
                )));
            }
        }
    }
    Ok(())
}

/// Refuses cross spectra with a non-finite entry (`names[i]` names channel `i`) before they
/// are decomposed, and a channel whose PSD is zero at every bin above DC (dead within every
/// Welch segment), naming the channel.
pub(super) fn check_spectra(
    spectra: &CrossSpectra,
    names: &[String],
    stretch: &str,
) -> Result<(), SubtractError> {
    for (c, name) in names.iter().enumerate() {
        let psd = spectra.psd(c);
        if psd.iter().any(|p| !p.is_finite()) {
            return Err(SubtractError::Record(
                format!(
                    "the power spectrum of {name} over the {stretch} stretch is not finite: its \
                 samples are far too large for its unit (check the units and the scale factor)"
                )
                .into(),
            ));
        }
        if psd.iter().skip(1).all(|&p| p == 0.0) {
            return Err(SubtractError::Record(
                format!(
                "{name} has no power above DC over the {stretch} stretch (constant within every \
                 Welch segment): a dead channel has no power to fit or subtract; leave it out"
            )
                .into(),
            ));
        }
        for (d, other) in names.iter().enumerate() {
            if spectra
                .csd(c, d)
                .iter()
                .any(|z| !(z.re.is_finite() && z.im.is_finite()))
            {
                return Err(SubtractError::Record(
                    format!(
                    "the cross spectrum of {name} and {other} over the {stretch} stretch is not \
                     finite: the samples are far too large for their units"
                )
                    .into(),
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::{csd_matrix, WelchConfig};

    #[test]
    fn dead_and_non_finite_channels_are_named() {
        let names = channel_names(
            &[Input::Tilt(crate::model::TiltAxis::EtaT)],
            &[Observable::X, Observable::Phi],
        );
        assert_eq!(names[1], "X of the measured record");
        let noise: Vec<f64> = (0..256).map(|k| ((k * 37 % 101) as f64).sin()).collect();
        let zero = vec![0.0; 256];
        let flat = vec![2.5; 256];
        let mut nan = noise.clone();
        nan[17] = f64::NAN;
        assert!(check_channels(&names, &[&noise], &[&noise, &noise]).is_ok());
        let e = check_channels(&names, &[&noise], &[&zero, &noise])
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("X of the measured record is zero at every sample"),
            "{e}"
        );
        let e = check_channels(&names, &[&flat], &[&noise, &noise])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("eta_t of the tilt record is constant (2.5)"),
            "{e}"
        );
        let e = check_channels(&names, &[&noise], &[&noise, &nan])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("phi of the measured record has the non-finite sample NaN at index 17"),
            "{e}"
        );
    }

    #[test]
    fn spectra_are_checked_before_they_are_decomposed() {
        let noise: Vec<f64> = (0..256).map(|k| ((k * 37 % 101) as f64).sin()).collect();
        let steps: Vec<f64> = (0..256).map(|k| (k / 32) as f64).collect();
        let names = vec!["a".to_string(), "b".to_string()];
        let cfg = WelchConfig::new(32).with_overlap(0);
        let ok = csd_matrix(&[&noise, &noise], 1.0, &cfg).unwrap();
        assert!(check_spectra(&ok, &names, "training").is_ok());
        // Constant within every segment, stepping between them: dead for the estimate.
        let dead = csd_matrix(&[&noise, &steps], 1.0, &cfg).unwrap();
        let e = check_spectra(&dead, &names, "training")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("b has no power above DC"), "{e}");
        let mut huge = noise.clone();
        huge[5] = 1e200;
        let inf = csd_matrix(&[&noise, &huge], 1.0, &cfg).unwrap();
        let e = check_spectra(&inf, &names, "training")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("power spectrum of b over the training stretch"),
            "{e}"
        );
    }
}
