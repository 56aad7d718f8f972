//! The posterior's figures, drawn by `subfric-plot`: the corner plot of the thinned chain and
//! the predictive-band overlay of each test.

use crate::predictive::TestBand;
use crate::summary::Posterior;
use crate::target::is_log;
use subfric_model::{Control, Model};
use subfric_plot::posterior::{BandFigure, CornerFigure, CornerMarker};
use subfric_plot::{Series, Style};
use subfric_reading::FitTest;

/// Samples of a parameter fitted on a logarithmic scale are drawn on a log₁₀ axis when they
/// span more than this ratio (a valley over decades is then a band, not a corner).
const LOG_AXIS_SPAN: f64 = 10.0;

/// The corner plot of `post`: parameters fitted on a logarithmic scale (κ, ξ, ũ, ...) whose
/// samples span more than a decade on log₁₀ axes; the least-squares optimum marked in red, and
/// `truth` (natural values in the order of `post.parameters`) in blue when known.
pub fn corner_figure(post: &Posterior, title: &str, truth: Option<&[f64]>) -> CornerFigure {
    let logs: Vec<bool> = post
        .parameters
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let c = post.chain.column(k);
            let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = c.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            is_log(*p) && lo > 0.0 && hi / lo > LOG_AXIS_SPAN
        })
        .collect();
    let axis = |k: usize, v: f64| if logs[k] { v.log10() } else { v };
    let labels = post
        .parameters
        .iter()
        .zip(&logs)
        .map(|(p, log)| {
            let unit = if p.unit().is_empty() {
                String::new()
            } else {
                format!(" [{}]", p.unit())
            };
            if *log {
                format!("log₁₀ {}{unit}", p.key())
            } else {
                format!("{}{unit}", p.key())
            }
        })
        .collect();
    let samples = (0..post.parameters.len())
        .map(|k| {
            post.chain
                .column(k)
                .into_iter()
                .map(|v| axis(k, v))
                .collect()
        })
        .collect();
    let marker = |label: &str, values: &[f64], style| CornerMarker {
        label: label.into(),
        values: values
            .iter()
            .enumerate()
            .map(|(k, v)| axis(k, *v))
            .collect(),
        style,
    };
    let mut fig = CornerFigure::new(title, labels, samples).with_marker(marker(
        "least-squares optimum",
        &post.optimum,
        Style::Fitted,
    ));
    if let Some(t) = truth {
        fig = fig.with_marker(marker("true values", t, Style::Published));
    }
    fig
}

/// The band of `test` over its measured curve: friction τ/σ_n against slip under slip
/// control, slip against time under traction control; the posterior median, and the
/// least-squares fit when given; below, the same minus the posterior median (where a band
/// thinner than a line on the full curve shows at its own scale).
pub fn band_figure(
    test: &FitTest,
    band: &TestBand,
    fitted: Option<&Model>,
    title: &str,
) -> BandFigure {
    let slip_control = test.control == Control::Slip;
    let (x, x_label, y_label) = if slip_control {
        (test.imposed.clone(), "slip u [mm]", "friction τ/σ_n [-]")
    } else {
        (test.time.clone(), "time t [s]", "slip u [mm]")
    };
    let to_y = |v: &[f64]| -> Vec<f64> {
        v.iter()
            .enumerate()
            .map(|(i, v)| if slip_control { v / test.normal[i] } else { *v })
            .collect()
    };
    let what = if band.with_noise {
        "95 % posterior predictive band (with noise)"
    } else {
        "95 % posterior band of the model curve"
    };
    let mut fig = BandFigure::new(
        title,
        x_label,
        y_label,
        x.clone(),
        to_y(&band.lo),
        to_y(&band.hi),
        format!("{what}, {} draws", band.draws),
    )
    .with_series(Series::new(
        "measured",
        x.clone(),
        to_y(&test.measured),
        Style::Measured,
    ));
    if let Some(p) = fitted.and_then(|m| test.predict(m).ok()) {
        fig = fig.with_series(Series::new(
            "least-squares fit",
            x.clone(),
            to_y(&p),
            Style::Other(1),
        ));
    }
    let unit = if slip_control { "[-]" } else { "[mm]" };
    fig.with_series(Series::new(
        "posterior median",
        x,
        to_y(&band.median),
        Style::Fitted,
    ))
    .with_difference(to_y(&band.median), format!("minus the median {unit}"))
}
