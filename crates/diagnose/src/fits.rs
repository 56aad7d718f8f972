//! Fitting the base model with any set of candidate forms, from several starts, and predicting
//! held-out pieces after refitting without them.

use crate::candidates::Form;
use crate::folds::Fold;
use crate::score::HeldOut;
use rayon::prelude::*;
use serde::Serialize;
use subfric_fit::lm::{LmOptions, Termination};
use subfric_fit::{calibrate_from, FitOptions, LocalMemo, Param, RunCounter, Space};
use subfric_model::{Extensions, Model};
use subfric_reading::FitTest;

/// A model: the base plus some candidate forms (none: the base model).
#[derive(Clone, Debug, Default)]
pub struct Spec {
    /// The forms switched on, at most one per family.
    pub forms: Vec<Form>,
    /// A drift of the measurement (the non-physical alternative, [`subfric_fit::drift`]): each
    /// test's zero drift linear in time and a creep of the load cell shared by the set.
    pub drift: bool,
}

impl Spec {
    /// The base model.
    pub fn base() -> Spec {
        Spec::default()
    }

    /// The base model with one form.
    pub fn with(form: &Form) -> Spec {
        Spec {
            forms: vec![form.clone()],
            drift: false,
        }
    }

    /// This model with one more form.
    pub fn plus(&self, form: &Form) -> Spec {
        let mut s = self.clone();
        s.forms.push(form.clone());
        s
    }

    /// Extra parameters of the forms.
    pub fn extra_params(&self) -> Vec<Param> {
        self.forms.iter().flat_map(|f| f.params.clone()).collect()
    }

    /// Number of extra parameters (one drift slope per test counts as `tests` parameters).
    pub fn extra_count(&self, tests: usize) -> usize {
        self.extra_params().len() + if self.drift { tests } else { 0 }
    }

    /// Short description: the forms' names joined.
    pub fn describe(&self) -> String {
        if self.drift {
            return "base + measurement drift (zero drift, load-cell creep)".into();
        }
        if self.forms.is_empty() {
            return "base".into();
        }
        self.forms
            .iter()
            .map(|f| format!("{} ({})", f.effect, f.name))
            .collect::<Vec<_>>()
            .join(" + ")
    }
}

/// Extensions of `a` with those set in `b` switched on.
pub fn merge(a: &Extensions, b: &Extensions) -> Extensions {
    Extensions {
        terms: b.terms.or(a.terms),
    }
}

/// The optimiser's space of a spec: the base parameters `base_free` of `template` plus the
/// forms' parameters, the forms switched on at their neutral values.
pub fn space_of(template: &Model, base_free: &[Param], spec: &Spec, v_ref: f64) -> Space {
    let mut base = *template;
    let mut bounds = Vec::new();
    for f in &spec.forms {
        base.ext = merge(&base.ext, &f.template);
        for (p, v) in f.params.iter().zip(&f.neutral) {
            p.set(&mut base, *v);
        }
        bounds.extend(f.bounds.iter().copied());
    }
    let mut free = base_free.to_vec();
    free.extend(spec.extra_params());
    Space::with_rate(base, &free, &bounds, v_ref)
}

/// `from` with the extension parameters of `spec` set to the values `values` (one vector per
/// form, natural units); forms not listed keep what `from` has.
pub fn with_values(from: &Model, spec: &Spec, values: &[Vec<f64>]) -> Model {
    let mut m = *from;
    for (f, v) in spec.forms.iter().zip(values) {
        m.ext = merge(&m.ext, &f.template);
        for (p, x) in f.params.iter().zip(v) {
            p.set(&mut m, *x);
        }
    }
    m
}

/// How much work a fit of a spec may take. Every fit goes through the calibration engine of
/// `subfric fit` ([`subfric_fit::calibrate_from`]): ranked starts (the given models, and with
/// `informed` the first guesses read off the curves crossed with them), an optional global
/// stage, and least squares from the best distinct starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Effort {
    /// Model runs of the global stage (0: none).
    pub global_evaluations: usize,
    /// Local runs from distinct starts.
    pub local_runs: usize,
    /// Least-squares iterations of each local run.
    pub iterations: usize,
    /// Also start from the first guesses read off the curves (off for warm-started refits).
    pub informed: bool,
}

impl Effort {
    /// A warm-started refit: the best of the given starts, polished for `iterations`.
    pub fn refit(iterations: usize) -> Effort {
        Effort {
            global_evaluations: 0,
            local_runs: 1,
            iterations,
            informed: false,
        }
    }
}

/// How a fit ended.
#[derive(Clone, Debug, Serialize)]
pub struct FitResult {
    /// Best model found.
    pub model: Model,
    /// Its SSR (noise units).
    pub ssr: f64,
    /// Converged: the best local run stopped at a point no step could improve.
    pub converged: bool,
    /// Why the best run stopped.
    pub termination: Termination,
    /// Starts given.
    pub starts: usize,
}

/// Fits `space` to `tests` from `starts` (and the informed guesses when asked) with the
/// calibration engine, its model runs counted into `run_counter` (the diagnosis's); a fit that
/// cannot run is a failed result, not an error.
pub fn fit(
    tests: &[FitTest],
    space: &Space,
    starts: &[Model],
    effort: Effort,
    run_counter: &RunCounter,
) -> FitResult {
    let opts = FitOptions {
        starts: effort.local_runs.max(1),
        global_evaluations: effort.global_evaluations,
        profiles: false,
        statistics: false,
        informed_guesses: effort.informed,
        lm: LmOptions {
            max_iterations: effort.iterations,
            ..LmOptions::default()
        },
        run_counter: Some(run_counter.clone()),
        // The rerun from the best start below may rank the first run's start among its own:
        // that local run is then not done twice.
        local_memo: Some(LocalMemo::new()),
        ..FitOptions::default()
    };
    let failed = |why: String| FitResult {
        model: space.base,
        ssr: f64::INFINITY,
        converged: false,
        termination: Termination::Failed(why),
        starts: starts.len(),
    };
    let run = |starts: &[Model], opts: &FitOptions| match calibrate_from(
        tests,
        space.clone(),
        starts,
        opts,
        &|_| {},
    ) {
        Ok(r) if r.ssr.is_finite() => FitResult {
            model: r.model,
            ssr: r.ssr,
            converged: r.optimizer.termination.converged(),
            termination: r.optimizer.termination,
            starts: starts.len(),
        },
        Ok(_) => failed("no start could be simulated".into()),
        Err(e) => failed(e.to_string()),
    };
    let result = run(starts, &opts);
    // The engine ranks its starting points (the given starts and the space's own template) on
    // a sample of the rows of a large problem and runs as many as asked from the top: one run
    // may then start from the template and end worse than a given start fits all rows (a
    // polish that loses the screened optimum). A fit never ends worse than its best start:
    // that start is run as well.
    if opts.starts == 1 && !starts.is_empty() && result.ssr.is_finite() {
        let (best, best_ssr) = starts
            .iter()
            .map(|m| ssr_on(tests, m))
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("starts is not empty");
        if best_ssr < ssr_on(tests, &result.model) {
            let both = FitOptions {
                starts: 2,
                ..opts.clone()
            };
            let again = run(std::slice::from_ref(&starts[best]), &both);
            if again.ssr < result.ssr {
                return again;
            }
        }
    }
    result
}

/// SSR of `m` on `tests` in noise units, the set's drift of the measurement removed where it is
/// fitted.
fn ssr_on(tests: &[FitTest], m: &Model) -> f64 {
    let drift = tests.iter().any(|t| t.detrend).then_some(tests);
    residuals(tests, m, drift)
        .iter()
        .flatten()
        .map(|&v| crate::score::squared_or_failed(v))
        .sum()
}

/// Per-row residuals k √w (prediction − measurement) of every test (NaN where the model cannot
/// simulate), with the set's drift of the measurement, fitted on the rows that weigh in `train`,
/// removed when `drift` is set.
pub fn residuals(tests: &[FitTest], m: &Model, drift: Option<&[FitTest]>) -> HeldOut {
    let mut out: HeldOut = subfric_fit::dataset::residuals_in_noise_units(tests, m);
    if let Some(train) = drift {
        // The drift is learned where the training weighs, and applied everywhere.
        let mut slices: Vec<&mut [f64]> = out.iter_mut().map(|r| &mut r[..]).collect();
        subfric_fit::remove_drift(
            tests,
            &mut slices,
            |ti, i| train[ti].weight_of(i) > 0.0,
            |ti| 0..tests[ti].len(),
        );
    }
    out
}

/// Held-out residuals of a spec: for each fold, refit `fit_tests` on the rows it keeps (from
/// the best of `starts` on those rows) and predict the rows of `tests` it holds out
/// (`fit_tests` are `tests` with the weights the fits use). The refits' model runs count into
/// `run_counter`.
// Each argument is a different input of the folds' refits; bundling them would only move the
// list into a struct built at both call sites.
#[allow(clippy::too_many_arguments)]
pub fn cross_validate(
    fit_tests: &[FitTest],
    tests: &[FitTest],
    folds: &[Fold],
    space: &Space,
    starts: &[Model],
    iterations: usize,
    drift: bool,
    run_counter: &RunCounter,
) -> HeldOut {
    let effort = Effort::refit(iterations);
    let per_fold: Vec<HeldOut> = folds
        .par_iter()
        .map(|f| {
            let mut train = f.training(fit_tests);
            for t in train.iter_mut() {
                t.detrend = drift;
            }
            // The starts are ranked on the training rows by one run each; the best is refitted
            // (the effect switched off wins where the training rows cannot see it).
            let r = fit(&train, space, starts, effort, run_counter);
            let mut res = residuals(tests, &r.model, drift.then_some(&train[..]));
            for (rt, held) in res.iter_mut().zip(&f.held_rows) {
                for (v, h) in rt.iter_mut().zip(held) {
                    if !h {
                        *v = f64::NAN;
                    }
                }
            }
            res
        })
        .collect();
    let mut out: HeldOut = tests.iter().map(|t| vec![f64::NAN; t.len()]).collect();
    for res in per_fold {
        for (o, r) in out.iter_mut().zip(res) {
            for (a, b) in o.iter_mut().zip(r) {
                if !b.is_nan() {
                    *a = b;
                }
            }
        }
    }
    out
}
