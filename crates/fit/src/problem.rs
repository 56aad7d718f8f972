//! The calibration problem: tests, the parameter space, and evaluation counting.

use crate::dataset::{residuals_into, residuals_into_unless_above};
use crate::residuals::{Bounded, Residuals};
use crate::space::Space;
use argmin::core::{CostFunction, Error as ArgminError};
use std::cell::RefCell;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use subfric_model::Model;
use subfric_reading::FitTest;

/// The model runs of one job (a calibration, a diagnosis, a plan): every [`Problem`] the job
/// creates [`Problem::counting`] into it adds its runs here. A progress display or a trace reads
/// the job's own count, so two jobs in one process (tests on parallel threads, a campaign's
/// sets) never see each other's runs. Clones share the count.
#[derive(Clone, Debug, Default)]
pub struct RunCounter(Arc<AtomicUsize>);

impl RunCounter {
    /// A counter at zero, shared by nothing yet.
    pub fn new() -> RunCounter {
        RunCounter::default()
    }

    /// Model runs (all tests simulated once) counted so far.
    pub fn runs(&self) -> usize {
        self.0.load(Ordering::Relaxed)
    }

    /// Whether `other` is a handle of this same count (a display handed one job's counter
    /// twice must not count its runs twice).
    pub fn same_count(&self, other: &RunCounter) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }

    fn add_one(&self) {
        self.0.fetch_add(1, Ordering::Relaxed);
    }
}

/// A least-squares problem over a [`Space`]: residuals are the noise-normalised errors of
/// every row of every test.
#[derive(Debug)]
pub struct Problem<'a> {
    /// Tests fitted jointly.
    pub tests: &'a [FitTest],
    /// Free parameters and their boxes.
    pub space: Space,
    evaluations: AtomicUsize,
    /// The job's counter this problem's runs count into as well, if any.
    job_runs: Option<RunCounter>,
}

impl<'a> Problem<'a> {
    /// A problem fitting `tests` over `space`; it counts its runs in [`Problem::evaluations`]
    /// only.
    pub fn new(tests: &'a [FitTest], space: Space) -> Self {
        Problem {
            tests,
            space,
            evaluations: AtomicUsize::new(0),
            job_runs: None,
        }
    }

    /// This problem with its runs counted into `job_runs` as well (`None`: its own count only),
    /// for the problems of a job someone watches.
    pub fn counting(mut self, job_runs: Option<&RunCounter>) -> Self {
        self.job_runs = job_runs.cloned();
        self
    }

    /// Number of rows that count in the fit (held-out rows excluded).
    pub fn rows(&self) -> usize {
        self.tests.iter().map(|t| t.counted_rows().len()).sum()
    }

    /// Model runs so far (one run = all tests simulated once).
    pub fn evaluations(&self) -> usize {
        self.evaluations.load(Ordering::Relaxed)
    }

    /// Residual vector at `x` (transformed coordinates).
    pub fn residuals(&self, x: &[f64], out: &mut Vec<f64>, scratch: &mut Vec<f64>) {
        self.count_run();
        let m = self.space.model_at(x);
        residuals_into(self.tests, &m, out, scratch);
    }

    /// [`Problem::residuals`] unless their sum of squares is sure to end above `ceiling`
    /// ([`residuals_into_unless_above`]). A run stopped early counts as a run.
    fn bounded_residuals(
        &self,
        x: &[f64],
        out: &mut Vec<f64>,
        scratch: &mut Vec<f64>,
        ceiling: f64,
    ) -> Bounded {
        self.count_run();
        let m = self.space.model_at(x);
        residuals_into_unless_above(self.tests, &m, out, scratch, ceiling)
    }

    fn count_run(&self) {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        if let Some(job) = &self.job_runs {
            job.add_one();
        }
    }

    /// Sum of squared residuals at `x`.
    pub fn ssr(&self, x: &[f64]) -> f64 {
        let mut r = Vec::new();
        let mut s = Vec::new();
        self.residuals(x, &mut r, &mut s);
        r.iter().map(|v| v * v).sum()
    }

    /// Model at `x`.
    pub fn model_at(&self, x: &[f64]) -> Model {
        self.space.model_at(x)
    }
}

thread_local! {
    /// Simulation buffer of the generic solvers' residual calls: one per worker thread, so a
    /// model run does not allocate.
    static SCRATCH: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// The solvers see the friction problem through its residuals and its box.
impl Residuals for Problem<'_> {
    fn dim(&self) -> usize {
        self.space.dim()
    }

    fn bounds(&self) -> (&[f64], &[f64]) {
        (&self.space.lo, &self.space.hi)
    }

    fn residuals_at(&self, x: &[f64], out: &mut Vec<f64>) {
        // A worker waiting inside a parallel model run (a set of many tests) may be handed
        // another model run, a Jacobian's column say, while it holds its buffer: that run
        // then simulates into a buffer of its own (the values do not depend on the buffer).
        SCRATCH.with(|s| match s.try_borrow_mut() {
            Ok(mut scratch) => self.residuals(x, out, &mut scratch),
            Err(_) => self.residuals(x, out, &mut Vec::new()),
        });
    }

    fn residuals_unless_above(&self, x: &[f64], out: &mut Vec<f64>, ceiling: f64) -> Bounded {
        SCRATCH.with(|s| match s.try_borrow_mut() {
            Ok(mut scratch) => self.bounded_residuals(x, out, &mut scratch, ceiling),
            Err(_) => self.bounded_residuals(x, out, &mut Vec::new(), ceiling),
        })
    }

    fn observations(&self) -> usize {
        self.rows()
    }

    fn sum_of_squares(&self, x: &[f64]) -> f64 {
        self.ssr(x)
    }
}

/// Nelder–Mead (argmin) sees the SSR of the point folded back into the box.
impl CostFunction for &Problem<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, x: &Self::Param) -> Result<f64, ArgminError> {
        let mut y = x.clone();
        fold_into_box(&mut y, &self.space.lo, &self.space.hi);
        Ok(self.ssr(&y))
    }
}

/// Reflects each coordinate back into [lo, hi] (a triangle wave), so unconstrained methods
/// can work in a box without flat regions at its walls.
pub fn fold_into_box(x: &mut [f64], lo: &[f64], hi: &[f64]) {
    for i in 0..x.len() {
        let w = hi[i] - lo[i];
        if w.is_nan() || w <= 0.0 || !x[i].is_finite() {
            x[i] = lo[i];
            continue;
        }
        let t = (x[i] - lo[i]).rem_euclid(2.0 * w);
        x[i] = lo[i] + if t <= w { t } else { 2.0 * w - t };
    }
}
