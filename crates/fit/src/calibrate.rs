//! The calibration strategy: informed first guesses → global stage (differential evolution)
//! → least-squares polish from several distinct starts in parallel → uncertainty and profiles.

use crate::dataset::{misfits, FitTest, TestMisfit};
use crate::global::{differential_evolution, evaluate_all, DeOptions};
use crate::guess::first_guesses;
use crate::lm::{levenberg_marquardt, LmOptions};
use crate::problem::{fold_into_box, Problem};
use crate::space::{Coord, Param, Space};
use crate::uncertainty::{
    linearise, natural_interval, profiles, variance_scale, FlatDirection, Profile,
};
use argmin::core::{Executor, State};
use argmin::solver::neldermead::NelderMead;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::time::Instant;
use subfric_model::Model;

/// Local method used from each start.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Levenberg–Marquardt least squares.
    Lsq,
    /// Nelder–Mead simplex (argmin).
    NelderMead,
}

/// Options of a calibration.
#[derive(Clone, Copy, Debug)]
pub struct FitOptions {
    /// Local method.
    pub method: Method,
    /// Number of local runs from distinct starts.
    pub starts: usize,
    /// Seed of every random choice (results are deterministic for a seed).
    pub seed: u64,
    /// Budget of model runs for the global stage (0 skips it).
    pub global_evaluations: usize,
    /// Compute profile intervals.
    pub profiles: bool,
    /// Least-squares settings.
    pub lm: LmOptions,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            method: Method::Lsq,
            starts: 8,
            seed: 1,
            global_evaluations: 3000,
            profiles: true,
            lm: LmOptions::default(),
        }
    }
}

/// How far a calibration has got (for progress bars).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
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

/// Identifiability verdict of one parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Status {
    /// Held at its given value.
    Fixed,
    /// The 95 % profile interval is closed and within ±10 % of the value.
    Determined,
    /// Closed but wider than ±10 %.
    Weak,
    /// Only a lower bound: the data allow any larger value.
    LowerBoundOnly,
    /// Only an upper bound: the data allow any smaller value.
    UpperBoundOnly,
    /// Neither bound: the data do not constrain it.
    NotDetermined,
    /// No profile computed; standard error only.
    Unprofiled,
}

impl Status {
    /// Human-readable description.
    pub fn describe(self) -> &'static str {
        match self {
            Status::Fixed => "fixed",
            Status::Determined => "determined",
            Status::Weak => "weakly determined",
            Status::LowerBoundOnly => "not determined (lower bound only)",
            Status::UpperBoundOnly => "not determined (upper bound only)",
            Status::NotDetermined => "not determined",
            Status::Unprofiled => "not profiled",
        }
    }
}

/// Result for one parameter.
#[derive(Clone, Debug, Serialize)]
pub struct ParamReport {
    /// Key.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Fitted (or fixed) value.
    pub value: f64,
    /// Linearised standard error (None if fixed or not estimable).
    pub std_error: Option<f64>,
    /// 95 % profile interval.
    pub interval: Option<(f64, f64)>,
    /// Whether the interval ends are open (lower, upper).
    pub interval_open: Option<(bool, bool)>,
    /// Identifiability verdict.
    pub status: Status,
    /// Published value, when known.
    pub published: Option<f64>,
    /// (value − published)/published [%].
    pub difference_percent: Option<f64>,
}

/// A combination of parameters the optimiser works with, with its profile interval.
#[derive(Clone, Debug, Serialize)]
pub struct Combination {
    /// Description.
    pub name: String,
    /// Value at the optimum.
    pub value: f64,
    /// 95 % profile interval.
    pub interval: Option<(f64, f64)>,
    /// Whether the ends are open (lower, upper).
    pub interval_open: Option<(bool, bool)>,
    /// Closed and within ±10 %.
    pub determined: bool,
}

fn classify(q: Param, value: f64, lo: f64, hi: f64, lo_open: bool, hi_open: bool) -> Status {
    let half = 0.5 * (hi - lo);
    let scale = match q.scale() {
        crate::space::Scale::Linear => value.abs().max(0.01),
        _ => value.abs(),
    };
    if half <= 0.1 * scale {
        return Status::Determined;
    }
    match (lo_open, hi_open) {
        (false, false) => Status::Weak,
        (true, false) => Status::UpperBoundOnly,
        (false, true) => Status::LowerBoundOnly,
        (true, true) => Status::NotDetermined,
    }
}

/// What the optimiser did.
#[derive(Clone, Debug, Serialize)]
pub struct OptimizerReport {
    /// Local method.
    pub method: Method,
    /// Seed.
    pub seed: u64,
    /// Local runs.
    pub starts: usize,
    /// Local runs that reached the best SSR (within max(1, 0.1 %)).
    pub starts_at_best: usize,
    /// Final SSR of each local run, in start order.
    pub start_ssr: Vec<f64>,
    /// Informed first guesses read off the curves.
    pub informed_guesses: usize,
    /// Model runs of the global stage.
    pub global_evaluations: usize,
    /// Generations of differential evolution.
    pub global_generations: usize,
    /// All model runs.
    pub evaluations: usize,
    /// Termination of the best local run.
    pub termination: String,
    /// Whether profiling found a better optimum and the fit was re-polished from it.
    pub repolished_from_profile: bool,
    /// Wall time [s].
    pub elapsed_s: f64,
}

/// Everything a calibration found.
#[derive(Clone, Debug, Serialize)]
pub struct FitReport {
    /// The fitted model (parameters and extensions), loadable with `--params`.
    pub model: Model,
    /// Free then fixed parameters.
    pub parameters: Vec<ParamReport>,
    /// Correlation matrix of the free parameters (order of `parameters`).
    pub correlation: Vec<Vec<f64>>,
    /// Directions the data hardly constrain.
    pub flat_directions: Vec<FlatDirection>,
    /// Sum of squared noise-normalised residuals.
    pub ssr: f64,
    /// Rows fitted.
    pub rows: usize,
    /// SSR/(rows − free parameters): about 1 when the misfit is at the noise level.
    pub reduced_chi2: f64,
    /// Per-test misfit.
    pub tests: Vec<TestMisfit>,
    /// Optimiser report.
    pub optimizer: OptimizerReport,
    /// Identifiable combinations (when μ_k, κ, ξ are charted together) with their intervals.
    pub combinations: Vec<Combination>,
    /// Profiles (value, ΔSSR/s²) per optimiser coordinate.
    pub profiles: Vec<(String, Vec<(f64, f64)>)>,
}

impl FitReport {
    /// Parameter report by key.
    pub fn param(&self, key: &str) -> Option<&ParamReport> {
        self.parameters.iter().find(|p| p.name == key)
    }
}

fn distinct(a: &[f64], b: &[f64]) -> bool {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
        > 0.05
}

fn local(p: &Problem, x0: &[f64], opts: &FitOptions) -> (Vec<f64>, f64, String) {
    match opts.method {
        Method::Lsq => {
            let r = levenberg_marquardt(p, x0, None, &opts.lm);
            (r.x, r.ssr, format!("{:?}", r.termination))
        }
        Method::NelderMead => {
            let m = x0.len();
            let mut simplex = vec![x0.to_vec()];
            for k in 0..m {
                let mut v = x0.to_vec();
                v[k] += 0.1 * (p.space.hi[k] - p.space.lo[k]).min(2.0);
                fold_into_box(&mut v, &p.space.lo, &p.space.hi);
                simplex.push(v);
            }
            let solver = match NelderMead::new(simplex).with_sd_tolerance(1e-10) {
                Ok(s) => s,
                Err(_) => return (x0.to_vec(), p.ssr(x0), "invalid-simplex".into()),
            };
            match Executor::new(p, solver)
                .configure(|s| s.max_iters(400 * m as u64))
                .run()
            {
                Ok(res) => {
                    let st = res.state();
                    let mut x = st.get_best_param().cloned().unwrap_or_else(|| x0.to_vec());
                    fold_into_box(&mut x, &p.space.lo, &p.space.hi);
                    let ssr = p.ssr(&x);
                    (x, ssr, format!("{}", st.get_termination_status()))
                }
                Err(e) => (x0.to_vec(), p.ssr(x0), format!("failed: {e}")),
            }
        }
    }
}

/// Calibrates the free parameters of `space` against `tests`.
///
/// ```
/// use subfric_fit::{calibrate, FitOptions, FitTest, Param, Space};
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
    progress: &(dyn Fn(Stage) + Sync),
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
    let p = Problem::new(tests, space);
    let m = p.space.dim();

    // 1. Informed guesses, plus the given model.
    let mut guesses: Vec<Vec<f64>> = vec![p.space.point_of(&base)];
    let informed: Vec<Model> = first_guesses(tests, &base)
        .into_iter()
        .filter(|g| Model::new(g.params, g.ext).is_ok())
        .collect();
    guesses.extend(informed.iter().map(|g| p.space.point_of(g)));
    let gcost = evaluate_all(&p, &guesses);
    let mut order: Vec<usize> = (0..guesses.len()).collect();
    order.sort_by(|&a, &b| gcost[a].total_cmp(&gcost[b]));
    let ranked: Vec<Vec<f64>> = order.iter().map(|&i| guesses[i].clone()).collect();

    // 2. Global stage.
    progress(Stage::Global);
    let (mut pool, mut pool_cost, gen, gev) = if opts.global_evaluations > 0 {
        let de = differential_evolution(
            &p,
            &ranked,
            &DeOptions {
                population: (10 * m).clamp(20, 60),
                max_evaluations: opts.global_evaluations,
                f: 0.7,
                cr: 0.9,
                tolerance: 1e-6,
            },
            opts.seed,
        );
        (de.members, de.costs, de.generations, de.evaluations)
    } else {
        (Vec::new(), Vec::new(), 0, 0)
    };
    for &i in &order {
        pool.push(guesses[i].clone());
        pool_cost.push(gcost[i]);
    }
    let mut idx: Vec<usize> = (0..pool.len()).collect();
    idx.sort_by(|&a, &b| pool_cost[a].total_cmp(&pool_cost[b]));
    let mut starts: Vec<Vec<f64>> = Vec::new();
    for &i in &idx {
        if starts.len() >= opts.starts.max(1) {
            break;
        }
        if starts.iter().all(|s| distinct(s, &pool[i])) {
            starts.push(pool[i].clone());
        }
    }

    // 3. Local runs in parallel.
    let total = starts.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    progress(Stage::Local(0, total));
    let runs: Vec<(Vec<f64>, f64, String)> = starts
        .par_iter()
        .map(|x0| {
            let r = local(&p, x0, opts);
            let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress(Stage::Local(k, total));
            r
        })
        .collect();
    let best_i = (0..runs.len())
        .min_by(|&a, &b| runs[a].1.total_cmp(&runs[b].1))
        .unwrap_or(0);
    let (mut x, mut ssr, mut termination) = runs[best_i].clone();
    let tol = |best: f64| best + (1e-3 * best).max(1.0);
    let starts_at_best = runs.iter().filter(|r| r.1 <= tol(ssr)).count();

    // 4. Uncertainty.
    let mut lin = linearise(&p, &x, ssr);
    let mut prof: Vec<Profile> = Vec::new();
    let mut repolished = false;
    if opts.profiles {
        progress(Stage::Profiles);
        prof = profiles(&p, &x, ssr, &lin.std_errors_x);
        let better = prof
            .iter()
            .filter_map(|q| q.better.clone())
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((xb, _)) = better {
            let r = levenberg_marquardt(&p, &xb, None, &opts.lm);
            if r.ssr < ssr {
                x = r.x;
                ssr = r.ssr;
                termination = format!("{:?}", r.termination);
                repolished = true;
                lin = linearise(&p, &x, ssr);
                prof = profiles(&p, &x, ssr, &lin.std_errors_x);
            }
        }
    }
    let model = p.model_at(&x);
    let natural = p.space.natural(&x);
    let mut parameters = Vec::new();
    for (k, &q) in p.space.free.iter().enumerate() {
        let value = natural[k];
        let se = lin.std_errors[k];
        let (interval, open, status) = if prof.is_empty() {
            (None, None, Status::Unprofiled)
        } else {
            let (lo, hi, lo_open, hi_open) = natural_interval(&p, &prof, k);
            let (lo, hi) = (lo.min(value), hi.max(value));
            (
                Some((lo, hi)),
                Some((lo_open, hi_open)),
                classify(q, value, lo, hi, lo_open, hi_open),
            )
        };
        parameters.push(ParamReport {
            name: q.key().into(),
            unit: q.unit().into(),
            value,
            std_error: se.is_finite().then_some(se),
            interval,
            interval_open: open,
            status,
            published: None,
            difference_percent: None,
        });
    }
    for q in Param::ALL {
        if p.space.free.contains(&q) {
            continue;
        }
        if let Some(v) = q.get(&model) {
            parameters.push(ParamReport {
                name: q.key().into(),
                unit: q.unit().into(),
                value: v,
                std_error: None,
                interval: None,
                interval_open: None,
                status: Status::Fixed,
                published: None,
                difference_percent: None,
            });
        }
    }
    let combinations: Vec<Combination> = p
        .space
        .coords
        .iter()
        .enumerate()
        .filter(|(_, c)| !matches!(c, Coord::Natural(_)))
        .map(|(k, c)| {
            let value = p.space.coord_value(k, &x);
            let (lower, upper, open) = match prof.get(k) {
                Some(pr) => (
                    Some(p.space.coord_value(k, &pr.lower.x).min(value)),
                    Some(p.space.coord_value(k, &pr.upper.x).max(value)),
                    Some((pr.lower.open, pr.upper.open)),
                ),
                None => (None, None, None),
            };
            let determined = match (lower, upper, open) {
                (Some(a), Some(b), Some((false, false))) => 0.5 * (b - a) <= 0.1 * value.abs(),
                _ => false,
            };
            Combination {
                name: match c {
                    Coord::SteadyRatio => format!("mu_ss at v = {:.4e} mm/s", p.space.v_ref),
                    Coord::DecayRate => {
                        format!("kappa + xi/v at v = {:.4e} mm/s [1/mm]", p.space.v_ref)
                    }
                    _ => "recovery share psi of the decay (0: all kappa, 1: mu_k = 0)".into(),
                },
                value,
                interval: lower.zip(upper),
                interval_open: open,
                determined,
            }
        })
        .collect();
    let rows = p.rows();
    progress(Stage::Done);
    Ok(FitReport {
        model,
        parameters,
        correlation: lin.correlation,
        flat_directions: lin.flat_directions,
        ssr,
        rows,
        reduced_chi2: ssr / (rows.saturating_sub(m)).max(1) as f64,
        tests: misfits(tests, &model),
        optimizer: OptimizerReport {
            method: opts.method,
            seed: opts.seed,
            starts: runs.len(),
            starts_at_best,
            start_ssr: runs.iter().map(|r| r.1).collect(),
            informed_guesses: informed.len(),
            global_evaluations: gev,
            global_generations: gen,
            evaluations: p.evaluations(),
            termination,
            repolished_from_profile: repolished,
            elapsed_s: t0.elapsed().as_secs_f64(),
        },
        combinations,
        profiles: p
            .space
            .coords
            .iter()
            .enumerate()
            .zip(&prof)
            .map(|((k, c), pr)| {
                let mut pts: Vec<(f64, f64)> = pr
                    .trace
                    .iter()
                    .map(|t| (p.space.coord_value(k, &t.x), t.delta))
                    .collect();
                pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                (c.name(), pts)
            })
            .collect(),
    })
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

/// The variance scale of a report (s² ≥ 1).
pub fn report_variance_scale(r: &FitReport) -> f64 {
    let m = r
        .parameters
        .iter()
        .filter(|p| p.status != Status::Fixed)
        .count();
    variance_scale(r.ssr, r.rows, m)
}
