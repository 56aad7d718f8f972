//! Step 4 of the plan: the top proposals simulated at the planning point with the set's noise,
//! fitted jointly with the current tests by the default calibration, the achieved intervals
//! beside the predicted ones; and the band of the top proposal's predicted curve.

use crate::outcome::{Band, Check, CheckParam, PlanError, PlanOptions, Proposal, Rig, ValleyPoint};
use crate::scenarios::candidate_test;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use subfric_fit::{calibrate, FitReport, Param, Space, Status};
use subfric_model::{simulate_predicted_into, Initial, Model, Protocol, Scenario};
use subfric_reading::{typical_rate, FitTest};

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
        .map(|v| v + sd * normal(&mut rng))
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

/// A standard normal draw.
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// Checks proposal `prop`: simulated with `truth` plus the rig's noise (seed: the fit's seed
/// plus `offset`), fitted jointly with `tests` over the free parameters `free`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn check(
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
pub(crate) fn band_of(
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
