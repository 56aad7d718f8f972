//! Levenberg–Marquardt in a box (projected steps), with a forward-difference Jacobian.
//! argmin offers Gauss–Newton but no damped, bounded least squares, hence this small solver.

use crate::problem::Problem;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// Why a least-squares run stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Termination {
    /// Relative decrease of the cost below tolerance.
    CostConverged,
    /// Step below tolerance.
    StepConverged,
    /// Iteration limit reached.
    MaxIterations,
    /// Damping grew without finding a decrease (at a minimum, or a non-smooth point).
    DampingLimit,
}

/// Options of a least-squares run.
#[derive(Clone, Copy, Debug)]
pub struct LmOptions {
    /// Iteration limit.
    pub max_iterations: usize,
    /// Stop when the relative cost decrease of an accepted step is below this.
    pub cost_tolerance: f64,
    /// Stop when the step (transformed units) is below this.
    pub step_tolerance: f64,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            max_iterations: 100,
            cost_tolerance: 1e-9,
            step_tolerance: 1e-8,
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

/// Forward-difference Jacobian of the residuals at `x` (N × m), stepping inward at the walls.
pub fn jacobian(p: &Problem, x: &[f64], r0: &[f64], only: Option<&[bool]>) -> DMatrix<f64> {
    let n = r0.len();
    let m = x.len();
    let mut j = DMatrix::zeros(n, m);
    let mut r = Vec::with_capacity(n);
    let mut s = Vec::new();
    let mut xp = x.to_vec();
    for k in 0..m {
        if let Some(mask) = only {
            if !mask[k] {
                continue;
            }
        }
        let mut h = 1e-6 * (1.0 + x[k].abs());
        if x[k] + h > p.space.hi[k] {
            h = -h;
        }
        xp[k] = x[k] + h;
        p.residuals(&xp, &mut r, &mut s);
        for i in 0..n {
            j[(i, k)] = (r[i] - r0[i]) / h;
        }
        xp[k] = x[k];
    }
    j
}

/// Minimises the SSR from `x0`; coordinates with `fixed[k]` true are held.
pub fn levenberg_marquardt(
    p: &Problem,
    x0: &[f64],
    fixed: Option<&[bool]>,
    opts: &LmOptions,
) -> LmResult {
    let m = x0.len();
    let mut x = x0.to_vec();
    p.space.clamp(&mut x);
    let mut r = Vec::new();
    let mut s = Vec::new();
    p.residuals(&x, &mut r, &mut s);
    let mut ssr: f64 = r.iter().map(|v| v * v).sum();
    let free: Vec<bool> = (0..m).map(|k| fixed.is_none_or(|f| !f[k])).collect();
    let mut lambda = 1e-3;
    let mut termination = Termination::MaxIterations;
    let mut it = 0;
    let mut rt = Vec::new();
    let mut stalls = 0;
    'outer: while it < opts.max_iterations {
        it += 1;
        let j = jacobian(p, &x, &r, Some(&free));
        let jt = j.transpose();
        let jtj = &jt * &j;
        let g = &jt * DVector::from_column_slice(&r);
        loop {
            let mut a = jtj.clone();
            for k in 0..m {
                if free[k] {
                    a[(k, k)] += lambda * jtj[(k, k)].max(1e-12);
                } else {
                    for l in 0..m {
                        a[(k, l)] = 0.0;
                        a[(l, k)] = 0.0;
                    }
                    a[(k, k)] = 1.0;
                }
            }
            let mut rhs = -g.clone();
            for k in 0..m {
                if !free[k] {
                    rhs[k] = 0.0;
                }
            }
            let Some(delta) = a.cholesky().map(|c| c.solve(&rhs)) else {
                lambda *= 10.0;
                if lambda > 1e12 {
                    termination = Termination::DampingLimit;
                    break 'outer;
                }
                continue;
            };
            let mut xt: Vec<f64> = x.iter().zip(delta.iter()).map(|(a, b)| a + b).collect();
            p.space.clamp(&mut xt);
            let step: f64 = xt
                .iter()
                .zip(&x)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                .sqrt();
            p.residuals(&xt, &mut rt, &mut s);
            let ssr_t: f64 = rt.iter().map(|v| v * v).sum();
            if ssr_t.is_finite() && ssr_t < ssr {
                let rel = (ssr - ssr_t) / ssr.max(1e-300);
                x = xt;
                std::mem::swap(&mut r, &mut rt);
                ssr = ssr_t;
                lambda = (lambda / 3.0).max(1e-12);
                // One tiny decrease may be a step in a curved valley; stop after several.
                stalls = if rel < opts.cost_tolerance {
                    stalls + 1
                } else {
                    0
                };
                if stalls >= 4 {
                    termination = Termination::CostConverged;
                    break 'outer;
                }
                if step < opts.step_tolerance {
                    termination = Termination::StepConverged;
                    break 'outer;
                }
                break;
            }
            if step < opts.step_tolerance {
                termination = Termination::StepConverged;
                break 'outer;
            }
            lambda *= 4.0;
            if lambda > 1e12 {
                termination = Termination::DampingLimit;
                break 'outer;
            }
        }
    }
    LmResult {
        x,
        ssr,
        iterations: it,
        termination,
    }
}
