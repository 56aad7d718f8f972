//! The predictive-band overlay: a shaded band between two curves (the 2.5 and 97.5 % of the
//! posterior's model curves) under the measured curve and any other curves, and optionally a
//! panel below with everything drawn relative to a reference curve (the posterior median): a
//! band a fraction of a line width wide on the full curve is seen there at its own scale.
//!
//! The band is drawn as one polygon per run of rows along which x moves on in one direction,
//! and as a one-pixel-wide bar where x stands still (a hold at constant slip), so that it
//! follows curves that go back and forth (cycles) or straight up.

use std::path::Path;

use plotters::prelude::*;

use crate::chart::{
    chart_err, dashed, draw_legend, frame, place_legend, plot_rect, plottable, rgb, shrink_to_fit,
    stroke, whole_numbers, AxisRange, Chart2d, Entry, Extent, Metrics, Occupancy, Pt, Swatch,
    Ticks,
};
use crate::colors::{INK_RGB, ZERO_RGB};
use crate::figure::title;
use crate::render::{self, Chart};
use crate::{check_size, DrawError, Invalid, PixelRect, PlotError, Series};

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

/// Colour of the band's edge: a darker shade of the band.
const BAND_EDGE_RGB: [u8; 3] = [222, 120, 108];

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

/// One panel: its band and curves in its own y units.
struct Panel {
    y: AxisRange,
    yticks: Ticks,
    y_label: (String, f64),
    lo: Vec<f64>,
    hi: Vec<f64>,
    series: Vec<Series>,
    zero_line: bool,
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
    for s in series {
        for (x, y) in s.x.iter().zip(&s.y) {
            if plottable(*x) {
                ye.add(*y);
            }
        }
    }
    ye.padded(zero)
}

/// The band as shapes in pixels: one polygon per run of rows along which x moves on in one
/// direction, and a bar over every step where it stands still.
fn band_shapes(
    x: &[f64],
    lo: &[f64],
    hi: &[f64],
    to_px: &dyn Fn((f64, f64)) -> Pt,
) -> Vec<Vec<Pt>> {
    let rows: Vec<Option<(f64, f64, f64)>> = (0..x.len())
        .map(|i| {
            (plottable(x[i]) && plottable(lo[i]) && plottable(hi[i])).then(|| {
                let (px, a) = to_px((x[i], lo[i]));
                (px, a, to_px((x[i], hi[i])).1)
            })
        })
        .collect();
    let mut shapes = Vec::new();
    let mut run: Vec<(f64, f64, f64)> = Vec::new();
    let mut dir = 0.0f64;
    // The row that ends the bar last pushed, while x stands still.
    let mut still: Option<usize> = None;
    // A run's polygon keeps, per pixel column, the highest and the lowest edge of its rows (a
    // long record does not give a polygon of millions of points, and covers the same pixels).
    let flush = |run: &mut Vec<(f64, f64, f64)>, shapes: &mut Vec<Vec<Pt>>| {
        if run.len() > 1 {
            let mut cols: Vec<(f64, f64, f64)> = Vec::new();
            for &(x, a, b) in run.iter() {
                let (top, bottom) = (a.min(b), a.max(b));
                match cols.last_mut() {
                    Some(c) if c.0.floor() == x.floor() => {
                        c.1 = c.1.min(top);
                        c.2 = c.2.max(bottom);
                    }
                    _ => cols.push((x, top, bottom)),
                }
            }
            let mut poly: Vec<Pt> = cols.iter().map(|c| (c.0, c.1)).collect();
            poly.extend(cols.iter().rev().map(|c| (c.0, c.2)));
            shapes.push(poly);
        }
        run.clear();
    };
    for (i, w) in rows.windows(2).enumerate() {
        let (Some(a), Some(b)) = (w[0], w[1]) else {
            flush(&mut run, &mut shapes);
            continue;
        };
        let d = x[i + 1] - x[i];
        if d == 0.0 {
            // x stands still: one bar over everything the rows of the stand cover.
            flush(&mut run, &mut shapes);
            let top = a.1.min(a.2).min(b.1).min(b.2);
            let bottom = a.1.max(a.2).max(b.1).max(b.2);
            let c = a.0.floor();
            match shapes.last_mut() {
                Some(bar) if still == Some(i) => {
                    bar[0].1 = bar[0].1.min(top);
                    bar[1].1 = bar[0].1;
                    bar[2].1 = bar[2].1.max(bottom);
                    bar[3].1 = bar[2].1;
                }
                _ => shapes.push(vec![
                    (c - 1.0, top),
                    (c + 1.0, top),
                    (c + 1.0, bottom),
                    (c - 1.0, bottom),
                ]),
            }
            still = Some(i + 1);
            continue;
        }
        if run.is_empty() || d.signum() != dir {
            flush(&mut run, &mut shapes);
            run.push(a);
            dir = d.signum();
        }
        run.push(b);
    }
    flush(&mut run, &mut shapes);
    shapes
}

/// Where a band figure's parts go, decided before anything is drawn: the metrics, the x range,
/// the title's height, the x label and its area, the main and difference panels' heights, the
/// panels (each with its y range, ticks, label, band and data), the margins and the x ticks.
struct Geometry {
    m: Metrics,
    x: AxisRange,
    title_h: i32,
    x_label: (String, f64),
    x_area: i32,
    main_h: i32,
    diff_h: i32,
    panels: Vec<Panel>,
    left: i32,
    right_margin: i32,
    xticks: Ticks,
}

/// The panels of `fig`: the band itself (`main_h` high), and where a difference is asked, the
/// band and data less the reference below it (`diff_h` high, with a zero line); each with its y
/// range, ticks and label.
fn panels_of(fig: &BandFigure, m: &Metrics, (main_h, diff_h): (i32, i32)) -> Vec<Panel> {
    let main_y = y_range(&fig.x, &fig.lo, &fig.hi, &fig.series, false);
    let mut panels = vec![Panel {
        y: main_y,
        yticks: Ticks::new(
            main_y,
            ((f64::from(main_h) / (60.0 * m.s)).round() as usize).clamp(2, 9),
            false,
        ),
        y_label: shrink_to_fit(&fig.y_label, m.label, m.label * 0.7, main_h),
        lo: fig.lo.clone(),
        hi: fig.hi.clone(),
        series: fig.series.clone(),
        zero_line: false,
    }];
    if let Some((reference, label)) = &fig.difference {
        let (lo, hi, series) = differences(fig, reference);
        let y = y_range(&fig.x, &lo, &hi, &series, true);
        panels.push(Panel {
            y,
            yticks: Ticks::new(
                y,
                ((f64::from(diff_h) / (45.0 * m.s)).round() as usize).clamp(2, 5),
                false,
            ),
            y_label: shrink_to_fit(label, m.label, m.label * 0.7, diff_h),
            lo,
            hi,
            series,
            zero_line: true,
        });
    }
    panels
}

/// The [`Geometry`] of `fig`; too low or too narrow a figure is refused.
fn geometry(fig: &BandFigure) -> Result<Geometry, Invalid> {
    let m = Metrics::new(fig.width, fig.height);
    let (w, h) = (fig.width as i32, fig.height as i32);
    let mut xe = Extent::default();
    for v in fig
        .x
        .iter()
        .chain(fig.series.iter().flat_map(|s| s.x.iter()))
    {
        xe.add(*v);
    }
    let x = xe.padded(false);
    let title_h = if fig.title.trim().is_empty() {
        m.pad
    } else {
        m.pad + (m.title * 1.3) as i32
    };
    let x_label = shrink_to_fit(&fig.x_label, m.label, m.label * 0.7, w - 2 * m.pad);
    let x_area = 2 * m.tick_len
        + (m.tick / 1.24 * 1.1) as i32
        + m.pad
        + if x_label.0.is_empty() {
            0
        } else {
            (m.label / 1.24 * 1.3) as i32
        };
    let gap = if fig.difference.is_some() {
        m.px(20.0) + m.tick_len + 1
    } else {
        0
    };
    let avail = h - title_h - x_area - gap;
    let main_h = if fig.difference.is_some() {
        (f64::from(avail) * 2.0 / 3.0).round() as i32
    } else {
        avail
    };
    let diff_h = avail - main_h;
    if main_h < 20 || (fig.difference.is_some() && diff_h < 15) {
        return Err(Invalid::Draw(DrawError::TooLow {
            width: fig.width,
            height: fig.height,
        }));
    }
    let panels = panels_of(fig, &m, (main_h, diff_h));
    let tick_w = panels
        .iter()
        .map(|p| p.yticks.widest(m.tick))
        .max()
        .unwrap_or(0);
    let left = (m.pad + (m.label / 1.24 * 1.25) as i32 + m.px(6.0) + tick_w + 2 * m.tick_len)
        .min((f64::from(w) * 0.45) as i32);
    let right_margin = m.px(30.0);
    let plot_w = w - left - right_margin;
    if plot_w < 40 {
        return Err(Invalid::Draw(DrawError::TooNarrow {
            width: fig.width,
            height: fig.height,
        }));
    }
    let integer_x = whole_numbers(fig.x.iter());
    let xticks = Ticks::fitting(
        x,
        plot_w,
        m.tick,
        ((f64::from(plot_w) / (110.0 * m.s)).round() as usize).clamp(2, 12),
        integer_x,
    );
    Ok(Geometry {
        m,
        x,
        title_h,
        x_label,
        x_area,
        main_h,
        diff_h,
        panels,
        left,
        right_margin,
        xticks,
    })
}

/// The main panel's legend (the band, then each labelled series) in the emptiest corner of its
/// plotting box `rect` (what the panel holds: `occupancy`); returns its box, if placed.
fn draw_band_legend<'a, 'b: 'a>(
    chart: &mut Chart2d<'a, 'b>,
    fig: &BandFigure,
    (rect, occupancy): (PixelRect, &Occupancy),
    m: &Metrics,
) -> Result<Option<PixelRect>, Invalid> {
    let mut entries = vec![Entry {
        label: fig.band_label.clone(),
        swatch: Swatch::Patch { color: BAND_RGB },
    }];
    entries.extend(
        fig.series
            .iter()
            .filter_map(|s| crate::figure::legend_entry(s, m)),
    );
    let legend = place_legend(entries, rect, occupancy, m);
    if let Some(l) = &legend {
        draw_legend(chart, l)?;
    }
    Ok(legend.map(|l| l.rect))
}

/// A chart's data coordinates to pixels.
type ToPixels<'a> = dyn Fn((f64, f64)) -> (f64, f64) + 'a;

/// The band of panel `p` over `x`, filled and edged a shade darker (a band thinner than a
/// pixel still shows as a line), each shape marked in `occupancy`.
fn draw_band(
    root: &crate::chart::Area<'_>,
    x: &[f64],
    p: &Panel,
    to_px: &ToPixels<'_>,
    occupancy: &mut Occupancy,
) -> Result<(), Invalid> {
    for shape in band_shapes(x, &p.lo, &p.hi, to_px) {
        occupancy.mark_polyline(&shape);
        let pts: Vec<(i32, i32)> = shape
            .iter()
            .map(|q| (q.0.round() as i32, q.1.round() as i32))
            .collect();
        root.draw(&Polygon::new(pts.clone(), rgb(BAND_RGB).filled()))
            .map_err(chart_err)?;
        // An edge a shade darker: a band thinner than a pixel still shows as a line.
        let mut edge = pts;
        if let Some(&first) = edge.first() {
            edge.push(first);
        }
        root.draw(&PathElement::new(edge, stroke(BAND_EDGE_RGB, 1)))
            .map_err(chart_err)?;
    }
    Ok(())
}

/// Panel `p`'s data on `chart` (x range `x`) as in every figure — a light line under the models,
/// its markers over them (drawn last), so that neither the median nor the band hides the
/// record — each marked in `occupancy`.
fn draw_data(
    chart: &mut Chart2d<'_, '_>,
    p: &Panel,
    x: AxisRange,
    (to_px, occupancy): (&ToPixels<'_>, &mut Occupancy),
    m: &Metrics,
) -> Result<(), Invalid> {
    let (lines, markers) = crate::figure::strokes(&p.series, x, p.y, to_px, m);
    for l in &lines {
        occupancy.mark_polyline(&l.pts.iter().map(|q| to_px(*q)).collect::<Vec<_>>());
    }
    for (q, _, _) in &markers {
        occupancy.mark_point(to_px(*q));
    }
    crate::figure::draw_lines(chart, lines, markers)?;
    Ok(())
}

struct Drawn {
    svg: String,
    layout: BandLayout,
}

fn draw(fig: &BandFigure) -> Result<Drawn, Invalid> {
    validate(fig)?;
    render::ensure_font().map_err(Invalid::Draw)?;
    let Geometry {
        m,
        x,
        title_h,
        x_label,
        x_area,
        main_h,
        diff_h,
        panels,
        left,
        right_margin,
        xticks,
    } = geometry(fig)?;
    let mut layout = None;
    let svg = render::svg_of(fig.width, fig.height, |root| {
        root.fill(&WHITE).map_err(chart_err)?;
        let mut rects = Vec::new();
        let mut legend_rect = None;
        let mut top = title_h;
        for (k, p) in panels.iter().enumerate() {
            let last = k + 1 == panels.len();
            let plot_h = if k == 0 { main_h } else { diff_h };
            let height = plot_h + if last { x_area } else { m.tick_len + 1 };
            let area = root.clone().shrink((0, top), (fig.width, height as u32));
            top += height + m.px(20.0);
            let mut chart = ChartBuilder::on(&area)
                .margin_right(right_margin)
                .margin_left(m.pad)
                .y_label_area_size(left - m.pad)
                .x_label_area_size(height - plot_h)
                .build_cartesian_2d(x.min..x.max, p.y.min..p.y.max)
                .map_err(chart_err)?;
            crate::figure::stacked_panel_mesh(
                &mut chart,
                (&xticks, last, &x_label),
                (&p.yticks, &p.y_label),
                &m,
            )?;
            let rect = plot_rect(&chart);
            let to_px = crate::chart::pixel_mapping(&chart);
            let mut occupancy = Occupancy::new(rect, m.px(12.0).max(4));
            draw_band(root, &fig.x, p, &to_px, &mut occupancy)?;
            if p.zero_line && p.y.contains(0.0) {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(x.min, 0.0), (x.max, 0.0)],
                        dashed(ZERO_RGB, 1),
                    )))
                    .map_err(chart_err)?;
            }
            draw_data(&mut chart, p, x, (&to_px, &mut occupancy), &m)?;
            frame(root, rect, INK_RGB)?;
            if k == 0 {
                legend_rect = draw_band_legend(&mut chart, fig, (rect, &occupancy), &m)?;
            }
            rects.push(rect);
        }
        title(root, &fig.title, rects[0], fig.width, &m)?;
        layout = Some(BandLayout {
            plot: rects[0],
            difference: rects.get(1).copied(),
            legend: legend_rect,
            x_range: (x.min, x.max),
            y_range: (panels[0].y.min, panels[0].y.max),
            difference_y_range: panels.get(1).map(|p| (p.y.min, p.y.max)),
        });
        Ok(())
    })?;
    let layout = layout.ok_or(Invalid::Draw(DrawError::Chart("nothing drawn".into())))?;
    Ok(Drawn { svg, layout })
}

impl Chart for BandFigure {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn svg_document(&self) -> Result<String, Invalid> {
        draw(self).map(|d| d.svg)
    }
}

/// Where the parts of `fig` would be drawn, or `None` if `fig` is invalid.
pub fn band_layout(fig: &BandFigure) -> Option<BandLayout> {
    draw(fig).ok().map(|d| d.layout)
}

/// Draws `fig` and writes it to `path` as an RGB PNG (see [`crate::write_figure`] for the PNG
/// and the SVG). Errors (each naming `path`): a size out of bounds, edges, reference or curves
/// whose lengths differ from their x, a file that cannot be written.
pub fn render_band_png(fig: &BandFigure, path: &Path) -> Result<(), PlotError> {
    render::write_png(fig, path)
}
