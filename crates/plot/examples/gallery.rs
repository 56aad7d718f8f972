//! One figure of every kind, for the before/after pairs in `docs/figures/`.
//!
//! `cargo run -p subfric-plot --release --example gallery -- DIR PREFIX` writes
//! `PREFIX-overlay.png`, `PREFIX-inset.png`, `PREFIX-bars.png`, `PREFIX-intervals.png`,
//! `PREFIX-corner.png` and `PREFIX-band.png` into DIR, each 800x600 (the corner plot 700x700).

#[path = "../tests/common/mod.rs"]
mod common;

use std::path::PathBuf;

use subfric_plot::posterior::{
    render_band_png, render_corner_png, BandFigure, CornerFigure, CornerMarker,
};
use subfric_plot::{
    render_bars_png, render_interval_png, render_png, Figure, IntervalEnd, IntervalFigure,
    IntervalPoint, Panel, Series, Style,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let dir = PathBuf::from(args.next().unwrap_or_else(|| "plot-gallery".into()));
    let prefix = args.next().unwrap_or_else(|| "figure".into());
    std::fs::create_dir_all(&dir)?;
    let at = |kind: &str| dir.join(format!("{prefix}-{kind}.png"));
    render_png(
        &common::cyclic_figure(3000).with_size(800, 600),
        &at("overlay"),
    )?;
    render_png(&inset_figure().with_size(800, 600), &at("inset"))?;
    render_bars_png(&common::bar_figure().with_size(800, 600), &at("bars"))?;
    let mut intervals = interval_figure();
    intervals.width = 800;
    intervals.height = 600;
    render_interval_png(&intervals, &at("intervals"))?;
    render_corner_png(&corner_figure().with_size(700, 700), &at("corner"))?;
    let mut band = band_figure();
    band.width = 800;
    band.height = 600;
    render_band_png(&band, &at("band"))?;
    Ok(())
}

/// A monotonic test with its first loading zoomed and a traction history below.
fn inset_figure() -> Figure {
    let x: Vec<f64> = (0..2000).map(|i| f64::from(i) * 0.0025).collect();
    let mut rng = common::Lcg::new(5);
    let measured: Vec<f64> = x
        .iter()
        .map(|u| 0.6 * (1.0 - (-u / 0.05).exp()) + 0.1 * (-u / 0.3).exp() + 0.004 * rng.next())
        .collect();
    let fitted: Vec<f64> = x
        .iter()
        .map(|u| 0.6 * (1.0 - (-u / 0.055).exp()) + 0.1 * (-u / 0.32).exp())
        .collect();
    let residual: Vec<f64> = fitted.iter().zip(&measured).map(|(f, m)| f - m).collect();
    Figure::new(
        "table1-medium: monotonic (100 kPa)",
        "slip u [mm]",
        Panel::new(
            "friction τ/σ_n [-]",
            vec![
                Series::new("measured", x.clone(), measured, Style::Measured),
                Series::new("fitted", x.clone(), fitted, Style::Fitted),
            ],
        ),
    )
    .with_inset("zoom: first loading (peak and decay)", 0.0, 0.6)
    .with_residual(
        Panel::new(
            "fit − measured [-]",
            vec![Series::new("fitted", x, residual, Style::Fitted)],
        )
        .with_zero_line(),
    )
}

/// μ_s and μ_k of five sets with 95 % intervals, one of them open upwards.
fn interval_figure() -> IntervalFigure {
    let point = |x: f64, y: f64, lo: f64, hi: IntervalEnd| IntervalPoint {
        x,
        y,
        lo: IntervalEnd::At(lo),
        hi,
        x_range: Some((x - 20.0, x + 20.0)),
    };
    let at = IntervalEnd::At;
    IntervalFigure::new(
        "Friction against normal stress",
        "normal stress σ_n [kPa]",
        "friction [-]",
    )
    .with_group(
        "μ_s",
        vec![
            point(50.0, 0.62, 0.6, at(0.64)),
            point(100.0, 0.6, 0.58, at(0.61)),
            point(200.0, 0.57, 0.55, IntervalEnd::Open),
            point(400.0, 0.55, 0.53, at(0.57)),
        ],
    )
    .with_group(
        "μ_k",
        vec![
            point(50.0, 0.45, 0.43, at(0.47)),
            point(100.0, 0.44, 0.43, at(0.45)),
            point(200.0, 0.42, 0.4, at(0.44)),
            point(400.0, 0.4, 0.39, at(0.41)),
        ],
    )
}

/// Samples along a valley b = 100/a², with an optimum marked.
fn corner_figure() -> CornerFigure {
    let mut rng = common::Lcg::new(3);
    let mut cols = vec![Vec::new(), Vec::new(), Vec::new()];
    for _ in 0..20_000 {
        let a = 5.5 + 4.5 * rng.next();
        cols[0].push(a);
        cols[1].push(100.0 / (a * a) * (1.0 + 0.01 * rng.next()));
        cols[2].push(0.5 + 0.2 * rng.next());
    }
    CornerFigure::new(
        "posterior of table1-medium",
        vec!["κ [1/mm]".into(), "ξ [1/s]".into(), "μ_k [-]".into()],
        cols,
    )
    .with_marker(CornerMarker {
        label: "least-squares optimum".into(),
        values: vec![4.0, 6.25, 0.5],
        style: Style::Fitted,
    })
}

/// A predictive band around a monotonic curve, with the difference panel.
fn band_figure() -> BandFigure {
    let x: Vec<f64> = (0..400).map(|i| f64::from(i) * 0.01).collect();
    let mid = common::monotonic(&x, 0.65, 0.55, 0.1);
    let lo: Vec<f64> = mid
        .iter()
        .zip(&x)
        .map(|(m, u)| m - 0.004 - 0.01 * u)
        .collect();
    let hi: Vec<f64> = mid
        .iter()
        .zip(&x)
        .map(|(m, u)| m + 0.004 + 0.01 * u)
        .collect();
    let mut rng = common::Lcg::new(9);
    let measured: Vec<f64> = mid.iter().map(|m| m + 0.006 * rng.next()).collect();
    BandFigure::new(
        "predictive band, table1-medium: monotonic",
        "slip u [mm]",
        "friction τ/σ_n [-]",
        x.clone(),
        lo,
        hi,
        "95 % band of the posterior's curves",
    )
    .with_series(Series::new(
        "measured",
        x.clone(),
        measured,
        Style::Measured,
    ))
    .with_series(Series::new(
        "posterior median",
        x,
        mid.clone(),
        Style::Fitted,
    ))
    .with_difference(mid, "minus the median [-]")
}
