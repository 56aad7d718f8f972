//! The corner plot: a triangle of panels, 1-D histograms of each parameter on the diagonal and
//! 2-D histograms (shaded by the square root of the count, so that the thin tails of a valley
//! stay visible) of every pair below it; markers (the optimum, a true value) on every panel.

use std::path::Path;

use plotters::prelude::*;

use crate::chart::{
    chart_err, dashed, draw_legend, font, frame, no_data, place_legend, plottable, rgb,
    shrink_to_fit, stroke, AxisRange, Entry, Metrics, Occupancy, Swatch, Ticks,
};
use crate::colors::{style_rgb, INK_RGB, ZERO_RGB};
use crate::figure::title;
use crate::render::{self, Chart};
use crate::{check_size, DrawError, Invalid, PixelRect, PlotError, Style};

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

/// Where a corner plot's cells go, decided before anything is drawn: the metrics, the
/// figure's size, each parameter's range, ticks and label, the fonts' sizes, the tick labels'
/// areas left of and below each cell, and the cells' size and spacing.
struct Geometry {
    m: Metrics,
    w: i32,
    h: i32,
    ranges: Vec<AxisRange>,
    ticks: Vec<Ticks>,
    labels: Vec<(String, f64)>,
    tick_font: f64,
    title_h: i32,
    y_area: i32,
    x_area: i32,
    left: i32,
    gap: i32,
    cell_w: i32,
    cell_h: i32,
}

impl Geometry {
    /// The plotting box of the cell in row `i`, column `j`.
    fn cell(&self, i: usize, j: usize) -> PixelRect {
        let l = self.left + j as i32 * (self.cell_w + self.gap);
        let t = self.title_h + i as i32 * (self.cell_h + self.gap);
        PixelRect {
            left: l,
            top: t,
            right: l + self.cell_w - 1,
            bottom: t + self.cell_h - 1,
        }
    }
}

/// The [`Geometry`] of `fig`; cells too narrow or too low are refused.
fn geometry(fig: &CornerFigure) -> Result<Geometry, Invalid> {
    let m = Metrics::new(fig.width, fig.height);
    let n = fig.samples.len();
    let (w, h) = (fig.width as i32, fig.height as i32);
    let ranges: Vec<AxisRange> = (0..n)
        .map(|k| {
            let mk: Vec<f64> = fig.markers.iter().map(|mk| mk.values[k]).collect();
            range_of(&fig.samples[k], &mk)
        })
        .collect();
    let ticks: Vec<Ticks> = ranges.iter().map(|r| Ticks::new(*r, 4, false)).collect();
    let tick_font = m.tick * 0.8;
    let label_font = m.label * 0.85;
    let title_h = if fig.title.trim().is_empty() {
        m.pad
    } else {
        m.pad + (m.title * 1.3) as i32
    };
    let y_area = (label_font / 1.24 * 1.25) as i32
        + m.px(6.0)
        + ticks
            .iter()
            .skip(1)
            .map(|t| t.widest(tick_font))
            .max()
            .unwrap_or(0)
        + 2 * m.tick_len;
    let x_area =
        2 * m.tick_len + (tick_font / 1.24 * 1.2) as i32 + (label_font / 1.24 * 1.3) as i32;
    let left = m.pad + y_area;
    let gap = m.px(10.0);
    let nn = n.max(1) as i32;
    let cell_w = (w - left - m.pad - m.px(10.0) - gap * (nn - 1)) / nn;
    let cell_h = (h - title_h - x_area - m.pad - gap * (nn - 1)) / nn;
    if n > 0 && cell_w < 30 {
        return Err(Invalid::Draw(DrawError::TooNarrow {
            width: fig.width,
            height: fig.height,
        }));
    }
    if n > 0 && cell_h < 30 {
        return Err(Invalid::Draw(DrawError::TooLow {
            width: fig.width,
            height: fig.height,
        }));
    }
    let labels: Vec<(String, f64)> = fig
        .labels
        .iter()
        .map(|l| {
            shrink_to_fit(
                l,
                label_font,
                label_font * 0.7,
                cell_w.min(cell_h) + m.px(6.0),
            )
        })
        .collect();
    Ok(Geometry {
        m,
        w,
        h,
        ranges,
        ticks,
        labels,
        tick_font,
        title_h,
        y_area,
        x_area,
        left,
        gap,
        cell_w,
        cell_h,
    })
}

/// The grid, ticks and axis labels of the cell in row `i`, column `j` of an `n`-parameter corner
/// plot: tick labels only on the outer cells (the bottom row's x, the first column's y below the
/// diagonal), the parameters' names beside them.
fn cell_mesh(
    chart: &mut Cell<'_, '_>,
    g: &Geometry,
    (i, j, n): (usize, usize, usize),
) -> Result<(), Invalid> {
    let xfmt = |v: &f64| {
        if i + 1 == n {
            g.ticks[j].label(*v)
        } else {
            String::new()
        }
    };
    let yfmt = |v: &f64| {
        if j == 0 && i != j {
            g.ticks[i].label(*v)
        } else {
            String::new()
        }
    };
    let mut mesh = chart.configure_mesh();
    mesh.x_labels(4)
        .y_labels(if i == j { 0 } else { 4 })
        .x_label_formatter(&xfmt)
        .y_label_formatter(&yfmt)
        .bold_line_style(rgb(crate::colors::GRID_RGB))
        .light_line_style(TRANSPARENT)
        .axis_style(BLACK)
        .set_all_tick_mark_size(g.m.tick_len)
        .label_style(font(g.tick_font));
    if i + 1 == n {
        mesh.axis_desc_style(font(g.labels[j].1))
            .x_desc(g.labels[j].0.clone());
    }
    if j == 0 && i > 0 {
        mesh.axis_desc_style(font(g.labels[i].1))
            .y_desc(g.labels[i].0.clone());
    }
    mesh.draw().map_err(chart_err)?;
    Ok(())
}

/// The legend of the corner plot in the empty upper triangle's box `area`: the markers, the
/// samples' shade, and the quantile lines.
fn draw_corner_legend(
    root: &crate::chart::Area<'_>,
    fig: &CornerFigure,
    area: PixelRect,
    m: &Metrics,
) -> Result<(), Invalid> {
    let mut entries: Vec<Entry> = fig
        .markers
        .iter()
        .map(|mk| Entry {
            label: mk.label.clone(),
            swatch: Swatch::Line {
                color: style_rgb(mk.style),
                width: m.width(2.0),
                dashed: false,
                marker: Some((marker_radius(m), style_rgb(mk.style))),
            },
        })
        .collect();
    entries.push(Entry {
        label: "posterior samples (shade: √ density)".into(),
        swatch: Swatch::Patch {
            color: mix(0.7, DENSITY_RGB),
        },
    });
    entries.push(Entry {
        label: "2.5 %, median, 97.5 %".into(),
        swatch: Swatch::Line {
            color: ZERO_RGB,
            width: m.width(1.2),
            dashed: true,
            marker: None,
        },
    });
    if let Some(l) = place_legend(entries, area, &Occupancy::new(area, 8), m) {
        // The legend is drawn by a chart over that corner (series labels are placed
        // within a chart's plotting area).
        let corner = root.clone().shrink(
            (area.left, area.top),
            (area.width() as u32, area.height() as u32),
        );
        let mut chart = ChartBuilder::on(&corner)
            .build_cartesian_2d(0.0..1.0, 0.0..1.0)
            .map_err(chart_err)?;
        draw_legend(&mut chart, &l)?;
    }
    Ok(())
}

struct Drawn {
    svg: String,
    layout: CornerLayout,
}

#[allow(clippy::too_many_lines)]
fn draw(fig: &CornerFigure) -> Result<Drawn, Invalid> {
    validate(fig)?;
    render::ensure_font().map_err(Invalid::Draw)?;
    let g = geometry(fig)?;
    let (m, n, w, h) = (g.m, fig.samples.len(), g.w, g.h);
    let ranges = &g.ranges;
    let (y_area, x_area) = (g.y_area, g.x_area);
    let (cell_w, cell_h) = (g.cell_w, g.cell_h);
    let bins = fig.bins.max(2);
    let mut panels = Vec::new();
    let svg = render::svg_of(fig.width, fig.height, |root| {
        root.fill(&WHITE).map_err(chart_err)?;
        let whole = PixelRect {
            left: 0,
            top: 0,
            right: w - 1,
            bottom: h - 1,
        };
        if n == 0 {
            no_data(root, whole, &m)?;
            return title(root, &fig.title, whole, fig.width, &m);
        }
        for i in 0..n {
            for j in 0..=i {
                let r = g.cell(i, j);
                // Every cell has room for tick labels left of and below it, so that all
                // plotting areas are the cells; only the outer ones write into it.
                let area = root.clone().shrink(
                    (r.left - y_area, r.top),
                    ((cell_w + y_area) as u32, (cell_h + x_area) as u32),
                );
                let (xr, yr) = (
                    ranges[j],
                    if i == j {
                        AxisRange { min: 0.0, max: 1.0 }
                    } else {
                        ranges[i]
                    },
                );
                let mut chart = ChartBuilder::on(&area)
                    .y_label_area_size(y_area)
                    .x_label_area_size(x_area)
                    .build_cartesian_2d(xr.min..xr.max, yr.min..yr.max)
                    .map_err(chart_err)?;
                cell_mesh(&mut chart, &g, (i, j, n))?;
                if i == j {
                    diagonal(&mut chart, fig, ranges, i, bins, &m)?;
                } else {
                    pair(&mut chart, fig, ranges, i, j, bins, &m)?;
                }
                frame(root, r, INK_RGB)?;
                panels.push((i, j, r));
            }
        }
        title(
            root,
            &fig.title,
            PixelRect {
                left: g.cell(0, 0).left,
                top: 0,
                right: g.cell(0, n - 1).right,
                bottom: 0,
            },
            fig.width,
            &m,
        )?;
        // The empty upper triangle holds the legend.
        if n >= 2 {
            let area = PixelRect {
                left: g.cell(0, n / 2).left,
                top: g.cell(0, n - 1).top,
                right: g.cell(0, n - 1).right,
                bottom: g.cell((n - 1) / 2, n - 1).bottom,
            };
            draw_corner_legend(root, fig, area, &m)?;
        }
        Ok(())
    })?;
    Ok(Drawn {
        svg,
        layout: CornerLayout {
            width: fig.width,
            height: fig.height,
            panels,
            ranges: ranges.iter().map(|r| (r.min, r.max)).collect(),
        },
    })
}

type Cell<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

fn marker_radius(m: &Metrics) -> u32 {
    (4.0 * m.s).round().max(3.0) as u32
}

/// A 2-D histogram of parameter j (across) and i (up), with the markers.
fn pair(
    chart: &mut Cell<'_, '_>,
    fig: &CornerFigure,
    ranges: &[AxisRange],
    i: usize,
    j: usize,
    bins: usize,
    m: &Metrics,
) -> Result<(), Invalid> {
    let (xr, yr) = (ranges[j], ranges[i]);
    let mut counts = vec![0u32; bins * bins];
    for (x, y) in fig.samples[j].iter().zip(&fig.samples[i]) {
        if let (Some(bx), Some(by)) = (bin(*x, xr, bins), bin(*y, yr, bins)) {
            counts[by * bins + bx] += 1;
        }
    }
    let max = f64::from(counts.iter().copied().max().unwrap_or(0).max(1));
    let edge = |r: AxisRange, k: usize| r.min + r.span() * k as f64 / bins as f64;
    let cells = (0..bins * bins).filter(|k| counts[*k] > 0).map(|k| {
        let (bx, by) = (k % bins, k / bins);
        let t = 0.12 + 0.88 * (f64::from(counts[k]) / max).sqrt();
        Rectangle::new(
            [
                (edge(xr, bx), edge(yr, by)),
                (edge(xr, bx + 1), edge(yr, by + 1)),
            ],
            rgb(mix(t, DENSITY_RGB)).filled(),
        )
    });
    chart.draw_series(cells).map_err(chart_err)?;
    let r = marker_radius(m);
    for mk in &fig.markers {
        let (x, y) = (mk.values[j], mk.values[i]);
        if xr.contains(x) && yr.contains(y) {
            chart
                .draw_series([
                    Circle::new((x, y), r + 2, WHITE.filled()),
                    Circle::new((x, y), r, rgb(style_rgb(mk.style)).filled()),
                ])
                .map_err(chart_err)?;
        }
    }
    Ok(())
}

/// The 1-D histogram of parameter i, its 2.5 / 50 / 97.5 % and the markers.
fn diagonal(
    chart: &mut Cell<'_, '_>,
    fig: &CornerFigure,
    ranges: &[AxisRange],
    i: usize,
    bins: usize,
    m: &Metrics,
) -> Result<(), Invalid> {
    let xr = ranges[i];
    let mut counts = vec![0u32; bins];
    for v in &fig.samples[i] {
        if let Some(b) = bin(*v, xr, bins) {
            counts[b] += 1;
        }
    }
    let max = f64::from(counts.iter().copied().max().unwrap_or(0).max(1)) * 1.1;
    let edge = |k: usize| xr.min + xr.span() * k as f64 / bins as f64;
    let bars = (0..bins).filter(|k| counts[*k] > 0).map(|k| {
        Rectangle::new(
            [(edge(k), 0.0), (edge(k + 1), f64::from(counts[k]) / max)],
            rgb(HISTOGRAM_FILL_RGB).filled(),
        )
    });
    chart.draw_series(bars).map_err(chart_err)?;
    let outline: Vec<(f64, f64)> = (0..bins)
        .flat_map(|k| {
            let y = f64::from(counts[k]) / max;
            [(edge(k), y), (edge(k + 1), y)]
        })
        .collect();
    chart
        .draw_series(LineSeries::new(
            outline,
            stroke(HISTOGRAM_EDGE_RGB, m.width(1.5)),
        ))
        .map_err(chart_err)?;
    let mut v: Vec<f64> = fig.samples[i]
        .iter()
        .copied()
        .filter(|x| plottable(*x))
        .collect();
    v.sort_by(f64::total_cmp);
    if !v.is_empty() {
        let lines = [0.025, 0.5, 0.975].map(|q| {
            let x = v[((v.len() - 1) as f64 * q).round() as usize];
            PathElement::new(vec![(x, 0.0), (x, 1.0)], dashed(ZERO_RGB, m.width(1.2)))
        });
        chart.draw_series(lines).map_err(chart_err)?;
    }
    for mk in fig.markers.iter().filter(|mk| xr.contains(mk.values[i])) {
        let x = mk.values[i];
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(x, 0.0), (x, 1.0)],
                stroke(style_rgb(mk.style), m.width(2.0)),
            )))
            .map_err(chart_err)?;
    }
    Ok(())
}

impl Chart for CornerFigure {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn svg_document(&self) -> Result<String, Invalid> {
        draw(self).map(|d| d.svg)
    }
}

/// Where the panels of `fig` would be drawn, or `None` if `fig` is invalid.
pub fn corner_layout(fig: &CornerFigure) -> Option<CornerLayout> {
    draw(fig).ok().map(|d| d.layout)
}

/// Draws `fig` and writes it to `path` as an RGB PNG (see [`crate::write_figure`] for the PNG
/// and the SVG). Errors (each naming `path`): a size out of bounds, labels, columns or marker
/// values of different lengths, a file that cannot be written. Non-finite samples are left
/// out.
pub fn render_corner_png(fig: &CornerFigure, path: &Path) -> Result<(), PlotError> {
    render::write_png(fig, path)
}
