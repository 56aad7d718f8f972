//! Curve figures: a main panel and an optional residual panel.

use std::path::Path;

use crate::canvas::{Canvas, HAlign, VAlign};
use crate::chrome::{
    dash_pattern, draw_axes, draw_grid, draw_legend, draw_no_data, draw_y_label, place_legend,
    place_title, x_ticks, AxisDraw, Legend, LegendEntry, Metrics,
};
use crate::colors::{INK_RGB, ZERO_RGB};
use crate::fonts::{self, CAP_HEIGHT, DESCENT};
use crate::geom::{ClipBox, Mapper, Occupancy, PixelRect, Pt};
use crate::inset::{draw_inset, plan_inset, InsetPlan};
use crate::scale::{plottable, ticks, AxisRange, Extent, Ticks};
use crate::strokes::{legend_entry, series_strokes, z_order, Stroke};
use crate::{check_size, png_io, DrawError, Figure, Invalid, Panel, PlotError, Series};

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
    history: Option<PanelPlan>,
    residual: Option<PanelPlan>,
    inset: Option<InsetPlan>,
}

fn validate(fig: &Figure) -> Result<(), Invalid> {
    check_size(fig.width, fig.height)?;
    let panels = std::iter::once(&fig.main)
        .chain(fig.history.as_ref())
        .chain(fig.residual.as_ref());
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

pub(crate) fn points(s: &Series) -> impl Iterator<Item = (f64, f64)> + '_ {
    s.x.iter()
        .zip(&s.y)
        .map(|(&x, &y)| (x, y))
        .filter(|&(x, y)| plottable(x) && plottable(y))
}

/// Axis ranges of a figure.
struct Ranges {
    /// Shared x.
    x: AxisRange,
    main: AxisRange,
    history: Option<AxisRange>,
    residual: Option<AxisRange>,
}

/// Axis ranges: shared x, and y of each panel.
fn ranges(fig: &Figure) -> Ranges {
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
    let main = panel_y(&fig.main, &mut x);
    let history = fig.history.as_ref().map(|p| panel_y(p, &mut x));
    let residual = fig.residual.as_ref().map(|p| panel_y(p, &mut x));
    Ranges {
        x: x.padded(false),
        main,
        history,
        residual,
    }
}

/// Whether every drawable point (both coordinates finite and within
/// [`crate::MAX_ABS_VALUE`]) lies inside the axis ranges the figure is drawn with.
pub fn series_inside(fig: &Figure) -> bool {
    let r = ranges(fig);
    let x = r.x;
    let inside = |p: &Panel, y: AxisRange| {
        p.series
            .iter()
            .all(|s| points(s).all(|(px, py)| x.contains(px) && y.contains(py)))
    };
    let below = |p: &Option<Panel>, y: Option<AxisRange>| match (p, y) {
        (Some(p), Some(y)) => inside(p, y),
        _ => true,
    };
    inside(&fig.main, r.main) && below(&fig.history, r.history) && below(&fig.residual, r.residual)
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
    /// Gap between two panels.
    gap: f64,
    /// Height of the history panel (0 without one).
    hist_h: f64,
    /// Height of the residual panel (0 without residual).
    res_h: f64,
}

fn rows(
    fig: &Figure,
    m: &Metrics,
    with_history: bool,
    with_residual: bool,
) -> Result<Rows, Invalid> {
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
    let gap = m.px(20.0);
    let gaps = f64::from(u8::from(with_history) + u8::from(with_residual));
    let avail = (f64::from(fig.height) - top - bottom - gaps * gap).floor();
    // Shares of the height: the main panel, the history, the residual.
    let (main_share, hist_share) = match (with_history, with_residual) {
        (false, false) => (1.0, 0.0),
        (false, true) => (2.0 / 3.0, 0.0),
        (true, false) => (0.72, 0.28),
        (true, true) => (0.52, 0.2),
    };
    let main_h = (avail * main_share).round();
    let hist_h = (avail * hist_share).round();
    let res_h = avail - main_h - hist_h;
    if main_h < 20.0 || (with_residual && res_h < 15.0) || (with_history && hist_h < 15.0) {
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
        hist_h,
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
        .chain(fig.history.as_ref())
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

/// A short panel below the main one rarely has a free corner: if its legend would cover much
/// data, its entries join the main legend instead.
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
    let r = ranges(fig);
    let x = r.x;
    let rows = rows(fig, &m, r.history.is_some(), r.residual.is_some())?;
    let y_target =
        |height: f64, per: f64, max: usize| ((height / (per * m.s)).round() as usize).clamp(2, max);
    let main_ticks = ticks(r.main, y_target(rows.main_h, 60.0, 9));
    let hist_ticks = r.history.map(|h| ticks(h, y_target(rows.hist_h, 45.0, 4)));
    let res_ticks = r.residual.map(|h| ticks(h, y_target(rows.res_h, 45.0, 5)));
    let all_ticks: Vec<&Ticks> = std::iter::once(&main_ticks)
        .chain(&hist_ticks)
        .chain(&res_ticks)
        .collect();
    let (left, plot_w) = columns(fig, &m, &all_ticks)?;
    let xticks = x_ticks(x, plot_w, &m);

    let (left, top) = (left as i32, rows.top as i32);
    let main_rect = PixelRect {
        left,
        top,
        right: left + plot_w as i32 - 1,
        bottom: top + rows.main_h as i32 - 1,
    };
    let mut main = plan_panel(&fig.main, main_rect, x, r.main, main_ticks, &m, &[]);
    let below = |above: PixelRect, h: f64| PixelRect {
        top: above.bottom + 1 + rows.gap as i32,
        bottom: above.bottom + rows.gap as i32 + h as i32,
        ..above
    };
    let mut history = match (&fig.history, r.history, hist_ticks) {
        (Some(p), Some(y), Some(t)) => {
            let skip: Vec<String> = main.entries.iter().map(|e| e.label.clone()).collect();
            let rect = below(main_rect, rows.hist_h);
            Some(plan_panel(p, rect, x, y, t, &m, &skip))
        }
        _ => None,
    };
    let last = history.as_ref().map_or(main_rect, |h| h.rect);
    let mut residual = match (&fig.residual, r.residual, res_ticks) {
        (Some(p), Some(y), Some(t)) => {
            let mut skip: Vec<String> = main.entries.iter().map(|e| e.label.clone()).collect();
            skip.extend(
                history
                    .iter()
                    .flat_map(|h| h.entries.iter().map(|e| e.label.clone())),
            );
            Some(plan_panel(p, below(last, rows.res_h), x, y, t, &m, &skip))
        }
        _ => None,
    };
    for p in history.iter_mut().chain(residual.as_mut()) {
        merge_crowded_legend(&mut main, p, &m);
        fit_ylabel(p, &m);
    }
    let inset = fig.inset.as_ref().and_then(|i| {
        let plan = plan_inset(fig, i, &main.rect, x, main.y, &main.occupancy, &m)?;
        main.occupancy.mark_rect(plan.outer);
        main.legend = place_legend(main.entries.clone(), main.rect, &main.occupancy, &m);
        Some(plan)
    });
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
        history,
        residual,
        inset,
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
        history: p.history.as_ref().map(|r| r.rect),
        inset: p.inset.as_ref().map(|i| i.outer),
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
    let below: Vec<&PanelPlan> = plan.history.iter().chain(&plan.residual).collect();
    draw_panel(&mut c, &plan.main, plan, below.is_empty());
    if let Some(i) = &plan.inset {
        draw_inset(&mut c, i, plan.x, plan.main.y, &plan.main.rect, &plan.m);
    }
    if let Some(l) = &plan.main.legend {
        draw_legend(&mut c, l, &plan.m);
    }
    for (k, p) in below.iter().enumerate() {
        draw_panel(&mut c, p, plan, k + 1 == below.len());
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
    let last = below.last().map_or(plan.main.rect, |r| r.rect);
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
    use crate::Style;

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
        let e = rows(&low, &m, false, false).err().unwrap();
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
        assert!(rows(&smallest, &m, false, true).is_ok());
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
