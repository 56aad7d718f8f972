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
            global_evaluations: 1500,
            starts: 4,
            folds: 4,
            tail_fraction: 0.4,
            candidate_iterations: 40,
            fold_iterations: 12,
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
    /// In-sample SSR (noise units, fitted rows).
    pub ssr: f64,
    /// In-sample BIC improvement over the base.
    pub delta_bic: f64,
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
        eprintln!("[{:7.2} s] {what}", t0.elapsed().as_secs_f64());
    }
}

/// The fitted tests and everything derived once from them.
struct Context<'a> {
    tests: Vec<FitTest>,
    features: DataFeatures,
    base_free: Vec<Param>,
    pieces: Vec<Piece>,
    folds: Vec<Fold>,
    /// Rows of the record each fitted row stands for.
    weights: Weights,
    opts: &'a DiagnoseOptions,
}

impl Context<'_> {
    fn space(&self, template: &Model, spec: &Spec) -> Space {
        space_of(template, &self.base_free, spec, self.features.v_ref)
    }

    /// Held-out residuals of `spec`, refitted in each fold from `starts`.
    fn held_out(&self, template: &Model, spec: &Spec, starts: &[Model]) -> HeldOut {
        cross_validate(
            &self.tests,
            &self.folds,
            &self.space(template, spec),
            starts,
            self.opts.fold_iterations,
            spec.drift,
        )
    }

    fn rows(&self) -> usize {
        self.tests.iter().map(|t| t.len()).sum()
    }
}

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

/// 2. Every form fitted to all data from its starts.
fn fit_forms(cx: &Context, base: &Model, base_ssr: f64, forms: &[Form]) -> Vec<FormReport> {
    let n = cx.rows() as f64;
    forms
        .par_iter()
        .map(|f| {
            let spec = Spec::with(f);
            let space = cx.space(base, &spec);
            let starts: Vec<Model> = f
                .starts
                .iter()
                .map(|s| with_values(base, &spec, std::slice::from_ref(s)))
                .collect();
            let r: FitResult = fit(&cx.tests, &space, &starts, cx.opts.candidate_iterations);
            let k = f.params.len() as f64;
            FormReport {
                effect: f.effect,
                form: f.name.to_string(),
                parameters: parameters_of(&r.model, std::slice::from_ref(f)),
                ssr: r.ssr,
                delta_bic: n * (base_ssr / r.ssr.max(1e-300)).ln() - k * n.ln(),
                converged: r.converged && r.ssr.is_finite(),
                termination: r.termination,
                chosen: false,
                model: r.model,
            }
        })
        .collect()
}

/// The best form of each family (largest in-sample ΔBIC), marked `chosen`.
fn choose_forms(reports: &mut [FormReport]) -> Vec<usize> {
    let mut best: BTreeMap<Effect, usize> = BTreeMap::new();
    for (i, r) in reports.iter().enumerate() {
        if !r.ssr.is_finite() {
            continue;
        }
        match best.get(&r.effect) {
            Some(&j) if reports[j].delta_bic >= r.delta_bic => {}
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

/// The current model of the selection: its spec, fitted model and held-out residuals.
struct Current {
    spec: Spec,
    model: Model,
    held: HeldOut,
}

/// 3. One stage of the forward selection: every remaining family added to the current model,
/// fitted on all data and compared on held-out pieces.
fn selection_stage(
    cx: &Context,
    current: &Current,
    families: &[(Effect, Form, Model)],
    with_drift: bool,
) -> (Stage, Vec<(Spec, Model, HeldOut)>) {
    let reference_chi2 =
        compare(&cx.pieces, &cx.weights, &current.held, &current.held).reference_chi2;
    let results: Vec<(Effect, Spec, Model, HeldOut)> = families
        .par_iter()
        .filter(|(e, _, _)| !current.spec.forms.iter().any(|f| f.effect == *e))
        .map(|(e, form, alone)| {
            let spec = current.spec.plus(form);
            let space = cx.space(&current.model, &spec);
            // Starts: the current model with the form as fitted alone, and switched off.
            let own: Vec<f64> = form
                .params
                .iter()
                .map(|p| p.get(alone).unwrap_or(0.0))
                .collect();
            let with_form = with_values(&current.model, &Spec::with(form), &[own]);
            let starts = [with_form, switched_off(&with_form, &Spec::with(form))];
            let r = fit(&cx.tests, &space, &starts, cx.opts.candidate_iterations);
            let held = cx.held_out(&current.model, &spec, &[r.model, current.model]);
            (*e, spec, r.model, held)
        })
        .collect();
    let mut candidates = Vec::new();
    let mut kept = Vec::new();
    for (e, spec, model, held) in results {
        candidates.push(candidate_score(cx, e, &spec, model, &current.held, &held));
        kept.push((spec, model, held));
    }
    let drift = with_drift.then(|| {
        let spec = Spec {
            forms: current.spec.forms.clone(),
            drift: true,
        };
        let space = cx.space(&current.model, &spec);
        let mut dt = cx.tests.clone();
        for t in dt.iter_mut() {
            t.detrend = true;
        }
        let r = fit(&dt, &space, &[current.model], cx.opts.candidate_iterations);
        let held = cx.held_out(&current.model, &spec, &[r.model, current.model]);
        candidate_score(
            cx,
            Effect::Unexplained,
            &spec,
            r.model,
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
    base: &Model,
    spec: &Spec,
    model: &Model,
) -> (Option<f64>, Option<f64>) {
    let (tail, loto) = extra_folds(&cx.tests, cx.opts.tail_fraction);
    let shrink = |folds: &[Fold]| -> Option<f64> {
        if folds.is_empty() {
            return None;
        }
        let cv = |s: &Spec, starts: &[Model]| {
            cross_validate(
                &cx.tests,
                folds,
                &cx.space(base, s),
                starts,
                cx.opts.fold_iterations,
                false,
            )
        };
        let b = cv(&Spec::base(), &[*base]);
        let c = cv(spec, &[*model, switched_off(model, spec)]);
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
    let cx = Context {
        weights,
        tests,
        features,
        base_free,
        pieces: all_pieces,
        folds,
        opts,
    };

    // 1. Base fit; where it misses (all rows).
    let base = base_fit(&cx, &template)?;
    trace(t0, "base fit");
    let base_ssr = ssr_of(&residuals(&cx.tests, &base, None));
    let fulls: Vec<FitTest> = prepared.iter().map(|p| p.full.clone()).collect();
    let localisation = localise(prepared, &residuals(&fulls, &base, None));

    // 2. Every form; the best of each family.
    let lib = library(&cx.features);
    let mut forms = fit_forms(&cx, &base, base_ssr, &lib);
    let chosen = choose_forms(&mut forms);
    trace(t0, "every form fitted");
    let families: Vec<(Effect, Form, Model)> = chosen
        .iter()
        .map(|&i| (forms[i].effect, lib[i].clone(), forms[i].model))
        .collect();

    // 3. Forward selection on held-out pieces.
    let base_held = cx.held_out(&base, &Spec::base(), &[base]);
    let mut current = Current {
        spec: Spec::base(),
        model: base,
        held: base_held.clone(),
    };
    let mut selection = Vec::new();
    let mut named: Vec<(Effect, Form, Comparison)> = Vec::new();
    for stage_no in 0..opts.thresholds.max_effects {
        let (stage, kept) = selection_stage(&cx, &current, &families, stage_no == 0);
        trace(t0, &format!("selection stage {}", stage_no + 1));
        let decision = stage.decision;
        if let Decision::Named(i) = decision {
            let (spec, model, held) = kept[i].clone();
            let form = spec.forms.last().expect("a named spec has a form").clone();
            named.push((form.effect, form, stage.candidates[i].held_out.clone()));
            current = Current { spec, model, held };
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
    let verdict = make_verdict(&cx, &base, &current, &named, &selection, &evidence);
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
            ssr: base_ssr,
            rows,
            fitted_rows: cx.rows(),
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

fn ssr_of(r: &HeldOut) -> f64 {
    r.iter()
        .flatten()
        .map(|v| if v.is_finite() { v * v } else { 1e6 })
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
    base: &Model,
    current: &Current,
    named: &[(Effect, Form, Comparison)],
    selection: &[Stage],
    evidence: &ResidualEvidence,
) -> Verdict {
    let effects: Vec<NamedEffect> = named
        .iter()
        .map(|(e, form, c)| {
            let (tail, loto) = extra_shrinks(cx, base, &Spec::with(form), &current.model);
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
            format!(
                "{} ({}) removes {:.0}% of the held-out misfit left before it ({:.0}% of its excess over the noise; evidence D = {:.0})",
                e.effect,
                e.form,
                100.0 * e.relative_shrink,
                100.0 * e.held_out_shrink.max(0.0),
                e.score
            )
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
