//! What a calibration found ([`FitOutcome`]) and the rig artifacts recognised in its records
//! ([`Artifact`]): the values the fit's table, the reports, the posterior and the plan read.
//! They sit below all of these, so that a report depends on the outcome and never the
//! reverse; the fit makes them and gives them their public paths
//! (`subfric_app::fit::FitOutcome`).

pub mod adequacy;
pub mod plan_basis;

use crate::outcome::adequacy::Adequacy;
use std::path::PathBuf;
use subfric_fit::FitReport;
use subfric_model::Model;
use subfric_reading::PreparedTest;

/// A finished calibration with what produced it.
pub struct FitOutcome {
    /// The report.
    pub report: FitReport,
    /// Does the model describe the data: the misfit and where it misses most.
    pub adequacy: Adequacy,
    /// The set folders fitted (for the next-step lines).
    pub dirs: Vec<PathBuf>,
    /// Tests fitted.
    pub tests: Vec<PreparedTest>,
    /// Published model (single set with reference parameters).
    pub published: Option<Model>,
    /// Name used for output.
    pub name: String,
    /// Rig artifacts recognised in the record and what the fit did about them.
    pub artifacts: Vec<Artifact>,
    /// μ_s and μ_k beside the peak and residual stress ratios the record shows.
    pub read_off: Vec<subfric_reading::ReadOff>,
    /// Each test's peak and residual stress ratio, and their change with the normal stress.
    pub levels: subfric_reading::LevelReadings,
}

/// A rig artifact recognised in a record, and what the fit did about it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Artifact {
    /// The test it was found in (empty for the whole set).
    pub test: String,
    /// `seating-toe` or `compliance`.
    pub kind: &'static str,
    /// What was found and done, in words.
    pub detail: String,
}

/// The rig artifacts of prepared tests: their seating toes (excluded), a normal-stress column
/// held at its levels (its scatter the reading's) and a series stiffness the loading slopes
/// resolve (fitted as α_t, unless the request fixes or frees α_t itself).
pub fn artifacts_of(
    tests: &[PreparedTest],
    stiffness: Option<&subfric_reading::Stiffness>,
) -> Vec<Artifact> {
    let mut out: Vec<Artifact> = tests
        .iter()
        .flat_map(|t| {
            let toe = t.toe.as_ref().map(|toe| Artifact {
                test: t.full.name.clone(),
                kind: "seating-toe",
                detail: toe.reason.clone(),
            });
            let held = t.segmentation.normal.held_because().map(|why| Artifact {
                test: t.full.name.clone(),
                kind: "normal-reading-noise",
                detail: why.to_string(),
            });
            toe.into_iter().chain(held)
        })
        .collect();
    if let Some(s) = stiffness {
        out.push(Artifact {
            test: String::new(),
            kind: "compliance",
            detail: format!("α_t fitted: {}", s.evidence),
        });
    }
    out
}
