//! The fitted tests of a diagnosis and everything derived once from them: pieces, folds,
//! weights, and the fits of one model spec on all data and in the folds.

use super::{DiagnoseOptions, Step};
use crate::candidates::Form;
use crate::features::{data_features, DataFeatures};
use crate::fits::{cross_validate, fit, residuals, space_of, with_values, Effort, FitResult, Spec};
use crate::folds::{mark_beyond_training, piece_folds, pieces, Fold, Piece};
use crate::score::{compare, squared_or_failed, Comparison, HeldOut, Weights};
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;
use subfric_fit::{
    best_informed_guesses, calibrate_from, with_base_of, FitError, FitOptions, Param, RunCounter,
    Space,
};
use subfric_model::Model;
use subfric_reading::{FitTest, PreparedTest, Stiffness};

/// Rounds of reweighting when model error dominates.
pub(super) const REWEIGHTING_ROUNDS: usize = 1;
/// Continuations of a fit stopped by its iteration limit in
/// [`Context::fit_spec_to_convergence`].
const CONTINUATIONS: usize = 3;

/// A continuation that lowers the SSR (noise-variance units) by less than this has settled:
/// less than one noise variance over all rows is below what the data resolve (the expected
/// χ² of a single degree of freedom), so the fit's score no longer depends on where its
/// iteration limit stopped it.
const SETTLED_SSR: f64 = 1.0;

/// The fitted tests and everything derived once from them.
pub(super) struct Context<'a> {
    /// The tests (rows weighted as the rows of the record they stand for).
    pub(super) tests: Vec<FitTest>,
    /// The tests thinned further, to about [`SCREENING_ROWS`]: what the forms are ranked on.
    pub(super) screening: Vec<FitTest>,
    /// The first guesses read off the curves that fit best on the base, computed once: every
    /// form starts from each of them with its own first guesses.
    pub(super) informed: Vec<Model>,
    /// Every event read on its own (it corroborates or speaks against a family).
    pub(super) events: crate::events::EventAnalysis,
    /// Model error dominates: every spec is fitted with a variance per piece (see
    /// [`Context::weighted_for`]).
    pub(super) reweight: bool,
    /// The base model's residuals on all data (what candidates are scored in-sample against).
    pub(super) base_residuals: HeldOut,
    pub(super) features: DataFeatures,
    pub(super) base_free: Vec<Param>,
    pub(super) pieces: Vec<Piece>,
    pub(super) folds: Vec<Fold>,
    /// Rows of the record each fitted row stands for.
    pub(super) weights: Weights,
    /// Per test, what a second specimen tested alike could differ by, in noise units
    /// ([`specimen_scatter`]).
    pub(super) scatter: Vec<f64>,
    pub(super) opts: &'a DiagnoseOptions,
    /// When the diagnosis began (for [`Context::trace`]).
    pub(super) started: Instant,
    /// Told where the diagnosis is ([`Context::step`]).
    report: &'a (dyn Fn(Step) + Sync),
    /// The diagnosis's model runs: every fit it makes counts here (for its caller's progress
    /// display and [`Context::trace`]).
    pub(super) run_counter: RunCounter,
    /// Candidate forms screened so far.
    forms_done: AtomicUsize,
}

/// A spec fitted to all data, with the tests as weighted for it.
#[derive(Clone)]
pub(super) struct SpecFit {
    pub(super) result: FitResult,
    pub(super) fit_tests: Vec<FitTest>,
    /// Stopped by its iteration limit, but continued from there its SSR fell by less than
    /// [`SETTLED_SSR`]: judged like a converged fit (see [`Context::fit_spec_to_convergence`]).
    pub(super) settled: bool,
}

impl SpecFit {
    /// Converged, or settled: its score says what the form can do, not where it stopped.
    pub(super) fn judged(&self) -> bool {
        self.result.ssr.is_finite() && (self.result.converged || self.settled)
    }
}

impl<'a> Context<'a> {
    /// The tests, pieces and folds of `prepared`, and the template the base fit starts from
    /// (α_t from the data when they resolve it, then also fitted). Its fits count their model
    /// runs into `run_counter`.
    pub(super) fn new(
        prepared: &[PreparedTest],
        stiffness: Option<&Stiffness>,
        opts: &'a DiagnoseOptions,
        report: &'a (dyn Fn(Step) + Sync),
        run_counter: &RunCounter,
    ) -> (Self, Model) {
        let tests: Vec<FitTest> = prepared.iter().map(|p| p.fit.clone()).collect();
        let screening = screening_tests(prepared);
        let mut template = opts.template;
        let mut base_free = Param::BASE.to_vec();
        if let Some(s) = stiffness {
            s.set_in(&mut template);
            base_free.push(Param::AlphaT);
        }
        let mut all_pieces = pieces(prepared);
        let folds = piece_folds(&tests, &all_pieces, opts.folds);
        mark_beyond_training(&mut all_pieces, &folds);
        let weights: Weights = tests
            .iter()
            .map(|t| (0..t.len()).map(|i| t.weight_of(i)).collect())
            .collect();
        let cx = Context {
            weights,
            scatter: tests.iter().map(specimen_scatter).collect(),
            reweight: false,
            base_residuals: Vec::new(),
            tests,
            screening,
            informed: Vec::new(),
            events: Default::default(),
            features: data_features(prepared),
            base_free,
            pieces: all_pieces,
            folds,
            opts,
            started: Instant::now(),
            report,
            run_counter: run_counter.clone(),
            forms_done: AtomicUsize::new(0),
        };
        (cx, template)
    }

    /// Tells the caller that step `number` ([`Step::WHAT`]) is under way, `done` of its
    /// `total` items done (0 of 0: not counted).
    pub(super) fn step(&self, number: usize, done: usize, total: usize) {
        (self.report)(Step::new(number, done, total));
    }

    /// One more candidate form screened, of `total`.
    pub(super) fn form_screened(&self, total: usize) {
        let done = self.forms_done.fetch_add(1, Ordering::Relaxed) + 1;
        self.step(2, done, total);
    }

    /// Prints the time and this diagnosis's model runs at each stage to stderr when
    /// `SUBFRIC_TRACE` is set (for tuning).
    pub(super) fn trace(&self, what: &str) {
        if std::env::var_os("SUBFRIC_TRACE").is_some() {
            eprintln!(
                "[{:7.2} s, {:6} model runs] {what}",
                self.started.elapsed().as_secs_f64(),
                self.run_counter.runs()
            );
        }
    }
    pub(super) fn space(&self, template: &Model, spec: &Spec) -> Space {
        space_of(template, &self.base_free, spec, self.features.v_ref)
    }

    /// The tests as fitted by a model whose residuals are `res`: when model error dominates,
    /// each piece's rows weigh n_eff / SSR of that model on the piece (a Gaussian likelihood
    /// with one unknown variance per piece, reweighted at the model), never more than the noise
    /// would give, normalised to keep the total weight. Pieces the model misses most (a run-in,
    /// one long relaxation) then stop deciding the fit, as they do not decide the score.
    pub(super) fn weighted_for(&self, res: &HeldOut) -> Vec<FitTest> {
        if !self.reweight {
            return self.tests.clone();
        }
        let mut factor: Vec<Vec<f64>> = self.tests.iter().map(|t| vec![1.0; t.len()]).collect();
        let (mut before, mut after) = (0.0, 0.0);
        for p in &self.pieces {
            let r = &res[p.test][p.start..p.end];
            let n = r.len() as f64;
            let ssr: f64 = r.iter().map(|&v| squared_or_failed(v)).sum();
            let c = crate::score::effective_rows(r) / ssr.max(n);
            let rows = &mut factor[p.test][p.start..p.end];
            for (f, w) in rows.iter_mut().zip(&self.weights[p.test][p.start..p.end]) {
                *f = c;
                before += w;
                after += w * c;
            }
        }
        let norm = if after > 0.0 { before / after } else { 1.0 };
        self.tests
            .iter()
            .zip(&factor)
            .map(|(t, f)| {
                let mut t = t.clone();
                t.row_weight = (0..t.len()).map(|i| t.weight_of(i) * f[i] * norm).collect();
                t
            })
            .collect()
    }

    /// Fits `spec` to all data from `starts` with `effort`, then, when model error dominates,
    /// reweighted at its own residuals.
    pub(super) fn fit_spec(
        &self,
        template: &Model,
        spec: &Spec,
        starts: &[Model],
        effort: Effort,
    ) -> SpecFit {
        self.fit_spec_with(template, spec, starts, effort, self.reweight)
    }

    /// [`Context::fit_spec`] for a form that is to be ranked: a fit stopped by its iteration
    /// limit is continued from where it stopped, on the same weights and with as many
    /// iterations again, up to [`CONTINUATIONS`] times, until it converges or settles (a
    /// continuation lowers its SSR by less than [`SETTLED_SSR`]: a valley floor the fit crawls
    /// along, where its score no longer depends on the stop). A form neither converged nor
    /// settled is not ranked ([`super::selection`]): its score says where the fit stopped.
    pub(super) fn fit_spec_to_convergence(
        &self,
        template: &Model,
        spec: &Spec,
        starts: &[Model],
        effort: Effort,
    ) -> SpecFit {
        let mut fitted = self.fit_spec(template, spec, starts, effort);
        let space = self.space(template, spec);
        for _ in 0..CONTINUATIONS {
            if fitted.result.converged || fitted.settled || !fitted.result.ssr.is_finite() {
                break;
            }
            // Continued on the objective it stopped on (the same weights): its SSR can then
            // only fall, and how far it falls says whether the stop mattered.
            let before = fitted.result.ssr;
            let result = fit(
                &fitted.fit_tests,
                &space,
                &[fitted.result.model],
                Effort::refit(effort.iterations),
                &self.run_counter,
            );
            if !result.ssr.is_finite() || result.ssr > before {
                break;
            }
            fitted.settled = !result.converged && before - result.ssr < SETTLED_SSR;
            fitted.result = result;
        }
        fitted
    }

    /// [`Context::fit_spec`], reweighting only when `reweight`.
    pub(super) fn fit_spec_with(
        &self,
        template: &Model,
        spec: &Spec,
        starts: &[Model],
        effort: Effort,
        reweight: bool,
    ) -> SpecFit {
        let space = self.space(template, spec);
        let detrended = |mut ts: Vec<FitTest>| {
            for t in ts.iter_mut() {
                t.detrend = spec.drift;
            }
            ts
        };
        // Plain least squares first: weights from another model's residuals would make the
        // pieces where this one differs most weightless, and the fit would never see them.
        let mut fit_tests = detrended(self.tests.clone());
        let mut result = fit(&fit_tests, &space, starts, effort, &self.run_counter);
        if reweight {
            for _ in 0..REWEIGHTING_ROUNDS {
                let own = residuals(
                    &self.tests,
                    &result.model,
                    spec.drift.then_some(&fit_tests[..]),
                );
                fit_tests = detrended(self.weighted_for(&own));
                let refit = Effort::refit(effort.iterations / 2 + 1);
                result = fit(
                    &fit_tests,
                    &space,
                    &[result.model],
                    refit,
                    &self.run_counter,
                );
            }
        }
        SpecFit {
            result,
            fit_tests,
            settled: false,
        }
    }

    /// Fits `spec` on the screening tests (no reweighting), from `starts` each also crossed
    /// with the informed guesses of the base.
    pub(super) fn screen_spec(
        &self,
        template: &Model,
        spec: &Spec,
        starts: &[Model],
        effort: Effort,
    ) -> SpecFit {
        let space = self.space(template, spec);
        let mut all: Vec<Model> = starts.to_vec();
        for s in starts {
            all.extend(self.informed.iter().map(|g| with_base_of(s, g)));
        }
        let result = fit(&self.screening, &space, &all, effort, &self.run_counter);
        SpecFit {
            result,
            fit_tests: self.screening.clone(),
            settled: false,
        }
    }

    /// Held-out residuals of `spec` fitted on `fit_tests`, refitted in each fold from `starts`.
    pub(super) fn held_out(
        &self,
        template: &Model,
        spec: &Spec,
        fit_tests: &[FitTest],
        starts: &[Model],
    ) -> HeldOut {
        cross_validate(
            fit_tests,
            &self.tests,
            &self.folds,
            &self.space(template, spec),
            starts,
            self.opts.fold_iterations,
            spec.drift,
            &self.run_counter,
        )
    }

    /// Compares `candidate` with `reference` on `pieces` ([`crate::score::compare`]) with the
    /// rows' weights of this set.
    pub(super) fn compare(
        &self,
        pieces: &[Piece],
        reference: &HeldOut,
        candidate: &HeldOut,
    ) -> Comparison {
        compare(pieces, &self.weights, reference, candidate)
    }

    /// A model's in-sample residuals on the tests (with the drift of the measurement projected
    /// out when `spec` carries it), to compare with the base's ([`Context::base_residuals`]).
    pub(super) fn in_sample(&self, model: &Model, spec: &Spec, fit_tests: &[FitTest]) -> HeldOut {
        residuals(&self.tests, model, spec.drift.then_some(fit_tests))
    }
}

/// Informed guesses of the base every form also starts from.
const INFORMED_STARTS: usize = 3;

/// Rows the forms are screened on: enough for each form's best fit to rank the forms of a
/// family as on all rows, few enough for every form to be fitted from many starts.
pub(super) const SCREENING_ROWS: usize = 800;

/// The prepared tests thinned to their share of [`SCREENING_ROWS`].
fn screening_tests(prepared: &[PreparedTest]) -> Vec<FitTest> {
    let total: usize = prepared.iter().map(|p| p.fit.len()).sum();
    prepared
        .iter()
        .map(|p| {
            if total <= SCREENING_ROWS {
                return p.fit.clone();
            }
            let share = (SCREENING_ROWS as f64 * p.fit.len() as f64 / total as f64).ceil();
            let mut q = p.clone();
            subfric_reading::thin_prepared(&mut q, (share as usize).max(100));
            q.fit
        })
        .collect()
}

/// `model` with the forms of `spec` switched off (their neutral values): a start for refits
/// that lets an effect the training rows cannot see stay off.
pub(super) fn switched_off(model: &Model, spec: &Spec) -> Model {
    let values: Vec<Vec<f64>> = spec.forms.iter().map(|f| f.neutral.clone()).collect();
    with_values(model, spec, &values)
}

pub(super) fn parameters_of(model: &Model, forms: &[Form]) -> BTreeMap<String, f64> {
    forms
        .iter()
        .flat_map(|f| f.params.iter())
        .map(|p| (p.key().to_string(), p.get(model).unwrap_or(f64::NAN)))
        .collect()
}

/// The current model of the selection: its spec, fitted model, weighted tests and held-out
/// residuals.
#[derive(Clone)]
pub(super) struct Current {
    pub(super) spec: Spec,
    pub(super) model: Model,
    pub(super) fit_tests: Vec<FitTest>,
    pub(super) held: HeldOut,
}

/// Step 1: the base fit (`calibrated`, from [`calibrated_base`]) and its held-out residuals.
/// When model error dominates, every spec from here on is fitted with a variance per piece, the
/// base included.
pub(super) fn fit_base(cx: &mut Context, calibrated: Model) -> Result<Current, FitError> {
    let mut base = calibrated;
    cx.informed = best_informed_guesses(
        &cx.screening,
        &cx.space(&base, &Spec::base()),
        INFORMED_STARTS,
        Some(&cx.run_counter),
    );
    cx.base_residuals = residuals(&cx.tests, &base, None);
    cx.reweight = model_error_dominates(cx);
    let spec = Spec::base();
    let fitted = cx.fit_spec(
        &base,
        &spec,
        &[base],
        Effort::refit(cx.opts.candidate_iterations),
    );
    if cx.reweight {
        base = fitted.result.model;
        cx.base_residuals = residuals(&cx.tests, &base, None);
        cx.trace("base refitted with a variance per piece");
    }
    let held = cx.held_out(&base, &spec, &fitted.fit_tests, &[base]);
    Ok(Current {
        spec,
        model: base,
        fit_tests: fitted.fit_tests,
        held,
    })
}

/// How the diagnosis fits its base unlike `subfric fit` with its defaults on the same data, in
/// sentences (issue 43: the two commands' parameters differ, and the diagnosis says why). Each
/// is a fact of this run: the rows kept, the weights, where α_t came from, the search.
pub(super) fn unlike_fit(
    cx: &Context,
    rows: usize,
    fitted_rows: usize,
    alpha_from_steps: bool,
    reduced_chi2: f64,
) -> Vec<String> {
    let fit_prepare = subfric_reading::PrepareOptions::default();
    let fit_options = subfric_fit::FitOptions::default();
    let mut out = Vec::new();
    if rows > super::DIAGNOSIS_BUDGET_ROWS && fitted_rows < rows.min(fit_prepare.budget_rows) {
        out.push(format!(
            "it is fitted on {fitted_rows} rows binned from the record's {rows} (the diagnosis bins a record to about {} rows, `fit` to about {})",
            super::DIAGNOSIS_BUDGET_ROWS,
            fit_prepare.budget_rows
        ));
    }
    if cx.reweight {
        out.push(format!(
            "each piece weighs by its own misfit (one variance per piece), because the model misses by {:.1}× the noise variance; `fit` weighs every row by the noise alone",
            reduced_chi2
        ));
    }
    if alpha_from_steps {
        out.push(
            "α_t is the spring the velocity steps needed one by one; `fit` holds it, or frees it where unloads or a first loading resolve it".to_string(),
        );
    }
    if cx.opts.global_evaluations != fit_options.global_evaluations
        || cx.opts.starts != fit_options.starts
    {
        out.push(format!(
            "its global search is {} model runs and {} local starts (`fit`: {} and {})",
            cx.opts.global_evaluations,
            cx.opts.starts,
            fit_options.global_evaluations,
            fit_options.starts
        ));
    }
    out
}

/// The base calibration (global stage and polish), with α_t free when the data resolve it,
/// from `starts` as well as from the informed guesses.
pub(super) fn calibrated_base(
    cx: &Context,
    template: &Model,
    starts: &[Model],
) -> Result<Model, FitError> {
    let space = cx.space(template, &Spec::base());
    let report = calibrate_from(
        &cx.tests,
        space,
        starts,
        &FitOptions {
            seed: cx.opts.seed,
            global_evaluations: cx.opts.global_evaluations,
            starts: cx.opts.starts,
            profiles: false,
            run_counter: Some(cx.run_counter.clone()),
            ..FitOptions::default()
        },
        &|_| {},
    )?;
    Ok(report.model)
}

/// What a second specimen tested alike could differ by in test `t`'s level, in units of its
/// noise: [`subfric_reading::levels::REPRODUCIBILITY_SHARE`] of its typical |shear| (the median
/// over its rows) over its noise SD; infinite under traction control, where the measured
/// column is a slip.
pub(super) fn specimen_scatter(t: &FitTest) -> f64 {
    let noise_read = t.noise_sd > 0.0;
    if t.control != subfric_model::Control::Slip || !noise_read {
        return f64::INFINITY;
    }
    let mut shear: Vec<f64> = t
        .measured
        .iter()
        .filter(|v| v.is_finite())
        .map(|v| v.abs())
        .collect();
    let typical = subfric_reading::stats::median(&mut shear).unwrap_or(0.0);
    subfric_reading::levels::REPRODUCIBILITY_SHARE * typical / t.noise_sd
}

/// The base misses by more than `model_error_chi2` × the noise variance per row.
fn model_error_dominates(cx: &Context) -> bool {
    let rows: usize = cx.base_residuals.iter().map(|r| r.len()).sum();
    let represented: f64 = cx.weights.iter().flatten().sum();
    let chi2 = 1.0 + (ssr_of(&cx.base_residuals) - rows as f64) / represented.max(1.0);
    chi2 >= cx.opts.thresholds.model_error_chi2
}

pub(super) fn ssr_of(r: &HeldOut) -> f64 {
    r.iter().flatten().map(|&v| squared_or_failed(v)).sum()
}

/// The fold that holds out each piece (pieces never held out get fold 0).
pub(super) fn fold_index(cx: &Context) -> Vec<usize> {
    let mut out = vec![0; cx.pieces.len()];
    for (fi, f) in cx.folds.iter().enumerate() {
        for &k in &f.held {
            out[k] = fi;
        }
    }
    out
}

#[cfg(test)]
#[path = "context_tests.rs"]
pub(super) mod tests;
