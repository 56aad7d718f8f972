//! One set of a campaign: skipped when its results folder's record matches its inputs and
//! options of today, else fitted (and diagnosed) into `sets/<id>/` as `subfric fit` and
//! `subfric diagnose` write, the record last. And the sets of a campaign run in parallel.

use super::record::{part_key, read_inputs, PartRecord, PartStatus, SetRecord, RECORD_FILE};
use super::{SetJob, SETS_DIR};
use crate::diagnose::diagnose_to_folder;
use crate::error_text;
use crate::fit::fit;
use crate::folders::io::{write_json, write_text};
use crate::folders::output::{Destination, ResultsDir};
use crate::progress::Progress;
use crate::render::fit_report::report_table;
use anyhow::{anyhow, Result};
use serde::Serialize;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// What became of one set.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "outcome", rename_all = "kebab-case")]
pub enum SetOutcome {
    /// Its inputs and options are those its results were written with: nothing run.
    Skipped,
    /// Run: the fit (unless still current), and the diagnosis when asked for and not current.
    Ran {
        /// The fit ran (false: it was current, only the diagnosis ran).
        fitted: bool,
        /// The diagnosis ran.
        diagnosed: bool,
    },
    /// Failed, with the error (file, line, field as the fit or diagnosis names them).
    Failed {
        /// The error text.
        error: String,
    },
}

/// One set's run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SetRun {
    /// Its index in the campaign's plan.
    pub index: usize,
    /// Its results folder name.
    pub id: String,
    /// What became of it.
    #[serde(flatten)]
    pub outcome: SetOutcome,
    /// Wall time, seconds.
    pub seconds: f64,
}

impl SetRun {
    /// Whether it failed.
    pub fn failed(&self) -> bool {
        matches!(self.outcome, SetOutcome::Failed { .. })
    }
}

/// The files of a set's results folder.
fn set_files() -> Vec<String> {
    ["fit.json", "fit.txt", RECORD_FILE, "diagnosis"]
        .map(String::from)
        .to_vec()
}

/// The results folder of a set.
pub fn set_dir(out: &Path, id: &str) -> PathBuf {
    out.join(SETS_DIR).join(id)
}

/// Notes already shown in a campaign: a note that holds for many sets (the stiffness held at
/// a typical value) is shown once, not once per set.
type SeenNotes = Mutex<BTreeSet<String>>;

/// Shows the warnings and notes of a set's work, naming the set; its stages are the
/// campaign's business.
struct SetProgress<'a> {
    id: &'a str,
    inner: &'a dyn Progress,
    seen: Option<&'a SeenNotes>,
}

impl Progress for SetProgress<'_> {
    fn stage(&self, _stage: &str, _budget: Option<usize>) {}
    fn watch_runs(&self, runs: &subfric_fit::RunCounter) {
        self.inner.watch_runs(runs);
    }
    fn warning(&self, text: &str) {
        self.inner.warning(&format!("{}: {text}", self.id));
    }
    fn note(&self, text: &str) {
        let first = match self.seen.map(Mutex::lock) {
            Some(Ok(mut seen)) => seen.insert(text.to_string()),
            _ => true,
        };
        match (first, self.seen.is_some()) {
            (false, _) => {}
            (true, true) => self.inner.note(&format!(
                "{}: {text} (said once: other sets of the campaign it holds for are not named)",
                self.id
            )),
            (true, false) => self.inner.note(&format!("{}: {text}", self.id)),
        }
    }
}

/// Runs set `index` of a campaign into `out/sets/<id>` (see the module documentation); a
/// failure is returned as the outcome, never raised, and a bug (a panic) is one too.
pub fn run_set(
    out: &Path,
    index: usize,
    job: &SetJob,
    force: bool,
    progress: &dyn Progress,
) -> SetRun {
    run_set_noting(out, index, job, force, progress, None)
}

/// [`run_set`], each note shown once in the campaign (`seen`).
fn run_set_noting(
    out: &Path,
    index: usize,
    job: &SetJob,
    force: bool,
    progress: &dyn Progress,
    seen: Option<&SeenNotes>,
) -> SetRun {
    let t0 = Instant::now();
    let p = SetProgress {
        id: &job.id,
        inner: progress,
        seen,
    };
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        run_set_inner(out, job, force, &p)
    }));
    let outcome = match result {
        Ok(Ok(o)) => o,
        Ok(Err(e)) => SetOutcome::Failed {
            error: error_text(&e),
        },
        Err(panic) => SetOutcome::Failed {
            error: format!(
                "{}: internal error: {} (a bug of subfric: please report it with this set)",
                job.dir.display(),
                panic
                    .downcast_ref::<String>()
                    .map(String::as_str)
                    .or_else(|| panic.downcast_ref::<&str>().copied())
                    .unwrap_or("a panic")
            ),
        },
    };
    SetRun {
        index,
        id: job.id.clone(),
        outcome,
        seconds: t0.elapsed().as_secs_f64(),
    }
}

/// Whether `record` is a successful part with `key` whose result file `result` is there.
fn current(record: Option<&PartRecord>, key: &str, result: &Path) -> bool {
    record.is_some_and(|r| r.status == PartStatus::Done && r.key == key && result.is_file())
}

fn part(key: String, options: serde_json::Value, result: &Result<()>) -> PartRecord {
    PartRecord {
        key,
        options,
        status: if result.is_ok() {
            PartStatus::Done
        } else {
            PartStatus::Failed
        },
        error: result.as_ref().err().map(error_text),
    }
}

fn run_set_inner(
    out: &Path,
    job: &SetJob,
    force: bool,
    progress: &dyn Progress,
) -> Result<SetOutcome> {
    let (_, inputs) = read_inputs(&job.dir)?;
    let dir = set_dir(out, &job.id);
    let old = SetRecord::read(&dir);
    let fit_options = job.options.fit_part();
    let fit_key = part_key("fit", &inputs, &fit_options);
    let fit_current = current(
        old.as_ref().and_then(|r| r.fit.as_ref()),
        &fit_key,
        &dir.join("fit.json"),
    );
    let diagnosis_options = job.options.diagnosis_part();
    let diagnosis_key = part_key("diagnosis", &inputs, &diagnosis_options);
    let diagnosis_current = !job.options.diagnose
        || current(
            old.as_ref().and_then(|r| r.diagnosis.as_ref()),
            &diagnosis_key,
            &dir.join("diagnosis").join("diagnosis.json"),
        );
    if fit_current && diagnosis_current {
        return Ok(SetOutcome::Skipped);
    }
    let claim = ResultsDir::claim(&dir, std::slice::from_ref(&job.dir), &set_files(), force)?;
    let mut record = SetRecord {
        set: job.id.clone(),
        subfric: env!("CARGO_PKG_VERSION").to_string(),
        inputs,
        fit: old.as_ref().and_then(|r| r.fit.clone()),
        diagnosis: old.and_then(|r| r.diagnosis),
    };
    let mut failure = None;
    if !fit_current {
        let r = fit_set(job, &dir, progress);
        record.fit = Some(part(fit_key, fit_options, &r));
        failure = r.err();
    }
    let diagnose = failure.is_none() && !diagnosis_current;
    if diagnose {
        let to = Destination {
            dir: Some(dir.join("diagnosis")),
            force,
        };
        let r = diagnose_to_folder(&job.dir, &job.options.diagnose_options(), 1, &to, progress)
            .map(|_| ());
        record.diagnosis = Some(part(diagnosis_key, diagnosis_options, &r));
        failure = r.err();
    }
    record.write(&dir)?;
    claim.commit()?;
    match failure {
        Some(e) => Err(e),
        None => Ok(SetOutcome::Ran {
            fitted: !fit_current,
            diagnosed: diagnose,
        }),
    }
}

/// The fit of a set: `fit.json` as `subfric fit` writes it, and `fit.txt`, its table.
fn fit_set(job: &SetJob, dir: &Path, progress: &dyn Progress) -> Result<()> {
    let req = job.options.fit_request(&job.dir)?;
    let fitted = fit(&req, progress)?;
    write_json(&dir.join("fit.json"), &fitted.json)?;
    let table = report_table(&fitted.outcome);
    write_text(&dir.join("fit.txt"), &format!("{table}\n"))
}

/// Runs `jobs` (each with its index in the plan), at most `parallel` sets at a time, reporting
/// each as it ends; the runs in the order of `jobs`.
///
/// Every set's work, its parallel parts (the global search, the multi-start, the profiles, the
/// diagnosis's candidates) and its serial parts (reading, segmenting, writing) alike, runs in
/// one pool of a thread per core; `parallel` threads each hand it one set at a time. So the
/// machine is never oversubscribed, the serial part of one set overlaps the parallel part of
/// another, and no more than `parallel` sets are held in memory (or lost when the campaign is
/// stopped).
pub fn run_sets(
    out: &Path,
    jobs: &[(usize, &SetJob)],
    parallel: usize,
    force: bool,
    on_set: &(dyn Fn(&SetRun) + Sync),
    progress: &dyn Progress,
) -> Result<Vec<SetRun>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .thread_name(|i| format!("subfric-campaign-{i}"))
        .build()
        .map_err(|e| anyhow!("cannot start the campaign's threads: {e}"))?;
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let seen = SeenNotes::default();
    let runs: Mutex<Vec<Option<SetRun>>> = Mutex::new(vec![None; jobs.len()]);
    let total = jobs.len();
    progress.count(0, total);
    progress.stage(&format!("campaign: 0 of {total} sets done"), None);
    let interrupt = interrupt::Watch::install();
    let workers = parallel.clamp(1, total.max(1));
    let running = AtomicUsize::new(workers);
    std::thread::scope(|scope| {
        // Says at once that a Ctrl-C was heard: the sets in progress may take a minute.
        scope.spawn(|| {
            while running.load(Ordering::Relaxed) > 0 {
                if interrupt.heard() {
                    let busy = running.load(Ordering::Relaxed);
                    progress.warning(&format!(
                        "interrupted: finishing the {busy} set(s) in progress, starting no other \
                         (Ctrl-C again stops at once; a set stopped midway reruns when the \
                         campaign is resumed)"
                    ));
                    break;
                }
                std::thread::sleep(std::time::Duration::from_millis(50));
            }
        });
        for _ in 0..workers {
            scope.spawn(|| loop {
                if interrupt.heard() {
                    running.fetch_sub(1, Ordering::Relaxed);
                    break;
                }
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(&(index, job)) = jobs.get(k) else {
                    running.fetch_sub(1, Ordering::Relaxed);
                    break;
                };
                let run =
                    pool.install(|| run_set_noting(out, index, job, force, progress, Some(&seen)));
                on_set(&run);
                let n = done.fetch_add(1, Ordering::Relaxed) + 1;
                progress.count(n, total);
                progress.stage(&format!("campaign: {n} of {total} sets done"), None);
                if let Ok(mut r) = runs.lock() {
                    r[k] = Some(run);
                }
            });
        }
    });
    let runs = runs
        .into_inner()
        .map_err(|_| anyhow!("a campaign thread stopped"))?;
    if interrupt.heard() {
        return Err(Interrupted {
            done: done.load(Ordering::Relaxed),
            total,
            out: out.to_path_buf(),
        }
        .into());
    }
    runs.into_iter()
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| anyhow!("a set of the campaign was not run (a thread stopped)"))
}

/// A campaign stopped by Ctrl-C once the sets in progress had finished (exit code 130, as a
/// program killed by SIGINT).
#[derive(Debug)]
pub struct Interrupted {
    /// Sets this run finished or found done (skipped) before the interrupt.
    pub done: usize,
    /// Sets of the campaign.
    pub total: usize,
    /// The campaign folder.
    pub out: PathBuf,
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "interrupted (Ctrl-C) with {} of {} sets done: their results are kept in {}; run \
             the same command again to resume (the sets done are skipped)",
            self.done,
            self.total,
            self.out.display()
        )
    }
}

impl std::error::Error for Interrupted {}

/// Ctrl-C (SIGINT) during a campaign: the first stops the campaign from starting another set and
/// lets those in progress finish (each set's record is written last, so a resumed campaign
/// skips exactly the sets that finished); the second stops the program at once, as without a
/// handler.
mod interrupt {
    use std::sync::atomic::{AtomicBool, Ordering};

    /// Set by the handler; read by the campaign's threads.
    static HEARD: AtomicBool = AtomicBool::new(false);

    extern "C" fn on_sigint(_: libc::c_int) {
        HEARD.store(true, Ordering::SeqCst);
        // `signal` is async-signal-safe: the next Ctrl-C gets the default action.
        // SAFETY: restoring the default disposition of SIGINT from its handler.
        unsafe {
            libc::signal(libc::SIGINT, libc::SIG_DFL);
        }
    }

    /// The handler, installed while a campaign runs its sets; the disposition it replaced
    /// comes back when it is dropped (in the Python package, Python's own handler, which turns
    /// Ctrl-C into `KeyboardInterrupt`).
    pub(super) struct Watch {
        previous: libc::sighandler_t,
    }

    impl Watch {
        pub(super) fn install() -> Watch {
            HEARD.store(false, Ordering::SeqCst);
            let handler = on_sigint as extern "C" fn(libc::c_int);
            // SAFETY: the handler only stores to an atomic and calls `signal`.
            let previous = unsafe { libc::signal(libc::SIGINT, handler as libc::sighandler_t) };
            Watch { previous }
        }

        /// Whether a Ctrl-C came since [`Watch::install`].
        pub(super) fn heard(&self) -> bool {
            HEARD.load(Ordering::SeqCst)
        }
    }

    impl Drop for Watch {
        fn drop(&mut self) {
            // `signal` answers SIG_ERR when it could not install the handler: then nothing was
            // replaced, and the default is what there was.
            let previous = if self.previous == libc::SIG_ERR {
                libc::SIG_DFL
            } else {
                self.previous
            };
            // SAFETY: restoring the disposition `install` replaced.
            unsafe {
                libc::signal(libc::SIGINT, previous);
            }
        }
    }

    #[cfg(test)]
    mod tests {
        use super::*;

        #[test]
        fn a_ctrl_c_is_heard_and_the_handler_it_replaced_comes_back_after_the_campaign() {
            // SAFETY: dispositions of SIGINT in a test process; the raised signal goes to the
            // handler installed just before.
            unsafe {
                // Stands for Python's handler, or a shell's choice.
                let before = libc::signal(libc::SIGINT, libc::SIG_IGN);
                {
                    let watch = Watch::install();
                    assert!(!watch.heard());
                    assert_eq!(libc::raise(libc::SIGINT), 0);
                    assert!(watch.heard(), "the Ctrl-C was not heard");
                    // The second Ctrl-C would stop the program: the default is in place.
                    let now = libc::signal(libc::SIGINT, libc::SIG_DFL);
                    assert_eq!(now, libc::SIG_DFL);
                }
                let after = libc::signal(libc::SIGINT, before);
                assert_eq!(
                    after,
                    libc::SIG_IGN,
                    "the replaced handler did not come back"
                );
            }
        }
    }
}
