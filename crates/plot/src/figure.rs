//! Curve figures: a main panel and an optional residual panel.

use std::path::Path;

use crate::canvas::{Canvas, HAlign, VAlign};
use crate::colors::{self, GRID_RGB, INK_RGB, ZERO_RGB};
use crate::fonts::{self, CAP_HEIGHT, DESCENT};
use crate::geom::{decimate, ClipBox, Mapper, Occupancy, PixelRect, Pt};
use crate::scale::{plottable, ticks, AxisRange, Extent, Ticks};
use crate::{check_size, png_io, Figure, Invalid, Panel, PlotError, Series, Style};

/// Sizes in pixels derived from the image size.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Metrics {
    /// Overall scale: 1 for 1000x750.
    pub s: f64,
    pub title: f64,
    pub label: f64,
    pub tick: f64,
    pub legend: f64,
    pub pad: f64,
    pub tick_len: f64,
    pub gap: f64,
}

impl Metrics {
    pub fn new(width: u32, height: u32) -> Self {
        let s = (f64::from(width) / 1000.0)
            .min(f64::from(height) / 750.0)
            .clamp(0.45, 4.0);
        Metrics {
            s,
            title: 24.0 * s,
            label: 20.0 * s,
            tick: 16.5 * s,
            legend: 16.0 * s,
            pad: (12.0 * s).round(),
            tick_len: (6.0 * s).round().max(3.0),
            gap: (5.0 * s).round().max(2.0),
        }
    }

    pub fn px(&self, v: f64) -> f64 {
        (v * self.s).round()
    }

    /// A line width in pixels (at least one pixel).
    pub fn width(&self, v: f64) -> f64 {
        (v * self.s).max(1.0)
    }
}

/// Where the parts of a [`Figure`] are drawn, in pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct FigureLayout {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Plotting area of the main panel (frame on its edge pixels); every
    /// curve of the main panel is drawn inside it.
    pub main: PixelRect,
    /// Plotting area of the residual panel, if any.
    pub residual: Option<PixelRect>,
    /// Legend box of the main panel, if it has one (inside `main`).
    pub main_legend: Option<PixelRect>,
    /// Legend box of the residual panel, if it has one (inside `residual`).
    pub residual_legend: Option<PixelRect>,
    /// Shared x axis range.
    pub x_range: (f64, f64),
    /// Y axis range of the main panel.
    pub main_y_range: (f64, f64),
    /// Y axis range of the residual panel.
    pub residual_y_range: Option<(f64, f64)>,
}

/// A polyline ready to draw, already clipped.
#[derive(Debug, Clone)]
struct Stroke {
    pts: Vec<Pt>,
    color: [u8; 3],
    width: f64,
    dashed: bool,
}

#[derive(Debug, Clone)]
pub(crate) enum Swatch {
    Line {
        color: [u8; 3],
        width: f64,
        dashed: bool,
        marker: Option<u32>,
    },
    Gradient {
        style: Style,
        width: f64,
        dashed: bool,
    },
    Patch {
        color: [u8; 3],
    },
}

#[derive(Debug, Clone)]
pub(crate) struct LegendEntry {
    pub label: String,
    pub swatch: Swatch,
}

/// A placed legend.
#[derive(Debug, Clone)]
pub(crate) struct Legend {
    pub rect: PixelRect,
    pub font: f64,
    pub row_h: f64,
    pub pad: f64,
    pub swatch_w: f64,
    pub gap: f64,
    pub entries: Vec<LegendEntry>,
}

struct PanelPlan {
    rect: PixelRect,
    y: AxisRange,
    yticks: Ticks,
    y_label: String,
    y_label_size: f64,
    zero_line: bool,
    strokes: Vec<Stroke>,
    markers: Vec<(Pt, u32, [u8; 3])>,
    /// Legend entries before fitting into the box.
    entries: Vec<LegendEntry>,
    occupancy: Occupancy,
    legend: Option<Legend>,
    has_data: bool,
}

struct Plan {
    width: u32,
    height: u32,
    m: Metrics,
    x: AxisRange,
    xticks: Ticks,
    title: String,
    title_size: f64,
    title_center: Pt,
    x_label: String,
    x_label_size: f64,
    main: PanelPlan,
    residual: Option<PanelPlan>,
}

fn validate(fig: &Figure) -> Result<(), Invalid> {
    check_size(fig.width, fig.height)?;
    let panels = std::iter::once(&fig.main).chain(fig.residual.as_ref());
    for s in panels.flat_map(|p| p.series.iter()) {
        if s.x.len() != s.y.len() {
            return Err(Invalid::Length {
                label: s.label.clone(),
                x_len: s.x.len(),
                y_len: s.y.len(),
            });
        }
        if let Some(c) = &s.cycle {
            if c.len() != s.x.len() {
                return Err(Invalid::Cycles {
                    label: s.label.clone(),
                    points: s.x.len(),
                    cycles: c.len(),
                });
            }
        }
    }
    Ok(())
}

fn points(s: &Series) -> impl Iterator<Item = (f64, f64)> + '_ {
    s.x.iter()
        .zip(&s.y)
        .map(|(&x, &y)| (x, y))
        .filter(|&(x, y)| plottable(x) && plottable(y))
}

/// Axis ranges: shared x, main y, residual y.
fn ranges(fig: &Figure) -> (AxisRange, AxisRange, Option<AxisRange>) {
    let mut x = Extent::default();
    let panel_y = |p: &Panel, x: &mut Extent| {
        let mut y = Extent::default();
        for s in &p.series {
            for (px, py) in points(s) {
                x.add(px);
                y.add(py);
            }
        }
        y.padded(p.zero_line)
    };
    let main_y = panel_y(&fig.main, &mut x);
    let res_y = fig.residual.as_ref().map(|p| panel_y(p, &mut x));
    (x.padded(false), main_y, res_y)
}

/// Whether every drawable point (both coordinates finite and within
/// [`crate::MAX_ABS_VALUE`]) lies inside the axis ranges the figure is drawn with.
pub fn series_inside(fig: &Figure) -> bool {
    let (x, main_y, res_y) = ranges(fig);
    let inside = |p: &Panel, y: AxisRange| {
        p.series
            .iter()
            .all(|s| points(s).all(|(px, py)| x.contains(px) && y.contains(py)))
    };
    inside(&fig.main, main_y)
        && match (&fig.residual, res_y) {
            (Some(p), Some(y)) => inside(p, y),
            _ => true,
        }
}

fn z_order(style: Style) -> u8 {
    match style {
        Style::Measured => 0,
        Style::Other(_) => 1,
        Style::Published => 2,
        Style::Fitted => 3,
    }
}

fn line_width(style: Style, m: &Metrics, cycled: bool) -> f64 {
    match style {
        Style::Measured if cycled => m.width(1.6),
        Style::Measured => m.width(1.0),
        Style::Published | Style::Other(_) => m.width(2.0),
        Style::Fitted => m.width(2.2),
    }
}

const MARKER_LIMIT: usize = 60;

fn uses_markers(s: &Series) -> bool {
    s.style == Style::Measured && points(s).count() <= MARKER_LIMIT
}

/// Cycle range of the drawable points of a series.
fn cycle_bounds(s: &Series) -> Option<(u32, u32)> {
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
fn legend_entry(s: &Series, m: &Metrics) -> Option<LegendEntry> {
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
                color: colors::style_rgb(s.style),
                width: line_width(s.style, m, false),
                dashed,
                marker: uses_markers(s).then(|| marker_radius(m)),
            };
            (label, swatch)
        }
    };
    Some(LegendEntry { label, swatch })
}

fn marker_radius(m: &Metrics) -> u32 {
    (2.5 * m.s).round().max(2.0) as u32
}

/// Strokes and markers of one series in a panel.
fn series_strokes(
    s: &Series,
    mapper: &Mapper,
    m: &Metrics,
    out: &mut Vec<Stroke>,
    markers: &mut Vec<(Pt, u32, [u8; 3])>,
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
        _ => colors::style_rgb(s.style),
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
        let r = marker_radius(m);
        let mclip = ClipBox::inside(mapper.rect, f64::from(r) + 1.0);
        for (pts, color) in &runs {
            for &p in pts {
                if mclip.contains(p) {
                    markers.push((p, r, *color));
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

/// Legend geometry for `entries` in `area`, placed in the corner where the
/// occupancy grid shows the least ink (upper right preferred, then lower
/// right, upper left, lower left).
pub(crate) fn place_legend(
    mut entries: Vec<LegendEntry>,
    area: PixelRect,
    occupancy: &Occupancy,
    m: &Metrics,
) -> Option<Legend> {
    if entries.is_empty() {
        return None;
    }
    let font = m.legend;
    let row_h = (font * 1.45).round();
    let pad = m.px(8.0);
    let swatch_w = m.px(34.0);
    let gap = m.px(8.0);
    let inset = m.px(10.0);
    let avail_w = f64::from(area.width()) - 2.0 * inset;
    let avail_h = f64::from(area.height()) - 2.0 * inset;
    let text_max = avail_w - 2.0 * pad - swatch_w - gap;
    if text_max < font * 2.0 {
        return None;
    }
    let rows = ((avail_h - pad) / row_h).floor();
    if rows < 1.0 {
        return None;
    }
    entries.truncate(rows as usize);
    for e in &mut entries {
        e.label = fonts::fit_text(&e.label, font, text_max);
    }
    let text_w = entries
        .iter()
        .map(|e| fonts::text_width(&e.label, font))
        .fold(0.0, f64::max);
    let w = (2.0 * pad + swatch_w + gap + text_w).ceil() as i32;
    let h = (pad + row_h * entries.len() as f64).ceil() as i32;
    let inset = inset as i32;
    let (l, r) = (area.left + inset, area.right - inset - w + 1);
    let (t, b) = (area.top + inset, area.bottom - inset - h + 1);
    let candidates = [(r, t), (r, b), (l, t), (l, b)];
    let margin = m.px(3.0) as i32;
    // A legend that would hide a large part of a small plot is left out.
    if f64::from(w) * f64::from(h) > 0.4 * f64::from(area.width()) * f64::from(area.height()) {
        return None;
    }
    let rect = candidates
        .iter()
        .map(|&(x, y)| PixelRect {
            left: x,
            top: y,
            right: x + w - 1,
            bottom: y + h - 1,
        })
        .min_by_key(|c| {
            occupancy.count(PixelRect {
                left: c.left - margin,
                top: c.top - margin,
                right: c.right + margin,
                bottom: c.bottom + margin,
            })
        })?;
    Some(Legend {
        rect,
        font,
        row_h,
        pad,
        swatch_w,
        gap,
        entries,
    })
}

fn plan_panel(
    panel: &Panel,
    rect: PixelRect,
    x: AxisRange,
    y: AxisRange,
    yticks: Ticks,
    m: &Metrics,
    skip_labels: &[String],
) -> PanelPlan {
    let mapper = Mapper { rect, x, y };
    let mut order: Vec<usize> = (0..panel.series.len()).collect();
    order.sort_by_key(|&i| (z_order(panel.series[i].style), i));
    let mut strokes = Vec::new();
    let mut markers = Vec::new();
    for &i in &order {
        series_strokes(&panel.series[i], &mapper, m, &mut strokes, &mut markers);
    }
    let mut occupancy = Occupancy::new(rect, m.px(6.0).max(3.0) as i32);
    for s in &strokes {
        occupancy.mark_polyline(&s.pts);
    }
    for (p, _, _) in &markers {
        occupancy.mark_point(*p);
    }
    // One entry per label: series repeated under the same label (e.g. one
    // per test) are listed once; labels already in the main legend are not
    // repeated in the residual panel.
    let mut entries: Vec<LegendEntry> = Vec::new();
    for e in panel.series.iter().filter_map(|s| legend_entry(s, m)) {
        if !skip_labels.contains(&e.label) && !entries.iter().any(|x| x.label == e.label) {
            entries.push(e);
        }
    }
    let legend = place_legend(entries.clone(), rect, &occupancy, m);
    PanelPlan {
        rect,
        y,
        yticks,
        y_label: panel.y_label.clone(),
        y_label_size: m.label,
        zero_line: panel.zero_line,
        strokes,
        markers,
        entries,
        occupancy,
        legend,
        has_data: panel.series.iter().any(|s| points(s).next().is_some()),
    }
}

fn plan(fig: &Figure) -> Result<Plan, Invalid> {
    validate(fig)?;
    fonts::ensure_fonts().map_err(Invalid::Draw)?;
    let (w, h) = (fig.width, fig.height);
    let m = Metrics::new(w, h);
    let (x, main_y, res_y) = ranges(fig);

    // Vertical layout.
    let has_title = !fig.title.trim().is_empty();
    let has_xlabel = !fig.x_label.trim().is_empty();
    let title_block = if has_title {
        (m.title * 1.5).round()
    } else {
        0.0
    };
    let top = m.pad + title_block + m.px(8.0);
    let tick_text_h = (CAP_HEIGHT + DESCENT) * m.tick;
    let mut bottom = m.tick_len + m.gap + tick_text_h + m.pad;
    if has_xlabel {
        bottom += m.px(10.0) + (CAP_HEIGHT + DESCENT) * m.label;
    }
    let panel_gap = if res_y.is_some() { m.px(20.0) } else { 0.0 };
    let avail = (f64::from(h) - top - bottom - panel_gap).floor();
    let main_h = if res_y.is_some() {
        (avail * 2.0 / 3.0).round()
    } else {
        avail
    };
    let res_h = avail - main_h;
    if main_h < 20.0 || (res_y.is_some() && res_h < 15.0) {
        return Err(Invalid::Draw(format!(
            "{w}x{h} is too small for the labels of this figure"
        )));
    }
    let y_target =
        |height: f64, per: f64, max: usize| ((height / (per * m.s)).round() as usize).clamp(2, max);
    let main_ticks = ticks(main_y, y_target(main_h, 60.0, 9));
    let res_ticks = res_y.map(|r| ticks(r, y_target(res_h, 45.0, 5)));

    // Horizontal layout: room for the rotated y label and the tick labels.
    let tick_w = main_ticks
        .labels
        .iter()
        .chain(res_ticks.iter().flat_map(|t| t.labels.iter()))
        .map(|l| fonts::text_width(l, m.tick))
        .fold(0.0, f64::max);
    let has_ylabel = !fig.main.y_label.trim().is_empty()
        || fig
            .residual
            .as_ref()
            .is_some_and(|p| !p.y_label.trim().is_empty());
    let ylabel_col = if has_ylabel {
        CAP_HEIGHT * m.label + DESCENT * m.label + m.px(10.0)
    } else {
        0.0
    };
    let left = (m.pad + ylabel_col + tick_w + m.gap + m.tick_len)
        .ceil()
        .min(f64::from(w) * 0.45);
    let right = m.px(30.0);
    let plot_w = f64::from(w) - left - right;
    if plot_w < 40.0 {
        return Err(Invalid::Draw(format!(
            "{w}x{h} is too narrow for the labels of this figure"
        )));
    }

    // X ticks: as many as fit without overlapping labels.
    let mut target = ((plot_w / (110.0 * m.s)).round() as usize).clamp(2, 12);
    let xticks = loop {
        let t = ticks(x, target);
        let widest = t
            .labels
            .iter()
            .map(|l| fonts::text_width(l, m.tick))
            .fold(0.0, f64::max);
        let spacing = if t.values.len() > 1 {
            (t.values[1] - t.values[0]) / x.span() * plot_w
        } else {
            f64::INFINITY
        };
        if widest + m.px(14.0) <= spacing || target <= 1 {
            break t;
        }
        target -= 1;
    };

    let left = left as i32;
    let top_i = top as i32;
    let main_rect = PixelRect {
        left,
        top: top_i,
        right: left + plot_w as i32 - 1,
        bottom: top_i + main_h as i32 - 1,
    };
    let main = plan_panel(&fig.main, main_rect, x, main_y, main_ticks, &m, &[]);
    let residual = match (&fig.residual, res_y, res_ticks) {
        (Some(p), Some(y), Some(t)) => {
            let rect = PixelRect {
                left,
                top: main_rect.bottom + 1 + panel_gap as i32,
                right: main_rect.right,
                bottom: main_rect.bottom + panel_gap as i32 + res_h as i32,
            };
            let skip: Vec<String> = main.entries.iter().map(|e| e.label.clone()).collect();
            Some(plan_panel(p, rect, x, y, t, &m, &skip))
        }
        _ => None,
    };

    // Y labels shrink (then shorten) to fit the height of their panel.
    let fit_ylabel = |p: &mut PanelPlan| {
        let (text, size) = fonts::shrink_to_fit(
            &p.y_label,
            m.label,
            m.label * 0.7,
            f64::from(p.rect.height()),
        );
        p.y_label = text;
        p.y_label_size = size;
    };
    let mut main = main;
    let mut residual = residual;
    // The short residual panel rarely has a free corner: if its legend
    // would cover much data, its entries join the main legend instead.
    if let Some(r) = residual.as_mut() {
        let crowded = r
            .legend
            .as_ref()
            .is_some_and(|l| r.occupancy.fraction(l.rect) > 0.15);
        if crowded {
            r.legend = None;
            let mut all = main.entries.clone();
            all.extend(r.entries.iter().cloned());
            main.legend = place_legend(all, main.rect, &main.occupancy, &m);
        }
    }
    fit_ylabel(&mut main);
    if let Some(r) = residual.as_mut() {
        fit_ylabel(r);
    }

    let plot_center = 0.5 * f64::from(main_rect.left + main_rect.right);
    let title_w_max = f64::from(w) - 2.0 * m.pad;
    let (title, title_size) =
        fonts::shrink_to_fit(fig.title.trim(), m.title, m.title * 0.6, title_w_max);
    let title_w = fonts::text_width(&title, title_size);
    let title_cx = plot_center
        .max(m.pad + 0.5 * title_w)
        .min(f64::from(w) - m.pad - 0.5 * title_w);
    let (x_label, x_label_size) =
        fonts::shrink_to_fit(fig.x_label.trim(), m.label, m.label * 0.7, title_w_max);

    Ok(Plan {
        width: w,
        height: h,
        m,
        x,
        xticks,
        title,
        title_size,
        title_center: (title_cx, m.pad + 0.5 * title_block),
        x_label,
        x_label_size,
        main,
        residual,
    })
}

/// Where the parts of `fig` would be drawn, or `None` if `fig` is invalid
/// (see [`render_png`] for the checks).
pub fn figure_layout(fig: &Figure) -> Option<FigureLayout> {
    let p = plan(fig).ok()?;
    Some(FigureLayout {
        width: p.width,
        height: p.height,
        main: p.main.rect,
        residual: p.residual.as_ref().map(|r| r.rect),
        main_legend: p.main.legend.as_ref().map(|l| l.rect),
        residual_legend: p
            .residual
            .as_ref()
            .and_then(|r| r.legend.as_ref().map(|l| l.rect)),
        x_range: (p.x.min, p.x.max),
        main_y_range: (p.main.y.min, p.main.y.max),
        residual_y_range: p.residual.as_ref().map(|r| (r.y.min, r.y.max)),
    })
}

/// Draws a legend box with its entries.
pub(crate) fn draw_legend(c: &mut Canvas<'_>, l: &Legend, m: &Metrics) -> Result<(), String> {
    c.fill(l.rect, [255, 255, 255])?;
    c.outline(l.rect, colors::LEGEND_BORDER_RGB)?;
    let x0 = f64::from(l.rect.left) + l.pad;
    let x1 = x0 + l.swatch_w;
    for (i, e) in l.entries.iter().enumerate() {
        let cy = (f64::from(l.rect.top) + 0.5 * l.pad + (i as f64 + 0.5) * l.row_h).round();
        match &e.swatch {
            Swatch::Line {
                color,
                width,
                dashed,
                marker,
            } => {
                if *dashed {
                    let (dash, gap) = dash_pattern(m);
                    for d in crate::geom::dashes(&[(x0, cy), (x1, cy)], dash, gap) {
                        c.polyline(&d, *color, *width)?;
                    }
                } else {
                    c.line((x0, cy), (x1, cy), *color, *width)?;
                }
                if let Some(r) = marker {
                    c.dot((0.5 * (x0 + x1), cy), *r, *color)?;
                }
            }
            Swatch::Gradient {
                style,
                width,
                dashed,
            } => {
                let n = 8;
                for k in 0..n {
                    if *dashed && k % 2 == 1 {
                        continue;
                    }
                    let a = x0 + (x1 - x0) * k as f64 / n as f64;
                    let b = x0 + (x1 - x0) * (k + 1) as f64 / n as f64;
                    let color = colors::cycle_rgb(*style, k as f64 / (n - 1) as f64);
                    c.line((a, cy), (b, cy), color, *width)?;
                }
            }
            Swatch::Patch { color } => {
                let hh = (0.35 * l.font).round() as i32;
                let r = PixelRect {
                    left: x0 as i32 + (l.swatch_w * 0.15) as i32,
                    right: x1 as i32 - (l.swatch_w * 0.15) as i32,
                    top: cy as i32 - hh,
                    bottom: cy as i32 + hh,
                };
                c.fill(r, *color)?;
                c.outline(r, INK_RGB)?;
            }
        }
        c.text(
            &e.label,
            l.font,
            INK_RGB,
            (x1 + l.gap, cy),
            HAlign::Left,
            VAlign::Center,
        )?;
    }
    Ok(())
}

pub(crate) fn dash_pattern(m: &Metrics) -> (f64, f64) {
    ((9.0 * m.s).max(4.0), (5.0 * m.s).max(3.0))
}

/// Grid lines, frame, y ticks and their labels, and (optionally) x ticks.
pub(crate) struct AxisDraw<'a> {
    pub rect: PixelRect,
    pub x: Option<(AxisRange, &'a Ticks)>,
    pub x_labels: bool,
    pub y: AxisRange,
    pub yticks: &'a Ticks,
}

/// Pixel column of x value `v` in a rectangle.
pub(crate) fn tick_px(range: AxisRange, v: f64, r: PixelRect) -> i32 {
    (f64::from(r.left) + (v - range.min) / range.span() * f64::from(r.right - r.left)).round()
        as i32
}

/// Pixel row of y value `v` in a rectangle.
pub(crate) fn tick_py(range: AxisRange, v: f64, r: PixelRect) -> i32 {
    (f64::from(r.bottom) - (v - range.min) / range.span() * f64::from(r.bottom - r.top)).round()
        as i32
}

pub(crate) fn draw_grid(c: &mut Canvas<'_>, a: &AxisDraw<'_>) -> Result<(), String> {
    let r = a.rect;
    for &v in &a.yticks.values {
        let y = tick_py(a.y, v, r);
        if y > r.top && y < r.bottom {
            c.fill(
                PixelRect {
                    top: y,
                    bottom: y,
                    left: r.left + 1,
                    right: r.right - 1,
                },
                GRID_RGB,
            )?;
        }
    }
    if let Some((xr, xt)) = a.x {
        for &v in &xt.values {
            let x = tick_px(xr, v, r);
            if x > r.left && x < r.right {
                c.fill(
                    PixelRect {
                        left: x,
                        right: x,
                        top: r.top + 1,
                        bottom: r.bottom - 1,
                    },
                    GRID_RGB,
                )?;
            }
        }
    }
    Ok(())
}

pub(crate) fn draw_axes(
    c: &mut Canvas<'_>,
    a: &AxisDraw<'_>,
    m: &Metrics,
    image_w: u32,
) -> Result<(), String> {
    let r = a.rect;
    c.outline(r, INK_RGB)?;
    let tl = m.tick_len as i32;
    for (v, label) in a.yticks.values.iter().zip(&a.yticks.labels) {
        let y = tick_py(a.y, *v, r);
        c.fill(
            PixelRect {
                left: r.left - tl,
                right: r.left - 1,
                top: y,
                bottom: y,
            },
            INK_RGB,
        )?;
        let at = (f64::from(r.left - tl) - m.gap, f64::from(y));
        c.text(label, m.tick, INK_RGB, at, HAlign::Right, VAlign::Center)?;
    }
    if let Some((xr, xt)) = a.x {
        for (v, label) in xt.values.iter().zip(&xt.labels) {
            let x = tick_px(xr, *v, r);
            c.fill(
                PixelRect {
                    left: x,
                    right: x,
                    top: r.bottom + 1,
                    bottom: r.bottom + tl,
                },
                INK_RGB,
            )?;
            if a.x_labels {
                let half = 0.5 * fonts::text_width(label, m.tick);
                let cx = f64::from(x)
                    .max(half + 2.0)
                    .min(f64::from(image_w) - half - 2.0);
                let at = (cx, f64::from(r.bottom + tl) + m.gap);
                c.text(label, m.tick, INK_RGB, at, HAlign::Center, VAlign::Top)?;
            }
        }
    }
    Ok(())
}

fn draw_panel(
    c: &mut Canvas<'_>,
    p: &PanelPlan,
    plan: &Plan,
    bottom_panel: bool,
) -> Result<(), String> {
    let m = &plan.m;
    let axes = AxisDraw {
        rect: p.rect,
        x: Some((plan.x, &plan.xticks)),
        x_labels: bottom_panel,
        y: p.y,
        yticks: &p.yticks,
    };
    draw_grid(c, &axes)?;
    let mapper = Mapper {
        rect: p.rect,
        x: plan.x,
        y: p.y,
    };
    if p.zero_line && p.y.contains(0.0) {
        let y = mapper.py(0.0).round();
        let clip = ClipBox::inside(p.rect, 1.0);
        if let Some((a, b)) =
            clip.clip_segment((f64::from(p.rect.left), y), (f64::from(p.rect.right), y))
        {
            let (dash, gap) = dash_pattern(m);
            for d in crate::geom::dashes(&[a, b], dash, gap) {
                c.polyline(&d, ZERO_RGB, 1.0)?;
            }
        }
    }
    let (dash, gap) = dash_pattern(m);
    for s in &p.strokes {
        if s.dashed {
            for d in crate::geom::dashes(&s.pts, dash, gap) {
                c.polyline(&d, s.color, s.width)?;
            }
        } else {
            c.polyline(&s.pts, s.color, s.width)?;
        }
    }
    for &(pt, r, color) in &p.markers {
        c.dot(pt, r, color)?;
    }
    draw_axes(c, &axes, m, plan.width)?;
    if !p.has_data {
        let center = (
            0.5 * f64::from(p.rect.left + p.rect.right),
            0.5 * f64::from(p.rect.top + p.rect.bottom),
        );
        c.text(
            "no data",
            m.label,
            ZERO_RGB,
            center,
            HAlign::Center,
            VAlign::Center,
        )?;
    }
    if let Some(l) = &p.legend {
        draw_legend(c, l, m)?;
    }
    let cx = m.pad + 0.5 * CAP_HEIGHT * p.y_label_size;
    let cy = 0.5 * f64::from(p.rect.top + p.rect.bottom);
    c.text_vertical(&p.y_label, p.y_label_size, INK_RGB, (cx, cy))?;
    Ok(())
}

fn draw(plan: &Plan, buf: &mut [u8]) -> Result<(), String> {
    let mut c = Canvas::new(buf, plan.width, plan.height)?;
    draw_panel(&mut c, &plan.main, plan, plan.residual.is_none())?;
    if let Some(r) = &plan.residual {
        draw_panel(&mut c, r, plan, true)?;
    }
    let m = &plan.m;
    c.text(
        &plan.title,
        plan.title_size,
        INK_RGB,
        plan.title_center,
        HAlign::Center,
        VAlign::Center,
    )?;
    let last = plan.residual.as_ref().map_or(plan.main.rect, |r| r.rect);
    let cx = 0.5 * f64::from(last.left + last.right);
    let half = 0.5 * fonts::text_width(&plan.x_label, plan.x_label_size);
    let cx = cx
        .max(m.pad + half)
        .min(f64::from(plan.width) - m.pad - half);
    c.text(
        &plan.x_label,
        plan.x_label_size,
        INK_RGB,
        (cx, f64::from(plan.height) - m.pad),
        HAlign::Center,
        VAlign::Bottom,
    )?;
    c.finish()
}

/// Renders `fig` to an RGB buffer (3 bytes per pixel, row-major).
fn render_rgb(fig: &Figure) -> Result<Vec<u8>, Invalid> {
    let plan = plan(fig)?;
    let mut buf = vec![255u8; plan.width as usize * plan.height as usize * 3];
    draw(&plan, &mut buf).map_err(Invalid::Draw)?;
    Ok(buf)
}

/// Draws `fig` and writes it to `path` as an RGB PNG.
///
/// Errors (each naming `path`): a size outside
/// [`crate::MIN_WIDTH`]x[`crate::MIN_HEIGHT`]..=[`crate::MAX_SIDE`]; a series whose x, y
/// (and cycle) lengths differ; a file that cannot be written. Series
/// without drawable points are allowed: the figure then shows "no data"
/// or the legend marks them "(no data)".
pub fn render_png(fig: &Figure, path: &Path) -> Result<(), PlotError> {
    let buf = render_rgb(fig).map_err(|e| e.with_path(path))?;
    png_io::write_rgb_png(path, fig.width, fig.height, &buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fig() -> Figure {
        let x: Vec<f64> = (0..200).map(|i| i as f64 * 0.05).collect();
        let y: Vec<f64> = x.iter().map(|v| v.sin()).collect();
        Figure::new(
            "t",
            "x (mm)",
            Panel::new("y (kPa)", vec![Series::new("fit", x, y, Style::Fitted)]),
        )
    }

    #[test]
    fn layout_is_consistent() {
        let f = fig().with_residual(Panel::new("r", vec![]).with_zero_line());
        let l = figure_layout(&f).unwrap();
        assert!(l.main.left > 0 && l.main.right < 1000 && l.main.bottom < 750);
        let r = l.residual.unwrap();
        assert!(r.top > l.main.bottom);
        assert!(r.height() * 2 < l.main.height());
        assert!(l.residual_y_range.unwrap().0 <= 0.0);
        let legend = l.main_legend.unwrap();
        assert!(legend.left >= l.main.left && legend.right <= l.main.right);
        assert!(series_inside(&f));
    }

    #[test]
    fn crowded_residual_legend_joins_the_main_legend() {
        // A residual that zig-zags over the whole panel height.
        let x: Vec<f64> = (0..2000).map(|i| i as f64 * 0.005).collect();
        let r: Vec<f64> = (0..2000)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let f = fig().with_residual(Panel::new(
            "r (kPa)",
            vec![Series::new("fit − data", x.clone(), r, Style::Other(1))],
        ));
        let p = plan(&f).unwrap();
        assert!(p.residual.as_ref().unwrap().legend.is_none());
        let labels: Vec<&str> = p
            .main
            .legend
            .as_ref()
            .unwrap()
            .entries
            .iter()
            .map(|e| e.label.as_str())
            .collect();
        assert_eq!(labels, vec!["fit", "fit − data"]);
        // A quiet residual keeps its own legend.
        let quiet: Vec<f64> = x.iter().map(|v| -v).collect();
        let f = fig().with_residual(Panel::new(
            "r (kPa)",
            vec![Series::new("fit − data", x, quiet, Style::Other(1))],
        ));
        assert!(figure_layout(&f).unwrap().residual_legend.is_some());
    }

    #[test]
    fn legend_labels() {
        let m = Metrics::new(1000, 750);
        let cycled = Series::new(
            "measured",
            vec![0.0, 1.0, 2.0, f64::NAN],
            vec![1.0; 4],
            Style::Measured,
        )
        .with_cycles(vec![1, 2, 5, 9]);
        assert_eq!(
            legend_entry(&cycled, &m).unwrap().label,
            "measured, cycle 1..5"
        );
        let one = Series::new("fit", vec![0.0], vec![1.0], Style::Fitted).with_cycles(vec![3]);
        assert_eq!(legend_entry(&one, &m).unwrap().label, "fit, cycle 3");
        let empty = Series::new("pub", vec![f64::NAN], vec![1.0], Style::Published);
        assert_eq!(legend_entry(&empty, &m).unwrap().label, "pub (no data)");
        let unlabelled = Series::new("  ", vec![0.0], vec![1.0], Style::Published);
        assert!(legend_entry(&unlabelled, &m).is_none());
    }

    #[test]
    fn invalid_figures_are_errors() {
        let mut f = fig();
        f.main.series[0].y.pop();
        assert!(matches!(validate(&f), Err(Invalid::Length { .. })));
        let f = fig().with_size(10, 10);
        assert!(matches!(validate(&f), Err(Invalid::Size(10, 10))));
        let mut f = fig();
        f.main.series[0].cycle = Some(vec![1, 2]);
        assert!(matches!(validate(&f), Err(Invalid::Cycles { .. })));
        assert!(figure_layout(&f).is_none());
    }
}
