//! The diagnosis: fit the base model, localise its residual, fit every form of every candidate
//! family, compare the best form of each family with the base on held-out pieces, name the
//! effects one after the other by forward selection, read the residual for supporting
//! evidence, and say how much of the held-out gap the named effects remove.

use crate::candidates::{library, Effect, Form};
use crate::evidence::{residual_evidence, ResidualEvidence};
use crate::features::{data_features, DataFeatures};
use crate::fits::{cross_validate, fit, residuals, space_of, with_values, FitResult, Spec};
use crate::folds::{extra_folds, piece_folds, pieces, Fold, Piece};
use crate::localise::{localise, GroupMisfit, Localisation};
use crate::score::{by_kind, compare, Comparison, HeldOut, Weights};
use crate::verdict::{decide, Decision, Thresholds};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;
use subfric_fit::{
    calibrate, misfits, resolved_stiffness, FitError, FitOptions, FitTest, Param, PreparedTest,
    Space, Stiffness, TestMisfit,
};
use subfric_model::Model;

/// Rows a diagnosis fits a set on: longer sets are thinned to about this many (it refits many
/// candidate models many times; the misfit is always reported on all rows).
pub const DIAGNOSIS_BUDGET_ROWS: usize = 3000;

/// Prepares a set for a diagnosis (conditioned, segmented, thinned to
/// [`DIAGNOSIS_BUDGET_ROWS`]).
pub fn prepare_for_diagnosis(set: &subfric_data::ExperimentSet) -> Vec<PreparedTest> {
    subfric_fit::prepare_set_with(
        set,
        false,
        &subfric_fit::PrepareOptions {
            budget_rows: DIAGNOSIS_BUDGET_ROWS,
            ..Default::default()
        },
    )
}

/// Options of a diagnosis.
#[derive(Clone, Debug)]
pub struct DiagnoseOptions {
    /// Seed of the base fit.
    pub seed: u64,
    /// Global-stage budget of the base fit (model runs).
    pub global_evaluations: usize,
    /// Local starts of the base fit.
    pub starts: usize,
    /// Held-out folds of pieces.
    pub folds: usize,
    /// Fraction of each test held out at its end in the extra tail folds.
    pub tail_fraction: f64,
    /// Least-squares iterations that rank the forms of a family.
    pub screening_iterations: usize,
    /// Least-squares iterations of a candidate fit on all data.
    pub candidate_iterations: usize,
    /// Least-squares iterations of a refit in a fold (warm-started).
    pub fold_iterations: usize,
    /// Model supplying fixed parameters (α) and the first template.
    pub template: Model,
    /// Verdict thresholds.
    pub thresholds: Thresholds,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        DiagnoseOptions {
            seed: 1,
            global_evaluations: 1000,
            starts: 4,
            folds: 4,
            tail_fraction: 0.4,
            screening_iterations: 12,
            candidate_iterations: 30,
            fold_iterations: 8,
            template: Model::base(subfric_model::Params::sample())
                .expect("sample parameters are valid"),
            thresholds: Thresholds::default(),
        }
    }
}

/// Why a diagnosis could not run.
#[derive(Debug, thiserror::Error)]
pub enum DiagnoseError {
    /// The base fit failed.
    #[error("base fit: {0}")]
    Fit(#[from] FitError),
    /// Not enough data.
    #[error("a diagnosis needs at least one test with 20 rows or more")]
    TooLittleData,
}

/// One form fitted to all data.
#[derive(Clone, Debug, Serialize)]
pub struct FormReport {
    /// Family.
    pub effect: Effect,
    /// Form.
    pub form: String,
    /// Fitted extra parameters.
    pub parameters: BTreeMap<String, f64>,
    /// In-sample SSR (noise units, fitted rows, with the weights it was fitted with).
    pub ssr: f64,
    /// In-sample evidence over the base, piece by piece like the held-out score, less
    /// ln(n_eff) per extra parameter (a BIC on the effective number of observations).
    pub in_sample_score: f64,
    /// The fit converged (a form that did not is reported, and only chosen if it still wins).
    pub converged: bool,
    /// How the best start stopped.
    pub termination: String,
    /// The best form of its family (the one compared on held-out data).
    pub chosen: bool,
    /// The fitted model.
    pub model: Model,
}

/// A candidate (the best form of a family, or the drift) against a reference model.
#[derive(Clone, Debug, Serialize)]
pub struct CandidateScore {
    /// Family (`unexplained` for the drift alternative).
    pub effect: Effect,
    /// The model compared, in words.
    pub spec: String,
    /// Fitted extra parameters.
    pub extra_parameters: BTreeMap<String, f64>,
    /// The fitted model.
    pub model: Model,
    /// Held-out comparison with the reference.
    pub held_out: Comparison,
    /// Fraction of the held-out excess removed (= `held_out.excess_shrink`), for scripts.
    pub held_out_shrink: f64,
    /// Shrink per kind of piece: (kind, reference χ², candidate χ²).
    pub by_kind: Vec<KindShrink>,
}

/// Held-out misfit of the reference and a candidate on one kind of piece.
#[derive(Clone, Debug, Serialize)]
pub struct KindShrink {
    /// Kind of piece.
    pub kind: String,
    /// Held-out rows.
    pub rows: usize,
    /// Reference RMS / noise.
    pub reference_rms_over_noise: f64,
    /// Candidate RMS / noise.
    pub candidate_rms_over_noise: f64,
    /// Fraction of the reference's SSR removed.
    pub shrink: f64,
}

/// One stage of the forward selection.
#[derive(Clone, Debug, Serialize)]
pub struct Stage {
    /// The model every candidate is added to.
    pub reference: String,
    /// Held-out reduced χ² of the reference.
    pub reference_chi2: f64,
    /// Each family added to it.
    pub candidates: Vec<CandidateScore>,
    /// The drift alternative (first stage only).
    pub drift: Option<CandidateScore>,
    /// What was decided.
    pub decision: Decision,
}

/// An effect the diagnosis names.
#[derive(Clone, Debug, Serialize)]
pub struct NamedEffect {
    /// Family.
    pub effect: Effect,
    /// Best form.
    pub form: String,
    /// Fitted parameters of the form.
    pub parameters: BTreeMap<String, f64>,
    /// Fraction of the held-out excess misfit (over the noise) of the model before it that it
    /// removes.
    pub held_out_shrink: f64,
    /// Fraction of the held-out misfit of the model before it that it removes.
    pub relative_shrink: f64,
    /// How much the misfit of a typical held-out piece falls.
    pub typical_shrink: f64,
    /// Held-out evidence D (deviance units).
    pub score: f64,
    /// Extra checks: shrink on the tail of each test, and on each test left out.
    pub tail_shrink: Option<f64>,
    /// Shrink with each test left out in turn (an effect seen in one test cannot be learned
    /// without it).
    pub leave_one_test_out_shrink: Option<f64>,
}

/// The answer for scripts.
#[derive(Clone, Debug, Serialize)]
pub struct Verdict {
    /// The first effect named, or `none`, or `unexplained`.
    pub effect: Effect,
    /// Held-out shrink of that effect (0 for none/unexplained).
    pub held_out_shrink: f64,
    /// Every named effect, in the order named.
    pub effects: Vec<NamedEffect>,
    /// Plain-language reason.
    pub explanation: String,
    /// Fitted extra parameters of the first effect.
    pub extra_parameters: BTreeMap<String, f64>,
    /// Held-out misfit with every named effect, reduced χ² in noise units: how far from the
    /// noise the final model still is.
    pub final_chi2: f64,
    /// Whether the residual evidence supports the first family named.
    pub evidence_supports: Option<bool>,
}

/// The base model's fit.
#[derive(Clone, Debug, Serialize)]
pub struct BaseFit {
    /// Fitted model.
    pub model: Model,
    /// Free parameters.
    pub free: Vec<String>,
    /// SSR on the fitted rows (noise units).
    pub ssr: f64,
    /// Rows of the record.
    pub rows: usize,
    /// Rows fitted (bins of a thinned record).
    pub fitted_rows: usize,
    /// Reduced χ² on all rows.
    pub reduced_chi2: f64,
    /// Per-test misfit on all rows.
    pub tests: Vec<TestMisfit>,
}

/// How each test starts.
#[derive(Clone, Debug, Serialize)]
pub struct TestStart {
    /// Test.
    pub test: String,
    /// The state.
    pub start: subfric_data::StartKind,
    /// From `experiment.json`, or decided from the data.
    pub from_spec: bool,
    /// Why.
    pub reason: String,
    /// Noise SD of the measured column, and whether it is only a quantisation floor.
    pub noise_sd: f64,
    /// Noise is a floor.
    pub noise_floor: bool,
}

/// A complete diagnosis.
#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    /// The verdict (first, for scripts).
    pub verdict: Verdict,
    /// Base fit.
    pub base: BaseFit,
    /// What the data contain.
    pub data: DataFeatures,
    /// Starts and noise of each test.
    pub starts: Vec<TestStart>,
    /// The elastic stiffness, when the data resolve it (then α_t is fitted).
    pub stiffness: Option<Stiffness>,
    /// Where the base residual lies (all rows).
    pub localisation: Localisation,
    /// Every form fitted to all data.
    pub forms: Vec<FormReport>,
    /// The best form of each family against the base, and the drift alternative.
    pub candidates: Vec<CandidateScore>,
    /// The forward selection, stage by stage.
    pub selection: Vec<Stage>,
    /// What the base model's held-out residual follows.
    pub evidence: ResidualEvidence,
    /// Where the residual lies with every named effect (all rows).
    pub remaining_by_segment: Vec<GroupMisfit>,
    /// The model with every named effect.
    pub final_model: Model,
    /// Held-out folds used.
    pub folds: Vec<String>,
    /// Pieces per kind.
    pub pieces: BTreeMap<String, usize>,
    /// Thresholds used.
    pub thresholds: Thresholds,
    /// Wall time [s].
    pub elapsed_s: f64,
}

/// Prints the time of each stage to stderr when `SUBFRIC_TRACE` is set (for tuning).
fn trace(t0: Instant, what: &str) {
    if std::env::var_os("SUBFRIC_TRACE").is_some() {
        eprintln!(
            "[{:7.2} s, {:6} model runs] {what}",
            t0.elapsed().as_secs_f64(),
            subfric_fit::problem::model_runs()
        );
    }
}

/// Rounds of reweighting when model error dominates.
const REWEIGHTING_ROUNDS: usize = 1;

/// The fitted tests and everything derived once from them.
struct Context<'a> {
    /// The tests (rows weighted as the rows of the record they stand for).
    tests: Vec<FitTest>,
    /// Model error dominates: every spec is fitted with a variance per piece (see
    /// [`Context::weighted_for`]).
    reweight: bool,
    /// The base model's residuals on all data (what candidates are scored in-sample against).
    base_residuals: HeldOut,
    features: DataFeatures,
    base_free: Vec<Param>,
    pieces: Vec<Piece>,
    folds: Vec<Fold>,
    /// Rows of the record each fitted row stands for.
    weights: Weights,
    opts: &'a DiagnoseOptions,
}

/// A spec fitted to all data, with the tests as weighted for it.
#[derive(Clone)]
struct Fitted {
    result: FitResult,
    fit_tests: Vec<FitTest>,
}

impl Context<'_> {
    fn space(&self, template: &Model, spec: &Spec) -> Space {
        space_of(template, &self.base_free, spec, self.features.v_ref)
    }

    /// The tests as fitted by a model whose residuals are `res`: when model error dominates,
    /// each piece's rows weigh n_eff / SSR of that model on the piece (a Gaussian likelihood
    /// with one unknown variance per piece, reweighted at the model), never more than the noise
    /// would give, normalised to keep the total weight. Pieces the model misses most (a run-in,
    /// one long relaxation) then stop deciding the fit, as they do not decide the score.
    fn weighted_for(&self, res: &HeldOut) -> Vec<FitTest> {
        if !self.reweight {
            return self.tests.clone();
        }
        let mut factor: Vec<Vec<f64>> = self.tests.iter().map(|t| vec![1.0; t.len()]).collect();
        let (mut before, mut after) = (0.0, 0.0);
        for p in &self.pieces {
            let r = &res[p.test][p.start..p.end];
            let n = r.len() as f64;
            let ssr: f64 = r
                .iter()
                .map(|v| if v.is_finite() { v * v } else { FAILED_ROW })
                .sum();
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

    /// Fits `spec` to all data from `starts` (the `keep` best of them) by least squares, then,
    /// when model error dominates, reweighted at its own residuals.
    fn fit_spec(
        &self,
        template: &Model,
        spec: &Spec,
        starts: &[Model],
        keep: usize,
        iterations: usize,
    ) -> Fitted {
        self.fit_spec_with(template, spec, starts, keep, iterations, self.reweight)
    }

    /// [`Context::fit_spec`], reweighting only when `reweight`.
    fn fit_spec_with(
        &self,
        template: &Model,
        spec: &Spec,
        starts: &[Model],
        keep: usize,
        iterations: usize,
        reweight: bool,
    ) -> Fitted {
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
        let mut result = fit(&fit_tests, &space, starts, keep, iterations);
        if reweight {
            for _ in 0..REWEIGHTING_ROUNDS {
                let own = residuals(
                    &self.tests,
                    &result.model,
                    spec.drift.then_some(&fit_tests[..]),
                );
                fit_tests = detrended(self.weighted_for(&own));
                result = fit(&fit_tests, &space, &[result.model], 1, iterations / 2 + 1);
            }
        }
        Fitted { result, fit_tests }
    }

    /// Held-out residuals of `spec` fitted on `fit_tests`, refitted in each fold from `starts`.
    fn held_out(
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
        )
    }

    /// In-sample comparison of a model's residuals with the base's, piece by piece.
    fn in_sample(&self, model: &Model, spec: &Spec, fit_tests: &[FitTest]) -> Comparison {
        let own = residuals(&self.tests, model, spec.drift.then_some(fit_tests));
        compare(&self.pieces, &self.weights, &self.base_residuals, &own)
    }
}

/// Squared residual (noise units) counted for a row the model cannot simulate.
const FAILED_ROW: f64 = 1e6;

/// `model` with the forms of `spec` switched off (their neutral values): a start for refits
/// that lets an effect the training rows cannot see stay off.
fn switched_off(model: &Model, spec: &Spec) -> Model {
    let values: Vec<Vec<f64>> = spec.forms.iter().map(|f| f.neutral.clone()).collect();
    with_values(model, spec, &values)
}

fn parameters_of(model: &Model, forms: &[Form]) -> BTreeMap<String, f64> {
    forms
        .iter()
        .flat_map(|f| f.params.iter())
        .map(|p| (p.key().to_string(), p.get(model).unwrap_or(f64::NAN)))
        .collect()
}

/// 1. The base fit (global stage and polish), with α_t free when the data resolve it.
fn base_fit(cx: &Context, template: &Model) -> Result<Model, FitError> {
    let space = cx.space(template, &Spec::base());
    let report = calibrate(
        &cx.tests,
        space,
        &FitOptions {
            seed: cx.opts.seed,
            global_evaluations: cx.opts.global_evaluations,
            starts: cx.opts.starts,
            profiles: false,
            ..FitOptions::default()
        },
        &|_| {},
    )?;
    Ok(report.model)
}

/// 2. Every form fitted to all data from its starts, scored in-sample against the base.
fn fit_forms(cx: &Context, base: &Model, forms: &[Form]) -> Vec<(FormReport, Fitted)> {
    forms
        .par_iter()
        .map(|f| {
            let spec = Spec::with(f);
            let starts: Vec<Model> = f
                .starts
                .iter()
                .map(|s| with_values(base, &spec, std::slice::from_ref(s)))
                .collect();
            // Screening: a few iterations rank the forms; the best of each family is then
            // polished (see `polish`).
            let fitted =
                cx.fit_spec_with(base, &spec, &starts, 1, cx.opts.screening_iterations, false);
            let r = &fitted.result;
            let c = cx.in_sample(&r.model, &spec, &fitted.fit_tests);
            let k = f.params.len() as f64;
            (
                FormReport {
                    effect: f.effect,
                    form: f.name.to_string(),
                    parameters: parameters_of(&r.model, std::slice::from_ref(f)),
                    ssr: r.ssr,
                    in_sample_score: c.score - k * c.n_eff.max(1.0).ln(),
                    converged: r.converged && r.ssr.is_finite(),
                    termination: r.termination.clone(),
                    chosen: false,
                    model: r.model,
                },
                fitted,
            )
        })
        .collect()
}

/// The best form of each family (largest penalised in-sample score), marked `chosen`.
fn choose_forms(reports: &mut [FormReport]) -> Vec<usize> {
    let mut best: BTreeMap<Effect, usize> = BTreeMap::new();
    for (i, r) in reports.iter().enumerate() {
        if !r.ssr.is_finite() {
            continue;
        }
        match best.get(&r.effect) {
            Some(&j) if reports[j].in_sample_score >= r.in_sample_score => {}
            _ => {
                best.insert(r.effect, i);
            }
        }
    }
    for &i in best.values() {
        reports[i].chosen = true;
    }
    best.into_values().collect()
}

fn kind_shrinks(c: &Comparison) -> Vec<KindShrink> {
    by_kind(c)
        .into_iter()
        .map(|(k, b, cc, n)| KindShrink {
            kind: k.name().into(),
            rows: n,
            reference_rms_over_noise: (b / n.max(1) as f64).sqrt(),
            candidate_rms_over_noise: (cc / n.max(1) as f64).sqrt(),
            shrink: if b > 0.0 { (b - cc) / b } else { 0.0 },
        })
        .collect()
}

fn candidate_score(
    cx: &Context,
    effect: Effect,
    spec: &Spec,
    model: Model,
    reference: &HeldOut,
    held: &HeldOut,
) -> CandidateScore {
    let c = compare(&cx.pieces, &cx.weights, reference, held);
    CandidateScore {
        effect,
        spec: spec.describe(),
        extra_parameters: parameters_of(&model, &spec.forms),
        model,
        held_out_shrink: c.excess_shrink,
        by_kind: kind_shrinks(&c),
        held_out: c,
    }
}

/// The current model of the selection: its spec, fitted model, weighted tests and held-out
/// residuals.
#[derive(Clone)]
struct Current {
    spec: Spec,
    model: Model,
    fit_tests: Vec<FitTest>,
    held: HeldOut,
}

/// A family's best form with its fit alone on the base.
#[derive(Clone)]
struct Family {
    effect: Effect,
    form: Form,
    alone: Fitted,
}

/// Step 3, one stage of the forward selection: every remaining family added to the current
/// model, fitted on all data and compared on held-out pieces.
fn selection_stage(
    cx: &Context,
    current: &Current,
    families: &[Family],
    with_drift: bool,
) -> (Stage, Vec<Current>) {
    let reference_chi2 =
        compare(&cx.pieces, &cx.weights, &current.held, &current.held).reference_chi2;
    let first_stage = current.spec.forms.is_empty();
    if !first_stage && reference_chi2 <= cx.opts.thresholds.gap_chi2 {
        // Nothing left to explain: no candidate is fitted.
        return (
            Stage {
                reference: current.spec.describe(),
                reference_chi2,
                candidates: Vec::new(),
                drift: None,
                decision: Decision::NoGap,
            },
            Vec::new(),
        );
    }
    let results: Vec<(Effect, Current)> = families
        .par_iter()
        .filter(|f| !current.spec.forms.iter().any(|g| g.effect == f.effect))
        .map(|f| {
            let spec = current.spec.plus(&f.form);
            // On the base, the form was fitted to all data already.
            let fitted = if first_stage {
                f.alone.clone()
            } else {
                // Starts: the current model with the form as fitted alone, and switched off.
                let own: Vec<f64> = f
                    .form
                    .params
                    .iter()
                    .map(|p| p.get(&f.alone.result.model).unwrap_or(0.0))
                    .collect();
                let alone = Spec::with(&f.form);
                let with_form = with_values(&current.model, &alone, &[own]);
                let starts = [with_form, switched_off(&with_form, &alone)];
                cx.fit_spec(
                    &current.model,
                    &spec,
                    &starts,
                    1,
                    // Both parts start near their own fits: a short polish suffices.
                    cx.opts.screening_iterations,
                )
            };
            let model = fitted.result.model;
            let held = cx.held_out(
                &current.model,
                &spec,
                &fitted.fit_tests,
                &[model, current.model],
            );
            (
                f.effect,
                Current {
                    spec,
                    model,
                    fit_tests: fitted.fit_tests,
                    held,
                },
            )
        })
        .collect();
    let mut candidates = Vec::new();
    let mut kept = Vec::new();
    for (e, c) in results {
        candidates.push(candidate_score(
            cx,
            e,
            &c.spec,
            c.model,
            &current.held,
            &c.held,
        ));
        kept.push(c);
    }
    let drift = with_drift.then(|| {
        let spec = Spec {
            forms: current.spec.forms.clone(),
            drift: true,
        };
        let fitted = cx.fit_spec(
            &current.model,
            &spec,
            &[current.model],
            1,
            cx.opts.candidate_iterations,
        );
        let held = cx.held_out(
            &current.model,
            &spec,
            &fitted.fit_tests,
            &[fitted.result.model, current.model],
        );
        candidate_score(
            cx,
            Effect::Unexplained,
            &spec,
            fitted.result.model,
            &current.held,
            &held,
        )
    });
    let pairs: Vec<(Effect, Comparison)> = candidates
        .iter()
        .map(|c| (c.effect, c.held_out.clone()))
        .collect();
    let decision = decide(
        reference_chi2,
        &pairs,
        drift.as_ref().map(|d| &d.held_out),
        &cx.opts.thresholds,
    );
    (
        Stage {
            reference: current.spec.describe(),
            reference_chi2,
            candidates,
            drift,
            decision,
        },
        kept,
    )
}

/// Shrink of `spec` against the base on extra folds (tail of each test, each test left out).
fn extra_shrinks(
    cx: &Context,
    base: &Current,
    spec: &Spec,
    model: &Model,
    fit_tests: &[FitTest],
) -> (Option<f64>, Option<f64>) {
    let (tail, loto) = extra_folds(&cx.tests, cx.opts.tail_fraction);
    let shrink = |folds: &[Fold]| -> Option<f64> {
        if folds.is_empty() {
            return None;
        }
        let cv = |s: &Spec, ft: &[FitTest], starts: &[Model]| {
            cross_validate(
                ft,
                &cx.tests,
                folds,
                &cx.space(&base.model, s),
                starts,
                cx.opts.fold_iterations,
                false,
            )
        };
        let b = cv(&Spec::base(), &base.fit_tests, &[base.model]);
        let c = cv(spec, fit_tests, &[*model]);
        let whole: Vec<Piece> = cx
            .tests
            .iter()
            .enumerate()
            .map(|(i, t)| Piece {
                test: i,
                start: 0,
                end: t.len(),
                kind: crate::folds::PieceKind::InitialLoading,
            })
            .collect();
        Some(compare(&whole, &cx.weights, &b, &c).excess_shrink)
    };
    (shrink(&tail), shrink(&loto))
}

/// Runs the whole diagnosis on prepared tests of one interface.
pub fn diagnose(
    prepared: &[PreparedTest],
    opts: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    let t0 = Instant::now();
    if prepared.iter().all(|p| p.full.len() < 20) {
        return Err(DiagnoseError::TooLittleData);
    }
    let tests: Vec<FitTest> = prepared.iter().map(|p| p.fit.clone()).collect();
    let features = data_features(prepared);
    let stiffness = resolved_stiffness(prepared);
    let mut template = opts.template;
    let mut base_free = Param::BASE.to_vec();
    if let Some(s) = &stiffness {
        template.params.alpha_t = s.alpha_t;
        template.params.alpha_n = s.alpha_t;
        base_free.push(Param::AlphaT);
    }
    let all_pieces = pieces(prepared);
    let folds = piece_folds(&tests, &all_pieces, opts.folds);
    let weights: Weights = tests
        .iter()
        .map(|t| (0..t.len()).map(|i| t.weight_of(i)).collect())
        .collect();
    let mut cx = Context {
        weights,
        reweight: false,
        base_residuals: Vec::new(),
        tests,
        features,
        base_free,
        pieces: all_pieces,
        folds,
        opts,
    };

    // 1. Base fit; where it misses (all rows). When model error dominates, every spec from here
    // on is fitted with a variance per piece, the base included.
    let mut base = base_fit(&cx, &template)?;
    trace(t0, "base fit");
    cx.base_residuals = residuals(&cx.tests, &base, None);
    cx.reweight = model_error_dominates(&cx);
    let base_spec = Spec::base();
    let base_fitted = cx.fit_spec(&base, &base_spec, &[base], 1, opts.candidate_iterations);
    if cx.reweight {
        base = base_fitted.result.model;
        cx.base_residuals = residuals(&cx.tests, &base, None);
        trace(t0, "base refitted with a variance per piece");
    }
    let fulls: Vec<FitTest> = prepared.iter().map(|p| p.full.clone()).collect();
    let localisation = localise(prepared, &residuals(&fulls, &base, None));

    // 2. Every form; the best of each family.
    let lib = library(&cx.features);
    let (mut forms, fits): (Vec<FormReport>, Vec<Fitted>) =
        fit_forms(&cx, &base, &lib).into_iter().unzip();
    let chosen = choose_forms(&mut forms);
    trace(t0, "every form screened");
    let families: Vec<Family> = chosen
        .par_iter()
        .map(|&i| {
            let spec = Spec::with(&lib[i]);
            let polished = cx.fit_spec(
                &base,
                &spec,
                &[fits[i].result.model],
                1,
                opts.candidate_iterations,
            );
            Family {
                effect: forms[i].effect,
                form: lib[i].clone(),
                alone: polished,
            }
        })
        .collect();
    for (f, &i) in families.iter().zip(&chosen) {
        let r = &f.alone.result;
        let c = cx.in_sample(&r.model, &Spec::with(&f.form), &f.alone.fit_tests);
        forms[i].parameters = parameters_of(&r.model, std::slice::from_ref(&f.form));
        forms[i].ssr = r.ssr;
        forms[i].in_sample_score = c.score - f.form.params.len() as f64 * c.n_eff.max(1.0).ln();
        forms[i].converged = r.converged && r.ssr.is_finite();
        forms[i].termination = r.termination.clone();
        forms[i].model = r.model;
    }
    trace(t0, "best forms polished");

    // 3. Forward selection on held-out pieces.
    let base_held = cx.held_out(&base, &base_spec, &base_fitted.fit_tests, &[base]);
    let base_current = Current {
        spec: base_spec,
        model: base,
        fit_tests: base_fitted.fit_tests,
        held: base_held.clone(),
    };
    let mut current = base_current.clone();
    let mut selection: Vec<Stage> = Vec::new();
    let mut named: Vec<(Effect, Form, Comparison, Current)> = Vec::new();
    for stage_no in 0..opts.thresholds.max_effects {
        // After the first stage only families with held-out evidence of their own compete.
        let competing: Vec<Family> = match selection.first() {
            None => families.clone(),
            Some(first) => families
                .iter()
                .filter(|f| {
                    first
                        .candidates
                        .iter()
                        .any(|c| c.effect == f.effect && c.held_out.score > 0.0)
                })
                .cloned()
                .collect(),
        };
        let (stage, kept) = selection_stage(&cx, &current, &competing, stage_no == 0);
        trace(t0, &format!("selection stage {}", stage_no + 1));
        let decision = stage.decision;
        if let Decision::Named(i) = decision {
            let next = kept[i].clone();
            let form = next
                .spec
                .forms
                .last()
                .expect("a named spec has a form")
                .clone();
            named.push((
                form.effect,
                form,
                stage.candidates[i].held_out.clone(),
                next.clone(),
            ));
            current = next;
        }
        selection.push(stage);
        if !matches!(decision, Decision::Named(_)) {
            break;
        }
    }
    let candidates: Vec<CandidateScore> = selection
        .first()
        .map(|s| s.candidates.iter().chain(&s.drift).cloned().collect())
        .unwrap_or_default();

    // 4. Evidence from the base model's held-out residual.
    let fold_of_piece = fold_index(&cx);
    let evidence = residual_evidence(
        prepared,
        &cx.pieces,
        &base_held,
        &fold_of_piece,
        cx.features.v_ref,
        cx.features.p_ref,
    );

    // 5. Verdict, with the extra checks for the named effects.
    let verdict = make_verdict(&cx, &base_current, &current, &named, &selection, &evidence);
    trace(t0, "verdict and extra folds");
    let remaining = localise(prepared, &residuals(&fulls, &current.model, None)).by_segment;
    let base_misfits = misfits(&fulls, &base);
    let rows: usize = fulls.iter().map(|t| t.len()).sum();
    let all_ssr = ssr_of(&residuals(&fulls, &base, None));
    let starts = prepared
        .iter()
        .map(|p| TestStart {
            test: p.full.name.clone(),
            start: p.segmentation.start.kind,
            from_spec: p.segmentation.start.from_spec,
            reason: p.segmentation.start.reason.clone(),
            noise_sd: p.full.noise_sd,
            noise_floor: subfric_data::estimate_noise(&p.full.time, &p.full.measured).floor,
        })
        .collect();
    let mut pieces_by_kind: BTreeMap<String, usize> = BTreeMap::new();
    for p in &cx.pieces {
        *pieces_by_kind.entry(p.kind.name().into()).or_default() += 1;
    }
    Ok(Diagnosis {
        verdict,
        base: BaseFit {
            model: base,
            free: cx.base_free.iter().map(|p| p.key().to_string()).collect(),
            ssr: ssr_of(&cx.base_residuals),
            rows,
            fitted_rows: cx.tests.iter().map(|t| t.len()).sum(),
            reduced_chi2: all_ssr / (rows as f64 - cx.base_free.len() as f64).max(1.0),
            tests: base_misfits,
        },
        data: cx.features.clone(),
        starts,
        stiffness,
        localisation,
        forms,
        candidates,
        selection,
        evidence,
        remaining_by_segment: remaining,
        final_model: current.model,
        folds: cx.folds.iter().map(|f| f.name.clone()).collect(),
        pieces: pieces_by_kind,
        thresholds: opts.thresholds,
        elapsed_s: t0.elapsed().as_secs_f64(),
    })
}

/// The base misses by more than `model_error_chi2` × the noise variance per row.
fn model_error_dominates(cx: &Context) -> bool {
    let rows: usize = cx.base_residuals.iter().map(|r| r.len()).sum();
    let represented: f64 = cx.weights.iter().flatten().sum();
    let chi2 = 1.0 + (ssr_of(&cx.base_residuals) - rows as f64) / represented.max(1.0);
    chi2 >= cx.opts.thresholds.model_error_chi2
}

fn ssr_of(r: &HeldOut) -> f64 {
    r.iter()
        .flatten()
        .map(|v| if v.is_finite() { v * v } else { FAILED_ROW })
        .sum()
}

/// The fold that holds out each piece (pieces never held out get fold 0).
fn fold_index(cx: &Context) -> Vec<usize> {
    let mut out = vec![0; cx.pieces.len()];
    for (fi, f) in cx.folds.iter().enumerate() {
        for &k in &f.held {
            out[k] = fi;
        }
    }
    out
}

fn make_verdict(
    cx: &Context,
    base: &Current,
    current: &Current,
    named: &[(Effect, Form, Comparison, Current)],
    selection: &[Stage],
    evidence: &ResidualEvidence,
) -> Verdict {
    let effects: Vec<NamedEffect> = named
        .iter()
        .map(|(e, form, c, at)| {
            let (tail, loto) = extra_shrinks(cx, base, &Spec::with(form), &at.model, &at.fit_tests);
            NamedEffect {
                effect: *e,
                form: form.name.to_string(),
                parameters: parameters_of(&current.model, std::slice::from_ref(form)),
                held_out_shrink: c.excess_shrink,
                relative_shrink: c.relative_shrink,
                typical_shrink: c.typical_shrink,
                score: c.score,
                tail_shrink: tail,
                leave_one_test_out_shrink: loto,
            }
        })
        .collect();
    let first = selection.first();
    let base_chi2 = first.map_or(0.0, |s| s.reference_chi2);
    let final_chi2 = compare(&cx.pieces, &cx.weights, &current.held, &current.held).reference_chi2;
    let (effect, explanation) = match (effects.first(), first.map(|s| s.decision)) {
        (Some(e), _) => (e.effect, explain_named(&effects, base_chi2, final_chi2)),
        (None, Some(Decision::NoGap)) | (None, None) => (
            Effect::None,
            format!(
                "the base model predicts the held-out pieces at {base_chi2:.2}× the noise variance: the gap is noise"
            ),
        ),
        (None, Some(Decision::Drift)) => (
            Effect::Unexplained,
            format!(
                "the base misfit is {base_chi2:.2}× the noise variance; no physical candidate explains it, but a drift of each measurement linear in time does better than all of them: the gap looks like a drift of the measurement, not friction; {}",
                evidence.summary
            ),
        ),
        (None, Some(_)) => (
            Effect::Unexplained,
            explain_unexplained(first, base_chi2, evidence),
        ),
    };
    let evidence_supports = effects.first().map(|e| {
        evidence
            .features
            .iter()
            .take(2)
            .any(|f| f.family == Some(e.effect) && f.share > 0.1)
    });
    Verdict {
        effect,
        held_out_shrink: effects.first().map_or(0.0, |e| e.held_out_shrink),
        extra_parameters: effects
            .first()
            .map(|e| e.parameters.clone())
            .unwrap_or_default(),
        effects,
        explanation,
        final_chi2,
        evidence_supports,
    }
}

fn explain_named(effects: &[NamedEffect], base_chi2: f64, final_chi2: f64) -> String {
    let parts: Vec<String> = effects
        .iter()
        .map(|e| {
            let mut t = format!(
                "{} ({}): evidence D = {:.0} on held-out pieces; the misfit of a typical held-out piece falls by {:.0}%",
                e.effect,
                e.form,
                e.score,
                100.0 * e.typical_shrink
            );
            if e.relative_shrink >= 0.0 {
                t.push_str(&format!(
                    ", and {:.0}% of the held-out misfit is removed ({:.0}% of its excess over the noise)",
                    100.0 * e.relative_shrink,
                    100.0 * e.held_out_shrink.max(0.0)
                ));
            } else {
                t.push_str(&format!(
                    ", but the total held-out misfit grows by {:.0}%: a few pieces it cannot describe get worse (see the misfit per kind of piece)",
                    -100.0 * e.relative_shrink
                ));
            }
            t
        })
        .collect();
    let far = if final_chi2 > 2.0 {
        format!(
            "; with {} the model still misses by {final_chi2:.1}× the noise variance on held-out pieces (base {base_chi2:.1}×): part of the gap remains",
            if effects.len() > 1 { "them" } else { "it" }
        )
    } else {
        format!("; with it the held-out misfit is {final_chi2:.2}× the noise variance (base {base_chi2:.1}×)")
    };
    format!("{}{far}", parts.join("; then "))
}

fn explain_unexplained(
    stage: Option<&Stage>,
    base_chi2: f64,
    evidence: &ResidualEvidence,
) -> String {
    let best = stage.and_then(|s| {
        s.candidates
            .iter()
            .max_by(|a, b| a.held_out.score.total_cmp(&b.held_out.score))
    });
    let best_text = best
        .map(|c| {
            format!(
                "the best candidate, {}, removes {:.0}% of the held-out excess (evidence D = {:.0})",
                c.spec,
                100.0 * c.held_out.excess_shrink.max(0.0),
                c.held_out.score
            )
        })
        .unwrap_or_else(|| "no candidate applies to these data".into());
    format!(
        "the base model misses the held-out pieces by {base_chi2:.2}× the noise variance and none of the candidates explains it: {best_text}; {}",
        evidence.summary
    )
}
