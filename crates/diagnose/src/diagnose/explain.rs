//! The verdict and its explanation in words, with the extra checks of the named effects.

use super::context::{parameters_of, Context, Current};
use super::report::{NamedEffect, SelectionStage, Verdict};
use super::selection::Selection;
use crate::candidates::Effect;
use crate::confidence;
use crate::evidence::ResidualEvidence;
use crate::fits::{cross_validate, Spec};
use crate::folds::{extra_folds, Fold, Piece, PieceKind};
use crate::score::HeldOut;
use crate::verdict::Decision;
use subfric_model::Model;
use subfric_reading::FitTest;

/// Reduced χ² of the final model above which the explanation says part of the gap remains.
const REMAINING_GAP_CHI2: f64 = 2.0;

/// Share of the residual a feature must carry to count as support for the named effect.
const SUPPORTING_SHARE: f64 = 0.1;

/// The extra folds (the tail of each test, each test left out) and the base's held-out
/// residuals on them: the same for every named effect, so refitted once.
struct ExtraFolds {
    tail: Vec<Fold>,
    loto: Vec<Fold>,
    base_tail: Option<HeldOut>,
    base_loto: Option<HeldOut>,
    /// Each test as one piece: the shrinks are compared over whole tests.
    whole: Vec<Piece>,
}

impl ExtraFolds {
    fn new(cx: &Context, base: &Current) -> ExtraFolds {
        let (tail, loto) = extra_folds(&cx.tests, cx.opts.tail_fraction);
        let base_on = |folds: &[Fold]| {
            (!folds.is_empty())
                .then(|| extra_cv(cx, base, folds, &Spec::base(), &base.fit_tests, base.model))
        };
        let (base_tail, base_loto) = (base_on(&tail), base_on(&loto));
        let whole = cx
            .tests
            .iter()
            .enumerate()
            .map(|(i, t)| Piece::new(i, 0, t.len(), PieceKind::InitialLoading))
            .collect();
        ExtraFolds {
            tail,
            loto,
            base_tail,
            base_loto,
            whole,
        }
    }

    /// Shrink of `spec` against the base on the tail folds and on the leave-one-test-out
    /// folds (`None` where there are none).
    fn shrinks(
        &self,
        cx: &Context,
        base: &Current,
        spec: &Spec,
        model: &Model,
        fit_tests: &[FitTest],
    ) -> (Option<f64>, Option<f64>) {
        let shrink = |folds: &[Fold], b: &Option<HeldOut>| -> Option<f64> {
            let b = b.as_ref()?;
            let c = extra_cv(cx, base, folds, spec, fit_tests, *model);
            Some(cx.compare(&self.whole, b, &c).excess_shrink)
        };
        (
            shrink(&self.tail, &self.base_tail),
            shrink(&self.loto, &self.base_loto),
        )
    }
}

/// Held-out residuals of `spec` on `folds`, refitted from `start` on the base's space.
fn extra_cv(
    cx: &Context,
    base: &Current,
    folds: &[Fold],
    spec: &Spec,
    fit_tests: &[FitTest],
    start: Model,
) -> HeldOut {
    cross_validate(
        fit_tests,
        &cx.tests,
        folds,
        &cx.space(&base.model, spec),
        &[start],
        cx.opts.fold_iterations,
        false,
        &cx.run_counter,
    )
}

/// Step 5: the verdict on the selection, each named effect checked on the extra folds (the
/// tail of each test, each test left out).
pub(super) fn make_verdict(
    cx: &Context,
    base: &Current,
    selection: &Selection,
    evidence: &ResidualEvidence,
) -> Verdict {
    let held_rows: usize = cx
        .folds
        .iter()
        .map(|f| f.held_rows.iter().flatten().filter(|&&h| h).count())
        .sum();
    if held_rows == 0 {
        return nothing_held_out(cx);
    }
    let first = selection.stages.first();
    let base_chi2 = first.map_or(0.0, |s| s.reference_chi2);
    let flat = constant_chi2(&cx.tests);
    if flat <= cx.opts.thresholds.gap_chi2 && base_chi2 > flat {
        return no_response(base_chi2, flat);
    }
    let current = &selection.current;
    let effects = named_effects(cx, base, selection);
    let final_chi2 = cx
        .compare(&cx.pieces, &current.held, &current.held)
        .reference_chi2;
    let (effect, explanation) =
        effect_and_explanation(cx, &effects, first, (base_chi2, final_chi2), evidence);
    let evidence_supports = effects.first().map(|e| {
        evidence
            .features
            .iter()
            .take(2)
            .any(|f| f.family == Some(e.effect) && f.share > SUPPORTING_SHARE)
    });
    let mut verdict = Verdict {
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
        confidence: None,
        alternatives: Vec::new(),
        weighed: Vec::new(),
        without_first_loadings: None,
    };
    weigh_certainty(cx, selection, &mut verdict);
    verdict
}

/// The effects the selection named, each with its held-out comparison against the model before
/// it, its parameters in the final model and the extra held-out checks (tail, each test left
/// out).
fn named_effects(cx: &Context, base: &Current, selection: &Selection) -> Vec<NamedEffect> {
    let current = &selection.current;
    if selection.named.is_empty() {
        return Vec::new();
    }
    let extra = ExtraFolds::new(cx, base);
    selection
        .named
        .iter()
        .map(|s| {
            let (form, c, at) = (&s.form, &s.own, &s.at);
            let (tail, loto) = extra.shrinks(cx, base, &Spec::with(form), &at.model, &at.fit_tests);
            NamedEffect {
                effect: form.effect,
                form: form.name.to_string(),
                parameters: parameters_of(&current.model, std::slice::from_ref(form)),
                held_out_shrink: c.excess_shrink,
                relative_shrink: c.relative_shrink,
                typical_shrink: c.typical_shrink,
                score: c.score,
                tail_shrink: tail,
                leave_one_test_out_shrink: loto,
                shown_by_events: crate::events::shows(&cx.events, form.effect),
            }
        })
        .collect()
}

/// The verdict's first effect and the sentence that explains it: the effects named, or, when
/// none is, what the first stage `first` decided (no gap, a drift of the measurement, unexplained);
/// `(base_chi2, final_chi2)` the held-out misfits of the base and of the final model.
fn effect_and_explanation(
    cx: &Context,
    effects: &[NamedEffect],
    first: Option<&SelectionStage>,
    (base_chi2, final_chi2): (f64, f64),
    evidence: &ResidualEvidence,
) -> (Effect, String) {
    match (effects.first(), first.map(|s| s.decision)) {
        (Some(e), _) => (e.effect, explain_named(effects, base_chi2, final_chi2)),
        (None, Some(Decision::NoGap)) | (None, None) => (
            Effect::None,
            if base_chi2 > cx.opts.thresholds.gap_chi2 {
                format!(
                    "the base model predicts the held-out pieces at {base_chi2:.2}× the noise variance and no candidate explains the rest: the record's steady stretches scatter {:.2}× their white noise variance (noise correlated in time), so the gap is noise",
                    cx.features.unseen_noise
                )
            } else {
                format!(
                    "the base model predicts the held-out pieces at {base_chi2:.2}× the noise variance: the gap is noise"
                )
            },
        ),
        (None, Some(Decision::Drift)) => (
            Effect::Unexplained,
            format!(
                "the base misfit is {base_chi2:.2}× the noise variance; no physical candidate explains it, but a drift of the measurement (each test's zero drift linear in time, a creep of the load cell in proportion to its load) does better than all of them: the gap looks like a drift of the measurement, not friction; {}",
                evidence.summary
            ),
        ),
        (None, Some(_)) => (
            Effect::Unexplained,
            explain_unexplained(first, base_chi2, evidence),
        ),
    }
}

/// The verdict's confidence and its alternatives, weighed over the stages of the selection
/// (docs/diagnosis.md, "How sure"), with what the evidence points to without the first
/// loadings.
fn weigh_certainty(cx: &Context, selection: &Selection, verdict: &mut Verdict) {
    verdict.without_first_loadings = cx
        .pieces
        .iter()
        .any(|p| p.kind != PieceKind::InitialLoading)
        .then(|| confidence::without_first_loadings(&selection.stages, &cx.opts.thresholds));
    let options = confidence::options_of(&selection.stages, &cx.opts.thresholds);
    let certainty = confidence::certainty(
        confidence::weigh(options, confidence::TEMPERATURE),
        &verdict.named(),
        verdict.without_first_loadings.as_deref(),
    );
    verdict.confidence = Some(certainty.confidence);
    verdict.alternatives = certainty.alternatives;
    verdict.weighed = certainty.stages;
}

/// The misfit (× the noise variance, each test's own) of a constant per test: the mean of its
/// measured column. At the noise, the measured column does not follow the imposed one at all.
fn constant_chi2(tests: &[FitTest]) -> f64 {
    let (mut ssr, mut rows, mut means) = (0.0, 0.0, 0.0);
    for t in tests {
        let n = t.measured.len();
        let w: f64 = (0..n).map(|i| t.weight_of(i)).sum();
        if n == 0 || !(w > 0.0 && t.noise_sd > 0.0) {
            continue;
        }
        let mean = (0..n).map(|i| t.weight_of(i) * t.measured[i]).sum::<f64>() / w;
        ssr += (0..n)
            .map(|i| t.weight_of(i) * ((t.measured[i] - mean) / t.noise_sd).powi(2))
            .sum::<f64>();
        rows += w;
        means += 1.0;
    }
    if rows > means {
        ssr / (rows - means)
    } else {
        f64::INFINITY
    }
}

/// The verdict when the measured column is a constant plus noise in every test, which the
/// base model describes worse: there is no friction response to explain, and an effect named
/// would be fitted to noise (constant shear through a reversal is "explained" by a direction
/// effect, say). No effect is named or ruled out.
fn no_response(base_chi2: f64, flat: f64) -> Verdict {
    Verdict {
        effect: Effect::CannotJudge,
        held_out_shrink: 0.0,
        effects: Vec::new(),
        explanation: format!(
            "cannot judge: the measured column does not follow the imposed one: a constant per test describes it at {flat:.2}× the noise variance, the base model predicts the held-out pieces at {base_chi2:.2}×, so there is no friction response to explain and any effect named would be fitted to noise (is it the right column, in the right unit?)"
        ),
        extra_parameters: Default::default(),
        final_chi2: f64::NAN,
        evidence_supports: None,
        confidence: None,
        alternatives: Vec::new(),
        weighed: Vec::new(),
        without_first_loadings: None,
    }
}

/// The verdict when no row could be held out: no effect is named and none is ruled out, since
/// every judgement of the diagnosis is a prediction of held-out pieces; the misfit on held-out
/// data is not determined (NaN, `null` in diagnosis.json).
fn nothing_held_out(cx: &Context) -> Verdict {
    let pieces = cx.pieces.len();
    Verdict {
        effect: Effect::CannotJudge,
        held_out_shrink: 0.0,
        effects: Vec::new(),
        explanation: format!(
            "cannot judge: nothing held out: the set's {} test{} give{} {pieces} piece{} and no kind of piece occurs twice, so none can be predicted after a refit without it; the base model's misfit on all rows says whether it describes the data, not which effect it lacks (a second test of the same kind, or velocity steps, holds or reversals, give pieces to hold out)",
            cx.tests.len(),
            if cx.tests.len() == 1 { "" } else { "s" },
            if cx.tests.len() == 1 { "s" } else { "" },
            if pieces == 1 { "" } else { "s" },
        ),
        extra_parameters: Default::default(),
        final_chi2: f64::NAN,
        evidence_supports: None,
        confidence: None,
        alternatives: Vec::new(),
        weighed: Vec::new(),
        without_first_loadings: None,
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
            if e.shown_by_events {
                t.push_str(
                    " (the events read one by one show it outright, section 1b: each held-out piece of its kind predicted better suffices)",
                );
            }
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
    let far = if final_chi2 > REMAINING_GAP_CHI2 {
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
    stage: Option<&SelectionStage>,
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

#[cfg(test)]
mod tests {
    use super::super::context::tests::{quiet, shs_set};
    use super::*;
    use subfric_fit::RunCounter;
    use subfric_model::Params;

    /// The base's held-out residuals on the extra folds are refitted once and shared by every
    /// named effect: the base checked against itself shrinks nothing on either kind of fold (a
    /// tail fold's base set against a leave-one-test-out refit, or the other way, would not).
    #[test]
    fn the_base_against_itself_shrinks_nothing_on_either_kind_of_extra_fold() {
        let mut set = shs_set(120);
        let mut second = set.tests[0].clone();
        second.spec.name = "shs-2".into();
        set.meta.tests.push(second.spec.clone());
        set.tests.push(second);
        let prepared = crate::prepare_for_diagnosis(&set);
        let opts = crate::DiagnoseOptions::default();
        let (cx, _) = Context::new(&prepared, None, &opts, &quiet, &RunCounter::new());
        let model = Model::base(Params::sample()).unwrap();
        let base = Current {
            spec: Spec::base(),
            model,
            fit_tests: cx.tests.clone(),
            held: Vec::new(),
        };
        let extra = ExtraFolds::new(&cx, &base);
        assert_eq!((extra.tail.len(), extra.loto.len()), (2, 2));
        let (tail, loto) = extra.shrinks(&cx, &base, &Spec::base(), &model, &base.fit_tests);
        assert_eq!(tail, Some(0.0));
        assert_eq!(loto, Some(0.0));
    }
}
