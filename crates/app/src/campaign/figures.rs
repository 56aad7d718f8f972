//! The campaign's summary figures: μ_s and μ_k with their 95 % profile intervals against the
//! normalised roughness R_max/D50 (the classic design chart of interface friction) and against
//! the normal stress, and the diagnosis's verdict per set.

use super::table::{ParamCell, Row, RowStatus};
use anyhow::Result;
use std::path::{Path, PathBuf};
use subfric_plot::{write_figure, IntervalEnd, IntervalFigure, IntervalPoint};

/// The figure of μ against R_max/D50.
pub const ROUGHNESS_FIGURE: &str = "mu-vs-roughness.png";
/// The figure of μ against the normal stress.
pub const STRESS_FIGURE: &str = "mu-vs-normal-stress.png";
/// The figure of the verdicts.
pub const VERDICT_FIGURE: &str = "verdicts.png";

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
fn verdict_figure(rows: &[Row]) -> IntervalFigure {
    let diagnosed: Vec<&Row> = rows.iter().filter(|r| r.verdict.is_some()).collect();
    let mut verdicts: Vec<&str> = diagnosed
        .iter()
        .filter_map(|r| r.verdict.as_deref())
        .collect();
    verdicts.sort();
    verdicts.dedup();
    let mut fig = IntervalFigure::new(
        format!(
            "Diagnosis per set: {} of {} sets diagnosed",
            diagnosed.len(),
            rows.len()
        ),
        "",
        "held-out misfit removed by the verdict's effect [%]",
    )
    .with_categories(rows.iter().map(|r| r.set.clone()).collect());
    fig.y_include = vec![0.0, 100.0];
    for v in verdicts {
        let points = rows
            .iter()
            .enumerate()
            .filter(|(_, r)| r.verdict.as_deref() == Some(v))
            .map(|(i, r)| IntervalPoint::at(i as f64, 100.0 * r.held_out_shrink.unwrap_or(0.0)))
            .collect();
        fig = fig.with_group(v, points);
    }
    fig
}

/// Writes the figures into `dir`; returns them. The verdict figure only when a set was
/// diagnosed (an old one is removed otherwise: the figures are those of this table).
pub fn write(dir: &Path, rows: &[Row]) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)
        .map_err(|e| anyhow::anyhow!("{}: cannot create the folder: {e}", dir.display()))?;
    let mut files = Vec::new();
    let roughness = mu_figure(
        rows,
        "normalised roughness",
        "normalised roughness R_max/D50 [-]",
        |r| r.rmax_over_d50.map(|x| (x, None)),
        "R_max and D50 in experiment.json",
    );
    let stress = mu_figure(
        rows,
        "normal stress",
        "normal stress σ_n [kPa] (a set tested at several: their median, the bar their range)",
        |r| {
            let s = &r.normal_stresses_kpa;
            let (lo, hi) = (*s.first()?, *s.last()?);
            let median = if s.len() % 2 == 1 {
                s[s.len() / 2]
            } else {
                0.5 * (s[s.len() / 2 - 1] + s[s.len() / 2])
            };
            Some((median, (hi > lo).then_some((lo, hi))))
        },
        "normal stress",
    );
    for (fig, name) in [(roughness, ROUGHNESS_FIGURE), (stress, STRESS_FIGURE)] {
        let f = dir.join(name);
        write_figure(&fig, &f)?;
        files.push(f);
    }
    let f = dir.join(VERDICT_FIGURE);
    if rows.iter().any(|r| r.verdict.is_some()) {
        write_figure(&verdict_figure(rows), &f)?;
        files.push(f);
    } else {
        for old in [f.clone(), f.with_extension("svg")] {
            if old.is_file() {
                std::fs::remove_file(&old)
                    .map_err(|e| anyhow::anyhow!("{}: cannot remove: {e}", old.display()))?;
            }
        }
    }
    Ok(files)
}
