//! # subfric-posterior
//!
//! Posterior sampling of the subloading-friction calibration (issue 23): what the least-squares
//! fit of `subfric-fit` leaves undetermined becomes visible as a distribution — the valley of κ
//! against ξ, the band of curves the data still allow — instead of a "not determined" verdict.
//!
//! - [`sample`]: the one entry point. An affine-invariant ensemble sampler (Goodman & Weare's
//!   stretch move, [`ensemble`]) started in a small ball around the least-squares optimum, in
//!   the optimiser's coordinates of [`subfric_fit::Space`], walkers moved in parallel,
//!   deterministic for a seed, within a budget of model runs, with a progress callback.
//! - The posterior ([`target`]): Gaussian likelihood of the noise-normalised residuals with the
//!   noise scale the fit uses, s² = max(1, reduced χ²), optionally inflated by the residuals'
//!   autocorrelation time as the profile intervals do ([`ResidualModel`]); priors in natural
//!   units ([`prior`], [`prior_file`]: uniform within the bounds on the fit's scale by default,
//!   i.e. log-uniform for parameters charted as logarithms), carried into the
//!   coordinates by the log-determinant of the chart's Jacobian.
//! - Convergence, reported and never assumed ([`convergence`]): τ per parameter, split R̂ over
//!   walker groups, effective sample size, and how many more steps a run that has not converged
//!   needs.
//! - Outputs as values ([`Posterior`]): summary per parameter (median, 95 % credible interval,
//!   mean, sd), correlations, the thinned chain (and [`Posterior::write_chain_csv`]),
//!   posterior predictive bands per test ([`predictive`]), and the figures ([`figures`]: corner
//!   plot, band overlays).
//!
//! The method and the file format are described in docs/posterior.md.

#![warn(missing_docs)]

pub mod convergence;
pub mod ensemble;
pub mod figures;
pub mod predictive;
pub mod prior;
pub mod prior_file;
pub mod summary;
pub mod target;

pub use convergence::{Convergence, Targets, Verdict};
pub use ensemble::{SamplerError, Stop};
pub use predictive::{BandOptions, PredictiveDraws, TestBand};
pub use prior::{Prior, PriorError, Priors};
pub use summary::{ParamSummary, Posterior};
pub use target::{NoiseScale, ResidualModel};

use ensemble::{run_ensemble, LogDensity, RunOptions};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::time::Instant;
use subfric_fit::uncertainty::coordinate_stats_scaled;
use subfric_fit::{Param, Problem, Space};
use subfric_model::Model;
use subfric_reading::FitTest;
use target::Target;

/// How a posterior is sampled.
#[derive(Clone, Debug, PartialEq)]
pub struct PosteriorOptions {
    /// Walkers (even, at least twice the free parameters); 0 chooses max(32, 4 × free
    /// parameters).
    pub walkers: usize,
    /// Budget of model runs (each walker move costs at most one).
    pub max_evals: usize,
    /// Seed of every random choice: the result is the same for the same seed.
    pub seed: u64,
    /// How the residuals' noise enters the likelihood.
    pub residuals: ResidualModel,
    /// What "converged" means.
    pub targets: Targets,
    /// The parameters whose convergence decides (e.g. those the fit determined); `None`: all
    /// free parameters.
    pub converge_on: Option<Vec<Param>>,
    /// Stop once converged (otherwise spend the budget).
    pub stop_when_converged: bool,
}

impl Default for PosteriorOptions {
    fn default() -> Self {
        PosteriorOptions {
            walkers: 0,
            max_evals: 300_000,
            seed: 1,
            residuals: ResidualModel::default(),
            targets: Targets::default(),
            converge_on: None,
            stop_when_converged: true,
        }
    }
}

impl PosteriorOptions {
    /// The walkers of a run with `dim` free parameters: [`PosteriorOptions::walkers`], or when
    /// that is 0, max(32, 4 × `dim`).
    pub fn walkers_for(&self, dim: usize) -> usize {
        match self.walkers {
            0 => MIN_WALKERS.max(4 * dim),
            w => w,
        }
    }

    /// The smallest budget of model runs that moves the ensemble of a run with `dim` free
    /// parameters once (one run per walker to start, one per walker and step): a front end can
    /// refuse a smaller `max_evals` before the fit rather than after it.
    pub fn smallest_budget(&self, dim: usize) -> usize {
        2 * self.walkers_for(dim)
    }
}

/// Why a posterior could not be sampled.
#[derive(Debug, thiserror::Error)]
pub enum PosteriorError {
    /// No test row to fit.
    #[error("no test rows to sample the posterior of")]
    NoData,
    /// No free parameter.
    #[error("no free parameter: nothing to sample")]
    NothingFree,
    /// A parameter to judge convergence on is not free.
    #[error("convergence judged on {key}, which is not free (expected some of: {free})")]
    NotFree {
        /// The parameter.
        key: String,
        /// The free parameters.
        free: String,
    },
    /// The priors do not fit this problem.
    #[error("{0}")]
    Prior(#[from] PriorError),
    /// The ensemble cannot run.
    #[error("{0}")]
    Sampler(#[from] SamplerError),
    /// The walkers cannot start around the optimum.
    #[error("the posterior is zero at the least-squares optimum, so the walkers cannot start around it: {0}")]
    Start(String),
}

/// Smallest number of walkers chosen automatically (16 per half of the ensemble).
const MIN_WALKERS: usize = 32;

/// The start ball: this many linearised standard errors across ...
const BALL_SE: f64 = 0.25;
/// ... or this share of the box where the standard error is infinite (a flat direction).
const BALL_BOX: f64 = 0.01;
/// Draws tried per walker before the ball is shrunk.
const BALL_TRIES: usize = 50;

/// Samples the posterior of the free parameters of `space` given `tests`, starting around
/// `optimum` (the least-squares fit, e.g. `FitReport::model`), with `priors` (use
/// `Priors::default()` for the default priors, uniform within the bounds on the fit's scale).
/// `progress(done, budget)` is called after every step with the model runs so far.
///
/// ```no_run
/// use subfric_posterior::{sample, PosteriorOptions, Priors};
/// # fn demo(tests: &[subfric_reading::FitTest], space: &subfric_fit::Space, fit: &subfric_model::Model) {
/// let post = sample(tests, space, fit, &Priors::default(), &PosteriorOptions::default(), &|_, _| {}).unwrap();
/// println!("{}", post.table());
/// # }
/// ```
pub fn sample(
    tests: &[FitTest],
    space: &Space,
    optimum: &Model,
    priors: &Priors,
    opts: &PosteriorOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Posterior, PosteriorError> {
    let t0 = Instant::now();
    if tests.iter().all(|t| t.counted_rows().is_empty()) {
        return Err(PosteriorError::NoData);
    }
    if space.free.is_empty() {
        return Err(PosteriorError::NothingFree);
    }
    let judged = judged_indices(space, opts.converge_on.as_deref())?;
    let x0 = space.point_of(optimum);
    // A default prior widened where the chart of combinations put the optimum beyond the
    // parameter's default bounds (an undetermined ξ at the wall of the recovery share).
    let resolved: Vec<prior::ResolvedPrior> = priors
        .resolve(space)?
        .into_iter()
        .zip(space.natural(&x0))
        .map(|(r, v)| r.holding(v))
        .collect();
    let problem = Problem::new(tests, space.clone());
    let noise = NoiseScale::at_optimum(&problem, &x0, opts.residuals);
    let target = Target::new(tests, space, resolved.clone(), &noise);
    if target.log_density(&x0) == f64::NEG_INFINITY {
        return Err(PosteriorError::Start(why_zero(
            &target, space, &resolved, &x0,
        )));
    }
    let se = coordinate_stats_scaled(&problem, &x0, noise.total()).std_errors;
    let walkers = opts.walkers_for(space.dim());
    let start = start_ball(&target, space, &x0, &se, walkers, opts.seed);
    let run_opts = RunOptions {
        seed: opts.seed,
        max_evals: opts.max_evals,
        targets: opts.targets,
        judged: Some(judged),
        stop_when_converged: opts.stop_when_converged,
    };
    let run = run_ensemble(&target, start, &run_opts, progress)?;
    Ok(summary::Assembly {
        run: &run,
        space,
        priors: resolved.iter().map(|r| r.describe()).collect(),
        noise,
        optimum: space.natural(&x0),
        model_runs: target.model_runs(),
        failed_runs: target.failed_runs(),
        elapsed_s: t0.elapsed().as_secs_f64(),
    }
    .posterior())
}

fn judged_indices(space: &Space, on: Option<&[Param]>) -> Result<Vec<usize>, PosteriorError> {
    let Some(on) = on else {
        return Ok((0..space.free.len()).collect());
    };
    on.iter()
        .map(|p| {
            space
                .free
                .iter()
                .position(|q| q == p)
                .ok_or_else(|| PosteriorError::NotFree {
                    key: p.key().into(),
                    free: space
                        .free
                        .iter()
                        .map(|q| q.key())
                        .collect::<Vec<_>>()
                        .join(", "),
                })
        })
        .collect()
}

/// Why the posterior is zero at `x`: the prior that excludes the optimum, or the model.
fn why_zero(target: &Target, space: &Space, priors: &[prior::ResolvedPrior], x: &[f64]) -> String {
    let natural = space.natural(x);
    let mu_s = space.model_at(x).params.mu_s;
    for ((p, r), v) in space.free.iter().zip(priors).zip(&natural) {
        if r.log_density(*v, mu_s) == f64::NEG_INFINITY {
            return format!(
                "{} = {v:.6e} lies outside its prior {}",
                p.key(),
                r.describe()
            );
        }
    }
    if target.log_likelihood(x) == f64::NEG_INFINITY {
        return "the model cannot be simulated there on every test".into();
    }
    "the chart of the parameters is degenerate there (a parameter on a hard limit)".into()
}

/// One start point per walker: the optimum plus a Gaussian ball of [`BALL_SE`] standard errors
/// (or [`BALL_BOX`] of the box along flat directions), redrawn until the posterior is positive
/// there, shrinking the ball if it keeps missing.
fn start_ball(
    target: &Target,
    space: &Space,
    x0: &[f64],
    se: &[f64],
    walkers: usize,
    seed: u64,
) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5EED_BA11);
    let widths: Vec<f64> = (0..x0.len())
        .map(|k| {
            let box_w = BALL_BOX * (space.hi[k] - space.lo[k]);
            if se[k].is_finite() && se[k] > 0.0 {
                (BALL_SE * se[k]).min(box_w.max(f64::MIN_POSITIVE))
            } else {
                box_w
            }
        })
        .collect();
    (0..walkers)
        .map(|_| {
            let mut scale = 1.0;
            loop {
                for _ in 0..BALL_TRIES {
                    let x: Vec<f64> = x0
                        .iter()
                        .zip(&widths)
                        .map(|(c, w)| c + scale * w * predictive::normal(&mut rng))
                        .collect();
                    if target.log_density(&x).is_finite() {
                        return x;
                    }
                }
                scale *= 0.5;
                if scale < 1e-6 {
                    // The optimum itself has a positive posterior (checked before).
                    return x0.to_vec();
                }
            }
        })
        .collect()
}
