//! Step 3 of the plan: the information matrix of the joint campaign (current tests plus a
//! proposal) at every valley point, carried to predicted 95 % half-widths of the natural
//! parameters, and the share, shrink and score of each proposal.

use crate::outcome::{PredictedParam, Proposal, ValleyPrediction, NARROWS_MIN_SHRINK};
use crate::rank::{scenario_hours, MIN_HOURS};
use crate::scenarios::Candidate;
use crate::valley::Valley;
use nalgebra::DMatrix;
use subfric_fit::dataset::residuals_into;
use subfric_fit::interval::DETERMINED_HALF_WIDTH;
use subfric_fit::lm::jacobian;
use subfric_fit::space::Scale;
use subfric_fit::uncertainty::{linearise_stats, stats_of_information};
use subfric_fit::{Interval, Param, Problem, RunCounter, Space};
use subfric_model::{Model, Scenario};
use subfric_reading::FitTest;

/// z of a two-sided 95 % interval.
const Z95: f64 = 1.96;

/// Below this magnitude a linear-scale parameter is judged by an absolute half-width (as
/// [`subfric_fit::calibrate`] does).
const LINEAR_SCALE_FLOOR: f64 = 0.01;

/// The interval of half-width `h` (in the parameter's own scale) about `value`.
pub(crate) fn interval_of(q: Param, value: f64, h: f64) -> Interval {
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

/// JᵀJ of the noise-normalised residuals of `tests` at `x` (`None` when a test cannot be
/// simulated there); the Jacobian's model runs count into `run_counter` when given.
pub(crate) fn information(
    tests: &[FitTest],
    space: &Space,
    x: &[f64],
    run_counter: Option<&RunCounter>,
) -> Option<DMatrix<f64>> {
    let p = Problem::new(tests, space.clone()).counting(run_counter);
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

/// What the prediction of every proposal shares (step 3).
pub(crate) struct PredictionContext<'a> {
    pub(crate) space: &'a Space,
    pub(crate) valley: &'a Valley,
    /// Information of the current tests at every valley point (`None`: not simulable there).
    pub(crate) a_now: Vec<Option<DMatrix<f64>>>,
    pub(crate) free: &'a [Param],
    pub(crate) undetermined: &'a [Param],
    /// Reported interval of each free parameter now.
    pub(crate) current: Vec<Option<Interval>>,
    /// Variance scale of the current fit.
    pub(crate) s2: f64,
    pub(crate) planning_point: &'a Model,
    pub(crate) setup_hours: f64,
    /// The plan's counter of model runs (the options' [`subfric_fit::FitOptions::run_counter`]).
    pub(crate) run_counter: Option<&'a RunCounter>,
}

impl PredictionContext<'_> {
    /// The proposal of a built candidate: its predictions over the valley, its share,
    /// shrink and score.
    pub(crate) fn evaluate(&self, c: Candidate, scenario: Scenario, test: FitTest) -> Proposal {
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
            narrows: determines_share > 0.0 || shrink >= NARROWS_MIN_SHRINK,
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
        let (Some(now), Some(add)) = (
            &self.a_now[j],
            information(one, self.space, x, self.run_counter),
        ) else {
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
