//! `report.html` of `subfric diagnose`, one self-contained page ([`crate::render::html`]) laid
//! out as the other reports ([`crate::render::report`]): the verdict first, where the base
//! misses, the selection, every figure, the readable report and the legend.

use crate::outcome::adequacy::{misfit_number, MISFIT_LEGEND};
use crate::render::html::{Cell, Mark, Page};
use crate::render::report::figures;
use anyhow::Result;
use std::path::{Path, PathBuf};
use subfric_diagnose::Diagnosis;

/// `report.html` of `subfric diagnose`: the verdict, where the base model misses, the
/// selection, every figure, and the readable report.
pub fn diagnosis_page(
    name: &str,
    set: &Path,
    d: &Diagnosis,
    text: &str,
    dir: &Path,
    plots: &[PathBuf],
) -> Result<String> {
    let mut page = Page::new(&format!("Diagnosis of {name}"));
    let base = crate::render::diagnose_report::base_adequacy(d);
    let mark = if d.verdict.effects.is_empty() {
        Mark::of(base.level)
    } else {
        Mark::of(crate::render::diagnose_report::final_adequacy(d).level)
    };
    page.verdict(mark, &crate::render::diagnose_report::verdict_lines(set, d));
    page.p(&d.verdict.explanation);
    page.link_line(
        "Files: ",
        &[
            ("diagnosis.json", "diagnosis.json".to_string()),
            ("diagnosis.txt", "diagnosis.txt".to_string()),
        ],
    );
    page.h2("where", "Where the base model misses");
    if !d.base.at_bounds.is_empty() {
        let hits: Vec<String> = d.base.at_bounds.iter().map(|b| b.sentence()).collect();
        page.p(&format!(
            "The base fit ended at a bound: {}. The box stopped it, not the data; its other parameters may make up for it, and every candidate is judged against this base.",
            hits.join(", ")
        ));
    }
    let mut groups = d.localisation.by_test_segment.clone();
    groups.sort_by(|a, b| b.share_of_gap.total_cmp(&a.share_of_gap));
    page.table(
        &[
            "test / segment",
            "rows",
            "misfit (× noise variance)",
            "share of the excess",
        ],
        groups
            .iter()
            .map(|g| {
                vec![
                    Cell::Text(g.group.clone()),
                    Cell::Num(g.rows.to_string()),
                    Cell::Num(misfit_number(g.reduced_chi2)),
                    Cell::Num(format!("{:.1} %", 100.0 * g.share_of_gap)),
                ]
            })
            .collect(),
    );
    selection_section(&mut page, d);
    page.h2("figures", "Figures");
    page.p("Per test: measured (dark markers), the base model, and the model with the named effects; then a zoom on every velocity step and hold; then the residual by segment and by test.");
    figures(&mut page, dir, plots)?;
    page.h2("report", "The whole report");
    page.pre(text);
    page.h2("how-to-read", "How to read the misfit");
    page.list("legend", &[MISFIT_LEGEND.to_string()]);
    Ok(page.finish())
}

/// The diagnosis page's section on the selection: each stage's candidates on the held-out
/// pieces and what it decided (the explanation alone where the data cannot be judged).
fn selection_section(page: &mut Page, d: &Diagnosis) {
    page.h2("selection", "Effects on data held out from the fit");
    let judged = d.verdict.effect != subfric_diagnose::Effect::CannotJudge;
    if !judged {
        page.p(&d.verdict.explanation);
    }
    for (k, st) in d.selection.iter().enumerate().filter(|_| judged) {
        page.h3(&format!(
            "Stage {}: added to {} (held-out misfit {}× the noise variance)",
            k + 1,
            st.reference,
            misfit_number(st.reference_chi2)
        ));
        let decided = crate::render::diagnose_report::decision_text(st.decision, k, &st.candidates);
        if st.candidates.is_empty() && st.drift.is_none() {
            // No candidate was left to try: the decision in words, not an empty table.
            page.p(&format!("→ {decided}"));
            continue;
        }
        page.table(
            &[
                "candidate",
                "evidence D",
                "excess removed",
                "misfit removed",
                "typical piece",
            ],
            st.candidates
                .iter()
                .chain(&st.drift)
                .map(|c| {
                    vec![
                        Cell::Text(c.spec.clone()),
                        Cell::Num(format!("{:.1}", c.held_out.score)),
                        Cell::Num(format!("{:.0} %", 100.0 * c.held_out.excess_shrink)),
                        Cell::Num(format!("{:.0} %", 100.0 * c.held_out.relative_shrink)),
                        Cell::Num(format!("{:.0} %", 100.0 * c.held_out.typical_shrink)),
                    ]
                })
                .collect(),
        );
        page.p(&format!("→ {decided}"));
    }
}
