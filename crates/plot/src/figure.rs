//! Curve figures: a main panel and an optional residual panel.

use std::path::Path;

use crate::canvas::{Canvas, HAlign, VAlign};
use crate::chrome::{
    dash_pattern, draw_axes, draw_grid, draw_legend, draw_no_data, draw_y_label, place_legend,
    place_title, AxisDraw, Legend, LegendEntry, Metrics, Swatch,
};
use crate::colors::{self, INK_RGB, ZERO_RGB};
use crate::fonts::{self, CAP_HEIGHT, DESCENT};
use crate::geom::{decimate, ClipBox, Mapper, Occupancy, PixelRect, Pt};
use crate::scale::{plottable, ticks, AxisRange, Extent, Ticks};
use crate::{check_size, png_io, DrawError, Figure, Invalid, Panel, PlotError, Series, Style};

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

struct PanelPlan {
    rect: PixelRect,
    y: AxisRange,
    yticks: Ticks,
    y_label: String,
    y_label_size: f64,
    zero_line: bool,
    strokes: Vec<Stroke>,
    markers: Vec<(Pt, f64, [u8; 3])>,
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

/// Radius of the markers of measured points: a 7-pixel disc at 1000x750.
fn marker_radius(m: &Metrics) -> f64 {
    (2.5 * m.s).round().max(2.0) + 0.5
}

/// Strokes and markers of one series in a panel.
fn series_strokes(
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
        let mclip = ClipBox::inside(mapper.rect, r + 1.0);
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

/// Vertical layout of a curve figure, in pixels.
struct Rows {
    /// Height of the title line (0 without title).
    title_block: f64,
    /// Top of the main panel.
    top: f64,
    /// Height of the main panel.
    main_h: f64,
    /// Gap between main and residual panel (0 without residual).
    gap: f64,
    /// Height of the residual panel (0 without residual).
    res_h: f64,
}

fn rows(fig: &Figure, m: &Metrics, with_residual: bool) -> Result<Rows, Invalid> {
    let title_block = if fig.title.trim().is_empty() {
        0.0
    } else {
        (m.title * 1.5).round()
    };
    let top = m.pad + title_block + m.px(8.0);
    let tick_text_h = (CAP_HEIGHT + DESCENT) * m.tick;
    let mut bottom = m.tick_len + m.gap + tick_text_h + m.pad;
    if !fig.x_label.trim().is_empty() {
        bottom += m.px(10.0) + (CAP_HEIGHT + DESCENT) * m.label;
    }
    let gap = if with_residual { m.px(20.0) } else { 0.0 };
    let avail = (f64::from(fig.height) - top - bottom - gap).floor();
    let main_h = if with_residual {
        (avail * 2.0 / 3.0).round()
    } else {
        avail
    };
    let res_h = avail - main_h;
    if main_h < 20.0 || (with_residual && res_h < 15.0) {
        return Err(Invalid::Draw(DrawError::TooLow {
            width: fig.width,
            height: fig.height,
        }));
    }
    Ok(Rows {
        title_block,
        top,
        main_h,
        gap,
        res_h,
    })
}

/// Left edge and width of the plotting areas: room for the rotated y label
/// and the widest tick label of either panel.
fn columns(fig: &Figure, m: &Metrics, yticks: &[&Ticks]) -> Result<(f64, f64), Invalid> {
    let tick_w = yticks
        .iter()
        .flat_map(|t| t.labels.iter())
        .map(|l| fonts::text_width(l, m.tick))
        .fold(0.0, f64::max);
    let has_ylabel = std::iter::once(&fig.main)
        .chain(fig.residual.as_ref())
        .any(|p| !p.y_label.trim().is_empty());
    let ylabel_col = if has_ylabel {
        CAP_HEIGHT * m.label + DESCENT * m.label + m.px(10.0)
    } else {
        0.0
    };
    let left = (m.pad + ylabel_col + tick_w + m.gap + m.tick_len)
        .ceil()
        .min(f64::from(fig.width) * 0.45);
    let plot_w = f64::from(fig.width) - left - m.px(30.0);
    if plot_w < 40.0 {
        return Err(Invalid::Draw(DrawError::TooNarrow {
            width: fig.width,
            height: fig.height,
        }));
    }
    Ok((left, plot_w))
}

/// X ticks: as many as fit `plot_w` pixels without overlapping labels.
fn x_ticks(x: AxisRange, plot_w: f64, m: &Metrics) -> Ticks {
    let mut target = ((plot_w / (110.0 * m.s)).round() as usize).clamp(2, 12);
    loop {
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
            return t;
        }
        target -= 1;
    }
}

/// The short residual panel rarely has a free corner: if its legend would
/// cover much data, its entries join the main legend instead.
fn merge_crowded_legend(main: &mut PanelPlan, residual: &mut PanelPlan, m: &Metrics) {
    let crowded = residual
        .legend
        .as_ref()
        .is_some_and(|l| residual.occupancy.fraction(l.rect) > 0.15);
    if crowded {
        residual.legend = None;
        let mut all = main.entries.clone();
        all.extend(residual.entries.iter().cloned());
        main.legend = place_legend(all, main.rect, &main.occupancy, m);
    }
}

/// Shrinks (then shortens) a y label to fit the height of its panel.
fn fit_ylabel(p: &mut PanelPlan, m: &Metrics) {
    let (text, size) = fonts::shrink_to_fit(
        &p.y_label,
        m.label,
        m.label * 0.7,
        f64::from(p.rect.height()),
    );
    p.y_label = text;
    p.y_label_size = size;
}

fn plan(fig: &Figure) -> Result<Plan, Invalid> {
    validate(fig)?;
    fonts::ensure_fonts().map_err(Invalid::Draw)?;
    let m = Metrics::new(fig.width, fig.height);
    let (x, main_y, res_y) = ranges(fig);
    let rows = rows(fig, &m, res_y.is_some())?;
    let y_target =
        |height: f64, per: f64, max: usize| ((height / (per * m.s)).round() as usize).clamp(2, max);
    let main_ticks = ticks(main_y, y_target(rows.main_h, 60.0, 9));
    let res_ticks = res_y.map(|r| ticks(r, y_target(rows.res_h, 45.0, 5)));
    let all_ticks: Vec<&Ticks> = std::iter::once(&main_ticks).chain(&res_ticks).collect();
    let (left, plot_w) = columns(fig, &m, &all_ticks)?;
    let xticks = x_ticks(x, plot_w, &m);

    let (left, top) = (left as i32, rows.top as i32);
    let main_rect = PixelRect {
        left,
        top,
        right: left + plot_w as i32 - 1,
        bottom: top + rows.main_h as i32 - 1,
    };
    let mut main = plan_panel(&fig.main, main_rect, x, main_y, main_ticks, &m, &[]);
    let mut residual = match (&fig.residual, res_y, res_ticks) {
        (Some(p), Some(y), Some(t)) => {
            let rect = PixelRect {
                top: main_rect.bottom + 1 + rows.gap as i32,
                bottom: main_rect.bottom + rows.gap as i32 + rows.res_h as i32,
                ..main_rect
            };
            let skip: Vec<String> = main.entries.iter().map(|e| e.label.clone()).collect();
            Some(plan_panel(p, rect, x, y, t, &m, &skip))
        }
        _ => None,
    };
    if let Some(r) = residual.as_mut() {
        merge_crowded_legend(&mut main, r, &m);
        fit_ylabel(r, &m);
    }
    fit_ylabel(&mut main, &m);

    let (title, title_size, title_center) =
        place_title(&fig.title, main_rect, fig.width, rows.title_block, &m);
    let max_w = f64::from(fig.width) - 2.0 * m.pad;
    let (x_label, x_label_size) =
        fonts::shrink_to_fit(fig.x_label.trim(), m.label, m.label * 0.7, max_w);
    Ok(Plan {
        width: fig.width,
        height: fig.height,
        m,
        x,
        xticks,
        title,
        title_size,
        title_center,
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

fn draw_panel(c: &mut Canvas, p: &PanelPlan, plan: &Plan, bottom_panel: bool) {
    let m = &plan.m;
    let axes = AxisDraw {
        rect: p.rect,
        x: Some((plan.x, &plan.xticks)),
        x_labels: bottom_panel,
        y: p.y,
        yticks: &p.yticks,
    };
    draw_grid(c, &axes);
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
            c.line(a, b, ZERO_RGB, 1.0, Some(dash_pattern(m)));
        }
    }
    for s in &p.strokes {
        let dash = s.dashed.then(|| dash_pattern(m));
        c.polyline(&s.pts, s.color, s.width, dash);
    }
    for &(pt, r, color) in &p.markers {
        c.dot(pt, r, color);
    }
    draw_axes(c, &axes, m, plan.width);
    if !p.has_data {
        draw_no_data(c, p.rect, m);
    }
    if let Some(l) = &p.legend {
        draw_legend(c, l, m);
    }
    draw_y_label(c, &p.y_label, p.y_label_size, p.rect, m);
}

fn draw(plan: &Plan) -> Result<Canvas, DrawError> {
    let mut c = Canvas::new(plan.width, plan.height)?;
    draw_panel(&mut c, &plan.main, plan, plan.residual.is_none());
    if let Some(r) = &plan.residual {
        draw_panel(&mut c, r, plan, true);
    }
    let m = &plan.m;
    c.text(
        &plan.title,
        plan.title_size,
        INK_RGB,
        plan.title_center,
        HAlign::Center,
        VAlign::Center,
    );
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
    );
    Ok(c)
}

/// Renders `fig` to an RGB buffer (3 bytes per pixel, row-major).
fn render_rgb(fig: &Figure) -> Result<Vec<u8>, Invalid> {
    let plan = plan(fig)?;
    Ok(draw(&plan).map_err(Invalid::Draw)?.into_rgb())
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
    fn no_room_for_the_plotting_area_is_a_draw_error() {
        let m = Metrics::new(200, 150);
        let low = fig().with_size(200, 40);
        let e = rows(&low, &m, false).err().unwrap();
        assert_eq!(
            e,
            Invalid::Draw(DrawError::TooLow {
                width: 200,
                height: 40
            })
        );
        let message = e.with_path(Path::new("out/low.png")).to_string();
        assert!(
            message.contains("low.png") && message.contains("200x40 is too low"),
            "{message}"
        );
        let narrow = fig().with_size(30, 150);
        let t = ticks(AxisRange { min: 0.0, max: 1.0 }, 5);
        assert!(matches!(
            columns(&narrow, &m, &[&t]),
            Err(Invalid::Draw(DrawError::TooNarrow { width: 30, .. }))
        ));
        // The smallest accepted figure, with a residual panel, has room.
        let smallest = fig()
            .with_residual(Panel::new("r", vec![]))
            .with_size(crate::MIN_WIDTH, crate::MIN_HEIGHT);
        assert!(rows(&smallest, &m, true).is_ok());
        assert!(columns(&smallest, &m, &[&t]).is_ok());
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
