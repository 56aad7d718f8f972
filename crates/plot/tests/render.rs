//! End-to-end checks: render figures into a temporary directory, decode the
//! PNGs with the `png` crate and check what a reader would see.

mod common;

use std::path::Path;

use subfric_plot::{
    bar_layout, figure_layout, inspect_png, read_rgb, render_bars_png, render_png, render_svg,
    series_inside, BarFigure, Figure, Panel, PixelRect, PlotError, RgbImage, Series, Style,
    FITTED_RGB, MEASURED_RGB, PUBLISHED_RGB,
};

/// Strongly red pixels: the fitted colour and its near-opaque blends. No
/// other colour this crate draws (text, grid, frame, viridis, blue, grey,
/// the other-series palette) falls into this class.
fn is_fitted_red(c: [u8; 3]) -> bool {
    let [r, g, b] = c.map(i32::from);
    r >= 150 && g <= 110 && b <= 110 && r - g >= 90 && (g - b).abs() <= 40
}

fn count(img: &RgbImage, pred: impl Fn([u8; 3]) -> bool) -> usize {
    img.pixels().filter(|&(_, _, c)| pred(c)).count()
}

fn inside_any(rects: &[PixelRect], x: u32, y: u32) -> bool {
    rects.iter().any(|r| r.contains(x as i32, y as i32))
}

fn render(fig: &Figure, dir: &Path, name: &str) -> RgbImage {
    let path = dir.join(name);
    render_png(fig, &path).unwrap_or_else(|e| panic!("{name}: {e}"));
    read_rgb(&path).unwrap()
}

#[test]
fn full_figure_is_a_readable_paper_figure() {
    let dir = tempfile::tempdir().unwrap();
    let fig = common::cyclic_figure(3000);
    let path = dir.path().join("cyclic.png");
    render_png(&fig, &path).unwrap();

    let check = inspect_png(&path).unwrap();
    assert_eq!((check.width, check.height), (1000, 750));
    assert!(
        check.inked_fraction > 0.03 && check.inked_fraction < 0.5,
        "inked fraction {}",
        check.inked_fraction
    );
    assert!(
        check.distinct_colors >= 30,
        "{} colours",
        check.distinct_colors
    );

    let layout = figure_layout(&fig).unwrap();
    let residual = layout.residual.expect("residual panel");
    // Residual panel below the main one, about a third of the plotting height.
    assert!(residual.top > layout.main.bottom);
    assert_eq!(
        (residual.left, residual.right),
        (layout.main.left, layout.main.right)
    );
    let share = f64::from(residual.height()) / f64::from(residual.height() + layout.main.height());
    assert!((0.28..=0.38).contains(&share), "residual share {share}");

    let img = read_rgb(&path).unwrap();
    // Fitted red appears in both panels, and only inside the plotting areas.
    let rects = [layout.main, residual];
    let mut in_main = 0;
    let mut in_residual = 0;
    for (x, y, c) in img.pixels() {
        if is_fitted_red(c) {
            assert!(
                inside_any(&rects, x, y),
                "fitted-colour pixel outside the axes at ({x}, {y})"
            );
            if layout.main.contains(x as i32, y as i32) {
                in_main += 1;
            } else {
                in_residual += 1;
            }
        }
    }
    assert!(in_main > 2000, "{in_main} red pixels in the main panel");
    assert!(
        in_residual > 2000,
        "{in_residual} red pixels in the residual panel"
    );
    assert!(count(&img, |c| c == FITTED_RGB) > 1000);
    // Published blue and the cycle colours (first and last cycle) appear.
    assert!(count(&img, |c| c == PUBLISHED_RGB) > 100);
    let first = subfric_plot::cycle_rgb(Style::Measured, 0.0);
    let last = subfric_plot::cycle_rgb(Style::Measured, 1.0);
    assert!(
        count(&img, |c| c == first) > 50,
        "first-cycle colour missing"
    );
    assert!(count(&img, |c| c == last) > 50, "last-cycle colour missing");

    // The legend is a white box inside the main panel.
    let legend = layout.main_legend.expect("legend");
    assert!(layout.main.contains(legend.left, legend.top));
    assert!(layout.main.contains(legend.right, legend.bottom));
    let white = (legend.left + 2..legend.right - 1)
        .flat_map(|x| (legend.top + 2..legend.bottom - 1).map(move |y| (x, y)))
        .filter(|&(x, y)| img.pixel(x as u32, y as u32) == Some([255, 255, 255]))
        .count();
    let area = ((legend.width() - 3) * (legend.height() - 3)) as usize;
    assert!(white * 10 > area * 6, "legend box is not mostly white");

    // Text was rendered with the bundled font: dark pixels in the title band,
    // left of the axes (y label and tick labels) and below them (x label).
    let dark = |c: [u8; 3]| c.iter().all(|&v| v < 100);
    let band = |x0: i32, x1: i32, y0: i32, y1: i32| {
        img.pixels()
            .filter(|&(x, y, c)| {
                (x0..x1).contains(&(x as i32)) && (y0..y1).contains(&(y as i32)) && dark(c)
            })
            .count()
    };
    assert!(band(0, 1000, 0, layout.main.top - 2) > 300, "no title text");
    assert!(
        band(
            0,
            layout.main.left - 10,
            layout.main.top,
            layout.main.bottom
        ) > 200,
        "no y label text"
    );
    assert!(
        band(0, 1000, residual.bottom + 10, 750) > 300,
        "no x tick/label text"
    );

    assert!(series_inside(&fig));
}

// How fast a figure renders is measured by `cargo run -p subfric-plot --release --example
// measure`, not asserted here: the project's speed targets live in benchmarks, and a wall-time
// limit in a test fails on a loaded machine (it did, at 123 ms against 100 ms, with a load
// average of 13).

#[test]
fn very_long_series_is_decimated_without_losing_extremes() {
    let dir = tempfile::tempdir().unwrap();
    let n = 100_000;
    let x: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
    let y: Vec<f64> = (0..n)
        .map(|i| {
            if i == 61_234 {
                100.0
            } else {
                ((i as f64) * 0.01).sin()
            }
        })
        .collect();
    let fig = Figure::new(
        "long",
        "x (mm)",
        Panel::new("y (kPa)", vec![Series::new("", x, y, Style::Fitted)]),
    );
    // (Its speed is the measure example's to report; see the note above.)
    let img = render(&fig, dir.path(), "long.png");
    let layout = figure_layout(&fig).unwrap();
    // The single spike reaches (almost) the top of the data range: red
    // pixels within a few rows of where y = 100 maps.
    let (ymin, ymax) = layout.main_y_range;
    let r = layout.main;
    let spike_y =
        f64::from(r.bottom) - (100.0 - ymin) / (ymax - ymin) * f64::from(r.bottom - r.top);
    let near_top = img
        .pixels()
        .filter(|&(_, y, c)| is_fitted_red(c) && (f64::from(y) - spike_y).abs() <= 3.0)
        .count();
    assert!(near_top > 0, "spike lost by decimation");
    assert!(series_inside(&fig));
}

fn degenerate_figures() -> Vec<(&'static str, Figure)> {
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    // Half size keeps the pixel checks quick in unoptimised builds.
    let fig = |main: Vec<Series>| {
        Figure::new("degenerate", "x (mm)", Panel::new("y (kPa)", main)).with_size(500, 375)
    };
    let s = |x: Vec<f64>, y: Vec<f64>, style| Series::new("s", x, y, style);
    vec![
        ("no_series", fig(vec![])),
        ("empty_series", fig(vec![s(vec![], vec![], Style::Fitted)])),
        ("nan_only", fig(vec![s(vec![nan; 10], vec![nan; 10], Style::Fitted)])),
        ("inf_only", fig(vec![s(vec![inf, -inf], vec![1.0, 2.0], Style::Published)])),
        ("single_point", fig(vec![s(vec![1.0], vec![2.0], Style::Fitted)])),
        ("all_equal", fig(vec![s(vec![3.0; 50], vec![7.0; 50], Style::Fitted)])),
        ("all_zero", fig(vec![s(vec![0.0; 5], vec![0.0; 5], Style::Measured)])),
        (
            "huge_values",
            fig(vec![s(vec![0.0, 1.0, 2.0, 3.0], vec![-1e308, 1e300, f64::MAX, 5.0], Style::Fitted)]),
        ),
        (
            "tiny_span",
            fig(vec![s(vec![1.0, 1.0 + 1e-13, 1.0 + 2e-13], vec![1e-300, 2e-300, 3e-300], Style::Fitted)]),
        ),
        (
            "nan_gaps_and_cycles",
            fig(vec![s(vec![0.0, 1.0, nan, 3.0, 4.0], vec![1.0, nan, 2.0, 3.0, 4.0], Style::Measured)
                .with_cycles(vec![1, 1, 2, 2, 3])]),
        ),
        (
            "nan_residual",
            fig(vec![s(vec![0.0, 1.0], vec![0.0, 1.0], Style::Fitted)])
                .with_residual(Panel::new("r", vec![s(vec![nan], vec![nan], Style::Fitted)]).with_zero_line()),
        ),
        (
            "empty_labels_everywhere",
            Figure::new("", "", Panel::new("", vec![Series::new("", vec![0.0, 1.0], vec![1.0, 0.0], Style::Other(99))])),
        ),
        (
            "very_long_labels",
            Figure::new(
                "A title that is far too long to fit on one line of a figure even at a reduced font size, really far too long",
                "an x label that is also much longer than it should ever be for a figure axis (mm)",
                Panel::new(
                    "a y label much longer than the panel is high, so it must shrink and be shortened (kPa)",
                    vec![Series::new("a legend label that is far too long for any legend box, so it is shortened", vec![0.0, 1.0], vec![0.0, 1.0], Style::Fitted)],
                ),
            )
            .with_residual(Panel::new("residual label longer than the residual panel (kPa)", vec![]).with_zero_line()),
        ),
        ("minimum_size", common::cyclic_figure(300).with_size(200, 150)),
        ("tall_narrow", common::monotonic_figure().with_size(240, 900)),
    ]
}

#[test]
fn degenerate_input_gives_valid_plots_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    for (name, fig) in degenerate_figures() {
        let path = dir.path().join(format!("{name}.png"));
        let result = std::panic::catch_unwind(|| render_png(&fig, &path));
        let result = result.unwrap_or_else(|_| panic!("{name}: panicked"));
        result.unwrap_or_else(|e| panic!("{name}: {e}"));
        let img = read_rgb(&path).unwrap();
        assert_eq!((img.width, img.height), (fig.width, fig.height), "{name}");
        let inked = img
            .data
            .chunks_exact(3)
            .filter(|c| c.iter().any(|&v| v < 245))
            .count();
        assert!(inked * 200 > img.data.len() / 3, "{name}: blank");
        assert!(series_inside(&fig), "{name}: points outside the ranges");
        let layout = figure_layout(&fig).unwrap();
        for (lo, hi) in [layout.x_range, layout.main_y_range] {
            assert!(
                lo.is_finite() && hi.is_finite() && lo < hi,
                "{name}: range {lo}..{hi}"
            );
        }
        // Fitted red stays inside the axes here too.
        let rects: Vec<PixelRect> = std::iter::once(layout.main)
            .chain(layout.residual)
            .collect();
        for (x, y, c) in img.pixels() {
            if is_fitted_red(c) {
                assert!(
                    inside_any(&rects, x, y),
                    "{name}: red pixel outside the axes at ({x}, {y})"
                );
            }
        }
    }
}

#[test]
fn invalid_input_is_an_error_naming_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.png");
    let mismatched = Figure::new(
        "t",
        "x",
        Panel::new(
            "y",
            vec![Series::new(
                "oops",
                vec![1.0, 2.0],
                vec![1.0],
                Style::Fitted,
            )],
        ),
    );
    let e = render_png(&mismatched, &path).unwrap_err();
    assert!(
        matches!(
            e,
            PlotError::LengthMismatch {
                x_len: 2,
                y_len: 1,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(
        e.to_string().contains("bad.png") && e.to_string().contains("oops"),
        "{e}"
    );

    let bad_cycles = Figure::new(
        "t",
        "x",
        Panel::new(
            "y",
            vec![
                Series::new("c", vec![1.0, 2.0], vec![1.0, 2.0], Style::Measured)
                    .with_cycles(vec![1]),
            ],
        ),
    );
    assert!(matches!(
        render_png(&bad_cycles, &path),
        Err(PlotError::CycleLengthMismatch { .. })
    ));

    for (w, h) in [(0, 0), (10, 750), (1000, 10), (100_000, 750)] {
        let fig = common::monotonic_figure().with_size(w, h);
        let e = render_png(&fig, &path).unwrap_err();
        assert!(matches!(e, PlotError::InvalidSize { .. }), "{w}x{h}: {e:?}");
        assert!(e.to_string().contains("bad.png"));
        assert!(figure_layout(&fig).is_none());
    }
    assert!(!path.exists(), "no file is written for invalid input");

    let unwritable = dir.path().join("missing-dir").join("out.png");
    let e = render_png(&common::monotonic_figure(), &unwritable).unwrap_err();
    assert!(matches!(e, PlotError::Io { .. }), "{e:?}");
    assert!(e.to_string().contains("out.png"));
}

#[test]
fn legend_goes_where_the_data_is_sparse() {
    let x: Vec<f64> = (0..200).map(|i| i as f64 / 199.0).collect();
    let rising: Vec<f64> = x.iter().map(|v| v * v * v).collect();
    let falling: Vec<f64> = x.iter().map(|v| 1.0 - v).collect();
    let fig = |y: Vec<f64>| {
        Figure::new(
            "legend",
            "x (mm)",
            Panel::new(
                "y (kPa)",
                vec![
                    Series::new("model A", x.clone(), y.clone(), Style::Fitted),
                    Series::new(
                        "model B",
                        x.clone(),
                        y.iter().map(|v| v * 0.95).collect(),
                        Style::Published,
                    ),
                ],
            ),
        )
    };
    // Falling curve: the upper right is empty, so the legend goes there.
    let l = figure_layout(&fig(falling)).unwrap();
    let legend = l.main_legend.unwrap();
    let mid_x = (l.main.left + l.main.right) / 2;
    let mid_y = (l.main.top + l.main.bottom) / 2;
    assert!(
        legend.left > mid_x && legend.bottom < mid_y,
        "falling: {legend:?} in {:?}",
        l.main
    );
    // Rising curve ends in the upper right: the legend moves to the lower right.
    let l = figure_layout(&fig(rising)).unwrap();
    let legend = l.main_legend.unwrap();
    assert!(
        legend.left > mid_x && legend.top > mid_y,
        "rising: {legend:?} in {:?}",
        l.main
    );
}

#[test]
fn measured_series_with_few_points_gets_markers() {
    let dir = tempfile::tempdir().unwrap();
    let fig = common::monotonic_figure();
    let img = render(&fig, dir.path(), "monotonic.png");
    // Filled grey markers: 3x3 blocks of the exact measured colour.
    let block = (1..img.width - 1)
        .flat_map(|x| (1..img.height - 1).map(move |y| (x, y)))
        .filter(|&(x, y)| {
            (0..3)
                .all(|dx| (0..3).all(|dy| img.pixel(x + dx - 1, y + dy - 1) == Some(MEASURED_RGB)))
        })
        .count();
    assert!(block > 20, "{block} marker pixels");
    assert!(series_inside(&fig));
}

#[test]
fn bar_chart_renders_and_decodes() {
    let dir = tempfile::tempdir().unwrap();
    let fig = common::bar_figure();
    let path = dir.path().join("bars.png");
    render_bars_png(&fig, &path).unwrap();
    let check = inspect_png(&path).unwrap();
    assert_eq!((check.width, check.height), (1000, 750));
    assert!(
        check.inked_fraction > 0.1 && check.inked_fraction < 0.7,
        "{}",
        check.inked_fraction
    );
    assert!(check.distinct_colors >= 10);

    let layout = bar_layout(&fig).unwrap();
    assert_eq!(layout.bars.len(), 12);
    assert!(layout.y_range.0 == 0.0 && layout.y_range.1 > 9.4);
    let img = read_rgb(&path).unwrap();
    // Each bar is filled with its group colour.
    for (j, g, r) in &layout.bars {
        let c = img
            .pixel(((r.left + r.right) / 2) as u32, (r.bottom - 2) as u32)
            .unwrap();
        let expected = if *g == 0 {
            [31, 119, 180]
        } else {
            [255, 127, 14]
        };
        assert_eq!(c, expected, "bar {j}/{g}");
        assert!(layout.plot.contains(r.left, r.top) && layout.plot.contains(r.right, r.bottom));
    }
    let legend = layout.legend.expect("legend");
    for (_, _, r) in &layout.bars {
        assert!(!r.intersects(&legend), "legend covers a bar");
    }
}

#[test]
fn degenerate_bar_charts() {
    let dir = tempfile::tempdir().unwrap();
    let cats = |n: usize| (0..n).map(|i| format!("category {i}")).collect::<Vec<_>>();
    let charts = vec![
        ("none", BarFigure::new("", "", vec![])),
        ("no_groups", BarFigure::new("t", "y", cats(3))),
        (
            "nan",
            BarFigure::new("t", "y", cats(2)).with_group("g", vec![f64::NAN, f64::INFINITY]),
        ),
        (
            "zeros",
            BarFigure::new("t", "y", cats(2)).with_group("g", vec![0.0, 0.0]),
        ),
        (
            "negative",
            BarFigure::new("t", "y", cats(3))
                .with_group("a", vec![-1.0, 2.0, -3.0])
                .with_reference_line("ref", -0.5),
        ),
        (
            "nan_reference",
            BarFigure::new("t", "y", cats(1))
                .with_group("a", vec![1.0])
                .with_reference_line("ref", f64::NAN),
        ),
        (
            "many",
            BarFigure::new("t", "y", cats(60))
                .with_group("a", vec![1.0; 60])
                .with_group("b", vec![2.0; 60])
                .with_group("c", vec![3.0; 60]),
        ),
        ("small", common::bar_figure().with_size(200, 150)),
    ];
    for (name, fig) in charts {
        let path = dir.path().join(format!("{name}.png"));
        render_bars_png(&fig, &path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let check = inspect_png(&path).unwrap();
        assert_eq!((check.width, check.height), (fig.width, fig.height));
        assert!(check.inked_fraction > 0.005, "{name}: blank");
    }
    let bad = BarFigure::new("t", "y", cats(3)).with_group("short", vec![1.0]);
    let path = dir.path().join("bad_bars.png");
    let e = render_bars_png(&bad, &path).unwrap_err();
    assert!(matches!(
        e,
        PlotError::GroupLengthMismatch {
            values: 1,
            categories: 3,
            ..
        }
    ));
    assert!(e.to_string().contains("bad_bars.png") && e.to_string().contains("short"));
    let e = render_bars_png(&common::bar_figure().with_size(100, 100), &path).unwrap_err();
    assert!(matches!(e, PlotError::InvalidSize { .. }));
}

#[test]
fn inspect_rejects_non_png() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fake.png");
    std::fs::write(&path, b"\x89PNG but not really").unwrap();
    let e = inspect_png(&path).unwrap_err();
    assert!(matches!(e, PlotError::Decode { .. }));
    assert!(e.to_string().contains("fake.png"));
}

#[test]
fn random_messy_input_never_panics() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = common::Lcg::new(42);
    let value = |rng: &mut common::Lcg| {
        let r = rng.next();
        match ((r + 1.0) * 10.0) as u32 {
            0 => f64::NAN,
            1 => f64::INFINITY,
            2 => -f64::INFINITY,
            3 => 1e305 * rng.next(),
            4 => 1e-305 * rng.next(),
            5 => 0.0,
            _ => 1e3 * rng.next(),
        }
    };
    for k in 0..30 {
        let mut panels = Vec::new();
        for _ in 0..2 {
            let n_series = ((rng.next() + 1.0) * 2.5) as usize;
            let mut series = Vec::new();
            for j in 0..n_series {
                let n = ((rng.next() + 1.0) * 250.0) as usize;
                let x: Vec<f64> = (0..n).map(|_| value(&mut rng)).collect();
                let y: Vec<f64> = (0..n).map(|_| value(&mut rng)).collect();
                let style = match j % 4 {
                    0 => Style::Measured,
                    1 => Style::Published,
                    2 => Style::Fitted,
                    _ => Style::Other(k),
                };
                let mut s = Series::new(format!("series {j}"), x, y, style);
                if rng.next() > 0.3 {
                    s = s.with_cycles((0..n).map(|i| (i / 7) as u32 * 3).collect());
                }
                series.push(s);
            }
            let mut p = Panel::new("y (kPa)", series);
            p.zero_line = rng.next() > 0.0;
            panels.push(p);
        }
        let residual = panels.pop().unwrap();
        let mut fig = Figure::new(format!("random {k}"), "x (mm)", panels.pop().unwrap())
            .with_size(200 + (k as u32 * 37) % 400, 150 + (k as u32 * 53) % 300);
        if k % 2 == 0 {
            fig = fig.with_residual(residual);
        }
        let path = dir.path().join(format!("random{k}.png"));
        render_png(&fig, &path).unwrap_or_else(|e| panic!("figure {k}: {e}"));
        assert!(series_inside(&fig), "figure {k}");
        let check = inspect_png(&path).unwrap();
        assert_eq!((check.width, check.height), (fig.width, fig.height));
    }
}

#[test]
fn random_messy_bar_charts_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = common::Lcg::new(7);
    for k in 0..20 {
        let n = ((rng.next() + 1.0) * 6.0) as usize;
        let cats: Vec<String> = (0..n).map(|i| "word ".repeat(i % 5 + 1)).collect();
        let mut fig = BarFigure::new(format!("bars {k}"), "value (kPa)", cats)
            .with_size(200 + (k as u32 * 71) % 600, 150 + (k as u32 * 29) % 400);
        for g in 0..(k % 4) {
            let values = (0..n)
                .map(|_| match ((rng.next() + 1.0) * 5.0) as u32 {
                    0 => f64::NAN,
                    1 => 1e300 * rng.next(),
                    2 => 1e-300 * rng.next(),
                    _ => 10.0 * rng.next(),
                })
                .collect();
            fig = fig.with_group(format!("group {g}"), values);
        }
        if k % 3 == 0 {
            fig = fig.with_reference_line("ref", 5.0 * rng.next());
        }
        let path = dir.path().join(format!("bars{k}.png"));
        render_bars_png(&fig, &path).unwrap_or_else(|e| panic!("chart {k}: {e}"));
        let check = inspect_png(&path).unwrap();
        assert_eq!((check.width, check.height), (fig.width, fig.height));
    }
}

/// A measured curve and a model that agrees with it: the data must stay visible on top.
fn agreeing_figure() -> Figure {
    let x: Vec<f64> = (0..400).map(|i| f64::from(i) * 0.01).collect();
    let y: Vec<f64> = x
        .iter()
        .map(|u| 0.6 * (1.0 - (-u / 0.05).exp()) + 0.1 * (-u / 0.3).exp())
        .collect();
    Figure::new(
        "agreeing",
        "slip u [mm]",
        Panel::new(
            "friction [-]",
            vec![
                Series::new("measured", x.clone(), y.clone(), Style::Measured),
                Series::new("published", x.clone(), y.clone(), Style::Published),
                Series::new("fitted", x, y, Style::Fitted),
            ],
        ),
    )
}

/// Pixels of exactly `colour` whose four neighbours are too: the inside of a marker disc (a
/// line of any width and direction in that colour is drawn beneath the markers, never over
/// them, so only discs give such crosses of the markers' colour).
fn blocks_of(img: &RgbImage, colour: [u8; 3], area: PixelRect) -> usize {
    (area.left + 1..area.right)
        .flat_map(|x| (area.top + 1..area.bottom).map(move |y| (x, y)))
        .filter(|&(x, y)| {
            [(0, 0), (-1, 0), (1, 0), (0, -1), (0, 1)]
                .iter()
                .all(|(dx, dy)| img.pixel((x + dx) as u32, (y + dy) as u32) == Some(colour))
        })
        .count()
}

#[test]
fn measured_data_are_drawn_on_top_of_an_agreeing_model() {
    let dir = tempfile::tempdir().unwrap();
    let fig = agreeing_figure();
    let img = render(&fig, dir.path(), "agreeing.png");
    let layout = figure_layout(&fig).unwrap();
    // Dense data (400 points): a sample of markers, spaced along the curve, over the red line.
    let markers = blocks_of(&img, MEASURED_RGB, layout.main);
    assert!(markers > 40, "{markers} marker pixels: the data are hidden");
    // ... and the model still shows between them.
    assert!(count(&img, is_fitted_red) > 300, "the model is hidden");
}

#[test]
fn an_inset_zooms_on_part_of_the_x_range_away_from_the_legend() {
    let dir = tempfile::tempdir().unwrap();
    let fig = agreeing_figure().with_inset("first loading", 0.0, 0.4);
    let layout = figure_layout(&fig).unwrap();
    let inset = layout.inset.expect("an inset");
    let main = layout.main;
    assert!(main.contains(inset.left, inset.top) && main.contains(inset.right, inset.bottom));
    assert!(inset.width() * 3 > main.width() && inset.height() * 3 > main.height());
    if let Some(legend) = layout.main_legend {
        assert!(!legend.intersects(&inset), "{legend:?} over {inset:?}");
    }
    let img = render(&fig, dir.path(), "inset.png");
    // The zoomed curve is drawn in the inset: red and marker pixels inside its box.
    let inside = |x: u32, y: u32| inset.contains(x as i32, y as i32);
    let red = img
        .pixels()
        .filter(|&(x, y, c)| inside(x, y) && is_fitted_red(c))
        .count();
    assert!(red > 150, "{red} red pixels in the inset");
    let marked = img
        .pixels()
        .filter(|&(x, y, c)| inside(x, y) && c == MEASURED_RGB)
        .count();
    assert!(marked > 30, "{marked} marker pixels in the inset");
    // A zoom over the whole range is no zoom: none is drawn.
    let whole = agreeing_figure().with_inset("all", -1.0, 10.0);
    assert!(figure_layout(&whole).unwrap().inset.is_none());
}

#[test]
fn a_history_panel_sits_between_the_main_and_the_residual_panel() {
    let x: Vec<f64> = (0..200).map(f64::from).collect();
    let imposed: Vec<f64> = x.iter().map(|t| 40.0 * (t / 20.0).sin().abs()).collect();
    let fig = agreeing_figure()
        .with_history(Panel::new(
            "imposed τ [kPa]",
            vec![Series::new("imposed", x.clone(), imposed, Style::Other(0))],
        ))
        .with_residual(Panel::new(
            "r",
            vec![Series::new("r", x, vec![0.0; 200], Style::Fitted)],
        ));
    let l = figure_layout(&fig).unwrap();
    let (h, r) = (l.history.unwrap(), l.residual.unwrap());
    assert!(l.main.bottom < h.top && h.bottom < r.top);
    assert_eq!((h.left, h.right), (l.main.left, l.main.right));
    assert!(h.height() * 2 < l.main.height());
    let dir = tempfile::tempdir().unwrap();
    let img = render(&fig, dir.path(), "history.png");
    let orange = subfric_plot::style_rgb(Style::Other(0));
    let in_history = img
        .pixels()
        .filter(|&(x, y, c)| h.contains(x as i32, y as i32) && c == orange)
        .count();
    assert!(
        in_history > 100,
        "{in_history} pixels of the imposed history"
    );
}

/// The tick labels of an SVG document: the text of its `<text>` elements.
fn svg_texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let body = &t[t.find('>')? + 1..];
            Some(body[..body.find("</text>")?].trim().to_string())
        })
        .collect()
}

#[test]
fn an_axis_that_counts_things_has_whole_ticks_even_beside_shifted_series() {
    // Three velocity steps with their estimates, and a second series drawn 0.15 to the right.
    let steps = Series::new(
        "fitted",
        vec![1.0, 2.0, 3.0],
        vec![0.1, 0.2, 0.15],
        Style::Fitted,
    );
    let beside = Series::new(
        "measured",
        vec![1.15, 2.15, 3.15],
        vec![0.12, 0.18, 0.16],
        Style::Measured,
    );
    let fig = |whole: bool| {
        let f = Figure::new(
            "steps",
            "velocity step",
            Panel::new("a", vec![steps.clone(), beside.clone()]),
        );
        if whole {
            f.with_whole_x()
        } else {
            f
        }
    };
    let texts = svg_texts(&render_svg(&fig(true), Path::new("steps.svg")).unwrap());
    for half in ["1.5", "2.5", "0.5"] {
        assert!(
            !texts.iter().any(|t| t == half),
            "a tick at {half}: {texts:?}"
        );
    }
    for whole in ["1", "2", "3"] {
        assert!(
            texts.iter().any(|t| t == whole),
            "no tick at {whole}: {texts:?}"
        );
    }
    // Without it the shifted series makes the axis continuous (the figure as before).
    let texts = svg_texts(&render_svg(&fig(false), Path::new("steps.svg")).unwrap());
    assert!(texts.iter().any(|t| t.contains('.')), "{texts:?}");
}
