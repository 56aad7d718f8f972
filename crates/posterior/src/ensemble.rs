//! The ensemble sampler: Goodman & Weare's affine-invariant stretch move (as emcee), run by the
//! `hammer-and-sample` crate, with the budget, the progress and the convergence checks of this
//! crate around it.
//!
//! # Why hammer-and-sample
//!
//! Issue 23 asks for a maintained crate if one does this well. Three were looked at: `emcee`
//! (a port of Python's emcee; its latest release, 1.0.0-alpha.2, is an alpha on rand 0.3, with
//! no parallel execution), `ganesh` (maintained, but a whole minimisation and sampling
//! framework whose current release needs Rust 1.83) and `hammer-and-sample` (maintained, small:
//! one file, the stretch move exactly as Goodman & Weare and emcee define it — z drawn from
//! g(z) ∝ 1/√z on [1/a, a], acceptance factor z^(d−1) — one seeded generator per walker, and a
//! rayon execution that moves the first half of the ensemble against the second, then the
//! second against the first). That half-against-half update is what makes the stretch move
//! parallel: the walkers of one half only read the other half, so they move at once, and the
//! result does not depend on the order the threads finish in (each walker draws from its own
//! generator). What the crate does not do — a budget of model runs, progress, convergence
//! checks that stop the run, located errors instead of its `assert!`s on the walker count — is
//! done here, through its `Schedule` hook, and is tested on known targets
//! (tests/known_targets.rs).
//!
//! Its current release (0.6) builds on rand 0.10 (Rust 1.85), which the workspace already
//! compiles for proptest's tests; this crate's own draws use the same rand 0.10 and rand_chacha
//! 0.10.

use crate::convergence::{judge, Convergence, Targets};
use hammer_and_sample::{sample, Model, Parallel, Schedule, Stretch};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use std::collections::HashMap;
use std::ops::ControlFlow;
use std::sync::Mutex;

/// A target density, in the sampler's coordinates.
pub trait LogDensity: Sync {
    /// Number of coordinates.
    fn dim(&self) -> usize;

    /// Log density at `x` up to a constant; −∞ outside the support (NaN is taken as −∞).
    fn log_density(&self, x: &[f64]) -> f64;

    /// Names of the quantities that are recorded for every sample and whose convergence is
    /// judged (by default the coordinates themselves, `x0`, `x1`, ...).
    fn quantity_names(&self) -> Vec<String> {
        (0..self.dim()).map(|k| format!("x{k}")).collect()
    }

    /// The recorded quantities at `x` (by default the coordinates).
    fn quantities(&self, x: &[f64]) -> Vec<f64> {
        x.to_vec()
    }
}

/// How a run goes and when it stops.
#[derive(Clone, Debug, PartialEq)]
pub struct RunOptions {
    /// Seed of every walker's generator (the run is deterministic for a seed).
    pub seed: u64,
    /// Budget of density evaluations (one per walker to start, then one per walker and step).
    pub max_evals: usize,
    /// What "converged" means.
    pub targets: Targets,
    /// Indices of the quantities judged for convergence (`None`: all).
    pub judged: Option<Vec<usize>>,
    /// Stop as soon as the run has converged (checked every few steps); otherwise spend the
    /// whole budget.
    pub stop_when_converged: bool,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            seed: 1,
            max_evals: 200_000,
            targets: Targets::default(),
            judged: None,
            stop_when_converged: true,
        }
    }
}

/// Why a run stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Stop {
    /// Every judged quantity met the targets.
    Converged,
    /// The budget of evaluations was spent.
    Budget,
}

/// Why a run cannot start.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SamplerError {
    /// The stretch move needs two halves of equal size.
    #[error("{walkers} walkers (expected an even number: the ensemble moves in two halves)")]
    OddWalkers {
        /// Walkers given.
        walkers: usize,
    },
    /// Fewer than twice as many walkers as coordinates: the ensemble would span a subspace.
    #[error("{walkers} walkers for {dim} coordinates (expected at least {} walkers)", 2 * dim)]
    TooFewWalkers {
        /// Walkers given.
        walkers: usize,
        /// Coordinates.
        dim: usize,
    },
    /// A start point of the wrong length or not finite.
    #[error("start point of walker {walker} is {problem}")]
    BadStart {
        /// Walker.
        walker: usize,
        /// What is wrong with it.
        problem: String,
    },
    /// Not even one step fits in the budget.
    #[error("a budget of {max_evals} model runs cannot move {walkers} walkers even once (expected at least {})", 2 * walkers)]
    BudgetTooSmall {
        /// Budget given.
        max_evals: usize,
        /// Walkers.
        walkers: usize,
    },
}

/// The samples of a run and what is known about them.
#[derive(Clone, Debug)]
pub struct Run {
    /// Walkers.
    pub walkers: usize,
    /// Coordinates per sample.
    pub dim: usize,
    /// Steps run.
    pub steps: usize,
    /// Coordinates of every sample, `[step][walker][coordinate]` flattened.
    pub coords: Vec<f64>,
    /// Recorded quantities per sample.
    pub quantity_names: Vec<String>,
    /// Quantities of every sample, `[step][walker][quantity]` flattened.
    pub quantities: Vec<f64>,
    /// Log density of every sample (as [`LogDensity::log_density`] gave it when the sample was
    /// proposed; −∞ never appears, a sample is always a state the walk accepted),
    /// `[step][walker]` flattened.
    pub log_density: Vec<f64>,
    /// Convergence over the whole run (burn-in included in `convergence.burn_in`).
    pub convergence: Convergence,
    /// Moves accepted (of steps × walkers proposed).
    pub accepted: usize,
    /// Density evaluations.
    pub evaluations: usize,
    /// Why the run stopped.
    pub stopped: Stop,
}

impl Run {
    /// Share of proposed moves that were accepted.
    pub fn acceptance(&self) -> f64 {
        self.accepted as f64 / (self.steps * self.walkers).max(1) as f64
    }

    /// Quantity `q` of walker `w` at every step from `from` on.
    pub fn series(&self, q: usize, w: usize, from: usize) -> Vec<f64> {
        let nq = self.quantity_names.len();
        (from..self.steps)
            .map(|s| self.quantities[(s * self.walkers + w) * nq + q])
            .collect()
    }

    /// Coordinates of walker `w` at step `s`.
    pub fn coords_at(&self, s: usize, w: usize) -> &[f64] {
        let i = (s * self.walkers + w) * self.dim;
        &self.coords[i..i + self.dim]
    }

    /// Log density of walker `w` at step `s`.
    pub fn log_density_at(&self, s: usize, w: usize) -> f64 {
        self.log_density[s * self.walkers + w]
    }

    /// Quantities of walker `w` at step `s`.
    pub fn quantities_at(&self, s: usize, w: usize) -> &[f64] {
        let nq = self.quantity_names.len();
        let i = (s * self.walkers + w) * nq;
        &self.quantities[i..i + nq]
    }
}

/// Fewest steps before the first convergence check, and least gap between checks.
const FIRST_CHECK: usize = 50;

/// Checks are spaced by this share of the steps run so far (so that their cost, which grows
/// with the chain, stays a small share of the run).
const CHECK_SHARE: f64 = 0.1;

/// Runs the ensemble from `start` (one point per walker) until it converges or the budget is
/// spent, calling `progress(evaluations so far, budget)` after every step.
pub fn run_ensemble<D: LogDensity>(
    density: &D,
    start: Vec<Vec<f64>>,
    opts: &RunOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Run, SamplerError> {
    let walkers = start.len();
    let dim = density.dim();
    if !walkers.is_multiple_of(2) {
        return Err(SamplerError::OddWalkers { walkers });
    }
    if walkers < 2 * dim || walkers == 0 {
        return Err(SamplerError::TooFewWalkers { walkers, dim });
    }
    for (w, x) in start.iter().enumerate() {
        if x.len() != dim {
            return Err(SamplerError::BadStart {
                walker: w,
                problem: format!("of length {} (expected {dim})", x.len()),
            });
        }
        if x.iter().any(|v| !v.is_finite()) {
            return Err(SamplerError::BadStart {
                walker: w,
                problem: "not finite".into(),
            });
        }
    }
    let max_steps = (opts.max_evals / walkers).saturating_sub(1);
    if max_steps == 0 {
        return Err(SamplerError::BudgetTooSmall {
            max_evals: opts.max_evals,
            walkers,
        });
    }
    let names = density.quantity_names();
    let judged: Vec<bool> = (0..names.len())
        .map(|q| opts.judged.as_ref().is_none_or(|j| j.contains(&q)))
        .collect();
    let seen = Mutex::new(HashMap::new());
    let mut monitor = Monitor {
        density,
        seen: &seen,
        densities: Vec::new(),
        walkers,
        names: &names,
        judged: &judged,
        opts,
        max_steps,
        progress,
        record: Vec::new(),
        steps: 0,
        next_check: FIRST_CHECK,
        stopped: Stop::Budget,
    };
    let model = Adapter {
        density,
        seen: &seen,
    };
    let seeded = start.into_iter().enumerate().map(|(w, x)| {
        let seed = opts
            .seed
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add(w as u64);
        (x, ChaCha8Rng::seed_from_u64(seed))
    });
    let (chain, accepted) = sample(&model, &Stretch::default(), seeded, &mut monitor, Parallel);
    monitor.catch_up(&chain);
    let steps = monitor.steps;
    let convergence = monitor.judge();
    let stopped = monitor.stopped;
    let record = monitor.record;
    let log_density = monitor.densities;
    Ok(Run {
        walkers,
        dim,
        steps,
        coords: chain.into_iter().flatten().collect(),
        quantity_names: names,
        quantities: record,
        log_density,
        convergence,
        accepted,
        evaluations: walkers * (steps + 1),
        stopped,
    })
}

/// The density as hammer-and-sample sees it (NaN folded into −∞). The crate keeps each
/// walker's log density to itself, so every value is also noted in `seen` by the state's bits,
/// for [`Monitor`] to record beside the sample (the posterior's `lp`, ArviZ's sample
/// statistics) without running the model again.
struct Adapter<'a, D> {
    density: &'a D,
    seen: &'a Seen,
}

/// Log densities of the states proposed since the last step was recorded, by their bits.
type Seen = Mutex<HashMap<Vec<u64>, f64>>;

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

impl<D: LogDensity> Model for Adapter<'_, D> {
    type Params = Vec<f64>;

    fn log_prob(&self, state: &Vec<f64>) -> f64 {
        let v = self.density.log_density(state);
        let v = if v.is_nan() { f64::NEG_INFINITY } else { v };
        self.seen
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .insert(bits(state), v);
        v
    }
}

/// Records the quantities of every new step, reports progress, and stops the run.
struct Monitor<'a, D> {
    density: &'a D,
    /// What the adapter noted since the last step was recorded.
    seen: &'a Seen,
    /// Log density of every recorded sample, `[step][walker]`.
    densities: Vec<f64>,
    walkers: usize,
    names: &'a [String],
    judged: &'a [bool],
    opts: &'a RunOptions,
    max_steps: usize,
    progress: &'a (dyn Fn(usize, usize) + Sync),
    record: Vec<f64>,
    steps: usize,
    next_check: usize,
    stopped: Stop,
}

impl<D: LogDensity> Monitor<'_, D> {
    /// Records the steps of `chain` not yet recorded.
    fn catch_up(&mut self, chain: &[Vec<f64>]) {
        let done = chain.len() / self.walkers;
        if done == self.steps {
            // Nothing new (the first call, before any step): the starts' densities stay noted.
            return;
        }
        let mut seen = self.seen.lock().unwrap_or_else(|p| p.into_inner());
        for x in &chain[self.steps * self.walkers..done * self.walkers] {
            self.record.extend(self.density.quantities(x));
            // A state was either proposed in this step (noted) or is the walker's state of the
            // step before (a rejected move), whose density is already recorded.
            let before = self.densities.len().checked_sub(self.walkers);
            let lp = seen
                .get(&bits(x))
                .copied()
                .or_else(|| before.map(|b| self.densities[b]))
                .unwrap_or(f64::NAN);
            self.densities.push(lp);
        }
        seen.clear();
        self.steps = done;
    }

    /// Convergence of the steps recorded so far.
    fn judge(&self) -> Convergence {
        let nq = self.names.len();
        let series: Vec<Vec<Vec<f64>>> = (0..nq)
            .map(|q| {
                (0..self.walkers)
                    .map(|w| {
                        (0..self.steps)
                            .map(|s| self.record[(s * self.walkers + w) * nq + q])
                            .collect()
                    })
                    .collect()
            })
            .collect();
        judge(self.names, &series, self.judged, &self.opts.targets)
    }
}

impl<D: LogDensity> Schedule<Vec<f64>> for &mut Monitor<'_, D> {
    fn next_step(&mut self, chain: &[Vec<f64>]) -> ControlFlow<()> {
        self.catch_up(chain);
        (self.progress)(
            self.walkers * (self.steps + 1),
            self.walkers * (self.max_steps + 1),
        );
        if self.opts.stop_when_converged && self.steps >= self.next_check {
            self.next_check =
                self.steps + FIRST_CHECK.max((CHECK_SHARE * self.steps as f64) as usize);
            if self.judge().converged() {
                self.stopped = Stop::Converged;
                return ControlFlow::Break(());
            }
        }
        if self.steps >= self.max_steps {
            self.stopped = Stop::Budget;
            return ControlFlow::Break(());
        }
        ControlFlow::Continue(())
    }

    fn iterations(&self, _walkers: usize) -> Option<usize> {
        Some(self.max_steps)
    }
}
