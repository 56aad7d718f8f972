//! The HTML reports: `report.html` of `fit` and `plan` in their output folders (`diagnose`'s
//! is [`crate::render::diagnosis_page`], so that a fit's page is made without the diagnosis),
//! and `fits/index.html` of `reproduce`. Each is one self-contained page ([`crate::render::html`]):
//! the verdict first (does the model describe the data, what to do next), then the tables,
//! every figure the job wrote, the legend of the notation, and the next test.

use crate::outcome::adequacy::{misfit_number, next_steps};
use crate::outcome::plan_basis::Basis;
use crate::outcome::FitOutcome;
use crate::render::fit_report::{
    determined_combinations, difference_text, estimate_interval_text, legend_items, std_error_text,
    value_text, verdict_lines,
};
use crate::render::html::{Cell, Mark, Page};
use anyhow::Result;
use std::path::{Path, PathBuf};
use subfric_design::Plan;
use subfric_fit::interval::short_number as num;
use subfric_fit::FitReport;

/// The file name of a report in its output folder.
pub const REPORT_FILE: &str = "report.html";

/// The figure's caption: its file name relative to the report's folder.
fn caption(dir: &Path, f: &Path) -> String {
    f.strip_prefix(dir).unwrap_or(f).display().to_string()
}

/// The parameter table of a fit.
fn parameter_rows(r: &FitReport) -> Vec<Vec<Cell>> {
    r.parameters
        .iter()
        .map(|p| {
            vec![
                Cell::Text(if p.unit.is_empty() {
                    p.name.clone()
                } else {
                    format!("{} [{}]", p.name, p.unit)
                }),
                Cell::Num(value_text(p, num)),
                Cell::Num(std_error_text(p, num)),
                Cell::Num(estimate_interval_text(p)),
                Cell::Text(p.status.describe().to_string()),
                Cell::Num(p.published.map(num).unwrap_or_default()),
                Cell::Num(difference_text(p)),
            ]
        })
        .collect()
}

const PARAMETER_HEADER: [&str; 7] = [
    "parameter",
    "value",
    "± s.e.",
    "95 % interval",
    "identifiability",
    "published",
    "difference",
];

/// Parameters, the combinations the data determine, the misfit per test.
fn fit_tables(page: &mut Page, r: &FitReport) {
    page.table(&PARAMETER_HEADER, parameter_rows(r));
    let combos = determined_combinations(r);
    if !combos.is_empty() {
        page.h3("Combinations the data determine");
        page.table(
            &["combination", "value", "95 % interval"],
            combos
                .iter()
                .map(|c| {
                    vec![
                        Cell::Text(c.name.clone()),
                        Cell::Num(num(c.value)),
                        Cell::Num(c.interval.map(|i| i.to_string()).unwrap_or_default()),
                    ]
                })
                .collect(),
        );
    }
    page.h3("Misfit per test");
    page.table(
        &[
            "test",
            "rows",
            "RMS",
            "% of scale",
            "misfit (× noise variance)",
        ],
        r.tests
            .iter()
            .map(|t| {
                vec![
                    Cell::Text(t.name.clone()),
                    Cell::Num(t.rows.to_string()),
                    Cell::Num(format!("{} {}", num(t.rms), t.unit)),
                    Cell::Num(format!("{:.2}", t.rms_percent)),
                    Cell::Num(misfit_number(t.reduced_chi2)),
                ]
            })
            .collect(),
    );
}

/// The legend of intervals and misfit.
fn legend(page: &mut Page) {
    page.h2("how-to-read", "How to read the tables");
    let items: Vec<String> = legend_items().iter().map(|s| s.to_string()).collect();
    page.list("legend", &items);
}

/// Every figure in `figures`, captioned by its path relative to `dir`.
pub(super) fn figures(page: &mut Page, dir: &Path, figures: &[PathBuf]) -> Result<()> {
    for f in figures {
        page.figure(f, &caption(dir, f))?;
    }
    Ok(())
}

/// `report.html` of `subfric fit`: verdict, next steps, tables, figures, legend.
pub fn fit_page(out: &FitOutcome, dir: &Path, plots: &[PathBuf]) -> Result<String> {
    let mut page = Page::new(&format!("Fit of {}", out.name));
    page.verdict(Mark::of(out.adequacy.level), &verdict_lines(out));
    page.link_line(
        "Files: ",
        &[
            ("fit.json", "fit.json".to_string()),
            ("fit.txt", "fit.txt".to_string()),
        ],
    );
    page.h2("parameters", "Parameters");
    fit_tables(&mut page, &out.report);
    page.h2("figures", "Measured and fitted");
    page.p("Data: dark markers over a light line through every point; the models beneath them; the residual below. A zoom shows the first loading of a monotonic test, and a traction-controlled test shows the traction the rig imposed.");
    figures(&mut page, dir, plots)?;
    legend(&mut page);
    Ok(page.finish())
}

/// `report.html` of `subfric plan`: the verdict on the model planned on, the next test, the
/// ranking, the check, the figure, the legend.
pub fn plan_page(
    out: &FitOutcome,
    basis: &Basis,
    set: &Path,
    p: &Plan,
    text: &str,
    dir: &Path,
    plots: &[PathBuf],
) -> Result<String> {
    let mut page = Page::new(&format!("Next test for {}", out.name));
    let mut lines = vec![format!(
        "verdict: {}",
        out.adequacy.sentence(&basis.model_words())
    )];
    if let Some(w) = crate::outcome::plan_basis::misfit_warning(&out.adequacy, basis, set) {
        lines.push(format!("warning: {w}"));
    }
    lines.push(basis.line());
    if !out.adequacy.describes() {
        lines.extend(basis.must_change_lines());
    }
    page.verdict(Mark::of(out.adequacy.level), &lines);
    let mut links = vec![
        ("plan.json", "plan.json".to_string()),
        ("plan.txt", "plan.txt".to_string()),
    ];
    if let Some(top) = p.top() {
        page.h2("next", "The next test");
        page.p(&format!(
            "{}, {:.2} h of lab time: {}.",
            top.name, top.hours, top.description
        ));
        links.push(("its scenario", format!("scenarios/{}.json", top.name)));
    }
    page.link_line("Files: ", &links);
    page.h2("ranking", "Proposals, ranked");
    page.table(
        &[
            "rank",
            "proposal",
            "lab h",
            "determines",
            "shrink",
            "score",
            "still undetermined",
        ],
        p.proposals
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let left: Vec<&str> = q
                    .predicted
                    .iter()
                    .filter(|x| !x.determined)
                    .map(|x| x.name.as_str())
                    .collect();
                vec![
                    Cell::Num(if q.narrows {
                        (i + 1).to_string()
                    } else {
                        "— (narrows nothing)".to_string()
                    }),
                    Cell::Text(q.name.clone()),
                    Cell::Num(format!("{:.2}", q.hours)),
                    Cell::Num(format!("{:.0} %", 100.0 * q.determines_share)),
                    Cell::Num(format!("{:.1}×", q.shrink)),
                    Cell::Num(format!("{:.3}", q.score)),
                    Cell::Text(if left.is_empty() {
                        "none".into()
                    } else {
                        left.join(", ")
                    }),
                ]
            })
            .collect(),
    );
    if !p.rejected.is_empty() {
        page.list(
            "",
            &p.rejected
                .iter()
                .map(|(n, why)| format!("not proposed: {n}: {why}"))
                .collect::<Vec<_>>(),
        );
    }
    page.h2("figures", "The next test, predicted");
    figures(&mut page, dir, plots)?;
    page.h2("plan", "The whole plan");
    page.pre(text);
    legend(&mut page);
    Ok(page.finish())
}

/// One set of `reproduce`: what `fits/index.html` shows of it.
pub struct IndexEntry<'a> {
    /// Set folder name under fits/.
    pub name: &'a str,
    /// The paper table it belongs to.
    pub table: &'a str,
    /// The fit.
    pub outcome: &'a FitOutcome,
    /// The next test, in words.
    pub next: Option<String>,
    /// Its figures (absolute or relative to the current folder).
    pub figures: Vec<PathBuf>,
}

/// `fits/index.html` of `subfric reproduce`: every set's verdict, table and figures, its next
/// test, and the legend.
pub fn index_page(out: &Path, sets: &[IndexEntry]) -> Result<String> {
    let mut page = Page::new("Fitted parameters beside the published values");
    page.p("Written by `subfric reproduce`: each set of `experiments/` fitted from informed first guesses, a global search and least-squares polish; 95 % profile intervals.");
    page.link_line(
        "The same as Markdown: ",
        &[("README.md", "README.md".to_string())],
    );
    legend(&mut page);
    let mut tables: Vec<&str> = sets.iter().map(|s| s.table).collect();
    tables.dedup();
    for table in tables {
        page.h2(&anchor(table), table);
        for s in sets.iter().filter(|s| s.table == table) {
            page.h3(s.name);
            let a = &s.outcome.adequacy;
            let mut lines = vec![format!("verdict: {}", a.sentence("the model"))];
            lines.extend(
                next_steps(a, &s.outcome.report, &s.outcome.dirs)
                    .into_iter()
                    .map(|n| format!("next: {n}")),
            );
            page.verdict(Mark::of(a.level), &lines);
            page.link_line(
                "Files: ",
                &[
                    ("fit.json", format!("{}/fit.json", s.name)),
                    ("fit.txt", format!("{}/fit.txt", s.name)),
                ],
            );
            fit_tables(&mut page, &s.outcome.report);
            if let Some(n) = &s.next {
                page.p(n);
            }
            figures(&mut page, out, &s.figures)?;
        }
    }
    Ok(page.finish())
}

/// An id for a heading: lower case, letters and digits, dashes between.
fn anchor(s: &str) -> String {
    let mut out = String::new();
    for c in s.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.ends_with('-') {
            out.push('-');
        }
    }
    out.trim_matches('-').to_string()
}
