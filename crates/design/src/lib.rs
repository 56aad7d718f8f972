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
//!    fitted jointly with the current tests by the default [`subfric_fit::calibrate()`], and
//!    the achieved intervals reported beside the predicted ones.
//!
//! Modules (private): `scenarios` (the proposals under slip and traction control), `valley`
//! (step 1), `information` (step 3), `rank`, `check` (step 4); [`plan`](fn@plan) runs them in
//! order. The crate sits on the calibration (`subfric-fit`): it reads a finished fit and
//! calls the calibration for the check, never the other way round.

mod check;
mod information;
mod outcome;
mod rank;
mod rig;
mod scenarios;
mod valley;

pub use check::simulate_proposal;
pub use outcome::{
    Band, Check, CheckParam, Plan, PlanError, PlanOptions, PredictedParam, Proposal, ProposalKind,
    Rig, ValleyPoint, ValleyPrediction, NARROWS_MIN_SHRINK,
};
pub use rig::rig_of;

use check::{band_of, check};
use information::{information, PredictionContext};
use rank::rank;
use rayon::prelude::*;
use scenarios::build_candidates;
use subfric_fit::calibrate::report_variance_scale;
use subfric_fit::{FitReport, Param, Space, Status};
use subfric_reading::{typical_rate, FitTest};
use valley::walk_valley;

/// Plans the next test for the data `tests` fitted as `report` (the five parameters of the
/// paper, or whichever were free).
pub fn plan(tests: &[FitTest], report: &FitReport, opts: &PlanOptions) -> Result<Plan, PlanError> {
    plan_excluding(tests, report, opts, &|_| None)
}

/// [`plan`](fn@plan), never proposing a test for which `excluded` gives a reason (a test the
/// set already holds, say): each candidate, simulated at the planning point, is offered to it
/// before it is evaluated, and one it refuses goes to [`Plan::rejected`] with that reason.
pub fn plan_excluding(
    tests: &[FitTest],
    report: &FitReport,
    opts: &PlanOptions,
    excluded: &(dyn Fn(&FitTest) -> Option<String> + Sync),
) -> Result<Plan, PlanError> {
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
    let (mut built, mut rejected) = build_candidates(&rig, report, &fit, &planning_point, opts);
    built.retain(|(c, _, test)| match excluded(test) {
        Some(why) => {
            rejected.push((c.name.clone(), why));
            false
        }
        None => true,
    });

    // 3. Predictions at every valley point.
    let ctx = PredictionContext {
        space: &space,
        valley: &valley,
        a_now: valley
            .xs
            .par_iter()
            .map(|x| information(tests, &space, x, opts.fit.run_counter.as_ref()))
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
        run_counter: opts.fit.run_counter.as_ref(),
    };
    let proposals: Vec<Proposal> = built
        .into_par_iter()
        .map(|(c, scenario, test)| ctx.evaluate(c, scenario, test))
        .collect();
    let mut proposals = rank(proposals, valley.planning_index, &mut rejected);

    // 4. Checks of the top proposals, and the band of the top one (of those that narrow
    // anything: the others are not ranked).
    for (i, prop) in proposals
        .iter_mut()
        .filter(|p| p.narrows)
        .take(opts.check)
        .enumerate()
    {
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
        .iter()
        .find(|p| p.narrows)
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
