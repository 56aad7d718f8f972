//! Which test to run next: proposals for one more test, ranked by how far they would take the
//! parameters the current data do not determine towards "determined", per hour of lab time.
//!
//! 1. **The valley.** The parameters the data do not determine lie along flat directions of
//!    the cost (one sliding rate: the recovery share ψ of the combined chart, the paper's κ–ξ
//!    trade-off). The primary undetermined coordinate (ψ when charted) is profiled and
//!    [`PlanOptions::valley_points`] points evenly spread over its profile interval are
//!    re-fitted with it held; the **planning point** is the one nearest the middle of that
//!    interval (in the optimiser's chart: the optimiser's own point often sits on a wall, ξ ≈ 0).
//!    Every other undetermined coordinate is walked the same way from the planning point, the
//!    primary one held. These are the parameter vectors the current data allow.
//! 2. **Proposals**, under the control the rig used, built from what the data determine (the
//!    sliding rate v, the decay length 1/λ = 1/(κ + ξ/v), the slip range, the normal stress, the
//!    sampling interval and the noise): slide–hold–slide with a series of holds, velocity steps
//!    ×3 and ×10 either side of v, a second constant rate, two-way cycles, another normal stress
//!    (under traction control: pulsating at another period, creep holds, two-way shear cycles,
//!    another normal stress). When ũ is not determined because the rows do not resolve the rise
//!    of the traction from rest (1.6/ũ of slip), every slip-controlled proposal starts slowly
//!    enough to put eight rows into it.
//! 3. **Prediction.** At every valley point the Fisher information of the joint campaign
//!    (current tests + proposal) is JᵀJ/s² in the optimiser's coordinates (the proposal at the
//!    set's noise level, s² the current fit's variance scale, correlation factor included),
//!    carried to the natural parameters by the chart's Jacobian: a predicted 95 % half-width per
//!    parameter. A proposal's **determines share** is the share of the valley points at which
//!    every parameter the current data leave undetermined is predicted within ±5 % (half the
//!    ±10 % of "determined": a margin for the scatter of one campaign); its **score** is that
//!    share per hour of lab time (test duration plus [`PlanOptions::setup_hours`] for a new
//!    specimen). Its **shrink** — the geometric mean over those parameters of current width /
//!    predicted width (each counted down to the ±5 % target, in its own scale: logarithmic for
//!    rates, relative for the others), averaged in logs over the valley — breaks ties, e.g.
//!    when no proposal determines everything. Valley regions where no test could help (ξ ≈ 0)
//!    lower every proposal's share alike and do not change the order.
//! 4. **Check.** The top proposals are simulated at the planning point with the set's noise,
//!    fitted jointly with the current tests by the default [`calibrate`], and the achieved
//!    intervals reported beside the predicted ones.

use crate::calibrate::{calibrate, report_variance_scale, FitOptions, FitReport, Status};
use crate::coverage::gauss;
use crate::dataset::{residuals_into, typical_rate, FitTest};
use crate::interval::{Interval, DETERMINED_HALF_WIDTH};
use crate::lm::{jacobian, levenberg_marquardt, LmOptions};
use crate::problem::Problem;
use crate::space::{Coord, Param, Scale, Space};
use crate::uncertainty::{linearise_stats, profile_one, stats_of_information, CHI2_1_95};
use nalgebra::DMatrix;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;
use subfric_model::{simulate_predicted_into, Control, Initial, Model, Protocol, Scenario, Stage};

/// z of a two-sided 95 % interval.
const Z95: f64 = 1.96;

/// Below this magnitude a linear-scale parameter is judged by an absolute half-width (as
/// [`crate::calibrate`] does).
const LINEAR_SCALE_FLOOR: f64 = 0.01;

/// Options of a plan.
#[derive(Clone, Copy, Debug)]
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
    Fit(#[from] crate::calibrate::FitError),
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
    /// Proposals, best score first.
    pub proposals: Vec<Proposal>,
    /// Candidates that could not be simulated at the planning point: (name, why).
    pub rejected: Vec<(String, String)>,
    /// The top proposal's predicted curve and the range the valley allows.
    #[serde(skip)]
    pub band: Option<Band>,
}

impl Plan {
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

/// The interval of half-width `h` (in the parameter's own scale) about `value`.
fn interval_of(q: Param, value: f64, h: f64) -> Interval {
    match q.scale() {
        Scale::Log => Interval::closed(value * (-h).exp(), value * h.exp()),
        Scale::RatioToMuS => Interval::closed((value - h).max(0.0), value + h),
        Scale::Linear => Interval::closed(value - h, value + h),
    }
}

/// The scale a width of parameter `q` is measured against (for shrink and "determined").
fn width_scale(q: Param, value: f64, mu_s: f64) -> f64 {
    match q.scale() {
        Scale::Log => 1.0,
        Scale::RatioToMuS => mu_s.max(1e-12),
        Scale::Linear => value.abs().max(LINEAR_SCALE_FLOOR),
    }
}

/// Predicted half-width, as a share of the value, below which a parameter earns no more
/// credit: half the ±10 % that counts as determined, so that a proposal is rewarded for
/// determining every parameter with a margin, not for pinning one ever tighter while another
/// stays open.
const TARGET_HALF_WIDTH: f64 = 0.5 * DETERMINED_HALF_WIDTH;

/// The target width in the parameter's own scale ([`TARGET_HALF_WIDTH`]).
fn target_width(q: Param, value: f64, mu_s: f64) -> f64 {
    match q.scale() {
        Scale::Log => 2.0 * TARGET_HALF_WIDTH,
        _ => {
            2.0 * TARGET_HALF_WIDTH * value.abs().max(LINEAR_SCALE_FLOOR)
                / width_scale(q, value, mu_s)
        }
    }
}

/// Width of the current interval in the parameter's own scale.
fn current_width(q: Param, value: f64, i: &Interval, mu_s: f64) -> f64 {
    match q.scale() {
        Scale::Log => {
            let lo = i.lo.max(value.abs() * 1e-12).max(1e-300);
            (i.hi.max(lo) / lo).ln()
        }
        _ => (i.hi - i.lo) / width_scale(q, value, mu_s),
    }
}

/// Predicted half-width in the parameter's own scale from a natural standard error.
fn half_width(q: Param, value: f64, se: f64) -> f64 {
    if !se.is_finite() {
        return f64::INFINITY;
    }
    match q.scale() {
        Scale::Log => Z95 * se / value.abs().max(1e-300),
        _ => Z95 * se,
    }
}

/// What a rig did, read off the tests and the fit.
pub fn rig_of(tests: &[FitTest], fit: &Model) -> Rig {
    let slip_rows: usize = tests
        .iter()
        .filter(|t| t.control == Control::Slip)
        .map(|t| t.len())
        .sum();
    let all_rows: usize = tests.iter().map(|t| t.len()).sum();
    let control = if 2 * slip_rows >= all_rows {
        Control::Slip
    } else {
        Control::Shear
    };
    let same: Vec<&FitTest> = tests.iter().filter(|t| t.control == control).collect();
    let mut normals: Vec<f64> = same.iter().flat_map(|t| t.normal.iter().copied()).collect();
    let mut steps: Vec<f64> = same
        .iter()
        .flat_map(|t| t.time.windows(2).map(|w| w[1] - w[0]))
        .filter(|d| *d > 0.0)
        .collect();
    let mut noise: Vec<f64> = same.iter().map(|t| t.noise_sd).collect();
    let slip_range_mm = same
        .iter()
        .map(|t| {
            let col = match control {
                Control::Slip => &t.imposed,
                Control::Shear => &t.measured,
            };
            let (lo, hi) = col
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
            hi - lo
        })
        .fold(0.0f64, f64::max);
    let (max_shear_kpa, period_s) = if control == Control::Shear {
        let tmax = same
            .iter()
            .flat_map(|t| t.imposed.iter())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let mut periods = Vec::new();
        for t in &same {
            let half = 0.5 * tmax;
            let ups = t
                .imposed
                .windows(2)
                .filter(|w| w[0] < half && w[1] >= half)
                .count();
            let span = t.time.last().unwrap_or(&0.0) - t.time.first().unwrap_or(&0.0);
            if ups >= 2 {
                periods.push(span / ups as f64);
            }
        }
        (tmax, median(&mut periods))
    } else {
        (0.0, 0.0)
    };
    let owned: Vec<FitTest> = same.iter().map(|t| (*t).clone()).collect();
    let rate = typical_rate(&owned);
    Rig {
        control,
        rate_mm_s: rate,
        normal_stress_kpa: median(&mut normals),
        dt_s: median(&mut steps),
        slip_range_mm,
        noise_sd: median(&mut noise),
        max_shear_kpa,
        period_s,
        decay_rate_per_mm: fit.params.kappa + fit.params.xi / rate.max(1e-300),
    }
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// A candidate test before evaluation.
struct Candidate {
    name: String,
    kind: ProposalKind,
    description: String,
    scenario: Scenario,
}

fn slide(rate: f64, distance: f64) -> Stage {
    Stage::Slide {
        rate_mm_s: rate,
        distance_mm: distance,
    }
}

/// A rate in µm/s for descriptions.
fn um_s(v: f64) -> String {
    let u = 1e3 * v;
    if u >= 10.0 {
        format!("{u:.0} µm/s")
    } else if u >= 1.0 {
        format!("{u:.1} µm/s")
    } else {
        format!("{u:.2} µm/s")
    }
}

/// Rows of the slow start within the rise of the traction.
const RISE_ROWS: f64 = 8.0;

/// Plastic slip over which the traction rises from rest to 95 % of the friction: cos(πr/2)
/// decays as exp(−(π/2)ũλ), and r = 0.95 at (π/2)ũλ = 1.62.
const RISE_TIMES_U_TILDE: f64 = 1.62;

/// When the current data do not determine ũ because their rows do not resolve the rise of the
/// traction from rest (its slip is 1.6/ũ), every proposal starts at a slower rate that puts
/// [`RISE_ROWS`] rows in the rise at the fitted ũ, over ten rise lengths: (rate, distance).
fn slow_start(rig: &Rig, report: &FitReport) -> Option<(f64, f64)> {
    let u = report.param("u_tilde")?;
    if matches!(u.status, Status::Determined | Status::Fixed) {
        return None;
    }
    let rise = RISE_TIMES_U_TILDE / u.value.max(1e-12);
    let rate = rise / (RISE_ROWS * rig.dt_s.max(1e-12));
    (rate < rig.rate_mm_s).then_some((rate, 10.0 * rise))
}

/// The candidates under slip control, each preceded by `start` (rate, distance) when given.
fn slip_candidates(rig: &Rig, start: Option<(f64, f64)>) -> Vec<Candidate> {
    let mut out = slip_tests(rig);
    if let Some((rate, distance)) = start {
        for c in out.iter_mut() {
            c.scenario.stages.insert(0, slide(rate, distance));
            c.description = format!(
                "{} (starting with {:.2} µm at {} to resolve the rise of the traction)",
                c.description,
                1e3 * distance,
                um_s(rate)
            );
        }
    }
    out
}

/// Decay lengths 1/λ after which a transient counts as settled (e^−5 < 1 %).
const SETTLE_DECAY_LENGTHS: f64 = 5.0;

/// Fewest rows of a stretch that is to show a transient or a level.
const MIN_STRETCH_ROWS: f64 = 20.0;

/// Slip of the first slide from rest, in settle lengths: the rise from rest is slower than the
/// recovery after a perturbation.
const FIRST_SLIDE_SETTLES: f64 = 3.0;

/// Fewest holds of a slide–hold–slide series: the healing's growth with the hold needs three
/// points.
const MIN_HOLDS: usize = 3;

/// Cycles of a two-way (or traction) cycle proposal.
const CYCLE_COUNT: u32 = 3;

/// Lengths and levels of the slip-controlled proposals, from what the data determine.
struct SlipGeometry {
    /// Current sliding rate v [mm/s].
    v: f64,
    /// Slip of a monotonic test [mm]: the current range, at least ten rows at v.
    d: f64,
    /// Slip to settle after a perturbation [mm].
    settle: f64,
    /// Slip to reach steady sliding from rest [mm].
    first: f64,
    /// Normal stress [kPa].
    p: f64,
    /// Sampling interval [s].
    dt: f64,
}

impl SlipGeometry {
    fn of(rig: &Rig) -> Self {
        let v = rig.rate_mm_s;
        let d = rig.slip_range_mm.max(10.0 * v * rig.dt_s);
        let lam = rig.decay_rate_per_mm.max(1e-6);
        let settle = (SETTLE_DECAY_LENGTHS / lam)
            .max(MIN_STRETCH_ROWS * v * rig.dt_s)
            .min(d);
        SlipGeometry {
            v,
            d,
            settle,
            first: (FIRST_SLIDE_SETTLES * settle).min(d).max(settle),
            p: rig.normal_stress_kpa,
            dt: rig.dt_s,
        }
    }

    /// A slip-controlled scenario at the rig's sampling interval.
    fn scenario(&self, name: &str, normal: f64, stages: Vec<Stage>) -> Scenario {
        Scenario {
            name: name.into(),
            control: Control::Slip,
            normal_stress_kpa: normal,
            dt_s: self.dt,
            stages,
        }
    }
}

/// The slip-controlled candidates (without a slow start).
fn slip_tests(rig: &Rig) -> Vec<Candidate> {
    let g = SlipGeometry::of(rig);
    let mut out = slide_hold_slide(&g);
    out.extend(velocity_steps(&g));
    out.extend(constant_rates(&g));
    out.push(two_way_cycles(&g));
    out.extend(other_normal_stresses(&g));
    out
}

/// Slide–hold–slide series of holds 1, 3, 10, 30, 100 × 3, 10 or 30 s (holds shorter than
/// three rows dropped; a series needs [`MIN_HOLDS`]).
fn slide_hold_slide(g: &SlipGeometry) -> Vec<Candidate> {
    let (v, settle, first) = (g.v, g.settle, g.first);
    let mut out = Vec::new();
    for t0 in [3.0, 10.0, 30.0] {
        let holds: Vec<f64> = [1.0, 3.0, 10.0, 30.0, 100.0]
            .iter()
            .map(|f| f * t0)
            .filter(|h| *h >= 3.0 * g.dt)
            .collect();
        if holds.len() < MIN_HOLDS {
            continue;
        }
        let mut stages = vec![slide(v, first)];
        for h in &holds {
            stages.push(Stage::Hold { duration_s: *h });
            stages.push(slide(v, 0.5 * settle));
        }
        let name = format!(
            "slide-hold-slide-{:.0}-{:.0}s",
            holds[0],
            holds[holds.len() - 1]
        );
        out.push(Candidate {
            description: format!(
                "slide {first:.3} mm at {}, then holds of {} s, each followed by {:.3} mm of sliding",
                um_s(v),
                holds
                    .iter()
                    .map(|h| format!("{h:.0}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                0.5 * settle
            ),
            scenario: g.scenario(&name, g.p, stages),
            name,
            kind: ProposalKind::SlideHoldSlide,
        });
    }
    out
}

/// Velocity steps ×3 and ×10 up from v, back, down and back.
fn velocity_steps(g: &SlipGeometry) -> Vec<Candidate> {
    let (v, first) = (g.v, g.first);
    let mut out = Vec::new();
    for f in [3.0, 10.0] {
        let name = format!("velocity-steps-x{f:.0}");
        // Each step long enough to settle, and to hold 20 rows at the fastest rate.
        let step = g.settle.max(MIN_STRETCH_ROWS * f * v * g.dt).min(g.d);
        out.push(Candidate {
            description: format!(
                "slide {first:.3} mm at {}, then steps to {}, {}, {} and back to {}, {step:.3} mm each",
                um_s(v),
                um_s(f * v),
                um_s(v),
                um_s(v / f),
                um_s(v)
            ),
            scenario: g.scenario(
                &name,
                g.p,
                vec![
                    slide(v, first),
                    Stage::VelocitySteps {
                        rates_mm_s: vec![f * v, v, v / f, v],
                        distance_mm: step,
                    },
                ],
            ),
            name,
            kind: ProposalKind::VelocitySteps,
        });
    }
    out
}

/// A monotonic test at another constant rate (÷10, ÷3, ×3, ×10).
fn constant_rates(g: &SlipGeometry) -> Vec<Candidate> {
    let (v, d) = (g.v, g.d);
    [
        (0.1, "div10"),
        (1.0 / 3.0, "div3"),
        (3.0, "x3"),
        (10.0, "x10"),
    ]
    .into_iter()
    .map(|(f, tag)| {
        let name = format!("constant-rate-{tag}");
        Candidate {
            description: format!(
                "a monotonic test over {d:.3} mm at {} instead of {}",
                um_s(f * v),
                um_s(v)
            ),
            scenario: g.scenario(&name, g.p, vec![slide(f * v, d)]),
            name,
            kind: ProposalKind::ConstantRate,
        }
    })
    .collect()
}

/// Two-way cycles whose amplitude lets the transient after each reversal settle.
fn two_way_cycles(g: &SlipGeometry) -> Candidate {
    let amplitude = (2.0 * g.settle).max(0.25 * g.d).min(0.5 * g.d);
    Candidate {
        name: "two-way-cycles".into(),
        kind: ProposalKind::TwoWayCycles,
        description: format!(
            "three two-way cycles of ±{amplitude:.3} mm at {}",
            um_s(g.v)
        ),
        scenario: g.scenario(
            "two-way-cycles",
            g.p,
            vec![Stage::Cycles {
                amplitude_mm: amplitude,
                rate_mm_s: g.v,
                count: CYCLE_COUNT,
            }],
        ),
    }
}

/// The monotonic test under twice and half the normal stress.
fn other_normal_stresses(g: &SlipGeometry) -> Vec<Candidate> {
    let (v, d, p) = (g.v, g.d, g.p);
    [(2.0, "x2"), (0.5, "half")]
        .into_iter()
        .map(|(f, tag)| {
            let name = format!("normal-stress-{tag}");
            Candidate {
                description: format!(
                    "a monotonic test over {d:.3} mm at {} under {:.0} kPa instead of {p:.0} kPa",
                    um_s(v),
                    f * p
                ),
                scenario: g.scenario(&name, f * p, vec![slide(v, d)]),
                name,
                kind: ProposalKind::NormalStress,
            }
        })
        .collect()
}

/// Cycles of a pulsating proposal.
const PULSE_COUNT: u32 = 5;

/// Period of the traction cycles when the rig's could not be read off the tests, in rows.
const DEFAULT_PERIOD_ROWS: f64 = 200.0;

/// Creep levels stay below this share of the static capacity μ_s p, so that they hold rather
/// than run away.
const CREEP_CAPACITY_SHARE: f64 = 0.95;

/// Each creep hold lasts this many periods of the rig's traction cycles: long against the
/// time scale the current tests resolve.
const CREEP_HOLD_PERIODS: f64 = 5.0;

/// Levels and times of the traction-controlled proposals.
struct ShearGeometry {
    /// Normal stress [kPa].
    p: f64,
    /// Largest imposed traction [kPa].
    tmax: f64,
    /// Period of the traction cycles [s].
    period: f64,
    /// Loading rate of those cycles [kPa/s].
    ramp: f64,
    /// Sampling interval [s].
    dt: f64,
}

impl ShearGeometry {
    fn of(rig: &Rig) -> Self {
        let tmax = rig.max_shear_kpa.max(1e-6);
        let period = if rig.period_s > 0.0 {
            rig.period_s
        } else {
            DEFAULT_PERIOD_ROWS * rig.dt_s
        };
        ShearGeometry {
            p: rig.normal_stress_kpa,
            tmax,
            period,
            ramp: 2.0 * tmax / period,
            dt: rig.dt_s,
        }
    }

    /// A traction-controlled scenario at the rig's sampling interval.
    fn scenario(&self, name: &str, normal: f64, stages: Vec<Stage>) -> Scenario {
        Scenario {
            name: name.into(),
            control: Control::Shear,
            normal_stress_kpa: normal,
            dt_s: self.dt,
            stages,
        }
    }
}

/// The candidates under traction control.
fn shear_candidates(rig: &Rig, fit: &Model) -> Vec<Candidate> {
    let g = ShearGeometry::of(rig);
    let mut out = pulsating_periods(&g);
    out.push(creep_holds(&g, fit));
    out.push(shear_cycles(&g));
    out.push(pulsating_double_normal_stress(&g));
    out
}

/// Pulsating cycles at a tenth and ten times the period.
fn pulsating_periods(g: &ShearGeometry) -> Vec<Candidate> {
    let (tmax, period) = (g.tmax, g.period);
    [(0.1, "div10"), (10.0, "x10")]
        .into_iter()
        .map(|(f, tag)| {
            let name = format!("pulsating-period-{tag}");
            Candidate {
                description: format!(
                    "five pulsating cycles 0 → {tmax:.1} kPa → 0 with a period of {:.0} s instead of {period:.0} s",
                    f * period
                ),
                scenario: g.scenario(
                    &name,
                    g.p,
                    vec![Stage::Pulsating {
                        max_kpa: tmax,
                        period_s: f * period,
                        count: PULSE_COUNT,
                    }],
                ),
                name,
                kind: ProposalKind::Pulsating,
            }
        })
        .collect()
}

/// Creep: traction held at levels between the largest imposed and the static capacity.
fn creep_holds(g: &ShearGeometry, fit: &Model) -> Candidate {
    let cap = CREEP_CAPACITY_SHARE * fit.params.mu_s * g.p;
    let levels: Vec<f64> = [1.0, 1.1, 1.2]
        .iter()
        .map(|f| (f * g.tmax).min(cap))
        .collect();
    let hold = CREEP_HOLD_PERIODS * g.period;
    let mut stages = Vec::new();
    for l in &levels {
        stages.push(Stage::ShearRamp {
            to_kpa: *l,
            rate_kpa_s: g.ramp,
        });
        stages.push(Stage::Hold { duration_s: hold });
    }
    Candidate {
        name: "creep-holds".into(),
        kind: ProposalKind::Creep,
        description: format!(
            "traction ramped at {:.2} kPa/s and held {hold:.0} s at each of {} kPa",
            g.ramp,
            levels
                .iter()
                .map(|l| format!("{l:.1}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        scenario: g.scenario("creep-holds", g.p, stages),
    }
}

/// Two-way traction cycles to the largest imposed traction.
fn shear_cycles(g: &ShearGeometry) -> Candidate {
    let (tmax, period) = (g.tmax, g.period);
    Candidate {
        name: "shear-cycles".into(),
        kind: ProposalKind::ShearCycles,
        description: format!(
            "three two-way traction cycles of ±{tmax:.1} kPa, period {period:.0} s"
        ),
        scenario: g.scenario(
            "shear-cycles",
            g.p,
            vec![Stage::ShearCycles {
                amplitude_kpa: tmax,
                period_s: period,
                count: CYCLE_COUNT,
            }],
        ),
    }
}

/// The pulsating test under twice the normal stress, to twice the traction.
fn pulsating_double_normal_stress(g: &ShearGeometry) -> Candidate {
    let p = g.p;
    Candidate {
        name: "normal-stress-x2".into(),
        kind: ProposalKind::NormalStress,
        description: format!(
            "five pulsating cycles to {:.1} kPa under {:.0} kPa instead of {p:.0} kPa",
            2.0 * g.tmax,
            2.0 * p
        ),
        scenario: g.scenario(
            "normal-stress-x2",
            2.0 * p,
            vec![Stage::Pulsating {
                max_kpa: 2.0 * g.tmax,
                period_s: g.period,
                count: PULSE_COUNT,
            }],
        ),
    }
}

/// A proposal keeps at least this many rows, whatever [`PlanOptions::max_rows`] says.
const FEWEST_ROWS: usize = 10;

/// The scenario with its time step coarsened so that it has at most `max_rows` rows.
fn within_rows(
    mut sc: Scenario,
    max_rows: usize,
) -> Option<(Scenario, subfric_model::scenario::ScenarioRows)> {
    let rows = sc.rows().ok()?;
    if rows.time.len() <= max_rows.max(FEWEST_ROWS) {
        return Some((sc, rows));
    }
    let duration = rows.time.last().copied().unwrap_or(0.0);
    sc.dt_s = duration / max_rows.max(FEWEST_ROWS) as f64;
    let rows = sc.rows().ok()?;
    Some((sc, rows))
}

/// A proposal as a test: its rows, the measured column from `model`, noise `sd`.
fn candidate_test(
    name: &str,
    control: Control,
    rows: &subfric_model::scenario::ScenarioRows,
    model: &Model,
    sd: f64,
) -> Result<FitTest, String> {
    let proto = Protocol {
        control,
        time: &rows.time,
        imposed: &rows.imposed,
        normal: &rows.normal,
        initial_slip: 0.0,
        initial: Initial::Rest,
    };
    let mut pred = Vec::new();
    simulate_predicted_into(model, &proto, &mut pred).map_err(|e| e.to_string())?;
    let mut t = FitTest::new(
        name,
        control,
        rows.time.clone(),
        rows.imposed.clone(),
        pred,
        rows.normal.clone(),
    );
    t.noise_sd = sd.max(1e-12);
    Ok(t)
}

/// JᵀJ of the noise-normalised residuals of `tests` at `x` (`None` when a test cannot be
/// simulated there).
fn information(tests: &[FitTest], space: &Space, x: &[f64]) -> Option<DMatrix<f64>> {
    let p = Problem::new(tests, space.clone());
    let mut r = Vec::new();
    let mut scratch = Vec::new();
    if residuals_into(tests, &space.model_at(x), &mut r, &mut scratch) > 0 {
        return None;
    }
    let j = jacobian(&p, x, &r, None);
    if j.iter().any(|v| !v.is_finite()) {
        return None;
    }
    Some(j.transpose() * j)
}

/// Iterations of each held re-fit of a walk: it starts next to its answer (the previous
/// point), so a few suffice.
const WALK_MAX_ITERATIONS: usize = 40;

/// Round-off allowance on the χ²₁(95 %) threshold of a walk point (the walk's own end points
/// sit on it).
const WALK_CHI2_SLACK: f64 = 1e-6;

/// A point of a valley walk: optimiser coordinates and (SSR − SSR_min)/s².
type WalkPoint = (Vec<f64>, f64);

/// Walks coordinate `k` over its profile interval: `n` points evenly spread, each re-fitted
/// with `k` held, walked outward from `x0` so that each re-fit starts next to its answer.
/// `hold`: another coordinate held at its value in `x0` (the primary valley's, so that a
/// secondary walk does not slide along it).
#[allow(clippy::too_many_arguments)]
fn walk(
    p: &Problem,
    x0: &[f64],
    ssr0: f64,
    s2: f64,
    se: f64,
    k: usize,
    n: usize,
    hold: Option<usize>,
) -> Vec<WalkPoint> {
    let prof = profile_one(p, x0, ssr0, s2, se, k);
    let (a, b) = (prof.lower.x[k], prof.upper.x[k]);
    let n = n.max(2);
    let targets: Vec<f64> = (0..n)
        .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
        .collect();
    let fixed: Vec<bool> = (0..x0.len()).map(|i| i == k || Some(i) == hold).collect();
    let opts = LmOptions {
        max_iterations: WALK_MAX_ITERATIONS,
        ..LmOptions::default()
    };
    let mut out = Vec::new();
    for side in [-1.0, 1.0] {
        let mut prev = x0.to_vec();
        let mut ts: Vec<f64> = targets
            .iter()
            .copied()
            .filter(|t| if side < 0.0 { *t < x0[k] } else { *t >= x0[k] })
            .collect();
        if side < 0.0 {
            ts.reverse();
        }
        for t in ts {
            let mut start = prev.clone();
            start[k] = t;
            let r = levenberg_marquardt(p, &start, Some(&fixed), &opts);
            let delta = (r.ssr - ssr0) / s2;
            if delta <= CHI2_1_95 + WALK_CHI2_SLACK {
                out.push((r.x.clone(), delta.max(0.0)));
            }
            prev = r.x;
        }
    }
    out
}

/// Plans the next test for the data `tests` fitted as `report` (the five parameters of the
/// paper, or whichever were free).
pub fn plan(tests: &[FitTest], report: &FitReport, opts: &PlanOptions) -> Result<Plan, PlanError> {
    if tests.iter().all(|t| t.is_empty()) {
        return Err(PlanError::NoData);
    }
    let free = params_where(report, |s| s != Status::Fixed);
    if free.is_empty() {
        return Err(PlanError::NothingFree);
    }
    let fit = report.model;
    let space = Space::with_rate(fit, &free, &[], typical_rate(tests));
    let undetermined = params_where(report, |s| !matches!(s, Status::Fixed | Status::Determined));
    let rig = rig_of(tests, &fit);

    // 1. The valley: walk every coordinate whose interval is not determined.
    let valley = walk_valley(tests, report, &space, opts);
    let planning_point = valley.points[valley.planning_index].model;

    // 2. Candidates, as tests simulated at the planning point.
    let (built, mut rejected) = build_candidates(&rig, report, &fit, &planning_point, opts);

    // 3. Predictions at every valley point.
    let ctx = PredictionContext {
        space: &space,
        valley: &valley,
        a_now: valley
            .xs
            .par_iter()
            .map(|x| information(tests, &space, x))
            .collect(),
        free: &free,
        undetermined: &undetermined,
        current: free
            .iter()
            .map(|q| report.param(q.key()).and_then(|p| p.interval))
            .collect(),
        s2: report_variance_scale(report),
        planning_point: &planning_point,
        setup_hours: opts.setup_hours,
    };
    let proposals: Vec<Proposal> = built
        .into_par_iter()
        .map(|(c, scenario, test)| ctx.evaluate(c, scenario, test))
        .collect();
    let mut proposals = rank(proposals, valley.planning_index, &mut rejected);

    // 4. Checks of the top proposals, and the band of the top one.
    for (i, prop) in proposals.iter_mut().take(opts.check).enumerate() {
        prop.check = Some(check(
            tests,
            report,
            &free,
            prop,
            &planning_point,
            &rig,
            opts,
            i as u64,
        )?);
    }
    let band = proposals
        .first()
        .and_then(|p| band_of(&p.scenario, &valley.points, &planning_point, &fit));
    Ok(Plan {
        rig,
        free: free.iter().map(|q| q.key().to_string()).collect(),
        undetermined: undetermined.iter().map(|q| q.key().to_string()).collect(),
        fit,
        planning_point,
        planning_index: valley.planning_index,
        valley: valley.points,
        proposals,
        rejected,
        band,
    })
}

/// The parameters of `report` whose status passes `keep`, in the report's order.
fn params_where(report: &FitReport, keep: impl Fn(Status) -> bool) -> Vec<Param> {
    report
        .parameters
        .iter()
        .filter(|p| keep(p.status))
        .filter_map(|p| Param::from_key(&p.name))
        .collect()
}

/// The parameter vectors the current data allow, with their optimiser coordinates.
struct Valley {
    /// The current fit first, then the primary walk, then the others.
    points: Vec<ValleyPoint>,
    /// Optimiser coordinates of each point.
    xs: Vec<Vec<f64>>,
    /// The planning point: the primary walk's point nearest the middle of its interval.
    planning_index: usize,
}

impl Valley {
    /// Appends the points of the walk along coordinate `k`.
    fn push_walk(&mut self, space: &Space, k: usize, pts: Vec<WalkPoint>) {
        for (x, d) in pts {
            self.points.push(ValleyPoint {
                model: space.model_at(&x),
                delta: d,
                walked: space.coords[k].name(),
            });
            self.xs.push(x);
        }
    }
}

/// Walks the valley (step 1 of the module documentation): the primary undetermined
/// coordinate from the current fit, the others from the planning point with the primary one
/// held.
fn walk_valley(tests: &[FitTest], report: &FitReport, space: &Space, opts: &PlanOptions) -> Valley {
    let fit = report.model;
    let problem = Problem::new(tests, space.clone());
    let x_fit = space.point_of(&fit);
    let ssr_fit = problem.ssr(&x_fit);
    let s2 = report_variance_scale(report);
    let se_x: Vec<f64> = match information(tests, space, &x_fit) {
        Some(a) => stats_of_information(&a, s2).std_errors,
        None => vec![f64::INFINITY; space.dim()],
    };
    let walked = walked_coords(space, report);
    // The planning point: the walked point nearest the middle of the primary walk (the
    // recovery share when the combined chart is used: the paper's κ–ξ valley). The other
    // undetermined coordinates are walked from it, not from the optimiser's point, which often
    // sits on a wall of the primary valley (ξ ≈ 0).
    let primary = walked
        .iter()
        .position(|&k| space.coords[k] == Coord::RecoveryShare)
        .unwrap_or(0);
    let mut valley = Valley {
        points: vec![ValleyPoint {
            model: fit,
            delta: 0.0,
            walked: "the current fit".into(),
        }],
        xs: vec![x_fit.clone()],
        planning_index: 0,
    };
    if let Some(&k) = walked.get(primary) {
        let pts = walk(
            &problem,
            &x_fit,
            ssr_fit,
            s2,
            se_x[k],
            k,
            opts.valley_points,
            None,
        );
        if let Some(i) = nearest_middle(&pts, k) {
            valley.planning_index = 1 + i;
        }
        valley.push_walk(space, k, pts);
    }
    let x_centre = valley.xs[valley.planning_index].clone();
    let others: Vec<(usize, Vec<WalkPoint>)> = walked
        .par_iter()
        .enumerate()
        .filter(|(i, _)| *i != primary)
        .map(|(_, &k)| {
            (
                k,
                walk(
                    &problem,
                    &x_centre,
                    ssr_fit,
                    s2,
                    se_x[k],
                    k,
                    opts.valley_points,
                    walked.get(primary).copied(),
                ),
            )
        })
        .collect();
    for (k, pts) in others {
        valley.push_walk(space, k, pts);
    }
    valley
}

/// The optimiser coordinates whose interval (or combination) the report does not call
/// determined.
fn walked_coords(space: &Space, report: &FitReport) -> Vec<usize> {
    let mut combos = report.combinations.iter();
    space
        .coords
        .iter()
        .enumerate()
        .filter(|(_, c)| match c {
            Coord::Natural(q) => report
                .param(q.key())
                .is_some_and(|p| p.status != Status::Determined),
            _ => combos.next().is_some_and(|c| !c.determined),
        })
        .map(|(k, _)| k)
        .collect()
}

/// Index of the walk point whose coordinate `k` is nearest the middle of the walk's range.
fn nearest_middle(pts: &[WalkPoint], k: usize) -> Option<usize> {
    let (lo, hi) = pts.iter().fold((f64::MAX, f64::MIN), |(a, b), (x, _)| {
        (a.min(x[k]), b.max(x[k]))
    });
    let mid = 0.5 * (lo + hi);
    (0..pts.len()).min_by(|&i, &j| {
        (pts[i].0[k] - mid)
            .abs()
            .total_cmp(&(pts[j].0[k] - mid).abs())
    })
}

/// A candidate with its (possibly coarsened) scenario and its test simulated at the planning
/// point.
type Built = (Candidate, Scenario, FitTest);

/// The candidates for the rig's control, each simulated at the planning point (step 2); those
/// that cannot be are returned as rejected (name, why).
fn build_candidates(
    rig: &Rig,
    report: &FitReport,
    fit: &Model,
    planning_point: &Model,
    opts: &PlanOptions,
) -> (Vec<Built>, Vec<(String, String)>) {
    let candidates = match rig.control {
        Control::Slip => slip_candidates(rig, slow_start(rig, report)),
        Control::Shear => shear_candidates(rig, fit),
    };
    let mut rejected = Vec::new();
    let mut built = Vec::new();
    for c in candidates {
        let Some((scenario, rows)) = within_rows(c.scenario.clone(), opts.max_rows) else {
            rejected.push((c.name.clone(), "the scenario generates no rows".into()));
            continue;
        };
        match candidate_test(&c.name, rig.control, &rows, planning_point, rig.noise_sd) {
            Ok(t) => built.push((c, scenario, t)),
            Err(e) => rejected.push((
                c.name.clone(),
                format!("cannot be simulated at the planning point: {e}"),
            )),
        }
    }
    (built, rejected)
}

/// What the prediction of every proposal shares (step 3).
struct PredictionContext<'a> {
    space: &'a Space,
    valley: &'a Valley,
    /// Information of the current tests at every valley point (`None`: not simulable there).
    a_now: Vec<Option<DMatrix<f64>>>,
    free: &'a [Param],
    undetermined: &'a [Param],
    /// Reported interval of each free parameter now.
    current: Vec<Option<Interval>>,
    /// Variance scale of the current fit.
    s2: f64,
    planning_point: &'a Model,
    setup_hours: f64,
}

impl PredictionContext<'_> {
    /// The proposal of a built candidate: its predictions over the valley, its share,
    /// shrink and score.
    fn evaluate(&self, c: Candidate, scenario: Scenario, test: FitTest) -> Proposal {
        let one = [test];
        let n_points = self.valley.xs.len();
        let valley_pred: Vec<ValleyPrediction> = (0..n_points)
            .filter_map(|j| self.predict_at(&one, j))
            .collect();
        let failed = n_points - valley_pred.len();
        let at_plan = valley_pred
            .iter()
            .find(|v| v.point == self.valley.planning_index)
            .map(|v| v.half_width.clone());
        // Points where the proposal cannot be simulated count as no shrink, not on target.
        let shrink =
            (valley_pred.iter().map(|v| v.log_shrink).sum::<f64>() / n_points.max(1) as f64).exp();
        let determines_share =
            valley_pred.iter().filter(|v| v.on_target).count() as f64 / n_points.max(1) as f64;
        let test_hours = scenario_hours(&one[0]);
        let hours = test_hours + self.setup_hours;
        Proposal {
            name: c.name,
            kind: c.kind,
            description: c.description,
            rows: one[0].len(),
            scenario,
            test_hours,
            hours,
            shrink,
            determines_share,
            score: determines_share / hours.max(MIN_HOURS),
            shrink_per_hour: shrink.ln() / hours.max(MIN_HOURS),
            predicted: self.predicted_at_plan(at_plan.as_deref()),
            valley: valley_pred,
            failed_points: failed,
            check: None,
        }
    }

    /// Predicted half-widths after adding `one` at valley point `j` (`None` when the current
    /// tests or the proposal cannot be simulated there).
    fn predict_at(&self, one: &[FitTest], j: usize) -> Option<ValleyPrediction> {
        let x = &self.valley.xs[j];
        let (Some(now), Some(add)) = (&self.a_now[j], information(one, self.space, x)) else {
            return None;
        };
        let joint = now + add;
        let stats = stats_of_information(&joint, self.s2);
        let lin = linearise_stats(self.space, x, &stats);
        let nat = self.space.natural(x);
        let mu_s = self.valley.points[j].model.params.mu_s;
        let hw: Vec<f64> = self
            .free
            .iter()
            .enumerate()
            .map(|(i, q)| half_width(*q, nat[i], lin.std_errors[i]))
            .collect();
        let mut on_target = true;
        let shrinks: Vec<f64> = self
            .free
            .iter()
            .enumerate()
            .filter(|(_, q)| self.undetermined.contains(q))
            .filter_map(|(i, q)| {
                let target = target_width(*q, nat[i], mu_s);
                let pred = 2.0 * hw[i] / width_scale(*q, nat[i], mu_s);
                on_target &= pred <= target;
                let cur = current_width(*q, nat[i], self.current[i].as_ref()?, mu_s);
                // Shrinking below the target earns nothing more.
                Some(if pred.is_finite() {
                    (cur / pred.max(target)).ln().max(0.0)
                } else {
                    0.0
                })
            })
            .collect();
        let log_shrink = if shrinks.is_empty() {
            0.0
        } else {
            shrinks.iter().sum::<f64>() / shrinks.len() as f64
        };
        Some(ValleyPrediction {
            point: j,
            half_width: hw,
            log_shrink,
            on_target,
        })
    }

    /// The predicted intervals at the planning point from its half-widths (`None`: the
    /// proposal could not be simulated there).
    fn predicted_at_plan(&self, at_plan: Option<&[f64]>) -> Vec<PredictedParam> {
        let nat = self
            .space
            .natural(&self.valley.xs[self.valley.planning_index]);
        let mu_s = self.planning_point.params.mu_s;
        self.free
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let h = at_plan.map_or(f64::INFINITY, |hw| hw[i]);
                let iv = h.is_finite().then(|| interval_of(*q, nat[i], h));
                let pct = match q.scale() {
                    Scale::Log => 100.0 * h.exp_m1(),
                    _ => 100.0 * h / width_scale(*q, nat[i], mu_s).max(nat[i].abs()),
                };
                let scale = match q.scale() {
                    Scale::Linear => nat[i].abs().max(LINEAR_SCALE_FLOOR),
                    _ => nat[i].abs(),
                };
                PredictedParam {
                    name: q.key().into(),
                    value: nat[i],
                    current: self.current[i],
                    predicted: iv,
                    predicted_half_width_percent: pct,
                    determined: iv
                        .is_some_and(|iv| iv.half_width() <= DETERMINED_HALF_WIDTH * scale),
                    undetermined_now: self.undetermined.contains(q),
                }
            })
            .collect()
    }
}

/// Lab time below which a score is not divided further [h] (guards a zero-hour proposal).
const MIN_HOURS: f64 = 1e-9;

/// Drops (to `rejected`) the proposals that could not be simulated at the planning point and
/// orders the rest: best score, then shrink per hour, then the shorter.
fn rank(
    mut proposals: Vec<Proposal>,
    planning_index: usize,
    rejected: &mut Vec<(String, String)>,
) -> Vec<Proposal> {
    for p in proposals
        .iter()
        .filter(|p| p.valley.iter().all(|v| v.point != planning_index))
    {
        rejected.push((
            p.name.clone(),
            "cannot be simulated at the planning point".into(),
        ));
    }
    proposals.retain(|p| p.valley.iter().any(|v| v.point == planning_index));
    proposals.sort_by(|a, b| {
        b.score
            .total_cmp(&a.score)
            .then(b.shrink_per_hour.total_cmp(&a.shrink_per_hour))
            .then(a.hours.total_cmp(&b.hours))
    });
    proposals
}

/// Duration of a test [h].
fn scenario_hours(t: &FitTest) -> f64 {
    (t.time.last().unwrap_or(&0.0) - t.time.first().unwrap_or(&0.0)) / 3600.0
}

/// A proposal simulated with `model` plus white noise of SD `sd` (seeded).
pub fn simulate_proposal(
    scenario: &Scenario,
    model: &Model,
    sd: f64,
    seed: u64,
) -> Result<FitTest, String> {
    let rows = scenario.rows().map_err(|e| e.to_string())?;
    let clean = candidate_test(&scenario.name, scenario.control, &rows, model, sd)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let noisy: Vec<f64> = clean
        .measured
        .iter()
        .map(|v| v + sd * gauss(&mut rng))
        .collect();
    Ok(FitTest::new(
        scenario.name.clone(),
        scenario.control,
        rows.time,
        rows.imposed,
        noisy,
        rows.normal,
    ))
}

#[allow(clippy::too_many_arguments)]
fn check(
    tests: &[FitTest],
    report: &FitReport,
    free: &[Param],
    prop: &Proposal,
    truth: &Model,
    rig: &Rig,
    opts: &PlanOptions,
    offset: u64,
) -> Result<Check, PlanError> {
    let seed = opts.fit.seed.wrapping_add(offset);
    let mut joint = tests.to_vec();
    match simulate_proposal(&prop.scenario, truth, rig.noise_sd, seed) {
        Ok(t) => joint.push(t),
        Err(_) => {
            return Ok(Check {
                seed,
                reduced_chi2: f64::NAN,
                parameters: Vec::new(),
                determines_all: false,
            })
        }
    }
    let space = Space::with_rate(report.model, free, &[], typical_rate(&joint));
    let r = calibrate(&joint, space, &opts.fit, &|_| {})?;
    let parameters: Vec<CheckParam> = free
        .iter()
        .zip(&prop.predicted)
        .map(|(q, pred)| {
            let t = q.get(truth).unwrap_or(f64::NAN);
            let p = r.param(q.key());
            let achieved = p.and_then(|p| p.interval);
            let width_ratio = match (achieved, pred.predicted) {
                (Some(a), Some(b)) if a.is_closed() && b.hi > b.lo => {
                    Some((a.hi - a.lo) / (b.hi - b.lo))
                }
                _ => None,
            };
            CheckParam {
                name: q.key().into(),
                truth: t,
                value: p.map_or(f64::NAN, |p| p.value),
                achieved,
                status: p.map_or(Status::Unprofiled, |p| p.status),
                predicted: pred.predicted,
                width_ratio,
                covered: achieved.is_some_and(|a| a.contains(t)),
            }
        })
        .collect();
    Ok(Check {
        seed,
        reduced_chi2: r.reduced_chi2,
        determines_all: parameters.iter().all(|p| p.status == Status::Determined),
        parameters,
    })
}

/// The predicted curve of `scenario` at the planning point, at the fit, and its range over
/// the valley.
fn band_of(
    scenario: &Scenario,
    valley: &[ValleyPoint],
    centre: &Model,
    fit: &Model,
) -> Option<Band> {
    let rows = scenario.rows().ok()?;
    let run = |m: &Model| -> Option<Vec<f64>> {
        let proto = Protocol {
            control: scenario.control,
            time: &rows.time,
            imposed: &rows.imposed,
            normal: &rows.normal,
            initial_slip: 0.0,
            initial: Initial::Rest,
        };
        let mut out = Vec::new();
        simulate_predicted_into(m, &proto, &mut out).ok()?;
        Some(out)
    };
    let c = run(centre)?;
    let f = run(fit).unwrap_or_else(|| vec![f64::NAN; c.len()]);
    let curves: Vec<Vec<f64>> = valley.par_iter().filter_map(|v| run(&v.model)).collect();
    let mut lo = c.clone();
    let mut hi = c.clone();
    for y in &curves {
        for i in 0..lo.len() {
            lo[i] = lo[i].min(y[i]);
            hi[i] = hi[i].max(y[i]);
        }
    }
    Some(Band {
        control: scenario.control,
        time: rows.time,
        imposed: rows.imposed,
        normal: rows.normal,
        centre: c,
        fit: f,
        lo,
        hi,
        curves: curves.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rig(control: Control) -> Rig {
        Rig {
            control,
            rate_mm_s: 0.01,
            normal_stress_kpa: 100.0,
            dt_s: 0.5,
            slip_range_mm: 3.0,
            noise_sd: 0.1,
            max_shear_kpa: 40.0,
            period_s: 60.0,
            decay_rate_per_mm: 2.0,
        }
    }

    #[test]
    fn every_proposal_is_a_scenario_the_rig_can_run_and_that_reads_back() {
        let fit = Model::base(subfric_model::Params::sample()).unwrap();
        for control in [Control::Slip, Control::Shear] {
            let r = rig(control);
            let cands = match control {
                Control::Slip => slip_candidates(&r, Some((1e-4, 0.005))),
                Control::Shear => shear_candidates(&r, &fit),
            };
            let kinds: std::collections::BTreeSet<String> =
                cands.iter().map(|c| format!("{:?}", c.kind)).collect();
            assert!(kinds.len() >= 4, "{control:?}: only {kinds:?}");
            for c in &cands {
                assert_eq!(c.scenario.control, control, "{}", c.name);
                let rows = c
                    .scenario
                    .rows()
                    .unwrap_or_else(|e| panic!("{}: {e}", c.name));
                assert!(rows.time.len() > 10, "{}", c.name);
                let text = serde_json::to_string(&c.scenario).unwrap();
                let back: Scenario = serde_json::from_str(&text).unwrap();
                assert_eq!(back, c.scenario, "{}", c.name);
            }
        }
    }

    #[test]
    fn a_slow_start_leads_every_slip_proposal() {
        let r = rig(Control::Slip);
        for c in slip_candidates(&r, Some((1e-4, 0.005))) {
            assert_eq!(c.scenario.stages[0], slide(1e-4, 0.005), "{}", c.name);
        }
    }

    #[test]
    fn long_proposals_are_sampled_more_coarsely_not_cut() {
        let r = rig(Control::Slip);
        let c = slip_candidates(&r, None)
            .into_iter()
            .find(|c| c.name == "constant-rate-div10")
            .unwrap();
        let full = c.scenario.rows().unwrap();
        let (sc, rows) = within_rows(c.scenario.clone(), 500).unwrap();
        assert!(rows.time.len() <= 501, "{}", rows.time.len());
        assert!(sc.dt_s > c.scenario.dt_s);
        let end = |t: &[f64]| *t.last().unwrap();
        assert!((end(&rows.time) - end(&full.time)).abs() < 1e-9);
        assert!((end(&rows.imposed) - end(&full.imposed)).abs() < 1e-12);
    }
}
