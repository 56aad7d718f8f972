//! A set as the lab made it: validated and summarised (`subfric check`), or made from a
//! laboratory export (`subfric import`).

use crate::output::LockedFolder;
use anyhow::Result;
use std::path::Path;
use subfric_data::{
    import, load_set, plausibility, summary, ExperimentSet, ImportSpec, PathKind, SetSummary,
    Warning,
};

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
    pub artifacts: Vec<crate::fit::Artifact>,
}

impl Checked {
    fn of(set: ExperimentSet) -> Checked {
        let prepared = subfric_fit::prepare_set(&set, false);
        let stiffness = subfric_fit::resolved_stiffness(&prepared);
        Checked {
            summary: summary(&set),
            warnings: plausibility(&set),
            artifacts: crate::fit::artifacts_of(&prepared, stiffness.as_ref()),
            set,
        }
    }
}

/// `subfric check`: the set in `dir` validated (an error names the file, line and field),
/// summarised, and looked over for implausible data.
pub fn check(dir: &Path) -> Result<Checked> {
    Ok(Checked::of(load_set(dir)?))
}

/// `subfric import`: the laboratory export `file` read as `spec` says and added as a test of
/// the set in `out` (created if need be). Nothing in `out` is overwritten, the CSV and the
/// set's description are written all or nothing, and `out` is locked meanwhile: two imports
/// into one set at once cannot both add their test to the description each read.
pub fn import_test(file: &Path, spec: &ImportSpec, out: &Path) -> Result<Checked> {
    // Anything but a folder (or nothing) at `out`: the import says what is wrong with it.
    let lock = match PathKind::of(out) {
        PathKind::Absent | PathKind::Folder => Some(LockedFolder::new(out, &[])?),
        _ => None,
    };
    let set = import(file, spec, out)?;
    if let Some(l) = lock {
        l.keep();
    }
    Ok(Checked::of(set))
}
