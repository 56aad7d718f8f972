//! Writes demo figures into the directory given as the first argument
//! (default: ./plot-demo) and prints their paths.

#[path = "../tests/common/mod.rs"]
mod common;

use std::path::{Path, PathBuf};
use std::time::Instant;

use subfric_plot::{render_bars_png, render_png, BarFigure, Figure, Panel, Series, Style};

type DemoResult<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> DemoResult<()> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "plot-demo".into()),
    );
    std::fs::create_dir_all(&dir)?;
    for (name, fig) in &line_figures() {
        timed(&dir.join(name), |path| render_png(fig, path))?;
    }
    for (name, fig) in &bar_figures() {
        timed(&dir.join(name), |path| render_bars_png(fig, path))?;
    }
    Ok(())
}

/// Renders to `path` and prints the path with the time it took.
fn timed<E: std::error::Error + 'static>(
    path: &Path,
    render: impl FnOnce(&Path) -> Result<(), E>,
) -> DemoResult<()> {
    let t = Instant::now();
    render(path)?;
    println!(
        "{} ({:.1} ms)",
        path.display(),
        t.elapsed().as_secs_f64() * 1e3
    );
    Ok(())
}

/// The line figures: typical, degenerate (no data, tiny, tall, overlong labels) and stressing
/// (100 000 points, every style, large magnitudes).
fn line_figures() -> Vec<(&'static str, Figure)> {
    vec![
        ("cyclic.png", common::cyclic_figure(3000)),
        ("monotonic.png", common::monotonic_figure()),
        ("long.png", long_figure()),
        ("empty.png", empty_figure()),
        ("small.png", common::cyclic_figure(500).with_size(500, 375)),
        ("tiny.png", common::cyclic_figure(300).with_size(200, 150)),
        ("tall.png", common::monotonic_figure().with_size(300, 900)),
        ("long_labels.png", long_labels_figure()),
        ("styles.png", styles_figure()),
        ("big_numbers.png", big_numbers_figure()),
    ]
}

/// 100 000 points with one spike: the decimation must keep the spike.
fn long_figure() -> Figure {
    let x: Vec<f64> = (0..100_000).map(|i| i as f64 * 1e-4).collect();
    let y: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(i, v)| {
            if i == 61_234 {
                140.0
            } else {
                60.0 * (1.0 - (-v * 3.0).exp()) + 3.0 * (v * 900.0).sin()
            }
        })
        .collect();
    Figure::new(
        "100 000 points",
        "displacement (mm)",
        Panel::new(
            "τ (kPa)",
            vec![Series::new("measured", x, y, Style::Fitted)],
        ),
    )
}

/// A series of NaN only: nothing to draw.
fn empty_figure() -> Figure {
    Figure::new(
        "No data",
        "x (mm)",
        Panel::new(
            "y (kPa)",
            vec![Series::new(
                "nan only",
                vec![f64::NAN; 5],
                vec![1.0; 5],
                Style::Measured,
            )],
        ),
    )
}

/// Title, axis labels and legend all too long: they must shrink or be shortened.
fn long_labels_figure() -> Figure {
    Figure::new(
        "A title that is far too long to fit on one line of a figure even at a reduced font size, really far too long",
        "an x label that is also much longer than it should ever be for a figure axis (mm)",
        Panel::new(
            "a y label much longer than the panel is high, so it must shrink and be shortened (kPa)",
            vec![Series::new("a legend label that is far too long for any legend box, so it is shortened", vec![0.0, 1.0], vec![0.0, 1.0], Style::Fitted)],
        ),
    )
    .with_residual(Panel::new("residual label longer than the panel (kPa)", vec![]).with_zero_line())
}

/// Every style: per-cycle fitted and published curves and eight others.
fn styles_figure() -> Figure {
    let (x, y, c) = common::cyclic(1500, 3, 50.0, 0.2, 0.0, 1);
    let shifted: Vec<f64> = y.iter().map(|v| v + 30.0).collect();
    let mut series = vec![
        Series::new("fitted per cycle", x.clone(), y, Style::Fitted).with_cycles(c.clone()),
        Series::new("published per cycle", x.clone(), shifted, Style::Published).with_cycles(c),
    ];
    for k in 0..8 {
        let xs: Vec<f64> = (0..20).map(|i| -1.5 + i as f64 * 0.15).collect();
        let ys: Vec<f64> = xs
            .iter()
            .map(|v| -90.0 + 8.0 * k as f64 + 5.0 * v)
            .collect();
        series.push(Series::new(format!("other {k}"), xs, ys, Style::Other(k)));
    }
    Figure::new("All styles", "δ (mm)", Panel::new("τ (kPa)", series))
}

/// Axis numbers of very different magnitudes (1e-5 on x, 1e6 on y).
fn big_numbers_figure() -> Figure {
    Figure::new(
        "large and small magnitudes",
        "time (s)",
        Panel::new(
            "stiffness (Pa/m)",
            vec![
                Series::new(
                    "k",
                    (0..50).map(|i| i as f64 * 2e-5).collect(),
                    (0..50)
                        .map(|i| 1e6 + 3e5 * (i as f64 * 0.2).sin())
                        .collect(),
                    Style::Other(0),
                ),
                Series::new(
                    "k2",
                    (0..50).map(|i| i as f64 * 2e-5).collect(),
                    (0..50).map(|i| -2e5 + 1e4 * i as f64).collect(),
                    Style::Other(1),
                ),
            ],
        ),
    )
}

/// The bar figures: typical, small, negative values with a NaN, many categories.
fn bar_figures() -> Vec<(&'static str, BarFigure)> {
    let cats = |n: usize| (1..=n).map(|i| format!("test {i}")).collect::<Vec<_>>();
    vec![
        ("bars.png", common::bar_figure()),
        ("bars_small.png", common::bar_figure().with_size(400, 300)),
        (
            "bars_negative.png",
            BarFigure::new("Bias per test", "mean residual (kPa)", cats(4))
                .with_group("base model", vec![-1.5, 2.0, f64::NAN, 0.7])
                .with_group("with effect", vec![-0.4, 0.6, 0.2, -0.1])
                .with_reference_line("tolerance", 1.0),
        ),
        (
            "bars_many.png",
            BarFigure::new("Many categories", "RMSE (kPa)", cats(30))
                .with_group("a", (0..30).map(|i| 1.0 + (i % 7) as f64).collect())
                .with_group("b", (0..30).map(|i| 0.5 + (i % 5) as f64).collect()),
        ),
    ]
}
