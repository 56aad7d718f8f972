//! What a fit's report says to do next, from whether the model describes the data. Whether
//! it does is decided in the fitting crate ([`subfric_fit::adequacy`]); the words about the
//! commands to run next (`diagnose`, `plan`) belong to the application.

use std::path::PathBuf;
pub use subfric_fit::adequacy::{misfit_number, Adequacy, Level, Miss, MISFIT_LEGEND};
use subfric_fit::{FitReport, Status};

/// The effects `subfric diagnose` tests by default, for the next-step lines: each family's
/// description up to its colon ("rate dependence, ..., slip hardening/softening").
pub fn diagnosed_effects() -> String {
    subfric_model::terms::FAMILIES
        .iter()
        .filter(|f| f.tried_by_default())
        .map(|f| f.describe().split(':').next().unwrap_or_default())
        .collect::<Vec<_>>()
        .join(", ")
}

/// What to do after a fit of the sets in `dirs`: diagnose when the model misses, plan when
/// it fits but leaves parameters undetermined, nothing when every parameter is determined.
pub fn next_steps(a: &Adequacy, report: &FitReport, dirs: &[PathBuf]) -> Vec<String> {
    let sets: Vec<String> = dirs.iter().map(|d| d.display().to_string()).collect();
    let mut out = Vec::new();
    if a.level == Level::CannotJudge {
        out.push(
            "record longer tests (tens of rows each, so that the data measure their own noise), or fix parameters with --fix: nothing can be judged before the noise is known".into(),
        );
        return out;
    }
    if !a.describes() {
        let effects = diagnosed_effects();
        for s in &sets {
            out.push(format!(
                "`subfric diagnose {s}` finds which effect the model lacks ({effects}) and how much of the gap it explains on data held out from the fit"
            ));
        }
        for s in &sets {
            out.push(format!(
                "then `subfric plan {s}` proposes the next test for the model the diagnosis chooses"
            ));
        }
        return out;
    }
    let undetermined = undetermined_names(report);
    if undetermined.is_empty() {
        out.push(
            "nothing more to measure for this model: every free parameter is determined".into(),
        );
    } else {
        for s in &sets {
            out.push(format!(
                "`subfric plan {s}` proposes the test that would determine {}",
                undetermined.join(", ")
            ));
        }
    }
    out
}

/// The free parameters a fit leaves undetermined (bounded on one side at most, or wider than
/// ±10 % of their value).
pub fn undetermined_names(report: &FitReport) -> Vec<String> {
    report
        .parameters
        .iter()
        .filter(|p| !matches!(p.status, Status::Fixed | Status::Determined))
        .map(|p| p.name.clone())
        .collect()
}
