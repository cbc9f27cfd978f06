//! What the front ends need of the file layer, re-exported: the staging of a run's outputs
//! (every output appears together when the run ends well, none otherwise), the output kinds
//! and the cleanup on an interrupt; the spectra and metadata of a simulated record that a
//! front end holds between the run and its `save` ([`SeriesAsd`], [`SimulationMeta`]); which
//! reader a path names ([`input_format`], to tell a file from a number in an option's value);
//! the version of the HDF5 library linked in. The front ends import these from here, never
//! from `tiltnoise-io` or `tiltnoise-plot`, whose writers only the jobs call.

pub use tiltnoise_io::input::input_format;
pub use tiltnoise_io::{
    check_outputs, hdf5_version, remove_staging_for_exit, ExitCleanup, OutputKind, SeriesAsd,
    SimulationMeta, Staging, TOOL_VERSION,
};
