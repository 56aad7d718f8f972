//! The posterior figures: a corner plot shows a valley where the samples lie along one, the
//! band overlay shades between its edges (also along a vertical stretch), and bad input is an
//! error naming the file, never a panic.

use std::path::Path;

use subfric_plot::posterior::{
    band_layout, corner_layout, render_band_png, render_corner_png, BandFigure, BandLayout,
    CornerFigure, CornerMarker,
};
use subfric_plot::{read_rgb, PlotError, RgbImage, Series, Style};

/// A small deterministic generator: uniform in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The pixel column of `v` on the main panel of a band figure.
fn pixel_x(l: &BandLayout, v: f64) -> u32 {
    (l.plot.left as f64
        + (v - l.x_range.0) / (l.x_range.1 - l.x_range.0) * (l.plot.right - l.plot.left) as f64)
        .round() as u32
}

/// The pixel row of `v` on the main panel of a band figure.
fn pixel_y(l: &BandLayout, v: f64) -> u32 {
    (l.plot.bottom as f64
        - (v - l.y_range.0) / (l.y_range.1 - l.y_range.0) * (l.plot.bottom - l.plot.top) as f64)
        .round() as u32
}

fn darkness(c: [u8; 3]) -> i32 {
    765 - c.iter().map(|v| i32::from(*v)).sum::<i32>()
}

/// Samples of (a, b, c): b = 100/a² along a curved valley (not symmetric under a swap of the
/// axes), c independent.
fn valley(n: usize) -> Vec<Vec<f64>> {
    let mut rng = Lcg(3);
    let mut cols = vec![Vec::new(), Vec::new(), Vec::new()];
    for _ in 0..n {
        let a = 1.0 + 9.0 * rng.next();
        cols[0].push(a);
        cols[1].push(100.0 / (a * a) * (1.0 + 0.02 * (rng.next() - 0.5)));
        cols[2].push(rng.next());
    }
    cols
}

fn render_corner(fig: &CornerFigure, dir: &Path) -> RgbImage {
    let path = dir.join("corner.png");
    render_corner_png(fig, &path).unwrap();
    read_rgb(&path).unwrap()
}

#[test]
fn a_corner_plot_shows_the_valley_the_samples_lie_in() {
    let dir = tempfile::tempdir().unwrap();
    let fig = CornerFigure::new(
        "valley",
        vec!["a".into(), "b".into(), "c".into()],
        valley(20_000),
    )
    .with_marker(CornerMarker {
        label: "optimum".into(),
        values: vec![2.0, 25.0, 0.5],
        style: Style::Fitted,
    });
    let img = render_corner(&fig, dir.path());
    let layout = corner_layout(&fig).unwrap();
    assert_eq!(layout.panels.len(), 6, "a triangle of 3 × 3 panels");
    let pair = layout.panel(1, 0).unwrap();
    let (ra, rb) = (layout.ranges[0], layout.ranges[1]);
    let at = |a: f64, b: f64| -> [u8; 3] {
        let x = pair.left as f64 + (a - ra.0) / (ra.1 - ra.0) * (pair.right - pair.left) as f64;
        let y = pair.bottom as f64 - (b - rb.0) / (rb.1 - rb.0) * (pair.bottom - pair.top) as f64;
        img.pixel(x.round() as u32, y.round() as u32).unwrap()
    };
    // Along the valley b = 100/a² the panel is shaded, off it (far from the curve) it is white
    // (or a light grid line).
    for a in [1.5, 3.0, 6.0, 9.0] {
        let b = 100.0 / (a * a);
        assert!(
            darkness(at(a, b)) > 100,
            "on the valley at a = {a}: {:?}",
            at(a, b)
        );
    }
    for (a, b) in [(8.0, 60.0), (9.0, 30.0), (2.0, 70.0), (5.0, 50.0)] {
        assert!(
            darkness(at(a, b)) < 100,
            "off the valley at ({a}, {b}): {:?}",
            at(a, b)
        );
    }
    // The marker is drawn in the fitted red on the pair panel.
    let m = at(2.0, 25.0);
    assert!(m[0] > 150 && m[1] < 110, "marker colour {m:?}");
    // The diagonal histogram of c (uniform) is filled across its whole range.
    let diag = layout.panel(2, 2).unwrap();
    let y = diag.bottom - 3;
    let filled = (diag.left + 5..diag.right - 5)
        .filter(|&x| img.pixel(x as u32, y as u32).unwrap() != [255, 255, 255])
        .count() as f64;
    assert!(filled > 0.9 * f64::from(diag.width() - 10), "{filled}");
    // The empty upper triangle stays empty apart from the legend.
    let upper = layout.panel(0, 0).unwrap();
    let right_of = (upper.right + 40) as u32;
    assert!(img.pixel(right_of, (upper.bottom - 5) as u32).unwrap() == [255, 255, 255]);
}

#[test]
fn corner_input_problems_are_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.png");
    let short = CornerFigure::new(
        "",
        vec!["a".into(), "b".into()],
        vec![vec![1.0; 5], vec![1.0; 4]],
    );
    let e = render_corner_png(&short, &path).unwrap_err();
    assert!(
        matches!(e, PlotError::LengthMismatch { .. }) && e.to_string().contains("bad.png"),
        "{e}"
    );
    let labels = CornerFigure::new("", vec!["a".into()], vec![vec![1.0; 5], vec![1.0; 5]]);
    assert!(render_corner_png(&labels, &path).is_err());
    let marker =
        CornerFigure::new("", vec!["a".into()], vec![vec![1.0; 5]]).with_marker(CornerMarker {
            label: "m".into(),
            values: vec![1.0, 2.0],
            style: Style::Fitted,
        });
    assert!(render_corner_png(&marker, &path).is_err());
    let tiny =
        CornerFigure::new("", vec!["a".into(); 12], vec![vec![1.0; 5]; 12]).with_size(300, 300);
    assert!(matches!(
        render_corner_png(&tiny, &path),
        Err(PlotError::Draw { .. })
    ));
    assert!(!path.exists(), "nothing half-written");
    // Degenerate but valid: constant, non-finite and empty columns, no parameter at all.
    for fig in [
        CornerFigure::new(
            "constant",
            vec!["a".into(), "b".into()],
            vec![vec![2.0; 50], vec![f64::NAN; 50]],
        ),
        CornerFigure::new("empty", vec!["a".into()], vec![Vec::new()]),
        CornerFigure::new("none", Vec::new(), Vec::new()),
    ] {
        render_corner_png(&fig, &path).unwrap_or_else(|e| panic!("{}: {e}", fig.title));
    }
}

#[test]
fn the_band_is_shaded_between_its_edges_even_where_x_stands_still() {
    let dir = tempfile::tempdir().unwrap();
    // Up to x = 1, then a "hold": x stays at 1 while the band moves down from 1 to 0.
    let mut x: Vec<f64> = (0..=100).map(|i| i as f64 / 100.0).collect();
    let mut mid: Vec<f64> = x.iter().map(|v| v.min(1.0)).collect();
    for k in 1..=50 {
        x.push(1.0);
        mid.push(1.0 - k as f64 / 50.0);
    }
    let lo: Vec<f64> = mid.iter().map(|v| v - 0.05).collect();
    let hi: Vec<f64> = mid.iter().map(|v| v + 0.05).collect();
    let fig = BandFigure::new("band", "x", "y", x.clone(), lo, hi, "95 % band")
        .with_series(Series::new("median", x, mid.clone(), Style::Fitted))
        .with_difference(mid, "minus the median");
    let path = dir.path().join("band.png");
    render_band_png(&fig, &path).unwrap();
    let img = read_rgb(&path).unwrap();
    let l = band_layout(&fig).unwrap();
    let (px, py) = (|v| pixel_x(&l, v), |v| pixel_y(&l, v));
    let band = [246, 190, 184];
    // Inside the band, just off the median line: band colour; well outside: white.
    assert_eq!(img.pixel(px(0.5), py(0.53)).unwrap(), band);
    let outside = img.pixel(px(0.5), py(0.8)).unwrap();
    assert!(outside != band && darkness(outside) < 100, "{outside:?}");
    // During the "hold" the band covers the vertical stretch at x = 1, down to 0.05 below the
    // lowest point of the median (which covers the rest of that column).
    assert_eq!(img.pixel(px(1.0), py(-0.03)).unwrap(), band);
    assert!(darkness(img.pixel(px(1.0), py(-0.1)).unwrap()) < 100);
    // The median is drawn over the band in red.
    let m = img.pixel(px(0.5), py(0.5)).unwrap();
    assert!(m[0] > 150 && m[1] < 110, "{m:?}");
    // Below, the band relative to the median: ±0.05 around zero, over its whole height.
    let d = l.difference.unwrap();
    let (d0, d1) = l.difference_y_range.unwrap();
    let dy = |v: f64| {
        (d.bottom as f64 - (v - d0) / (d1 - d0) * (d.bottom - d.top) as f64).round() as u32
    };
    assert!(d0 < -0.05 && d1 > 0.05 && d1 < 0.1, "{d0}..{d1}");
    assert_eq!(img.pixel(px(0.3), dy(0.035)).unwrap(), band);
    assert_eq!(img.pixel(px(0.3), dy(-0.035)).unwrap(), band);
    let bad = BandFigure::new("", "x", "y", vec![0.0, 1.0], vec![0.0], vec![1.0, 2.0], "b");
    let e = render_band_png(&bad, &dir.path().join("bad.png")).unwrap_err();
    assert!(
        e.to_string().contains("bad.png") && e.to_string().contains("band lower edge"),
        "{e}"
    );
}

#[test]
fn the_data_are_drawn_over_the_median_and_a_band_thinner_than_a_pixel_still_shows() {
    let dir = tempfile::tempdir().unwrap();
    let x: Vec<f64> = (0..=30).map(|i| i as f64 / 30.0).collect();
    let mid: Vec<f64> = x.iter().map(|v| 0.2 + 0.6 * v).collect();
    // A band of ±1e-5 on a unit axis: far below a pixel.
    let lo: Vec<f64> = mid.iter().map(|v| v - 1e-5).collect();
    let hi: Vec<f64> = mid.iter().map(|v| v + 1e-5).collect();
    let fig = BandFigure::new("band", "x", "y", x.clone(), lo, hi, "95 % band")
        .with_series(Series::new(
            "measured",
            x.clone(),
            mid.clone(),
            Style::Measured,
        ))
        .with_series(Series::new("median", x.clone(), mid.clone(), Style::Fitted));
    let path = dir.path().join("band.png");
    render_band_png(&fig, &path).unwrap();
    let img = read_rgb(&path).unwrap();
    let l = band_layout(&fig).unwrap();
    let (px, py) = (|v| pixel_x(&l, v), |v| pixel_y(&l, v));
    // On a measured point the marker (dark grey), not the red median drawn after the data
    // in an earlier version.
    let at = img.pixel(px(x[15]), py(mid[15])).unwrap();
    assert!(darkness(at) > 500, "{at:?}");
    // With the data and the median left out, the band's edge shows where the band lies.
    let bare = BandFigure::new(
        "band",
        "x",
        "y",
        x.clone(),
        fig.lo.clone(),
        fig.hi.clone(),
        "b",
    );
    let path = dir.path().join("bare.png");
    render_band_png(&bare, &path).unwrap();
    let img = read_rgb(&path).unwrap();
    let l = band_layout(&bare).unwrap();
    let (col, row) = (pixel_x(&l, 0.5), pixel_y(&l, 0.5));
    let near: Vec<[u8; 3]> = (row.saturating_sub(2)..=row + 2)
        .filter_map(|r| img.pixel(col, r))
        .collect();
    assert!(
        near.iter().any(|c| c[0] > 180 && c[1] < 170 && c[2] < 160),
        "no band colour within 2 px of the band: {near:?}"
    );
}
