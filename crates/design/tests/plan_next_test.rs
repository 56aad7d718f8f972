//! Issue 15: on each single-test set of Tables 1–2 one sliding rate leaves ξ undetermined. The
//! plan's top proposal, simulated with the published parameters plus the set's noise and fitted
//! jointly with the original test (from generic starts), determines every parameter; every
//! published value lies inside its interval; and the achieved interval of ξ is within a factor
//! 2 of the one the plan predicted for that value of ξ.
//!
//! "Inside its interval" is judged family-wise: this file checks 20 intervals (5 parameters on
//! 4 sets), and 95 % intervals miss one of 20 about as often as not, so each is widened about
//! the estimate to the Bonferroni level 1 − 0.05/20 (z = 3.02 instead of 1.96). A published
//! value outside that is a real miss at the 5 % level over the whole file, not one draw of
//! the noise.

use std::path::Path;
use subfric_data::load_set;
use subfric_design::{plan, simulate_proposal, PlanOptions};
use subfric_fit::{calibrate, FitOptions, FitReport, Interval, Param, Space, Status};
use subfric_model::{Model, Params};
use subfric_reading::{prepare_set, reference_model, typical_rate, FitTest};

/// Widening of a 95 % interval to the family-wise level over the 20 intervals of this file:
/// z(1 − 0.05/40) / z(0.975) = 3.023 / 1.960.
const FAMILY_WISE_WIDENING: f64 = 3.023 / 1.960;

/// `i` (about the estimate `v`) widened by [`FAMILY_WISE_WIDENING`].
fn family_wise(i: Interval, v: f64) -> Interval {
    Interval::closed(
        v - FAMILY_WISE_WIDENING * (v - i.lo),
        v + FAMILY_WISE_WIDENING * (i.hi - v),
    )
}

fn generic_fit(tests: &[FitTest], published: &Model) -> FitReport {
    // Generic start: only α (which these data cannot see) is taken as published.
    let mut template = Model::base(Params::sample()).unwrap();
    template.params.alpha_t = published.params.alpha_t;
    template.params.alpha_n = published.params.alpha_n;
    let space = Space::with_rate(template, &Param::BASE, &[], typical_rate(tests));
    calibrate(tests, space, &FitOptions::default(), &|_| {}).expect("fit runs")
}

fn top_proposal_determines_everything(name: &str) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../experiments")
        .join(name);
    let set = load_set(&dir).expect("bundled set loads");
    let published = reference_model(&set).expect("reference parameters");
    let tests: Vec<FitTest> = prepare_set(&set, false)
        .into_iter()
        .map(|p| p.fit)
        .collect();
    let now = generic_fit(&tests, &published);
    assert_ne!(
        now.param("xi").unwrap().status,
        Status::Determined,
        "{name}: one rate cannot determine ξ"
    );
    let opts = PlanOptions {
        check: 0,
        ..PlanOptions::default()
    };
    let p = plan(&tests, &now, &opts).expect("plan runs");
    assert!(
        p.undetermined.iter().any(|k| k == "xi"),
        "{name}: the plan must know ξ is undetermined: {:?}",
        p.undetermined
    );
    let top = &p.proposals[0];
    eprintln!(
        "{name}: top proposal {} ({:.2} h, shrink ×{:.1}); ranking: {}",
        top.name,
        top.hours,
        top.shrink,
        p.proposals
            .iter()
            .map(|q| format!(
                "{} {:.2}/{:.2} (ξ ±{:.0}%)",
                q.name,
                q.score,
                q.shrink_per_hour,
                q.predicted
                    .iter()
                    .find(|x| x.name == "xi")
                    .map_or(f64::NAN, |x| x.predicted_half_width_percent)
            ))
            .collect::<Vec<_>>()
            .join(", ")
    );

    // The lab runs it: published parameters, the set's noise level.
    let new = simulate_proposal(&top.scenario, &published, p.rig.noise_sd, 15).expect("simulates");
    let mut joint = tests.clone();
    joint.push(new);
    let after = generic_fit(&joint, &published);
    for q in Param::BASE {
        let r = after.param(q.key()).unwrap();
        let truth = q.get(&published).unwrap();
        let i = r.interval.expect("profiled");
        eprintln!(
            "  {:<8} {:>10.5} {}  {:?}  published {truth}",
            q.key(),
            r.value,
            i,
            r.status
        );
        assert_eq!(
            r.status,
            Status::Determined,
            "{name} + {}: {} not determined: {i}",
            top.name,
            q.key()
        );
        let wide = family_wise(i, r.value);
        assert!(
            wide.contains(truth),
            "{name} + {}: published {} = {truth} outside {i} (family-wise {wide})",
            top.name,
            q.key()
        );
    }
    let xi = published.params.xi;
    let predicted = p
        .predicted_interval_at(0, "xi", xi)
        .expect("the plan predicts an interval for ξ");
    let achieved = after.param("xi").unwrap().interval.unwrap();
    let ratio = (achieved.hi - achieved.lo) / (predicted.hi - predicted.lo);
    eprintln!("  ξ predicted {predicted}, achieved {achieved}: width ratio {ratio:.2}");
    assert!(
        (0.5..=2.0).contains(&ratio),
        "{name}: achieved ξ interval {achieved} vs predicted {predicted} (ratio {ratio:.2})"
    );
}

#[test]
fn table1_smooth_top_proposal_determines_every_parameter() {
    top_proposal_determines_everything("table1-smooth");
}

#[test]
fn table1_medium_top_proposal_determines_every_parameter() {
    top_proposal_determines_everything("table1-medium");
}

#[test]
fn table1_rough_top_proposal_determines_every_parameter() {
    top_proposal_determines_everything("table1-rough");
}

#[test]
fn table2_ring_torsion_top_proposal_determines_every_parameter() {
    top_proposal_determines_everything("table2-ring-torsion");
}
