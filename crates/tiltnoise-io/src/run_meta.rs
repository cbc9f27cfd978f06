//! Provenance of a run, stored with its results in self-describing formats.

/// Provenance of a run, stored alongside the results in self-describing formats (HDF5).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct RunMeta {
    /// Version of the tool that wrote the file: [`TOOL_VERSION`].
    pub tool_version: String,
    /// The full effective parameter set as TOML text ([`tiltnoise_core::params::Params::to_toml`]).
    pub params_toml: String,
    /// The command line that produced the file.
    pub command_line: String,
    /// Normal modes to record: `(index, frequency in Hz)`. The index is stored unchanged; by
    /// convention it is the mode's `index` from the `modes` module (1-based, in order of
    /// increasing frequency: the paper's nu_1 ... nu_8). Empty: no `/modes` group is written.
    pub modes: Vec<(usize, f64)>,
}

impl RunMeta {
    /// The provenance of the running process: this tool's version, `params` as TOML, the
    /// command line, and the frequencies of `modes` when given.
    pub fn of_this_run(
        params: &tiltnoise_core::params::Params,
        modes: Option<&tiltnoise_core::modes::NormalModes>,
    ) -> RunMeta {
        RunMeta {
            tool_version: TOOL_VERSION.to_string(),
            params_toml: params.to_toml(),
            command_line: std::env::args().collect::<Vec<_>>().join(" "),
            modes: modes
                .map(|m| m.modes.iter().map(|m| (m.index, m.frequency_hz)).collect())
                .unwrap_or_default(),
        }
    }
}

/// This crate's version, `env!("CARGO_PKG_VERSION")`, for [`RunMeta::tool_version`].
pub const TOOL_VERSION: &str = env!("CARGO_PKG_VERSION");
