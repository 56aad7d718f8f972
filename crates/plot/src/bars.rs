//! Grouped bar charts.

use std::path::Path;

use crate::canvas::{Canvas, HAlign, VAlign};
use crate::chrome::{
    dash_pattern, draw_axes, draw_grid, draw_legend, draw_no_data, draw_y_label, place_legend,
    place_title, tick_px, tick_py, AxisDraw, Legend, LegendEntry, Metrics, Swatch,
};
use crate::colors::{BAR_PALETTE, INK_RGB, ZERO_RGB};
use crate::fonts::{self, CAP_HEIGHT, DESCENT};
use crate::geom::{Occupancy, PixelRect, Pt};
use crate::scale::{plottable, ticks, AxisRange, Extent, Ticks};
use crate::{check_size, png_io, BarFigure, DrawError, Invalid, PlotError};

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

struct CategoryLabel {
    lines: Vec<String>,
    size: f64,
    cx: f64,
}

struct BarPlan {
    width: u32,
    height: u32,
    m: Metrics,
    plot: PixelRect,
    y: AxisRange,
    yticks: Ticks,
    title: String,
    title_size: f64,
    title_center: Pt,
    y_label: String,
    y_label_size: f64,
    categories: Vec<CategoryLabel>,
    bars: Vec<(usize, usize, PixelRect, [u8; 3])>,
    value_labels: Vec<(String, Pt, VAlign)>,
    value_size: f64,
    missing: Vec<Pt>,
    reference: Option<i32>,
    legend: Option<Legend>,
    has_data: bool,
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

/// Number format for bar value labels: three significant digits for the
/// largest magnitude and the same number of decimals for all labels.
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
        let s = match self {
            _ if v == 0.0 => "0".to_string(),
            ValueFormat::Fixed(d) => format!("{v:.d$}"),
            ValueFormat::Scientific => format!("{v:.2e}"),
        };
        crate::scale::typographic_minus(s)
    }
}

/// A single value with three significant digits.
fn format_value(v: f64) -> String {
    ValueFormat::for_values(std::iter::once(&v)).format(v)
}

/// Splits a label into two lines at the space nearest its middle.
fn split_two(text: &str) -> Option<(String, String)> {
    let mid = text.chars().count() / 2;
    let best = text
        .char_indices()
        .filter(|(_, c)| *c == ' ')
        .map(|(i, _)| i)
        .min_by_key(|&i| (text[..i].chars().count() as i64 - mid as i64).abs())?;
    Some((
        text[..best].trim().to_string(),
        text[best..].trim().to_string(),
    ))
}

/// Largest size in `[min_size, size]` (5 % steps) at which all `lines` fit `width`.
fn common_size(lines: &[&str], size: f64, min_size: f64, width: f64) -> f64 {
    let mut s = size;
    while s > min_size && lines.iter().any(|l| fonts::text_width(l, s) > width) {
        s = (s * 0.95).max(min_size);
    }
    s
}

/// Splits category labels into at most `max_lines` lines each and finds one
/// font size for all of them that fits `width` (shortening labels that do
/// not fit even at the smallest size).
fn fit_categories(
    texts: &[String],
    size: f64,
    width: f64,
    max_lines: usize,
) -> (Vec<Vec<String>>, f64) {
    let split: Vec<Vec<String>> = texts
        .iter()
        .map(|t| {
            let t = t.trim();
            if max_lines >= 2 && fonts::text_width(t, size) > width {
                if let Some((a, b)) = split_two(t) {
                    return vec![a, b];
                }
            }
            vec![t.to_string()]
        })
        .collect();
    let all: Vec<&str> = split.iter().flatten().map(String::as_str).collect();
    let s = common_size(&all, size, size * 0.75, width);
    let fitted = split
        .into_iter()
        .map(|lines| lines.iter().map(|l| fonts::fit_text(l, s, width)).collect())
        .collect();
    (fitted, s)
}

fn y_range(fig: &BarFigure, min_hi: f64) -> AxisRange {
    let mut e = Extent::default();
    e.add(0.0);
    for (_, values) in &fig.groups {
        for &v in values {
            e.add(v);
        }
    }
    if let Some((_, r)) = &fig.reference_line {
        e.add(*r);
    }
    let (lo, hi) = e.bounds.unwrap_or((0.0, 0.0));
    let span = hi - lo;
    if !(span > lo.abs().max(hi.abs()) * 1e-12 && span > 0.0) {
        return AxisRange {
            min: 0.0,
            max: 1.0f64.max(min_hi),
        };
    }
    let min = if lo < 0.0 { lo - 0.05 * span } else { 0.0 };
    let max = if hi > 0.0 { hi + 0.05 * span } else { 0.0 };
    AxisRange {
        min,
        max: max.max(min_hi),
    }
}

/// Plotting area and y ticks of a bar chart, and the number of lines
/// (1 or 2) the category labels get.
struct Frame {
    plot: PixelRect,
    yticks: Ticks,
    label_lines: usize,
    title_block: f64,
}

/// Lays out the plotting area: category labels on one line if they fit
/// their slots, else on two.
fn frame(fig: &BarFigure, m: &Metrics, y: AxisRange) -> Result<Frame, Invalid> {
    let (w, h) = (fig.width, fig.height);
    let title_block = if fig.title.trim().is_empty() {
        0.0
    } else {
        (m.title * 1.5).round()
    };
    let top = m.pad + title_block + m.px(8.0);
    let line_h = (CAP_HEIGHT + DESCENT) * m.tick * 1.25;
    let ylabel_col = if fig.y_label.trim().is_empty() {
        0.0
    } else {
        (CAP_HEIGHT + DESCENT) * m.label + m.px(10.0)
    };
    let n = fig.categories.len().max(1) as f64;
    let mut lines = 1;
    loop {
        let bottom = m.tick_len + m.gap + line_h * lines as f64 + m.pad;
        let plot_h = (f64::from(h) - top - bottom).floor();
        if plot_h < 20.0 {
            return Err(Invalid::Draw(DrawError::TooLow {
                width: w,
                height: h,
            }));
        }
        let target = ((plot_h / (60.0 * m.s)).round() as usize).clamp(2, 9);
        let yticks = ticks(y, target);
        let tick_w = yticks
            .labels
            .iter()
            .map(|l| fonts::text_width(l, m.tick))
            .fold(0.0, f64::max);
        let left = (m.pad + ylabel_col + tick_w + m.gap + m.tick_len)
            .ceil()
            .min(f64::from(w) * 0.45);
        let plot_w = f64::from(w) - left - m.px(30.0);
        if plot_w < 40.0 {
            return Err(Invalid::Draw(DrawError::TooNarrow {
                width: w,
                height: h,
            }));
        }
        let slot = plot_w / n;
        let fits = fig
            .categories
            .iter()
            .all(|c| fonts::text_width(c.trim(), m.tick * 0.9) <= slot * 0.9);
        if fits || lines == 2 {
            let plot = PixelRect {
                left: left as i32,
                top: top as i32,
                right: left as i32 + plot_w as i32 - 1,
                bottom: top as i32 + plot_h as i32 - 1,
            };
            return Ok(Frame {
                plot,
                yticks,
                label_lines: lines,
                title_block,
            });
        }
        lines = 2;
    }
}

/// Width of one category's slot along the x axis.
fn slot_width(plot: PixelRect, categories: usize) -> f64 {
    f64::from(plot.right - plot.left) / categories.max(1) as f64
}

/// Category labels under the slots, split and sized to fit them.
fn category_labels(
    fig: &BarFigure,
    plot: PixelRect,
    lines: usize,
    m: &Metrics,
) -> Vec<CategoryLabel> {
    let slot = slot_width(plot, fig.categories.len());
    let (label_lines, size) = fit_categories(&fig.categories, m.tick, slot * 0.9, lines);
    label_lines
        .into_iter()
        .enumerate()
        .map(|(j, lines)| CategoryLabel {
            lines,
            size,
            cx: f64::from(plot.left) + slot * (j as f64 + 0.5),
        })
        .collect()
}

/// Bars, their value labels and "n/a" marks, with the occupancy they leave.
struct Bars {
    bars: Vec<(usize, usize, PixelRect, [u8; 3])>,
    value_labels: Vec<(String, Pt, VAlign)>,
    value_size: f64,
    missing: Vec<Pt>,
}

/// A bar: its value, rectangle and horizontal centre.
struct Bar {
    v: f64,
    rect: PixelRect,
    cx: f64,
}

/// The value label of a bar, centred above it (below it for a negative
/// value), if it fits the bar's width and stays inside the plotting area;
/// also returns the band of pixels it covers.
fn value_label(
    text: String,
    bar: &Bar,
    plot: PixelRect,
    size: f64,
    m: &Metrics,
) -> Option<((String, Pt, VAlign), PixelRect)> {
    let Bar { v, rect: bar, cx } = *bar;
    if fonts::text_width(&text, size) + 2.0 > f64::from(bar.width()) {
        return None;
    }
    let text_h = (CAP_HEIGHT + DESCENT) * size;
    let (at, va, band) = if v >= 0.0 {
        let y = f64::from(bar.top) - m.px(3.0);
        ((cx, y), VAlign::Bottom, (y - text_h, y))
    } else {
        let y = f64::from(bar.bottom) + m.px(3.0);
        ((cx, y), VAlign::Top, (y, y + text_h))
    };
    if band.0 <= f64::from(plot.top) || band.1 >= f64::from(plot.bottom) {
        return None;
    }
    let band = PixelRect {
        top: band.0 as i32,
        bottom: band.1 as i32,
        ..bar
    };
    Some(((text, at, va), band))
}

fn place_bars(
    fig: &BarFigure,
    plot: PixelRect,
    y: AxisRange,
    m: &Metrics,
    occupancy: &mut Occupancy,
) -> Bars {
    let n = fig.categories.len();
    let slot = slot_width(plot, n);
    let bar_w = slot * 0.8 / fig.groups.len().max(1) as f64;
    let y0 = tick_py(y, 0.0_f64.clamp(y.min, y.max), plot);
    let value_size = m.tick * 0.8;
    let format = ValueFormat::for_values(fig.groups.iter().flat_map(|(_, v)| v.iter()));
    let mut out = Bars {
        bars: Vec::new(),
        value_labels: Vec::new(),
        value_size,
        missing: Vec::new(),
    };
    for (gi, (_, values)) in fig.groups.iter().enumerate() {
        let color = BAR_PALETTE[gi % BAR_PALETTE.len()];
        for (j, &v) in values.iter().enumerate().take(n) {
            let x0 = f64::from(plot.left) + slot * j as f64 + 0.1 * slot + bar_w * gi as f64;
            let cx = x0 + 0.5 * bar_w;
            if !plottable(v) {
                out.missing.push((cx, f64::from(y0)));
                continue;
            }
            let (l, r) = (x0.round() as i32, (x0 + bar_w).round() as i32 - 1);
            let yv = tick_py(y, v, plot).clamp(plot.top + 1, plot.bottom - 1);
            let rect = PixelRect {
                left: l.max(plot.left + 1),
                right: r.min(plot.right - 1).max(l),
                top: yv.min(y0),
                bottom: yv.max(y0),
            };
            occupancy.mark_rect(rect);
            out.bars.push((j, gi, rect, color));
            let bar = Bar { v, rect, cx };
            if let Some((label, band)) = value_label(format.format(v), &bar, plot, value_size, m) {
                occupancy.mark_rect(band);
                out.value_labels.push(label);
            }
        }
    }
    out
}

/// Legend entries: one patch per named group, then the reference line.
fn legend_entries(fig: &BarFigure, m: &Metrics) -> Vec<LegendEntry> {
    let mut entries: Vec<LegendEntry> = fig
        .groups
        .iter()
        .enumerate()
        .filter(|(_, (name, _))| !name.trim().is_empty())
        .map(|(gi, (name, _))| LegendEntry {
            label: name.clone(),
            swatch: Swatch::Patch {
                color: BAR_PALETTE[gi % BAR_PALETTE.len()],
            },
        })
        .collect();
    if let Some((label, v)) = &fig.reference_line {
        if !label.trim().is_empty() {
            entries.push(LegendEntry {
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
    }
    entries
}

/// One layout of the chart with the top of the y axis at least `min_hi`.
fn plan_pass(fig: &BarFigure, min_hi: f64) -> Result<BarPlan, Invalid> {
    let m = Metrics::new(fig.width, fig.height);
    let y = y_range(fig, min_hi);
    let frame = frame(fig, &m, y)?;
    let plot = frame.plot;
    let categories = category_labels(fig, plot, frame.label_lines, &m);
    let mut occupancy = Occupancy::new(plot, m.px(6.0).max(3.0) as i32);
    let bars = place_bars(fig, plot, y, &m, &mut occupancy);
    let reference = fig
        .reference_line
        .as_ref()
        .filter(|(_, v)| plottable(*v) && y.contains(*v))
        .map(|(_, v)| tick_py(y, *v, plot));
    if let Some(py) = reference {
        occupancy.mark_polyline(&[
            (f64::from(plot.left), f64::from(py)),
            (f64::from(plot.right), f64::from(py)),
        ]);
    }
    let legend = place_legend(legend_entries(fig, &m), plot, &occupancy, &m);
    let (y_label, y_label_size) = fonts::shrink_to_fit(
        fig.y_label.trim(),
        m.label,
        m.label * 0.7,
        f64::from(plot.height()),
    );
    let (title, title_size, title_center) =
        place_title(&fig.title, plot, fig.width, frame.title_block, &m);
    Ok(BarPlan {
        width: fig.width,
        height: fig.height,
        m,
        plot,
        y,
        yticks: frame.yticks,
        title,
        title_size,
        title_center,
        y_label,
        y_label_size,
        categories,
        has_data: !bars.bars.is_empty(),
        bars: bars.bars,
        value_labels: bars.value_labels,
        value_size: bars.value_size,
        missing: bars.missing,
        reference,
        legend,
    })
}

/// The y maximum needed so that nothing drawn under the legend's columns
/// reaches into the legend box (None if no raise is needed or possible).
fn headroom(fig: &BarFigure, p: &BarPlan) -> Option<f64> {
    let legend = p.legend.as_ref()?;
    let lr = legend.rect;
    let margin = 2.0 * p.value_size;
    let free = f64::from(p.plot.bottom - lr.bottom) - margin;
    let plot_h = f64::from(p.plot.bottom - p.plot.top);
    if free < plot_h * 0.3 {
        return None;
    }
    let n = fig.categories.len().max(1) as f64;
    let slot = f64::from(p.plot.right - p.plot.left) / n;
    let mut vmax = f64::NEG_INFINITY;
    for (_, values) in &fig.groups {
        for (j, &v) in values.iter().enumerate() {
            let (l, r) = (
                f64::from(p.plot.left) + slot * j as f64,
                f64::from(p.plot.left) + slot * (j as f64 + 1.0),
            );
            if plottable(v) && r >= f64::from(lr.left) && l <= f64::from(lr.right) {
                vmax = vmax.max(v);
            }
        }
    }
    if let Some((_, v)) = &fig.reference_line {
        if plottable(*v) {
            vmax = vmax.max(*v);
        }
    }
    if vmax.is_nan() || vmax <= 0.0 {
        return None;
    }
    let need = p.y.min + (vmax - p.y.min) * plot_h / free;
    (need > p.y.max * (1.0 + 1e-9) && need.is_finite()).then_some(need)
}

fn plan(fig: &BarFigure) -> Result<BarPlan, Invalid> {
    validate(fig)?;
    fonts::ensure_fonts().map_err(Invalid::Draw)?;
    let mut p = plan_pass(fig, f64::NEG_INFINITY)?;
    // Raise the top of the axis so that the legend does not cover bars.
    for _ in 0..3 {
        match headroom(fig, &p) {
            Some(hi) => p = plan_pass(fig, hi)?,
            None => break,
        }
    }
    Ok(p)
}

/// Where the parts of `fig` would be drawn, or `None` if `fig` is invalid
/// (see [`render_bars_png`] for the checks).
pub fn bar_layout(fig: &BarFigure) -> Option<BarLayout> {
    let p = plan(fig).ok()?;
    Some(BarLayout {
        width: p.width,
        height: p.height,
        plot: p.plot,
        legend: p.legend.as_ref().map(|l| l.rect),
        y_range: (p.y.min, p.y.max),
        bars: p.bars.iter().map(|&(j, g, r, _)| (j, g, r)).collect(),
    })
}

/// Bars, the zero line, the reference line, value labels and "n/a" marks.
fn draw_bars(c: &mut Canvas, p: &BarPlan) {
    let m = &p.m;
    for &(_, _, r, color) in &p.bars {
        c.fill(r, color);
        c.outline(r, INK_RGB);
    }
    if p.y.min < 0.0 && p.y.max > 0.0 {
        let y0 = tick_py(p.y, 0.0, p.plot);
        c.fill(
            PixelRect {
                top: y0,
                bottom: y0,
                ..p.plot
            },
            INK_RGB,
        );
    }
    if let Some(py) = p.reference {
        c.line(
            (f64::from(p.plot.left + 2), f64::from(py)),
            (f64::from(p.plot.right - 2), f64::from(py)),
            ZERO_RGB,
            m.width(1.5),
            Some(dash_pattern(m)),
        );
    }
    for (text, at, va) in &p.value_labels {
        c.text(text, p.value_size, INK_RGB, *at, HAlign::Center, *va);
    }
    for at in &p.missing {
        let at = (at.0, at.1 - m.px(3.0));
        c.text(
            "n/a",
            p.value_size,
            ZERO_RGB,
            at,
            HAlign::Center,
            VAlign::Bottom,
        );
    }
}

/// A tick under the middle of each category slot and its label below.
fn draw_categories(c: &mut Canvas, p: &BarPlan) {
    let m = &p.m;
    let tl = m.tick_len as i32;
    let x_range = AxisRange {
        min: 0.0,
        max: p.categories.len().max(1) as f64,
    };
    for (j, cat) in p.categories.iter().enumerate() {
        let x = tick_px(x_range, j as f64 + 0.5, p.plot);
        c.fill(
            PixelRect {
                left: x,
                right: x,
                top: p.plot.bottom + 1,
                bottom: p.plot.bottom + tl,
            },
            INK_RGB,
        );
        for (k, line) in cat.lines.iter().enumerate() {
            let y = f64::from(p.plot.bottom + tl)
                + m.gap
                + k as f64 * (CAP_HEIGHT + DESCENT) * cat.size * 1.25;
            c.text(
                line,
                cat.size,
                INK_RGB,
                (cat.cx, y),
                HAlign::Center,
                VAlign::Top,
            );
        }
    }
}

fn draw(p: &BarPlan) -> Result<Canvas, DrawError> {
    let m = &p.m;
    let mut c = Canvas::new(p.width, p.height)?;
    let axes = AxisDraw {
        rect: p.plot,
        x: None,
        x_labels: false,
        y: p.y,
        yticks: &p.yticks,
    };
    draw_grid(&mut c, &axes);
    draw_bars(&mut c, p);
    draw_axes(&mut c, &axes, m, p.width);
    draw_categories(&mut c, p);
    if !p.has_data {
        draw_no_data(&mut c, p.plot, m);
    }
    if let Some(l) = &p.legend {
        draw_legend(&mut c, l, m);
    }
    draw_y_label(&mut c, &p.y_label, p.y_label_size, p.plot, m);
    c.text(
        &p.title,
        p.title_size,
        INK_RGB,
        p.title_center,
        HAlign::Center,
        VAlign::Center,
    );
    Ok(c)
}

/// Draws a grouped bar chart and writes it to `path` as an RGB PNG.
///
/// Bars start at zero; the y range covers all finite values, zero and the
/// reference line with 5 % padding, raised if needed so that the legend
/// (upper right if free, otherwise another free corner) does not cover
/// bars. Errors (each naming `path`): a size outside the accepted bounds, a
/// group without exactly one value per category, a file that cannot be
/// written. Non-finite values are shown as "n/a".
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
    let p = plan(fig).map_err(|e| e.with_path(path))?;
    let canvas = draw(&p).map_err(|e| Invalid::Draw(e).with_path(path))?;
    png_io::write_rgb_png(path, p.width, p.height, &canvas.into_rgb())
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
        assert_eq!(f.format(0.7), "0.70");
        assert_eq!(format_value(1.5e-5), "1.50e-5");
        assert_eq!(
            split_two("dense sand test"),
            Some(("dense".into(), "sand test".into()))
        );
        assert_eq!(split_two("nospace"), None);
    }

    #[test]
    fn ranges_include_zero_and_reference() {
        let f = BarFigure::new("", "", vec!["a".into(), "b".into()])
            .with_group("g", vec![1.0, 2.0])
            .with_reference_line("noise", 3.0);
        let r = y_range(&f, f64::NEG_INFINITY);
        assert_eq!(r.min, 0.0);
        assert!(r.max > 3.0);
        let empty = BarFigure::new("", "", vec![]);
        assert_eq!(
            y_range(&empty, f64::NEG_INFINITY),
            AxisRange { min: 0.0, max: 1.0 }
        );
        let neg = BarFigure::new("", "", vec!["a".into()]).with_group("g", vec![-2.0]);
        let r = y_range(&neg, f64::NEG_INFINITY);
        assert!(r.min < -2.0 && r.max == 0.0);
    }

    #[test]
    fn no_room_for_the_bars_is_a_draw_error() {
        let chart = |w, h| {
            BarFigure::new("t", "y (kPa)", vec!["a".into(), "b".into()])
                .with_group("g", vec![1.0, 2.0])
                .with_size(w, h)
        };
        let m = Metrics::new(200, 150);
        let y = AxisRange { min: 0.0, max: 2.1 };
        assert!(matches!(
            frame(&chart(200, 40), &m, y),
            Err(Invalid::Draw(DrawError::TooLow { height: 40, .. }))
        ));
        assert!(matches!(
            frame(&chart(30, 150), &m, y),
            Err(Invalid::Draw(DrawError::TooNarrow { width: 30, .. }))
        ));
        let smallest = chart(crate::MIN_WIDTH, crate::MIN_HEIGHT);
        assert_eq!(frame(&smallest, &m, y).map(|f| f.label_lines).ok(), Some(1));
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
