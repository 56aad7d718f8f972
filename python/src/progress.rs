//! Progress of the long calls (`fit`, `diagnose`), handed to a Python callable
//! `progress(stage, done, total)` as the command's progress display shows it: a stage begins
//! (`done` None, `total` its budget in model runs when known, else None), and work within a stage
//! (`done` of about `total`). The calls run with the GIL released; each report takes it back for
//! the call only. Counts arrive often and from worker threads: they are passed on at most every
//! [`COUNT_INTERVAL`], and always when a stage's work is done.

use pyo3::prelude::*;
use std::sync::Mutex;
use std::time::{Duration, Instant};
use subfric_app::progress::Progress;

/// Least time between two counts passed on.
const COUNT_INTERVAL: Duration = Duration::from_millis(100);

/// A Python callable as the progress of a long call. The first exception it raises stops the
/// reports and is raised by [`Callback::finish`] once the call has returned.
pub(crate) struct Callback {
    callable: Py<PyAny>,
    /// The stage under way (counts are reported in it) and when a count was last passed on.
    current: Mutex<(String, Option<Instant>)>,
    raised: Mutex<Option<PyErr>>,
}

impl Callback {
    /// `callable`, when given, checked to be callable (a `TypeError` naming `progress`
    /// otherwise).
    pub(crate) fn of(py: Python<'_>, callable: Option<Py<PyAny>>) -> PyResult<Option<Callback>> {
        let Some(callable) = callable else {
            return Ok(None);
        };
        if !callable.bind(py).is_callable() {
            let type_name = callable.bind(py).get_type().name()?.to_string();
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "progress: a {type_name} is not callable (expected a function progress(stage, done, total), or None)"
            )));
        }
        Ok(Some(Callback {
            callable,
            current: Mutex::new((String::new(), None)),
            raised: Mutex::new(None),
        }))
    }

    fn call(&self, stage: &str, done: Option<usize>, total: Option<usize>) {
        let mut raised = self.raised.lock().unwrap_or_else(|e| e.into_inner());
        if raised.is_some() {
            return;
        }
        Python::attach(|py| {
            if let Err(e) = self.callable.call1(py, (stage, done, total)) {
                *raised = Some(e);
            }
        });
    }

    /// The exception the callable raised, if it raised one.
    pub(crate) fn finish(self) -> PyResult<()> {
        match self.raised.into_inner().unwrap_or_else(|e| e.into_inner()) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

/// A campaign's progress as its sets end ("campaign: 3 of 20 sets done", `done` of `total`
/// sets), without the stages of each set's own fit and diagnosis, which run several at once.
pub(crate) struct SetsOnly<'a>(pub(crate) &'a Callback);

impl Progress for SetsOnly<'_> {
    // The sets' own stages interleave; the count below says where the campaign is.
    fn stage(&self, _stage: &str, _budget: Option<usize>) {}

    fn warning(&self, _text: &str) {}

    fn note(&self, _text: &str) {}

    // Every set's end is passed on: there are few, and each ends seconds after the last.
    fn count(&self, done: usize, total: usize) {
        self.0.call(
            &format!("campaign: {done} of {total} sets done"),
            Some(done),
            Some(total),
        );
    }
}

impl Progress for Callback {
    fn stage(&self, stage: &str, budget: Option<usize>) {
        {
            let mut current = self.current.lock().unwrap_or_else(|e| e.into_inner());
            *current = (stage.to_string(), None);
        }
        self.call(stage, None, budget);
    }

    // The results carry their warnings and notes, as with the command's --json.
    fn warning(&self, _text: &str) {}

    fn note(&self, _text: &str) {}

    fn count(&self, done: usize, total: usize) {
        let stage = {
            let mut current = self.current.lock().unwrap_or_else(|e| e.into_inner());
            let now = Instant::now();
            let due = current
                .1
                .is_none_or(|last| now.duration_since(last) >= COUNT_INTERVAL);
            if !(due || done >= total) {
                return;
            }
            current.1 = Some(now);
            current.0.clone()
        };
        self.call(&stage, Some(done), Some(total));
    }
}
