//! A fit hands its progress the counter of its own model runs as it starts, and every model
//! run of the job (the calibration's, and any stiffness trial or bedding fit before it) counts
//! there: the display reads the job's runs, not the process's.

use std::path::Path;
use std::sync::Mutex;
use subfric_app::fit::run_fit;
use subfric_app::{FitRequest, Progress};
use subfric_fit::{FitOptions, RunCounter};

/// Records the counters it is handed, and their runs as each stage begins.
#[derive(Default)]
struct Recorded {
    counters: Mutex<Vec<RunCounter>>,
    stages: Mutex<Vec<(String, usize)>>,
}

impl Recorded {
    fn runs(&self) -> usize {
        self.counters.lock().unwrap().iter().map(|c| c.runs()).sum()
    }
}

impl Progress for Recorded {
    fn stage(&self, stage: &str, _budget: Option<usize>) {
        let runs = self.runs();
        self.stages.lock().unwrap().push((stage.to_string(), runs));
    }
    fn warning(&self, _text: &str) {}
    fn note(&self, _text: &str) {}
    fn watch_runs(&self, runs: &RunCounter) {
        self.counters.lock().unwrap().push(runs.clone());
    }
}

fn medium() -> FitRequest {
    let set = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../experiments/table1-medium");
    FitRequest::of_set(
        set,
        FitOptions {
            global_evaluations: 300,
            starts: 2,
            profiles: false,
            ..FitOptions::default()
        },
    )
}

#[test]
fn a_fit_hands_its_progress_the_counter_of_its_own_runs() {
    let (shown, beside) = (Recorded::default(), Recorded::default());
    // Two fits at once in one process, each with its own display.
    let (outcome, _) = std::thread::scope(|s| {
        let other = s.spawn(|| run_fit(&medium(), &beside).unwrap());
        (run_fit(&medium(), &shown).unwrap(), other.join().unwrap())
    });
    let counters = shown.counters.lock().unwrap();
    assert_eq!(counters.len(), 1, "one job, one counter");
    let own = outcome.report.optimizer.evaluations;
    // The calibration's runs, and those of any trial before it, and none of the other fit's.
    assert!(
        counters[0].runs() >= own && own > 0,
        "{} {own}",
        counters[0].runs()
    );
    assert_eq!(
        counters[0].runs(),
        beside.runs(),
        "the same fit twice: the same runs"
    );
    let stages = shown.stages.lock().unwrap();
    let polished = stages
        .iter()
        .rfind(|(s, _)| s.starts_with("least-squares polish"))
        .expect("a polish stage");
    let global = stages
        .iter()
        .find(|(s, _)| s.starts_with("global search"))
        .expect("a global stage");
    assert!(
        polished.1 > global.1,
        "runs rise over the stages: {stages:?}"
    );
}

#[test]
fn a_counter_the_request_carries_is_the_one_counted_and_shown() {
    let job = RunCounter::new();
    let mut req = medium();
    req.options.run_counter = Some(job.clone());
    let shown = Recorded::default();
    let outcome = run_fit(&req, &shown).unwrap();
    let counters = shown.counters.lock().unwrap();
    assert!(counters.len() == 1 && counters[0].same_count(&job));
    assert!(job.runs() >= outcome.report.optimizer.evaluations);
}
