//! The diagnosis: fit the base model, localise its residual, fit every form of every candidate
//! family, compare the best form of each family with the base on held-out pieces, name the
//! effects one after the other by forward selection, read the residual for supporting
//! evidence, and say how much of the held-out gap the named effects remove.

mod context;
mod explain;
mod report;
mod selection;

pub use report::{
    BaseFit, CandidateScore, Diagnosis, DroppedEffect, FormReport, KindShrink, NamedEffect,
    OwnKindScore, SelectionStage, TestStart, Verdict,
};

use crate::candidates::library_with;
use crate::evidence::residual_evidence;
use crate::fits::{residuals, Effort};
use crate::verdict::Thresholds;
use context::{calibrated_base, fit_base, fold_index, ssr_of, Context, Current};
use explain::make_verdict;
use selection::{forward_selection, screen_and_polish};
use std::collections::BTreeMap;
use subfric_fit::localise::localise;
use subfric_fit::{misfits, FitError, RunCounter};
use subfric_model::Model;
use subfric_reading::{resolved_stiffness, FitTest, PreparedTest};

/// Rows the longest test must reach for a diagnosis to run at all.
const MIN_ROWS: usize = 20;

/// Rows a diagnosis fits a set on: longer sets are thinned to about this many (it refits many
/// candidate models many times; the misfit is always reported on all rows).
pub const DIAGNOSIS_BUDGET_ROWS: usize = 3000;

/// Prepares a set for a diagnosis (conditioned, segmented, thinned to
/// [`DIAGNOSIS_BUDGET_ROWS`]).
pub fn prepare_for_diagnosis(set: &subfric_data::ExperimentSet) -> Vec<PreparedTest> {
    subfric_reading::prepare_set_with(
        set,
        false,
        &subfric_reading::PrepareOptions {
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
    /// How every form is fitted to rank the forms of a family (from the base with the form's
    /// starts and from the informed guesses crossed with them).
    pub screening: Effort,
    /// How the best form of each family is then fitted.
    pub polish: Effort,
    /// How the shortlisted forms are fitted on top of the model of a later selection stage.
    pub rescreening: Effort,
    /// Least-squares iterations of a warm-started refit on all data.
    pub candidate_iterations: usize,
    /// Least-squares iterations of a refit in a fold (warm-started).
    pub fold_iterations: usize,
    /// Model supplying fixed parameters (α) and the first template.
    pub template: Model,
    /// Verdict thresholds.
    pub thresholds: Thresholds,
    /// Candidate forms left out of the library, by name (as in [`crate::library`]): how
    /// `selfcheck --unlisted` asks whether a family is still named when the form that made
    /// the data is not among the candidates.
    pub excluded_forms: Vec<String>,
    /// Registered families tried beyond those tried by default, by name (see
    /// `subfric_model::terms`; `diagnose --with-family`).
    pub with_families: Vec<String>,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        DiagnoseOptions {
            seed: 1,
            global_evaluations: 1000,
            starts: 4,
            folds: 4,
            tail_fraction: 0.4,
            screening: Effort {
                global_evaluations: 0,
                local_runs: 1,
                iterations: 20,
                informed: false,
            },
            polish: Effort {
                global_evaluations: 0,
                local_runs: 1,
                iterations: 80,
                informed: false,
            },
            rescreening: Effort {
                global_evaluations: 0,
                local_runs: 1,
                iterations: 20,
                informed: false,
            },
            candidate_iterations: 40,
            fold_iterations: 12,
            template: Model::base(subfric_model::Params::sample())
                .expect("sample parameters are valid"),
            thresholds: Thresholds::default(),
            excluded_forms: Vec::new(),
            with_families: Vec::new(),
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
    #[error("a diagnosis needs at least one test with {MIN_ROWS} rows or more")]
    TooLittleData,
}

/// Where a diagnosis is, for a progress display: step `number` of [`Step::COUNT`], and the
/// items of the step done so far when they are counted (candidate forms screened, selection
/// stages run).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Step {
    /// 1 to [`Step::COUNT`].
    pub number: usize,
    /// What the step does ([`Step::WHAT`]).
    pub what: &'static str,
    /// Items done.
    pub done: usize,
    /// Items in all (0: not counted).
    pub total: usize,
}

impl Step {
    /// What each step does.
    pub const WHAT: [&'static str; 5] = [
        "fitting the base model",
        "screening every candidate form",
        "polishing the best form of each family",
        "selecting effects on held-out pieces",
        "extra held-out checks and the verdict",
    ];
    /// Steps of a diagnosis.
    pub const COUNT: usize = Step::WHAT.len();

    fn new(number: usize, done: usize, total: usize) -> Step {
        Step {
            number,
            what: Step::WHAT[number.clamp(1, Step::COUNT) - 1],
            done,
            total,
        }
    }
}

/// Runs the whole diagnosis on prepared tests of one interface: 1. the base fit, 2. every
/// form screened and the best of each family polished, 3. forward selection on held-out
/// pieces, 4. evidence from the base's held-out residual, 5. the verdict.
pub fn diagnose(
    prepared: &[PreparedTest],
    opts: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    diagnose_reporting(prepared, opts, &|_| {}, &RunCounter::new())
}

/// The elastic stiffness α_t the diagnosis holds, decided as `fit` decides it
/// ([`subfric_reading::decide_stiffness`]: unloads and reloads, then the springs the velocity steps
/// needed one by one — the diagnosis's own reading — then a trial on the first loadings); the
/// trial's runs count into `run_counter`.
fn elastic_stiffness(
    prepared: &[PreparedTest],
    resolved: Option<subfric_reading::Stiffness>,
    events: &crate::events::EventAnalysis,
    opts: &DiagnoseOptions,
    run_counter: &RunCounter,
) -> Option<subfric_reading::Stiffness> {
    let readings = subfric_reading::StiffnessReadings {
        resolved,
        springs: events.stiffness(),
    };
    subfric_reading::decide_stiffness(readings, || {
        subfric_fit::stiffness_by_trial(
            prepared,
            &opts.template,
            &subfric_fit::Param::BASE,
            &subfric_fit::FitOptions {
                seed: opts.seed,
                global_evaluations: opts.global_evaluations,
                starts: opts.starts,
                run_counter: Some(run_counter.clone()),
                ..subfric_fit::FitOptions::default()
            },
        )
    })
}

/// `prepared` with the bedding of each first loading taken out of its travel where the rise is
/// a closure of the rig ([`subfric_fit::fit_bedding`], each refit of the base a polish from
/// `calibrated`), and the bedding found.
fn bedding_taken_out(
    cx: &Context,
    template: &Model,
    prepared: &[PreparedTest],
    calibrated: &Model,
) -> (Vec<PreparedTest>, Vec<subfric_fit::Bedding>) {
    let space = cx.space(template, &crate::fits::Spec::base());
    let refit = |fits: &[FitTest], start: &Model| {
        crate::fits::fit(
            fits,
            &space,
            &[*start],
            Effort::refit(cx.opts.polish.iterations),
            &cx.run_counter,
        )
        .model
    };
    subfric_fit::fit_bedding(prepared, calibrated, &refit)
}

/// The base calibrated, and the tests it was calibrated on where a bedding was taken out.
struct Calibrated<'a> {
    cx: Context<'a>,
    calibrated: Model,
    /// The tests with the bedding taken out (`None`: none was).
    seated: Option<Vec<PreparedTest>>,
    bedding: Vec<subfric_fit::Bedding>,
}

/// The base calibrated on `prepared` with the elastic stiffness `stiffness`, then, where a first
/// loading's rise is a closure of the rig rather than the interface's, on the tests with that
/// bedding taken out of the travel (see subfric_fit::bedding), from the first calibration.
fn calibrated_on_seated<'a>(
    prepared: &[PreparedTest],
    stiffness: Option<&subfric_reading::Stiffness>,
    opts: &'a DiagnoseOptions,
    report: &'a (dyn Fn(Step) + Sync),
    run_counter: &RunCounter,
) -> Result<Calibrated<'a>, DiagnoseError> {
    let (cx, template) = Context::new(prepared, stiffness, opts, report, run_counter);
    cx.step(1, 0, 0);
    let calibrated = calibrated_base(&cx, &template, &[])?;
    cx.trace("base fit");
    let (seated, bedding) = bedding_taken_out(&cx, &template, prepared, &calibrated);
    if bedding.is_empty() {
        return Ok(Calibrated {
            cx,
            calibrated,
            seated: None,
            bedding,
        });
    }
    let (cx, _) = Context::new(&seated, stiffness, opts, report, run_counter);
    let start = calibrated_base(&cx, &template, &[calibrated])?;
    cx.trace("base fit on the travel with the bedding taken out");
    Ok(Calibrated {
        cx,
        calibrated: start,
        seated: Some(seated),
        bedding,
    })
}

/// Step 1 done: the base fitted ([`fit_base`]) on the tests it was calibrated on, its residual
/// on all rows of the record localised.
struct Based<'a> {
    cx: Context<'a>,
    base: Current,
    /// The tests with the bedding taken out (`None`: none was).
    seated: Option<Vec<PreparedTest>>,
    bedding: Vec<subfric_fit::Bedding>,
    /// Every row of each test.
    fulls: Vec<FitTest>,
    localisation: subfric_fit::localise::Localisation,
}

/// The base calibrated ([`calibrated_on_seated`]) and fitted, and where it misses on all rows.
fn based_on_seated<'a>(
    prepared: &[PreparedTest],
    stiffness: Option<&subfric_reading::Stiffness>,
    opts: &'a DiagnoseOptions,
    report: &'a (dyn Fn(Step) + Sync),
    run_counter: &RunCounter,
) -> Result<Based<'a>, DiagnoseError> {
    let Calibrated {
        mut cx,
        calibrated,
        seated,
        bedding,
    } = calibrated_on_seated(prepared, stiffness, opts, report, run_counter)?;
    let prepared = seated.as_deref().unwrap_or(prepared);
    let base = fit_base(&mut cx, calibrated)?;
    let fulls: Vec<FitTest> = prepared.iter().map(|p| p.full.clone()).collect();
    let base_on_all_rows = residuals(&fulls, &base.model, None);
    cx.features.unseen_noise = crate::features::unseen_noise_about(prepared, &base_on_all_rows);
    let localisation = localise(prepared, &base_on_all_rows);
    Ok(Based {
        cx,
        base,
        seated,
        bedding,
        fulls,
        localisation,
    })
}

/// What a diagnosis begins with: the events read one by one, the elastic stiffness it holds,
/// whether that stiffness is the velocity steps' springs (`fit` reads α_t off unloads and
/// reloads or tries it on the first loadings; the springs are the diagnosis's own reading), and
/// the base fitted with it ([`based_on_seated`]).
struct Begun<'a> {
    events: crate::events::EventAnalysis,
    stiffness: Option<subfric_reading::Stiffness>,
    alpha_from_steps: bool,
    based: Based<'a>,
}

/// Reads the events and fits the base ([`Begun`]). Where the record resolves α_t (unloads,
/// reloads) the events decide nothing the base's fits need (they seed the candidate forms,
/// next): the two run side by side, so a velocity step slow to fit no longer holds up the base
/// fit while the other cores wait. Each is computed as it would be alone.
fn events_and_based<'a>(
    prepared: &[PreparedTest],
    opts: &'a DiagnoseOptions,
    report: &'a (dyn Fn(Step) + Sync),
    run_counter: &RunCounter,
) -> Result<Begun<'a>, DiagnoseError> {
    let resolved = resolved_stiffness(prepared);
    if resolved.is_some() {
        let (events, based) = rayon::join(
            || crate::events::analyse(prepared, resolved.as_ref()),
            || based_on_seated(prepared, resolved.as_ref(), opts, report, run_counter),
        );
        // What `elastic_stiffness` decides when the record resolves α_t.
        return Ok(Begun {
            events,
            stiffness: resolved,
            alpha_from_steps: false,
            based: based?,
        });
    }
    let events = crate::events::analyse(prepared, None);
    let alpha_from_steps = events.stiffness().is_some();
    let mut stiffness = elastic_stiffness(prepared, None, &events, opts, run_counter);
    let mut based = based_on_seated(prepared, stiffness.as_ref(), opts, report, run_counter)?;
    // A rise that stiffens is a closure of the rig and reads no stiffness
    // (`subfric_reading::stiffness`): the closure first, then the spring. Where nothing decided
    // α_t and a bedding was taken out, α_t is tried again on the seated travel; where that
    // decides it, the bedding is read again from the travel as recorded against a base with
    // that spring (read against a rigid one, the closure had taken the spring's travel too,
    // and the spring then counted it twice).
    if stiffness.is_none() {
        if let Some(seated) = based.seated.clone() {
            let again = elastic_stiffness(
                &seated,
                resolved_stiffness(&seated),
                &events,
                opts,
                run_counter,
            );
            if let Some(found) = again {
                based = based_on_seated(prepared, Some(&found), opts, report, run_counter)?;
                stiffness = Some(found);
            }
        }
    }
    Ok(Begun {
        events,
        stiffness,
        alpha_from_steps,
        based,
    })
}

/// [`diagnose`](fn@diagnose), telling `report` where it is ([`Step`]) as it goes and counting
/// its model runs into `run_counter` (the caller's progress display reads them there).
pub fn diagnose_reporting(
    prepared: &[PreparedTest],
    opts: &DiagnoseOptions,
    report: &(dyn Fn(Step) + Sync),
    run_counter: &RunCounter,
) -> Result<Diagnosis, DiagnoseError> {
    if prepared.iter().all(|p| p.full.len() < MIN_ROWS) {
        return Err(DiagnoseError::TooLittleData);
    }
    let Begun {
        events,
        stiffness,
        alpha_from_steps,
        based:
            Based {
                mut cx,
                base,
                seated,
                bedding,
                fulls,
                localisation,
            },
    } = events_and_based(prepared, opts, report, run_counter)?;
    // The diagnosis runs on the tests with any bedding taken out.
    let prepared = seated.as_deref().unwrap_or(prepared);
    cx.features.seeds = events.seeds();
    cx.events = events.clone();

    let mut lib = library_with(&cx.features, &opts.with_families);
    lib.retain(|f| !opts.excluded_forms.iter().any(|x| x == f.name));
    cx.step(2, 0, lib.len());
    let (forms, families) = screen_and_polish(&cx, &base.model, &lib);
    let shortlist = shortlist(&forms, &lib, &events);
    cx.step(4, 0, opts.thresholds.max_effects);
    let selection = forward_selection(&cx, &base, &families, &shortlist, &forms);
    cx.step(5, 0, 0);

    let evidence = residual_evidence(
        prepared,
        &cx.pieces,
        &base.held,
        &fold_index(&cx),
        cx.features.v_ref,
        cx.features.p_ref,
    );
    let verdict = make_verdict(&cx, &base, &selection, &evidence);
    cx.trace("verdict and extra folds");

    let final_model = selection.current.model;
    let candidates: Vec<CandidateScore> = selection
        .stages
        .first()
        .map(|s| s.candidates.iter().chain(&s.drift).cloned().collect())
        .unwrap_or_default();
    Ok(Diagnosis {
        verdict,
        base: base_report(&cx, &fulls, &base, alpha_from_steps),
        data: cx.features.clone(),
        starts: test_starts(prepared),
        stiffness,
        bedding,
        prepared: prepared.to_vec(),
        localisation,
        events,
        forms,
        candidates,
        selection: selection.stages,
        dropped: selection.dropped,
        evidence,
        remaining_by_segment: localise(prepared, &residuals(&fulls, &final_model, None)).by_segment,
        final_read_off: subfric_reading::read_off(&fulls, &final_model),
        final_model,
        folds: cx.folds.iter().map(|f| f.name.clone()).collect(),
        pieces: pieces_by_kind(&cx),
        thresholds: opts.thresholds,
        excluded_forms: opts.excluded_forms.clone(),
        with_families: opts.with_families.clone(),
        elapsed_s: cx.started.elapsed().as_secs_f64(),
    })
}

/// Forms of each family that later selection stages refit on top of the model they reach:
/// the best [`SHORTLIST_PER_FAMILY`] of each family by their in-sample score on the base, and
/// the forms the events read one by one single out
/// ([`subfric_model::terms::TermEvidence::singled_out`]: every rate-and-state form when the
/// velocity steps agree on rate and state, healing erased by slip when the holds show peaks).
fn shortlist(
    forms: &[FormReport],
    lib: &[crate::Form],
    events: &crate::events::EventAnalysis,
) -> Vec<crate::Form> {
    let mut by_family: BTreeMap<crate::Effect, Vec<(f64, usize)>> = BTreeMap::new();
    for (i, f) in forms.iter().enumerate() {
        if f.ssr.is_finite() {
            by_family
                .entry(f.effect)
                .or_default()
                .push((f.in_sample_score, i));
        }
    }
    let mut keep: Vec<usize> = Vec::new();
    for mut ranked in by_family.into_values() {
        ranked.sort_by(|a, b| b.0.total_cmp(&a.0));
        keep.extend(
            ranked
                .into_iter()
                .take(SHORTLIST_PER_FAMILY)
                .map(|(_, i)| i),
        );
    }
    // And the forms a family's module says the events single out: every rate-and-state form
    // when the velocity steps agree on rate and state (on a base that lacks another effect they
    // may rank low, and the steps say they are the ones to try), healing erased by slip when
    // the holds show peaks, ...
    keep.extend(singled_out(lib, events));
    keep.sort_unstable();
    keep.dedup();
    keep.into_iter().map(|i| lib[i].clone()).collect()
}

/// The forms of `lib` (indices) that the events read one by one single out
/// ([`subfric_model::terms::TermEvidence::singled_out`]).
pub(super) fn singled_out(
    lib: &[crate::Form],
    events: &crate::events::EventAnalysis,
) -> Vec<usize> {
    let readings = events.readings();
    let mut out = Vec::new();
    for (family, fam) in subfric_model::terms::FAMILIES.iter().enumerate() {
        for form in fam.singled_out(&readings) {
            let name = fam.forms()[form].describe;
            out.extend((0..lib.len()).filter(|&i| {
                lib[i].effect == crate::Effect::Term(family as u8) && lib[i].name == name
            }));
        }
    }
    out
}

/// Forms per family kept for the later selection stages.
const SHORTLIST_PER_FAMILY: usize = 2;

/// The base fit as reported: its misfit on all rows of the record, per test and in total.
fn base_report(cx: &Context, fulls: &[FitTest], base: &Current, alpha_from_steps: bool) -> BaseFit {
    let rows: usize = fulls.iter().map(|t| t.len()).sum();
    let fitted_rows = cx.tests.iter().map(|t| t.len()).sum();
    let all_ssr = ssr_of(&residuals(fulls, &base.model, None));
    let reduced_chi2 = all_ssr / (rows as f64 - cx.base_free.len() as f64).max(1.0);
    let unlike_fit = context::unlike_fit(cx, rows, fitted_rows, alpha_from_steps, reduced_chi2);
    BaseFit {
        model: base.model,
        free: cx.base_free.iter().map(|p| p.key().to_string()).collect(),
        ssr: ssr_of(&cx.base_residuals),
        rows,
        fitted_rows,
        reduced_chi2,
        tests: misfits(fulls, &base.model),
        read_off: subfric_reading::read_off(fulls, &base.model),
        at_bounds: cx
            .space(&base.model, &crate::fits::Spec::base())
            .at_bounds(&base.model),
        unlike_fit,
    }
}

/// How each test starts (at rest, loaded, sliding) and its noise estimate.
fn test_starts(prepared: &[PreparedTest]) -> Vec<TestStart> {
    prepared
        .iter()
        .map(|p| TestStart {
            test: p.full.name.clone(),
            start: p.segmentation.start.kind,
            from_spec: p.segmentation.start.from_spec,
            reason: p.segmentation.start.reason.clone(),
            noise_sd: p.full.noise_sd,
            noise_floor: subfric_reading::estimate_noise(&p.full.time, &p.full.measured).floor,
            seating_toe: p.toe.clone(),
            normal_held: p.segmentation.normal.held_because().map(String::from),
        })
        .collect()
}

fn pieces_by_kind(cx: &Context) -> BTreeMap<String, usize> {
    let mut out: BTreeMap<String, usize> = BTreeMap::new();
    for p in &cx.pieces {
        *out.entry(p.kind.name().into()).or_default() += 1;
    }
    out
}
