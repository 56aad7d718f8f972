//! Grouped bar charts: a plotters chart with one slot per category along x.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use crate::chart::{
    anchored, chart_err, dashed, draw_legend, font, frame, no_data, place_legend, plot_rect,
    plottable, rgb, shrink_to_fit, stroke, text_width, typographic_minus, AxisRange, Chart2d,
    Entry, Extent, Metrics, Occupancy, Swatch, Ticks,
};
use crate::colors::{BAR_PALETTE, INK_RGB, ZERO_RGB};
use crate::figure::title;
use crate::render::{self, Chart};
use crate::{check_size, BarFigure, DrawError, Invalid, PixelRect, PlotError};

/// Where the parts of a [`BarFigure`] are drawn, in pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct BarLayout {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Plotting area (frame on its edge pixels); all bars are inside it.
    pub plot: PixelRect,
    /// Legend box, if any (inside `plot`).
    pub legend: Option<PixelRect>,
    /// Y axis range.
    pub y_range: (f64, f64),
    /// Rectangles of the drawn bars: (category index, group index, rect).
    pub bars: Vec<(usize, usize, PixelRect)>,
}

fn validate(fig: &BarFigure) -> Result<(), Invalid> {
    check_size(fig.width, fig.height)?;
    for (name, values) in &fig.groups {
        if values.len() != fig.categories.len() {
            return Err(Invalid::Group {
                group: name.clone(),
                values: values.len(),
                categories: fig.categories.len(),
            });
        }
    }
    Ok(())
}

/// Number format for bar value labels: three significant digits for the largest magnitude and
/// the same number of decimals for all labels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ValueFormat {
    Fixed(usize),
    Scientific,
}

impl ValueFormat {
    fn for_values<'a>(values: impl Iterator<Item = &'a f64>) -> Self {
        let max_abs = values
            .filter(|v| plottable(**v))
            .fold(0.0f64, |m, v| m.max(v.abs()));
        if max_abs == 0.0 {
            ValueFormat::Fixed(0)
        } else if !(1e-3..1e5).contains(&max_abs) {
            ValueFormat::Scientific
        } else {
            ValueFormat::Fixed((2 - max_abs.log10().floor() as i32).clamp(0, 6) as usize)
        }
    }

    fn format(self, v: f64) -> String {
        typographic_minus(match self {
            _ if v == 0.0 => "0".to_string(),
            ValueFormat::Fixed(d) => format!("{v:.d$}"),
            ValueFormat::Scientific => format!("{v:.2e}"),
        })
    }
}

/// A single value with three significant digits.
fn format_value(v: f64) -> String {
    ValueFormat::for_values(std::iter::once(&v)).format(v)
}

/// Legend entries: one patch per named group, then the reference line.
fn entries(fig: &BarFigure, m: &Metrics) -> Vec<Entry> {
    let mut out: Vec<Entry> = fig
        .groups
        .iter()
        .enumerate()
        .filter(|(_, (name, _))| !name.trim().is_empty())
        .map(|(g, (name, _))| Entry {
            label: name.clone(),
            swatch: Swatch::Patch {
                color: BAR_PALETTE[g % BAR_PALETTE.len()],
            },
        })
        .collect();
    if let Some((label, v)) = fig
        .reference_line
        .as_ref()
        .filter(|(l, _)| !l.trim().is_empty())
    {
        out.push(Entry {
            label: if plottable(*v) {
                format!("{label} ({})", format_value(*v))
            } else {
                format!("{label} (no data)")
            },
            swatch: Swatch::Line {
                color: ZERO_RGB,
                width: m.width(1.5),
                dashed: true,
                marker: None,
            },
        });
    }
    out
}

/// The y range: zero, every finite value and the reference line, padded by 5 %, with room at
/// the top for a legend `legend_share` of the plotting height high.
fn y_range(fig: &BarFigure, legend_share: f64) -> AxisRange {
    let mut e = Extent::default();
    e.add(0.0);
    for v in fig.groups.iter().flat_map(|(_, v)| v.iter()) {
        e.add(*v);
    }
    if let Some((_, r)) = &fig.reference_line {
        e.add(*r);
    }
    let (lo, hi) = e.bounds.unwrap_or((0.0, 0.0));
    let span = hi - lo;
    if !(span > 0.0 && span > lo.abs().max(hi.abs()) * 1e-12) {
        return AxisRange { min: 0.0, max: 1.0 };
    }
    let min = if lo < 0.0 { lo - 0.05 * span } else { 0.0 };
    let max = if hi > 0.0 { hi + 0.05 * span } else { 0.0 };
    let max = if hi > 0.0 && legend_share > 0.0 {
        min + (max - min) / (1.0 - legend_share.min(0.6))
    } else {
        max
    };
    AxisRange { min, max }
}

/// The zero line where the bars go both ways, and the figure's reference line (dashed, marked in
/// `occupancy` so that the legend keeps off it), across the `n` categories of the y range `y`.
fn draw_level_lines(
    chart: &mut Chart2d<'_, '_>,
    fig: &BarFigure,
    (y, n): (AxisRange, usize),
    occupancy: &mut Occupancy,
    m: &Metrics,
) -> Result<(), Invalid> {
    let spec = chart.as_coord_spec().clone();
    let px = |x: f64, v: f64| plotters::coord::CoordTranslate::translate(&spec, &(x, v));
    if y.min < 0.0 && y.max > 0.0 {
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(-0.5, 0.0), (n as f64 - 0.5, 0.0)],
                stroke(INK_RGB, 1),
            )))
            .map_err(chart_err)?;
    }
    if let Some((_, v)) = fig
        .reference_line
        .as_ref()
        .filter(|(_, v)| plottable(*v) && y.contains(*v))
    {
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(-0.5, *v), (n as f64 - 0.5, *v)],
                dashed(ZERO_RGB, m.width(1.5)),
            )))
            .map_err(chart_err)?;
        let (a, b) = (px(-0.5, *v), px(n as f64 - 0.5, *v));
        occupancy.mark_polyline(&[
            (f64::from(a.0), f64::from(a.1)),
            (f64::from(b.0), f64::from(b.1)),
        ]);
    }
    Ok(())
}

/// A value's label drawn over (or under) its bar: text, anchor, vertical side, colour.
type ValueLabel = (String, (i32, i32), VPos, [u8; 3]);

/// A bar drawn: its category, its group and its box.
type DrawnBar = (usize, usize, PixelRect);

/// Every bar of `fig` drawn on `chart` (its y range `y`), each marked in `occupancy` (the
/// plotting box `plot`); returns each bar's (category, group, box) and the value labels that
/// fit in their bars, to be drawn over everything else ("n/a" where a value is missing).
fn draw_bars(
    chart: &mut Chart2d<'_, '_>,
    fig: &BarFigure,
    y: AxisRange,
    format: &ValueFormat,
    (occupancy, plot): (&mut Occupancy, PixelRect),
    m: &Metrics,
) -> Result<(Vec<DrawnBar>, Vec<ValueLabel>), Invalid> {
    let spec = chart.as_coord_spec().clone();
    let px = |x: f64, v: f64| plotters::coord::CoordTranslate::translate(&spec, &(x, v));
    let groups = fig.groups.len().max(1) as f64;
    let bar_w = 0.8 / groups;
    let y0 = 0.0f64.clamp(y.min, y.max);
    let mut bars = Vec::new();
    let mut texts = Vec::new();
    let value_size = m.tick * 0.8;
    for (g, (_, values)) in fig.groups.iter().enumerate() {
        let color = BAR_PALETTE[g % BAR_PALETTE.len()];
        for (j, &v) in values.iter().enumerate() {
            let x0 = j as f64 - 0.4 + bar_w * g as f64;
            let cx = x0 + 0.5 * bar_w;
            if !plottable(v) {
                texts.push(("n/a".to_string(), px(cx, y0), VPos::Bottom, ZERO_RGB));
                continue;
            }
            let (a, b) = (px(x0, v.clamp(y.min, y.max)), px(x0 + bar_w, y0));
            let rect = PixelRect {
                left: a.0.min(b.0),
                right: a.0.max(b.0) - 1,
                top: a.1.min(b.1),
                bottom: a.1.max(b.1),
            };
            occupancy.mark_rect(rect);
            bars.push((j, g, rect));
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x0, v), (x0 + bar_w, y0)],
                    rgb(color).filled(),
                )))
                .map_err(chart_err)?;
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x0, v), (x0 + bar_w, y0)],
                    BLACK.stroke_width(1),
                )))
                .map_err(chart_err)?;
            let label = format.format(v);
            if text_width(&label, value_size) + 2 <= rect.width() {
                let (at, vp) = if v >= 0.0 {
                    ((px(cx, v).0, rect.top - m.px(3.0)), VPos::Bottom)
                } else {
                    ((px(cx, v).0, rect.bottom + m.px(3.0)), VPos::Top)
                };
                let th = (value_size / 1.24) as i32;
                let inside = if v >= 0.0 {
                    at.1 - th > plot.top
                } else {
                    at.1 + th < plot.bottom
                };
                if inside {
                    texts.push((label, at, vp, INK_RGB));
                }
            }
        }
    }
    Ok((bars, texts))
}

/// Where a bar chart's parts go, decided before anything is drawn: the metrics, the figure's
/// height, the number of categories, the title's and the x labels' heights, the legend's
/// entries, the y range (room left above the bars for the legend) and its ticks and label, the
/// left margin and the right one, and the category labels with their common size.
struct Geometry {
    m: Metrics,
    h: i32,
    n: usize,
    title_h: i32,
    x_area: i32,
    legend_entries: Vec<Entry>,
    y: AxisRange,
    yticks: Ticks,
    y_label: (String, f64),
    left: i32,
    right_margin: i32,
    cat_size: f64,
    labels: Vec<String>,
}

/// The [`Geometry`] of `fig`; too low or too narrow a figure is refused.
fn geometry(fig: &BarFigure) -> Result<Geometry, Invalid> {
    let m = Metrics::new(fig.width, fig.height);
    let (w, h) = (fig.width as i32, fig.height as i32);
    let n = fig.categories.len().max(1);
    let title_h = if fig.title.trim().is_empty() {
        m.pad
    } else {
        m.pad + (m.title * 1.3) as i32
    };
    let x_area = 2 * m.tick_len + (m.tick / 1.24 * 1.2) as i32 + m.pad;
    let plot_h = h - title_h - x_area;
    if plot_h < 20 {
        return Err(Invalid::Draw(DrawError::TooLow {
            width: fig.width,
            height: fig.height,
        }));
    }
    // Room for the legend above the bars: its rows and margins as a share of the plotting height.
    let legend_entries = entries(fig, &m);
    let legend_h = if legend_entries.is_empty() {
        0.0
    } else {
        (legend_entries.len() as f64 * m.legend * 1.25 + f64::from(m.px(36.0))) / f64::from(plot_h)
    };
    let y = y_range(fig, if legend_h < 0.5 { legend_h } else { 0.0 });
    let yticks = Ticks::new(
        y,
        ((f64::from(plot_h) / (60.0 * m.s)).round() as usize).clamp(2, 9),
        false,
    );
    let y_label = shrink_to_fit(&fig.y_label, m.label, m.label * 0.7, plot_h);
    let ylabel_col = if y_label.0.is_empty() {
        0
    } else {
        (m.label / 1.24 * 1.25) as i32 + m.px(6.0)
    };
    let left = (m.pad + ylabel_col + yticks.widest(m.tick) + 2 * m.tick_len)
        .min((f64::from(w) * 0.45) as i32);
    let right_margin = m.px(30.0);
    let plot_w = w - left - right_margin;
    if plot_w < 40 {
        return Err(Invalid::Draw(DrawError::TooNarrow {
            width: fig.width,
            height: fig.height,
        }));
    }
    // Category labels: one size for all that fits their slots, shortened where even that
    // does not fit.
    let slot = plot_w / n as i32;
    let widest = fig
        .categories
        .iter()
        .map(|c| text_width(c.trim(), m.tick))
        .max()
        .unwrap_or(0);
    let mut cat_size = m.tick;
    while cat_size > m.tick * 0.7 && f64::from(widest) * cat_size / m.tick > f64::from(slot) * 0.92
    {
        cat_size *= 0.95;
    }
    let labels: Vec<String> = fig
        .categories
        .iter()
        .map(|c| crate::chart::fit_text(c.trim(), cat_size, (f64::from(slot) * 0.92) as i32))
        .collect();
    Ok(Geometry {
        m,
        h,
        n,
        title_h,
        x_area,
        legend_entries,
        y,
        yticks,
        y_label,
        left,
        right_margin,
        cat_size,
        labels,
    })
}

struct Drawn {
    svg: String,
    layout: BarLayout,
}

fn draw(fig: &BarFigure) -> Result<Drawn, Invalid> {
    validate(fig)?;
    render::ensure_font().map_err(Invalid::Draw)?;
    let Geometry {
        m,
        h,
        n,
        title_h,
        x_area,
        legend_entries,
        y,
        yticks,
        y_label,
        left,
        right_margin,
        cat_size,
        labels,
    } = geometry(fig)?;
    let format = ValueFormat::for_values(fig.groups.iter().flat_map(|(_, v)| v.iter()));
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
            .build_cartesian_2d(-0.5..n as f64 - 0.5, y.min..y.max)
            .map_err(chart_err)?;
        let xfmt = |v: &f64| {
            let j = v.round();
            if (v - j).abs() < 1e-9 && j >= 0.0 {
                labels.get(j as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        };
        let yfmt = |v: &f64| yticks.label(*v);
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(n)
            .y_labels(yticks.values.len().max(1))
            .x_label_formatter(&xfmt)
            .y_label_formatter(&yfmt)
            .bold_line_style(rgb(crate::colors::GRID_RGB))
            .light_line_style(TRANSPARENT)
            .axis_style(BLACK)
            .set_all_tick_mark_size(m.tick_len)
            .x_label_style(font(cat_size))
            .y_label_style(font(m.tick))
            .axis_desc_style(font(y_label.1))
            .y_desc(y_label.0.clone())
            .draw()
            .map_err(chart_err)?;
        let plot = plot_rect(&chart);
        let mut occupancy = Occupancy::new(plot, m.px(6.0).max(3));
        let value_size = m.tick * 0.8;
        let (bars, texts) = draw_bars(&mut chart, fig, y, &format, (&mut occupancy, plot), &m)?;
        draw_level_lines(&mut chart, fig, (y, n), &mut occupancy, &m)?;
        for (text, at, vp, color) in texts {
            root.draw(&Text::new(
                text,
                at,
                anchored(value_size, color, HPos::Center, vp),
            ))
            .map_err(chart_err)?;
        }
        if bars.is_empty() {
            no_data(root, plot, &m)?;
        }
        frame(root, plot, INK_RGB)?;
        let legend = place_legend(legend_entries.clone(), plot, &occupancy, &m);
        if let Some(l) = &legend {
            draw_legend(&mut chart, l)?;
        }
        title(root, &fig.title, plot, fig.width, &m)?;
        layout = Some(BarLayout {
            width: fig.width,
            height: fig.height,
            plot,
            legend: legend.map(|l| l.rect),
            y_range: (y.min, y.max),
            bars,
        });
        Ok(())
    })?;
    let layout = layout.ok_or(Invalid::Draw(DrawError::Chart("nothing drawn".into())))?;
    Ok(Drawn { svg, layout })
}

impl Chart for BarFigure {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn svg_document(&self) -> Result<String, Invalid> {
        draw(self).map(|d| d.svg)
    }
}

/// Where the parts of `fig` would be drawn, or `None` if `fig` is invalid
/// (see [`render_bars_png`] for the checks).
pub fn bar_layout(fig: &BarFigure) -> Option<BarLayout> {
    draw(fig).ok().map(|d| d.layout)
}

/// Draws a grouped bar chart and writes it to `path` as an RGB PNG (see
/// [`crate::write_figure`] for the PNG and the SVG).
///
/// Bars start at zero; the y range covers all finite values, zero and the reference line with
/// 5 % padding, and room at the top for the legend (in the emptier upper corner), so that the
/// legend does not cover bars. Errors (each naming `path`): a size outside the accepted
/// bounds, a group without exactly one value per category, a file that cannot be written.
/// Non-finite values are shown as "n/a".
///
/// ```
/// use subfric_plot::{bar_layout, read_rgb, render_bars_png, BarFigure};
///
/// let tests = vec!["dense".to_string(), "loose".to_string(), "cyclic".to_string()];
/// let fig = BarFigure::new("Fit error per test", "RMSE (kPa)", tests)
///     .with_group("base model", vec![4.2, 3.3, f64::NAN])
///     .with_group("with dilatancy", vec![2.9, 3.1, 4.4])
///     .with_reference_line("noise level", 2.5);
/// let path = std::env::temp_dir().join(format!("subfric-bars-doc-{}.png", std::process::id()));
/// render_bars_png(&fig, &path)?;
/// // Five bars (the NaN is shown as "n/a"), each filled with its group's colour.
/// let layout = bar_layout(&fig).expect("a valid chart");
/// assert_eq!(layout.bars.len(), 5);
/// let img = read_rgb(&path)?;
/// let (_, group, r) = layout.bars[0];
/// assert_eq!(group, 0);
/// let mid = ((r.left + r.right) / 2) as u32;
/// assert_eq!(img.pixel(mid, (r.bottom - 2) as u32), Some([31, 119, 180]));
/// # std::fs::remove_file(&path).ok();
/// # Ok::<(), subfric_plot::PlotError>(())
/// ```
pub fn render_bars_png(fig: &BarFigure, path: &Path) -> Result<(), PlotError> {
    render::write_png(fig, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_formatting() {
        assert_eq!(format_value(0.0), "0");
        assert_eq!(format_value(0.01234), "0.0123");
        assert_eq!(format_value(12.345), "12.3");
        assert_eq!(format_value(1234.0), "1234");
        assert_eq!(format_value(-0.5), "\u{2212}0.500");
        let f = ValueFormat::for_values([9.4, 0.7, f64::NAN].iter());
        assert_eq!(f, ValueFormat::Fixed(2));
        assert_eq!(format_value(1.5e-5), "1.50e-5");
    }

    #[test]
    fn ranges_include_zero_and_reference() {
        let f = BarFigure::new("", "", vec!["a".into(), "b".into()])
            .with_group("g", vec![1.0, 2.0])
            .with_reference_line("noise", 3.0);
        let r = y_range(&f, 0.0);
        assert_eq!(r.min, 0.0);
        assert!(r.max > 3.0);
        assert!(y_range(&f, 0.25).max > r.max * 1.3);
        let empty = BarFigure::new("", "", vec![]);
        assert_eq!(y_range(&empty, 0.2), AxisRange { min: 0.0, max: 1.0 });
        let neg = BarFigure::new("", "", vec!["a".into()]).with_group("g", vec![-2.0]);
        let r = y_range(&neg, 0.2);
        assert!(r.min < -2.0 && r.max == 0.0);
    }

    #[test]
    fn bars_stay_inside_and_legend_avoids_them() {
        let cats: Vec<String> = (1..=6).map(|i| format!("test {i}")).collect();
        let f = BarFigure::new("RMSE", "RMSE (kPa)", cats)
            .with_group("base model", vec![5.0, 6.0, 4.0, 7.0, 8.0, 9.0])
            .with_group("with effect", vec![3.0, 4.0, 3.5, 5.0, 5.5, 6.0])
            .with_reference_line("noise level", 2.0);
        let l = bar_layout(&f).unwrap();
        assert_eq!(l.bars.len(), 12);
        let legend = l.legend.unwrap();
        for (_, _, r) in &l.bars {
            assert!(l.plot.contains(r.left, r.top) && l.plot.contains(r.right, r.bottom));
            assert!(!r.intersects(&legend), "bar {r:?} under legend {legend:?}");
        }
    }
}
