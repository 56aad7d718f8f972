//! Every figure kind on the records a lab hands in at the edges: a test of a single row, a test
//! without sliding (the slip stands still), a test of a million rows, and a test with a name
//! outside ASCII. Each figure is written as PNG and SVG; the PNG decodes at its size, the SVG
//! reads back as SVG, the legend names what it shows, and a long record is decimated.

mod common;

use std::path::Path;

use resvg::usvg;
use subfric_plot::posterior::{BandFigure, CornerFigure, CornerMarker};
use subfric_plot::{
    read_rgb, write_figure, BarFigure, Chart, Figure, IntervalEnd, IntervalFigure, IntervalPoint,
    Panel, Series, Style,
};

/// The name of the test outside ASCII.
const NAME: &str = "Prüfung-σ₁";

/// Writes `chart` as `name`.png and .svg into `dir` and checks both files: the PNG decodes at
/// the chart's size and is not blank, the SVG is a document usvg reads at the same size and
/// holds every text of `texts`. Returns the SVG.
fn written(chart: &impl Chart, dir: &Path, name: &str, texts: &[&str]) -> String {
    let png = dir.join(format!("{name}.png"));
    let files = write_figure(chart, &png).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(files.svg, dir.join(format!("{name}.svg")));
    let img = read_rgb(&png).unwrap();
    assert_eq!((img.width, img.height), chart.size(), "{name}");
    let inked = img
        .pixels()
        .filter(|(_, _, c)| c.iter().any(|&v| v < 200))
        .count();
    assert!(inked > 2000, "{name}: {inked} inked pixels");
    let svg = std::fs::read_to_string(&files.svg).unwrap();
    let tree = usvg::Tree::from_str(&svg, &usvg::Options::default())
        .unwrap_or_else(|e| panic!("{name}: the SVG does not read back: {e}"));
    let size = tree.size();
    assert_eq!(
        (size.width() as u32, size.height() as u32),
        chart.size(),
        "{name}"
    );
    for t in texts {
        assert!(svg.contains(t), "{name}: `{t}` is not in the SVG");
    }
    svg
}

/// The number of points of each line (`<polyline>`) of an SVG document.
fn line_points(svg: &str) -> Vec<usize> {
    svg.lines()
        .filter(|l| l.starts_with("<polyline "))
        .filter_map(|l| {
            let start = l.find("points=\"")? + "points=\"".len();
            let end = start + l[start..].find('"')?;
            Some(l[start..end].split_whitespace().count())
        })
        .collect()
}

/// A measured curve, the fitted model and the residual over `x` (slip, mm) and `y` (friction).
fn overlay(title: &str, x: Vec<f64>, measured: Vec<f64>, fitted: Vec<f64>) -> Figure {
    let residual: Vec<f64> = fitted.iter().zip(&measured).map(|(f, m)| f - m).collect();
    Figure::new(
        title,
        "slip u [mm]",
        Panel::new(
            "friction τ/σ_n [-]",
            vec![
                Series::new("measured", x.clone(), measured, Style::Measured),
                Series::new("fitted", x.clone(), fitted, Style::Fitted),
            ],
        ),
    )
    .with_residual(
        Panel::new(
            "fit − measured [-]",
            vec![Series::new("fitted", x, residual, Style::Fitted)],
        )
        .with_zero_line(),
    )
}

fn bars(title: &str, tests: &[&str], base: Vec<f64>, with: Vec<f64>) -> BarFigure {
    BarFigure::new(
        title,
        "RMS residual / noise SD [-]",
        tests.iter().map(|t| t.to_string()).collect(),
    )
    .with_group("base model", base)
    .with_group("with rate", with)
    .with_reference_line("noise level", 1.0)
}

fn intervals(title: &str, points: Vec<IntervalPoint>, labels: Vec<String>) -> IntervalFigure {
    IntervalFigure::new(title, "", "μ_s [-]")
        .with_group("μ_s", points)
        .with_categories(labels)
}

fn corner(title: &str, samples: Vec<Vec<f64>>) -> CornerFigure {
    CornerFigure::new(title, vec!["κ [1/mm]".into(), "ξ [1/s]".into()], samples)
        .with_marker(CornerMarker {
            label: "optimum".into(),
            values: vec![1.0, 2.0],
            style: Style::Fitted,
        })
        .with_size(700, 700)
}

fn band(title: &str, x: Vec<f64>, mid: Vec<f64>) -> BandFigure {
    let lo: Vec<f64> = mid.iter().map(|v| v - 0.01).collect();
    let hi: Vec<f64> = mid.iter().map(|v| v + 0.01).collect();
    BandFigure::new(
        title,
        "slip u [mm]",
        "friction τ/σ_n [-]",
        x.clone(),
        lo,
        hi,
        "95 % band",
    )
    .with_series(Series::new("median", x, mid.clone(), Style::Fitted))
    .with_difference(mid, "minus the median [-]")
}

#[test]
fn a_test_of_a_single_row_is_drawn_by_every_figure_kind() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fig = overlay("one row", vec![0.0], vec![0.31], vec![0.3]);
    let svg = written(&fig, d, "overlay", &["measured", "fitted"]);
    // The single point is a marker (a disc), not a line.
    assert!(svg.contains("<circle"), "no marker for the one row");
    written(
        &bars("one row", &["one-row"], vec![2.0], vec![1.1]),
        d,
        "bars",
        &["base model", "noise level (1.00)", "one-row"],
    );
    let point = IntervalPoint {
        lo: IntervalEnd::At(0.5),
        hi: IntervalEnd::Open,
        ..IntervalPoint::at(0.0, 0.55)
    };
    written(
        &intervals("one row", vec![point], vec!["one-row".into()]),
        d,
        "intervals",
        &["μ_s", "interval not bounded by the data"],
    );
    written(
        &corner("one sample", vec![vec![1.0], vec![2.0]]),
        d,
        "corner",
        &["optimum", "2.5 %, median, 97.5 %"],
    );
    written(
        &band("one row", vec![0.0], vec![0.3]),
        d,
        "band",
        &["95 % band", "median"],
    );
}

#[test]
fn a_test_without_sliding_is_drawn_by_every_figure_kind() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The slip stands still at 0.2 mm while the friction rises: a hold, or a stuck rig.
    let n = 500;
    let x = vec![0.2; n];
    let y: Vec<f64> = (0..n).map(|i| 0.4 + 0.2 * (i as f64 / n as f64)).collect();
    let fig = overlay("no sliding", x.clone(), y.clone(), y.clone());
    let l = subfric_plot::figure_layout(&fig).unwrap();
    assert!(l.x_range.0 < 0.2 && l.x_range.1 > 0.2, "{:?}", l.x_range);
    written(&fig, d, "overlay", &["measured", "fitted"]);
    // No sliding, no misfit to show: zeros and a test without a value.
    written(
        &bars(
            "no sliding",
            &["stuck", "held"],
            vec![0.0, f64::NAN],
            vec![0.0, 0.0],
        ),
        d,
        "bars",
        &["n/a", "base model"],
    );
    let points = vec![IntervalPoint::at(0.0, 0.5), IntervalPoint::at(1.0, 0.5)];
    written(
        &intervals("no sliding", points, vec!["stuck".into(), "held".into()]),
        d,
        "intervals",
        &["μ_s", "stuck", "held"],
    );
    // What sliding would determine stays at its first guess: a constant column.
    let kappa: Vec<f64> = (0..400).map(|i| 1.0 + 0.001 * f64::from(i % 7)).collect();
    written(
        &corner("no sliding", vec![kappa, vec![2.0; 400]]),
        d,
        "corner",
        &["optimum"],
    );
    let b = band("no sliding", x, y);
    let l = subfric_plot::posterior::band_layout(&b).unwrap();
    assert!(l.x_range.0 < 0.2 && l.x_range.1 > 0.2);
    let svg = written(&b, d, "band", &["95 % band"]);
    assert!(svg.contains("<polygon"), "the band where x stands still");
}

#[test]
fn a_test_of_a_million_rows_is_decimated_by_every_figure_kind() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let n = 1_000_000;
    let x: Vec<f64> = (0..n).map(|i| i as f64 * 1e-5).collect();
    let mut rng = common::Lcg::new(11);
    let fitted = common::monotonic(&x, 0.7, 0.55, 0.05);
    let measured: Vec<f64> = fitted.iter().map(|v| v + 0.01 * rng.next()).collect();
    let fig = overlay(
        "a million rows",
        x.clone(),
        measured.clone(),
        fitted.clone(),
    );
    let svg = written(&fig, d, "overlay", &["measured", "fitted"]);
    // Every line keeps at most four points per pixel column of the 1000-pixel-wide figure
    // (first, lowest, highest, last), and so the whole figure stays small.
    let lines = line_points(&svg);
    assert!(lines.len() >= 3, "{lines:?}");
    assert!(lines.iter().all(|&k| k <= 4 * 1000), "{lines:?}");
    assert!(lines.iter().any(|&k| k >= 1000), "{lines:?}");
    let layout = subfric_plot::figure_layout(&fig).unwrap();
    assert!(layout.main_line_points.iter().all(|&k| k <= 4 * 1000));
    assert!(svg.len() < 2_000_000, "{} bytes of SVG", svg.len());
    // The bar chart and the interval figure show one number of such a test.
    let rms = (measured
        .iter()
        .zip(&fitted)
        .map(|(m, f)| (m - f) * (m - f))
        .sum::<f64>()
        / n as f64)
        .sqrt()
        / 0.01;
    written(
        &bars("a million rows", &["long"], vec![rms], vec![rms * 0.9]),
        d,
        "bars",
        &["long"],
    );
    written(
        &intervals(
            "a million rows",
            vec![IntervalPoint::at(0.0, measured[n / 2])],
            vec!["long".into()],
        ),
        d,
        "intervals",
        &["long"],
    );
    // A million posterior samples become 30 x 30 bins.
    let a: Vec<f64> = (0..n).map(|_| 1.0 + 0.1 * rng.next()).collect();
    let b: Vec<f64> = a.iter().map(|v| 2.0 / v + 0.01 * rng.next()).collect();
    let svg = written(
        &corner("a million samples", vec![a, b]),
        d,
        "corner",
        &["optimum"],
    );
    assert!(svg.len() < 1_000_000, "{} bytes of SVG", svg.len());
    let svg = written(
        &band("a million rows", x, fitted),
        d,
        "band",
        &["95 % band"],
    );
    let polygon_points: usize = svg
        .lines()
        .filter(|l| l.starts_with("<polygon "))
        .map(|l| l.matches(',').count())
        .sum();
    assert!(
        polygon_points <= 4 * 2 * 1000,
        "{polygon_points} band points"
    );
    assert!(line_points(&svg).iter().all(|&k| k <= 4 * 1000));
}

#[test]
fn a_test_named_outside_ascii_is_named_in_every_figure_kind() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let x: Vec<f64> = (0..200).map(|i| f64::from(i) * 0.01).collect();
    let y = common::monotonic(&x, 0.7, 0.55, 0.1);
    let title = format!("table1: {NAME} (100 kPa)");
    let mut fig = overlay(&title, x.clone(), y.clone(), y.clone());
    fig.main.series[1].label = format!("fitted to {NAME}");
    let svg = written(&fig, d, NAME, &[&title, &format!("fitted to {NAME}")]);
    // The text is laid out with the bundled font, which has these letters: the title is
    // drawn, not boxes (the PNG holds dark pixels across the title's width).
    assert!(svg.contains("font-family=\"DejaVu Sans"));
    let img = read_rgb(&d.join(format!("{NAME}.png"))).unwrap();
    let title_ink = img
        .pixels()
        .filter(|&(_, y, c)| y < 40 && c.iter().all(|&v| v < 100))
        .count();
    assert!(title_ink > 300, "{title_ink} dark pixels in the title");
    written(
        &bars(&title, &[NAME, "other"], vec![2.0, 1.5], vec![1.0, 1.2]),
        d,
        "bars",
        &[NAME],
    );
    written(
        &intervals(&title, vec![IntervalPoint::at(0.0, 0.6)], vec![NAME.into()]),
        d,
        "intervals",
        &[NAME],
    );
    written(
        &corner(&title, vec![vec![1.0, 1.1, 0.9], vec![2.0, 2.1, 1.9]]),
        d,
        "corner",
        &[NAME],
    );
    written(&band(&title, x, y), d, "band", &[NAME]);
}
