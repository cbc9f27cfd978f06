//! What the front ends need of the file layer, re-exported: the staging of a run's outputs
//! (every output appears together when the run ends well, none otherwise), the output kinds
//! and the cleanup on an interrupt. The front ends import these from here, never from
//! `tiltnoise-io` or `tiltnoise-plot`, whose writers only the jobs call.

pub use tiltnoise_io::{
    check_outputs, remove_staging_for_exit, ExitCleanup, OutputKind, Staging, ALLOWED_EXTENSIONS,
    TOOL_VERSION,
};
