//! Step 2 of the plan: one more test of each kind the rig can run, as declarative scenarios
//! ([`slip`] under slip control, [`shear`] under traction control), sampled within the row
//! budget and simulated at the planning point.

mod shear;
mod slip;

use shear::shear_candidates;
use slip::{slip_candidates, slow_start};

use crate::outcome::{PlanOptions, ProposalKind, Rig};
use subfric_fit::FitReport;
use subfric_model::{simulate_predicted_into, Control, Initial, Model, Protocol, Scenario, Stage};
use subfric_reading::FitTest;

/// Cycles of a two-way (or traction) cycle proposal.
const CYCLE_COUNT: u32 = 3;

/// A candidate test before evaluation.
pub(crate) struct Candidate {
    pub(crate) name: String,
    pub(crate) kind: ProposalKind,
    pub(crate) description: String,
    pub(crate) scenario: Scenario,
}

/// Slip `distance` [mm] at `rate` [mm/s].
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
pub(crate) fn candidate_test(
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

/// A candidate with its (possibly coarsened) scenario and its test simulated at the planning
/// point.
pub(crate) type Built = (Candidate, Scenario, FitTest);

/// The candidates for the rig's control, each simulated at the planning point (step 2); those
/// that cannot be are returned as rejected (name, why).
pub(crate) fn build_candidates(
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
