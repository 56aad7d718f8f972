//! Does the model describe the data? The first thing every command that fits says: the
//! misfit against the noise estimated from the data, where the model misses most.
//!
//! One measure everywhere: the **misfit** is the mean square of the residual divided by the
//! noise variance estimated from the data (a reduced χ²; `reduced_chi2` in every JSON file),
//! written "N× the noise variance". 1 means the model follows the data to within their noise;
//! an RMS residual twice the noise is 4×. The levels are [`GAP_CHI2`] (at or below it the gap
//! is noise) and [`MODEL_ERROR_CHI2`] (at or above it model error dominates); the diagnosis
//! judges its gaps by the same two numbers (`subfric_diagnose::Thresholds` starts from them).
//! Decided here, in the fitting crate, so that a fit is judged without the diagnosis.

use crate::localise::{localise, GroupMisfit};
use crate::FitReport;
use std::fmt::Write as _;
use subfric_model::Model;
use subfric_reading::{FitTest, PreparedTest};

/// Reduced χ² (noise units) at or below which the gap between a model and its data is noise.
pub const GAP_CHI2: f64 = 1.3;

/// Reduced χ² (noise units) at or above which model error dominates: the model does not
/// describe the data, and its parameters make up for what it lacks.
pub const MODEL_ERROR_CHI2: f64 = 10.0;

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
        let level = if !reduced_chi2.is_finite() || reduced_chi2 >= MODEL_ERROR_CHI2 {
            Level::Fails
        } else if reduced_chi2 > GAP_CHI2 {
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
        let res = crate::dataset::residuals_in_noise_units(&fulls, model);
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
    fn levels_follow_the_gap_and_model_error_misfits() {
        assert_eq!(Adequacy::of_groups(0.97, &[]).level, Level::AtNoise);
        assert_eq!(Adequacy::of_groups(GAP_CHI2, &[]).level, Level::AtNoise);
        assert_eq!(
            Adequacy::of_groups(GAP_CHI2 * 1.01, &[]).level,
            Level::AboveNoise
        );
        assert_eq!(
            Adequacy::of_groups(MODEL_ERROR_CHI2 * 0.99, &[]).level,
            Level::AboveNoise
        );
        assert_eq!(
            Adequacy::of_groups(MODEL_ERROR_CHI2, &[]).level,
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
