//! The predictive-band overlay: a shaded band between two curves (the 2.5 and 97.5 % of the
//! posterior's model curves) under the measured curve and any other curves, and optionally a
//! panel below with everything drawn relative to a reference curve (the posterior median): a
//! band a fraction of a line width wide on the full curve is seen there at its own scale.
//!
//! The band is drawn as the union of the quadrilaterals between consecutive rows, column of
//! pixels by column of pixels, so that it follows curves that go back and forth (cycles) or
//! straight up (a hold at constant slip).

use std::path::Path;

use crate::canvas::{Canvas, HAlign, VAlign};
use crate::chrome::{
    dash_pattern, draw_axes, draw_grid, draw_legend, draw_y_label, place_legend, place_title,
    x_ticks, AxisDraw, Legend, LegendEntry, Metrics, Swatch,
};
use crate::colors::{style_rgb, INK_RGB, ZERO_RGB};
use crate::fonts::{self, CAP_HEIGHT, DESCENT};
use crate::geom::{decimate, ClipBox, Mapper, Occupancy, PixelRect, Pt};
use crate::scale::{plottable, ticks, AxisRange, Extent, Ticks};
use crate::{check_size, png_io, DrawError, Invalid, PlotError, Series, Style};

/// A band between two curves, with curves drawn over it.
#[derive(Debug, Clone, PartialEq)]
pub struct BandFigure {
    /// Title (may be empty).
    pub title: String,
    /// X axis label, with units.
    pub x_label: String,
    /// Y axis label, with units.
    pub y_label: String,
    /// X of the band's rows.
    pub x: Vec<f64>,
    /// Lower edge of the band per row.
    pub lo: Vec<f64>,
    /// Upper edge of the band per row.
    pub hi: Vec<f64>,
    /// Legend label of the band.
    pub band_label: String,
    /// Curves drawn over the band, in order (measured first).
    pub series: Vec<Series>,
    /// A reference curve (one value per row of the band) and the y label of a panel below that
    /// shows the band and every curve minus it.
    pub difference: Option<(Vec<f64>, String)>,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl BandFigure {
    /// A 1000x750 band figure without curves over it.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
        x: Vec<f64>,
        lo: Vec<f64>,
        hi: Vec<f64>,
        band_label: impl Into<String>,
    ) -> Self {
        BandFigure {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x,
            lo,
            hi,
            band_label: band_label.into(),
            series: Vec::new(),
            difference: None,
            width: 1000,
            height: 750,
        }
    }

    /// The same figure with one more curve over the band.
    pub fn with_series(mut self, s: Series) -> Self {
        self.series.push(s);
        self
    }

    /// The same figure with a panel below showing the band and the curves minus `reference`
    /// (one value per row of the band; curves with other x are left out of that panel).
    pub fn with_difference(mut self, reference: Vec<f64>, y_label: impl Into<String>) -> Self {
        self.difference = Some((reference, y_label.into()));
        self
    }
}

/// Where a [`BandFigure`] is drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct BandLayout {
    /// Plotting area of the main panel.
    pub plot: PixelRect,
    /// Plotting area of the difference panel, if any.
    pub difference: Option<PixelRect>,
    /// Legend box, if any.
    pub legend: Option<PixelRect>,
    /// X range.
    pub x_range: (f64, f64),
    /// Y range of the main panel.
    pub y_range: (f64, f64),
    /// Y range of the difference panel.
    pub difference_y_range: Option<(f64, f64)>,
}

/// Colour of the band: a light red under the red fitted curves.
const BAND_RGB: [u8; 3] = [246, 190, 184];

/// One panel: its band and curves in its own y units.
struct Panel {
    rect: PixelRect,
    y: AxisRange,
    yticks: Ticks,
    y_label: (String, f64),
    lo: Vec<f64>,
    hi: Vec<f64>,
    series: Vec<Series>,
    zero_line: bool,
}

struct Plan {
    m: Metrics,
    x: AxisRange,
    xticks: Ticks,
    title: (String, f64, (f64, f64)),
    x_label: (String, f64),
    main: Panel,
    difference: Option<Panel>,
    legend: Option<Legend>,
}

fn validate(fig: &BandFigure) -> Result<(), Invalid> {
    check_size(fig.width, fig.height)?;
    let reference = fig.difference.as_ref().map(|d| &d.0);
    for (name, v) in [
        ("band lower edge", Some(&fig.lo)),
        ("band upper edge", Some(&fig.hi)),
        ("reference curve", reference),
    ] {
        if let Some(v) = v.filter(|v| v.len() != fig.x.len()) {
            return Err(Invalid::Length {
                label: name.into(),
                x_len: fig.x.len(),
                y_len: v.len(),
            });
        }
    }
    for s in &fig.series {
        if s.x.len() != s.y.len() {
            return Err(Invalid::Length {
                label: s.label.clone(),
                x_len: s.x.len(),
                y_len: s.y.len(),
            });
        }
    }
    Ok(())
}

fn series_points(s: &Series) -> impl Iterator<Item = (f64, f64)> + '_ {
    s.x.iter().zip(&s.y).map(|(a, b)| (*a, *b))
}

fn line_width(style: Style, m: &Metrics) -> f64 {
    match style {
        Style::Measured => m.width(1.2),
        Style::Fitted => m.width(2.2),
        _ => m.width(2.0),
    }
}

/// The difference panel's band and curves: everything minus the reference, row by row.
fn differences(fig: &BandFigure, reference: &[f64]) -> (Vec<f64>, Vec<f64>, Vec<Series>) {
    let minus = |v: &[f64]| -> Vec<f64> { v.iter().zip(reference).map(|(a, b)| a - b).collect() };
    let series = fig
        .series
        .iter()
        .filter(|s| s.x == fig.x)
        .map(|s| Series::new(s.label.clone(), s.x.clone(), minus(&s.y), s.style))
        .collect();
    (minus(&fig.lo), minus(&fig.hi), series)
}

/// Y range of a panel: its band and its curves.
fn y_range(x: &[f64], lo: &[f64], hi: &[f64], series: &[Series], zero: bool) -> AxisRange {
    let mut ye = Extent::default();
    for ((x, lo), hi) in x.iter().zip(lo).zip(hi) {
        if plottable(*x) && plottable(*lo) && plottable(*hi) {
            ye.add(*lo);
            ye.add(*hi);
        }
    }
    for (x, y) in series.iter().flat_map(series_points) {
        if plottable(x) && plottable(y) {
            ye.add(y);
        }
    }
    ye.padded(zero)
}

fn plan(fig: &BandFigure) -> Result<Plan, Invalid> {
    validate(fig)?;
    fonts::ensure_fonts().map_err(Invalid::Draw)?;
    let m = Metrics::new(fig.width, fig.height);
    let mut xe = Extent::default();
    for v in fig
        .x
        .iter()
        .chain(fig.series.iter().flat_map(|s| s.x.iter()))
    {
        if plottable(*v) {
            xe.add(*v);
        }
    }
    let x = xe.padded(false);
    let title_block = if fig.title.trim().is_empty() {
        0.0
    } else {
        (m.title * 1.5).round()
    };
    let text_h = |size: f64| (CAP_HEIGHT + DESCENT) * size;
    let top = m.pad + title_block + m.px(8.0);
    let mut bottom = m.tick_len + m.gap + text_h(m.tick) + m.pad;
    if !fig.x_label.trim().is_empty() {
        bottom += m.px(10.0) + text_h(m.label);
    }
    let gap = if fig.difference.is_some() {
        m.px(20.0)
    } else {
        0.0
    };
    let avail = (f64::from(fig.height) - top - bottom - gap).floor();
    let main_h = if fig.difference.is_some() {
        (avail * 2.0 / 3.0).round()
    } else {
        avail
    };
    let diff_h = avail - main_h;
    if main_h < 20.0 || (fig.difference.is_some() && diff_h < 15.0) {
        return Err(Invalid::Draw(DrawError::TooLow {
            width: fig.width,
            height: fig.height,
        }));
    }
    let main_y = y_range(&fig.x, &fig.lo, &fig.hi, &fig.series, false);
    let main_ticks = ticks(
        main_y,
        ((main_h / (60.0 * m.s)).round() as usize).clamp(2, 9),
    );
    let diff = fig.difference.as_ref().map(|(reference, label)| {
        let (lo, hi, series) = differences(fig, reference);
        let y = y_range(&fig.x, &lo, &hi, &series, true);
        let t = ticks(y, ((diff_h / (45.0 * m.s)).round() as usize).clamp(2, 5));
        (lo, hi, series, y, t, label.clone())
    });
    let tick_w = main_ticks
        .labels
        .iter()
        .chain(diff.iter().flat_map(|d| d.4.labels.iter()))
        .map(|l| fonts::text_width(l, m.tick))
        .fold(0.0, f64::max);
    let left = (m.pad + text_h(m.label) + m.px(10.0) + tick_w + m.gap + m.tick_len)
        .ceil()
        .min(f64::from(fig.width) * 0.45);
    let plot_w = f64::from(fig.width) - left - m.px(30.0);
    if plot_w < 40.0 {
        return Err(Invalid::Draw(DrawError::TooNarrow {
            width: fig.width,
            height: fig.height,
        }));
    }
    let xticks = x_ticks(x, plot_w, &m);
    let rect = PixelRect {
        left: left as i32,
        top: top as i32,
        right: left as i32 + plot_w as i32 - 1,
        bottom: top as i32 + main_h as i32 - 1,
    };
    let y_label = |text: &str, r: PixelRect| {
        fonts::shrink_to_fit(text.trim(), m.label, m.label * 0.7, f64::from(r.height()))
    };
    let main = Panel {
        rect,
        y: main_y,
        yticks: main_ticks,
        y_label: y_label(&fig.y_label, rect),
        lo: fig.lo.clone(),
        hi: fig.hi.clone(),
        series: fig.series.clone(),
        zero_line: false,
    };
    let difference = diff.map(|(lo, hi, series, y, yticks, label)| {
        let r = PixelRect {
            top: rect.bottom + 1 + gap as i32,
            bottom: rect.bottom + gap as i32 + diff_h as i32,
            ..rect
        };
        Panel {
            rect: r,
            y,
            yticks,
            y_label: y_label(&label, r),
            lo,
            hi,
            series,
            zero_line: true,
        }
    });
    let legend = main_legend(fig, &main, x, &m);
    let title = place_title(&fig.title, rect, fig.width, title_block, &m);
    let max_w = f64::from(fig.width) - 2.0 * m.pad;
    let x_label = fonts::shrink_to_fit(fig.x_label.trim(), m.label, m.label * 0.7, max_w);
    Ok(Plan {
        m,
        x,
        xticks,
        title,
        x_label,
        main,
        difference,
        legend,
    })
}

/// The legend of the main panel, in its emptiest corner.
fn main_legend(fig: &BandFigure, p: &Panel, x: AxisRange, m: &Metrics) -> Option<Legend> {
    let mapper = Mapper {
        rect: p.rect,
        x,
        y: p.y,
    };
    let mut occupancy = Occupancy::new(p.rect, (12.0 * m.s).round().max(4.0) as i32);
    for edge in [&p.lo, &p.hi] {
        let pts: Vec<Pt> = fig
            .x
            .iter()
            .zip(edge)
            .filter(|(a, b)| plottable(**a) && plottable(**b))
            .map(|(a, b)| (mapper.px(*a), mapper.py(*b)))
            .collect();
        occupancy.mark_polyline(&pts);
    }
    let mut entries = vec![LegendEntry {
        label: fig.band_label.clone(),
        swatch: Swatch::Patch { color: BAND_RGB },
    }];
    for s in &p.series {
        let pts: Vec<Pt> = series_points(s)
            .filter(|(a, b)| plottable(*a) && plottable(*b))
            .map(|(a, b)| (mapper.px(a), mapper.py(b)))
            .collect();
        occupancy.mark_polyline(&pts);
        if !s.label.trim().is_empty() {
            entries.push(LegendEntry {
                label: s.label.clone(),
                swatch: Swatch::Line {
                    color: style_rgb(s.style),
                    width: line_width(s.style, m),
                    dashed: s.style == Style::Published,
                    marker: None,
                },
            });
        }
    }
    place_legend(entries, p.rect, &occupancy, m)
}

/// Where the parts of `fig` would be drawn, or `None` if `fig` is invalid.
pub fn band_layout(fig: &BandFigure) -> Option<BandLayout> {
    let p = plan(fig).ok()?;
    Some(BandLayout {
        plot: p.main.rect,
        difference: p.difference.as_ref().map(|d| d.rect),
        legend: p.legend.as_ref().map(|l| l.rect),
        x_range: (p.x.min, p.x.max),
        y_range: (p.main.y.min, p.main.y.max),
        difference_y_range: p.difference.as_ref().map(|d| (d.y.min, d.y.max)),
    })
}

/// Fills the band between consecutive rows, one pixel column at a time.
fn fill_band(c: &mut Canvas, x: &[f64], p: &Panel, mapper: &Mapper) {
    let r = mapper.rect;
    let clamp_y = |v: f64| {
        v.round()
            .clamp(f64::from(r.top + 1), f64::from(r.bottom - 1)) as i32
    };
    let row = |i: usize| -> Option<(f64, f64, f64)> {
        let (x, lo, hi) = (x[i], p.lo[i], p.hi[i]);
        (plottable(x) && plottable(lo) && plottable(hi))
            .then(|| (mapper.px(x), mapper.py(lo), mapper.py(hi)))
    };
    for i in 1..x.len() {
        let (Some((xa, la, ha)), Some((xb, lb, hb))) = (row(i - 1), row(i)) else {
            continue;
        };
        let (c0, c1) = (xa.min(xb).round() as i32, xa.max(xb).round() as i32);
        for col in c0.max(r.left + 1)..=c1.min(r.right - 1) {
            let (top, bottom) = if (xb - xa).abs() < 1.0 {
                (ha.min(hb).min(la).min(lb), ha.max(hb).max(la).max(lb))
            } else {
                let t = ((f64::from(col) - xa) / (xb - xa)).clamp(0.0, 1.0);
                let lo = la + t * (lb - la);
                let hi = ha + t * (hb - ha);
                (lo.min(hi), lo.max(hi))
            };
            c.fill(
                PixelRect {
                    left: col,
                    right: col,
                    top: clamp_y(top),
                    bottom: clamp_y(bottom),
                },
                BAND_RGB,
            );
        }
    }
}

fn draw_series(c: &mut Canvas, s: &Series, mapper: &Mapper, m: &Metrics) {
    let width = line_width(s.style, m);
    let clip = ClipBox::inside(mapper.rect, width + 1.0);
    let dash = (s.style == Style::Published).then(|| dash_pattern(m));
    let mut run: Vec<Pt> = Vec::new();
    let flush = |run: &mut Vec<Pt>, c: &mut Canvas| {
        for piece in clip.clip_polyline(&decimate(run)) {
            c.polyline(&piece, style_rgb(s.style), width, dash);
        }
        run.clear();
    };
    for (x, y) in series_points(s) {
        if plottable(x) && plottable(y) {
            run.push((mapper.px(x), mapper.py(y)));
        } else {
            flush(&mut run, c);
        }
    }
    flush(&mut run, c);
}

fn draw_panel(c: &mut Canvas, fig: &BandFigure, plan: &Plan, p: &Panel, bottom: bool) {
    let axes = AxisDraw {
        rect: p.rect,
        x: Some((plan.x, &plan.xticks)),
        x_labels: bottom,
        y: p.y,
        yticks: &p.yticks,
    };
    draw_grid(c, &axes);
    let mapper = Mapper {
        rect: p.rect,
        x: plan.x,
        y: p.y,
    };
    fill_band(c, &fig.x, p, &mapper);
    if p.zero_line && p.y.contains(0.0) {
        let y = mapper.py(0.0).round();
        let (l, r) = (f64::from(p.rect.left + 1), f64::from(p.rect.right - 1));
        c.line((l, y), (r, y), ZERO_RGB, 1.0, Some(dash_pattern(&plan.m)));
    }
    for s in &p.series {
        draw_series(c, s, &mapper, &plan.m);
    }
    draw_axes(c, &axes, &plan.m, fig.width);
    draw_y_label(c, &p.y_label.0, p.y_label.1, p.rect, &plan.m);
}

fn draw(fig: &BandFigure, p: &Plan) -> Result<Canvas, DrawError> {
    let mut c = Canvas::new(fig.width, fig.height)?;
    draw_panel(&mut c, fig, p, &p.main, p.difference.is_none());
    if let Some(d) = &p.difference {
        draw_panel(&mut c, fig, p, d, true);
    }
    if let Some(l) = &p.legend {
        draw_legend(&mut c, l, &p.m);
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
    let cx = 0.5 * f64::from(p.main.rect.left + p.main.rect.right);
    c.text(
        &p.x_label.0,
        p.x_label.1,
        INK_RGB,
        (cx, f64::from(fig.height) - p.m.pad),
        HAlign::Center,
        VAlign::Bottom,
    );
    Ok(c)
}

/// Draws `fig` and writes it to `path` as an RGB PNG. Errors (each naming `path`): a size out
/// of bounds, edges, reference or curves whose lengths differ from their x, a file that cannot
/// be written.
pub fn render_band_png(fig: &BandFigure, path: &Path) -> Result<(), PlotError> {
    let p = plan(fig).map_err(|e| e.with_path(path))?;
    let canvas = draw(fig, &p).map_err(|e| Invalid::Draw(e).with_path(path))?;
    png_io::write_rgb_png(path, fig.width, fig.height, &canvas.into_rgb())
}
