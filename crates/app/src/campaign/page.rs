//! `campaign.html`: the campaign on one page — how many sets stand where, the table (the cells
//! of `campaign.md`, each set linked to its fit and its diagnosis's report), the sets without
//! results with why, and the summary figures embedded. Made from the same rows as the table,
//! so that whoever collected the results writes the same page.

use super::table::{self, Row, RowStatus};
use crate::render::html::{Cell, Page};
use anyhow::Result;
use std::path::{Path, PathBuf};

/// The campaign's page, beside `campaign.md`.
pub const PAGE: &str = "campaign.html";

/// The page of the campaign `title` in folder `out`: `figures` are the summary figures written
/// (PNG; the SVG beside each is embedded when there is one).
pub fn page(
    title: &str,
    out: &Path,
    rows: &[Row],
    diagnosed: bool,
    figures: &[PathBuf],
) -> Result<String> {
    let mut page = Page::new(&format!("Campaign {title}"));
    page.p(&table::counts(rows));
    page.link_line(
        "Files: ",
        &[
            ("campaign.csv", super::TABLE_CSV.to_string()),
            ("campaign.md", super::TABLE_MD.to_string()),
        ],
    );
    page.h2("table", "Every set");
    page.p(table::TABLE_LEGEND);
    let head = table::header(rows, diagnosed);
    let mut header: Vec<&str> = head.iter().map(String::as_str).collect();
    header.push("reports");
    let plain = |s: &str| s.to_string();
    let body = rows
        .iter()
        .map(|r| {
            let mut cells: Vec<Cell> = table::cells(r, rows, diagnosed, &plain)
                .into_iter()
                .enumerate()
                .map(|(k, c)| {
                    // The set, its soil and surface, the verdict and the status are words;
                    // the rest numbers.
                    if k == 0 || k == 1 || k == 3 || k + 2 >= head.len() {
                        Cell::Text(c)
                    } else {
                        Cell::Num(c)
                    }
                })
                .collect();
            cells.push(Cell::Links(reports(out, r)));
            cells
        })
        .collect();
    page.table(&header, body);
    let incomplete: Vec<String> = rows
        .iter()
        .filter(|r| r.status != RowStatus::Ok)
        .map(|r| {
            format!(
                "`{}` ({}): {}",
                r.set,
                r.status.text(),
                table::why_incomplete(r)
            )
        })
        .collect();
    if !incomplete.is_empty() {
        page.h2("incomplete", "Sets without results");
        page.list("", &incomplete);
    }
    if !figures.is_empty() {
        page.h2("figures", "Figures");
        for f in figures {
            let name = f
                .file_name()
                .map(|n| n.to_string_lossy().to_string())
                .unwrap_or_default();
            page.figure(f, &format!("`figures/{name}`"))?;
        }
    }
    Ok(page.finish())
}

/// The results of a set's folder that exist, to open from the page: (label, path relative
/// to the page) — its fit as text and JSON, its diagnosis's report when it was diagnosed.
fn reports(out: &Path, r: &Row) -> Vec<(String, String)> {
    let dir = Path::new(super::SETS_DIR).join(&r.set);
    [
        ("fit.txt", dir.join("fit.txt")),
        ("fit.json", dir.join("fit.json")),
        (
            "diagnosis",
            dir.join("diagnosis")
                .join(crate::render::report::REPORT_FILE),
        ),
    ]
    .into_iter()
    .filter(|(_, p)| out.join(p).is_file())
    .map(|(label, p)| (label.to_string(), p.display().to_string()))
    .collect()
}
