//! Entry points for programs that use subfric as a library (the Python package in `python/`):
//! the pipelines of `subfric fit` and `subfric diagnose`, returning the content of `fit.json`
//! and `diagnosis.json` as values instead of writing files. Errors are the command's, located
//! the same way.

use crate::fit_cmd;
use crate::located;
use crate::progress::Progress;
use anyhow::{bail, Result};
use serde_json::Value;
use std::path::Path;
use subfric_data::{load_set, plausibility, Warning};
use subfric_diagnose::{prepare_for_diagnosis, DiagnoseOptions, Diagnosis};
use subfric_fit::PreparedTest;

pub use crate::fit_cmd::{FitOutcome, FitRequest};
pub use crate::io::load_model;
pub use crate::progress::ProgressMode;

/// A calibration as `subfric fit` runs it, with the content of its `fit.json`.
pub struct Fitted {
    /// The calibration.
    pub outcome: FitOutcome,
    /// What `subfric fit` writes to `fit.json`.
    pub json: Value,
    /// Plausibility warnings of the sets (the command prints them).
    pub warnings: Vec<Warning>,
}

/// `subfric fit` without output files: the same checks, the same calibration, the same
/// errors (a single set's errors name its folder).
pub fn fit(req: &FitRequest) -> Result<Fitted> {
    let progress = Progress::new(req.progress);
    let setup = fit_cmd::setup_fit(req, &progress)?;
    let warnings = setup.warnings.clone();
    let outcome = fit_cmd::fit_setup(req, setup, &progress).map_err(|e| match &req.dirs[..] {
        [one] => located(e, one),
        _ => e,
    })?;
    progress.finish();
    let json = fit_cmd::fit_json(&outcome)?;
    Ok(Fitted {
        outcome,
        json,
        warnings,
    })
}

/// A diagnosis as `subfric diagnose` runs it, with the content of its `diagnosis.json`.
pub struct Diagnosed {
    /// The set's name.
    pub name: String,
    /// The diagnosis.
    pub diagnosis: Diagnosis,
    /// The tests as the diagnosis saw them.
    pub prepared: Vec<PreparedTest>,
    /// What `subfric diagnose` writes to `diagnosis.json`.
    pub json: Value,
    /// Plausibility warnings of the set (the command prints them).
    pub warnings: Vec<Warning>,
}

/// `subfric diagnose` without output files: the diagnosis of the set in `dir`, refused (with
/// the set named) when it ends with a number that is not finite.
pub fn diagnose(dir: &Path, opts: &DiagnoseOptions) -> Result<Diagnosed> {
    let run = || -> Result<Diagnosed> {
        let set = load_set(dir)?;
        let warnings = plausibility(&set);
        let prepared = prepare_for_diagnosis(&set);
        let d = subfric_diagnose::diagnose(&prepared, opts)?;
        let json = diagnosis_json(&set.meta.name, &d);
        Ok(Diagnosed {
            name: set.meta.name,
            diagnosis: d,
            prepared,
            json,
            warnings,
        })
    };
    let out = run().map_err(|e| located(e, dir))?;
    check_diagnosis_finite(dir, &out.diagnosis)?;
    Ok(out)
}

/// The content of `diagnosis.json`: the set's name, the verdict, the whole diagnosis.
pub fn diagnosis_json(set_name: &str, d: &Diagnosis) -> Value {
    serde_json::json!({
        "set": set_name,
        "verdict": {
            "effect": d.verdict.effect.name(),
            "held_out_shrink": d.verdict.held_out_shrink,
            "explanation": d.verdict.explanation,
            "extra_parameters": d.verdict.extra_parameters,
        },
        "diagnosis": d,
    })
}

/// A diagnosis whose base misfit or held-out shrink is not finite is not a result: the error
/// names the set's folder `dir`.
pub fn check_diagnosis_finite(dir: &Path, d: &Diagnosis) -> Result<()> {
    if !(d.base.reduced_chi2.is_finite() && d.verdict.held_out_shrink.is_finite()) {
        bail!(
            "{}: the diagnosis ended with a number that is not finite (base misfit {}, held-out shrink {}); its result is not to be trusted",
            dir.display(),
            d.base.reduced_chi2,
            d.verdict.held_out_shrink
        );
    }
    Ok(())
}
