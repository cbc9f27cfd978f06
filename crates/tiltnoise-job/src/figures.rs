//! What the front ends need of the figures, re-exported: the options a request carries for
//! its figures (limits, size, resolution) and each figure's default size. The front ends
//! import these from here, never from `tiltnoise-plot`, whose drawing only the jobs call.
//! One item a line.

pub use tiltnoise_plot::mc_figure::DEFAULT_SIZE as MC_FIGURE_SIZE;
pub use tiltnoise_plot::simulate_figure::ASD_SIZE as SIMULATE_FIGURE_SIZE;
pub use tiltnoise_plot::ImageFormat;
pub use tiltnoise_plot::View;
