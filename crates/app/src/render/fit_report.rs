//! The readable table of a fit: printed by `subfric fit`, written to `fit.txt` by
//! `subfric reproduce`; and the cells the tables of `reproduce` and the HTML reports share.
//!
//! Written for an engineer who skims: the verdict first (does the model describe the data),
//! then what to do next, then the parameters. A parameter the data do not determine is shown
//! as "not determined (≤ 0.47)" — the bound the data set, never the optimiser's point in a
//! flat valley with a precise-looking difference from the published value.

use crate::outcome::adequacy::{misfit_number, next_steps, MISFIT_LEGEND};
use crate::outcome::FitOutcome;
use std::fmt::Write as _;
use subfric_fit::interval::short_number as fmt_num;
use subfric_fit::{Combination, FitReport, ParamReport, Status};

/// How to read an interval and an identifiability verdict: the one legend of every table,
/// report and README that shows them, one item per line.
pub const INTERVAL_LEGEND: [&str; 4] = [
    "95 % interval [a, b]: the values the data allow (profile likelihood); determined: closed and within ±10 % of the value; weakly determined: closed but wider",
    "not determined (≤ b): the data set only an upper bound b and any smaller value fits as well, so no value is given (fit.json keeps the optimiser's point, one point of a flat valley); not determined (≥ a): only a lower bound; not determined (any value): no bound",
    "in an interval, (≤a or b≥) marks an end the data leave open; a or b is then where the search stopped",
    "difference: from the published value, for estimates only",
];

/// Every legend item: the intervals, then the misfit.
pub fn legend_items() -> Vec<&'static str> {
    let mut v = INTERVAL_LEGEND.to_vec();
    v.push(MISFIT_LEGEND);
    v
}

/// The legend in plain text, one item per line, each starting with `prefix`.
pub fn legend_text(prefix: &str) -> String {
    legend_items()
        .iter()
        .map(|l| format!("{prefix}{l}"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Interval text with open ends marked (empty for a fixed or unprofiled parameter).
pub fn interval_text(p: &ParamReport) -> String {
    p.interval.map(|i| i.to_string()).unwrap_or_default()
}

/// The data leave this parameter undetermined: bounded on one side at most.
pub fn undetermined(p: &ParamReport) -> bool {
    p.undetermined()
}

/// The value cell: the fitted value, or "not determined (≤ b)", "(≥ a)", "(any value)" (as
/// fit.json's `reads` says it).
pub fn value_text(p: &ParamReport, number: impl Fn(f64) -> String) -> String {
    p.reads_with(number)
}

/// The interval cell: the closed interval of an estimate (the bound of an undetermined
/// parameter is in its value cell already).
pub fn estimate_interval_text(p: &ParamReport) -> String {
    if undetermined(p) {
        String::new()
    } else {
        interval_text(p)
    }
}

/// The standard-error cell: empty for a fixed or undetermined parameter (its linearised error
/// says nothing), ∞ when the data give no curvature.
pub fn std_error_text(p: &ParamReport, number: impl Fn(f64) -> String) -> String {
    if p.status == Status::Fixed || undetermined(p) {
        return String::new();
    }
    p.std_error.map(number).unwrap_or_else(|| "∞".into())
}

/// The difference from the published value, for an estimate only: an undetermined
/// parameter's value is not an estimate, and a fixed one was set, not found.
pub fn difference_text(p: &ParamReport) -> String {
    if p.status == Status::Fixed || undetermined(p) {
        return String::new();
    }
    p.difference_percent
        .map(|d| format!("{d:+.1}%"))
        .unwrap_or_default()
}

/// The combinations the data determine (closed and within ±10 %).
pub fn determined_combinations(r: &FitReport) -> Vec<&Combination> {
    r.combinations.iter().filter(|c| c.determined).collect()
}

/// The verdict and the next steps of a fit, one line each ("verdict: …", "next: …").
pub fn verdict_lines(out: &FitOutcome) -> Vec<String> {
    let mut v = vec![format!("verdict: {}", out.adequacy.sentence("the model"))];
    for n in next_steps(&out.adequacy, &out.report, &out.dirs) {
        v.push(format!("next: {n}"));
    }
    v
}

/// The readable table written to `fit.txt`: verdict, next steps, parameters, combinations,
/// misfit per test, optimiser, legend. No wall time, so that the file depends on the data,
/// the code and the seed only.
pub fn report_table(out: &FitOutcome) -> String {
    table(out, false)
}

/// The table with the wall time, for the terminal.
pub fn report_table_timed(out: &FitOutcome) -> String {
    table(out, true)
}

fn table(out: &FitOutcome, timed: bool) -> String {
    let (name, r) = (&out.name, &out.report);
    let mut s = String::new();
    for l in verdict_lines(out) {
        let _ = writeln!(s, "{l}");
    }
    let misfit = if out.adequacy.level == crate::outcome::adequacy::Level::CannotJudge {
        "misfit not judged (the noise is not measured)".to_string()
    } else {
        format!(
            "misfit {}× the noise variance",
            misfit_number(r.reduced_chi2)
        )
    };
    let _ = writeln!(
        s,
        "fit of {}: {} rows, {misfit}",
        crate::visible(name),
        r.rows
    );
    write_parameter_rows(&mut s, r);
    write_read_off(&mut s, out);
    write_combinations(&mut s, r);
    write_undetermined_note(&mut s, r);
    let _ = writeln!(s, "per test:");
    for t in &r.tests {
        let _ = writeln!(
            s,
            "  {:<30} {:>6} rows  RMS {:>9} {:<3} ({:.2}% of scale)  misfit {:>6}× the noise variance",
            crate::visible(&t.name),
            t.rows,
            fmt_num(t.rms),
            t.unit,
            t.rms_percent,
            misfit_number(t.reduced_chi2)
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
    if timed {
        let _ = write!(s, "; {:.1} s wall time", o.elapsed_s);
    }
    let _ = write!(s, "\nhow to read:\n{}", legend_text("  "));
    s
}

/// μ_s and μ_k beside the peak and residual stress ratios the record shows (the paper reads
/// them off these), and what a departure means.
fn write_read_off(s: &mut String, out: &FitOutcome) {
    if out.read_off.is_empty() {
        return;
    }
    let _ = writeln!(s, "read off the record (the paper's Section 5, item 2):");
    for r in &out.read_off {
        // A parameter the data do not determine reads as its bound, never as a number.
        let reads = out
            .report
            .param(r.param)
            .filter(|p| undetermined(p))
            .map(|p| p.reads());
        let _ = writeln!(s, "  {}", r.sentence_reading(reads.as_deref()));
    }
    if out.read_off.iter().any(|r| r.departs) {
        let _ = writeln!(
            s,
            "  the fitted model does not keep what the record shows: the fit traded the level for something else (a rig artifact, an effect the model lacks: subfric diagnose); quote μ_s and μ_k only with that said."
        );
    }
    write_stress_trends(s, &out.levels);
}

/// A peak or residual stress ratio that changes with the normal stress across the tests: one
/// μ_s (or μ_k) cannot keep them all, and the reader is told which way they go.
fn write_stress_trends(s: &mut String, l: &subfric_reading::LevelReadings) {
    for (what, param, trend, pick) in [
        (
            "peak",
            "μ_s",
            &l.peak,
            (|t: &subfric_reading::TestLevels| t.peak) as fn(&subfric_reading::TestLevels) -> _,
        ),
        ("residual", "μ_k", &l.residual, |t| t.residual),
    ] {
        let Some(t) = trend.as_ref().filter(|t| t.changes()) else {
            continue;
        };
        let values: Vec<String> = l
            .tests
            .iter()
            .filter_map(|x| pick(x).map(|e| format!("{:.3} at {:.0} kPa", e.value, x.normal_kpa)))
            .collect();
        let _ = writeln!(
            s,
            "  the {what} stress ratio {} with the normal stress ({}; {:+.4} [{:+.4}, {:+.4}] per e-fold of it, Mohr–Coulomb φ {:.1}°, c {:.1} kPa): one {param} cannot keep every test's {what}; `subfric diagnose` tries a pressure effect",
            if t.per_efold.value < 0.0 { "falls" } else { "rises" },
            values.join(", "),
            t.per_efold.value,
            t.per_efold.lo,
            t.per_efold.hi,
            t.friction_angle_deg.value,
            t.cohesion_kpa.value
        );
    }
}

/// One line per parameter: value (or what the data allow), standard error, interval,
/// verdict, and the published value with the difference from it.
fn write_parameter_rows(s: &mut String, r: &FitReport) {
    let _ = writeln!(
        s,
        "{:<18} {:>27} {:>10} {:>24}  {:<34} {:>10} {:>10}",
        "parameter",
        "value",
        "± s.e.",
        "95% interval",
        "identifiability",
        "published",
        "difference"
    );
    for p in &r.parameters {
        let _ = writeln!(
            s,
            "{:<18} {:>27} {:>10} {:>24}  {:<34} {:>10} {:>10}",
            format!(
                "{} {}",
                p.name,
                if p.unit.is_empty() {
                    String::new()
                } else {
                    format!("[{}]", p.unit)
                }
            ),
            value_text(p, fmt_num),
            std_error_text(p, fmt_num),
            estimate_interval_text(p),
            p.status.describe(),
            p.published.map(fmt_num).unwrap_or_default(),
            difference_text(p),
        );
    }
}

/// The combinations of parameters the data determine (when the fit charted any).
fn write_combinations(s: &mut String, r: &FitReport) {
    let determined = determined_combinations(r);
    if determined.is_empty() {
        return;
    }
    let _ = writeln!(s, "combinations the data determine:");
    for c in determined {
        let iv = c.interval.map(|i| i.to_string()).unwrap_or_default();
        let _ = writeln!(s, "  {:<58} {:>11} {:>26}", c.name, fmt_num(c.value), iv);
    }
}

/// Why the undetermined parameters have no value.
fn write_undetermined_note(s: &mut String, r: &FitReport) {
    let names: Vec<&str> = r
        .parameters
        .iter()
        .filter(|p| undetermined(p))
        .map(|p| p.name.as_str())
        .collect();
    if !names.is_empty() {
        let _ = writeln!(
            s,
            "the data do not determine {}: they bound {} on one side at most, so no value is given (fit.json keeps the optimiser's point, one point of a flat valley)",
            names.join(", "),
            if names.len() == 1 { "it" } else { "them" }
        );
    }
}
