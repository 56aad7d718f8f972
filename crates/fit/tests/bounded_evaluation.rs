//! A trial point the optimiser will reject is stopped where its sum of squares is sure to end
//! above the point it challenges (`Residuals::residuals_unless_above`), and a local run a refit
//! would repeat is taken from a memo (`FitOptions::local_memo`). Neither may change a result:
//! each is checked against the same computation done whole.

use subfric_fit::global::{differential_evolution, DeOptions};
use subfric_fit::lm::{levenberg_marquardt, LmOptions};
use subfric_fit::{
    calibrate_from, Bounded, FitOptions, LocalMemo, Param, Problem, Residuals, Space,
};
use subfric_model::{simulate, Control, Model, Params, Protocol};
use subfric_reading::FitTest;

/// A slip-controlled test of the sample parameters: a monotonic slide at `rate` mm/s with a
/// little synthetic noise, so no point of the box fits exactly.
fn monotonic(name: &str, rate: f64) -> FitTest {
    let truth = Model::base(Params::sample()).unwrap();
    let time: Vec<f64> = (0..=240).map(|i| i as f64).collect();
    let slip: Vec<f64> = time.iter().map(|t| rate * t).collect();
    let normal = vec![100.0; time.len()];
    let proto = Protocol {
        control: Control::Slip,
        time: &time,
        imposed: &slip,
        normal: &normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    let shear: Vec<f64> = simulate(&truth, &proto)
        .unwrap()
        .shear
        .iter()
        .enumerate()
        .map(|(i, s)| s + 0.05 * ((i * 7919 % 13) as f64 - 6.0))
        .collect();
    FitTest::new(name, Control::Slip, time, slip, shear, normal)
}

fn tests() -> Vec<FitTest> {
    vec![monotonic("slow", 0.01), monotonic("fast", 0.05)]
}

/// μ_s, μ_k, κ and ũ free, started away from the truth.
fn space() -> Space {
    let mut start = Model::base(Params::sample()).unwrap();
    start.params.mu_s = 0.7;
    start.params.u_tilde = 50.0;
    Space::new(
        start,
        &[Param::MuS, Param::MuK, Param::Kappa, Param::UTilde],
        &[],
    )
}

/// Points spread over the box (a fixed lattice, the same on every run).
fn points(p: &Problem) -> Vec<Vec<f64>> {
    let (lo, hi) = p.bounds();
    (0..12)
        .map(|j| {
            (0..p.dim())
                .map(|k| {
                    let u = ((j * (2 * k + 3) + k) % 11) as f64 / 10.0;
                    lo[k] + u * (hi[k] - lo[k])
                })
                .collect()
        })
        .collect()
}

/// The problem seen without its bounded evaluation: every trial runs whole.
struct Whole<'a>(&'a Problem<'a>);

impl Residuals for Whole<'_> {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn bounds(&self) -> (&[f64], &[f64]) {
        self.0.bounds()
    }
    fn residuals_at(&self, x: &[f64], out: &mut Vec<f64>) {
        self.0.residuals_at(x, out)
    }
}

fn ssr(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

#[test]
fn a_bounded_evaluation_is_the_whole_one_unless_its_sum_ends_above_the_ceiling() {
    let tests = tests();
    let p = Problem::new(&tests, space());
    for x in points(&p) {
        let mut whole = Vec::new();
        p.residuals_at(&x, &mut whole);
        let total = ssr(&whole);
        assert!(total > 0.0 && total.is_finite());
        // At or above the sum the evaluation runs whole, bit for bit.
        for ceiling in [total, 2.0 * total, f64::INFINITY] {
            let mut r = Vec::new();
            assert_eq!(
                p.residuals_unless_above(&x, &mut r, ceiling),
                Bounded::Computed
            );
            let same = r
                .iter()
                .zip(&whole)
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same && r.len() == whole.len(), "at {x:?} below {ceiling}");
        }
        // Below it, the evaluation says so (at the last row at the latest).
        for ceiling in [0.0, 0.5 * total, total * (1.0 - 1e-12)] {
            let mut r = Vec::new();
            assert_eq!(
                p.residuals_unless_above(&x, &mut r, ceiling),
                Bounded::Above,
                "at {x:?} the sum {total} is above {ceiling}"
            );
        }
        assert_eq!(p.sum_of_squares_unless_above(&x, 0.5 * total), None);
        assert_eq!(
            p.sum_of_squares_unless_above(&x, total).map(f64::to_bits),
            Some(total.to_bits())
        );
    }
}

#[test]
fn a_test_that_fails_further_on_is_not_stopped_on_the_rows_before_its_failure() {
    // Traction control with the imposed shear raised past the friction capacity (about 45 kPa
    // under 100 kPa): the run fails near its end, and every row of the test then weighs the
    // failed residual (1e3 noise units). The measured slip is far from anything the model
    // does, so the rows before the failure alone pass the ceiling: stopping there would call
    // the point worse than the failure's sum, which lies below the ceiling.
    let time: Vec<f64> = (0..=200).map(|i| i as f64).collect();
    let shear: Vec<f64> = time.iter().map(|t| 0.3 * t).collect();
    let normal = vec![100.0; time.len()];
    // The model's slip starts at the first measured value and stays within a millimetre.
    let measured: Vec<f64> = time.iter().map(|t| 5.0 * t).collect();
    let mut t = FitTest::new("runaway", Control::Shear, time, shear, measured, normal);
    t.noise_sd = 1e-3;
    let model = Model::base(Params::sample()).unwrap();
    assert!(t.predict(&model).is_err(), "the test must fail to simulate");
    let tests = [t];
    let space = Space::new(model, &[Param::MuS], &[]);
    let p = Problem::new(&tests, space);
    let x = p.space.point_of(&p.space.base);
    let mut whole = Vec::new();
    p.residuals_at(&x, &mut whole);
    let total = ssr(&whole);
    assert!(whole.iter().all(|v| *v == 1e3), "every row failed");
    let mut r = Vec::new();
    let rows_before_failure: f64 = {
        let mut slip = Vec::new();
        let _ = subfric_model::simulate_predicted_while(
            &p.model_at(&x),
            &tests[0].protocol(),
            &mut slip,
            |_, _| true,
        );
        (1..140)
            .map(|i| (1e3 * (slip[i] - tests[0].measured[i])).powi(2))
            .sum()
    };
    assert!(
        rows_before_failure > 2.0 * total,
        "the rows before the failure pass the ceiling"
    );
    assert_eq!(
        p.residuals_unless_above(&x, &mut r, 2.0 * total),
        Bounded::Computed
    );
    assert_eq!(ssr(&r).to_bits(), total.to_bits());
    assert_eq!(
        p.residuals_unless_above(&x, &mut r, 0.5 * total),
        Bounded::Above
    );
}

#[test]
fn least_squares_and_differential_evolution_end_where_they_end_with_every_trial_run_whole() {
    let tests = tests();
    let p = Problem::new(&tests, space());
    let whole = Whole(&p);
    let x0 = p.space.point_of(&p.space.base);
    let opts = LmOptions {
        max_iterations: 40,
        ..LmOptions::default()
    };
    let bounded = levenberg_marquardt(&p, &x0, None, &opts);
    let before = p.evaluations();
    let full = levenberg_marquardt(&whole, &x0, None, &opts);
    assert_eq!(
        p.evaluations() - before,
        before,
        "one run per evaluation either way"
    );
    assert_eq!(bounded.x, full.x);
    assert_eq!(bounded.ssr.to_bits(), full.ssr.to_bits());
    assert_eq!(
        (bounded.iterations, bounded.termination),
        (full.iterations, full.termination)
    );

    let de = DeOptions {
        population: 12,
        max_evaluations: 240,
        f: 0.7,
        cr: 0.9,
        tolerance: 1e-9,
    };
    let seeds = points(&p);
    let a = differential_evolution(&p, &seeds, &de, 7);
    let b = differential_evolution(&whole, &seeds, &de, 7);
    assert_eq!(a.members, b.members);
    let bits = |c: &[f64]| c.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a.costs), bits(&b.costs));
    assert_eq!(
        (a.generations, a.evaluations),
        (b.generations, b.evaluations)
    );
}

#[test]
fn a_refit_sharing_the_memo_reuses_the_local_runs_it_would_repeat_and_ends_the_same() {
    let tests = tests();
    let opts = FitOptions {
        starts: 2,
        global_evaluations: 0,
        profiles: false,
        statistics: false,
        informed_guesses: false,
        lm: LmOptions {
            max_iterations: 30,
            ..LmOptions::default()
        },
        ..FitOptions::default()
    };
    let start = [space().base];
    let alone = calibrate_from(&tests, space(), &start, &opts, &|_| {}).unwrap();
    let memo = FitOptions {
        local_memo: Some(LocalMemo::new()),
        ..opts.clone()
    };
    let first = calibrate_from(&tests, space(), &start, &memo, &|_| {}).unwrap();
    let again = calibrate_from(&tests, space(), &start, &memo, &|_| {}).unwrap();
    for r in [&first, &again] {
        assert_eq!(r.ssr.to_bits(), alone.ssr.to_bits());
        assert_eq!(r.model.params, alone.model.params);
        assert_eq!(r.optimizer.start_ssr, alone.optimizer.start_ssr);
    }
    assert_eq!(first.optimizer.evaluations, alone.optimizer.evaluations);
    assert!(
        again.optimizer.evaluations < first.optimizer.evaluations / 2,
        "the local runs were done again: {} runs against {}",
        again.optimizer.evaluations,
        first.optimizer.evaluations
    );
    // Another set of tests (another address) does not take the memo's runs.
    let other = tests.clone();
    let elsewhere = calibrate_from(&other, space(), &start, &memo, &|_| {}).unwrap();
    assert_eq!(elsewhere.optimizer.evaluations, alone.optimizer.evaluations);
}
