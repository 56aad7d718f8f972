//! The readable table of a fit: printed by `subfric fit`, written to `fit.txt` by
//! `subfric reproduce`.

use std::fmt::Write as _;
use subfric_fit::interval::short_number as fmt_num;
use subfric_fit::{FitReport, Status};

/// Interval text with open ends marked (empty for a fixed or unprofiled parameter).
pub fn interval_text(p: &subfric_fit::ParamReport) -> String {
    p.interval.map(|i| i.to_string()).unwrap_or_default()
}

/// The readable table printed by `subfric fit`.
pub fn report_table(name: &str, r: &FitReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "fit of {}: {} rows, misfit {:.3}× the noise variance (reduced χ²)",
        crate::visible(name),
        r.rows,
        r.reduced_chi2
    );
    write_parameter_rows(&mut s, r);
    write_combinations(&mut s, r);
    write_undetermined_note(&mut s, r);
    let _ = writeln!(s, "per test:");
    for t in &r.tests {
        let _ = writeln!(
            s,
            "  {:<30} {:>6} rows  RMS {:>9} {:<3} ({:.2}% of scale, {:.2}× noise)",
            crate::visible(&t.name),
            t.rows,
            fmt_num(t.rms),
            t.unit,
            t.rms_percent,
            t.rms_over_noise
        );
    }
    let o = &r.optimizer;
    let _ = write!(
        s,
        "optimiser: {:?}, {} starts of which {} reached the best, {} informed guesses, {} global + {} total model runs",
        o.method, o.starts, o.starts_at_best, o.informed_guesses, o.global_evaluations, o.evaluations
    );
    if o.repolished_from_profile {
        let _ = write!(s, " (profiling found a better optimum; re-polished)");
    }
    s
}

/// One line per parameter: value, standard error (∞: unbounded), interval, verdict, and the
/// published value with the difference from it.
fn write_parameter_rows(s: &mut String, r: &FitReport) {
    let _ = writeln!(
        s,
        "{:<18} {:>11} {:>10} {:>26}  {:<34} {:>10} {:>8}",
        "parameter",
        "value",
        "std.err",
        "95% profile interval",
        "identifiability",
        "published",
        "diff"
    );
    for p in &r.parameters {
        let _ = writeln!(
            s,
            "{:<18} {:>11} {:>10} {:>26}  {:<34} {:>10} {:>8}",
            format!(
                "{} {}",
                p.name,
                if p.unit.is_empty() {
                    String::new()
                } else {
                    format!("[{}]", p.unit)
                }
            ),
            fmt_num(p.value),
            p.std_error
                .map(fmt_num)
                .unwrap_or_else(|| if p.status == Status::Fixed {
                    "".into()
                } else {
                    "∞".into()
                }),
            interval_text(p),
            p.status.describe(),
            p.published.map(fmt_num).unwrap_or_default(),
            p.difference_percent
                .map(|d| format!("{d:+.1}%"))
                .unwrap_or_default(),
        );
    }
}

/// The combinations of parameters the data determine (when the fit charted any).
fn write_combinations(s: &mut String, r: &FitReport) {
    if r.combinations.is_empty() {
        return;
    }
    let _ = writeln!(s, "combinations the data determine:");
    for c in &r.combinations {
        let iv = c.interval.map(|i| i.to_string()).unwrap_or_default();
        let _ = writeln!(
            s,
            "  {:<58} {:>11} {:>26}  {}",
            c.name,
            fmt_num(c.value),
            iv,
            if c.determined {
                "determined"
            } else {
                "not determined"
            }
        );
    }
}

/// A warning that the values of undetermined parameters are not estimates.
fn write_undetermined_note(s: &mut String, r: &FitReport) {
    let undetermined: Vec<&str> = r
        .parameters
        .iter()
        .filter(|p| {
            matches!(
                p.status,
                Status::NotDetermined | Status::LowerBoundOnly | Status::UpperBoundOnly
            )
        })
        .map(|p| p.name.as_str())
        .collect();
    if !undetermined.is_empty() {
        let _ = writeln!(
            s,
            "the data do not determine {}: their values above are one point of a flat valley, not estimates",
            undetermined.join(", ")
        );
    }
}

/// The table with the wall time, for the terminal (files get [`report_table`]: no timings, so
/// that they depend on the data, the code and the seed only).
pub fn report_table_timed(name: &str, r: &FitReport) -> String {
    format!(
        "{}; {:.1} s wall time",
        report_table(name, r),
        r.optimizer.elapsed_s
    )
}
