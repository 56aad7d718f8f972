//! What a calibration reports: per parameter its value, standard error, 95 % interval and
//! whether the data determine it ([`Status`]); the combinations the data determine; the
//! optimiser's run.

use crate::calibrate::Method;
use crate::dataset::TestMisfit;
use crate::interval::Interval;
use crate::lm::Termination;
use crate::space::{Param, Scale};
use crate::uncertainty::FlatDirection;
use serde::Serialize;
use subfric_model::Model;

/// Identifiability verdict of one parameter. It is written to JSON in the words the readable
/// reports use ([`Status::describe`]), so that a script, the Python package and the terminal
/// say the same thing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Status {
    /// Held at its given value.
    #[serde(rename = "fixed")]
    Fixed,
    /// The 95 % profile interval is closed and within ±10 % of the value
    /// ([`Interval::determines`]).
    #[serde(rename = "determined")]
    Determined,
    /// Closed but wider than ±10 %.
    #[serde(rename = "weakly determined")]
    Weak,
    /// Only a lower bound: the data allow any larger value.
    #[serde(rename = "not determined (lower bound only)")]
    LowerBoundOnly,
    /// Only an upper bound: the data allow any smaller value.
    #[serde(rename = "not determined (upper bound only)")]
    UpperBoundOnly,
    /// Neither bound: the data do not constrain it.
    #[serde(rename = "not determined")]
    NotDetermined,
    /// No profile computed; standard error only.
    #[serde(rename = "not profiled")]
    Unprofiled,
    /// No interval or standard error: the noise variance every interval rests on is not
    /// measured well enough (too few rows to read it, or no more rows than free parameters).
    #[serde(rename = "not determined (the noise is not measured)")]
    NoiseUnknown,
}

impl Status {
    /// Human-readable description.
    pub fn describe(self) -> &'static str {
        match self {
            Status::Fixed => "fixed",
            Status::Determined => "determined",
            Status::Weak => "weakly determined",
            Status::LowerBoundOnly => "not determined (lower bound only)",
            Status::UpperBoundOnly => "not determined (upper bound only)",
            Status::NotDetermined => "not determined",
            Status::Unprofiled => "not profiled",
            Status::NoiseUnknown => "not determined (the noise is not measured)",
        }
    }
}

/// Result for one parameter. Written to JSON with `reads`: the value as every report reads
/// it ([`ParamReport::reads`]), so a script or the Python package never takes the optimiser's
/// point of an undetermined parameter for a value.
#[derive(Clone, Debug, Serialize)]
#[serde(into = "ParamReportJson")]
pub struct ParamReport {
    /// Key.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Fitted (or fixed) value.
    pub value: f64,
    /// Linearised standard error (None if fixed or not estimable).
    pub std_error: Option<f64>,
    /// 95 % profile interval, with its open ends (None if fixed or not profiled).
    pub interval: Option<Interval>,
    /// Identifiability verdict.
    pub status: Status,
    /// Published value, when known.
    pub published: Option<f64>,
    /// (value − published)/published [%].
    pub difference_percent: Option<f64>,
}

impl ParamReport {
    /// The data leave this parameter undetermined: bounded on one side at most.
    pub fn undetermined(&self) -> bool {
        matches!(
            self.status,
            Status::NotDetermined
                | Status::LowerBoundOnly
                | Status::UpperBoundOnly
                | Status::NoiseUnknown
        )
    }

    /// The value as the reports read it, its number written by `number`: the fitted value, or
    /// "not determined (≤ b)", "(≥ a)", "(any value)" — the bound the data set, never the
    /// optimiser's point in a flat valley.
    pub fn reads_with(&self, number: impl Fn(f64) -> String) -> String {
        use crate::interval::short_number;
        match (self.status, self.interval) {
            (Status::UpperBoundOnly, Some(i)) => {
                format!("not determined (≤ {})", short_number(i.hi))
            }
            (Status::LowerBoundOnly, Some(i)) => {
                format!("not determined (≥ {})", short_number(i.lo))
            }
            (Status::NotDetermined, _) => "not determined (any value)".into(),
            (s, _) if self.undetermined() => s.describe().to_string(),
            _ => number(self.value),
        }
    }

    /// [`ParamReport::reads_with`] with about four significant digits.
    pub fn reads(&self) -> String {
        self.reads_with(crate::interval::short_number)
    }
}

/// A parameter as fit.json holds it: [`ParamReport`] and how it reads.
#[derive(Serialize)]
struct ParamReportJson {
    name: String,
    unit: String,
    value: f64,
    /// The value as the reports read it ([`ParamReport::reads`]).
    reads: String,
    std_error: Option<f64>,
    interval: Option<Interval>,
    status: Status,
    published: Option<f64>,
    difference_percent: Option<f64>,
}

impl From<ParamReport> for ParamReportJson {
    fn from(p: ParamReport) -> Self {
        ParamReportJson {
            reads: p.reads(),
            name: p.name,
            unit: p.unit,
            value: p.value,
            std_error: p.std_error,
            interval: p.interval,
            status: p.status,
            published: p.published,
            difference_percent: p.difference_percent,
        }
    }
}

/// A combination of parameters the optimiser works with, with its profile interval.
#[derive(Clone, Debug, Serialize)]
pub struct Combination {
    /// Description.
    pub name: String,
    /// Value at the optimum.
    pub value: f64,
    /// 95 % profile interval, with its open ends.
    pub interval: Option<Interval>,
    /// Closed and within ±10 % ([`Interval::determines`]).
    pub determined: bool,
}

/// Below this magnitude a linear-scale parameter (an extension's coefficient, which may be 0)
/// is judged by an absolute half-width, ±10 % of it, instead of a share of its value.
const LINEAR_SCALE_FLOOR: f64 = 0.01;

pub(crate) fn classify(q: Param, value: f64, interval: &Interval) -> Status {
    let scale = match q.scale() {
        Scale::Linear => value.abs().max(LINEAR_SCALE_FLOOR),
        _ => value.abs(),
    };
    if interval.determines(scale) {
        return Status::Determined;
    }
    match (interval.lo_open, interval.hi_open) {
        (false, false) => Status::Weak,
        (true, false) => Status::UpperBoundOnly,
        (false, true) => Status::LowerBoundOnly,
        (true, true) => Status::NotDetermined,
    }
}

/// What the optimiser did.
#[derive(Clone, Debug, Serialize)]
pub struct OptimizerReport {
    /// Local method.
    pub method: Method,
    /// Seed.
    pub seed: u64,
    /// Local runs.
    pub starts: usize,
    /// Local runs that reached the best SSR (within max(1, 0.1 %)).
    pub starts_at_best: usize,
    /// Final SSR of each local run, in start order.
    pub start_ssr: Vec<f64>,
    /// Informed first guesses read off the curves.
    pub informed_guesses: usize,
    /// Model runs of the global stage.
    pub global_evaluations: usize,
    /// Generations of differential evolution.
    pub global_generations: usize,
    /// All model runs.
    pub evaluations: usize,
    /// Termination of the best local run.
    pub termination: Termination,
    /// Whether profiling found a better optimum and the fit was re-polished from it.
    pub repolished_from_profile: bool,
    /// Wall time [s].
    pub elapsed_s: f64,
}

/// Everything a calibration found.
#[derive(Clone, Debug, Serialize)]
pub struct FitReport {
    /// The fitted model (parameters and extensions), loadable with `--params`.
    pub model: Model,
    /// Free then fixed parameters.
    pub parameters: Vec<ParamReport>,
    /// Correlation matrix of the free parameters (order of `parameters`).
    pub correlation: Vec<Vec<f64>>,
    /// Directions the data hardly constrain.
    pub flat_directions: Vec<FlatDirection>,
    /// Sum of squared noise-normalised residuals.
    pub ssr: f64,
    /// Rows fitted.
    pub rows: usize,
    /// SSR/(rows − free parameters): about 1 when the misfit is at the noise level.
    pub reduced_chi2: f64,
    /// Variance inflation for correlated residuals, τ ≥ 1 ([`noise_correlation`]): the
    /// residuals' integrated autocorrelation time in rows. Every standard error and interval
    /// is computed as if the fit had rows/τ independent rows (s² = max(1, reduced χ²)·τ).
    pub noise_correlation: f64,
    /// Per-test misfit.
    pub tests: Vec<TestMisfit>,
    /// Optimiser report.
    pub optimizer: OptimizerReport,
    /// Identifiable combinations (when μ_k, κ, ξ are charted together) with their intervals.
    pub combinations: Vec<Combination>,
    /// Profiles (value, ΔSSR/s²) per optimiser coordinate.
    pub profiles: Vec<(String, Vec<(f64, f64)>)>,
}

impl FitReport {
    /// Withholds every interval and standard error of the free parameters (their status
    /// becomes [`Status::NoiseUnknown`]) and of the combinations: the noise variance they rest
    /// on is not known. The values stay (the optimiser's point).
    pub fn withhold_intervals(&mut self) {
        for p in &mut self.parameters {
            if p.status != Status::Fixed {
                p.status = Status::NoiseUnknown;
                p.interval = None;
                p.std_error = None;
                p.difference_percent = None;
            }
        }
        for c in &mut self.combinations {
            c.interval = None;
            c.determined = false;
        }
    }

    /// Parameter report by key.
    pub fn param(&self, key: &str) -> Option<&ParamReport> {
        self.parameters.iter().find(|p| p.name == key)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(status: Status, interval: Option<Interval>) -> ParamReport {
        ParamReport {
            name: "mu_k".into(),
            unit: String::new(),
            value: 0.4725,
            std_error: Some(1e-4),
            interval,
            status,
            published: None,
            difference_percent: None,
        }
    }

    #[test]
    fn json_reads_an_undetermined_parameter_by_its_bound_never_by_its_point() {
        let open_below = Interval {
            lo: 1e-4,
            hi: 0.5,
            lo_open: true,
            hi_open: false,
        };
        let json = serde_json::to_value(report(Status::UpperBoundOnly, Some(open_below))).unwrap();
        assert_eq!(json["reads"], "not determined (≤ 0.5000)");
        assert_eq!(json["status"], "not determined (upper bound only)");
        // The point stays for simulating the fitted model.
        assert_eq!(json["value"], 0.4725);
        let closed = Interval {
            lo: 0.47,
            hi: 0.475,
            lo_open: false,
            hi_open: false,
        };
        let json = serde_json::to_value(report(Status::Determined, Some(closed))).unwrap();
        assert_eq!(json["reads"], "0.4725");
        let json = serde_json::to_value(report(Status::NoiseUnknown, None)).unwrap();
        assert_eq!(json["reads"], Status::NoiseUnknown.describe());
    }
}
