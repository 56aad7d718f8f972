//! Does the model describe the data? The first thing every command that fits says: the
//! misfit against the noise estimated from the data, where the model misses most, and what
//! to do next.
//!
//! One measure everywhere: the **misfit** is the mean square of the residual divided by the
//! noise variance estimated from the data (a reduced χ²; `reduced_chi2` in every JSON file),
//! written "N× the noise variance". 1 means the model follows the data to within their noise;
//! an RMS residual twice the noise is 4×. The levels are the diagnosis's own thresholds
//! ([`subfric_diagnose::Thresholds`]): at or below `gap_chi2` the gap is noise, at or above
//! `model_error_chi2` model error dominates.

use std::fmt::Write as _;
use std::path::PathBuf;
use subfric_diagnose::localise::{localise, GroupMisfit};
use subfric_diagnose::Thresholds;
use subfric_fit::{FitReport, FitTest, PreparedTest, Status};
use subfric_model::Model;

/// What "× the noise variance" means, for the legends of every report.
pub const MISFIT_LEGEND: &str = "misfit: the mean square of the residual divided by the noise variance estimated from the data (a reduced χ²): 1 = the model follows the data to within their noise; an RMS residual twice the noise is 4×";

/// How well a model describes its data.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Level {
    /// At the noise: the model describes the data.
    AtNoise,
    /// Above the noise, but model error does not dominate.
    AboveNoise,
    /// Model error dominates: the model does not describe the data.
    Fails,
    /// The noise the misfit is measured in is not known: whether the model describes the data
    /// cannot be judged ([`Adequacy::unjudged`] says why).
    CannotJudge,
}

/// A group of rows where the model misses (a test and a kind of segment).
#[derive(Clone, Debug, serde::Serialize)]
pub struct Miss {
    /// Test / segment.
    pub group: String,
    /// Misfit of the group (× the noise variance).
    pub reduced_chi2: f64,
    /// Its share of the excess over the noise.
    pub share_of_gap: f64,
}

/// The answer to "does the model describe the data".
#[derive(Clone, Debug, serde::Serialize)]
pub struct Adequacy {
    /// Misfit on all rows (× the noise variance).
    pub reduced_chi2: f64,
    /// The level.
    pub level: Level,
    /// Where the model misses most (above the noise only).
    pub worst: Vec<Miss>,
    /// Why the misfit cannot be judged ([`Level::CannotJudge`]), if it cannot.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unjudged: Option<String>,
}

/// Groups listed as where the model misses most.
const WORST_SHOWN: usize = 3;

/// A group is listed when it holds at least this share of the excess over the noise.
const WORST_MIN_SHARE: f64 = 0.1;

impl Adequacy {
    /// From a misfit and the groups of rows it was localised by (any order).
    pub fn of_groups(reduced_chi2: f64, groups: &[GroupMisfit]) -> Adequacy {
        let th = Thresholds::default();
        let level = if !reduced_chi2.is_finite() || reduced_chi2 >= th.model_error_chi2 {
            Level::Fails
        } else if reduced_chi2 > th.gap_chi2 {
            Level::AboveNoise
        } else {
            Level::AtNoise
        };
        let mut worst: Vec<Miss> = if level == Level::AtNoise {
            Vec::new()
        } else {
            groups
                .iter()
                .filter(|g| g.share_of_gap >= WORST_MIN_SHARE)
                .map(|g| Miss {
                    group: g.group.clone(),
                    reduced_chi2: g.reduced_chi2,
                    share_of_gap: g.share_of_gap,
                })
                .collect()
        };
        worst.sort_by(|a, b| b.share_of_gap.total_cmp(&a.share_of_gap));
        worst.truncate(WORST_SHOWN);
        Adequacy {
            reduced_chi2,
            level,
            worst,
            unjudged: None,
        }
    }

    /// A misfit in units of a noise that is not known: no level, no place where the model
    /// misses, the reason instead.
    pub fn unjudged(reduced_chi2: f64, reason: String) -> Adequacy {
        Adequacy {
            reduced_chi2,
            level: Level::CannotJudge,
            worst: Vec::new(),
            unjudged: Some(reason),
        }
    }

    /// The model `model` against the prepared tests it was fitted to: misfit `reduced_chi2`,
    /// localised per test and kind of segment on every row.
    pub fn of_model(reduced_chi2: f64, tests: &[PreparedTest], model: &Model) -> Adequacy {
        let fulls: Vec<FitTest> = tests.iter().map(|t| t.full.clone()).collect();
        let res = subfric_diagnose::fits::residuals(&fulls, model, None);
        let groups = localise(tests, &res).by_test_segment;
        Adequacy::of_groups(reduced_chi2, &groups)
    }

    /// A fit's adequacy.
    pub fn of_fit(report: &FitReport, tests: &[PreparedTest]) -> Adequacy {
        Adequacy::of_model(report.reduced_chi2, tests, &report.model)
    }

    /// The verdict as JSON files give it: `describes_the_data`, `level`, `reduced_chi2`,
    /// `worst` and the `sentence` about `subject`.
    pub fn json(&self, subject: &str) -> serde_json::Value {
        serde_json::json!({
            "describes_the_data": self.describes(),
            "level": self.level,
            "reduced_chi2": self.reduced_chi2,
            "worst": self.worst,
            "sentence": self.sentence(subject),
        })
    }

    /// Whether the model describes the data (at the noise).
    pub fn describes(&self) -> bool {
        self.level == Level::AtNoise
    }

    /// One plain sentence about `subject` ("the model", "the base model"): whether it
    /// describes the data, the misfit, and where it misses most.
    pub fn sentence(&self, subject: &str) -> String {
        self.sentence_on(subject, "these data")
    }

    /// [`Adequacy::sentence`] on `data` ("these data", "the held-out data").
    pub fn sentence_on(&self, subject: &str, data: &str) -> String {
        let misfit = format!(
            "misfit {}× the noise variance (1 = the data's own noise)",
            misfit_number(self.reduced_chi2)
        );
        let mut s = match self.level {
            Level::CannotJudge => {
                return format!(
                    "cannot judge whether {subject} describes {data}: {}",
                    self.unjudged
                        .as_deref()
                        .unwrap_or("the noise is not measured")
                )
            }
            Level::AtNoise => format!("{subject} describes {data}: {misfit}"),
            Level::AboveNoise => format!("{subject} describes {data} only roughly: {misfit}"),
            Level::Fails => format!("{subject} does NOT describe {data}: {misfit}"),
        };
        if !self.worst.is_empty() {
            let parts: Vec<String> = self
                .worst
                .iter()
                .map(|w| {
                    format!(
                        "{} ({}×, {:.0} % of the excess)",
                        w.group,
                        misfit_number(w.reduced_chi2),
                        100.0 * w.share_of_gap
                    )
                })
                .collect();
            let _ = write!(s, "; it misses most in {}", parts.join(", "));
        }
        if self.level == Level::Fails {
            s.push_str(
                "; its parameters make up for what it lacks and are not properties of the interface",
            );
        }
        s
    }
}

/// A misfit with three significant digits (more when near 1, where the digits matter).
pub fn misfit_number(v: f64) -> String {
    if !v.is_finite() {
        return "∞".into();
    }
    if v >= 100.0 {
        format!("{v:.0}")
    } else if v >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// The effects `subfric diagnose` tests by default, for the next-step lines: each family's
/// description up to its colon ("rate dependence, ..., slip hardening/softening").
pub fn diagnosed_effects() -> String {
    use subfric_diagnose::Effect;
    subfric_model::terms::FAMILIES
        .iter()
        .enumerate()
        .filter(|(_, f)| f.tried_by_default())
        .map(|(i, _)| Effect::Term(i as u8))
        .map(|e| e.describe().split(':').next().unwrap_or_default())
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

#[cfg(test)]
mod tests {
    use super::*;

    fn group(name: &str, chi2: f64, share: f64) -> GroupMisfit {
        GroupMisfit {
            group: name.into(),
            rows: 100,
            rms_over_noise: chi2.sqrt(),
            reduced_chi2: chi2,
            share_of_gap: share,
        }
    }

    #[test]
    fn levels_follow_the_diagnosis_thresholds() {
        let th = Thresholds::default();
        assert_eq!(Adequacy::of_groups(0.97, &[]).level, Level::AtNoise);
        assert_eq!(
            Adequacy::of_groups(th.gap_chi2 * 1.01, &[]).level,
            Level::AboveNoise
        );
        assert_eq!(
            Adequacy::of_groups(th.model_error_chi2, &[]).level,
            Level::Fails
        );
        assert_eq!(Adequacy::of_groups(f64::NAN, &[]).level, Level::Fails);
    }

    #[test]
    fn the_sentence_says_no_and_where() {
        let groups = [
            group("shs / hold", 180.0, 0.6),
            group("vs / velocity step", 57.0, 0.35),
            group("cyclic / reversal", 1.1, 0.05),
        ];
        let a = Adequacy::of_groups(49.18, &groups);
        let s = a.sentence("the model");
        assert!(
            s.starts_with(
                "the model does NOT describe these data: misfit 49.2× the noise variance"
            ),
            "{s}"
        );
        assert!(s.contains("shs / hold (180×, 60 % of the excess)"), "{s}");
        assert!(s.contains("vs / velocity step"), "{s}");
        // A group with little of the excess is not blamed.
        assert!(!s.contains("cyclic"), "{s}");
        // At the noise: yes, and no blame.
        let ok = Adequacy::of_groups(0.97, &groups).sentence("the model");
        assert!(
            ok.starts_with("the model describes these data: misfit 0.97×"),
            "{ok}"
        );
        assert!(!ok.contains("misses"), "{ok}");
    }
}
