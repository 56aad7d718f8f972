//! Levenberg–Marquardt in a box (projected steps), with a forward-difference Jacobian.
//! argmin offers Gauss–Newton but no damped, bounded least squares, hence this small solver —
//! written as an argmin `Solver` and run by its `Executor`, as the crate's Nelder–Mead is.
//!
//! The damped step solves min ‖J δ + r‖² + λ ‖D δ‖² as a least-squares problem by QR
//! (J = QR once per iteration, then a small QR of [R; √λ D] per damping trial), as MINPACK does,
//! rather than by Cholesky on JᵀJ + λD²: forming JᵀJ squares the condition number, and the
//! friction problems have nearly flat directions (κ against ξ at one rate) where that loses
//! every digit of the step.

use crate::residuals::{Bounded, Residuals};
use argmin::core::{
    Error as ArgminError, Executor, IterState, Problem, Solver, State, TerminationReason, KV,
};
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// Why a local run stopped (Levenberg–Marquardt, or Nelder–Mead for the last two variants).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Termination {
    /// Relative decrease of the cost below tolerance over several accepted steps.
    CostConverged,
    /// Step below tolerance.
    StepConverged,
    /// The residual is (nearly) orthogonal to every free column of the Jacobian that the box
    /// lets move: a stationary point.
    GradientConverged,
    /// Iteration limit reached.
    MaxIterations,
    /// Damping grew without finding a decrease (at a minimum, or a non-smooth point).
    DampingLimit,
    /// Nelder–Mead: the spread of the simplex's costs fell below tolerance.
    SimplexConverged,
    /// The local method could not run or stopped for another reason (argmin's message).
    Failed(String),
}

impl Termination {
    /// True when the run stopped at a point no step could improve: a stationary point by one of
    /// the tolerances, or the damping limit (a minimum, or a kink). An iteration limit or a
    /// failure is not convergence.
    pub fn converged(&self) -> bool {
        !matches!(self, Termination::MaxIterations | Termination::Failed(_))
    }
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Termination::CostConverged => f.write_str("cost converged"),
            Termination::StepConverged => f.write_str("step converged"),
            Termination::GradientConverged => f.write_str("gradient converged"),
            Termination::MaxIterations => f.write_str("iteration limit"),
            Termination::DampingLimit => f.write_str("damping limit"),
            Termination::SimplexConverged => f.write_str("simplex converged"),
            Termination::Failed(why) => write!(f, "failed: {why}"),
        }
    }
}

/// Relative forward-difference step of the Jacobian: h = step·(1 + |x|). Larger than √ε
/// because the model's return mapping is solved to a tolerance (about 1e-10 of the traction),
/// not to round-off, and that solver noise must stay small against the differences.
pub const JACOBIAN_STEP: f64 = 1e-6;

/// Floor of the damping scale D_k = ‖J_k‖, so a column with no sensitivity is still damped.
const MIN_COLUMN_SCALE: f64 = 1e-6;

/// Options of a least-squares run.
#[derive(Clone, Copy, Debug)]
pub struct LmOptions {
    /// Iteration limit.
    pub max_iterations: usize,
    /// Stop when the relative cost decrease of `stall_steps` accepted steps in a row is below
    /// this.
    pub cost_tolerance: f64,
    /// Accepted steps with a tiny decrease before stopping: one may be a step along a curved
    /// valley, several in a row are not.
    pub stall_steps: usize,
    /// Stop when the step (transformed units) is below this.
    pub step_tolerance: f64,
    /// Stop when max_k |J_kᵀ r| / (‖J_k‖ ‖r‖) over the free coordinates the box lets move is
    /// below this (MINPACK's `gtol`: the cosine between the residual and each column; 0
    /// disables the test).
    pub gradient_tolerance: f64,
    /// Damping λ of the first iteration (relative to D² = diag JᵀJ).
    pub initial_damping: f64,
    /// λ is multiplied by this after a step that did not decrease the cost.
    pub damping_increase: f64,
    /// λ is divided by this after an accepted step.
    pub damping_decrease: f64,
    /// Smallest λ.
    pub min_damping: f64,
    /// Largest λ: beyond it the run stops with [`Termination::DampingLimit`].
    pub max_damping: f64,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            max_iterations: 100,
            cost_tolerance: 1e-9,
            stall_steps: 4,
            step_tolerance: 1e-8,
            gradient_tolerance: 1e-10,
            initial_damping: 1e-3,
            damping_increase: 4.0,
            damping_decrease: 3.0,
            min_damping: 1e-12,
            max_damping: 1e12,
        }
    }
}

/// Result of a least-squares run.
#[derive(Clone, Debug)]
pub struct LmResult {
    /// Final point.
    pub x: Vec<f64>,
    /// Sum of squared residuals there.
    pub ssr: f64,
    /// Iterations.
    pub iterations: usize,
    /// Why it stopped.
    pub termination: Termination,
}

/// Forward-difference Jacobian of the residuals at `x` (N × m), stepping inward at the upper
/// wall. Columns with `only[k]` false are left zero (not evaluated).
///
/// The columns are independent model runs and are evaluated in parallel: a least-squares run
/// is a chain of Jacobians, and where one run is all that is left (the last polish of a
/// diagnosis, the slowest velocity step) its columns are the only work the other cores can
/// take. Each column is computed exactly as in a serial loop, so the matrix is the same.
pub fn jacobian<R: Residuals + ?Sized>(
    p: &R,
    x: &[f64],
    r0: &[f64],
    only: Option<&[bool]>,
) -> DMatrix<f64> {
    use rayon::prelude::*;
    let n = r0.len();
    let m = x.len();
    let hi = p.bounds().1;
    let columns: Vec<(usize, f64, Vec<f64>)> = (0..m)
        .into_par_iter()
        .filter(|&k| only.is_none_or(|mask| mask[k]))
        .map(|k| {
            let mut h = JACOBIAN_STEP * (1.0 + x[k].abs());
            if x[k] + h > hi[k] {
                h = -h;
            }
            let mut xp = x.to_vec();
            xp[k] = x[k] + h;
            let mut r = Vec::with_capacity(n);
            p.residuals_at(&xp, &mut r);
            (k, h, r)
        })
        .collect();
    let mut j = DMatrix::zeros(n, m);
    for (k, h, r) in columns {
        for i in 0..n {
            j[(i, k)] = (r[i] - r0[i]) / h;
        }
    }
    j
}

/// The linearisation of one iteration, restricted to the free coordinates, factored once so
/// that every damping trial costs only a small QR.
struct Linearisation {
    /// Indices of the free coordinates.
    free: Vec<usize>,
    /// R of J_free = Q R (min(N, f) × f).
    r: DMatrix<f64>,
    /// First min(N, f) entries of Qᵀ r.
    qtr: DVector<f64>,
    /// Damping scale D_k (column norms, floored).
    scale: Vec<f64>,
}

impl Linearisation {
    fn new(j: &DMatrix<f64>, r: &[f64], free: Vec<usize>) -> Linearisation {
        let jf = j.select_columns(free.iter());
        let scale: Vec<f64> = jf
            .column_iter()
            .map(|c| c.norm().max(MIN_COLUMN_SCALE))
            .collect();
        let k = jf.nrows().min(jf.ncols());
        let qr = jf.qr();
        let mut qtr = DMatrix::from_column_slice(r.len(), 1, r);
        qr.q_tr_mul(&mut qtr);
        let qtr = DVector::from_iterator(k, qtr.column(0).iter().take(k).copied());
        Linearisation {
            free,
            r: qr.r(),
            qtr,
            scale,
        }
    }

    /// The step minimising ‖J δ + r‖² + λ ‖D δ‖² over the free coordinates (zero elsewhere),
    /// or `None` if it is not finite.
    fn step(&self, lambda: f64, m: usize) -> Option<Vec<f64>> {
        let (k, f) = (self.r.nrows(), self.free.len());
        let mut a = DMatrix::zeros(k + f, f);
        a.view_mut((0, 0), (k, f)).copy_from(&self.r);
        let mut b = DMatrix::zeros(k + f, 1);
        for i in 0..k {
            b[(i, 0)] = -self.qtr[i];
        }
        let root = lambda.sqrt();
        for (c, d) in self.scale.iter().enumerate() {
            a[(k + c, c)] = root * d;
        }
        let qr = a.qr();
        qr.q_tr_mul(&mut b);
        let top = b.rows(0, f).into_owned();
        let delta = qr.r().solve_upper_triangular(&top)?;
        let mut full = vec![0.0; m];
        for (c, &i) in self.free.iter().enumerate() {
            full[i] = delta[(c, 0)];
        }
        full.iter().all(|v| v.is_finite()).then_some(full)
    }
}

/// The free coordinates the box lets move: those at a wall whose descent direction points out
/// of the box are held for this iteration (an active set), so the step of the others is solved
/// as if they were fixed, instead of being computed with them and then cut by the projection.
fn movable(
    j: &DMatrix<f64>,
    r: &[f64],
    x: &[f64],
    lo: &[f64],
    hi: &[f64],
    free: &[usize],
) -> Vec<usize> {
    free.iter()
        .copied()
        .filter(|&k| {
            // g_k = J_kᵀ r is half the SSR's derivative: descent lowers x_k when g_k > 0.
            let g: f64 = j.column(k).iter().zip(r).map(|(a, b)| a * b).sum();
            !((g > 0.0 && x[k] <= lo[k]) || (g < 0.0 && x[k] >= hi[k]))
        })
        .collect()
}

/// MINPACK's gradient measure over the movable coordinates: the largest cosine between the
/// residual and a column of J (0 when the residual is zero).
fn gradient_cosine(j: &DMatrix<f64>, r: &[f64], movable: &[usize]) -> f64 {
    let rnorm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
    if rnorm == 0.0 {
        return 0.0;
    }
    movable
        .iter()
        .map(|&k| {
            let col = j.column(k);
            let cnorm = col.norm();
            if cnorm == 0.0 {
                return 0.0;
            }
            let g: f64 = col.iter().zip(r).map(|(a, b)| a * b).sum();
            g.abs() / (cnorm * rnorm)
        })
        .fold(0.0, f64::max)
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(u, v)| (u - v).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Minimises the SSR from `x0` within the box; coordinates with `fixed[k]` true are held.
///
/// Each iteration holds the coordinates pressed against a wall by the gradient, solves the
/// damped step of the others, and projects the trial point into the box. The iterations are
/// [`LevenbergMarquardt`]'s, run by argmin's `Executor` (as Nelder–Mead is): the iteration
/// limit is the executor's, every other stop is the solver's, and both come back as a
/// [`Termination`].
pub fn levenberg_marquardt<R: Residuals + ?Sized>(
    p: &R,
    x0: &[f64],
    fixed: Option<&[bool]>,
    opts: &LmOptions,
) -> LmResult {
    let m = x0.len();
    let free_mask: Vec<bool> = (0..m).map(|k| fixed.is_none_or(|f| !f[k])).collect();
    let solver = LevenbergMarquardt::new(*opts, free_mask);
    let run = Executor::new(p, solver)
        .configure(|s| s.param(x0.to_vec()).max_iters(opts.max_iterations as u64))
        .timer(false)
        .run();
    match run {
        Ok(mut res) => {
            let iterations = res.state().get_iter() as usize;
            let termination = match res.solver().stopped.clone() {
                Some(t) => t,
                None => match res.state().get_termination_reason() {
                    Some(TerminationReason::MaxItersReached) => Termination::MaxIterations,
                    other => Termination::Failed(format!("{other:?}")),
                },
            };
            let ssr = res.state().get_cost();
            let x = res.state.take_param().unwrap_or_else(|| x0.to_vec());
            LmResult {
                x,
                ssr,
                iterations,
                termination,
            }
        }
        Err(e) => {
            let mut x = x0.to_vec();
            p.clamp_into_box(&mut x);
            let mut r = Vec::new();
            p.residuals_at(&x, &mut r);
            LmResult {
                ssr: r.iter().map(|v| v * v).sum(),
                x,
                iterations: 0,
                termination: Termination::Failed(e.to_string()),
            }
        }
    }
}

/// The state argmin keeps for [`LevenbergMarquardt`]: the point and its SSR (the cost).
pub type LmState = IterState<Vec<f64>, (), (), (), (), f64>;

/// Bounded Levenberg–Marquardt as an argmin [`Solver`] over any [`Residuals`] problem: one
/// `next_iter` is one Jacobian and the damping trials until a step lowers the cost (or a stop).
/// Its own stops end the run with argmin's `SolverExit` and are kept in `stopped`.
#[derive(Clone, Debug)]
pub struct LevenbergMarquardt {
    opts: LmOptions,
    /// Coordinates the run may move (the others are held).
    free_mask: Vec<bool>,
    free: Vec<usize>,
    /// Damping of the next trial.
    lambda: f64,
    /// Accepted steps in a row with a tiny relative decrease.
    stalls: usize,
    /// Residuals at the current point, and scratch for a trial's.
    r: Vec<f64>,
    rt: Vec<f64>,
    /// Why the solver stopped the run, when it did (an iteration limit is the executor's).
    pub stopped: Option<Termination>,
}

impl LevenbergMarquardt {
    /// A solver with `opts` moving the coordinates `free_mask` marks.
    pub fn new(opts: LmOptions, free_mask: Vec<bool>) -> LevenbergMarquardt {
        let free = (0..free_mask.len()).filter(|&k| free_mask[k]).collect();
        LevenbergMarquardt {
            opts,
            free_mask,
            free,
            lambda: opts.initial_damping,
            stalls: 0,
            r: Vec::new(),
            rt: Vec::new(),
            stopped: None,
        }
    }

    fn stop(&mut self, state: LmState, x: Vec<f64>, ssr: f64, why: Termination) -> LmState {
        let reason = TerminationReason::SolverExit(why.to_string());
        self.stopped = Some(why);
        state.param(x).cost(ssr).terminate_with(reason)
    }
}

impl<R: Residuals + ?Sized> Solver<&R, LmState> for LevenbergMarquardt {
    const NAME: &'static str = "Levenberg-Marquardt in a box";

    fn init(
        &mut self,
        problem: &mut Problem<&R>,
        mut state: LmState,
    ) -> Result<(LmState, Option<KV>), ArgminError> {
        let p = *crate::residuals::given(problem)?;
        let mut x = state.take_param().unwrap_or_default();
        p.clamp_into_box(&mut x);
        p.residuals_at(&x, &mut self.r);
        let ssr: f64 = self.r.iter().map(|v| v * v).sum();
        if self.free.is_empty() {
            return Ok((self.stop(state, x, ssr, Termination::StepConverged), None));
        }
        Ok((state.param(x).cost(ssr), None))
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<&R>,
        mut state: LmState,
    ) -> Result<(LmState, Option<KV>), ArgminError> {
        let p = *crate::residuals::given(problem)?;
        let (lo, hi) = p.bounds();
        let opts = self.opts;
        let mut ssr = state.get_cost();
        let mut x = state.take_param().unwrap_or_default();
        let m = x.len();
        let j = jacobian(p, &x, &self.r, Some(&self.free_mask));
        let active = movable(&j, &self.r, &x, lo, hi, &self.free);
        if active.is_empty() || gradient_cosine(&j, &self.r, &active) <= opts.gradient_tolerance {
            return Ok((
                self.stop(state, x, ssr, Termination::GradientConverged),
                None,
            ));
        }
        let lin = Linearisation::new(&j, &self.r, active);
        // Damping trials until a step lowers the cost.
        loop {
            let Some(delta) = lin.step(self.lambda, m) else {
                self.lambda *= opts.damping_increase;
                if self.lambda > opts.max_damping {
                    return Ok((self.stop(state, x, ssr, Termination::DampingLimit), None));
                }
                continue;
            };
            let mut xt: Vec<f64> = x.iter().zip(&delta).map(|(a, b)| a + b).collect();
            p.clamp_into_box(&mut xt);
            let step = distance(&xt, &x);
            // A trial is kept only below the current SSR: one sure to end above it stops there.
            let ssr_t: f64 = match p.residuals_unless_above(&xt, &mut self.rt, ssr) {
                Bounded::Computed => self.rt.iter().map(|v| v * v).sum(),
                Bounded::Above => f64::INFINITY,
            };
            if ssr_t.is_finite() && ssr_t < ssr {
                let rel = (ssr - ssr_t) / ssr.max(f64::MIN_POSITIVE);
                x = xt;
                std::mem::swap(&mut self.r, &mut self.rt);
                ssr = ssr_t;
                self.lambda = (self.lambda / opts.damping_decrease).max(opts.min_damping);
                self.stalls = if rel < opts.cost_tolerance {
                    self.stalls + 1
                } else {
                    0
                };
                if self.stalls >= opts.stall_steps {
                    return Ok((self.stop(state, x, ssr, Termination::CostConverged), None));
                }
                if step < opts.step_tolerance {
                    return Ok((self.stop(state, x, ssr, Termination::StepConverged), None));
                }
                return Ok((state.param(x).cost(ssr), None));
            }
            if step < opts.step_tolerance {
                return Ok((self.stop(state, x, ssr, Termination::StepConverged), None));
            }
            self.lambda *= opts.damping_increase;
            if self.lambda > opts.max_damping {
                return Ok((self.stop(state, x, ssr, Termination::DampingLimit), None));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_problems::*;

    fn run(p: &impl Residuals, x0: &[f64], fixed: Option<&[bool]>) -> LmResult {
        levenberg_marquardt(p, x0, fixed, &LmOptions::default())
    }

    fn assert_close(got: &[f64], want: &[f64], tol: f64) {
        for (k, (g, w)) in got.iter().zip(want).enumerate() {
            assert!((g - w).abs() <= tol, "x[{k}] = {g}, expected {w} (±{tol})");
        }
    }

    #[test]
    fn rosenbrock_reaches_its_minimum() {
        let r = run(&rosenbrock(), &[-1.2, 1.0], None);
        assert_close(&r.x, &[1.0, 1.0], 1e-6);
        assert!(r.ssr < 1e-20, "{r:?}");
        assert!(r.iterations < 40, "{r:?}");
    }

    #[test]
    fn the_solver_runs_under_argmins_executor_and_its_observers_see_every_iteration() {
        use argmin::core::observers::{Observe, ObserverMode};
        use std::sync::atomic::{AtomicUsize, Ordering};
        use std::sync::Arc;
        // An observer counting iterations and checking the cost never rises: what a progress
        // display or a log would be given.
        struct Watch(Arc<AtomicUsize>, f64);
        impl Observe<LmState> for Watch {
            fn observe_iter(&mut self, state: &LmState, _kv: &KV) -> Result<(), ArgminError> {
                assert!(state.get_cost() <= self.1, "the cost rose");
                self.1 = state.get_cost();
                self.0.fetch_add(1, Ordering::SeqCst);
                Ok(())
            }
        }
        let p = rosenbrock();
        let seen = Arc::new(AtomicUsize::new(0));
        let solver = LevenbergMarquardt::new(LmOptions::default(), vec![true, true]);
        let res = Executor::new(&p, solver)
            .configure(|s| s.param(vec![-1.2, 1.0]).max_iters(100))
            .add_observer(Watch(seen.clone(), f64::INFINITY), ObserverMode::Always)
            .run()
            .unwrap();
        let iterations = res.state().get_iter() as usize;
        assert_eq!(seen.load(Ordering::SeqCst), iterations);
        // The same run as the function's, which reports the solver's own stop.
        let direct = run(&p, &[-1.2, 1.0], None);
        assert_eq!(direct.iterations, iterations);
        assert_eq!(res.state().get_param().unwrap(), &direct.x);
        assert!(direct.termination.converged(), "{direct:?}");
        assert_eq!(
            res.state().get_termination_reason(),
            Some(&TerminationReason::SolverExit(
                direct.termination.to_string()
            ))
        );
        // An iteration limit is the executor's, and says so.
        let short = levenberg_marquardt(
            &p,
            &[-1.2, 1.0],
            None,
            &LmOptions {
                max_iterations: 3,
                ..LmOptions::default()
            },
        );
        assert_eq!(
            (short.iterations, short.termination),
            (3, Termination::MaxIterations)
        );
    }

    #[test]
    fn rosenbrock_stops_on_an_active_bound() {
        // With x₁ ≤ 0.5 the valley floor x₂ = x₁² is followed to the wall:
        // minimum (1 − 0.5)² = 0.25 at (0.5, 0.25).
        let p = rosenbrock().with_box(vec![-2.0, -2.0], vec![0.5, 2.0]);
        let r = run(&p, &[-1.2, 1.0], None);
        assert_eq!(r.x[0], 0.5, "the bound is active and held exactly");
        assert_close(&r.x, &[0.5, 0.25], 1e-7);
        assert!((r.ssr - 0.25).abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn rosenbrock_holds_a_fixed_coordinate() {
        // x₁ held at 0.8: the best x₂ is 0.64, SSR (1 − 0.8)² = 0.04.
        let r = run(&rosenbrock(), &[0.8, -1.0], Some(&[true, false]));
        assert_eq!(r.x[0], 0.8, "fixed coordinate moved");
        assert_close(&r.x, &[0.8, 0.64], 1e-8);
        assert!((r.ssr - 0.04).abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn helical_valley_reaches_its_minimum() {
        let r = run(&helical_valley(), &[-1.0, 0.0, 0.0], None);
        assert_close(&r.x, &[1.0, 0.0, 0.0], 1e-6);
        assert!(r.ssr < 1e-16, "{r:?}");
    }

    #[test]
    fn helical_valley_stops_on_an_active_bound() {
        // x₃ ≥ 0.1: the helix x₃ = 10θ on the unit circle leaves only x₃² = 0.01, at
        // θ = 0.01 turn.
        let p = helical_valley().with_box(vec![-2.0, -2.0, 0.1], vec![2.0, 2.0, 2.0]);
        let r = run(&p, &[-1.0, 0.0, 0.5], None);
        let angle = 2.0 * std::f64::consts::PI * 0.01;
        assert_eq!(r.x[2], 0.1, "the bound is active and held exactly");
        assert_close(&r.x, &[angle.cos(), angle.sin(), 0.1], 1e-6);
        assert!((r.ssr - 0.01).abs() < 1e-10, "{r:?}");
    }

    #[test]
    fn helical_valley_holds_a_fixed_coordinate() {
        // x₃ held at 0.5: θ = 0.05 turn on the unit circle, SSR 0.25.
        let r = run(
            &helical_valley(),
            &[-1.0, 0.0, 0.5],
            Some(&[false, false, true]),
        );
        let angle = 2.0 * std::f64::consts::PI * 0.05;
        assert_eq!(r.x[2], 0.5, "fixed coordinate moved");
        assert_close(&r.x, &[angle.cos(), angle.sin(), 0.5], 1e-6);
        assert!((r.ssr - 0.25).abs() < 1e-10, "{r:?}");
    }

    #[test]
    fn the_parallel_jacobian_is_the_serial_loops_bit_for_bit() {
        // Each column as a serial loop computes it, stepping inward at the upper wall and
        // leaving the masked columns zero: the parallel evaluation must not change a bit.
        let p = kowalik_osborne().with_box(vec![-1.0; 4], vec![0.25, 1.0, 1.0, 1.0]);
        let x = [0.25, 0.39, 0.415, 0.39];
        let mut r0 = Vec::new();
        p.residuals_at(&x, &mut r0);
        let only = [true, true, false, true];
        let got = jacobian(&p, &x, &r0, Some(&only));
        let mut r = Vec::new();
        for k in 0..4 {
            let mut h = JACOBIAN_STEP * (1.0 + x[k].abs());
            if x[k] + h > p.bounds().1[k] {
                h = -h;
            }
            let mut xp = x.to_vec();
            xp[k] += h;
            p.residuals_at(&xp, &mut r);
            for i in 0..r0.len() {
                let want = if only[k] { (r[i] - r0[i]) / h } else { 0.0 };
                assert_eq!(got[(i, k)].to_bits(), want.to_bits(), "row {i}, column {k}");
            }
        }
        assert!(got[(0, 0)] != 0.0 && got[(0, 2)] == 0.0);
    }

    #[test]
    fn powell_singular_converges_despite_a_singular_jacobian() {
        let r = run(&powell_singular(), &[3.0, -1.0, 0.0, 1.0], None);
        assert!(r.ssr < 1e-14, "{r:?}");
        assert_close(&r.x, &[0.0; 4], 1e-3);
    }

    #[test]
    fn bard_reaches_the_published_nonzero_residual_minimum() {
        let r = run(&bard(), &[1.0, 1.0, 1.0], None);
        assert!((r.ssr - 8.21487e-3).abs() < 1e-8, "{r:?}");
        assert_close(&r.x, &[0.0824106, 1.13304, 2.34369], 1e-4);
    }

    #[test]
    fn kowalik_osborne_reaches_the_published_minimum() {
        let r = run(&kowalik_osborne(), &[0.25, 0.39, 0.415, 0.39], None);
        assert!((r.ssr - 3.07505e-4).abs() < 1e-9, "{r:?}");
        assert_close(&r.x, &[0.192807, 0.191282, 0.123056, 0.136062], 1e-4);
    }

    #[test]
    fn an_ill_conditioned_linear_model_is_solved_to_its_exact_answer() {
        // Hilbert(8): cond(H) ≈ 1.5e10. The damping floor is lowered below σ_min(H)² ≈ 1e-20,
        // which would otherwise stall the smallest singular direction whatever the
        // factorisation. (Iterating refines the step, so Cholesky on HᵀH gets there too on
        // this problem; the test guards the QR step's accuracy, not the difference.)
        let h = hilbert(8);
        let truth = vec![1.0; 8];
        let b: Vec<f64> = h
            .iter()
            .map(|row| row.iter().zip(&truth).map(|(a, x)| a * x).sum())
            .collect();
        let (lo, hi) = (vec![-100.0; 8], vec![100.0; 8]);
        let p = linear(h, b, lo, hi);
        let opts = LmOptions {
            min_damping: 1e-30,
            max_iterations: 200,
            ..LmOptions::default()
        };
        let r = levenberg_marquardt(&p, &[0.0; 8], None, &opts);
        // cond(H)·ε ≈ 3e-6 is what any backward-stable solver can promise.
        assert_close(&r.x, &truth, 1e-4);
    }

    #[test]
    fn the_gradient_test_stops_at_a_stationary_point() {
        // A nonzero-residual linear fit: after the first (exact) step the residual is
        // orthogonal to the columns, and the next iteration stops on the gradient test.
        let a = vec![
            vec![1.0, 0.0],
            vec![1.0, 1.0],
            vec![1.0, 2.0],
            vec![1.0, 3.0],
        ];
        let b = vec![0.1, 0.9, 2.2, 2.8];
        let p = linear(a, b, vec![-10.0; 2], vec![10.0; 2]);
        let opts = LmOptions {
            gradient_tolerance: 1e-6,
            ..LmOptions::default()
        };
        let r = levenberg_marquardt(&p, &[0.0, 0.0], None, &opts);
        assert_eq!(r.termination, Termination::GradientConverged, "{r:?}");
        // Least squares: slope 0.94, intercept 0.09.
        assert_close(&r.x, &[0.09, 0.94], 1e-6);
    }

    #[test]
    fn a_bound_blocking_the_gradient_does_not_prevent_the_gradient_stop() {
        // The sphere's centre lies outside the box: at the wall the gradient points out of
        // the box, which the projected gradient test ignores.
        let p = sphere(vec![2.0, 0.5], vec![-1.0, -1.0], vec![1.0, 1.0]);
        let opts = LmOptions {
            gradient_tolerance: 1e-6,
            ..LmOptions::default()
        };
        let r = levenberg_marquardt(&p, &[0.0, 0.0], None, &opts);
        assert_eq!(r.termination, Termination::GradientConverged, "{r:?}");
        assert_close(&r.x, &[1.0, 0.5], 1e-6);
    }
}
