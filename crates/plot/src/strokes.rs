//! How one series is drawn: its strokes and markers, their order, widths and colours, and
//! its legend entry. Measured data are drawn on top of the models: a thin light line through
//! every point, and markers on a sample of the points drawn last, so that a model curve
//! beneath them shows between the markers and a data point off the curve stands out.

use crate::chrome::{LegendEntry, Metrics, Swatch};
use crate::colors;
use crate::figure::points;
use crate::geom::{decimate, ClipBox, Mapper, Pt};
use crate::scale::plottable;
use crate::{Series, Style};

/// A polyline ready to draw, already clipped.
#[derive(Debug, Clone)]
pub(crate) struct Stroke {
    pub(crate) pts: Vec<Pt>,
    pub(crate) color: [u8; 3],
    pub(crate) width: f64,
    pub(crate) dashed: bool,
}

pub(crate) fn z_order(style: Style) -> u8 {
    match style {
        Style::Measured => 0,
        Style::Other(_) => 1,
        Style::Published => 2,
        Style::Fitted => 3,
    }
}

pub(crate) fn line_width(style: Style, m: &Metrics, cycled: bool) -> f64 {
    match style {
        Style::Measured if cycled => m.width(1.6),
        Style::Measured => m.width(1.0),
        Style::Published | Style::Other(_) => m.width(2.0),
        Style::Fitted => m.width(2.2),
    }
}

/// A measured series of at most this many points gets a marker on every point.
const MARKER_LIMIT: usize = 60;

/// On a denser measured series, markers sit at least this far apart along the curve
/// [pixels at 1000x750]: a sample of the data points, dense enough to show the data's course
/// and sparse enough for the model beneath to show between them.
const MARKER_SPACING: f64 = 11.0;

/// Every measured series gets markers (all its points, or a sample of them).
pub(crate) fn uses_markers(s: &Series) -> bool {
    s.style == Style::Measured
}

/// Whether a measured series is dense (its markers are a sample of its points).
fn dense(s: &Series) -> bool {
    points(s).count() > MARKER_LIMIT
}

/// The colour of a series' line: a light grey under a measured series' markers.
fn line_rgb(style: Style) -> [u8; 3] {
    match style {
        Style::Measured => colors::MEASURED_LINE_RGB,
        _ => colors::style_rgb(style),
    }
}

/// Cycle range of the drawable points of a series.
pub(crate) fn cycle_bounds(s: &Series) -> Option<(u32, u32)> {
    let c = s.cycle.as_ref()?;
    let mut b: Option<(u32, u32)> = None;
    for ((&x, &y), &k) in s.x.iter().zip(&s.y).zip(c) {
        if plottable(x) && plottable(y) {
            b = Some(match b {
                None => (k, k),
                Some((lo, hi)) => (lo.min(k), hi.max(k)),
            });
        }
    }
    b
}

/// Legend entry of a series (None for an empty label).
pub(crate) fn legend_entry(s: &Series, m: &Metrics) -> Option<LegendEntry> {
    if s.label.trim().is_empty() {
        return None;
    }
    let has_data = points(s).next().is_some();
    let dashed = s.style == Style::Published;
    let (label, swatch) = match cycle_bounds(s) {
        Some((a, b)) if has_data => {
            let label = if a == b {
                format!("{}, cycle {a}", s.label)
            } else {
                format!("{}, cycle {a}..{b}", s.label)
            };
            let swatch = Swatch::Gradient {
                style: s.style,
                width: line_width(s.style, m, true),
                dashed,
            };
            (label, swatch)
        }
        _ => {
            let label = if has_data {
                s.label.clone()
            } else {
                format!("{} (no data)", s.label)
            };
            let swatch = Swatch::Line {
                color: line_rgb(s.style),
                width: line_width(s.style, m, false),
                dashed,
                marker: uses_markers(s).then(|| (marker_radius(m), colors::style_rgb(s.style))),
            };
            (label, swatch)
        }
    };
    Some(LegendEntry { label, swatch })
}

/// Radius of the markers of measured points: a 7-pixel disc at 1000x750.
pub(crate) fn marker_radius(m: &Metrics) -> f64 {
    (2.5 * m.s).round().max(2.0) + 0.5
}

/// Radius of the sampled markers of a dense measured series: a 5-pixel disc at 1000x750.
fn sample_marker_radius(m: &Metrics) -> f64 {
    (1.8 * m.s).round().max(1.5) + 0.5
}

/// Strokes and markers of one series in a panel.
pub(crate) fn series_strokes(
    s: &Series,
    mapper: &Mapper,
    m: &Metrics,
    out: &mut Vec<Stroke>,
    markers: &mut Vec<(Pt, f64, [u8; 3])>,
) {
    let cycled = s.cycle.is_some();
    let width = line_width(s.style, m, cycled);
    let clip = ClipBox::inside(mapper.rect, width + 1.0);
    let dashed = s.style == Style::Published;
    let decimate_above = mapper.rect.width().max(16) as usize;
    let bounds = cycle_bounds(s);
    let color_of = |k: Option<u32>| match (k, bounds) {
        (Some(k), Some((a, b))) => {
            let t = if b > a {
                f64::from(k - a.min(k)) / f64::from(b - a)
            } else {
                0.0
            };
            colors::cycle_rgb(s.style, t)
        }
        _ => line_rgb(s.style),
    };
    let marker_of = |c: [u8; 3]| {
        if bounds.is_some() {
            c
        } else {
            colors::style_rgb(s.style)
        }
    };

    // Runs of drawable points with one colour; a new colour run starts at
    // the last point of the previous one so the curve stays connected.
    let mut runs: Vec<(Vec<Pt>, [u8; 3])> = Vec::new();
    let mut cur: Vec<Pt> = Vec::new();
    let mut cur_cycle: Option<u32> = None;
    for i in 0..s.x.len().min(s.y.len()) {
        let (x, y) = (s.x[i], s.y[i]);
        if !(plottable(x) && plottable(y)) {
            if !cur.is_empty() {
                runs.push((std::mem::take(&mut cur), color_of(cur_cycle)));
            }
            continue;
        }
        let k = s.cycle.as_ref().and_then(|c| c.get(i).copied());
        let p = (mapper.px(x), mapper.py(y));
        if !cur.is_empty() && k != cur_cycle {
            let last = *cur.last().unwrap_or(&p);
            runs.push((std::mem::take(&mut cur), color_of(cur_cycle)));
            cur.push(last);
        }
        cur_cycle = k;
        cur.push(p);
    }
    if !cur.is_empty() {
        runs.push((cur, color_of(cur_cycle)));
    }

    if uses_markers(s) {
        let sampled = dense(s);
        let r = if sampled {
            sample_marker_radius(m)
        } else {
            marker_radius(m)
        };
        let spacing = if sampled { MARKER_SPACING * m.s } else { 0.0 };
        let mclip = ClipBox::inside(mapper.rect, r + 1.0);
        let mut last: Option<Pt> = None;
        for (pts, color) in &runs {
            for &p in pts {
                let far = last.is_none_or(|q| (p.0 - q.0).hypot(p.1 - q.1) >= spacing);
                if far && mclip.contains(p) {
                    markers.push((p, r, marker_of(*color)));
                    last = Some(p);
                }
            }
        }
    }
    for (pts, color) in runs {
        let pts = if pts.len() > decimate_above {
            decimate(&pts)
        } else {
            pts
        };
        for piece in clip.clip_polyline(&pts) {
            out.push(Stroke {
                pts: piece,
                color,
                width,
                dashed,
            });
        }
    }
}
