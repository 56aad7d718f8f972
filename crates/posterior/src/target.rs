//! The log posterior in the optimiser's coordinates: the Gaussian likelihood of the
//! noise-normalised residuals, the priors in natural units, and the log-determinant of the
//! chart's Jacobian that carries those priors into the coordinates.

use crate::ensemble::LogDensity;
use crate::prior::ResolvedPrior;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};
use std::cell::RefCell;
use std::sync::atomic::{AtomicUsize, Ordering};
use subfric_fit::dataset::residuals_into;
use subfric_fit::space::Scale;
use subfric_fit::uncertainty::{noise_correlation, variance_scale};
use subfric_fit::{Param, Problem, Space};
use subfric_reading::FitTest;

/// How the residuals' noise enters the likelihood.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ResidualModel {
    /// Independent rows: log L = −SSR / (2 s²) with s² = max(1, reduced χ²) at the optimum.
    Independent,
    /// Rows correlated in time, as the profile intervals take them: the variance is further
    /// inflated by the residuals' integrated autocorrelation time τ (rows), as if the fit had
    /// rows/τ independent rows: log L = −SSR / (2 s² τ). With independent residuals τ ≈ 1, so
    /// this costs nothing there.
    #[default]
    Autocorrelated,
}

/// The noise scale of the likelihood, estimated at the least-squares optimum.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct NoiseScale {
    /// SSR/(rows − free parameters) at the optimum.
    pub reduced_chi2: f64,
    /// s² = max(1, reduced χ²): a misfit above the noise widens the posterior accordingly.
    pub variance_scale: f64,
    /// τ of the residuals (1 for [`ResidualModel::Independent`]).
    pub correlation_time: f64,
    /// The residual model.
    pub model: ResidualModel,
}

impl NoiseScale {
    /// The variance the SSR is divided by: s² τ.
    pub fn total(&self) -> f64 {
        self.variance_scale * self.correlation_time
    }

    /// Estimates the scale at `x` (the optimum) of `problem`.
    pub fn at_optimum(problem: &Problem, x: &[f64], model: ResidualModel) -> NoiseScale {
        let mut r = Vec::new();
        let mut scratch = Vec::new();
        problem.residuals(x, &mut r, &mut scratch);
        let ssr: f64 = r.iter().map(|v| v * v).sum();
        let m = x.len();
        let rows = problem.rows();
        NoiseScale {
            reduced_chi2: ssr / rows.saturating_sub(m).max(1) as f64,
            variance_scale: variance_scale(ssr, rows, m),
            correlation_time: match model {
                ResidualModel::Independent => 1.0,
                ResidualModel::Autocorrelated => noise_correlation(problem.tests, &r),
            },
            model,
        }
    }
}

thread_local! {
    /// Residual and simulation buffers of each worker thread.
    static BUFFERS: RefCell<(Vec<f64>, Vec<f64>)> = const { RefCell::new((Vec::new(), Vec::new())) };
}

/// Relative step of the chart's Jacobian (central differences: error of order step², and the
/// chart is exact arithmetic).
const JACOBIAN_STEP: f64 = 1e-6;

/// The log posterior of a fit problem in its optimiser coordinates.
pub struct Target<'a> {
    tests: &'a [FitTest],
    space: &'a Space,
    priors: Vec<ResolvedPrior>,
    /// 1 / (2 s² τ).
    half_precision: f64,
    /// Whether the likelihood counts (off: the prior alone, for tests of the Jacobian).
    with_likelihood: bool,
    model_runs: AtomicUsize,
    failed_runs: AtomicUsize,
}

impl<'a> Target<'a> {
    /// The posterior of `space` given `tests`, the resolved priors (order of `space.free`) and
    /// the noise scale.
    pub fn new(
        tests: &'a [FitTest],
        space: &'a Space,
        priors: Vec<ResolvedPrior>,
        noise: &NoiseScale,
    ) -> Target<'a> {
        Target {
            tests,
            space,
            priors,
            half_precision: 0.5 / noise.total(),
            with_likelihood: true,
            model_runs: AtomicUsize::new(0),
            failed_runs: AtomicUsize::new(0),
        }
    }

    /// The prior alone, carried into the coordinates (the likelihood left out).
    pub fn prior_only(space: &'a Space, priors: Vec<ResolvedPrior>) -> Target<'a> {
        Target {
            tests: &[],
            space,
            priors,
            half_precision: 0.0,
            with_likelihood: false,
            model_runs: AtomicUsize::new(0),
            failed_runs: AtomicUsize::new(0),
        }
    }

    /// Model runs so far (proposals outside the box or the priors' support cost none).
    pub fn model_runs(&self) -> usize {
        self.model_runs.load(Ordering::Relaxed)
    }

    /// Model runs that failed (counted as −∞).
    pub fn failed_runs(&self) -> usize {
        self.failed_runs.load(Ordering::Relaxed)
    }

    /// Log prior density of the natural parameters at `x` plus log |det ∂natural/∂x|; −∞
    /// outside the box or the priors' support.
    pub fn log_prior(&self, x: &[f64]) -> f64 {
        let s = self.space;
        if x.iter()
            .zip(s.lo.iter().zip(&s.hi))
            .any(|(v, (lo, hi))| !(v >= lo && v <= hi))
        {
            return f64::NEG_INFINITY;
        }
        let natural = s.natural(x);
        let mu_s = s.model_at(x).params.mu_s;
        let mut lp = 0.0;
        for (prior, v) in self.priors.iter().zip(&natural) {
            lp += prior.log_density(*v, mu_s);
            if lp == f64::NEG_INFINITY {
                return lp;
            }
        }
        let lj = log_abs_det_jacobian(s, x);
        if lp.is_finite() && lj.is_finite() {
            lp + lj
        } else {
            f64::NEG_INFINITY
        }
    }

    /// Log likelihood at `x`: −SSR/(2 s² τ); −∞ when a test cannot be simulated.
    pub fn log_likelihood(&self, x: &[f64]) -> f64 {
        if !self.with_likelihood {
            return 0.0;
        }
        self.model_runs.fetch_add(1, Ordering::Relaxed);
        let model = self.space.model_at(x);
        let ssr = BUFFERS.with(|b| {
            let (out, scratch) = &mut *b.borrow_mut();
            let failed = residuals_into(self.tests, &model, out, scratch);
            if failed > 0 {
                f64::NAN
            } else {
                out.iter().map(|v| v * v).sum::<f64>()
            }
        });
        if ssr.is_finite() {
            -ssr * self.half_precision
        } else {
            self.failed_runs.fetch_add(1, Ordering::Relaxed);
            f64::NEG_INFINITY
        }
    }
}

impl LogDensity for Target<'_> {
    fn dim(&self) -> usize {
        self.space.dim()
    }

    fn log_density(&self, x: &[f64]) -> f64 {
        let lp = self.log_prior(x);
        if lp == f64::NEG_INFINITY {
            return lp;
        }
        lp + self.log_likelihood(x)
    }

    fn quantity_names(&self) -> Vec<String> {
        self.space
            .free
            .iter()
            .map(|p| p.key().to_string())
            .collect()
    }

    /// The natural parameters, those fitted on a logarithmic scale as their logarithm (where
    /// τ and R̂ are measured: a parameter spread over decades is judged on its log).
    fn quantities(&self, x: &[f64]) -> Vec<f64> {
        self.space
            .natural(x)
            .into_iter()
            .zip(&self.space.free)
            .map(|(v, p)| if is_log(*p) { v.ln() } else { v })
            .collect()
    }
}

/// Whether `p`'s convergence is judged on its logarithm.
pub fn is_log(p: Param) -> bool {
    p.scale() == Scale::Log
}

/// log |det ∂natural/∂x| of the chart at `x`, by central differences.
pub fn log_abs_det_jacobian(space: &Space, x: &[f64]) -> f64 {
    let m = x.len();
    let mut j = DMatrix::zeros(m, m);
    let mut y = x.to_vec();
    for k in 0..m {
        let h = JACOBIAN_STEP * x[k].abs().max(1.0);
        y[k] = x[k] + h;
        let up = space.natural(&y);
        y[k] = x[k] - h;
        let down = space.natural(&y);
        y[k] = x[k];
        for i in 0..m {
            j[(i, k)] = (up[i] - down[i]) / (2.0 * h);
        }
    }
    let det = j.determinant().abs();
    if det > 0.0 && det.is_finite() {
        det.ln()
    } else {
        f64::NEG_INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfric_model::{Model, Params};

    #[test]
    fn the_jacobian_of_logarithmic_coordinates_is_the_product_of_the_values() {
        let m = Model::base(Params::sample()).unwrap();
        let space = Space::new(
            m,
            &[
                Param::Kappa,
                Param::UTilde,
                Param::from_key("rate.a").unwrap(),
            ],
            &[],
        );
        let x = space.point_of(&m);
        // κ and ũ are charted as logarithms (d value/dx = value), rate.a linearly.
        let want = x[0] + x[1];
        let got = log_abs_det_jacobian(&space, &x);
        assert!((got - want).abs() < 1e-8, "{got} vs {want}");
    }

    #[test]
    fn the_jacobian_of_the_combined_chart_matches_its_closed_form() {
        // (μ_s, logit m, ln λ, logit ψ) → (μ_s, μ_k, κ, ξ) with m = μ_ss/μ_s, φ = ψ m,
        // κ = (1 − φ) λ, ξ = φ λ v, μ_k = μ_s m (1 − ψ)/(1 − φ). Checked against a
        // Jacobian worked out by hand in the (m, λ, ψ) variables.
        let m0 = Model::base(Params::sample()).unwrap();
        let v = 0.01;
        let space = Space::with_rate(
            m0,
            &[Param::MuS, Param::MuK, Param::Kappa, Param::Xi],
            &[],
            v,
        );
        let x = space.point_of(&m0);
        let got = log_abs_det_jacobian(&space, &x);
        let idx = |c| space.coords.iter().position(|d| *d == c).unwrap();
        use subfric_fit::Coord;
        let sig = |t: f64| 1.0 / (1.0 + (-t).exp());
        let (mr, lam, psi) = (
            sig(x[idx(Coord::SteadyRatio)]),
            x[idx(Coord::DecayRate)].exp(),
            sig(x[idx(Coord::RecoveryShare)]),
        );
        let mu_s = x[idx(Coord::Natural(Param::MuS))].exp();
        let phi = psi * mr;
        // Partial derivatives with respect to (m, λ, ψ).
        let dk = [-psi * lam, 1.0 - phi, -mr * lam];
        let dxi = [psi * lam * v, phi * v, mr * lam * v];
        let g = |mr: f64, psi: f64| mu_s * mr * (1.0 - psi) / (1.0 - psi * mr);
        let e = 1e-7;
        let dmk = [
            (g(mr + e, psi) - g(mr - e, psi)) / (2.0 * e),
            0.0,
            (g(mr, psi + e) - g(mr, psi - e)) / (2.0 * e),
        ];
        let a = DMatrix::from_row_slice(
            3,
            3,
            &[
                dmk[0], dmk[1], dmk[2], dk[0], dk[1], dk[2], dxi[0], dxi[1], dxi[2],
            ],
        );
        // Chain rule to the coordinates: dm/dx = m(1−m), dλ/dx = λ, dψ/dx = ψ(1−ψ); μ_s = e^x.
        let want = a.determinant().abs().ln()
            + (mr * (1.0 - mr)).ln()
            + lam.ln()
            + (psi * (1.0 - psi)).ln()
            + mu_s.ln();
        assert!((got - want).abs() < 1e-6, "{got} vs {want}");
    }
}
