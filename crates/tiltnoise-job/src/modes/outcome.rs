//! The normal modes found: tables on the terminal, JSON, nothing to save.

use crate::error::JobError;
use crate::outcome::{output_kind, Outcome, Provenance};
use std::path::Path;
use tiltnoise_core::modes::NormalModes;
use tiltnoise_io::{OutputKind, Staging};

/// The model's normal modes, its rest configuration and the provenance.
#[derive(Debug, Clone)]
pub struct ModesOutcome {
    /// The normal modes, in order of increasing frequency.
    pub modes: NormalModes,
    /// The rest configuration `q0` per coordinate (rad, m): 0 for the symmetric pendulum,
    /// the tilted equilibrium of a pendulum as built.
    pub rest_configuration: Vec<f64>,
    /// Whether the model is the symmetric pendulum (else a pendulum as built).
    pub symmetric: bool,
    pub(crate) provenance: Provenance,
}

impl Outcome for ModesOutcome {
    fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    /// None: the modes are printed, not saved (every saved output records them).
    fn output_kinds(&self) -> &'static [OutputKind] {
        &[]
    }

    fn save(&self, _stage: &Staging, path: &Path) -> Result<(), JobError> {
        output_kind(path, self.output_kinds())?;
        Ok(())
    }

    /// `modes --format json`: every mode's frequency, loss angle, quality factor (`null`
    /// when undamped), block, dominant coordinates, observable amplitudes and ratios, the
    /// observables that see it; the ratio threshold; the rest configuration.
    fn json(&self) -> serde_json::Value {
        super::json::modes_json(&self.modes, &self.rest_configuration)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::modes::{run, ModesRequest};
    use tiltnoise_core::cancel::Cancel;
    use tiltnoise_core::model::Model;
    use tiltnoise_core::params::Params;

    #[test]
    fn json_lists_keys_alphabetically_and_undamped_q_is_null() {
        let model = Model::new(&Params::table_i()).unwrap();
        let req = ModesRequest {
            model: &model,
            invocation: Default::default(),
        };
        let outcome = run(&req, &Cancel::never(), &crate::Silent).unwrap();
        let value = outcome.json();
        let text = serde_json::to_string_pretty(&value).unwrap();
        let reparsed: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(reparsed, value);
        assert!(value["modes"][0]["quality_factor"].is_null());
        assert_eq!(value["modes"][0]["undamped"], true);
        assert_eq!(outcome.provenance().modes.len(), 8);
    }
}
