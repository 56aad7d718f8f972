//! Progress on stderr for the long jobs (fit, diagnose, plan, reproduce): the stage, the model
//! runs done (sampled from [`subfric_fit::model_runs`]) and the elapsed time. A live bar
//! (indicatif) on a terminal; nothing when stderr is not a terminal, unless asked for with
//! `--progress always`, which then prints one plain line per stage. Warnings and notes of the
//! job are printed on stderr in every mode, without garbling the bar. This is the command
//! line's implementation of [`subfric_app::Progress`]. A stderr that cannot be written (closed,
//! `2> /dev/full`) is ignored: progress never stops the job.

use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use subfric_fit::model_runs;

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

#[derive(Default)]
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
}

struct Shared {
    t0: Instant,
    runs0: usize,
    state: Mutex<State>,
    stop: AtomicBool,
}

impl Shared {
    fn line(&self) -> String {
        let runs = model_runs().saturating_sub(self.runs0);
        let s = self.state.lock().map(|s| {
            let in_stage = model_runs().saturating_sub(s.runs_at_stage);
            match (s.counted, s.budget) {
                (Some((done, total)), _) => format!(
                    "{} ({done}/{total} model runs, {:.0} %)",
                    s.stage,
                    100.0 * done as f64 / total.max(1) as f64
                ),
                (None, Some(b)) => format!("{} ({in_stage}/{b} model runs)", s.stage),
                (None, None) => s.stage.clone(),
            }
        });
        format!(
            "{} · {runs} model runs · {:.1} s",
            s.unwrap_or_default(),
            self.t0.elapsed().as_secs_f64()
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
        let terminal = std::io::stderr().is_terminal();
        let (bar, lines) = match (mode, terminal) {
            (ProgressMode::Never, _) | (ProgressMode::Auto, false) => (false, false),
            (_, true) => (true, false),
            (ProgressMode::Always, false) => (false, true),
        };
        let shared = Arc::new(Shared {
            t0: Instant::now(),
            runs0: model_runs(),
            state: Mutex::new(State::default()),
            stop: AtomicBool::new(false),
        });
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

    /// Starts a stage, with the model runs it is expected to take when known.
    fn show_stage(&self, stage: &str, budget: Option<usize>) {
        if self.bar.is_none() && !self.lines {
            return;
        }
        let stage = stage.to_string();
        if let Ok(mut s) = self.shared.state.lock() {
            if s.stage == stage {
                return;
            }
            s.stage = stage;
            s.budget = budget;
            s.runs_at_stage = model_runs();
            s.counted = None;
            s.tenths_shown = 0;
        }
        if self.lines {
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

    /// The live display picks the count up at its next tick; a log gets a line at every
    /// tenth of the total.
    fn count(&self, done: usize, total: usize) {
        if self.bar.is_none() && !self.lines {
            return;
        }
        let mut line_due = false;
        if let Ok(mut s) = self.shared.state.lock() {
            s.counted = Some((done, total));
            let tenths = (10 * done / total.max(1)).min(10);
            if tenths > s.tenths_shown {
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
