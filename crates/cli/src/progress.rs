//! Progress on stderr for the long jobs (fit, diagnose, plan, reproduce): the stage, the model
//! runs done (sampled from the counters the job handed over, [`subfric_app::Progress::watch_runs`])
//! and the elapsed time. A live bar
//! (indicatif) on a terminal; nothing when stderr is not a terminal, unless asked for with
//! `--progress always`, which then prints one plain line per stage. Warnings and notes of the
//! job are printed on stderr in every mode, without garbling the bar. This is the command
//! line's implementation of [`subfric_app::Progress`]. A stderr that cannot be written (closed,
//! `2> /dev/full`) is ignored: progress never stops the job.
//!
//! A job made of many like units (a campaign's sets, a Slurm array's tasks) shows a bar of the
//! units done instead ([`Progress::counted`]), with the time left estimated from the units that
//! took time (skipped ones do not count, [`Progress::skipped`]).

use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use subfric_fit::RunCounter;

/// When to show progress.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum ProgressMode {
    /// A live bar when stderr is a terminal, nothing otherwise
    #[default]
    Auto,
    /// Always: a live bar on a terminal, one line per stage otherwise (logs)
    Always,
    /// Never
    Never,
}

struct State {
    stage: String,
    /// Model runs expected in this stage, when known.
    budget: Option<usize>,
    /// Model runs when the stage began.
    runs_at_stage: usize,
    /// Work the stage counts itself (`Progress::count`): done and total.
    counted: Option<(usize, usize)>,
    /// Tenths of the total reported so far as lines (`--progress always` off a terminal).
    tenths_shown: usize,
    /// What `Progress::count` counts.
    unit: &'static str,
    /// Counted units that took no time (skipped), left out of the time-left estimate.
    skipped: usize,
    /// Whether the display estimates the time left from the counted units.
    eta: bool,
    /// When a counted job last printed a line (`--progress always` off a terminal).
    last_line: Option<Instant>,
}

impl Default for State {
    fn default() -> Self {
        State {
            stage: String::new(),
            budget: None,
            runs_at_stage: 0,
            counted: None,
            tenths_shown: 0,
            unit: "model runs",
            skipped: 0,
            eta: false,
            last_line: None,
        }
    }
}

/// A duration to read: `42 s`, `3 min 05 s`, `2 h 07 min`.
pub fn duration_text(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {:02} s", s / 60, s % 60),
        _ => format!("{} h {:02} min", s / 3600, (s % 3600) / 60),
    }
}

/// The time left when `done` of `total` units are done, `skipped` of them without taking time,
/// after `elapsed` seconds: the rest at the pace of those that took time.
pub fn time_left(done: usize, total: usize, skipped: usize, elapsed: f64) -> Option<f64> {
    let worked = done.checked_sub(skipped).filter(|&w| w > 0)?;
    Some(total.saturating_sub(done) as f64 * elapsed / worked as f64)
}

struct Shared {
    t0: Instant,
    /// The counters of the jobs shown (one per fit or diagnosis; a campaign's sets each hand
    /// theirs): the runs shown are theirs, not those of other jobs of the process.
    job_runs: Mutex<Vec<RunCounter>>,
    state: Mutex<State>,
    stop: AtomicBool,
}

impl Shared {
    /// Model runs of the jobs shown so far.
    fn runs(&self) -> usize {
        self.job_runs
            .lock()
            .map_or(0, |jobs| jobs.iter().map(RunCounter::runs).sum())
    }

    fn line(&self) -> String {
        let runs = self.runs();
        let elapsed = self.t0.elapsed().as_secs_f64();
        if let Ok(s) = self.state.lock() {
            if s.eta {
                let (done, total) = s.counted.unwrap_or((0, 0));
                let left = match time_left(done, total, s.skipped, elapsed) {
                    _ if total > 0 && done >= total => String::new(),
                    Some(t) => format!(" · about {} left", duration_text(t)),
                    None => " · time left: not known yet".into(),
                };
                return format!("{} · {}{left}", s.stage, duration_text(elapsed));
            }
        }
        let s = self.state.lock().map(|s| {
            let in_stage = self.runs().saturating_sub(s.runs_at_stage);
            match (s.counted, s.budget) {
                (Some((done, total)), _) => format!(
                    "{} ({done}/{total} {}, {:.0} %)",
                    s.stage,
                    s.unit,
                    100.0 * done as f64 / total.max(1) as f64
                ),
                (None, Some(b)) => format!("{} ({in_stage}/{b} model runs)", s.stage),
                (None, None) => s.stage.clone(),
            }
        });
        format!(
            "{} · {runs} model runs · {elapsed:.1} s",
            s.unwrap_or_default()
        )
    }
}

/// A progress display; inactive ones cost nothing.
pub struct Progress {
    shared: Arc<Shared>,
    bar: Option<ProgressBar>,
    lines: bool,
    ticker: Option<JoinHandle<()>>,
}

impl Progress {
    /// A display in `mode`.
    pub fn new(mode: ProgressMode) -> Progress {
        Progress::start(mode, None)
    }

    /// A display in `mode` of a job made of like units (`unit`: "sets", "tasks"): a bar of the
    /// units done, the time elapsed and the time left (on a terminal), or a line at every
    /// tenth of them (`--progress always` off a terminal).
    pub fn counted(mode: ProgressMode, unit: &'static str) -> Progress {
        Progress::start(mode, Some(unit))
    }

    fn start(mode: ProgressMode, unit: Option<&'static str>) -> Progress {
        let terminal = std::io::stderr().is_terminal();
        let (bar, lines) = match (mode, terminal) {
            (ProgressMode::Never, _) | (ProgressMode::Auto, false) => (false, false),
            (_, true) => (true, false),
            (ProgressMode::Always, false) => (false, true),
        };
        let mut state = State::default();
        if let Some(unit) = unit {
            state.unit = unit;
            state.eta = true;
        }
        let shared = Arc::new(Shared {
            t0: Instant::now(),
            job_runs: Mutex::new(Vec::new()),
            state: Mutex::new(state),
            stop: AtomicBool::new(false),
        });
        // A counted job's bar appears with its first count (`Progress::count`).
        let bar = bar.then(|| {
            let b = ProgressBar::new_spinner();
            if let Ok(style) = ProgressStyle::with_template("{spinner} {msg}") {
                b.set_style(style);
            }
            b.enable_steady_tick(Duration::from_millis(120));
            b
        });
        let ticker = bar.clone().map(|b| {
            let sh = Arc::clone(&shared);
            std::thread::spawn(move || {
                while !sh.stop.load(Ordering::Relaxed) {
                    b.set_message(sh.line());
                    std::thread::sleep(Duration::from_millis(200));
                }
            })
        });
        Progress {
            shared,
            bar,
            lines,
            ticker,
        }
    }

    /// A counted unit took no time (a set skipped): the time left is estimated without it.
    pub fn skipped(&self) {
        if let Ok(mut s) = self.shared.state.lock() {
            s.skipped += 1;
        }
    }

    /// Starts a stage, with the model runs it is expected to take when known.
    fn show_stage(&self, stage: &str, budget: Option<usize>) {
        if self.bar.is_none() && !self.lines {
            return;
        }
        let stage = stage.to_string();
        let mut line_due = self.lines;
        if let Ok(mut s) = self.shared.state.lock() {
            if s.stage == stage {
                return;
            }
            // A counted job's log gets a line at most every 5 s (a resumed campaign skips
            // hundreds of sets at once), and its last one.
            if self.lines && s.eta {
                let last = s.counted.is_some_and(|(d, t)| d >= t);
                line_due = last
                    || s.last_line
                        .is_none_or(|t| t.elapsed() >= Duration::from_secs(5));
                if line_due {
                    s.last_line = Some(Instant::now());
                }
            }
            s.stage = stage;
            s.budget = budget;
            s.runs_at_stage = self.shared.runs();
            // A counted job's units run across its stages (each stage line says how many).
            if !s.eta {
                s.counted = None;
                s.tenths_shown = 0;
            }
        }
        if line_due {
            crate::print::err(format!("progress: {}", self.shared.line()));
        }
        if let Some(b) = &self.bar {
            b.set_message(self.shared.line());
        }
    }

    /// Prints a line on stderr without garbling the live display (a stderr that cannot be
    /// written is ignored: the job goes on).
    pub fn println(&self, line: &str) {
        match &self.bar {
            Some(b) => b.suspend(|| crate::print::err(line)),
            None => crate::print::err(line),
        }
    }

    /// Clears the display.
    pub fn finish(mut self) {
        self.stop();
    }

    fn stop(&mut self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.ticker.take() {
            let _ = t.join();
        }
        if let Some(b) = self.bar.take() {
            b.finish_and_clear();
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.stop();
    }
}

impl subfric_app::Progress for Progress {
    fn stage(&self, stage: &str, budget: Option<usize>) {
        self.show_stage(stage, budget);
    }

    fn watch_runs(&self, runs: &RunCounter) {
        if let Ok(mut jobs) = self.shared.job_runs.lock() {
            // A counter handed over again (by a job and by the fits it shares it with) counts
            // once.
            if !jobs.iter().any(|j| j.same_count(runs)) {
                jobs.push(runs.clone());
            }
        }
    }

    /// The live display picks the count up at its next tick; a log gets a line at every
    /// tenth of the total (a counted job's, at each of its stages instead).
    fn count(&self, done: usize, total: usize) {
        if self.bar.is_none() && !self.lines {
            return;
        }
        let mut line_due = false;
        if let Ok(mut s) = self.shared.state.lock() {
            // Units end on several threads: a count that arrives late is not a step back.
            if s.eta && s.counted.is_some_and(|(d, t)| t == total && d > done) {
                return;
            }
            if let (Some(b), true) = (&self.bar, s.eta) {
                if s.counted.is_none() {
                    let template = format!(
                        "{{spinner}} [{{bar:30}}] {{pos}}/{{len}} {} · {{msg}}",
                        s.unit
                    );
                    if let Ok(style) = ProgressStyle::with_template(&template) {
                        b.set_style(style.progress_chars("=> "));
                    }
                }
                b.set_length(total as u64);
                b.set_position(done as u64);
            }
            s.counted = Some((done, total));
            let tenths = (10 * done / total.max(1)).min(10);
            if tenths > s.tenths_shown && !s.eta {
                s.tenths_shown = tenths;
                line_due = self.lines;
            }
        }
        if line_due {
            crate::print::err(format!("progress: {}", self.shared.line()));
        }
    }

    fn warning(&self, text: &str) {
        self.println(&format!("warning: {text}"));
    }

    fn note(&self, text: &str) {
        self.println(&format!("note: {text}"));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfric_app::Progress as _;
    use subfric_fit::{Param, Problem, Space};
    use subfric_model::{Control, Model, Params};
    use subfric_reading::FitTest;

    /// `runs` model runs of a small problem, counted into `job`.
    fn run_model(job: &RunCounter, runs: usize) {
        let time: Vec<f64> = (0..20).map(f64::from).collect();
        let slip: Vec<f64> = time.iter().map(|t| 0.01 * t).collect();
        let tests = [FitTest::new(
            "t",
            Control::Slip,
            time,
            slip,
            vec![10.0; 20],
            vec![100.0; 20],
        )];
        let space = Space::new(Model::base(Params::sample()).unwrap(), &[Param::MuS], &[]);
        let p = Problem::new(&tests, space).counting(Some(job));
        let x = p.space.point_of(&p.space.base);
        for _ in 0..runs {
            p.ssr(&x);
        }
    }

    #[test]
    fn a_display_shows_the_runs_of_the_jobs_handed_to_it_and_of_no_other() {
        let (shown, other) = (
            Progress::new(ProgressMode::Never),
            Progress::new(ProgressMode::Never),
        );
        let (fit, diagnosis, elsewhere) = (RunCounter::new(), RunCounter::new(), RunCounter::new());
        shown.watch_runs(&fit);
        shown.watch_runs(&diagnosis);
        // Handed over again by a job that shares it: counted once.
        shown.watch_runs(&fit.clone());
        other.watch_runs(&elsewhere);
        run_model(&fit, 3);
        run_model(&diagnosis, 2);
        run_model(&elsewhere, 7);
        assert_eq!(shown.shared.runs(), 5);
        assert_eq!(other.shared.runs(), 7);
        assert!(
            shown.shared.line().contains(" 5 model runs"),
            "{}",
            shown.shared.line()
        );
        // Runs made after the hand-over are shown as they are made.
        run_model(&diagnosis, 1);
        assert_eq!(shown.shared.runs(), 6);
    }
}
