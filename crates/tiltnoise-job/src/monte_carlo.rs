//! The Monte Carlo job: the normal modes over the parameter errors (the error model of the
//! parameter file, see [`tiltnoise_core::params::uncertainty`]), with the nominal modes beside
//! them.

use crate::error::JobError;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::mc::{self, McConfig, McResult};
use tiltnoise_core::model::Model;
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::params::Params;

/// A Monte Carlo of the modes to run.
#[derive(Debug, Clone, Copy)]
pub struct McRequest<'a> {
    /// The nominal parameters and their error model.
    pub params: &'a Params,
    /// Number of draws.
    pub samples: usize,
    /// Seed of the random streams (the result depends on it alone).
    pub seed: u64,
    /// Worker threads (0: every core); the result does not depend on it.
    pub threads: usize,
}

/// The draws, the configuration they were made with and the nominal modes.
pub struct McRun {
    /// The draws and their statistics.
    pub result: McResult,
    /// The configuration (the error model drawn from).
    pub config: McConfig,
    /// The nominal mode frequencies (Hz), ascending.
    pub nominal_hz: [f64; 8],
}

/// Refuses more draws or threads than allowed or than fit into memory, before anything is
/// allocated (a front end checks this before its outputs).
///
/// # Errors
///
/// [`JobError::MonteCarlo`] naming `samples` or `threads`.
pub fn check(req: &McRequest<'_>) -> Result<(), JobError> {
    let names = (
        OptionKey::new("samples").to_string(),
        OptionKey::new("threads").to_string(),
    );
    mc::check_size(req.samples, req.threads, (&names.0, &names.1))
        .map_err(|e| JobError::MonteCarlo(Box::new(e.into())))
}

/// Runs the Monte Carlo; `progress` is called from the workers with the draws done so far.
///
/// # Errors
///
/// [`JobError::MonteCarlo`]: sizes over their limits, an error model that cannot be used,
/// every draw rejected, or `cancel` set.
pub fn run(
    req: McRequest<'_>,
    cancel: &Cancel,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<McRun, JobError> {
    check(&req)?;
    let config = McConfig {
        samples: req.samples,
        seed: req.seed,
        threads: req.threads,
        cancel: cancel.clone(),
        ..McConfig::default_for(req.params)
    };
    let mc_error = |e: mc::McError| JobError::MonteCarlo(Box::new(e));
    let result = mc::run(req.params, &config, progress).map_err(mc_error)?;
    let model = Model::new(req.params).map_err(|e| mc_error(e.into()))?;
    let nominal: Vec<f64> = NormalModes::new(&model).frequencies_hz();
    let nominal_hz = <[f64; 8]>::try_from(nominal.as_slice())
        .expect("the model has eight coordinates, so eight modes");
    Ok(McRun {
        result,
        config,
        nominal_hz,
    })
}

/// The histograms' caption: what is marked, counts, seed and the error model, grouped by
/// error.
pub fn caption(run: &McRun) -> String {
    let (result, cfg) = (&run.result, &run.config);
    let mut groups: Vec<(f64, &str, Vec<&str>)> = Vec::new();
    for u in cfg.uncertainties.iter().filter(|u| u.rel_sigma > 0.0) {
        let name = u.key.split_once('.').map_or(u.key.as_str(), |(_, n)| n);
        let shape = u.distribution.name();
        match groups
            .iter_mut()
            .find(|g| g.0 == u.rel_sigma && g.1 == shape)
        {
            Some(g) => g.2.push(name),
            None => groups.push((u.rel_sigma, shape, vec![name])),
        }
    }
    let model: Vec<String> = groups
        .iter()
        .map(|(s, shape, names)| format!("{} % {shape} on {}", s * 100.0, names.join(", ")))
        .collect();
    // The [asymmetry] offsets have absolute errors, in their own unit.
    let offsets: Vec<String> = cfg
        .uncertainties
        .iter()
        .filter(|u| u.abs_sigma > 0.0)
        .map(|u| {
            let name = u.key.split_once('.').map_or(u.key.as_str(), |(_, n)| n);
            format!("{:e} {} on {name}", u.abs_sigma, u.distribution.name())
        })
        .collect();
    let absolute = if offsets.is_empty() {
        String::new()
    } else {
        format!(
            "; absolute errors (1 std, in the key's unit): {}",
            offsets.join("; ")
        )
    };
    format!(
        "Black dashed: nominal parameters; orange: mean; shaded: mean ± 1 std. {} draws, {} \
         rejected as non-physical, seed {}. Relative errors (1 std): {}{absolute}; all other \
         parameters exact.",
        result.samples,
        result.rejected,
        cfg.seed,
        model.join("; ")
    )
}
