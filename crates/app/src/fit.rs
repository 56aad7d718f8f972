//! The fit: sets loaded and checked, the request checked (tests, weights, fixed values,
//! bounds), the calibration run, its result withheld when it cannot be trusted, and `fit.json`.
//! Everything in the request is checked before any output folder is claimed or any fitting
//! done ([`setup`]); [`fit()`] returns the result, [`fit_to_folder`] writes it as `subfric fit`
//! does. The result ([`FitOutcome`]) is defined below the tables and reports that read it;
//! the folder form (`fit/folder.rs`) renders them, above both.

mod folder;
mod prepare;
mod run;
mod stiffness;

pub use crate::outcome::{artifacts_of, Artifact, FitOutcome};
pub use folder::{fit_to_folder, FitWritten};
pub use prepare::setup;
pub use run::{run_setup, MIN_NOISE_DEGREES_OF_FREEDOM};

use crate::folders::io::write_json;
use crate::posterior::{PosteriorRequest, Sampled};
use crate::progress::Progress;
use anyhow::Result;
use std::path::{Path, PathBuf};
use subfric_data::Warning;
use subfric_fit::{FitOptions, Param, Space};
use subfric_model::Model;
use subfric_reading::{FitTest, PreparedTest};

/// What to fit and how.
#[derive(Clone, Debug)]
pub struct FitRequest {
    /// Set folders (joint fit when several).
    pub dirs: Vec<PathBuf>,
    /// Only these tests (by name), all when empty.
    pub tests: Vec<String>,
    /// Free parameters (the five of the paper by default).
    pub free: Vec<Param>,
    /// Fixed values.
    pub fix: Vec<(Param, f64)>,
    /// Bounds in natural units, each honoured or refused.
    pub bounds: Vec<(Param, f64, f64)>,
    /// Per-test weights.
    pub weights: Vec<(String, f64)>,
    /// Sample the posterior after the fit (`--posterior`), and how.
    pub posterior: Option<PosteriorRequest>,
    /// Optimiser options.
    pub options: FitOptions,
    /// The model whose form is fitted (its extensions, with their values and its base
    /// parameters as one more start; α from it): e.g. the model a diagnosis chose. `None`:
    /// the base model of the paper, α from the published values.
    pub start: Option<Model>,
}

impl FitRequest {
    /// The default calibration of one set (as `reproduce`, `plan` and `bench` run it).
    pub fn of_set(dir: PathBuf, options: FitOptions) -> FitRequest {
        FitRequest {
            dirs: vec![dir],
            tests: vec![],
            free: Param::BASE.to_vec(),
            fix: vec![],
            bounds: vec![],
            weights: vec![],
            posterior: None,
            options,
            start: None,
        }
    }

    /// The parameters the request frees, less those it fixes.
    pub(crate) fn free_not_fixed(&self) -> Vec<Param> {
        self.free
            .iter()
            .copied()
            .filter(|p| !self.fix.iter().any(|(q, _)| q == p))
            .collect()
    }
}

/// Sets loaded, checked and charted, ready for the long work.
pub struct FitSetup {
    tests: Vec<PreparedTest>,
    /// The CSV file of each test, by test name (for messages).
    files: Vec<(String, PathBuf)>,
    fits: Vec<FitTest>,
    space: Space,
    published: Option<Model>,
    names: Vec<String>,
    /// Plausibility warnings of the sets.
    pub warnings: Vec<Warning>,
    /// Rig artifacts recognised and what the fit does about them.
    pub artifacts: Vec<Artifact>,
    /// Starting models beside the informed guesses (the request's `start`).
    starts: Vec<Model>,
    /// The request's options with the counter of the job's model runs, which its progress
    /// display was handed.
    options: FitOptions,
}

impl FitSetup {
    /// Name of the fit (set names joined by `+`).
    pub fn name(&self) -> String {
        self.names.join("+")
    }
}

/// Loads, checks and calibrates, without the content of `fit.json` (`reproduce`, `bench`).
pub fn run_fit(req: &FitRequest, progress: &dyn Progress) -> Result<FitOutcome> {
    let setup = setup(req, progress)?;
    run_setup(req, setup, progress)
}

/// A calibration as `subfric fit` runs it, with the content of its `fit.json`.
pub struct Fitted {
    /// The calibration.
    pub outcome: FitOutcome,
    /// What `subfric fit` writes to `fit.json`.
    pub json: serde_json::Value,
    /// Plausibility warnings of the sets (also given to the progress).
    pub warnings: Vec<Warning>,
    /// The posterior, when the request asked for it (also in `json`, under `posterior`).
    pub posterior: Option<Sampled>,
}

/// Loads, checks and calibrates: `subfric fit` without output files (the same checks, the
/// same calibration, the same errors), then samples the posterior when asked.
pub fn fit(req: &FitRequest, progress: &dyn Progress) -> Result<Fitted> {
    let setup = setup(req, progress)?;
    let sampler = prepare_posterior(req, &setup)?;
    let warnings = setup.warnings.clone();
    let outcome = run_setup(req, setup, progress)?;
    let posterior = sampler.map(|s| s.sample(&outcome, progress)).transpose()?;
    let json = with_posterior(fit_json(&outcome)?, &outcome, posterior.as_ref())?;
    Ok(Fitted {
        outcome,
        json,
        warnings,
        posterior,
    })
}

/// The posterior request checked against the fit (prior file, budget) before any fitting.
fn prepare_posterior(
    req: &FitRequest,
    setup: &FitSetup,
) -> Result<Option<crate::posterior::Prepared>> {
    req.posterior
        .as_ref()
        .map(|p| crate::posterior::prepare(p, &setup.space, &setup.fits))
        .transpose()
}

/// `fit.json`'s content with the posterior's block, when there is one.
fn with_posterior(
    mut json: serde_json::Value,
    outcome: &FitOutcome,
    posterior: Option<&Sampled>,
) -> Result<serde_json::Value> {
    if let (Some(p), Some(o)) = (posterior, json.as_object_mut()) {
        o.insert("posterior".into(), p.json(&outcome.report)?);
    }
    Ok(json)
}

/// Writes `fit.json` under `dir` (atomically), without the wall time: a fit.json depends on the
/// data, the code and the seed only.
pub fn write_fit(dir: &Path, out: &FitOutcome) -> Result<PathBuf> {
    let file = dir.join("fit.json");
    write_json(&file, &fit_json(out)?)?;
    Ok(file)
}

/// The content of `fit.json`: the set, the tests, the fitted parameters and model, and the
/// report without the wall time (what `subfric fit` writes and the Python package returns).
pub fn fit_json(out: &FitOutcome) -> Result<serde_json::Value> {
    let mut report = serde_json::to_value(&out.report)?;
    if let Some(o) = report
        .get_mut("optimizer")
        .and_then(serde_json::Value::as_object_mut)
    {
        o.remove("elapsed_s");
    }
    let mut v = serde_json::json!({
        "set": out.name,
        "tests": out.tests.iter().map(|t| t.fit.name.clone()).collect::<Vec<_>>(),
        "verdict": out.adequacy.json("the model"),
        "params": out.report.model.params,
        "model": out.report.model,
        "report": report,
    });
    if !out.artifacts.is_empty() {
        v["artifacts"] = serde_json::to_value(&out.artifacts)?;
    }
    if !out.read_off.is_empty() {
        v["read_off"] = serde_json::to_value(&out.read_off)?;
    }
    // Only where tests at two normal stresses or more were compared.
    if out.levels.peak.is_some() || out.levels.residual.is_some() {
        v["levels"] = serde_json::to_value(&out.levels)?;
    }
    Ok(v)
}
