//! What a long job tells its caller while it runs: the stage it is in, and the warnings and
//! notes a user should see now rather than after the work. The caller decides how to show
//! them: the command line draws a live bar on a terminal and prints warnings on stderr; the
//! Python package shows nothing ([`Silent`]) and returns the warnings with the result.

use subfric_fit::{CalibrationStage, RunCounter};

/// The caller's side of a long job. Called from the job's worker threads too (hence `Sync`);
/// every method should return quickly.
pub trait Progress: Sync {
    /// A stage begins; `budget`: the model runs it is expected to take, when known.
    fn stage(&self, stage: &str, budget: Option<usize>);

    /// A warning about the input or a result (implausible data, a curve that cannot be
    /// drawn), without the `warning:` prefix. Results that carry their warnings return them
    /// too.
    fn warning(&self, text: &str);

    /// A note on how the request is carried out (e.g. the coordinates the optimiser works
    /// in, a file replaced), without the `note:` prefix.
    fn note(&self, text: &str);

    /// Work done within the current stage: `done` of about `total` units, in the units of the
    /// stage's budget (model runs of the posterior sampler). Called often, from worker threads;
    /// the default shows nothing.
    fn count(&self, _done: usize, _total: usize) {}

    /// A job reporting here counts its model runs in `runs` (a fit, a diagnosis, a plan hands
    /// its counter over as it starts): a display that shows model runs reads them from the
    /// counters it was handed, never from other jobs of the process. The default shows none.
    fn watch_runs(&self, _runs: &RunCounter) {}

    /// A stage of a calibration, as [`Progress::stage`] shows it (`global_budget`: the model
    /// runs of the global stage).
    fn calibration_stage(&self, s: CalibrationStage, global_budget: usize) {
        match s {
            CalibrationStage::Global => self.stage(
                "global search (differential evolution)",
                Some(global_budget),
            ),
            CalibrationStage::Local(k, n) => {
                self.stage(&format!("least-squares polish {k}/{n}"), None)
            }
            CalibrationStage::Profiles => self.stage("profile intervals", None),
            CalibrationStage::Done => self.stage("done", None),
        }
    }
}

/// Shows nothing (the warnings are in the results).
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Progress for Silent {
    fn stage(&self, _stage: &str, _budget: Option<usize>) {}
    fn warning(&self, _text: &str) {}
    fn note(&self, _text: &str) {}
}
