//! The corner plot: a triangle of panels, 1-D histograms of each parameter on the diagonal and
//! 2-D histograms (shaded by the square root of the count, so that the thin tails of a valley
//! stay visible) of every pair below it; markers (the optimum, a true value) on every panel.

use std::path::Path;

use crate::canvas::{Canvas, HAlign, VAlign};
use crate::chrome::{
    dash_pattern, draw_legend, place_legend, place_title, LegendEntry, Metrics, Swatch,
};
use crate::colors::{style_rgb, GRID_RGB, INK_RGB, ZERO_RGB};
use crate::fonts::{self, CAP_HEIGHT, DESCENT};
use crate::geom::{Mapper, Occupancy, PixelRect};
use crate::scale::{plottable, ticks, AxisRange, Ticks};
use crate::{check_size, png_io, DrawError, Invalid, PlotError, Style};

/// A point drawn on every panel (e.g. the least-squares optimum, or the true values).
#[derive(Debug, Clone, PartialEq)]
pub struct CornerMarker {
    /// Legend label.
    pub label: String,
    /// One value per parameter (NaN: not drawn for that parameter).
    pub values: Vec<f64>,
    /// Colour: the style's colour ([`Style::Fitted`] red, [`Style::Published`] blue, ...).
    pub style: Style,
}

/// A corner plot of samples of several parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct CornerFigure {
    /// Title above the triangle (may be empty).
    pub title: String,
    /// Axis label of each parameter, with units (e.g. "log₁₀ κ [1/mm]").
    pub labels: Vec<String>,
    /// One column of samples per parameter, all of the same length.
    pub samples: Vec<Vec<f64>>,
    /// Points drawn on every panel.
    pub markers: Vec<CornerMarker>,
    /// Histogram bins per axis.
    pub bins: usize,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl CornerFigure {
    /// A 1000x1000 corner plot with 30 bins per axis and no markers.
    pub fn new(title: impl Into<String>, labels: Vec<String>, samples: Vec<Vec<f64>>) -> Self {
        CornerFigure {
            title: title.into(),
            labels,
            samples,
            markers: Vec::new(),
            bins: 30,
            width: 1000,
            height: 1000,
        }
    }

    /// The same figure with one more marker.
    pub fn with_marker(mut self, marker: CornerMarker) -> Self {
        self.markers.push(marker);
        self
    }

    /// The same figure with another size in pixels.
    pub fn with_size(mut self, width: u32, height: u32) -> Self {
        self.width = width;
        self.height = height;
        self
    }
}

/// Where the panels of a [`CornerFigure`] are drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct CornerLayout {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Panels as (row, column, plotting area): the diagonal (i, i) holds parameter i's
    /// histogram, (i, j) with i > j parameter j across and parameter i up.
    pub panels: Vec<(usize, usize, PixelRect)>,
    /// Axis range of each parameter.
    pub ranges: Vec<(f64, f64)>,
}

impl CornerLayout {
    /// The plotting area of panel (row, column).
    pub fn panel(&self, row: usize, col: usize) -> Option<PixelRect> {
        self.panels
            .iter()
            .find(|(r, c, _)| *r == row && *c == col)
            .map(|p| p.2)
    }
}

/// Darkest shade of the 2-D histograms and colour of the 1-D ones.
const DENSITY_RGB: [u8; 3] = [8, 48, 107];
const HISTOGRAM_FILL_RGB: [u8; 3] = [158, 202, 225];
const HISTOGRAM_EDGE_RGB: [u8; 3] = [33, 113, 181];

/// Samples outside these quantiles do not stretch the axes (a stray walker would squash the
/// rest into a corner); markers always do.
const RANGE_QUANTILES: (f64, f64) = (0.001, 0.999);

struct Plan {
    m: Metrics,
    n: usize,
    cells: Vec<Vec<PixelRect>>,
    ranges: Vec<AxisRange>,
    ticks: Vec<Ticks>,
    tick_font: f64,
    label_font: f64,
    title: (String, f64, (f64, f64)),
    legend_area: Option<PixelRect>,
}

fn validate(fig: &CornerFigure) -> Result<(), Invalid> {
    check_size(fig.width, fig.height)?;
    let n = fig.samples.first().map_or(0, Vec::len);
    if fig.labels.len() != fig.samples.len() {
        return Err(Invalid::Length {
            label: "parameter labels".into(),
            x_len: fig.samples.len(),
            y_len: fig.labels.len(),
        });
    }
    for (label, col) in fig.labels.iter().zip(&fig.samples) {
        if col.len() != n {
            return Err(Invalid::Length {
                label: format!("{label} (samples against the first parameter's)"),
                x_len: n,
                y_len: col.len(),
            });
        }
    }
    for mk in &fig.markers {
        if mk.values.len() != fig.samples.len() {
            return Err(Invalid::Length {
                label: format!("marker {} (values against parameters)", mk.label),
                x_len: fig.samples.len(),
                y_len: mk.values.len(),
            });
        }
    }
    Ok(())
}

fn range_of(col: &[f64], markers: &[f64]) -> AxisRange {
    let mut v: Vec<f64> = col.iter().copied().filter(|x| plottable(*x)).collect();
    v.sort_by(f64::total_cmp);
    let pick = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    let (mut lo, mut hi) = if v.is_empty() {
        (f64::INFINITY, f64::NEG_INFINITY)
    } else {
        (pick(RANGE_QUANTILES.0), pick(RANGE_QUANTILES.1))
    };
    for &mk in markers.iter().filter(|x| plottable(**x)) {
        lo = lo.min(mk);
        hi = hi.max(mk);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return AxisRange { min: 0.0, max: 1.0 };
    }
    let span = hi - lo;
    let pad = if span > 0.0 {
        0.05 * span
    } else {
        (1e-3 * lo.abs()).max(1e-12)
    };
    AxisRange {
        min: lo - pad,
        max: hi + pad,
    }
}

fn plan(fig: &CornerFigure) -> Result<Plan, Invalid> {
    validate(fig)?;
    fonts::ensure_fonts().map_err(Invalid::Draw)?;
    let m = Metrics::new(fig.width, fig.height);
    let n = fig.samples.len();
    let ranges: Vec<AxisRange> = (0..n)
        .map(|k| {
            let mk: Vec<f64> = fig.markers.iter().map(|mk| mk.values[k]).collect();
            range_of(&fig.samples[k], &mk)
        })
        .collect();
    let ticks: Vec<Ticks> = ranges.iter().map(|r| ticks(*r, 3)).collect();
    if n == 0 {
        // Nothing sampled: the title over an empty image that says so.
        let whole = PixelRect {
            left: 0,
            top: 0,
            right: fig.width as i32 - 1,
            bottom: fig.height as i32 - 1,
        };
        let title = place_title(&fig.title, whole, fig.width, (m.title * 1.5).round(), &m);
        return Ok(Plan {
            m,
            n,
            cells: Vec::new(),
            ranges,
            ticks,
            tick_font: m.tick,
            label_font: m.label,
            title,
            legend_area: None,
        });
    }
    let tick_font = m.tick * 0.8;
    let label_font = m.label * 0.85;
    let title_block = if fig.title.trim().is_empty() {
        0.0
    } else {
        (m.title * 1.5).round()
    };
    let text_h = |size: f64| (CAP_HEIGHT + DESCENT) * size;
    let tick_w = ticks
        .iter()
        .skip(1)
        .flat_map(|t| t.labels.iter())
        .map(|l| fonts::text_width(l, tick_font))
        .fold(0.0, f64::max);
    let left = (m.pad + text_h(label_font) + m.px(8.0) + tick_w + m.gap + m.tick_len).ceil();
    let top = m.pad + title_block + m.px(8.0);
    let bottom = m.tick_len + m.gap + text_h(tick_font) + m.px(8.0) + text_h(label_font) + m.pad;
    let gap = m.px(8.0);
    let avail_w = f64::from(fig.width) - left - m.pad - m.px(10.0);
    let avail_h = f64::from(fig.height) - top - bottom;
    let cell_w = ((avail_w - gap * (n as f64 - 1.0)) / n.max(1) as f64).floor();
    let cell_h = ((avail_h - gap * (n as f64 - 1.0)) / n.max(1) as f64).floor();
    if cell_w < 30.0 {
        return Err(Invalid::Draw(DrawError::TooNarrow {
            width: fig.width,
            height: fig.height,
        }));
    }
    if cell_h < 30.0 {
        return Err(Invalid::Draw(DrawError::TooLow {
            width: fig.width,
            height: fig.height,
        }));
    }
    let cells: Vec<Vec<PixelRect>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let l = (left + j as f64 * (cell_w + gap)) as i32;
                    let t = (top + i as f64 * (cell_h + gap)) as i32;
                    PixelRect {
                        left: l,
                        top: t,
                        right: l + cell_w as i32 - 1,
                        bottom: t + cell_h as i32 - 1,
                    }
                })
                .collect()
        })
        .collect();
    // The empty upper triangle holds the legend: from the second column of the first row to
    // the last column of the row above the last.
    let legend_area = (n >= 2).then(|| PixelRect {
        left: cells[0][n / 2].left,
        top: cells[0][n - 1].top,
        right: cells[0][n - 1].right,
        bottom: cells[(n - 1) / 2][n - 1].bottom,
    });
    let whole = PixelRect {
        left: cells[0][0].left,
        top: cells[0][0].top,
        right: cells[0][n - 1].right,
        bottom: cells[n - 1][0].bottom,
    };
    let title = place_title(&fig.title, whole, fig.width, title_block, &m);
    Ok(Plan {
        m,
        n,
        cells,
        ranges,
        ticks,
        tick_font,
        label_font,
        title,
        legend_area,
    })
}

/// Where the panels of `fig` would be drawn, or `None` if `fig` is invalid.
pub fn corner_layout(fig: &CornerFigure) -> Option<CornerLayout> {
    let p = plan(fig).ok()?;
    let mut panels = Vec::new();
    for i in 0..p.n {
        for j in 0..=i {
            panels.push((i, j, p.cells[i][j]));
        }
    }
    Some(CornerLayout {
        width: fig.width,
        height: fig.height,
        panels,
        ranges: p.ranges.iter().map(|r| (r.min, r.max)).collect(),
    })
}

/// Bin of `v` among `bins` equal bins of `r`, if inside.
fn bin(v: f64, r: AxisRange, bins: usize) -> Option<usize> {
    if !plottable(v) || v < r.min || v > r.max {
        return None;
    }
    Some((((v - r.min) / r.span() * bins as f64) as usize).min(bins - 1))
}

fn mix(t: f64, to: [u8; 3]) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    let c = |a: u8| (255.0 + (f64::from(a) - 255.0) * t).round() as u8;
    [c(to[0]), c(to[1]), c(to[2])]
}

/// Equal-width columns of a rectangle: pixel column range of bin `k` of `bins`.
fn bin_cols(r: PixelRect, k: usize, bins: usize) -> (i32, i32) {
    let w = f64::from(r.width());
    let a = r.left + (w * k as f64 / bins as f64).round() as i32;
    let b = r.left + (w * (k + 1) as f64 / bins as f64).round() as i32 - 1;
    (a, b.max(a))
}

fn bin_rows(r: PixelRect, k: usize, bins: usize) -> (i32, i32) {
    let h = f64::from(r.height());
    let b = r.bottom - (h * k as f64 / bins as f64).round() as i32;
    let a = r.bottom - (h * (k + 1) as f64 / bins as f64).round() as i32 + 1;
    (a.min(b), b)
}

fn draw_pair(c: &mut Canvas, fig: &CornerFigure, p: &Plan, i: usize, j: usize) {
    let r = p.cells[i][j];
    let bins = fig.bins.max(2);
    let mut counts = vec![0u32; bins * bins];
    for (x, y) in fig.samples[j].iter().zip(&fig.samples[i]) {
        if let (Some(bx), Some(by)) = (bin(*x, p.ranges[j], bins), bin(*y, p.ranges[i], bins)) {
            counts[by * bins + bx] += 1;
        }
    }
    let max = f64::from(counts.iter().copied().max().unwrap_or(0).max(1));
    for by in 0..bins {
        for bx in 0..bins {
            let k = counts[by * bins + bx];
            if k == 0 {
                continue;
            }
            let (left, right) = bin_cols(r, bx, bins);
            let (top, bottom) = bin_rows(r, by, bins);
            let t = 0.12 + 0.88 * (f64::from(k) / max).sqrt();
            c.fill(
                PixelRect {
                    left,
                    top,
                    right,
                    bottom,
                },
                mix(t, DENSITY_RGB),
            );
        }
    }
    let mapper = Mapper {
        rect: r,
        x: p.ranges[j],
        y: p.ranges[i],
    };
    let radius = (4.0 * p.m.s).max(2.5);
    for mk in &fig.markers {
        let (x, y) = (mk.values[j], mk.values[i]);
        if p.ranges[j].contains(x) && p.ranges[i].contains(y) {
            let at = (mapper.px(x), mapper.py(y));
            c.dot(at, radius + 1.5, [255, 255, 255]);
            c.dot(at, radius, style_rgb(mk.style));
        }
    }
}

fn draw_diagonal(c: &mut Canvas, fig: &CornerFigure, p: &Plan, i: usize) {
    let r = p.cells[i][i];
    let bins = fig.bins.max(2);
    let mut counts = vec![0u32; bins];
    for v in &fig.samples[i] {
        if let Some(b) = bin(*v, p.ranges[i], bins) {
            counts[b] += 1;
        }
    }
    let max = f64::from(counts.iter().copied().max().unwrap_or(0).max(1)) * 1.1;
    let mut edge = Vec::with_capacity(2 * bins);
    for (k, &n) in counts.iter().enumerate() {
        let (left, right) = bin_cols(r, k, bins);
        let top = r.bottom - (f64::from(n) / max * f64::from(r.height() - 1)).round() as i32;
        if n > 0 {
            c.fill(
                PixelRect {
                    left,
                    top,
                    right,
                    bottom: r.bottom,
                },
                HISTOGRAM_FILL_RGB,
            );
        }
        edge.push((f64::from(left), f64::from(top)));
        edge.push((f64::from(right), f64::from(top)));
    }
    c.polyline(&edge, HISTOGRAM_EDGE_RGB, p.m.width(1.5), None);
    // 2.5 / 50 / 97.5 % of the samples.
    let mut v: Vec<f64> = fig.samples[i]
        .iter()
        .copied()
        .filter(|x| plottable(*x))
        .collect();
    v.sort_by(f64::total_cmp);
    let mapper = Mapper {
        rect: r,
        x: p.ranges[i],
        y: AxisRange { min: 0.0, max: 1.0 },
    };
    if !v.is_empty() {
        for q in [0.025, 0.5, 0.975] {
            let x = mapper.px(v[((v.len() - 1) as f64 * q).round() as usize]);
            c.line(
                (x, f64::from(r.top)),
                (x, f64::from(r.bottom)),
                ZERO_RGB,
                p.m.width(1.2),
                Some(dash_pattern(&p.m)),
            );
        }
    }
    for mk in &fig.markers {
        let x = mk.values[i];
        if p.ranges[i].contains(x) {
            let px = mapper.px(x);
            c.line(
                (px, f64::from(r.top)),
                (px, f64::from(r.bottom)),
                style_rgb(mk.style),
                p.m.width(2.0),
                None,
            );
        }
    }
}

/// Tick marks on the bottom (and left) edge of a panel, labelled when asked.
fn draw_ticks(
    c: &mut Canvas,
    p: &Plan,
    r: PixelRect,
    x: usize,
    y: Option<usize>,
    x_labels: bool,
    y_labels: bool,
) {
    let tl = p.m.tick_len as i32;
    let xr = p.ranges[x];
    for (v, label) in p.ticks[x].values.iter().zip(&p.ticks[x].labels) {
        let px = crate::chrome::tick_px(xr, *v, r);
        if px > r.left && px < r.right {
            c.fill(
                PixelRect {
                    left: px,
                    right: px,
                    top: r.top + 1,
                    bottom: r.bottom - 1,
                },
                GRID_RGB,
            );
        }
        c.fill(
            PixelRect {
                left: px,
                right: px,
                top: r.bottom + 1,
                bottom: r.bottom + tl,
            },
            INK_RGB,
        );
        if x_labels {
            let at = (f64::from(px), f64::from(r.bottom + tl) + p.m.gap);
            c.text(label, p.tick_font, INK_RGB, at, HAlign::Center, VAlign::Top);
        }
    }
    let Some(y) = y else { return };
    let yr = p.ranges[y];
    for (v, label) in p.ticks[y].values.iter().zip(&p.ticks[y].labels) {
        let py = crate::chrome::tick_py(yr, *v, r);
        if py > r.top && py < r.bottom {
            c.fill(
                PixelRect {
                    left: r.left + 1,
                    right: r.right - 1,
                    top: py,
                    bottom: py,
                },
                GRID_RGB,
            );
        }
        c.fill(
            PixelRect {
                left: r.left - tl,
                right: r.left - 1,
                top: py,
                bottom: py,
            },
            INK_RGB,
        );
        if y_labels {
            let at = (f64::from(r.left - tl) - p.m.gap, f64::from(py));
            c.text(
                label,
                p.tick_font,
                INK_RGB,
                at,
                HAlign::Right,
                VAlign::Center,
            );
        }
    }
}

fn draw(fig: &CornerFigure, p: &Plan) -> Result<Canvas, DrawError> {
    let mut c = Canvas::new(fig.width, fig.height)?;
    let n = p.n;
    if n == 0 {
        let whole = PixelRect {
            left: 0,
            top: 0,
            right: fig.width as i32 - 1,
            bottom: fig.height as i32 - 1,
        };
        crate::chrome::draw_no_data(&mut c, whole, &p.m);
    }
    for i in 0..n {
        for j in 0..=i {
            let r = p.cells[i][j];
            let (y, y_labels) = if i == j {
                (None, false)
            } else {
                (Some(i), j == 0)
            };
            draw_ticks(&mut c, p, r, j, y, i == n - 1, y_labels);
            if i == j {
                draw_diagonal(&mut c, fig, p, i);
            } else {
                draw_pair(&mut c, fig, p, i, j);
            }
            c.outline(r, INK_RGB);
        }
    }
    // Parameter names: under the bottom row, and left of the first column (rows with a y axis).
    for k in 0..n {
        let r = p.cells[n - 1][k];
        let (text, size) = fonts::shrink_to_fit(
            &fig.labels[k],
            p.label_font,
            p.label_font * 0.7,
            f64::from(r.width()) + p.m.px(6.0),
        );
        let at = (
            0.5 * f64::from(r.left + r.right),
            f64::from(fig.height) - p.m.pad,
        );
        c.text(&text, size, INK_RGB, at, HAlign::Center, VAlign::Bottom);
        if k >= 1 {
            let r = p.cells[k][0];
            let (text, size) = fonts::shrink_to_fit(
                &fig.labels[k],
                p.label_font,
                p.label_font * 0.7,
                f64::from(r.height()),
            );
            let cx = p.m.pad + 0.5 * CAP_HEIGHT * size;
            c.text_vertical(
                &text,
                size,
                INK_RGB,
                (cx, 0.5 * f64::from(r.top + r.bottom)),
            );
        }
    }
    let (title, size, centre) = &p.title;
    c.text(
        title,
        *size,
        INK_RGB,
        *centre,
        HAlign::Center,
        VAlign::Center,
    );
    if let Some(area) = p.legend_area {
        let mut entries: Vec<LegendEntry> = fig
            .markers
            .iter()
            .map(|mk| LegendEntry {
                label: mk.label.clone(),
                swatch: Swatch::Line {
                    color: style_rgb(mk.style),
                    width: p.m.width(2.0),
                    dashed: false,
                    marker: Some(((4.0 * p.m.s).max(2.5), style_rgb(mk.style))),
                },
            })
            .collect();
        entries.push(LegendEntry {
            label: "posterior samples (shade: √ density)".into(),
            swatch: Swatch::Patch {
                color: mix(0.7, DENSITY_RGB),
            },
        });
        entries.push(LegendEntry {
            label: "2.5 %, median, 97.5 %".into(),
            swatch: Swatch::Line {
                color: ZERO_RGB,
                width: p.m.width(1.2),
                dashed: true,
                marker: None,
            },
        });
        let occupancy = Occupancy::new(area, 8);
        if let Some(l) = place_legend(entries, area, &occupancy, &p.m) {
            draw_legend(&mut c, &l, &p.m);
        }
    }
    Ok(c)
}

/// Draws `fig` and writes it to `path` as an RGB PNG. Errors (each naming `path`): a size out
/// of bounds, labels, columns or marker values of different lengths, a file that cannot be
/// written. Non-finite samples are left out.
pub fn render_corner_png(fig: &CornerFigure, path: &Path) -> Result<(), PlotError> {
    let p = plan(fig).map_err(|e| e.with_path(path))?;
    let canvas = draw(fig, &p).map_err(|e| Invalid::Draw(e).with_path(path))?;
    png_io::write_rgb_png(path, fig.width, fig.height, &canvas.into_rgb())
}
