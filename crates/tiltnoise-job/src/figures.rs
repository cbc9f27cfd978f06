//! The figure options the front ends build, re-exported from `tiltnoise-plot`: a front end
//! parses its options into these types and puts them in a request; only the jobs draw. One
//! item per line.

pub use tiltnoise_plot::coherence_figure::CoherenceFigureOptions;
pub use tiltnoise_plot::methods_figure::DEFAULT_SIZE as METHODS_FIGURE_SIZE;
pub use tiltnoise_plot::tf_figure::default_size as tf_figure_size;
pub use tiltnoise_plot::tf_figure::TfFigureOptions;
pub use tiltnoise_plot::ImageFormat;
pub use tiltnoise_plot::View;
pub use tiltnoise_plot::MAX_PIXELS;
