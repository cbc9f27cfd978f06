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
pub use tiltnoise_plot::View;
pub use tiltnoise_plot::MAX_PIXELS;
