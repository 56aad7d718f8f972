//! # subfric-app
//!
//! The application layer of subfric, below its front ends (the `subfric` command line in
//! `crates/cli`, the Python package in `python/`, and any later one): what a user asks for
//! (requests), the pipelines that answer it, returning values, and the files they write. A
//! front end parses its own input (clap flags, Python arguments) into these requests, shows
//! progress through [`Progress`], and prints or converts the results; the same request gives
//! the same result and the same files whichever front end made it.
//!
//! One room per command, and three below them that every command shares:
//!
//! - [`fit`](mod@fit): load and check sets, calibrate, `fit.json` ([`fit()`] returns values,
//!   [`fit::fit_to_folder`] writes them).
//! - [`diagnose`](mod@diagnose): the diagnosis of a set and `diagnosis.json`, `diagnosis.txt`
//!   and its figures; [`replicates`] its verdict again at further seeds of the fits' random
//!   start; [`selfcheck`] the diagnosis scored on sets with a known truth.
//! - [`plan`]: the next test to run (`plan.json`, `plan.txt`, scenarios, figure), on the model
//!   the set's diagnosis chose ([`outcome::plan_basis`]), never a test the set holds
//!   ([`repeat`]).
//! - [`posterior`]: the posterior of a fit's parameters (`fit --posterior`): summary beside
//!   the profile intervals, predictive bands, corner plot, thinned chain.
//! - [`reproduce`]: every bundled set fitted, the paper's tables beside the published values.
//! - [`campaign`](mod@campaign): many sets at once, locally or by Slurm or Dask, and the
//!   campaign table and figures.
//! - [`simulate`], [`sets`] (check and import), [`bench`](mod@bench).
//! - [`render`]: everything a person reads — the fit's table ([`render::fit_report`]), the
//!   diagnosis's text ([`render::diagnose_report`]), the HTML reports ([`render::report`],
//!   pages of [`render::html`]), the overlay figures ([`render::figures`]).
//! - [`outcome`]: what a command found, below the reports that show it: the fit's outcome,
//!   [`outcome::adequacy`] (whether the model describes the data, the first thing every
//!   command that fits says) and the model a plan rests on.
//! - [`folders`]: where results go and what may be replaced there ([`folders::output`]),
//!   the lock on a results folder ([`folders::lock`]) and the file helpers ([`folders::io`]:
//!   atomic writes, the parameter-file reader).
//! - [`flags`]: values of `--fix`, `--bounds`, `--weight` and `--free` as both front ends take
//!   them.
//!
//! Errors are `anyhow` errors whose text names the file, line and field and what was
//! expected; [`error_text`] prints one with each cause once.

pub mod bench;
pub mod campaign;
pub mod diagnose;
pub mod fit;
pub mod flags;
pub mod folders;
pub mod outcome;
pub mod plan;
pub mod posterior;
pub mod progress;
pub mod render;
pub mod repeat;
pub mod replicates;
pub mod reproduce;
pub mod selfcheck;
pub mod sets;
pub mod simulate;

pub use diagnose::{diagnose, Diagnosed};
pub use fit::{fit, FitOutcome, FitRequest, Fitted};
pub use folders::io::load_model;
pub use progress::{Progress, Silent};
pub use subfric_data::visible;

/// `s` cut to `n` characters, its last one an ellipsis when cut (a column of a text table).
pub(crate) fn truncate(s: &str, n: usize) -> String {
    if s.chars().count() <= n {
        s.to_string()
    } else {
        format!("{}…", s.chars().take(n - 1).collect::<String>())
    }
}

/// An error and its causes, each cause once: a cause whose text the message already holds
/// (such as an OS error that a file error quotes) is not repeated.
pub fn error_text(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !text.contains(&c) {
            text.push_str(": ");
            text.push_str(&c);
        }
    }
    text
}

/// An error that names `place` (a set folder): as it is when its text already does, else with
/// `place` in front.
pub(crate) fn located(e: anyhow::Error, place: &std::path::Path) -> anyhow::Error {
    let p = place.display().to_string();
    if error_text(&e).contains(&p) {
        e
    } else {
        anyhow::anyhow!("{p}: {}", error_text(&e))
    }
}
