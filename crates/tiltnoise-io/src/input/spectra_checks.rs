//! What spectra refuse: translation channels and the options of time series.

use std::path::Path;
use tiltnoise_core::input::{InputError, ReadOptions, Resolved};

/// Spectra are read for the tilt axes only: a translation channel mapped from a spectrum file
/// (an `x_t` column, or a map that asks for one) is refused rather than dropped.
pub(super) fn refuse_translation_spectra(
    path: &Path,
    resolved: &Resolved,
) -> Result<(), InputError> {
    match resolved.channels.iter().find(|m| m.tilt_axis().is_none()) {
        None => Ok(()),
        Some(m) => Err(InputError::ChannelUnit {
            path: path.to_path_buf(),
            channel: m.source.clone(),
            message: format!(
                "feeds {}, a translation of the floor, and the file holds spectra; allowed: \
                 spectra of the tilt axes (theta_t, eta_t, phi_t); give translations as a time \
                 series",
                m.input.name()
            )
            .into(),
        }),
    }
}

/// Scale factors apply to the samples of a time series; spectra refuse them rather than
/// ignore them.
pub(super) fn no_scale_for_spectra(path: &Path, opts: &ReadOptions) -> Result<(), InputError> {
    let series_only = |channel: &str, what: &str| {
        Err(InputError::Scale {
            path: path.to_path_buf(),
            channel: channel.to_string(),
            message: format!(
                "is given {what}, but the file holds spectra; allowed: {what} for time series \
                 only"
            ),
        })
    };
    if let Some(s) = opts.scale.first() {
        return series_only(&s.channel, "a scale");
    }
    if let Some(u) = opts.units.first() {
        return series_only(&u.channel, "a unit");
    }
    match opts.corrected.first().or(opts.pendulum.first()) {
        Some(c) => series_only(c, "a sensor declaration"),
        None => Ok(()),
    }
}
