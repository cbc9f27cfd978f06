//! Figure options shared by every command that draws: `--size` and `--dpi` everywhere, and
//! `--xlim`, `--ylim` where the figures have a frequency axis. One parser and one set of
//! messages, so the options mean the same everywhere, and a command's help lists only the
//! ones it takes.

use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;
use tiltnoise_core::error::Shown;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options::{self, OptionError};
use tiltnoise_job::figures::{View, MAX_PIXELS};

/// Smallest and largest figure side accepted by `--size` (pixels at 100 dpi).
const SIZE_RANGE_PX: (u32, u32) = (200, 10_000);
/// Resolutions accepted by `--dpi`.
const DPI_RANGE: (f64, f64) = (30.0, 600.0);

/// Size and resolution of the figures a command saves (.png, .svg), for figures whose axes
/// follow the results (histograms, the methods chart).
#[derive(Debug, Clone, Default, Args)]
pub struct SizeArgs {
    /// Figure size WxH in pixels at 100 dpi, each side 200 to 10000 (e.g. 1600x1200).
    #[arg(long, value_name = "WxH")]
    pub size: Option<String>,
    /// Resolution of PNG figures, 30 to 600 (default 100): the image has size x DPI/100
    /// pixels with text and lines scaled alike.
    #[arg(long, value_name = "DPI", allow_negative_numbers = true)]
    pub dpi: Option<f64>,
}

/// Axis limits, size and resolution of the figures a command saves (.png, .svg), for figures
/// with a frequency axis.
#[derive(Debug, Clone, Default, Args)]
pub struct FigureArgs {
    /// Frequency range of the figures, LO:HI in Hz with 0 < LO < HI (e.g. 1e-3:1; LO,HI is
    /// accepted too).
    #[arg(long, value_name = "LO:HI", allow_hyphen_values = true)]
    pub xlim: Option<String>,
    /// Range of the figures' log y axes (ASDs, |H|), LO:HI in the panels' units with
    /// 0 < LO < HI (e.g. 1e-14:1e-6; LO,HI is accepted too); default: chosen so every curve
    /// is visible where it matters, resonance peaks clipped at the top.
    #[arg(long, value_name = "LO:HI", allow_hyphen_values = true)]
    pub ylim: Option<String>,
    #[command(flatten)]
    pub size: SizeArgs,
}

impl SizeArgs {
    /// The validated view (size and resolution), also checking that the image of `default`
    /// size (when `--size` is absent) stays below the pixel bound at the chosen resolution.
    ///
    /// # Errors
    ///
    /// One line naming the option, the value and what is allowed.
    pub fn view_for(&self, default: (u32, u32)) -> Result<View> {
        let mut view = View::default();
        if let Some(text) = &self.size {
            view.size = Some(parse_size(text)?);
        }
        if let Some(dpi) = self.dpi {
            if !(dpi.is_finite() && (DPI_RANGE.0..=DPI_RANGE.1).contains(&dpi)) {
                bail!(
                    "--dpi {dpi}: the resolution must be a number from {} to {}",
                    DPI_RANGE.0,
                    DPI_RANGE.1
                );
            }
            view.dpi = dpi;
        }
        let (w, h) = view.pixels(default);
        if u64::from(w) * u64::from(h) > MAX_PIXELS {
            bail!(
                "--size/--dpi: a {w} x {h} pixel image is too large (at most {} megapixels)",
                MAX_PIXELS / 1_000_000
            );
        }
        Ok(view)
    }
}

impl SizeArgs {
    /// The options given, by their flags.
    fn given(&self) -> Vec<&'static str> {
        [
            ("--size", self.size.is_some()),
            ("--dpi", self.dpi.is_some()),
        ]
        .into_iter()
        .filter_map(|(flag, set)| set.then_some(flag))
        .collect()
    }

    /// Refuses these options when no output of `outputs` is a figure: they would be ignored.
    pub fn refuse_without_figure(&self, outputs: &[PathBuf]) -> Result<()> {
        refuse_without_figure(&self.given(), outputs)
    }
}

/// Refuses the figure options `given` (their flags) when none of `outputs` is a figure
/// (`.png`, `.svg`): an option that would change nothing is an error, never ignored.
pub fn refuse_without_figure(given: &[&str], outputs: &[PathBuf]) -> Result<()> {
    let figure = outputs
        .iter()
        .any(|p| tiltnoise_job::figures::image_format(p).is_ok());
    match given.first() {
        Some(flag) if !figure => bail!(
            "{flag} applies to the figures, and no figure is saved: add --save FILE.png (or \
             .svg), or leave {flag} out"
        ),
        _ => Ok(()),
    }
}

impl FigureArgs {
    /// The options given, by their flags.
    pub fn given(&self) -> Vec<&'static str> {
        let mut flags: Vec<&'static str> = [
            ("--xlim", self.xlim.is_some()),
            ("--ylim", self.ylim.is_some()),
        ]
        .into_iter()
        .filter_map(|(flag, set)| set.then_some(flag))
        .collect();
        flags.extend(self.size.given());
        flags
    }

    /// Refuses these options when no output of `outputs` is a figure: they would be ignored.
    pub fn refuse_without_figure(&self, outputs: &[PathBuf]) -> Result<()> {
        refuse_without_figure(&self.given(), outputs)
    }

    /// The validated view: [`SizeArgs::view_for`] and the axis limits.
    ///
    /// # Errors
    ///
    /// One line naming the option, the value and what is allowed.
    pub fn view_for(&self, default: (u32, u32)) -> Result<View> {
        let mut view = self.size.view_for(default)?;
        if let Some(text) = &self.xlim {
            view.x_range = Some(parse_range(OptionKey::XLIM, text, "Hz")?);
        }
        if let Some(text) = &self.ylim {
            view.y_range = Some(parse_range(OptionKey::YLIM, text, "the panels' unit")?);
        }
        Ok(view)
    }
}

/// `LO:HI` (or `LO,HI`, [`options::parse_range`]) with 0 < LO < HI.
fn parse_range(option: OptionKey, text: &str, unit: &str) -> Result<(f64, f64)> {
    let expected = format!("expected LO:HI in {unit} with 0 < LO < HI (log axes), e.g. 1e-3:1");
    let (lo, hi) = options::parse_range(option, text, &expected)?;
    if !(lo > 0.0 && hi > lo) {
        return Err(OptionError::Range {
            option,
            text: text.to_string(),
            part: None,
            expected,
        }
        .into());
    }
    Ok((lo, hi))
}

/// `WxH` in pixels, each side within [`SIZE_RANGE_PX`].
fn parse_size(text: &str) -> Result<(u32, u32)> {
    let (lo, hi) = SIZE_RANGE_PX;
    let expected = format!("expected WxH in pixels, each side {lo} to {hi}, e.g. 1600x1200");
    let Some((w, h)) = text.trim().split_once(['x', 'X']) else {
        bail!("--size {}: {expected}", Shown(text));
    };
    let side = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|v| (lo..=hi).contains(v))
    };
    match (side(w), side(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => bail!("--size {}: {expected}", Shown(text)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_and_sizes_parse_or_say_why_not() {
        for good in ["1e-3:1", "1e-3, 1", " 1e-3 : 1 "] {
            assert_eq!(
                parse_range(OptionKey::XLIM, good, "Hz").unwrap(),
                (1e-3, 1.0)
            );
        }
        for bad in ["1", "0,1", "2:1", "a,1", "1,inf", "1,2,3", "1:2:3", "1:2,3"] {
            let e = parse_range(OptionKey::XLIM, bad, "Hz").unwrap_err();
            let e = crate::option_style::rendered(&e);
            assert!(e.starts_with("--xlim ") && e.contains("0 < LO < HI"), "{e}");
        }
        assert_eq!(parse_size("1600x1200").unwrap(), (1600, 1200));
        for bad in ["1600", "10x1000", "1600x", "axb", "20000x1000"] {
            let e = parse_size(bad).unwrap_err().to_string();
            assert!(
                e.starts_with("--size ") && e.contains("200 to 10000"),
                "{e}"
            );
        }
    }
}
