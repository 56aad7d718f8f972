//! What a plan holds: its options, the proposals with their predicted and checked intervals,
//! the valley, the rig, and the band of the top proposal.

use crate::information::interval_of;
use serde::Serialize;
use subfric_fit::space::Scale;
use subfric_fit::{FitOptions, Interval, Param, Status};
use subfric_model::{Control, Model, Scenario};

/// Options of a plan.
#[derive(Clone, Debug)]
pub struct PlanOptions {
    /// Lab time of a new test beyond its duration: specimen preparation, consolidation,
    /// set-up [h].
    pub setup_hours: f64,
    /// Points spread over the profile interval of each coordinate the data do not determine.
    pub valley_points: usize,
    /// Most rows of a proposal: longer tests are sampled more coarsely than the set.
    pub max_rows: usize,
    /// How many of the top proposals are checked by fitting a simulated joint campaign.
    pub check: usize,
    /// Options of the check's calibration (its seed also seeds the simulated noise).
    pub fit: FitOptions,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            setup_hours: 0.5,
            valley_points: 9,
            max_rows: 4000,
            check: 1,
            fit: FitOptions::default(),
        }
    }
}

/// Why no plan could be made.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// No test rows.
    #[error("no test rows to plan from")]
    NoData,
    /// The fit has no free parameter.
    #[error("the fit has no free parameter")]
    NothingFree,
    /// The check's calibration failed.
    #[error("check fit: {0}")]
    Fit(#[from] subfric_fit::FitError),
}

/// What kind of test a proposal is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ProposalKind {
    /// Slide–hold–slide with a series of holds.
    SlideHoldSlide,
    /// Velocity steps up and down from the current rate.
    VelocitySteps,
    /// A monotonic test at another constant rate.
    ConstantRate,
    /// Two-way slip cycles.
    TwoWayCycles,
    /// The current kind of test at another normal stress.
    NormalStress,
    /// Pulsating (one-way) traction cycles at another period.
    Pulsating,
    /// Creep: traction held at a series of levels.
    Creep,
    /// Two-way traction cycles.
    ShearCycles,
}

/// A parameter's interval now and as predicted after a proposal.
#[derive(Clone, Debug, Serialize)]
pub struct PredictedParam {
    /// Key.
    pub name: String,
    /// Value at the planning point.
    pub value: f64,
    /// Reported 95 % interval of the current fit.
    pub current: Option<Interval>,
    /// Predicted 95 % interval after the proposal (linearised; `None`: still unbounded).
    pub predicted: Option<Interval>,
    /// Predicted half-width as a share of the value [%] (of μ_s for μ_k).
    pub predicted_half_width_percent: f64,
    /// Predicted to be determined (closed, half-width ≤ 10 %).
    pub determined: bool,
    /// Not determined by the current data.
    pub undetermined_now: bool,
}

/// A parameter vector the current data allow.
#[derive(Clone, Debug, Serialize)]
pub struct ValleyPoint {
    /// The model.
    pub model: Model,
    /// (SSR − SSR_min)/s² of the current data there (≤ χ²₁(95 %) = 3.84).
    pub delta: f64,
    /// The coordinate walked to reach it.
    pub walked: String,
}

/// Predicted 95 % half-widths at one valley point, in the parameters' own scales (ln units for
/// logarithmic parameters, natural units otherwise; infinite: unbounded).
#[derive(Clone, Debug, Serialize)]
pub struct ValleyPrediction {
    /// Index into [`Plan::valley`].
    pub point: usize,
    /// Per free parameter (order of [`Plan::free`]).
    pub half_width: Vec<f64>,
    /// Mean log-shrink of the undetermined parameters there.
    pub log_shrink: f64,
    /// Every undetermined parameter predicted within the target half-width there.
    pub on_target: bool,
}

/// A parameter of the check: achieved beside predicted.
#[derive(Clone, Debug, Serialize)]
pub struct CheckParam {
    /// Key.
    pub name: String,
    /// The value the proposal was simulated with.
    pub truth: f64,
    /// Fitted value.
    pub value: f64,
    /// Achieved 95 % profile interval of the joint fit.
    pub achieved: Option<Interval>,
    /// Identifiability verdict of the joint fit.
    pub status: Status,
    /// Predicted interval.
    pub predicted: Option<Interval>,
    /// Achieved width / predicted width.
    pub width_ratio: Option<f64>,
    /// The achieved interval holds the truth.
    pub covered: bool,
}

/// A simulated joint campaign: the proposal simulated at the planning point with the set's
/// noise, fitted with the current tests.
#[derive(Clone, Debug, Serialize)]
pub struct Check {
    /// Seed of the simulated noise.
    pub seed: u64,
    /// Misfit of the joint fit.
    pub reduced_chi2: f64,
    /// Per free parameter.
    pub parameters: Vec<CheckParam>,
    /// Every parameter determined.
    pub determines_all: bool,
}

/// Least geometric-mean narrowing of the undetermined parameters' intervals for a proposal
/// that determines nothing to count as narrowing them (a tenth off their width).
pub const NARROWS_MIN_SHRINK: f64 = 1.1;

/// One proposed test.
#[derive(Clone, Debug, Serialize)]
pub struct Proposal {
    /// Name (also the scenario's).
    pub name: String,
    /// Kind.
    pub kind: ProposalKind,
    /// What it is, in words.
    pub description: String,
    /// The test as a scenario (`subfric simulate --scenario` runs it).
    pub scenario: Scenario,
    /// Duration of the test [h].
    pub test_hours: f64,
    /// Lab time: duration plus set-up [h].
    pub hours: f64,
    /// Rows.
    pub rows: usize,
    /// Geometric-mean factor by which the undetermined parameters' intervals shrink, each
    /// counted down to the target (±5 %), averaged (in logs) over the valley.
    pub shrink: f64,
    /// Share of the valley points at which every parameter the current data leave undetermined
    /// is predicted to be determined with a margin (half-width within ±5 %).
    pub determines_share: f64,
    /// `determines_share` per hour of lab time: the ranking.
    pub score: f64,
    /// ln(shrink) per hour: the ranking among proposals of equal score (e.g. when none
    /// determines everything).
    pub shrink_per_hour: f64,
    /// Whether the proposal narrows anything: it determines the undetermined parameters
    /// somewhere in the valley, or narrows their intervals by at least
    /// [`NARROWS_MIN_SHRINK`]. Proposals that narrow nothing are listed after the ranked
    /// ones, not ranked: a lab hour spent on them buys nothing the plan can see.
    pub narrows: bool,
    /// Predicted intervals at the planning point.
    pub predicted: Vec<PredictedParam>,
    /// Predicted half-widths at each valley point where the proposal could be simulated.
    pub valley: Vec<ValleyPrediction>,
    /// Valley points where the proposal cannot be simulated (e.g. runaway under traction).
    pub failed_points: usize,
    /// The check, when run.
    pub check: Option<Check>,
}

/// The predicted curve of a proposal with the range the valley allows.
#[derive(Clone, Debug)]
pub struct Band {
    /// Control of the proposal.
    pub control: Control,
    /// Time [s].
    pub time: Vec<f64>,
    /// Imposed column.
    pub imposed: Vec<f64>,
    /// Normal stress [kPa].
    pub normal: Vec<f64>,
    /// Prediction at the planning point.
    pub centre: Vec<f64>,
    /// Prediction at the current fit.
    pub fit: Vec<f64>,
    /// Lowest prediction over the valley, per row.
    pub lo: Vec<f64>,
    /// Highest prediction over the valley, per row.
    pub hi: Vec<f64>,
    /// Valley points that could be simulated.
    pub curves: usize,
}

/// What the rig did, as read off the current tests.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Rig {
    /// Control of the rig.
    pub control: Control,
    /// Typical sliding rate [mm/s] (traction control: mean slip rate).
    pub rate_mm_s: f64,
    /// Normal stress [kPa] (median).
    pub normal_stress_kpa: f64,
    /// Sampling interval [s] (median).
    pub dt_s: f64,
    /// Slip range of a test [mm] (largest).
    pub slip_range_mm: f64,
    /// Noise SD of the measured column (kPa, or mm under traction control).
    pub noise_sd: f64,
    /// Largest imposed traction [kPa] (traction control).
    pub max_shear_kpa: f64,
    /// Period of the imposed traction cycles [s] (traction control; 0 when none).
    pub period_s: f64,
    /// Decay rate λ = κ + ξ/v at the current fit [1/mm].
    pub decay_rate_per_mm: f64,
}

/// A plan: the valley, the proposals ranked, the band of the top one.
#[derive(Clone, Debug, Serialize)]
pub struct Plan {
    /// What the rig did.
    pub rig: Rig,
    /// Free parameters (order of the per-parameter vectors).
    pub free: Vec<String>,
    /// Free parameters the current data do not determine.
    pub undetermined: Vec<String>,
    /// The current fit (the optimiser's point).
    pub fit: Model,
    /// The planning point: the middle of the valley.
    pub planning_point: Model,
    /// Index of the planning point in `valley`.
    pub planning_index: usize,
    /// Parameter vectors the current data allow.
    pub valley: Vec<ValleyPoint>,
    /// Proposals, best score first; those that narrow nothing ([`Proposal::narrows`]) last.
    pub proposals: Vec<Proposal>,
    /// Candidates that could not be simulated at the planning point: (name, why).
    pub rejected: Vec<(String, String)>,
    /// The top proposal's predicted curve and the range the valley allows.
    #[serde(skip)]
    pub band: Option<Band>,
}

impl Plan {
    /// The proposals that narrow something, in their rank order.
    pub fn ranked(&self) -> impl Iterator<Item = &Proposal> {
        self.proposals.iter().filter(|p| p.narrows)
    }

    /// The best proposal, when one narrows anything.
    pub fn top(&self) -> Option<&Proposal> {
        self.ranked().next()
    }

    /// Predicted 95 % interval of parameter `key` after proposal `index` if the parameter's
    /// true value is `value`: the predicted half-width interpolated over the valley points
    /// (in ln of the value for logarithmic parameters), centred on `value`. `None` when the
    /// parameter is unknown or no valley point bounds it.
    pub fn predicted_interval_at(&self, index: usize, key: &str, value: f64) -> Option<Interval> {
        let q = Param::from_key(key)?;
        let k = self.free.iter().position(|f| f == key)?;
        let prop = self.proposals.get(index)?;
        let log = q.scale() == Scale::Log;
        let coord = |v: f64| if log { v.max(1e-300).ln() } else { v };
        // The primary walk (and the parameter's own walk, if it was walked): along the
        // other walks the parameter hardly moves while the others do.
        let primary = &self.valley[self.planning_index].walked;
        let mut pts: Vec<(f64, f64)> = prop
            .valley
            .iter()
            .filter(|vp| {
                let w = &self.valley[vp.point].walked;
                w == primary || w == key || vp.point == 0
            })
            .filter(|vp| vp.half_width[k].is_finite())
            .filter_map(|vp| {
                let v = q.get(&self.valley[vp.point].model)?;
                Some((coord(v), vp.half_width[k]))
            })
            .collect();
        if pts.is_empty() {
            return None;
        }
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let c = coord(value);
        let h = if c <= pts[0].0 {
            pts[0].1
        } else if c >= pts[pts.len() - 1].0 {
            pts[pts.len() - 1].1
        } else {
            let i = pts.iter().position(|p| p.0 >= c).unwrap_or(pts.len() - 1);
            let (a, b) = (pts[i - 1], pts[i]);
            if b.0 - a.0 <= 0.0 {
                0.5 * (a.1 + b.1)
            } else if a.1 > 0.0 && b.1 > 0.0 {
                // Half-widths vary by orders of magnitude along a valley: interpolate their log.
                let w = (c - a.0) / (b.0 - a.0);
                (a.1.ln() + w * (b.1.ln() - a.1.ln())).exp()
            } else {
                a.1 + (c - a.0) / (b.0 - a.0) * (b.1 - a.1)
            }
        };
        Some(interval_of(q, value, h))
    }
}
