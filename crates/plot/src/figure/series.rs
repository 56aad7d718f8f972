//! How a curve is drawn: its order, line width and colours, markers, and legend entry.

use plotters::prelude::*;

use crate::chart::{
    chart_err, clip_polyline, dashed, decimate, distinct_pixels, plottable, rgb, stroke, AxisRange,
    Chart2d, Entry, Metrics, Pt, Swatch,
};
use crate::colors;
use crate::{Invalid, Series, Style};

use super::points;

/// How a series is drawn: order (measured first, fitted last), width, colours, markers.
fn z_order(style: Style) -> u8 {
    match style {
        Style::Measured => 0,
        Style::Other(_) => 1,
        Style::Published => 2,
        Style::Fitted => 3,
    }
}

fn line_width(style: Style, m: &Metrics, cycled: bool) -> u32 {
    match style {
        Style::Measured if cycled => m.width(2.0),
        Style::Measured => m.width(1.0),
        Style::Published | Style::Other(_) => m.width(2.0),
        Style::Fitted => m.width(2.4),
    }
}

/// A measured series of at most this many points gets a marker on every point.
const MARKER_LIMIT: usize = 60;

/// On a denser measured series, one marker per square of this side [pixels at 1000x750] that
/// the curve passes through: dense enough to show the data's course, sparse enough for the
/// model beneath to show between them.
const MARKER_SPACING: f64 = 11.0;

/// The colour of a series' line: a light grey under a measured series' markers.
fn line_rgb(style: Style) -> [u8; 3] {
    match style {
        Style::Measured => colors::MEASURED_LINE_RGB,
        _ => colors::style_rgb(style),
    }
}

/// Cycle range of the drawable points of a series.
fn cycle_bounds(s: &Series) -> Option<(u32, u32)> {
    let c = s.cycle.as_ref()?;
    let mut b: Option<(u32, u32)> = None;
    for ((&x, &y), &k) in s.x.iter().zip(&s.y).zip(c) {
        if plottable(x) && plottable(y) {
            b = Some(b.map_or((k, k), |(lo, hi)| (lo.min(k), hi.max(k))));
        }
    }
    b
}

/// Legend entry of a series (None for an empty label).
pub(crate) fn legend_entry(s: &Series, m: &Metrics) -> Option<Entry> {
    if s.label.trim().is_empty() {
        return None;
    }
    let has_data = points(s).next().is_some();
    let dashed = s.style == Style::Published;
    Some(match cycle_bounds(s) {
        Some((a, b)) if has_data => Entry {
            label: if a == b {
                format!("{}, cycle {a}", s.label)
            } else {
                format!("{}, cycle {a}..{b}", s.label)
            },
            swatch: Swatch::Gradient {
                colors: [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0].map(|t| colors::cycle_rgb(s.style, t)),
                width: line_width(s.style, m, true),
            },
        },
        _ => Entry {
            label: if has_data {
                s.label.clone()
            } else {
                format!("{} (no data)", s.label)
            },
            swatch: Swatch::Line {
                color: line_rgb(s.style),
                width: line_width(s.style, m, false),
                dashed,
                marker: (s.style == Style::Measured)
                    .then(|| (marker_radius(m), colors::style_rgb(s.style))),
            },
        },
    })
}

/// Radius of the markers of a short measured series.
fn marker_radius(m: &Metrics) -> u32 {
    (3.0 * m.s).round().max(2.0) as u32
}

/// Radius of the sampled markers of a dense measured series.
fn sample_marker_radius(m: &Metrics) -> u32 {
    (2.0 * m.s).round().max(2.0) as u32
}

/// A line ready to draw (data coordinates, decimated and clipped) and its style.
pub(crate) struct Line {
    pub(crate) pts: Vec<(f64, f64)>,
    color: [u8; 3],
    width: u32,
    dashed: bool,
}

/// A marker: its place (data coordinates), radius and colour.
pub(super) type Marker = ((f64, f64), u32, [u8; 3]);

/// A run of points drawn in one colour.
type Run = (Vec<(f64, f64)>, [u8; 3]);

/// Lines and markers of the series of a panel, in drawing order, within `x` and `y`; `to_px`
/// maps data to image pixels (for decimation, marker spacing and the occupancy grid).
pub(crate) fn strokes(
    series: &[Series],
    x: AxisRange,
    y: AxisRange,
    to_px: &dyn Fn((f64, f64)) -> Pt,
    m: &Metrics,
) -> (Vec<Line>, Vec<Marker>) {
    let mut order: Vec<usize> = (0..series.len()).collect();
    order.sort_by_key(|&i| (z_order(series[i].style), i));
    let (mut lines, mut markers) = (Vec::new(), Vec::new());
    for s in order.into_iter().map(|i| &series[i]) {
        let bounds = cycle_bounds(s);
        let color_of = |k: Option<u32>| match (k, bounds) {
            (Some(k), Some((a, b))) if b > a => {
                colors::cycle_rgb(s.style, f64::from(k.max(a) - a) / f64::from(b - a))
            }
            (Some(_), Some(_)) => colors::cycle_rgb(s.style, 0.0),
            _ => line_rgb(s.style),
        };
        // Runs of drawable points of one colour; a new colour starts at the last point of the
        // run before so that the curve stays connected.
        let mut runs: Vec<Run> = Vec::new();
        let mut cur: Vec<(f64, f64)> = Vec::new();
        let mut cur_cycle = None;
        for i in 0..s.x.len() {
            let p = (s.x[i], s.y[i]);
            if !(plottable(p.0) && plottable(p.1)) {
                if !cur.is_empty() {
                    runs.push((std::mem::take(&mut cur), color_of(cur_cycle)));
                }
                continue;
            }
            let k = s.cycle.as_ref().map(|c| c[i]);
            if !cur.is_empty() && k != cur_cycle {
                let last = cur[cur.len() - 1];
                runs.push((std::mem::take(&mut cur), color_of(cur_cycle)));
                cur.push(last);
            }
            cur_cycle = k;
            cur.push(p);
        }
        if !cur.is_empty() {
            runs.push((cur, color_of(cur_cycle)));
        }
        let width = line_width(s.style, m, bounds.is_some());
        if s.style == Style::Measured {
            let sampled = points(s).count() > MARKER_LIMIT;
            let (r, spacing) = if sampled {
                (sample_marker_radius(m), MARKER_SPACING * m.s)
            } else {
                (marker_radius(m), 0.0)
            };
            // A dense record gets a marker at least `spacing` pixels from the one before and
            // at most one per square of that side: evenly spread along a smooth curve, and
            // bounded by the area however noisy and long the record.
            let mut taken = std::collections::HashSet::new();
            let mut last: Option<Pt> = None;
            for (pts, color) in &runs {
                let mc = if bounds.is_some() {
                    *color
                } else {
                    colors::MEASURED_RGB
                };
                for &p in pts.iter().filter(|p| x.contains(p.0) && y.contains(p.1)) {
                    let q = to_px(p);
                    let cell = if sampled {
                        (
                            (q.0 / spacing).floor() as i64,
                            (q.1 / spacing).floor() as i64,
                        )
                    } else {
                        (markers.len() as i64, 0)
                    };
                    let far = last.is_none_or(|l: Pt| (q.0 - l.0).hypot(q.1 - l.1) >= spacing);
                    if far && taken.insert(cell) {
                        markers.push((p, r, mc));
                        last = Some(q);
                    }
                }
            }
        }
        for (pts, color) in runs {
            let pts = distinct_pixels(decimate(&pts, |p| to_px(*p)), |p| to_px(*p));
            for piece in clip_polyline(&pts, x, y) {
                lines.push(Line {
                    pts: piece,
                    color,
                    width,
                    dashed: s.style == Style::Published,
                });
            }
        }
    }
    (lines, markers)
}

/// Lines, then markers over them.
pub(crate) fn draw_lines(
    chart: &mut Chart2d<'_, '_>,
    lines: Vec<Line>,
    markers: Vec<Marker>,
) -> Result<(), Invalid> {
    for l in lines {
        let style = if l.dashed {
            dashed(l.color, l.width)
        } else {
            stroke(l.color, l.width)
        };
        if l.pts.len() == 1 {
            chart
                .draw_series(std::iter::once(Circle::new(
                    l.pts[0],
                    l.width.max(2),
                    rgb(l.color).filled(),
                )))
                .map_err(chart_err)?;
        } else {
            chart
                .draw_series(LineSeries::new(l.pts, style))
                .map_err(chart_err)?;
        }
    }
    chart
        .draw_series(
            markers
                .into_iter()
                .map(|(p, r, c)| Circle::new(p, r, rgb(c).filled())),
        )
        .map_err(chart_err)?;
    Ok(())
}
