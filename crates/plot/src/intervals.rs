//! Points with intervals: one point per item (a set of a campaign) with a vertical interval
//! (a 95 % profile interval) and optionally a horizontal range, in groups told apart by colour
//! (μ_s and μ_k; or one group per verdict). The x axis is numeric, or one labelled slot per
//! item ([`IntervalFigure::categories`]).
//!
//! An interval end that the data do not bound ([`IntervalEnd::Open`]) is drawn dashed to the
//! edge of the plot, and the legend says so: the figure never shows a box wall as if it were a
//! bound. The axis ranges cover the points and the bounded ends only.

use std::path::Path;

use crate::canvas::{Canvas, HAlign, VAlign};
use crate::chrome::{
    dash_pattern, draw_axes, draw_grid, draw_legend, draw_no_data, draw_y_label, place_legend,
    place_title, x_ticks, AxisDraw, Legend, LegendEntry, Metrics, Swatch,
};
use crate::colors::{style_rgb, INK_RGB};
use crate::fonts::{self, CAP_HEIGHT, DESCENT};
use crate::geom::{Mapper, Occupancy, PixelRect, Pt};
use crate::scale::{plottable, ticks, AxisRange, Extent, Ticks};
use crate::{check_size, png_io, DrawError, Invalid, PlotError, Style};

/// One end of a point's interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum IntervalEnd {
    /// Bounded at this value.
    At(f64),
    /// Not bounded by the data: drawn dashed to the edge of the plot.
    Open,
    /// No interval on this side.
    Absent,
}

/// One point: its position, its vertical interval and an optional horizontal range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntervalPoint {
    /// X (with categories: the item's index).
    pub x: f64,
    /// Y.
    pub y: f64,
    /// Lower end of the vertical interval.
    pub lo: IntervalEnd,
    /// Upper end of the vertical interval.
    pub hi: IntervalEnd,
    /// Horizontal range drawn through the point (what x stands for, e.g. the normal stresses
    /// of a set's tests).
    pub x_range: Option<(f64, f64)>,
}

impl IntervalPoint {
    /// A point without intervals.
    pub fn at(x: f64, y: f64) -> IntervalPoint {
        IntervalPoint {
            x,
            y,
            lo: IntervalEnd::Absent,
            hi: IntervalEnd::Absent,
            x_range: None,
        }
    }
}

/// Points of one colour, with their legend label.
#[derive(Debug, Clone, PartialEq)]
pub struct PointGroup {
    /// Legend label (empty: not in the legend).
    pub label: String,
    /// The points.
    pub points: Vec<IntervalPoint>,
}

/// A figure of points with intervals.
#[derive(Debug, Clone, PartialEq)]
pub struct IntervalFigure {
    /// Title (may be empty).
    pub title: String,
    /// X axis label, with units.
    pub x_label: String,
    /// Y axis label, with units.
    pub y_label: String,
    /// Groups, drawn in order, each in its colour, side by side at a shared x.
    pub groups: Vec<PointGroup>,
    /// Labels of the items x = 0, 1, … (a slot each) instead of a numeric x axis.
    pub categories: Option<Vec<String>>,
    /// Values the y axis shows whatever the points (e.g. 0 and 100 of a percentage).
    pub y_include: Vec<f64>,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl IntervalFigure {
    /// A 1000x750 figure with a numeric x axis and no groups.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        IntervalFigure {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            groups: Vec::new(),
            categories: None,
            y_include: Vec::new(),
            width: 1000,
            height: 750,
        }
    }

    /// The same figure with one more group.
    pub fn with_group(mut self, label: impl Into<String>, points: Vec<IntervalPoint>) -> Self {
        self.groups.push(PointGroup {
            label: label.into(),
            points,
        });
        self
    }

    /// The same figure with one labelled slot per item along x.
    pub fn with_categories(mut self, labels: Vec<String>) -> Self {
        self.categories = Some(labels);
        self
    }
}

/// Where an [`IntervalFigure`] is drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct IntervalLayout {
    /// Plotting area.
    pub plot: PixelRect,
    /// Legend box, if any.
    pub legend: Option<PixelRect>,
    /// X range.
    pub x_range: (f64, f64),
    /// Y range.
    pub y_range: (f64, f64),
    /// Pixel centre of every drawn point: (group, index in the group, centre).
    pub points: Vec<(usize, usize, (f64, f64))>,
    /// Whether category labels are written upwards (they do not fit side by side).
    pub upright_categories: bool,
}

/// Colour of group `g`.
fn group_rgb(g: usize) -> [u8; 3] {
    match g {
        0 => style_rgb(Style::Fitted),
        1 => style_rgb(Style::Published),
        k => style_rgb(Style::Other(k - 2)),
    }
}

struct Plan {
    m: Metrics,
    rect: PixelRect,
    x: AxisRange,
    y: AxisRange,
    xticks: Option<Ticks>,
    yticks: Ticks,
    /// Category labels, their size, and whether upright.
    categories: Option<(Vec<String>, f64, bool)>,
    title: (String, f64, (f64, f64)),
    x_label: (String, f64),
    y_label: (String, f64),
    legend: Option<Legend>,
    /// Pixel offset of each group at a shared x.
    dodge: Vec<f64>,
    empty: bool,
}

fn drawable(p: &IntervalPoint) -> bool {
    plottable(p.x) && plottable(p.y)
}

fn validate(fig: &IntervalFigure) -> Result<(), Invalid> {
    check_size(fig.width, fig.height)
}

fn extents(fig: &IntervalFigure) -> (AxisRange, AxisRange, bool) {
    let (mut xe, mut ye) = (Extent::default(), Extent::default());
    for v in &fig.y_include {
        ye.add(*v);
    }
    let mut any = false;
    for p in fig
        .groups
        .iter()
        .flat_map(|g| &g.points)
        .filter(|p| drawable(p))
    {
        any = true;
        xe.add(p.x);
        ye.add(p.y);
        for end in [p.lo, p.hi] {
            if let IntervalEnd::At(v) = end {
                ye.add(v);
            }
        }
        if let Some((a, b)) = p.x_range {
            xe.add(a);
            xe.add(b);
        }
    }
    let x = match &fig.categories {
        Some(c) => AxisRange {
            min: -0.5,
            max: c.len().max(1) as f64 - 0.5,
        },
        None => xe.padded(false),
    };
    (x, ye.padded(false), any)
}

fn text_h(size: f64) -> f64 {
    (CAP_HEIGHT + DESCENT) * size
}

fn plan(fig: &IntervalFigure) -> Result<Plan, Invalid> {
    validate(fig)?;
    fonts::ensure_fonts().map_err(Invalid::Draw)?;
    let m = Metrics::new(fig.width, fig.height);
    let (x, y, any) = extents(fig);
    let (w, h) = (f64::from(fig.width), f64::from(fig.height));
    let title_block = if fig.title.trim().is_empty() {
        0.0
    } else {
        (m.title * 1.5).round()
    };
    let top = m.pad + title_block + m.px(8.0);
    let x_label_h = if fig.x_label.trim().is_empty() {
        0.0
    } else {
        m.px(10.0) + text_h(m.label)
    };
    let yticks_guess = ticks(y, 6);
    let tick_w = yticks_guess
        .labels
        .iter()
        .map(|l| fonts::text_width(l, m.tick))
        .fold(0.0, f64::max);
    let left = (m.pad + text_h(m.label) + m.px(10.0) + tick_w + m.gap + m.tick_len)
        .ceil()
        .min(w * 0.45);
    let plot_w = w - left - m.px(30.0);
    if plot_w < 40.0 {
        return Err(Invalid::Draw(DrawError::TooNarrow {
            width: fig.width,
            height: fig.height,
        }));
    }
    // Category labels: side by side when they fit their slots, else upright (cut to a third
    // of the height).
    let categories = fig.categories.as_ref().map(|labels| {
        let slot = plot_w / labels.len().max(1) as f64;
        let widest = labels
            .iter()
            .map(|l| fonts::text_width(l, m.tick))
            .fold(0.0, f64::max);
        if widest <= slot * 0.9 {
            (labels.clone(), m.tick, false)
        } else {
            let size = (slot * 0.8 / text_h(1.0)).min(m.tick).max(m.tick * 0.5);
            let cut: Vec<String> = labels
                .iter()
                .map(|l| fonts::fit_text(l, size, h / 3.0))
                .collect();
            (cut, size, true)
        }
    });
    let x_tick_block = match &categories {
        Some((labels, size, true)) => labels
            .iter()
            .map(|l| fonts::text_width(l, *size))
            .fold(0.0, f64::max),
        Some((_, size, false)) => text_h(*size),
        None => text_h(m.tick),
    };
    let bottom = m.tick_len + m.gap + x_tick_block + x_label_h + m.pad;
    let plot_h = (h - top - bottom).floor();
    if plot_h < 20.0 {
        return Err(Invalid::Draw(DrawError::TooLow {
            width: fig.width,
            height: fig.height,
        }));
    }
    let rect = PixelRect {
        left: left as i32,
        top: top as i32,
        right: left as i32 + plot_w as i32 - 1,
        bottom: top as i32 + plot_h as i32 - 1,
    };
    let yticks = ticks(y, ((plot_h / (60.0 * m.s)).round() as usize).clamp(2, 9));
    let xticks = fig.categories.is_none().then(|| x_ticks(x, plot_w, &m));
    let n = fig.groups.len();
    let step = m.px(8.0);
    let dodge = (0..n)
        .map(|g| (g as f64 - 0.5 * (n as f64 - 1.0)) * step)
        .collect();
    let mut plan = Plan {
        m,
        rect,
        x,
        y,
        xticks,
        yticks,
        categories,
        title: place_title(&fig.title, rect, fig.width, title_block, &m),
        x_label: fonts::shrink_to_fit(fig.x_label.trim(), m.label, m.label * 0.7, w - 2.0 * m.pad),
        y_label: fonts::shrink_to_fit(
            fig.y_label.trim(),
            m.label,
            m.label * 0.7,
            f64::from(rect.height()),
        ),
        legend: None,
        dodge,
        empty: !any,
    };
    plan.legend = legend(fig, &plan);
    Ok(plan)
}

/// A drawn point: its centre, its interval's pixel ends (top, bottom) with whether each is
/// open, and its horizontal range.
struct Marks {
    centre: Pt,
    top: Option<(f64, bool)>,
    bottom: Option<(f64, bool)>,
    across: Option<(f64, f64)>,
}

fn marks(p: &IntervalPoint, plan: &Plan, dx: f64) -> Marks {
    let mapper = Mapper {
        rect: plan.rect,
        x: plan.x,
        y: plan.y,
    };
    let r = plan.rect;
    let clamp_y = |v: f64| v.clamp(f64::from(r.top), f64::from(r.bottom));
    let end = |e: IntervalEnd, edge: i32| match e {
        IntervalEnd::At(v) if plottable(v) => Some((clamp_y(mapper.py(v)), false)),
        IntervalEnd::Open => Some((f64::from(edge), true)),
        _ => None,
    };
    let clamp_x = |v: f64| v.clamp(f64::from(r.left), f64::from(r.right));
    Marks {
        centre: (mapper.px(p.x) + dx, mapper.py(p.y)),
        top: end(p.hi, r.top),
        bottom: end(p.lo, r.bottom),
        across: p
            .x_range
            .filter(|(a, b)| plottable(*a) && plottable(*b))
            .map(|(a, b)| (clamp_x(mapper.px(a)), clamp_x(mapper.px(b)))),
    }
}

fn legend(fig: &IntervalFigure, plan: &Plan) -> Option<Legend> {
    let m = &plan.m;
    let mut occupancy = Occupancy::new(plan.rect, (12.0 * m.s).round().max(4.0) as i32);
    let mut entries = Vec::new();
    let mut open = false;
    for (g, group) in fig.groups.iter().enumerate() {
        for p in group.points.iter().filter(|p| drawable(p)) {
            let k = marks(p, plan, plan.dodge[g]);
            occupancy.mark_point(k.centre);
            for (end, is_open) in [k.top, k.bottom].into_iter().flatten() {
                occupancy.mark_polyline(&[k.centre, (k.centre.0, end)]);
                open |= is_open;
            }
            if let Some((a, b)) = k.across {
                occupancy.mark_polyline(&[(a, k.centre.1), (b, k.centre.1)]);
            }
        }
        if !group.label.trim().is_empty() {
            entries.push(LegendEntry {
                label: group.label.clone(),
                swatch: Swatch::Line {
                    color: group_rgb(g),
                    width: m.width(1.5),
                    dashed: false,
                    marker: Some((marker_radius(m), group_rgb(g))),
                },
            });
        }
    }
    if open {
        entries.push(LegendEntry {
            label: "interval not bounded by the data".into(),
            swatch: Swatch::Line {
                color: INK_RGB,
                width: m.width(1.5),
                dashed: true,
                marker: None,
            },
        });
    }
    place_legend(entries, plan.rect, &occupancy, m)
}

fn marker_radius(m: &Metrics) -> f64 {
    (3.0 * m.s).round().max(2.0) + 0.5
}

/// Where the parts of `fig` would be drawn, or `None` if `fig` is invalid.
pub fn interval_layout(fig: &IntervalFigure) -> Option<IntervalLayout> {
    let p = plan(fig).ok()?;
    let mut points = Vec::new();
    for (g, group) in fig.groups.iter().enumerate() {
        for (i, pt) in group.points.iter().enumerate() {
            if drawable(pt) {
                points.push((g, i, marks(pt, &p, p.dodge[g]).centre));
            }
        }
    }
    Some(IntervalLayout {
        plot: p.rect,
        legend: p.legend.as_ref().map(|l| l.rect),
        x_range: (p.x.min, p.x.max),
        y_range: (p.y.min, p.y.max),
        points,
        upright_categories: p.categories.as_ref().is_some_and(|c| c.2),
    })
}

fn draw_categories(c: &mut Canvas, plan: &Plan) {
    let Some((labels, size, upright)) = &plan.categories else {
        return;
    };
    let r = plan.rect;
    let tl = plan.m.tick_len as i32;
    let slot = f64::from(r.right - r.left) / labels.len().max(1) as f64;
    for (i, label) in labels.iter().enumerate() {
        let x = f64::from(r.left) + (i as f64 + 0.5) * slot;
        c.fill(
            PixelRect {
                left: x.round() as i32,
                right: x.round() as i32,
                top: r.bottom + 1,
                bottom: r.bottom + tl,
            },
            INK_RGB,
        );
        let y0 = f64::from(r.bottom + tl) + plan.m.gap;
        if *upright {
            let w = fonts::text_width(label, *size);
            c.text_vertical(label, *size, INK_RGB, (x, y0 + 0.5 * w));
        } else {
            c.text(label, *size, INK_RGB, (x, y0), HAlign::Center, VAlign::Top);
        }
    }
}

fn draw(fig: &IntervalFigure, plan: &Plan) -> Result<Canvas, DrawError> {
    let m = &plan.m;
    let mut c = Canvas::new(fig.width, fig.height)?;
    let axes = AxisDraw {
        rect: plan.rect,
        x: plan.xticks.as_ref().map(|t| (plan.x, t)),
        x_labels: true,
        y: plan.y,
        yticks: &plan.yticks,
    };
    draw_grid(&mut c, &axes);
    let width = m.width(1.6);
    let cap = m.px(5.0);
    let dash = dash_pattern(m);
    for (g, group) in fig.groups.iter().enumerate() {
        let color = group_rgb(g);
        for p in group.points.iter().filter(|p| drawable(p)) {
            let k = marks(p, plan, plan.dodge[g]);
            let (cx, cy) = k.centre;
            if let Some((a, b)) = k.across {
                c.line((a, cy), (b, cy), color, m.width(1.0), None);
            }
            for (end, open) in [k.top, k.bottom].into_iter().flatten() {
                if open {
                    c.line((cx, cy), (cx, end), color, width, Some(dash));
                } else {
                    c.line((cx, cy), (cx, end), color, width, None);
                    c.line((cx - cap, end), (cx + cap, end), color, width, None);
                }
            }
            c.dot((cx, cy), marker_radius(m), color);
        }
    }
    if plan.empty {
        draw_no_data(&mut c, plan.rect, m);
    }
    draw_axes(&mut c, &axes, m, fig.width);
    draw_categories(&mut c, plan);
    draw_y_label(&mut c, &plan.y_label.0, plan.y_label.1, plan.rect, m);
    if let Some(l) = &plan.legend {
        draw_legend(&mut c, l, m);
    }
    let (title, size, centre) = &plan.title;
    c.text(
        title,
        *size,
        INK_RGB,
        *centre,
        HAlign::Center,
        VAlign::Center,
    );
    let cx = 0.5 * f64::from(plan.rect.left + plan.rect.right);
    c.text(
        &plan.x_label.0,
        plan.x_label.1,
        INK_RGB,
        (cx, f64::from(fig.height) - m.pad),
        HAlign::Center,
        VAlign::Bottom,
    );
    Ok(c)
}

/// Draws `fig` and writes it to `path` as an RGB PNG. Errors (each naming `path`): a size out
/// of bounds, a file that cannot be written. A figure without drawable points says "no data".
pub fn render_interval_png(fig: &IntervalFigure, path: &Path) -> Result<(), PlotError> {
    let p = plan(fig).map_err(|e| e.with_path(path))?;
    let canvas = draw(fig, &p).map_err(|e| Invalid::Draw(e).with_path(path))?;
    png_io::write_rgb_png(path, fig.width, fig.height, &canvas.into_rgb())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(x: f64, y: f64, lo: IntervalEnd, hi: IntervalEnd) -> IntervalPoint {
        IntervalPoint {
            x,
            y,
            lo,
            hi,
            x_range: None,
        }
    }

    #[test]
    fn ranges_cover_points_and_bounded_ends_only() {
        use IntervalEnd::*;
        let fig = IntervalFigure::new("t", "x", "y")
            .with_group(
                "mu_s",
                vec![
                    point(1.0, 0.5, At(0.45), At(0.55)),
                    point(2.0, 0.6, Open, At(0.62)),
                ],
            )
            .with_group("mu_k", vec![point(1.0, 0.3, At(0.29), Open)]);
        let l = interval_layout(&fig).unwrap();
        // 0.29..0.62 padded by 5 %: the open ends do not stretch the axis to a box wall.
        assert!(l.y_range.0 > 0.25 && l.y_range.0 < 0.29, "{:?}", l.y_range);
        assert!(l.y_range.1 > 0.62 && l.y_range.1 < 0.66, "{:?}", l.y_range);
        assert_eq!(l.points.len(), 3);
        // Groups at the same x are drawn side by side, not on top of each other.
        let (a, b) = (l.points[0].2, l.points[2].2);
        assert!((a.0 - b.0).abs() >= 4.0, "{a:?} {b:?}");
        assert!(l.legend.is_some());
    }

    #[test]
    fn long_category_labels_stand_upright_and_everything_stays_in_the_image() {
        let labels: Vec<String> = (0..40).map(|i| format!("a-long-set-name-{i}")).collect();
        let pts = (0..40)
            .map(|i| IntervalPoint::at(i as f64, i as f64))
            .collect();
        let fig = IntervalFigure::new("verdicts", "", "shrink [%]")
            .with_group("none", pts)
            .with_categories(labels);
        let l = interval_layout(&fig).unwrap();
        assert!(l.upright_categories);
        assert!(l.plot.bottom < 740 && l.plot.bottom > 300, "{:?}", l.plot);
        let few = IntervalFigure::new("verdicts", "", "shrink [%]")
            .with_group("none", vec![IntervalPoint::at(0.0, 1.0)])
            .with_categories(vec!["pair-1".into(), "pair-2".into()]);
        assert!(!interval_layout(&few).unwrap().upright_categories);
    }

    #[test]
    fn an_empty_figure_is_drawn_and_a_bad_size_is_an_error_naming_the_file() {
        let dir = std::env::temp_dir().join(format!("subfric-intervals-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("empty.png");
        render_interval_png(&IntervalFigure::new("nothing", "x", "y"), &f).unwrap();
        let check = crate::inspect_png(&f).unwrap();
        assert_eq!((check.width, check.height), (1000, 750));
        let mut small = IntervalFigure::new("t", "x", "y");
        small.width = 10;
        let e = render_interval_png(&small, &dir.join("small.png")).unwrap_err();
        assert!(e.to_string().contains("small.png"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
