//! Figures of the per-event reading of a diagnosis: the velocity steps fitted one by one (a
//! and b with their 95 % intervals per step; below, a − b beside the change of steady
//! friction measured on the record, per e-fold of rate), and the peak gain after each hold
//! against the hold time with the healing line.

use std::path::{Path, PathBuf};
use subfric_diagnose::events::{Estimate, EventAnalysis};
use subfric_plot::{Figure, Panel, Series, Style};

/// A series of values and one two-point series per interval (no legend entry): the plot crate
/// draws intervals as short vertical lines. An interval's ends are clipped to twice the
/// spread of the values around them, so that one step the record barely determines does not
/// flatten the others (its open or wide interval still shows as a long bar).
fn with_intervals(label: &str, x: &[f64], e: &[Estimate], style: Style) -> Vec<Series> {
    let values: Vec<f64> = e.iter().map(|v| v.value).collect();
    let (lo, hi) = values
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
    let pad = 2.0 * (hi - lo).max(0.5 * lo.abs().max(hi.abs())).max(1e-12);
    let (floor, ceiling) = (lo - pad, hi + pad);
    let mut out = vec![Series::new(label, x.to_vec(), values, style)];
    for (xi, v) in x.iter().zip(e) {
        let (a, b) = (v.lo.max(floor), v.hi.min(ceiling));
        if a.is_finite() && b.is_finite() && a < b {
            out.push(Series::new("", vec![*xi, *xi], vec![a, b], style));
        }
    }
    out
}

/// The figures, each with the file in `out` it is to be written to (the caller renders them
/// with the other figures of the diagnosis, in parallel).
pub(crate) fn event_figures(name: &str, e: &EventAnalysis, out: &Path) -> Vec<(Figure, PathBuf)> {
    let mut files = Vec::new();
    if !e.steps.is_empty() {
        let x: Vec<f64> = (1..=e.steps.len()).map(|k| k as f64).collect();
        let a: Vec<Estimate> = e.steps.iter().map(|s| s.a).collect();
        let b: Vec<Estimate> = e.steps.iter().map(|s| s.b).collect();
        let mut main = with_intervals("a (direct effect)", &x, &a, Style::Fitted);
        main.extend(with_intervals("b (evolution)", &x, &b, Style::Other(0)));
        // Per e-fold of rate, so that both read as a − b.
        let per_efold = |s: &subfric_diagnose::events::StepFit, v: &Estimate| {
            let ln = (s.rate_after / s.rate_before).ln();
            let (p, q) = (v.lo / ln, v.hi / ln);
            Estimate {
                value: v.value / ln,
                lo: p.min(q),
                hi: p.max(q),
            }
        };
        let amb: Vec<Estimate> = e.steps.iter().map(|s| s.a_minus_b).collect();
        let measured: Vec<Estimate> = e
            .steps
            .iter()
            .map(|s| per_efold(s, &s.measured_steady_change))
            .collect();
        let shifted: Vec<f64> = x.iter().map(|v| v + 0.15).collect();
        let mut lower = with_intervals("a − b fitted", &x, &amb, Style::Fitted);
        lower.extend(with_intervals(
            "Δμ_ss / ln(v₁/v₀) measured",
            &shifted,
            &measured,
            Style::Measured,
        ));
        let fig = Figure::new(
            format!("{name}: velocity steps fitted one by one (95 % intervals)"),
            "velocity step (in the order of diagnosis.json)",
            Panel::new("rate-and-state a, b [-]", main),
        )
        .with_residual(Panel::new("a − b [-]", lower).with_zero_line())
        .with_whole_x();
        files.push((fig, out.join("velocity-steps-one-by-one.png")));
    }
    if e.holds.len() >= 2 {
        let x: Vec<f64> = e
            .holds
            .iter()
            .map(|h| h.duration_s.max(1e-3).log10())
            .collect();
        let gains: Vec<Estimate> = e.holds.iter().map(|h| h.peak_gain).collect();
        let mut series = with_intervals("peak gain on reloading", &x, &gains, Style::Measured);
        if let Some(t) = &e.healing {
            let (lo, hi) = x
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
            let mean_x = x.iter().sum::<f64>() / x.len() as f64;
            let mean_y = gains.iter().map(|g| g.value).sum::<f64>() / x.len() as f64;
            let line = |v: f64| mean_y + t.per_decade.value * (v - mean_x);
            series.push(Series::new(
                format!("{:.4} per decade", t.per_decade.value),
                vec![lo, hi],
                vec![line(lo), line(hi)],
                Style::Fitted,
            ));
        }
        let fig = Figure::new(
            format!("{name}: healing over the holds"),
            "log₁₀ hold time [s]",
            Panel::new("Δμ peak after the hold [-]", series).with_zero_line(),
        );
        files.push((fig, out.join("holds-one-by-one.png")));
    }
    files
}
