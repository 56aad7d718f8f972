//! Curve figures: a main panel, optionally a history and a residual panel below it sharing the
//! x axis, and optionally a zoom inside the main panel; each panel a plotters chart.

use std::path::Path;

use plotters::coord::CoordTranslate;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use crate::chart::{
    anchored, chart_err, clip_polyline, dashed, decimate, distinct_pixels, draw_legend, frame,
    no_data, place_legend, plot_rect, plottable, rgb, shrink_to_fit, stroke, whole_numbers, Area,
    AxisRange, Chart2d, Entry, Extent, Legend, Metrics, Occupancy, Pt, Swatch, Ticks,
};
use crate::colors::{self, INK_RGB, ZERO_RGB};
use crate::render::{self, Chart};
use crate::{check_size, DrawError, Figure, Invalid, Panel, PixelRect, PlotError, Series, Style};

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
    /// Plotting area of the history panel (between main and residual), if any.
    pub history: Option<PixelRect>,
    /// The zoom drawn inside the main panel, if any: its box (frame included).
    pub inset: Option<PixelRect>,
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
    /// Points of each drawn line of the main panel after decimation, in drawing order.
    pub main_line_points: Vec<usize>,
}

fn validate(fig: &Figure) -> Result<(), Invalid> {
    check_size(fig.width, fig.height)?;
    for s in panels(fig).flat_map(|p| p.series.iter()) {
        if s.x.len() != s.y.len() {
            return Err(Invalid::Length {
                label: s.label.clone(),
                x_len: s.x.len(),
                y_len: s.y.len(),
            });
        }
        if let Some(c) = s.cycle.as_ref().filter(|c| c.len() != s.x.len()) {
            return Err(Invalid::Cycles {
                label: s.label.clone(),
                points: s.x.len(),
                cycles: c.len(),
            });
        }
    }
    Ok(())
}

fn panels(fig: &Figure) -> impl Iterator<Item = &Panel> {
    std::iter::once(&fig.main)
        .chain(fig.history.as_ref())
        .chain(fig.residual.as_ref())
}

pub(crate) fn points(s: &Series) -> impl Iterator<Item = (f64, f64)> + '_ {
    s.x.iter()
        .zip(&s.y)
        .map(|(&x, &y)| (x, y))
        .filter(|&(x, y)| plottable(x) && plottable(y))
}

/// Shared x range, and the y range of each panel in the order main, history, residual.
fn ranges(fig: &Figure) -> (AxisRange, Vec<AxisRange>) {
    let mut x = Extent::default();
    let ys = panels(fig)
        .map(|p| {
            let mut y = Extent::default();
            for (px, py) in p.series.iter().flat_map(points) {
                x.add(px);
                y.add(py);
            }
            y.padded(p.zero_line)
        })
        .collect();
    (x.padded(false), ys)
}

/// Whether every drawable point (both coordinates finite and within
/// [`crate::MAX_ABS_VALUE`]) lies inside the axis ranges the figure is drawn with.
pub fn series_inside(fig: &Figure) -> bool {
    let (x, ys) = ranges(fig);
    panels(fig).zip(ys).all(|(p, y)| {
        p.series
            .iter()
            .flat_map(points)
            .all(|(a, b)| x.contains(a) && y.contains(b))
    })
}

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
type Marker = ((f64, f64), u32, [u8; 3]);

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

/// Legend entries of a panel: one per label, leaving out labels listed in `skip`.
fn entries(p: &Panel, m: &Metrics, skip: &[Entry]) -> Vec<Entry> {
    let mut out: Vec<Entry> = Vec::new();
    for e in p.series.iter().filter_map(|s| legend_entry(s, m)) {
        let seen = |l: &[Entry]| l.iter().any(|x| x.label == e.label);
        if !seen(skip) && !seen(&out) {
            out.push(e);
        }
    }
    out
}

/// One panel, planned: its place, ranges, ticks, lines and legend.
struct PanelPlan<'f> {
    panel: &'f Panel,
    /// Top of its area and the area's height (plotting area plus the x labels below it).
    top: i32,
    height: i32,
    plot_h: i32,
    x_labels: bool,
    y: AxisRange,
    yticks: Ticks,
    y_label: (String, f64),
    entries: Vec<Entry>,
    legend: Option<Legend>,
}

/// The vertical layout: where each panel's area starts and how high it is.
struct Rows {
    title_h: i32,
    /// Height below the lowest plotting area: x tick labels and the x label.
    x_area: i32,
    heights: Vec<i32>,
    gap: i32,
}

fn rows(fig: &Figure, m: &Metrics, n: usize) -> Result<Rows, Invalid> {
    let title_h = if fig.title.trim().is_empty() {
        m.pad
    } else {
        m.pad + (m.title * 1.3) as i32
    };
    let mut x_area = 2 * m.tick_len + (m.tick / 1.24 * 1.1) as i32 + m.pad;
    if !fig.x_label.trim().is_empty() {
        x_area += (m.label / 1.24 * 1.3) as i32;
    }
    let gap = m.px(20.0);
    let tick_room = m.tick_len + 1;
    let avail = fig.height as i32 - title_h - x_area - (n as i32 - 1) * (gap + tick_room);
    let shares: &[f64] = match n {
        1 => &[1.0],
        2 if fig.history.is_some() => &[0.72, 0.28],
        2 => &[2.0 / 3.0, 1.0 / 3.0],
        _ => &[0.52, 0.2, 0.28],
    };
    let mut heights: Vec<i32> = shares
        .iter()
        .map(|s| (f64::from(avail) * s).round() as i32)
        .collect();
    let used: i32 = heights.iter().sum();
    heights[n - 1] += avail - used;
    if heights[0] < 20 || heights.iter().skip(1).any(|&h| h < 15) {
        return Err(Invalid::Draw(DrawError::TooLow {
            width: fig.width,
            height: fig.height,
        }));
    }
    Ok(Rows {
        title_h,
        x_area,
        heights,
        gap,
    })
}

/// The whole figure planned, and drawn into an SVG document.
struct Drawn {
    svg: String,
    layout: FigureLayout,
}

fn draw(fig: &Figure) -> Result<Drawn, Invalid> {
    validate(fig)?;
    render::ensure_font().map_err(Invalid::Draw)?;
    let m = Metrics::new(fig.width, fig.height);
    let (x, ys) = ranges(fig);
    let list: Vec<&Panel> = panels(fig).collect();
    let n = list.len();
    let rows = rows(fig, &m, n)?;
    let integer_x = fig.whole_x
        || whole_numbers(
            list.iter()
                .flat_map(|p| p.series.iter())
                .flat_map(|s| s.x.iter()),
        );
    // Y ticks per panel, then the column left of the plotting areas that fits them all.
    let yticks: Vec<Ticks> = rows
        .heights
        .iter()
        .zip(&ys)
        .enumerate()
        .map(|(k, (h, y))| {
            let per = if k == 0 { 60.0 } else { 45.0 };
            let most = ((f64::from(*h) / (per * m.s)).round() as usize)
                .clamp(2, if k == 0 { 9 } else { 5 });
            Ticks::new(*y, most, false)
        })
        .collect();
    let tick_w = yticks.iter().map(|t| t.widest(m.tick)).max().unwrap_or(0);
    let has_ylabel = list.iter().any(|p| !p.y_label.trim().is_empty());
    let ylabel_col = if has_ylabel {
        (m.label / 1.24 * 1.25) as i32 + m.px(6.0)
    } else {
        0
    };
    let left =
        (m.pad + ylabel_col + tick_w + 2 * m.tick_len).min((f64::from(fig.width) * 0.45) as i32);
    let right_margin = m.px(30.0);
    let plot_w = fig.width as i32 - left - right_margin;
    if plot_w < 40 {
        return Err(Invalid::Draw(DrawError::TooNarrow {
            width: fig.width,
            height: fig.height,
        }));
    }
    let xticks = Ticks::fitting(
        x,
        plot_w,
        m.tick,
        ((f64::from(plot_w) / (110.0 * m.s)).round() as usize).clamp(2, 12),
        integer_x,
    );
    let mut top = rows.title_h;
    let mut plans: Vec<PanelPlan> = Vec::new();
    let mut skip: Vec<Entry> = Vec::new();
    for (k, ((p, y), yt)) in list.iter().zip(&ys).zip(yticks).enumerate() {
        let last = k + 1 == n;
        let height = rows.heights[k] + if last { rows.x_area } else { m.tick_len + 1 };
        let entries = entries(p, &m, &skip);
        skip.extend(entries.iter().cloned());
        plans.push(PanelPlan {
            panel: p,
            top,
            height,
            plot_h: rows.heights[k],
            x_labels: last,
            y: *y,
            yticks: yt,
            y_label: shrink_to_fit(&p.y_label, m.label, m.label * 0.7, rows.heights[k]),
            entries,
            legend: None,
        });
        top += height + rows.gap;
    }
    let mut svg_layout = None;
    let svg = render::svg_of(fig.width, fig.height, |root| {
        root.fill(&WHITE).map_err(chart_err)?;
        let layout = draw_panels(root, fig, &m, x, &xticks, left, right_margin, &mut plans)?;
        title(root, &fig.title, layout.main, fig.width, &m)?;
        svg_layout = Some(layout);
        Ok(())
    })?;
    let layout = svg_layout.ok_or(Invalid::Draw(DrawError::Chart("nothing drawn".into())))?;
    Ok(Drawn { svg, layout })
}

/// The title over the plotting area, shifted or shrunk to stay inside the image.
pub(crate) fn title(
    root: &Area<'_>,
    text: &str,
    plot: PixelRect,
    width: u32,
    m: &Metrics,
) -> Result<(), Invalid> {
    if text.trim().is_empty() {
        return Ok(());
    }
    let max_w = width as i32 - 2 * m.pad;
    let (text, size) = shrink_to_fit(text, m.title, m.title * 0.6, max_w);
    let half = crate::chart::text_width(&text, size) / 2;
    let cx = ((plot.left + plot.right) / 2)
        .max(m.pad + half)
        .min(width as i32 - m.pad - half);
    root.draw(&Text::new(
        text,
        (cx, m.pad),
        anchored(size, INK_RGB, HPos::Center, VPos::Top),
    ))
    .map_err(chart_err)
}

/// The grid, ticks and axis labels of one panel of a stack sharing its x axis (the figures'
/// data and residual panels, a band and its difference): the x ticks' labels (`xticks`) and the x
/// axis's label (`x_label`) only on the panel that shows them (`x_labels`: the bottom one), the
/// y ticks and label its own.
pub(crate) fn stacked_panel_mesh(
    chart: &mut Chart2d<'_, '_>,
    (xticks, x_labels, x_label): (&Ticks, bool, &(String, f64)),
    (yticks, y_label): (&Ticks, &(String, f64)),
    m: &Metrics,
) -> Result<(), Invalid> {
    let xfmt = |v: &f64| {
        if x_labels {
            xticks.label(*v)
        } else {
            String::new()
        }
    };
    let yfmt = |v: &f64| yticks.label(*v);
    let mut mesh = chart.configure_mesh();
    mesh.x_labels(xticks.values.len().max(1))
        .y_labels(yticks.values.len().max(1))
        .x_label_formatter(&xfmt)
        .y_label_formatter(&yfmt)
        .bold_line_style(rgb(colors::GRID_RGB))
        .light_line_style(TRANSPARENT)
        .axis_style(BLACK)
        .set_all_tick_mark_size(m.tick_len)
        .label_style(crate::chart::font(m.tick))
        .axis_desc_style(crate::chart::font(y_label.1))
        .y_desc(y_label.0.clone());
    if x_labels && !x_label.0.is_empty() {
        mesh.x_desc(x_label.0.clone());
    }
    mesh.draw().map_err(chart_err)?;
    Ok(())
}

/// What a panel's plotting box `rect` holds once its `lines` and `markers` are drawn (`to_px`:
/// data to pixels): where a legend would cover them.
fn occupancy_of(
    rect: PixelRect,
    (lines, markers): (&[Line], &[Marker]),
    to_px: &dyn Fn(Pt) -> Pt,
    m: &Metrics,
) -> Occupancy {
    let mut occupancy = Occupancy::new(rect, m.px(6.0).max(3));
    for l in lines {
        let px: Vec<Pt> = l.pts.iter().map(|q| to_px(*q)).collect();
        occupancy.mark_polyline(&px);
    }
    for (q, _, _) in markers {
        occupancy.mark_point(to_px(*q));
    }
    occupancy
}

/// Each panel's legend after the first placed in its emptiest corner (kept in `plans`); one that
/// would cover much of a short panel's data joins the main legend. Returns the main legend's
/// entries.
fn place_panel_legends(
    plans: &mut [PanelPlan<'_>],
    rects: &[PixelRect],
    occupancies: &[Occupancy],
    m: &Metrics,
) -> Vec<Entry> {
    let mut main_entries = plans[0].entries.clone();
    for k in 1..plans.len() {
        let l = place_legend(plans[k].entries.clone(), rects[k], &occupancies[k], m);
        if l.as_ref()
            .is_some_and(|l| occupancies[k].fraction(l.rect) > 0.15)
        {
            main_entries.extend(plans[k].entries.iter().cloned());
        } else {
            plans[k].legend = l;
        }
    }
    main_entries
}

#[allow(clippy::too_many_arguments)]
fn draw_panels(
    root: &Area<'_>,
    fig: &Figure,
    m: &Metrics,
    x: AxisRange,
    xticks: &Ticks,
    left: i32,
    right_margin: i32,
    plans: &mut [PanelPlan],
) -> Result<FigureLayout, Invalid> {
    let mut rects = Vec::new();
    let mut charts = Vec::new();
    let mut occupancies = Vec::new();
    let mut line_points = Vec::new();
    let x_label = shrink_to_fit(
        &fig.x_label,
        m.label,
        m.label * 0.7,
        fig.width as i32 - 2 * m.pad,
    );
    for p in plans.iter() {
        let area = root
            .clone()
            .shrink((0, p.top), (fig.width, p.height as u32));
        let x_area = p.height - p.plot_h;
        let mut chart = ChartBuilder::on(&area)
            .margin_right(right_margin)
            .margin_left(m.pad)
            .y_label_area_size(left - m.pad)
            .x_label_area_size(x_area)
            .build_cartesian_2d(x.min..x.max, p.y.min..p.y.max)
            .map_err(chart_err)?;
        stacked_panel_mesh(
            &mut chart,
            (xticks, p.x_labels, &x_label),
            (&p.yticks, &p.y_label),
            m,
        )?;
        let rect = plot_rect(&chart);
        let spec = chart.as_coord_spec().clone();
        let to_px = |q: (f64, f64)| {
            let c = spec.translate(&q);
            (f64::from(c.0), f64::from(c.1))
        };
        if p.panel.zero_line && p.y.contains(0.0) {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x.min, 0.0), (x.max, 0.0)],
                    dashed(ZERO_RGB, 1),
                )))
                .map_err(chart_err)?;
        }
        let (lines, markers) = strokes(&p.panel.series, x, p.y, &to_px, m);
        let occupancy = occupancy_of(rect, (&lines, &markers), &to_px, m);
        if line_points.is_empty() {
            line_points = lines.iter().map(|l| l.pts.len()).collect();
        }
        draw_lines(&mut chart, lines, markers)?;
        if !p.panel.series.iter().any(|s| points(s).next().is_some()) {
            no_data(root, rect, m)?;
        }
        frame(root, rect, INK_RGB)?;
        rects.push(rect);
        occupancies.push(occupancy);
        charts.push(chart);
    }
    let main_entries = place_panel_legends(plans, &rects, &occupancies, m);
    let inset = match &fig.inset {
        Some(i) => draw_inset(
            root,
            fig,
            i,
            &mut charts[0],
            x,
            plans[0].y,
            &mut occupancies[0],
            m,
        )?,
        None => None,
    };
    plans[0].legend = place_legend(main_entries, rects[0], &occupancies[0], m);
    for (chart, p) in charts.iter_mut().zip(plans.iter()) {
        if let Some(l) = &p.legend {
            draw_legend(chart, l)?;
        }
    }
    Ok(layout_of(fig, plans, (&rects, inset), x, line_points))
}

/// Where the figure's parts went: its panels' boxes (`rects`, in the order of `plans`), the
/// inset's, the legends', the ranges, and how many points each of the main panel's lines kept.
fn layout_of(
    fig: &Figure,
    plans: &[PanelPlan<'_>],
    (rects, inset): (&[PixelRect], Option<PixelRect>),
    x: AxisRange,
    line_points: Vec<usize>,
) -> FigureLayout {
    let residual_at = fig.residual.as_ref().map(|_| plans.len() - 1);
    let history_at = fig.history.as_ref().map(|_| 1);
    FigureLayout {
        width: fig.width,
        height: fig.height,
        main: rects[0],
        residual: residual_at.map(|k| rects[k]),
        history: history_at.map(|k| rects[k]),
        inset,
        main_legend: plans[0].legend.as_ref().map(|l| l.rect),
        residual_legend: residual_at.and_then(|k| plans[k].legend.as_ref().map(|l| l.rect)),
        x_range: (x.min, x.max),
        main_y_range: (plans[0].y.min, plans[0].y.max),
        residual_y_range: residual_at.map(|k| (plans[k].y.min, plans[k].y.max)),
        main_line_points: line_points,
    }
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

/// The region the zoom `inset` shows, `(x, y)`: its slip range within the panel's (`x`), and
/// the range of the main panel's data there (`y` padded); `None` when it holds no data or would
/// show most of the panel (`x`, `y`) anyway.
fn inset_region(
    fig: &Figure,
    inset: &crate::Inset,
    x: AxisRange,
    y: AxisRange,
) -> Option<(AxisRange, AxisRange)> {
    let (lo, hi) = inset.x_range;
    let (lo, hi) = (lo.min(hi).max(x.min), hi.max(lo).min(x.max));
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return None;
    }
    let mut ey = Extent::default();
    for (px, py) in fig.main.series.iter().flat_map(points) {
        if (lo..=hi).contains(&px) {
            ey.add(py);
        }
    }
    // No data in the zoom's slip range: nothing to show.
    ey.bounds?;
    let (zx, zy) = (AxisRange { min: lo, max: hi }, ey.padded(false));
    if zx.span() > 0.6 * x.span() && zy.span() > 0.6 * y.span() {
        return None;
    }
    Some((zx, zy))
}

/// Outlines the zoomed region `(zx, zy)` in the main panel (dashed), each side clipped to the
/// panel's ranges `x`, `y`; a side the clipping moved onto the panel's edge is left out (the
/// frame is there).
fn outline_zoom(
    main: &mut Chart2d<'_, '_>,
    (zx, zy): (AxisRange, AxisRange),
    x: AxisRange,
    y: AxisRange,
) -> Result<(), Invalid> {
    let outline = [
        (zx.min, zy.max),
        (zx.max, zy.max),
        (zx.max, zy.min),
        (zx.min, zy.min),
        (zx.min, zy.max),
    ];
    for w in outline.windows(2) {
        let Some((a, b)) = crate::chart::clip_segment(w[0], w[1], x, y) else {
            continue;
        };
        if (a.1 == b.1) && (a.1 == y.min || a.1 == y.max) {
            continue;
        }
        main.draw_series(std::iter::once(PathElement::new(
            vec![a, b],
            dashed(ZERO_RGB, 1),
        )))
        .map_err(chart_err)?;
    }
    Ok(())
}

/// Share of the main panel's width and height the inset takes.
const INSET_SHARE: (f64, f64) = (0.44, 0.46);

/// Draws the zoom `inset` in the emptiest corner of the main panel, with the zoomed region
/// outlined in the panel; returns its box, or `None` when the zoom holds no data, would show
/// most of the panel anyway, or has no room.
#[allow(clippy::too_many_arguments)]
fn draw_inset(
    root: &Area<'_>,
    fig: &Figure,
    inset: &crate::Inset,
    main: &mut Chart2d<'_, '_>,
    x: AxisRange,
    y: AxisRange,
    occupancy: &mut Occupancy,
    m: &Metrics,
) -> Result<Option<PixelRect>, Invalid> {
    let Some((zx, zy)) = inset_region(fig, inset, x, y) else {
        return Ok(None);
    };
    let r = plot_rect(main);
    let (w, h) = (
        (f64::from(r.width()) * INSET_SHARE.0) as i32,
        (f64::from(r.height()) * INSET_SHARE.1) as i32,
    );
    if w < 120 || h < 90 {
        return Ok(None);
    }
    let margin = m.px(12.0);
    let (l, rr) = (r.left + margin, r.right - margin - w);
    let (t, b) = (r.top + margin, r.bottom - margin - h);
    let Some(outer) = [(rr, b), (rr, t), (l, b), (l, t)]
        .into_iter()
        .map(|(left, top)| PixelRect {
            left,
            top,
            right: left + w,
            bottom: top + h,
        })
        .min_by_key(|c| occupancy.count(*c))
    else {
        return Ok(None);
    };
    occupancy.mark_rect(outer);
    outline_zoom(main, (zx, zy), x, y)?;
    let sm = Metrics::new(
        (f64::from(fig.width) * 0.78) as u32,
        (f64::from(fig.height) * 0.78) as u32,
    );
    root.draw(&Rectangle::new(
        [(outer.left, outer.top), (outer.right, outer.bottom)],
        WHITE.filled(),
    ))
    .map_err(chart_err)?;
    frame(root, outer, ZERO_RGB)?;
    let area = root.clone().shrink(
        (outer.left + 1, outer.top + 1),
        ((w - 1) as u32, (h - 1) as u32),
    );
    let yticks = Ticks::new(zy, 4, false);
    let x_area = 2 * sm.tick_len + (sm.tick / 1.24 * 1.2) as i32 + sm.px(4.0);
    let y_area = yticks.widest(sm.tick) + 2 * sm.tick_len + sm.pad / 2;
    let inner_w = w - y_area - sm.px(14.0);
    let integer_x = fig.whole_x || whole_numbers(fig.main.series.iter().flat_map(|s| s.x.iter()));
    let xticks = Ticks::fitting(zx, inner_w, sm.tick, 4, integer_x);
    let title = crate::chart::fit_text(inset.title.trim(), sm.legend, w - 2 * sm.pad);
    let mut chart = ChartBuilder::on(&area)
        .caption(&title, crate::chart::font(sm.legend))
        .margin_right(sm.px(14.0))
        .margin_top(sm.pad / 2)
        .y_label_area_size(y_area)
        .x_label_area_size(x_area)
        .build_cartesian_2d(zx.min..zx.max, zy.min..zy.max)
        .map_err(chart_err)?;
    let xfmt = |v: &f64| xticks.label(*v);
    let yfmt = |v: &f64| yticks.label(*v);
    chart
        .configure_mesh()
        .x_labels(xticks.values.len().max(1))
        .y_labels(yticks.values.len().max(1))
        .x_label_formatter(&xfmt)
        .y_label_formatter(&yfmt)
        .bold_line_style(rgb(colors::GRID_RGB))
        .light_line_style(TRANSPARENT)
        .axis_style(BLACK)
        .set_all_tick_mark_size(sm.tick_len)
        .label_style(crate::chart::font(sm.tick))
        .draw()
        .map_err(chart_err)?;
    let inner = plot_rect(&chart);
    let spec = chart.as_coord_spec().clone();
    let to_px = |q: (f64, f64)| {
        let c = spec.translate(&q);
        (f64::from(c.0), f64::from(c.1))
    };
    let (lines, markers) = strokes(&fig.main.series, zx, zy, &to_px, &sm);
    draw_lines(&mut chart, lines, markers)?;
    frame(root, inner, INK_RGB)?;
    Ok(Some(outer))
}

impl Chart for Figure {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn svg_document(&self) -> Result<String, Invalid> {
        draw(self).map(|d| d.svg)
    }
}

/// Where the parts of `fig` would be drawn, or `None` if `fig` is invalid
/// (see [`render_png`] for the checks).
pub fn figure_layout(fig: &Figure) -> Option<FigureLayout> {
    draw(fig).ok().map(|d| d.layout)
}

/// Draws `fig` and writes it to `path` as an RGB PNG (see [`crate::write_figure`] for the PNG
/// and the SVG).
///
/// Errors (each naming `path`): a size outside
/// [`crate::MIN_WIDTH`]x[`crate::MIN_HEIGHT`]..=[`crate::MAX_SIDE`]; a series whose x, y
/// (and cycle) lengths differ; a file that cannot be written. Series
/// without drawable points are allowed: the figure then shows "no data"
/// or the legend marks them "(no data)".
pub fn render_png(fig: &Figure, path: &Path) -> Result<(), PlotError> {
    render::write_png(fig, path)
}
