//! The calibration strategy: informed first guesses → global stage (differential evolution)
//! → least-squares polish from several distinct starts in parallel → uncertainty and profiles.

use crate::dataset::misfits;
use crate::global::{differential_evolution, evaluate_all, GlobalTuning};
use crate::interval::Interval;
use crate::lm::{levenberg_marquardt, LmOptions, LmResult, Termination};
use crate::problem::{fold_into_box, Problem, RunCounter};
use crate::sampling::{global_sample, informed_guess_budget, spread, GLOBAL_STAGE_ROWS};
use crate::space::{Coord, Param, Space};
use crate::uncertainty::{
    linearise_scaled, natural_interval, noise_correlation, profiles_scaled, variance_scale,
    Linearised, Profile,
};
use argmin::core::{Executor, State, TerminationReason, TerminationStatus};
use argmin::solver::neldermead::NelderMead;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;
use subfric_model::Model;
use subfric_reading::guess::first_guesses;
use subfric_reading::FitTest;

/// Local method used from each start.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Levenberg–Marquardt least squares.
    Lsq,
    /// Nelder–Mead simplex (argmin).
    NelderMead,
}

/// Options of a calibration.
#[derive(Clone, Debug)]
pub struct FitOptions {
    /// Local method.
    pub method: Method,
    /// Number of local runs from distinct starts.
    pub starts: usize,
    /// Seed of every random choice (results are deterministic for a seed).
    pub seed: u64,
    /// Budget of model runs for the global stage (0 skips it).
    pub global_evaluations: usize,
    /// Differential evolution's tunables (weight, crossover, population per coordinate).
    pub global: GlobalTuning,
    /// Compute profile intervals.
    pub profiles: bool,
    /// Start from the first guesses read off the curves as well as from the given model and
    /// starts (off for warm-started refits, whose starts are the answer already nearly).
    pub informed_guesses: bool,
    /// Compute the linearised statistics (standard errors, correlations, flat directions); off
    /// for fits that only need the optimum (profiles then are off too).
    pub statistics: bool,
    /// Least-squares settings.
    pub lm: LmOptions,
    /// The counter of the job this calibration is part of: every problem it creates counts its
    /// model runs there too, for the job's progress display. `None`: counted only in the
    /// report's `evaluations`.
    pub run_counter: Option<RunCounter>,
    /// Local runs done by earlier calibrations of the same tests and space with these same
    /// options, reused instead of run again (`None`: every run is done).
    pub local_memo: Option<LocalMemo>,
}

/// Local runs already done, by their start bit for bit: a local run is deterministic, so a
/// calibration that would run one again from the same start (a refit that ranks the same start
/// first) takes its result instead. Share it only between calibrations of the same tests, the
/// same space and the same method and least-squares options — the memo checks the tests (by
/// address), the method and the iteration limit, not the space.
#[derive(Clone, Debug, Default)]
pub struct LocalMemo(Arc<Mutex<HashMap<MemoKey, LocalRun>>>);

/// The tests' address and length, the method, the iteration limit and the start's bits.
type MemoKey = (usize, usize, Method, usize, Vec<u64>);

impl LocalMemo {
    /// An empty memo.
    pub fn new() -> LocalMemo {
        LocalMemo::default()
    }

    fn key(p: &Problem, x0: &[f64], opts: &FitOptions) -> MemoKey {
        (
            p.tests.as_ptr() as usize,
            p.tests.len(),
            opts.method,
            opts.lm.max_iterations,
            x0.iter().map(|v| v.to_bits()).collect(),
        )
    }

    /// The local run from `x0`: the memo's if it holds one, else run now and kept.
    fn run_or_recall(&self, p: &Problem, x0: &[f64], opts: &FitOptions) -> LocalRun {
        let key = Self::key(p, x0, opts);
        if let Some(known) = self.0.lock().ok().and_then(|m| m.get(&key).cloned()) {
            return known;
        }
        let run = local(p, x0, opts);
        if let Ok(mut memo) = self.0.lock() {
            memo.insert(key, run.clone());
        }
        run
    }
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            method: Method::Lsq,
            starts: 8,
            seed: 1,
            global_evaluations: 3000,
            global: GlobalTuning::default(),
            profiles: true,
            informed_guesses: true,
            statistics: true,
            lm: LmOptions::default(),
            run_counter: None,
            local_memo: None,
        }
    }
}

/// How far a calibration has got (for progress bars).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CalibrationStage {
    /// Global search running.
    Global,
    /// Local runs: (finished, total).
    Local(usize, usize),
    /// Profiles running.
    Profiles,
    /// Done.
    Done,
}

/// Why a calibration could not run.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// Nothing to fit.
    #[error("no test rows to fit")]
    NoData,
    /// No free parameter.
    #[error("no free parameter: free at least one of {0}")]
    NothingFree(String),
    /// The starting model is invalid.
    #[error("{0}")]
    Params(#[from] subfric_model::ParamError),
}

// The report types live in `report.rs`; they keep their paths here.
use crate::report::classify;
pub use crate::report::{Combination, FitReport, OptimizerReport, ParamReport, Status};

/// The outcome of one local run.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalRun {
    /// Final point (optimiser coordinates).
    pub x: Vec<f64>,
    /// Sum of squared residuals there.
    pub ssr: f64,
    /// Why it stopped.
    pub termination: Termination,
}

impl From<LmResult> for LocalRun {
    fn from(r: LmResult) -> LocalRun {
        LocalRun {
            x: r.x,
            ssr: r.ssr,
            termination: r.termination,
        }
    }
}

/// Two starts closer than this (Euclidean, transformed units) are one start: polishing both
/// would only find the same optimum twice.
const DISTINCT_STARTS: f64 = 0.05;

/// A local run reached the best optimum when its SSR is within this share of the best ...
const AT_BEST_RELATIVE: f64 = 1e-3;
/// ... or within this absolute amount (noise units: well below one row's worth of misfit).
const AT_BEST_ABSOLUTE: f64 = 1.0;

/// Nelder–Mead's first simplex: each vertex moves one coordinate by this share of its box ...
const NM_INITIAL_SHARE: f64 = 0.1;
/// ... but by at most this (transformed units; the boxes of log-scaled rates span up to 20).
const NM_INITIAL_MAX: f64 = 0.2;
/// Nelder–Mead stops when the standard deviation of the simplex's costs falls below this.
const NM_SD_TOLERANCE: f64 = 1e-10;
/// Nelder–Mead's iteration limit per coordinate.
const NM_ITERATIONS_PER_COORDINATE: u64 = 400;

fn distinct(a: &[f64], b: &[f64]) -> bool {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
        > DISTINCT_STARTS
}

fn local(p: &Problem, x0: &[f64], opts: &FitOptions) -> LocalRun {
    match opts.method {
        Method::Lsq => levenberg_marquardt(p, x0, None, &opts.lm).into(),
        Method::NelderMead => nelder_mead(p, x0),
    }
}

fn nelder_mead(p: &Problem, x0: &[f64]) -> LocalRun {
    let m = x0.len();
    let failed = |why: String| LocalRun {
        x: x0.to_vec(),
        ssr: p.ssr(x0),
        termination: Termination::Failed(why),
    };
    let mut simplex = vec![x0.to_vec()];
    for k in 0..m {
        let mut v = x0.to_vec();
        v[k] += (NM_INITIAL_SHARE * (p.space.hi[k] - p.space.lo[k])).min(NM_INITIAL_MAX);
        fold_into_box(&mut v, &p.space.lo, &p.space.hi);
        simplex.push(v);
    }
    let solver = match NelderMead::new(simplex).with_sd_tolerance(NM_SD_TOLERANCE) {
        Ok(s) => s,
        Err(e) => return failed(format!("invalid simplex: {e}")),
    };
    match Executor::new(p, solver)
        .configure(|s| s.max_iters(NM_ITERATIONS_PER_COORDINATE * m as u64))
        .run()
    {
        Ok(res) => {
            let st = res.state();
            let mut x = st.get_best_param().cloned().unwrap_or_else(|| x0.to_vec());
            fold_into_box(&mut x, &p.space.lo, &p.space.hi);
            let ssr = p.ssr(&x);
            let termination = match st.get_termination_status() {
                TerminationStatus::Terminated(TerminationReason::SolverConverged) => {
                    Termination::SimplexConverged
                }
                TerminationStatus::Terminated(TerminationReason::MaxItersReached) => {
                    Termination::MaxIterations
                }
                other => Termination::Failed(other.to_string()),
            };
            LocalRun {
                x,
                ssr,
                termination,
            }
        }
        Err(e) => failed(e.to_string()),
    }
}

/// Step 1: the given model, the given starts and the informed guesses read off the curves,
/// ranked by cost.
struct Guesses {
    /// Points, best first.
    ranked: Vec<Vec<f64>>,
    /// Their costs, in the same order.
    costs: Vec<f64>,
    /// How many were informed guesses (the given model and starts excluded).
    informed: usize,
}

/// Informed guesses carried over to each given start: the base parameters read off the curves
/// with the extension parameters of the start (an effect's size is not on the curves of the
/// base parameters, and a base bent to mimic an effect is no start for a model that has it).
const GUESSES_PER_START: usize = 4;

fn ranked_guesses(
    p: &Problem,
    tests: &[FitTest],
    base: &Model,
    starts: &[Model],
    informed: bool,
    budget: usize,
) -> Guesses {
    let mut points: Vec<Vec<f64>> = vec![p.space.point_of(base)];
    points.extend(starts.iter().map(|m| p.space.point_of(m)));
    let guesses: Vec<Model> = if informed {
        let valid: Vec<Model> = first_guesses(tests, base)
            .into_iter()
            .filter(|g| Model::new(g.params, g.ext).is_ok())
            .collect();
        // Within the global budget (each guess costs a model run).
        spread(valid, informed_guess_budget(budget))
    } else {
        Vec::new()
    };
    let guess_points: Vec<Vec<f64>> = guesses.iter().map(|g| p.space.point_of(g)).collect();
    let guess_cost = evaluate_all(p, &guess_points);
    let mut crossed = Vec::new();
    if !starts.is_empty() && !guesses.is_empty() {
        let mut order: Vec<usize> = (0..guesses.len()).collect();
        order.sort_by(|&a, &b| guess_cost[a].total_cmp(&guess_cost[b]));
        for &i in order.iter().take(GUESSES_PER_START) {
            for s in starts {
                crossed.push(p.space.point_of(&with_base_of(s, &guesses[i])));
            }
        }
    }
    let mut cost = evaluate_all(p, &points);
    cost.extend(guess_cost);
    cost.extend(evaluate_all(p, &crossed));
    points.extend(guess_points);
    points.extend(crossed);
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| cost[a].total_cmp(&cost[b]));
    Guesses {
        ranked: order.iter().map(|&i| points[i].clone()).collect(),
        costs: order.iter().map(|&i| cost[i]).collect(),
        informed: points.len() - 1 - starts.len(),
    }
}

/// The `n` first guesses read off the curves that fit `tests` best in `space` (its model's
/// extensions kept as they are), best first: computed once, they can start many fits of models
/// that share the base (see [`with_base_of`]). Their runs count into `run_counter` when given.
pub fn best_informed_guesses(
    tests: &[FitTest],
    space: &Space,
    n: usize,
    run_counter: Option<&RunCounter>,
) -> Vec<Model> {
    let p = Problem::new(tests, space.clone()).counting(run_counter);
    let guesses: Vec<Model> = first_guesses(tests, &space.base)
        .into_iter()
        .filter(|g| Model::new(g.params, g.ext).is_ok())
        .collect();
    let points: Vec<Vec<f64>> = guesses.iter().map(|g| space.point_of(g)).collect();
    let cost = evaluate_all(&p, &points);
    let mut order: Vec<usize> = (0..guesses.len()).collect();
    order.sort_by(|&a, &b| cost[a].total_cmp(&cost[b]));
    let mut out: Vec<(Vec<f64>, Model)> = Vec::new();
    for i in order {
        if out.len() >= n {
            break;
        }
        if cost[i] < f64::MAX && out.iter().all(|(x, _)| distinct(x, &points[i])) {
            out.push((points[i].clone(), guesses[i]));
        }
    }
    out.into_iter().map(|(_, g)| g).collect()
}

/// `start` with the five base parameters of `guess` (μ₀ following μ_s).
pub fn with_base_of(start: &Model, guess: &Model) -> Model {
    let mut m = *start;
    let (p, g) = (&mut m.params, &guess.params);
    (p.mu_s, p.mu_k, p.kappa, p.xi, p.u_tilde) = (g.mu_s, g.mu_k, g.kappa, g.xi, g.u_tilde);
    p.mu_0 = None;
    m
}

/// Step 2: the global stage's population (seeded with the guesses) followed by the guesses,
/// from which the starts are chosen.
struct Pool {
    /// Candidate points.
    points: Vec<Vec<f64>>,
    /// Their costs.
    costs: Vec<f64>,
    /// Generations of differential evolution.
    generations: usize,
    /// Model runs of differential evolution.
    evaluations: usize,
}

fn global_stage(p: &Problem, guesses: &Guesses, opts: &FitOptions) -> Pool {
    let mut pool = if opts.global_evaluations > 0 {
        let de_opts = opts.global.options(p.space.dim(), opts.global_evaluations);
        let de = differential_evolution(p, &guesses.ranked, &de_opts, opts.seed);
        Pool {
            points: de.members,
            costs: de.costs,
            generations: de.generations,
            evaluations: de.evaluations,
        }
    } else {
        Pool {
            points: Vec::new(),
            costs: Vec::new(),
            generations: 0,
            evaluations: 0,
        }
    };
    pool.points.extend(guesses.ranked.iter().cloned());
    pool.costs.extend(guesses.costs.iter().copied());
    pool
}

/// The `n` best points of the pool that are pairwise [`distinct`] (a stable sort: on equal
/// cost the population's members come before the guesses).
fn distinct_starts(pool: &Pool, n: usize) -> Vec<Vec<f64>> {
    let mut idx: Vec<usize> = (0..pool.points.len()).collect();
    idx.sort_by(|&a, &b| pool.costs[a].total_cmp(&pool.costs[b]));
    let mut starts: Vec<Vec<f64>> = Vec::new();
    for &i in &idx {
        if starts.len() >= n {
            break;
        }
        if starts.iter().all(|s| distinct(s, &pool.points[i])) {
            starts.push(pool.points[i].clone());
        }
    }
    starts
}

/// Step 3: a local run from every start, in parallel (results in start order).
fn local_runs(
    p: &Problem,
    starts: &[Vec<f64>],
    opts: &FitOptions,
    progress: &(dyn Fn(CalibrationStage) + Sync),
) -> Vec<LocalRun> {
    let total = starts.len();
    let done = AtomicUsize::new(0);
    progress(CalibrationStage::Local(0, total));
    starts
        .par_iter()
        .map(|x0| {
            let r = match &opts.local_memo {
                Some(memo) => memo.run_or_recall(p, x0, opts),
                None => local(p, x0, opts),
            };
            let k = done.fetch_add(1, Ordering::Relaxed) + 1;
            progress(CalibrationStage::Local(k, total));
            r
        })
        .collect()
}

/// Whether a run's SSR reached the best one.
fn at_best(ssr: f64, best: f64) -> bool {
    ssr <= best + (AT_BEST_RELATIVE * best).max(AT_BEST_ABSOLUTE)
}

/// Step 4: the best point with its linearised statistics and profiles.
struct Uncertainty {
    /// The optimum (re-polished if a profile found a better point).
    best: LocalRun,
    /// Standard errors, correlations, flat directions.
    lin: Linearised,
    /// Profiles per coordinate (empty when not requested).
    profiles: Vec<Profile>,
    /// Whether the optimum came from re-polishing a profile point.
    repolished: bool,
    /// Variance inflation for correlated residuals at the optimum.
    correlation: f64,
}

/// The variance scale of a fit at `x`: max(1, reduced χ²) times the residuals' correlation
/// factor; returns (s², factor).
fn scale_at(p: &Problem, x: &[f64], ssr: f64) -> (f64, f64) {
    let mut r = Vec::new();
    let mut scratch = Vec::new();
    p.residuals(x, &mut r, &mut scratch);
    let tau = noise_correlation(p.tests, &r);
    (variance_scale(ssr, p.rows(), x.len()) * tau, tau)
}

fn uncertainty(
    p: &Problem,
    best: LocalRun,
    opts: &FitOptions,
    progress: &(dyn Fn(CalibrationStage) + Sync),
) -> Uncertainty {
    if !opts.statistics {
        return Uncertainty {
            lin: Linearised::unknown(p.space.dim()),
            best,
            profiles: Vec::new(),
            repolished: false,
            correlation: 1.0,
        };
    }
    let (s2, correlation) = scale_at(p, &best.x, best.ssr);
    let lin = linearise_scaled(p, &best.x, s2);
    let mut u = Uncertainty {
        best,
        lin,
        profiles: Vec::new(),
        repolished: false,
        correlation,
    };
    if !opts.profiles {
        return u;
    }
    progress(CalibrationStage::Profiles);
    u.profiles = profiles_scaled(p, &u.best.x, u.best.ssr, s2, &u.lin.std_errors_x);
    let better = u
        .profiles
        .iter()
        .filter_map(|q| q.better.clone())
        .min_by(|a, b| a.1.total_cmp(&b.1));
    if let Some((xb, _)) = better {
        let r = levenberg_marquardt(p, &xb, None, &opts.lm);
        if r.ssr < u.best.ssr {
            u.best = r.into();
            u.repolished = true;
            let (s2, correlation) = scale_at(p, &u.best.x, u.best.ssr);
            u.correlation = correlation;
            u.lin = linearise_scaled(p, &u.best.x, s2);
            u.profiles = profiles_scaled(p, &u.best.x, u.best.ssr, s2, &u.lin.std_errors_x);
        }
    }
    u
}

/// Step 5a: the free parameters (value, standard error, interval, verdict), then the fixed.
fn parameter_reports(p: &Problem, u: &Uncertainty, model: &Model) -> Vec<ParamReport> {
    let natural = p.space.natural(&u.best.x);
    let mut out = Vec::new();
    for (k, &q) in p.space.free.iter().enumerate() {
        let value = natural[k];
        let se = u.lin.std_errors[k];
        let interval = if u.profiles.is_empty() {
            None
        } else {
            natural_interval(p, &u.profiles, k).map(|i| i.including(value))
        };
        out.push(ParamReport {
            name: q.key().into(),
            unit: q.unit().into(),
            value,
            std_error: se.is_finite().then_some(se),
            interval,
            status: interval.map_or(Status::Unprofiled, |i| classify(q, value, &i)),
            published: None,
            difference_percent: None,
        });
    }
    for q in Param::all() {
        if p.space.free.contains(&q) {
            continue;
        }
        if let Some(v) = q.get(model) {
            out.push(ParamReport {
                name: q.key().into(),
                unit: q.unit().into(),
                value: v,
                std_error: None,
                interval: None,
                status: Status::Fixed,
                published: None,
                difference_percent: None,
            });
        }
    }
    out
}

/// Step 5b: the combined chart's coordinates (μ_ss, κ + ξ/v, ψ) with their intervals.
fn combinations(p: &Problem, u: &Uncertainty) -> Vec<Combination> {
    let x = &u.best.x;
    p.space
        .coords
        .iter()
        .enumerate()
        .filter(|(_, c)| !matches!(c, Coord::Natural(_)))
        .map(|(k, c)| {
            let value = p.space.coord_value(k, x);
            let interval = u.profiles.get(k).map(|pr| {
                Interval {
                    lo: p.space.coord_value(k, &pr.lower.x),
                    hi: p.space.coord_value(k, &pr.upper.x),
                    lo_open: pr.lower.open,
                    hi_open: pr.upper.open,
                }
                .including(value)
            });
            Combination {
                name: match c {
                    Coord::SteadyRatio => format!("mu_ss at v = {:.4e} mm/s", p.space.v_ref),
                    Coord::DecayRate => {
                        format!("kappa + xi/v at v = {:.4e} mm/s [1/mm]", p.space.v_ref)
                    }
                    _ => "recovery share psi of the decay (0: all kappa, 1: mu_k = 0)".into(),
                },
                value,
                interval,
                determined: interval.is_some_and(|i| i.determines(value.abs())),
            }
        })
        .collect()
}

/// Step 5c: each coordinate's profile as (display value, ΔSSR/s²), sorted by value.
fn profile_traces(p: &Problem, profiles: &[Profile]) -> Vec<(String, Vec<(f64, f64)>)> {
    p.space
        .coords
        .iter()
        .enumerate()
        .zip(profiles)
        .map(|((k, c), pr)| {
            let mut pts: Vec<(f64, f64)> = pr
                .trace
                .iter()
                .map(|t| (p.space.coord_value(k, &t.x), t.delta))
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            (c.name(), pts)
        })
        .collect()
}

/// Calibrates the free parameters of `space` against `tests`.
///
/// ```
/// use subfric_fit::{calibrate, FitOptions, Param, Space};
/// use subfric_reading::FitTest;
/// use subfric_model::{simulate, Control, Model, Params, Protocol};
/// // A monotonic test from known parameters.
/// let truth = Model::base(Params::sample()).unwrap();
/// let time: Vec<f64> = (0..=300).map(|i| i as f64).collect();
/// let slip: Vec<f64> = time.iter().map(|t| 0.01 * t).collect();
/// let normal = vec![100.0; time.len()];
/// let proto = Protocol { control: Control::Slip, time: &time, imposed: &slip, normal: &normal, initial_slip: 0.0, initial: Default::default() };
/// let shear = simulate(&truth, &proto).unwrap().shear;
/// let test = FitTest::new("mono", Control::Slip, time, slip, shear, normal);
/// // Free only μ_s and ũ, starting away from the truth.
/// let mut start = truth;
/// start.params.mu_s = 0.7;
/// start.params.u_tilde = 50.0;
/// let space = Space::new(start, &[Param::MuS, Param::UTilde], &[]);
/// let opts = FitOptions { global_evaluations: 200, starts: 2, profiles: false, ..FitOptions::default() };
/// let report = calibrate(&[test], space, &opts, &|_| {}).unwrap();
/// assert!((report.model.params.mu_s - 0.45).abs() < 1e-3);
/// assert!((report.model.params.u_tilde - 15.0).abs() < 0.1);
/// ```
pub fn calibrate(
    tests: &[FitTest],
    space: Space,
    opts: &FitOptions,
    progress: &(dyn Fn(CalibrationStage) + Sync),
) -> Result<FitReport, FitError> {
    calibrate_from(tests, space, &[], opts, progress)
}

/// [`calibrate`] from given starting models as well as from the space's model and the informed
/// guesses: each start, and each start with the base parameters of the best informed guesses,
/// joins the points the global stage and the local runs start from. This is how a model with
/// an extension is fitted: the starts carry the extension's first guesses.
pub fn calibrate_from(
    tests: &[FitTest],
    space: Space,
    starts: &[Model],
    opts: &FitOptions,
    progress: &(dyn Fn(CalibrationStage) + Sync),
) -> Result<FitReport, FitError> {
    let t0 = Instant::now();
    if tests.iter().all(|t| t.is_empty()) {
        return Err(FitError::NoData);
    }
    if space.free.is_empty() {
        return Err(FitError::NothingFree(
            Param::BASE
                .iter()
                .map(|p| p.key())
                .collect::<Vec<_>>()
                .join(", "),
        ));
    }
    let base = space.base;
    Model::new(base.params, base.ext)?;
    let job_runs = opts.run_counter.as_ref();
    let p = Problem::new(tests, space).counting(job_runs);
    let m = p.space.dim();
    // A large problem explores on a spread share of its tests (see `sampling`).
    let sample = global_sample(tests, GLOBAL_STAGE_ROWS);
    let share = sample
        .as_deref()
        .map(|s| Problem::new(s, p.space.clone()).counting(job_runs));
    let explore = share.as_ref().unwrap_or(&p);

    // 1. Informed guesses, plus the given model.
    let guesses = ranked_guesses(
        explore,
        explore.tests,
        &base,
        starts,
        opts.informed_guesses,
        opts.global_evaluations,
    );

    // 2. Global stage, and distinct starts from its population and the guesses.
    progress(CalibrationStage::Global);
    let pool = global_stage(explore, &guesses, opts);
    let starts = distinct_starts(&pool, opts.starts.max(1));

    // 3. Local runs in parallel; the best one (the first of equals) goes on.
    let runs = local_runs(&p, &starts, opts, progress);
    let best = runs
        .iter()
        .min_by(|a, b| a.ssr.total_cmp(&b.ssr))
        .cloned()
        .expect("the pool holds at least the given model, so there is a start");
    let starts_at_best = runs.iter().filter(|r| at_best(r.ssr, best.ssr)).count();

    // 4. Uncertainty: linearised statistics and profiles (re-polished if they found better).
    let u = uncertainty(&p, best, opts, progress);

    // 5. The report.
    let model = p.model_at(&u.best.x);
    let rows = p.rows();
    let report = FitReport {
        model,
        parameters: parameter_reports(&p, &u, &model),
        correlation: u.lin.correlation.clone(),
        flat_directions: u.lin.flat_directions.clone(),
        ssr: u.best.ssr,
        rows,
        reduced_chi2: u.best.ssr / (rows.saturating_sub(m)).max(1) as f64,
        noise_correlation: u.correlation,
        tests: misfits(tests, &model),
        optimizer: OptimizerReport {
            method: opts.method,
            seed: opts.seed,
            starts: runs.len(),
            starts_at_best,
            start_ssr: runs.iter().map(|r| r.ssr).collect(),
            informed_guesses: guesses.informed,
            global_evaluations: pool.evaluations,
            global_generations: pool.generations,
            evaluations: p.evaluations() + share.as_ref().map_or(0, Problem::evaluations),
            termination: u.best.termination.clone(),
            repolished_from_profile: u.repolished,
            elapsed_s: t0.elapsed().as_secs_f64(),
        },
        combinations: combinations(&p, &u),
        profiles: profile_traces(&p, &u.profiles),
    };
    progress(CalibrationStage::Done);
    Ok(report)
}

/// Fills `published` and `difference_percent` from a reference model.
pub fn compare_with_published(report: &mut FitReport, published: &Model) {
    for pr in report.parameters.iter_mut() {
        if let Some(q) = Param::from_key(&pr.name) {
            if let Some(v) = q.get(published) {
                pr.published = Some(v);
                if v != 0.0 {
                    pr.difference_percent = Some(100.0 * (pr.value - v) / v);
                }
            }
        }
    }
}

/// The variance scale of a report (s² ≥ 1), the correlation factor included.
pub fn report_variance_scale(r: &FitReport) -> f64 {
    let m = r
        .parameters
        .iter()
        .filter(|p| p.status != Status::Fixed)
        .count();
    variance_scale(r.ssr, r.rows, m) * r.noise_correlation.max(1.0)
}
