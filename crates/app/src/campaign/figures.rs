//! The campaign's summary figures: μ_s and μ_k with their 95 % profile intervals against the
//! normalised roughness R_max/D50 (the classic design chart of interface friction) and against
//! the normal stress, and the diagnosis's verdict per set.
//!
//! With more than [`STRESS_RANGES`] fitted sets, the normal-stress figure leaves out the bars
//! over each set's range of normal stresses (hundreds of them across one span hide the points).
//! The verdict figure names each set on its axis; past [`VERDICT_PAGE`] sets the names no longer
//! fit, so a larger campaign gets an overview by verdict (`verdicts.png`: per verdict, how many
//! sets, the median share of the misfit removed and the middle half of the sets) and the sets
//! by name, each with its verdict, on pages of [`VERDICT_PAGE`] (`verdicts-01.png`, ...), in
//! the table's order.

use super::table::{ParamCell, Row, RowStatus};
use anyhow::Result;
use std::path::{Path, PathBuf};
use subfric_plot::{write_figure, IntervalEnd, IntervalFigure, IntervalPoint};

/// The figure of μ against R_max/D50.
pub const ROUGHNESS_FIGURE: &str = "mu-vs-roughness.png";
/// The figure of μ against the normal stress.
pub const STRESS_FIGURE: &str = "mu-vs-normal-stress.png";
/// The figure of the verdicts (with more than [`VERDICT_PAGE`] diagnosed sets, the overview
/// by verdict; the sets by name on its pages, [`verdict_page`]).
pub const VERDICT_FIGURE: &str = "verdicts.png";

/// Fitted sets up to which the normal-stress figure draws each set's range of normal stresses
/// (past it, only their medians: the ranges are in the table).
pub const STRESS_RANGES: usize = 40;

/// Sets named on one verdict figure: their names stay readable (upright when they must be).
pub const VERDICT_PAGE: usize = 40;

/// Page `page` (from 1) of the verdict figure of a campaign of more than [`VERDICT_PAGE`]
/// diagnosed sets.
pub fn verdict_page(page: usize) -> String {
    format!("verdicts-{page:02}.png")
}

/// A parameter's point at `x`: its value and interval (open ends drawn open).
fn point(c: &ParamCell, x: f64, x_range: Option<(f64, f64)>) -> IntervalPoint {
    let end = |v: Option<f64>, open: bool| match (v, open) {
        (_, true) => IntervalEnd::Open,
        (Some(v), false) => IntervalEnd::At(v),
        (None, false) => IntervalEnd::Absent,
    };
    IntervalPoint {
        x,
        y: c.value,
        lo: end(c.lo, c.lo_open),
        hi: end(c.hi, c.hi_open),
        x_range,
    }
}

/// μ_s and μ_k of the fitted rows at the x each row gives (rows without one are left out);
/// the title says how many sets are shown.
fn mu_figure(
    rows: &[Row],
    what: &str,
    x_label: &str,
    x_of: impl Fn(&Row) -> Option<(f64, Option<(f64, f64)>)>,
    missing: &str,
) -> IntervalFigure {
    let fitted: Vec<&Row> = rows.iter().filter(|r| r.status == RowStatus::Ok).collect();
    let mut groups = [("μ_s", "mu_s"), ("μ_k", "mu_k")].map(|(label, key)| (label, key, vec![]));
    let mut shown = 0;
    for r in &fitted {
        let Some((x, range)) = x_of(r) else { continue };
        shown += 1;
        for (_, key, points) in groups.iter_mut() {
            if let Some(c) = r.parameter(key) {
                points.push(point(c, x, range));
            }
        }
    }
    let left_out = fitted.len() - shown;
    let mut title = format!("μ_s and μ_k against {what}: {shown} of {} sets", rows.len());
    if left_out > 0 {
        title.push_str(&format!(" ({left_out} give no {missing})"));
    }
    let mut fig = IntervalFigure::new(title, x_label, "friction coefficient [-]");
    for (label, _, points) in groups {
        fig = fig.with_group(format!("{label} (95 % profile interval)"), points);
    }
    fig
}

/// The verdict per diagnosed set: the held-out shrink of the misfit its verdict gives, one
/// colour per verdict.
fn verdict_figure(rows: &[Row], title: String) -> IntervalFigure {
    let mut fig = IntervalFigure::new(
        title,
        "",
        "held-out misfit removed by the verdict's effect [%]",
    )
    .with_categories(rows.iter().map(|r| r.set.clone()).collect());
    fig.y_include = vec![0.0, 100.0];
    for v in verdicts(rows) {
        let points = rows
            .iter()
            .enumerate()
            .filter(|(_, r)| verdict_of(r).as_ref() == Some(&v))
            .map(|(i, r)| IntervalPoint::at(i as f64, 100.0 * r.held_out_shrink.unwrap_or(0.0)))
            .collect();
        fig = fig.with_group(v, points);
    }
    fig
}

/// A page of a large campaign's verdicts: each set named with its verdict, its point in one
/// colour at its name (groups of colours would be drawn side by side, off their names, once
/// many verdicts share a narrow slot).
fn verdict_page_figure(rows: &[Row], title: String) -> IntervalFigure {
    let labels = rows
        .iter()
        .map(|r| match &r.verdict {
            Some(v) => format!("{} · {v}", r.set),
            None => format!("{} · not diagnosed", r.set),
        })
        .collect();
    let mut fig = IntervalFigure::new(
        title,
        "set · verdict",
        "held-out misfit removed by the verdict's effect [%]",
    )
    .with_categories(labels);
    fig.y_include = vec![0.0, 100.0];
    let points = rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.verdict.is_some())
        .map(|(i, r)| IntervalPoint::at(i as f64, 100.0 * r.held_out_shrink.unwrap_or(0.0)))
        .collect();
    fig.with_group("", points)
}

/// The verdict of `row` as the figures group it: its effects in alphabetical order. The table
/// keeps the diagnosis's order (the effect named first explained most), but "pressure +
/// log-healing" and "log-healing + pressure" are one verdict, not two groups.
fn verdict_of(row: &Row) -> Option<String> {
    row.verdict.as_deref().map(|v| {
        let mut effects: Vec<&str> = v.split(" + ").map(str::trim).collect();
        effects.sort_unstable();
        effects.join(" + ")
    })
}

/// The verdicts of the campaign ([`verdict_of`]), sorted.
fn verdicts(rows: &[Row]) -> Vec<String> {
    let mut v: Vec<String> = rows.iter().filter_map(verdict_of).collect();
    v.sort();
    v.dedup();
    v
}

use subfric_reading::stats::quantile;

/// The overview of a large campaign's verdicts: per verdict, its sets counted, the median
/// share of the held-out misfit removed and the bar from the first to the third quartile.
fn verdict_overview(rows: &[Row], pages: usize) -> IntervalFigure {
    let diagnosed = rows.iter().filter(|r| r.verdict.is_some()).count();
    let verdicts = verdicts(rows);
    let labels = verdicts
        .iter()
        .map(|v| {
            let n = rows
                .iter()
                .filter(|r| verdict_of(r).as_ref() == Some(v))
                .count();
            format!("{v} ({n})")
        })
        .collect();
    let mut fig = IntervalFigure::new(
        format!(
            "Diagnosis by verdict: {diagnosed} of {} sets diagnosed (each set by name: {} to {})",
            rows.len(),
            verdict_page(1),
            verdict_page(pages)
        ),
        "verdict (sets)",
        "held-out misfit removed [%] (median, bar: middle half)",
    )
    .with_categories(labels);
    fig.y_include = vec![0.0, 100.0];
    let points = verdicts
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let mut shrink: Vec<f64> = rows
                .iter()
                .filter(|r| verdict_of(r).as_ref() == Some(v))
                .map(|r| 100.0 * r.held_out_shrink.unwrap_or(0.0))
                .collect();
            shrink.sort_by(f64::total_cmp);
            IntervalPoint {
                x: i as f64,
                y: quantile(&shrink, 0.5),
                lo: IntervalEnd::At(quantile(&shrink, 0.25)),
                hi: IntervalEnd::At(quantile(&shrink, 0.75)),
                x_range: None,
            }
        })
        .collect();
    // One colour: the verdicts are named on the axis (groups would be drawn side by side).
    fig.with_group("", points)
}

/// The verdict figures of `rows` with their file names: one figure naming every set, or for a
/// campaign of more than [`VERDICT_PAGE`] sets the overview and the pages.
fn verdict_figures(rows: &[Row]) -> Vec<(String, IntervalFigure)> {
    let diagnosed = rows.iter().filter(|r| r.verdict.is_some()).count();
    if rows.len() <= VERDICT_PAGE {
        let title = format!(
            "Diagnosis per set: {diagnosed} of {} sets diagnosed",
            rows.len()
        );
        return vec![(VERDICT_FIGURE.into(), verdict_figure(rows, title))];
    }
    let pages = rows.len().div_ceil(VERDICT_PAGE);
    let mut figures = vec![(VERDICT_FIGURE.into(), verdict_overview(rows, pages))];
    for (k, page) in rows.chunks(VERDICT_PAGE).enumerate() {
        let first = k * VERDICT_PAGE + 1;
        let title = format!(
            "Diagnosis per set: sets {first}–{} of {} (page {} of {pages})",
            first + page.len() - 1,
            rows.len(),
            k + 1
        );
        figures.push((verdict_page(k + 1), verdict_page_figure(page, title)));
    }
    figures
}

/// Removes the verdict figures in `dir` that are not in `keep` (a campaign's figures are those
/// of its table: fewer sets, or none diagnosed, leave no old page behind).
fn remove_old_verdicts(dir: &Path, keep: &[PathBuf]) -> Result<()> {
    let entries = std::fs::read_dir(dir)
        .map_err(|e| anyhow::anyhow!("{}: cannot read the folder: {e}", dir.display()))?;
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        // Each figure is written as PNG and SVG: both are ours, kept or removed together.
        let Some(stem) = name
            .strip_suffix(".png")
            .or_else(|| name.strip_suffix(".svg"))
        else {
            continue;
        };
        let ours = stem == VERDICT_FIGURE.trim_end_matches(".png")
            || stem
                .strip_prefix("verdicts-")
                .is_some_and(|n| !n.is_empty() && n.chars().all(|c| c.is_ascii_digit()));
        let f = e.path();
        if ours && !keep.contains(&f.with_extension("png")) {
            std::fs::remove_file(&f)
                .map_err(|e| anyhow::anyhow!("{}: cannot remove: {e}", f.display()))?;
        }
    }
    Ok(())
}

/// μ against the normal stress: a set tested at several at their median, with a bar over
/// their range while the campaign has at most [`STRESS_RANGES`] fitted sets.
fn stress_figure(rows: &[Row]) -> IntervalFigure {
    // The range bars of hundreds of sets tested over one span would stripe the whole figure.
    let ranges = rows.iter().filter(|r| r.status == RowStatus::Ok).count() <= STRESS_RANGES;
    mu_figure(
        rows,
        "normal stress",
        if ranges {
            "normal stress σ_n [kPa] (a set tested at several: their median, the bar their range)"
        } else {
            "normal stress σ_n [kPa] (a set tested at several: their median; their range is in the table)"
        },
        |r| {
            let s = &r.normal_stresses_kpa;
            let (lo, hi) = (*s.first()?, *s.last()?);
            let median = subfric_reading::stats::median(&mut s.clone())?;
            Some((median, (ranges && hi > lo).then_some((lo, hi))))
        },
        "normal stress",
    )
}

/// Writes the figures into `dir`; returns them. The verdict figures only when a set was
/// diagnosed (old ones are removed otherwise: the figures are those of this table).
pub fn write(dir: &Path, rows: &[Row]) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)
        .map_err(|e| anyhow::anyhow!("{}: cannot create the folder: {e}", dir.display()))?;
    let mut files = Vec::new();
    // μ against roughness only where a set gives its roughness: an empty frame says nothing
    // (an old one of another table is removed, PNG and SVG).
    if rows.iter().any(|r| r.rmax_over_d50.is_some()) {
        let roughness = mu_figure(
            rows,
            "normalised roughness",
            "normalised roughness R_max/D50 [-]",
            |r| r.rmax_over_d50.map(|x| (x, None)),
            "R_max and D50 in experiment.json",
        );
        let f = dir.join(ROUGHNESS_FIGURE);
        write_figure(&roughness, &f)?;
        files.push(f);
    } else {
        for f in [
            dir.join(ROUGHNESS_FIGURE),
            dir.join(ROUGHNESS_FIGURE).with_extension("svg"),
        ] {
            if f.is_file() {
                std::fs::remove_file(&f)
                    .map_err(|e| anyhow::anyhow!("{}: cannot remove: {e}", f.display()))?;
            }
        }
    }
    let f = dir.join(STRESS_FIGURE);
    write_figure(&stress_figure(rows), &f)?;
    files.push(f);
    let mut verdict_files = Vec::new();
    if rows.iter().any(|r| r.verdict.is_some()) {
        for (name, fig) in verdict_figures(rows) {
            let f = dir.join(name);
            write_figure(&fig, &f)?;
            verdict_files.push(f);
        }
    }
    remove_old_verdicts(dir, &verdict_files)?;
    files.extend(verdict_files);
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` diagnosed sets, their verdicts in turn `rate`, `none`, `pressure`.
    fn rows(n: usize) -> Vec<Row> {
        (0..n)
            .map(|i| Row {
                status: RowStatus::Ok,
                normal_stresses_kpa: vec![100.0],
                rows: Some(1000),
                reduced_chi2: Some(1.0),
                verdict: Some(["rate", "none", "pressure"][i % 3].into()),
                held_out_shrink: Some((i % 10) as f64 / 10.0),
                confidence: Some(0.95),
                ..Row::not_run(
                    format!("s{:02}-pair-{}", i / 20 + 1, 61 + i % 20),
                    String::new(),
                )
            })
            .collect()
    }

    #[test]
    fn no_roughness_figure_without_a_roughness_and_an_old_one_is_removed() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join(ROUGHNESS_FIGURE), b"old").unwrap();
        std::fs::write(dir.path().join("mu-vs-roughness.svg"), b"old").unwrap();
        let files = write(dir.path(), &rows(3)).unwrap();
        let names: Vec<String> = files
            .iter()
            .map(|f| f.file_name().unwrap().to_string_lossy().to_string())
            .collect();
        assert!(!names.contains(&ROUGHNESS_FIGURE.to_string()), "{names:?}");
        assert!(names.contains(&STRESS_FIGURE.to_string()), "{names:?}");
        assert!(!dir.path().join(ROUGHNESS_FIGURE).exists());
        assert!(!dir.path().join("mu-vs-roughness.svg").exists());
        // With one set's roughness given, the figure is drawn.
        let mut with = rows(3);
        with[1].rmax_over_d50 = Some(0.05);
        let files = write(dir.path(), &with).unwrap();
        assert!(files.iter().any(|f| f.ends_with(ROUGHNESS_FIGURE)));
    }

    #[test]
    fn a_small_campaign_names_every_set_on_one_verdict_figure() {
        let f = verdict_figures(&rows(VERDICT_PAGE));
        assert_eq!(f.len(), 1);
        assert_eq!(f[0].0, VERDICT_FIGURE);
        assert_eq!(f[0].1.categories.as_ref().unwrap().len(), VERDICT_PAGE);
    }

    #[test]
    fn the_same_effects_named_in_either_order_are_one_verdict_on_the_figures() {
        // The diagnosis names its effects in the order it took them; a 200-set campaign drew
        // "pressure + log-healing" (10 sets) and "log-healing + pressure" (5) as two verdicts.
        let mut rows = rows(60);
        for (i, r) in rows.iter_mut().enumerate() {
            r.verdict =
                Some(["pressure + log-healing", "log-healing + pressure", "rate"][i % 3].into());
        }
        let overview = verdict_overview(&rows, 2);
        assert_eq!(
            overview.categories.as_deref().unwrap(),
            ["log-healing + pressure (40)", "rate (20)"]
        );
        let page = verdict_figure(&rows[..VERDICT_PAGE], "page".into());
        let groups: Vec<&str> = page.groups.iter().map(|g| g.label.as_str()).collect();
        assert_eq!(groups, ["log-healing + pressure", "rate"]);
        // The table keeps the diagnosis's own order.
        assert_eq!(rows[0].verdict.as_deref(), Some("pressure + log-healing"));
    }

    #[test]
    fn a_large_campaign_has_an_overview_by_verdict_and_pages_of_named_sets() {
        let rows = rows(200);
        let f = verdict_figures(&rows);
        let names: Vec<&str> = f.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            [
                "verdicts.png",
                "verdicts-01.png",
                "verdicts-02.png",
                "verdicts-03.png",
                "verdicts-04.png",
                "verdicts-05.png"
            ]
        );
        // The overview: one slot per verdict, its sets counted, its median and quartiles.
        let overview = &f[0].1;
        assert_eq!(
            overview.categories.as_deref().unwrap(),
            ["none (67)", "pressure (66)", "rate (67)"]
        );
        assert_eq!(overview.groups.len(), 1);
        let rate = &overview.groups[0].points[2];
        let mut shrink: Vec<f64> = rows
            .iter()
            .filter(|r| r.verdict.as_deref() == Some("rate"))
            .map(|r| 100.0 * r.held_out_shrink.unwrap())
            .collect();
        shrink.sort_by(f64::total_cmp);
        assert_eq!(rate.y, shrink[33]);
        assert!(matches!(rate.lo, IntervalEnd::At(v) if v <= rate.y));
        assert!(matches!(rate.hi, IntervalEnd::At(v) if v >= rate.y));
        // The pages: every set once, in order, named with its verdict, its point at its name.
        let named: Vec<String> = f[1..]
            .iter()
            .flat_map(|(_, fig)| fig.categories.clone().unwrap())
            .collect();
        let sets: Vec<String> = rows
            .iter()
            .map(|r| format!("{} · {}", r.set, r.verdict.as_deref().unwrap()))
            .collect();
        assert_eq!(named, sets);
        for (_, fig) in &f[1..] {
            assert_eq!(fig.groups.len(), 1);
            let n = fig.categories.as_ref().unwrap().len();
            assert!(n <= VERDICT_PAGE);
            let layout = subfric_plot::interval_layout(fig).expect("the page can be drawn");
            assert_eq!(layout.points.len(), n);
            // Each point in its set's slot.
            let (l, r) = (f64::from(layout.plot.left), f64::from(layout.plot.right));
            for (_, i, (x, _)) in &layout.points {
                let slot = (x - l) / (r - l) * n as f64;
                assert!((slot - (*i as f64 + 0.5)).abs() < 0.25, "{slot} {i}");
            }
        }
        assert!(f[5].1.title.contains("sets 161–200 of 200 (page 5 of 5)"));
    }

    #[test]
    fn the_stress_ranges_are_drawn_for_a_small_campaign_only() {
        let with_stresses = |n: usize| {
            let mut rows = rows(n);
            for r in &mut rows {
                r.normal_stresses_kpa = vec![50.0, 100.0, 400.0];
                r.parameters = vec![ParamCell {
                    name: "mu_s".into(),
                    unit: String::new(),
                    value: 0.5,
                    lo: Some(0.4),
                    hi: None,
                    lo_open: false,
                    hi_open: true,
                    status: "determined".into(),
                }];
            }
            rows
        };
        for (n, drawn) in [(STRESS_RANGES, true), (STRESS_RANGES + 1, false)] {
            let dir = tempfile::tempdir().unwrap();
            let fig = stress_figure(&with_stresses(n));
            let points = &fig.groups[0].points;
            assert_eq!(points.len(), n);
            assert!(points.iter().all(|p| p.x == 100.0));
            assert!(
                points.iter().all(|p| p.x_range.is_some() == drawn),
                "{n} sets"
            );
            write(dir.path(), &with_stresses(n)).unwrap();
        }
    }

    #[test]
    fn old_verdict_pages_are_removed_when_the_campaign_no_longer_has_them() {
        let dir = tempfile::tempdir().unwrap();
        let written = write(dir.path(), &rows(90)).unwrap();
        for f in ["verdicts.png", "verdicts-01.png", "verdicts-03.png"] {
            assert!(written.contains(&dir.path().join(f)), "{f}");
        }
        std::fs::write(dir.path().join("verdicts-notes.png"), b"not ours").unwrap();
        write(dir.path(), &rows(10)).unwrap();
        assert!(dir.path().join("verdicts.png").is_file());
        assert!(!dir.path().join("verdicts-01.png").exists());
        assert!(!dir.path().join("verdicts-01.svg").exists());
        assert!(dir.path().join("verdicts.svg").is_file());
        assert!(dir.path().join("verdicts-notes.png").is_file());
        let mut fitted = rows(10);
        fitted.iter_mut().for_each(|r| r.verdict = None);
        write(dir.path(), &fitted).unwrap();
        assert!(!dir.path().join("verdicts.png").exists());
        assert!(!dir.path().join("verdicts.svg").exists());
    }
}
