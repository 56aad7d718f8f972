//! A set as the lab made it: validated and summarised (`subfric check`), or made from a
//! laboratory export (`subfric import`).

use crate::folders::output::LockedFolder;
use anyhow::Result;
use std::path::Path;
use subfric_data::{import, load_set, plausibility, ExperimentSet, ImportSpec, PathKind, Warning};
use subfric_reading::{summary, SetSummary};

/// A set read and looked over.
pub struct Checked {
    /// The set.
    pub set: ExperimentSet,
    /// Its summary: tests, rows, controls, segments (`Display` gives the text `check` prints).
    pub summary: SetSummary,
    /// Plausibility warnings (a unit off by 10³, a column constant, ...).
    pub warnings: Vec<Warning>,
    /// Rig artifacts recognised in the records (a seating toe, a machine compliance), and what
    /// `fit` and `diagnose` do about them.
    pub artifacts: Vec<crate::outcome::Artifact>,
}

impl Checked {
    fn of(set: ExperimentSet) -> Checked {
        let prepared = subfric_reading::prepare_set(&set, false);
        let stiffness = subfric_reading::resolved_stiffness(&prepared);
        Checked {
            summary: summary(&set),
            warnings: plausibility(&set),
            artifacts: crate::outcome::artifacts_of(&prepared, stiffness.as_ref()),
            set,
        }
    }
}

/// `subfric check`: the set in `dir` validated (an error names the file, line and field; its
/// published parameters too), summarised, and looked over for implausible data.
pub fn check(dir: &Path) -> Result<Checked> {
    let set = load_set(dir)?;
    published(&set)?;
    Ok(Checked::of(set))
}

/// The set's published parameters (`reference_parameters` of its `experiment.json`), if it
/// gives any, checked as every parameter file is ([`subfric_model::model_from_value`]): a
/// value that is not a number, outside its parameter's domain, or not an object at all is
/// refused at its line, never dropped (a fit would then hold α_t at a typical value "as the
/// set publishes none").
pub fn published(set: &ExperimentSet) -> Result<Option<subfric_model::Model>> {
    let Some(v) = &set.meta.reference_parameters else {
        return Ok(None);
    };
    subfric_model::model_from_value(v).map(Some).map_err(|e| {
        let json = set.dir.join(subfric_data::EXPERIMENT_JSON);
        let line = crate::folders::io::read_settings_text(&json, subfric_data::EXPERIMENT_JSON)
            .ok()
            .and_then(|text| subfric_data::meta::field_line(&text, "reference_parameters"))
            .map_or(String::new(), |l| format!(":{l}"));
        anyhow::anyhow!(
            "{}{line}: field `reference_parameters`: {e} (expected the published parameters: an object of numbers mu_s, mu_k, kappa, xi, u_tilde, alpha_t in their domains, or no reference_parameters)",
            json.display()
        )
    })
}

/// `subfric import`: the laboratory export `file` read as `spec` says and added as a test of
/// the set in `out` (created if need be). Nothing in `out` is overwritten, the CSV and the
/// set's description are written all or nothing, and `out` is locked meanwhile: two imports
/// into one set at once cannot both add their test to the description each read.
pub fn import_test(file: &Path, spec: &ImportSpec, out: &Path) -> Result<Checked> {
    // Measured data never go among results (as results never go among measured data): a fit
    // could never be written there again.
    let record = out.join(crate::folders::output::SOURCE_FILE);
    if PathKind::of(&record) != PathKind::Absent {
        anyhow::bail!(
            "{}: holds the results of a subfric command ({}); a set never goes into a results folder, where the command that wrote them could not write them again (expected a set folder, or a new --out folder)",
            out.display(),
            crate::folders::output::SOURCE_FILE
        );
    }
    let lock = match PathKind::of(out) {
        PathKind::Absent | PathKind::Folder => Some(LockedFolder::new(out, &[])?),
        kind => anyhow::bail!(
            "{}: --out {} (expected a set folder, or a new folder to make one in)",
            out.display(),
            kind.describe()
        ),
    };
    let set = import(file, spec, out)?;
    if let Some(l) = lock {
        l.keep();
    }
    Ok(Checked::of(set))
}
