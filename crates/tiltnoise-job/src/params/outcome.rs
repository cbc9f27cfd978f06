//! The parameter set shown: TOML on standard output, JSON, nothing to save.

use crate::error::JobError;
use crate::outcome::{output_kind, Outcome, Provenance};
use std::path::Path;
use tiltnoise_core::params::Params;
use tiltnoise_io::{OutputKind, Staging};

/// The effective parameter set and its provenance.
#[derive(Debug, Clone)]
pub struct ParamsOutcome {
    /// The parameters.
    pub params: Params,
    pub(crate) provenance: Provenance,
}

impl ParamsOutcome {
    /// The parameter set as TOML (units in the keys), as `tiltnoise params` prints it; it
    /// reads back unchanged.
    pub fn toml(&self) -> String {
        self.params.to_toml()
    }
}

impl Outcome for ParamsOutcome {
    fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    /// None: the parameter set is printed, not saved.
    fn output_kinds(&self) -> &'static [OutputKind] {
        &[]
    }

    fn save(&self, _stage: &Staging, path: &Path) -> Result<(), JobError> {
        output_kind(path, self.output_kinds())?;
        Ok(())
    }

    /// The parameter set as JSON: the TOML's tables and keys (SI units in the key names).
    fn json(&self) -> serde_json::Value {
        serde_json::to_value(&self.params).expect("JSON of plain data")
    }
}
