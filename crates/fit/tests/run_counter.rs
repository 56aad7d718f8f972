//! Model runs are counted per job: a calibration counts into the `RunCounter` its options carry
//! and into no other, so two calibrations in one process (tests on parallel threads, a
//! campaign's sets) never see each other's runs.

use subfric_fit::{calibrate, FitOptions, Param, Problem, RunCounter, Space};
use subfric_model::{simulate, Control, Model, Params, Protocol};
use subfric_reading::FitTest;

/// A monotonic slip-controlled test of the sample parameters at `rate` mm/s.
fn monotonic(rate: f64) -> FitTest {
    let truth = Model::base(Params::sample()).unwrap();
    let time: Vec<f64> = (0..=300).map(|i| i as f64).collect();
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
    let shear = simulate(&truth, &proto).unwrap().shear;
    FitTest::new("mono", Control::Slip, time, slip, shear, normal)
}

/// μ_s and ũ free, started away from the truth.
fn space() -> Space {
    let mut start = Model::base(Params::sample()).unwrap();
    start.params.mu_s = 0.7;
    start.params.u_tilde = 50.0;
    Space::new(start, &[Param::MuS, Param::UTilde], &[])
}

#[test]
fn a_problem_counts_its_runs_into_the_job_counter_it_is_given_and_nowhere_else() {
    let tests = [monotonic(0.01)];
    let job = RunCounter::new();
    let counted = Problem::new(&tests, space()).counting(Some(&job));
    let alone = Problem::new(&tests, space());
    let x = counted.space.point_of(&counted.space.base);
    for _ in 0..3 {
        counted.ssr(&x);
    }
    alone.ssr(&x);
    assert_eq!((counted.evaluations(), alone.evaluations()), (3, 1));
    assert_eq!(
        job.runs(),
        3,
        "the problem without a counter adds nothing to it"
    );
    // Clones are handles of one count; a new counter is another count.
    let handle = job.clone();
    let also = Problem::new(&tests, space()).counting(Some(&handle));
    also.ssr(&x);
    assert_eq!(job.runs(), 4);
    assert!(job.same_count(&handle) && !job.same_count(&RunCounter::new()));
}

#[test]
fn two_calibrations_on_two_threads_each_count_exactly_their_own_runs() {
    let (a, b) = (RunCounter::new(), RunCounter::new());
    let options = |seed: u64, starts: usize, run_counter: &RunCounter| FitOptions {
        seed,
        starts,
        global_evaluations: 200,
        profiles: true,
        run_counter: Some(run_counter.clone()),
        ..FitOptions::default()
    };
    let (opts_a, opts_b) = (options(1, 2, &a), options(7, 3, &b));
    let (tests_a, tests_b) = ([monotonic(0.01)], [monotonic(0.02)]);
    let (report_a, report_b) = std::thread::scope(|s| {
        let ta = s.spawn(|| calibrate(&tests_a, space(), &opts_a, &|_| {}).unwrap());
        let tb = s.spawn(|| calibrate(&tests_b, space(), &opts_b, &|_| {}).unwrap());
        (ta.join().unwrap(), tb.join().unwrap())
    });
    let (own_a, own_b) = (
        report_a.optimizer.evaluations,
        report_b.optimizer.evaluations,
    );
    assert!(own_a > 0 && own_b > 0, "{own_a} {own_b}");
    // Exactly the runs of each calibration's problems: a process-wide count would give each
    // the sum.
    assert_eq!(a.runs(), own_a);
    assert_eq!(b.runs(), own_b);
}

#[test]
fn a_calibration_without_a_counter_still_reports_its_runs() {
    let tests = [monotonic(0.01)];
    let opts = FitOptions {
        global_evaluations: 100,
        starts: 1,
        profiles: false,
        ..FitOptions::default()
    };
    let r = calibrate(&tests, space(), &opts, &|_| {}).unwrap();
    assert!(r.optimizer.evaluations > opts.global_evaluations);
}
