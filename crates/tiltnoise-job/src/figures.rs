//! What the front ends need of the figures, re-exported: the options a request (or the budget
//! outcome's `save_with`) carries for its figures (limits, size, resolution) and each figure's
//! default size. A front end parses its options into these types and hands them to the job;
//! only the jobs draw. The front ends import these from here, never from `tiltnoise-plot`. One
//! item a line.

pub use tiltnoise_plot::budget_figure::BudgetFigureOptions;
pub use tiltnoise_plot::coherence_figure::CoherenceFigureOptions;
pub use tiltnoise_plot::mc_figure::DEFAULT_SIZE as MC_FIGURE_SIZE;
pub use tiltnoise_plot::methods_figure::DEFAULT_SIZE as METHODS_FIGURE_SIZE;
pub use tiltnoise_plot::simulate_figure::ASD_SIZE as SIMULATE_FIGURE_SIZE;
pub use tiltnoise_plot::tf_figure::default_size as tf_figure_size;
pub use tiltnoise_plot::tf_figure::TfFigureOptions;
pub use tiltnoise_plot::ImageFormat;

use std::path::Path;
use tiltnoise_io::{OutputError, OutputKind};

/// The output kinds of a figure.
pub const IMAGE_KINDS: &[OutputKind] = &[OutputKind::Png, OutputKind::Svg];

/// The image format the extension of `path` names ([`OutputKind::of_path`] among
/// [`IMAGE_KINDS`]).
///
/// # Errors
///
/// [`OutputError::UnknownFormat`] for an extension other than `.png`, `.svg`.
pub fn image_format(path: &Path) -> Result<ImageFormat, OutputError> {
    Ok(match OutputKind::of_path(path, IMAGE_KINDS)? {
        OutputKind::Svg => ImageFormat::Svg,
        // The one other kind of `IMAGE_KINDS`.
        _ => ImageFormat::Png,
    })
}
pub use tiltnoise_plot::View;
pub use tiltnoise_plot::MAX_PIXELS;
