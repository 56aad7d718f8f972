//! The terminal report of `subfric diagnose` (also written as diagnosis.txt): the verdict and
//! the next step first, then one section per step of the diagnosis. Every misfit is "× the
//! noise variance" ([`crate::outcome::adequacy`]).

use crate::outcome::adequacy::{misfit_number, Adequacy, MISFIT_LEGEND};
use crate::truncate;
use std::fmt::Write as _;
use std::path::Path;
use subfric_diagnose::confidence::Standing;
use subfric_diagnose::verdict::Decision;
use subfric_diagnose::{Diagnosis, NamedEffect};
use subfric_fit::localise::GroupMisfit;

/// Localised groups listed in section 1 (the largest shares of the gap first).
const WORST_GROUPS_SHOWN: usize = 8;

/// Width of the candidate column of section 3.
const CANDIDATE_WIDTH: usize = 58;

/// The terminal report of the diagnosis `d` of the set `name` read from `dir`, with its
/// verdict at further seeds (`replicates`) beside the verdict when they were run.
pub fn report_text(
    name: &str,
    dir: &Path,
    d: &Diagnosis,
    replicates: Option<&crate::replicates::Replicates>,
) -> String {
    let mut s = String::new();
    let mut lines = verdict_lines(dir, d);
    if let Some(r) = replicates {
        // Before the last line, "next: …": what the seeds say belongs to how sure the verdict is.
        let at = lines.len().saturating_sub(1);
        lines.insert(at, format!("replicates: {}", r.sentence));
    }
    for l in lines {
        let _ = writeln!(s, "{l}");
    }
    let _ = writeln!(s);
    header(&mut s, name, d);
    where_it_misses(&mut s, d);
    crate::render::events_report::events_section(&mut s, d);
    every_form(&mut s, d);
    held_out_selection(&mut s, d);
    let _ = writeln!(
        s,
        "\n4. what the held-out residual of the base model follows:"
    );
    let _ = writeln!(s, "   {}", d.evidence.summary);
    verdict(&mut s, d);
    let _ = writeln!(s, "how to read: {MISFIT_LEGEND}");
    let _ = write!(s, "({:.1} s)", d.elapsed_s);
    s
}

/// Does the base model describe the data (all rows), where it misses most.
pub fn base_adequacy(d: &Diagnosis) -> Adequacy {
    Adequacy::of_groups(d.base.reduced_chi2, &d.localisation.by_test_segment)
}

/// Does the model with the named effects describe the held-out data.
pub fn final_adequacy(d: &Diagnosis) -> Adequacy {
    Adequacy::of_groups(d.verdict.final_chi2, &d.remaining_by_segment)
}

/// The verdict in plain words and the next step, one line each ("verdict: …", "how sure: …",
/// "next: …"): whether the base model describes the data, which effect it lacks, whether the
/// model with it describes the held-out data, how sure that is (or what else the data allow),
/// and what to run next on the set in `dir`. The verdict leads with the word its confidence
/// earns ([`Standing`]): plain when confident, "probably" below, "uncertain" where the data give
/// the comparison's pick less than even odds — a user acts on the first words.
pub fn verdict_lines(dir: &Path, d: &Diagnosis) -> Vec<String> {
    let base = base_adequacy(d);
    let mut v = vec![format!("verdict: {}", base.sentence("the base model"))];
    let set = dir.display();
    let head = |stated: &str, uncertain: &str| lead(d.verdict.confidence, stated, uncertain);
    if d.verdict.effects.is_empty() {
        match d.verdict.effect {
            subfric_diagnose::Effect::None => v.push(format!(
                "verdict: {}: none of the candidate effects predicts held-out data better than the base model",
                head(
                    "no missing effect",
                    "no candidate effect is taken, and the data give \"none\" only"
                )
            )),
            subfric_diagnose::Effect::CannotJudge => v.push(format!(
                "verdict: {}",
                d.verdict.explanation
            )),
            _ => v.push(format!(
                "verdict: {}: none of the candidate effects explains the gap ({}); see section 5",
                head(
                    "unexplained",
                    "no candidate effect is taken, and the data give \"unexplained\" only"
                ),
                crate::outcome::adequacy::diagnosed_effects()
            )),
        }
        if let Some(sure) = d.verdict.certainty_sentence() {
            v.push(format!("how sure: {sure}"));
        }
        v.extend(first_loadings_line(d).filter(|l| l.contains("instead")));
        v.push(format!(
            "next: `subfric plan {set}` proposes the next test for the base model{}",
            if base.describes() {
                ""
            } else {
                " (it warns that the model does not describe the data)"
            }
        ));
        return v;
    }
    let label = effects_label(d);
    let with = final_adequacy(d);
    v.push(format!(
        "verdict: {}; {}",
        head(
            &format!("missing effect: {label}"),
            &format!(
                "the held-out comparison picks missing effect: {label}, and the data give it only"
            )
        ),
        with.sentence_on(
            &format!("the model with {label}"),
            "the data held out from its fit"
        )
    ));
    if let Some(sure) = d.verdict.certainty_sentence() {
        v.push(format!("how sure: {sure}"));
    }
    v.extend(first_loadings_line(d).filter(|l| l.contains("instead")));
    v.push(format!(
        "next: `subfric plan {set}` proposes the next test for the model with {label} (it reads this diagnosis)"
    ));
    v
}

/// The head of a verdict line by how it stands at `confidence` ([`Standing`]): `stated` as it
/// is when confident (or not judged), "probably `stated` (p %)" from [`PROBABLE`], and
/// "uncertain: `uncertain` p %" below it, where `uncertain` says what the comparison picked.
///
/// [`PROBABLE`]: subfric_diagnose::confidence::PROBABLE
fn lead(confidence: Option<f64>, stated: &str, uncertain: &str) -> String {
    let Some(c) = confidence else {
        return stated.to_string();
    };
    let p = 100.0 * c;
    match Standing::of(c) {
        Standing::Confident => stated.to_string(),
        Standing::Probable => format!("probably {stated} ({p:.0} %)"),
        Standing::Uncertain => format!("uncertain: {uncertain} {p:.0} %"),
    }
}

/// Whether the verdict holds with the first loadings left out (where a seating toe or a
/// compliant start lives), in words; `None` when that was not checked.
fn first_loadings_line(d: &Diagnosis) -> Option<String> {
    let without = d.verdict.without_first_loadings.as_ref()?;
    Some(
        if subfric_diagnose::confidence::same(without, &d.verdict.named()) {
            "first loadings left out: the held-out evidence of the other pieces points to the same verdict".to_string()
        } else {
            format!(
            "first loadings left out: the held-out evidence of the other pieces points to {} instead: the first loadings (seating, the elastic rise) weigh in this verdict",
            subfric_diagnose::confidence::label(without)
        )
        },
    )
}

/// The named effects joined with " + " (empty when none).
pub(crate) fn effects_label(d: &Diagnosis) -> String {
    d.verdict
        .effects
        .iter()
        .map(|e| e.effect.to_string())
        .collect::<Vec<_>>()
        .join(" + ")
}

fn row(s: &mut String, x: &GroupMisfit) {
    let _ = writeln!(
        s,
        "   {:<48} {:>6} rows  misfit {:>7}×  {:5.1}% of the excess",
        crate::visible(&x.group),
        x.rows,
        misfit_number(x.reduced_chi2),
        100.0 * x.share_of_gap
    );
}

/// A group's misfit without a share: for cuts of the rows other than the one the shares
/// partition (cycles, normal-stress levels), whose shares would not add up with those above.
fn row_without_share(s: &mut String, x: &GroupMisfit) {
    let _ = writeln!(
        s,
        "   {:<48} {:>6} rows  misfit {:>7}×",
        x.group,
        x.rows,
        misfit_number(x.reduced_chi2)
    );
}

fn parameter_list(parameters: &std::collections::BTreeMap<String, f64>) -> String {
    parameters
        .iter()
        .map(|(k, v)| format!("{k}={v:.4e}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Rows, how each test starts, the noise estimate when it is a floor, and the base fit.
fn header(s: &mut String, name: &str, d: &Diagnosis) {
    let p = &d.base.model.params;
    let _ = writeln!(
        s,
        "diagnosis of {}: {} rows{}",
        crate::visible(name),
        d.base.rows,
        if d.base.fitted_rows < d.base.rows {
            format!(
                ", fitted on {} bins (dense where the data change, thin in steady sliding)",
                d.base.fitted_rows
            )
        } else {
            String::new()
        }
    );
    for st in &d.starts {
        if !st.from_spec && st.start != subfric_reading::StartKind::Rest {
            let _ = writeln!(s, "   {}: {}", st.test, st.reason);
        }
        if let Some(toe) = &st.seating_toe {
            let _ = writeln!(s, "   {}: {}", st.test, toe.reason);
        }
        if let Some(why) = &st.normal_held {
            let _ = writeln!(s, "   {}: {why}", st.test);
        }
        if st.noise_floor {
            let _ = writeln!(
                s,
                "   {}: the noise estimate {:.3e} is the quantisation floor, not a measurement",
                st.test, st.noise_sd
            );
        }
    }
    if let Some(k) = &d.stiffness {
        let _ = writeln!(s, "   α_t fitted: {}", k.evidence);
    }
    for b in &d.bedding {
        let _ = writeln!(s, "   {}: {}", b.test, b.describe());
    }
    let _ = writeln!(
        s,
        "base model: misfit {}× the noise variance on all rows (μ_s {:.3}, μ_k {:.3}, κ {:.4}, ξ {:.3e}, ũ {:.3}, α_t {:.4})",
        misfit_number(d.base.reduced_chi2), p.mu_s, p.mu_k, p.kappa, p.xi, p.u_tilde, p.alpha_t
    );
    if !d.base.at_bounds.is_empty() {
        let hits: Vec<String> = d.base.at_bounds.iter().map(|b| b.sentence()).collect();
        let _ = writeln!(
            s,
            "   AT A BOUND: {} — the fit was stopped by its box, not by the data; its other parameters may make up for it, and every candidate below is judged against this base",
            hits.join(", ")
        );
    }
    if !d.base.unlike_fit.is_empty() {
        let _ = writeln!(
            s,
            "   unlike `subfric fit` on these data (so its parameters can differ): {}",
            d.base.unlike_fit.join("; ")
        );
    }
    read_off(s, "base model", &d.base.read_off);
    if d.final_model != d.base.model {
        read_off(s, "final model", &d.final_read_off);
    }
}

/// μ_s and μ_k of a model beside the peak and residual stress ratios the record shows.
fn read_off(s: &mut String, which: &str, r: &[subfric_reading::ReadOff]) {
    if r.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "   {which} read off the record (the paper's Section 5, item 2):"
    );
    for x in r {
        let _ = writeln!(s, "     {}", x.sentence());
    }
}

/// 1. Where the base misses, on all rows.
fn where_it_misses(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        s,
        "\n1. where the base model misses (all rows; misfit × the noise variance; share of the excess over the noise, per test and segment):"
    );
    // The excess of a sum of n squared unit normals has an SD of √(2n).
    if d.localisation.total_excess < 3.0 * (2.0 * d.base.rows as f64).sqrt() {
        let _ = writeln!(
            s,
            "   (the total excess over the noise is within its scatter: the shares below are of nothing significant)"
        );
    }
    let mut g = d.localisation.by_test_segment.clone();
    g.sort_by(|a, b| b.share_of_gap.total_cmp(&a.share_of_gap));
    for x in g.iter().take(WORST_GROUPS_SHOWN) {
        row(s, x);
    }
    if !d.localisation.by_cycle.is_empty() {
        let _ = writeln!(s, "   the same rows cut by cycle:");
        for x in &d.localisation.by_cycle {
            row_without_share(s, x);
        }
    }
    if d.localisation.by_normal_stress.len() > 1 {
        let _ = writeln!(s, "   the same rows cut by normal stress:");
        for x in &d.localisation.by_normal_stress {
            row_without_share(s, x);
        }
    }
}

/// 2. Every form of every family, in-sample.
fn every_form(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        s,
        "\n2. every form of every candidate family, fitted to all data (in-sample):"
    );
    if !d.excluded_forms.is_empty() {
        let _ = writeln!(
            s,
            "   left out on request (--without-form): {}",
            d.excluded_forms.join("; ")
        );
    }
    if !d.with_families.is_empty() {
        let _ = writeln!(
            s,
            "   tried on request beyond the default library (--with-family): {}",
            d.with_families.join(", ")
        );
    }
    let _ = writeln!(
        s,
        "   {:<15} {:<44} {:>10}  {:<10} parameters",
        "family", "form", "score", "fit"
    );
    let _ = writeln!(
        s,
        "   (fit: screened = ranked by a short fit on a share of the rows, behind the polished forms of its family; converged or settled = polished on all rows; off = polished, and the fit wants none of the effect on the base; NOT conv. = polished, stopped by its limit, not judged; ← best in-sample: of a family that acts on whole tests, every form is polished and its three best are predicted held out, and section 3 names the one that predicts the held-out tests best)"
    );
    for f in &d.forms {
        let _ = writeln!(
            s,
            "   {:<15} {:<44} {:>10.1}  {:<10} {}{}{}",
            f.effect.name(),
            f.form,
            f.in_sample_score,
            if !f.polished {
                "screened"
            } else if f.switched_off {
                "off"
            } else if f.converged {
                "converged"
            } else if f.settled {
                "settled"
            } else {
                "NOT conv."
            },
            parameter_list(&f.parameters),
            // A form only screened was ranked, not judged: nothing to say why it stopped.
            if !f.polished || f.converged || f.settled {
                String::new()
            } else {
                format!("  (stopped: {}; not judged)", f.termination)
            },
            if f.chosen {
                "  ← best in-sample of its family"
            } else {
                ""
            }
        );
    }
}

/// 3. The forward selection on held-out pieces, stage by stage, and the backward step.
fn held_out_selection(s: &mut String, d: &Diagnosis) {
    let counts: Vec<String> = d.pieces.iter().map(|(k, n)| format!("{n} {k}")).collect();
    if d.verdict.effect == subfric_diagnose::Effect::CannotJudge {
        let _ = writeln!(
            s,
            "\n3. held out: pieces ({}) left out in {} folds; no candidate is judged: {}",
            counts.join(", "),
            d.folds.len(),
            d.verdict.explanation
        );
        return;
    }
    let _ = writeln!(
        s,
        "\n3. held out: pieces ({}) left out in {} folds, each predicted after refitting without it",
        counts.join(", "),
        d.folds.len()
    );
    for (k, st) in d.selection.iter().enumerate() {
        let _ = writeln!(
            s,
            "   stage {}: added to {} (held-out misfit {}× the noise variance)",
            k + 1,
            st.reference,
            misfit_number(st.reference_chi2)
        );
        let _ = writeln!(
            s,
            "     {:<CANDIDATE_WIDTH$} {:>10} {:>9} {:>9} {:>9}",
            "candidate", "evidence D", "excess", "relative", "typical"
        );
        for c in st.candidates.iter().chain(&st.drift) {
            let _ = writeln!(
                s,
                "     {:<CANDIDATE_WIDTH$} {:>10.1} {:>8.0}% {:>8.0}% {:>8.0}%",
                truncate(
                    &if k == 0 {
                        c.spec.clone()
                    } else {
                        added_label(&c.spec, &st.reference)
                    },
                    CANDIDATE_WIDTH
                ),
                c.held_out.score,
                100.0 * c.held_out.excess_shrink.max(-9.99),
                100.0 * c.held_out.relative_shrink.max(-9.99),
                100.0 * c.held_out.typical_shrink.max(-9.99),
            );
        }
        let _ = writeln!(
            s,
            "     → {}",
            decision_text(st.decision, k, &st.candidates)
        );
        if let (Decision::Named(i) | Decision::Tentative(i), Some(drift)) = (st.decision, &st.drift)
        {
            if subfric_diagnose::verdict::drift_outweighs(
                &drift.held_out,
                &st.candidates[i].held_out,
            ) {
                // Only the fact: the effect can be taken here because another candidate is not
                // outweighed, or because the effects taken after it outweigh the drift together.
                let _ = writeln!(
                    s,
                    "       the drift of the measurement outweighs this effect alone (D {:.1} against {:.1}); section 5 says what is named",
                    drift.held_out.score, st.candidates[i].held_out.score
                );
            }
        }
        if let Decision::Named(i) | Decision::Tentative(i) = st.decision {
            for x in &st.candidates[i].by_kind {
                let _ = writeln!(
                    s,
                    "       {:<18} {:>6} rows  misfit {:>7} → {:>7}× the noise variance ({:+.0}% of its misfit)",
                    x.kind,
                    x.rows,
                    misfit_number(x.reference_chi2),
                    misfit_number(x.candidate_chi2),
                    -100.0 * x.shrink
                );
            }
        }
    }
    for x in &d.dropped {
        let _ = writeln!(
            s,
            "   backward step: {} ({}) dropped — the effects after it explain the gap without it (evidence D = {:.1} given them)",
            x.effect, x.form, x.score_given_the_others
        );
    }
}

pub(crate) fn decision_text(
    decision: Decision,
    stage: usize,
    candidates: &[subfric_diagnose::diagnose::CandidateScore],
) -> String {
    match decision {
        Decision::Named(i) => format!("selected: {}", candidates[i].spec),
        Decision::Tentative(i) => format!(
            "selected tentatively (significant, too little on its own): {}",
            candidates[i].spec
        ),
        Decision::NoGap if stage == 0 => "nothing to explain: the base fits at the noise".into(),
        Decision::NoGap => "nothing left to explain".into(),
        Decision::Drift => "a drift of the measurement explains more than any candidate".into(),
        Decision::Unexplained if stage == 0 => "no candidate explains enough".into(),
        Decision::Unexplained => "no further effect".into(),
    }
}

/// 5. The verdict with each named effect's parameters and extra checks.
fn verdict(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        s,
        "\n5. verdict: {}",
        if d.verdict.effects.is_empty() {
            d.verdict.effect.to_string()
        } else {
            effects_label(d)
        }
    );
    for e in &d.verdict.effects {
        named_effect(s, e);
    }
    let _ = writeln!(s, "   {}", d.verdict.explanation);
    if let Some(sure) = d.verdict.certainty_sentence() {
        let _ = writeln!(s, "   how sure: {sure}");
        if let Some(line) = first_loadings_line(d) {
            let _ = writeln!(s, "   {line}");
        }
        for a in &d.verdict.alternatives {
            let _ = writeln!(
                s,
                "   or {} ({:.0} %): {}",
                a.label,
                100.0 * a.probability,
                a.tell_apart
            );
        }
    }
    if let Some(sup) = d.verdict.evidence_supports {
        let _ = writeln!(
            s,
            "   the residual evidence {} this",
            if sup {
                "supports"
            } else {
                "does not single out"
            }
        );
    }
}

fn named_effect(s: &mut String, e: &NamedEffect) {
    let _ = writeln!(
        s,
        "   {} — {}: {}",
        e.effect,
        e.form,
        parameter_list(&e.parameters)
    );
    let checks: Vec<String> = [
        ("tail of each test", e.tail_shrink),
        ("each test left out", e.leave_one_test_out_shrink),
    ]
    .iter()
    .filter_map(|(n, v)| v.map(|v| format!("{n}: {:.0}%", 100.0 * v)))
    .collect();
    if !checks.is_empty() {
        let _ = writeln!(
            s,
            "     extra held-out checks (share of the excess removed) — {}",
            checks.join(", ")
        );
    }
}

/// A candidate of a later selection stage named by what it adds: its spec is the stage's
/// reference followed by " + " and the added form, and the reference alone, cut to the
/// column's width, would make every row of the stage read the same.
fn added_label(spec: &str, reference: &str) -> String {
    match spec
        .strip_prefix(reference)
        .and_then(|rest| rest.strip_prefix(" + "))
    {
        Some(added) => format!("+ {added}"),
        None => spec.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::{added_label, lead};

    #[test]
    fn a_verdict_line_leads_with_the_word_its_confidence_earns() {
        let head = |c| lead(c, "missing effect: rate", "the comparison picks rate, only");
        assert_eq!(head(Some(0.93)), "missing effect: rate");
        assert_eq!(head(None), "missing effect: rate");
        assert_eq!(head(Some(0.72)), "probably missing effect: rate (72 %)");
        assert_eq!(head(Some(0.5)), "probably missing effect: rate (50 %)");
        assert_eq!(
            head(Some(0.02)),
            "uncertain: the comparison picks rate, only 2 %"
        );
    }

    #[test]
    fn a_later_stages_candidate_is_labelled_by_the_form_it_adds() {
        let reference = "pressure (power law on mu_s and mu_k, each its own beta)";
        let spec = format!("{reference} + log-healing (log time at rest)");
        assert_eq!(
            added_label(&spec, reference),
            "+ log-healing (log time at rest)"
        );
        // A spec that does not extend the reference keeps its own name.
        assert_eq!(
            added_label("rate (direct effect)", reference),
            "rate (direct effect)"
        );
    }
}
