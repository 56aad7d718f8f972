//! Points with intervals: one point per item (a set of a campaign) with a vertical interval
//! (a 95 % profile interval) and optionally a horizontal range, in groups told apart by colour
//! (μ_s and μ_k; or one group per verdict). The x axis is numeric, or one labelled slot per
//! item ([`IntervalFigure::categories`]).
//!
//! An interval end that the data do not bound ([`IntervalEnd::Open`]) is drawn dashed to the
//! edge of the plot, and the legend says so: the figure never shows a box wall as if it were a
//! bound. The axis ranges cover the points and the bounded ends only.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontTransform;

use crate::chart::{
    chart_err, dashed, draw_legend, font, frame, no_data, place_legend, plot_rect, plottable, rgb,
    shrink_to_fit, stroke, text_width, whole_numbers, AxisRange, Chart2d, Entry, Extent, Metrics,
    Occupancy, Swatch, Ticks,
};
use crate::colors::{style_rgb, INK_RGB};
use crate::figure::title;
use crate::render::{self, Chart};
use crate::{check_size, DrawError, Invalid, PixelRect, PlotError, Style};

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

fn drawable(p: &IntervalPoint) -> bool {
    plottable(p.x) && plottable(p.y)
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

fn marker_radius(m: &Metrics) -> u32 {
    (3.5 * m.s).round().max(2.0) as u32
}

/// Where an interval chart's parts go, decided before anything is drawn: the metrics, the
/// axes' ranges (and whether any point is drawable), the figure's height, the title's height,
/// the margins, the x labels' area, the category labels (with their size, and whether upright),
/// the axis labels, the ticks, and each group's sideways dodge in pixels.
struct Geometry {
    m: Metrics,
    x: AxisRange,
    y: AxisRange,
    any: bool,
    h: i32,
    title_h: i32,
    left: i32,
    right_margin: i32,
    x_area: i32,
    categories: Option<(Vec<String>, f64, bool)>,
    x_label: (String, f64),
    y_label: (String, f64),
    xticks: Ticks,
    yticks: Ticks,
    dodge_px: Vec<f64>,
}

/// The category labels, their size and whether upright: side by side when they fit their slots
/// of the plotting width `plot_w`, else upright, cut to a third of the height `h`; `None` for a
/// numeric x axis.
fn category_labels(
    fig: &IntervalFigure,
    plot_w: i32,
    h: i32,
    m: &Metrics,
) -> Option<(Vec<String>, f64, bool)> {
    fig.categories.as_ref().map(|labels| {
        let slot = plot_w / labels.len().max(1) as i32;
        let widest = labels
            .iter()
            .map(|l| text_width(l, m.tick))
            .max()
            .unwrap_or(0);
        if f64::from(widest) <= f64::from(slot) * 0.9 {
            (labels.clone(), m.tick, false)
        } else {
            let size = (f64::from(slot) * 0.8 * 1.24).min(m.tick).max(m.tick * 0.5);
            let cut: Vec<String> = labels
                .iter()
                .map(|l| crate::chart::fit_text(l, size, h / 3))
                .collect();
            (cut, size, true)
        }
    })
}

/// The [`Geometry`] of `fig`; too narrow or too low a figure is refused.
fn geometry(fig: &IntervalFigure) -> Result<Geometry, Invalid> {
    let m = Metrics::new(fig.width, fig.height);
    let (x, y, any) = extents(fig);
    let (w, h) = (fig.width as i32, fig.height as i32);
    let title_h = if fig.title.trim().is_empty() {
        m.pad
    } else {
        m.pad + (m.title * 1.3) as i32
    };
    let yticks = Ticks::new(y, 7, false);
    let left = (m.pad
        + (m.label / 1.24 * 1.25) as i32
        + m.px(6.0)
        + yticks.widest(m.tick)
        + 2 * m.tick_len)
        .min((f64::from(w) * 0.45) as i32);
    let right_margin = m.px(30.0);
    let plot_w = w - left - right_margin;
    if plot_w < 40 {
        return Err(Invalid::Draw(DrawError::TooNarrow {
            width: fig.width,
            height: fig.height,
        }));
    }
    let categories = category_labels(fig, plot_w, h, &m);
    let tick_block = match &categories {
        Some((labels, size, true)) => labels
            .iter()
            .map(|l| text_width(l, *size))
            .max()
            .unwrap_or(0),
        Some((_, size, false)) => (size / 1.24 * 1.2) as i32,
        None => (m.tick / 1.24 * 1.2) as i32,
    };
    let x_label = shrink_to_fit(&fig.x_label, m.label, m.label * 0.7, w - 2 * m.pad);
    let x_label_h = if x_label.0.is_empty() {
        0
    } else {
        (m.label / 1.24 * 1.3) as i32
    };
    let x_area = 2 * m.tick_len + tick_block + x_label_h + m.pad;
    let plot_h = h - title_h - x_area;
    if plot_h < 20 {
        return Err(Invalid::Draw(DrawError::TooLow {
            width: fig.width,
            height: fig.height,
        }));
    }
    let yticks = Ticks::new(
        y,
        ((f64::from(plot_h) / (60.0 * m.s)).round() as usize).clamp(2, 9),
        false,
    );
    let integer_x = fig.categories.is_some()
        || whole_numbers(
            fig.groups
                .iter()
                .flat_map(|g| g.points.iter().map(|p| &p.x)),
        );
    let xticks = match &categories {
        Some((labels, ..)) => Ticks {
            values: (0..labels.len()).map(|i| i as f64).collect(),
            labels: labels.clone(),
        },
        None => Ticks::fitting(
            x,
            plot_w,
            m.tick,
            ((f64::from(plot_w) / (110.0 * m.s)).round() as usize).clamp(2, 12),
            integer_x,
        ),
    };
    let y_label = shrink_to_fit(&fig.y_label, m.label, m.label * 0.7, plot_h);
    let n = fig.groups.len();
    let dodge_px: Vec<f64> = (0..n)
        .map(|g| (g as f64 - 0.5 * (n as f64 - 1.0)) * f64::from(m.px(8.0)))
        .collect();
    Ok(Geometry {
        m,
        x,
        y,
        any,
        h,
        title_h,
        left,
        right_margin,
        x_area,
        categories,
        x_label,
        y_label,
        xticks,
        yticks,
        dodge_px,
    })
}

/// A point drawn: its group, its index in the group, and where it is (pixels).
type DrawnPoint = (usize, usize, (f64, f64));

/// Category labels stood upright (`labels` at font size `size`), each hanging from its tick
/// below the plotting area `plot`: anchored at its end, it runs down from the axis. The mesh's
/// own would not do: plotters centres a rotated tick label on its point, so half of a long one
/// stood in the plotting area, over the data (a campaign's verdict figure of 200 sets).
fn draw_upright_categories(
    root: &crate::chart::Area<'_>,
    chart: &Chart2d<'_, '_>,
    (labels, size): (&[String], f64),
    plot: PixelRect,
    m: &Metrics,
) -> Result<(), Invalid> {
    let style = font(size)
        .transform(FontTransform::Rotate270)
        .pos(Pos::new(HPos::Right, VPos::Center));
    let top = plot.bottom + 2 * m.tick_len;
    for (i, label) in labels.iter().enumerate() {
        let (px, _) = chart.backend_coord(&(i as f64, 0.0));
        root.draw_text(label, &style, (px, top))
            .map_err(chart_err)?;
    }
    Ok(())
}

/// Every drawable point of `fig` on `chart` (ranges `(x, y)`), dodged sideways by its group's
/// `dodge_px`, with its x range, its interval (capped; dashed to the edge where open) and its
/// marker, each marked in `occupancy` (the plotting box `plot`); returns the points drawn and
/// whether any interval was open.
fn draw_intervals(
    chart: &mut Chart2d<'_, '_>,
    fig: &IntervalFigure,
    (x, y): (AxisRange, AxisRange),
    dodge_px: &[f64],
    (occupancy, plot): (&mut Occupancy, PixelRect),
    m: &Metrics,
) -> Result<(Vec<DrawnPoint>, bool), Invalid> {
    let to_px = crate::chart::pixel_mapping(chart);
    let per_px = x.span() / f64::from(plot.width().max(1));
    let mut points = Vec::new();
    let mut open = false;
    let width = m.width(1.6);
    let cap = f64::from(m.px(5.0)) * per_px;
    for (g, group) in fig.groups.iter().enumerate() {
        let color = group_rgb(g);
        let dx = dodge_px[g] * per_px;
        for (i, p) in group.points.iter().enumerate().filter(|(_, p)| drawable(p)) {
            let (cx, cy) = (p.x + dx, p.y);
            if let Some((a, b)) = p.x_range.filter(|(a, b)| plottable(*a) && plottable(*b)) {
                let (a, b) = (a.clamp(x.min, x.max), b.clamp(x.min, x.max));
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(a, cy), (b, cy)],
                        stroke(color, m.width(1.0)),
                    )))
                    .map_err(chart_err)?;
                occupancy.mark_polyline(&[to_px((a, cy)), to_px((b, cy))]);
            }
            for (end, edge) in [(p.hi, y.max), (p.lo, y.min)] {
                let (to, is_open) = match end {
                    IntervalEnd::At(v) if plottable(v) => (v.clamp(y.min, y.max), false),
                    IntervalEnd::Open => (edge, true),
                    _ => continue,
                };
                open |= is_open;
                let style = if is_open {
                    dashed(color, width)
                } else {
                    stroke(color, width)
                };
                let mut parts = vec![PathElement::new(vec![(cx, cy), (cx, to)], style)];
                if !is_open {
                    parts.push(PathElement::new(
                        vec![(cx - cap, to), (cx + cap, to)],
                        stroke(color, width),
                    ));
                }
                chart.draw_series(parts).map_err(chart_err)?;
                occupancy.mark_polyline(&[to_px((cx, cy)), to_px((cx, to))]);
            }
            chart
                .draw_series(std::iter::once(Circle::new(
                    (cx, cy),
                    marker_radius(m),
                    rgb(color).filled(),
                )))
                .map_err(chart_err)?;
            occupancy.mark_point(to_px((cx, cy)));
            points.push((g, i, to_px((cx, cy))));
        }
    }
    Ok((points, open))
}

/// The legend's entries: each labelled group, and the dashed line of an open interval where one
/// was drawn (`open`).
fn legend_entries(fig: &IntervalFigure, open: bool, m: &Metrics) -> Vec<Entry> {
    let mut entries: Vec<Entry> = fig
        .groups
        .iter()
        .enumerate()
        .filter(|(_, g)| !g.label.trim().is_empty())
        .map(|(g, group)| Entry {
            label: group.label.clone(),
            swatch: Swatch::Line {
                color: group_rgb(g),
                width: m.width(1.5),
                dashed: false,
                marker: Some((marker_radius(m), group_rgb(g))),
            },
        })
        .collect();
    if open {
        entries.push(Entry {
            label: "interval not bounded by the data".into(),
            swatch: Swatch::Line {
                color: INK_RGB,
                width: m.width(1.5),
                dashed: true,
                marker: None,
            },
        });
    }
    entries
}

struct Drawn {
    svg: String,
    layout: IntervalLayout,
}

fn draw(fig: &IntervalFigure) -> Result<Drawn, Invalid> {
    check_size(fig.width, fig.height)?;
    render::ensure_font().map_err(Invalid::Draw)?;
    let Geometry {
        m,
        x,
        y,
        any,
        h,
        title_h,
        left,
        right_margin,
        x_area,
        categories,
        x_label,
        y_label,
        xticks,
        yticks,
        dodge_px,
    } = geometry(fig)?;
    let mut layout = None;
    let svg = render::svg_of(fig.width, fig.height, |root| {
        root.fill(&WHITE).map_err(chart_err)?;
        let area = root
            .clone()
            .shrink((0, title_h), (fig.width, (h - title_h) as u32));
        let mut chart = ChartBuilder::on(&area)
            .margin_right(right_margin)
            .margin_left(m.pad)
            .y_label_area_size(left - m.pad)
            .x_label_area_size(x_area)
            .build_cartesian_2d(x.min..x.max, y.min..y.max)
            .map_err(chart_err)?;
        // Upright category labels are drawn apart ([`draw_upright_categories`]).
        let upright = categories.as_ref().is_some_and(|c| c.2);
        let xfmt = |v: &f64| {
            if upright {
                String::new()
            } else {
                xticks.label(*v)
            }
        };
        let yfmt = |v: &f64| yticks.label(*v);
        let x_style = font(categories.as_ref().map_or(m.tick, |c| c.1));
        let mut mesh = chart.configure_mesh();
        mesh.x_labels(xticks.values.len().max(1))
            .y_labels(yticks.values.len().max(1))
            .x_label_formatter(&xfmt)
            .y_label_formatter(&yfmt)
            .bold_line_style(rgb(crate::colors::GRID_RGB))
            .light_line_style(TRANSPARENT)
            .axis_style(BLACK)
            .set_all_tick_mark_size(m.tick_len)
            .x_label_style(x_style)
            .y_label_style(font(m.tick))
            .axis_desc_style(font(y_label.1))
            .y_desc(y_label.0.clone());
        if !x_label.0.is_empty() {
            mesh.x_desc(x_label.0.clone());
        }
        mesh.draw().map_err(chart_err)?;
        let plot = plot_rect(&chart);
        if let Some((labels, size, true)) = &categories {
            draw_upright_categories(root, &chart, (labels, *size), plot, &m)?;
        }
        let mut occupancy = Occupancy::new(plot, m.px(12.0).max(4));
        let (points, open) = draw_intervals(
            &mut chart,
            fig,
            (x, y),
            &dodge_px,
            (&mut occupancy, plot),
            &m,
        )?;
        if !any {
            no_data(root, plot, &m)?;
        }
        frame(root, plot, INK_RGB)?;
        let entries = legend_entries(fig, open, &m);
        let legend = place_legend(entries, plot, &occupancy, &m);
        if let Some(l) = &legend {
            draw_legend(&mut chart, l)?;
        }
        title(root, &fig.title, plot, fig.width, &m)?;
        layout = Some(IntervalLayout {
            plot,
            legend: legend.map(|l| l.rect),
            x_range: (x.min, x.max),
            y_range: (y.min, y.max),
            points,
            upright_categories: categories.as_ref().is_some_and(|c| c.2),
        });
        Ok(())
    })?;
    let layout = layout.ok_or(Invalid::Draw(DrawError::Chart("nothing drawn".into())))?;
    Ok(Drawn { svg, layout })
}

impl Chart for IntervalFigure {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn svg_document(&self) -> Result<String, Invalid> {
        draw(self).map(|d| d.svg)
    }
}

/// Where the parts of `fig` would be drawn, or `None` if `fig` is invalid.
pub fn interval_layout(fig: &IntervalFigure) -> Option<IntervalLayout> {
    draw(fig).ok().map(|d| d.layout)
}

/// Draws `fig` and writes it to `path` as an RGB PNG (see [`crate::write_figure`] for the PNG
/// and the SVG). Errors (each naming `path`): a size out of bounds, a file that cannot be
/// written. A figure without drawable points says "no data".
pub fn render_interval_png(fig: &IntervalFigure, path: &Path) -> Result<(), PlotError> {
    render::write_png(fig, path)
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
    fn upright_category_labels_hang_below_the_plotting_area_never_over_the_data() {
        // plotters centres a rotated tick label on its point: half of a long label stood in the
        // plotting area, over the points (a campaign's verdict figure of 200 sets).
        let labels: Vec<String> = (0..12)
            .map(|i| format!("log-healing + pressure ({i})"))
            .collect();
        let pts = (0..12)
            .map(|i| IntervalPoint::at(i as f64, 10.0 * i as f64))
            .collect();
        let fig = IntervalFigure::new("verdicts", "verdict (sets)", "shrink [%]")
            .with_group("", pts)
            .with_categories(labels.clone());
        let d = draw(&fig).unwrap();
        assert!(d.layout.upright_categories);
        let bottom = d.layout.plot.bottom as f64;
        let mut seen = 0;
        // Each text element: its attributes on the tag's line, its content on the next.
        for block in d.svg.split("<text ").skip(1) {
            let mut lines = block.lines();
            let (tag, content) = (lines.next().unwrap_or(""), lines.next().unwrap_or(""));
            if !labels.iter().any(|l| l == content.trim()) {
                continue;
            }
            seen += 1;
            let at = tag.split("rotate(270, ").nth(1).expect("upright");
            let y: f64 = at
                .split(')')
                .next()
                .unwrap()
                .split(", ")
                .nth(1)
                .unwrap()
                .parse()
                .unwrap();
            assert!(
                y > bottom,
                "{content}: anchored at {y}, the plot ends at {bottom}"
            );
            // Anchored at its end: the text runs down from the axis.
            assert!(tag.contains("text-anchor=\"end\""), "{tag}");
        }
        assert_eq!(seen, labels.len(), "every label drawn once");
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
