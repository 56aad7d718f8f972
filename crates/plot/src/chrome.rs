//! What both figure kinds share: sizes derived from the image size, the
//! title, legends (placed in the emptiest corner) and axes with grid lines,
//! ticks and tick labels.

use crate::canvas::{Canvas, Dash, HAlign, VAlign};
use crate::colors::{self, GRID_RGB, INK_RGB, ZERO_RGB};
use crate::fonts::{self, CAP_HEIGHT};
use crate::geom::{Occupancy, PixelRect, Pt};
use crate::scale::{ticks, AxisRange, Ticks};
use crate::Style;

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

/// What a legend entry shows left of its label.
#[derive(Debug, Clone)]
pub(crate) enum Swatch {
    Line {
        color: [u8; 3],
        width: f64,
        dashed: bool,
        /// Radius and colour of a marker drawn on the line.
        marker: Option<(f64, [u8; 3])>,
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

/// One row of a legend.
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

/// Title text, size and centre: over the plotting area if it fits there,
/// shifted or shrunk (then shortened) to stay inside the image.
pub(crate) fn place_title(
    title: &str,
    plot: PixelRect,
    width: u32,
    title_block: f64,
    m: &Metrics,
) -> (String, f64, Pt) {
    let max_w = f64::from(width) - 2.0 * m.pad;
    let (title, size) = fonts::shrink_to_fit(title.trim(), m.title, m.title * 0.6, max_w);
    let half = 0.5 * fonts::text_width(&title, size);
    let cx = (0.5 * f64::from(plot.left + plot.right))
        .max(m.pad + half)
        .min(f64::from(width) - m.pad - half);
    (title, size, (cx, m.pad + 0.5 * title_block))
}

/// Draws a legend box with its entries.
pub(crate) fn draw_legend(c: &mut Canvas, l: &Legend, m: &Metrics) {
    c.fill(l.rect, [255, 255, 255]);
    c.outline(l.rect, colors::LEGEND_BORDER_RGB);
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
                let dash = dashed.then(|| dash_pattern(m));
                c.line((x0, cy), (x1, cy), *color, *width, dash);
                if let Some((r, mc)) = marker {
                    c.dot((0.5 * (x0 + x1), cy), *r, *mc);
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
                    c.line((a, cy), (b, cy), color, *width, None);
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
                c.fill(r, *color);
                c.outline(r, INK_RGB);
            }
        }
        c.text(
            &e.label,
            l.font,
            INK_RGB,
            (x1 + l.gap, cy),
            HAlign::Left,
            VAlign::Center,
        );
    }
}

/// Dash and gap lengths of dashed lines.
pub(crate) fn dash_pattern(m: &Metrics) -> Dash {
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

pub(crate) fn draw_grid(c: &mut Canvas, a: &AxisDraw<'_>) {
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
            );
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
                );
            }
        }
    }
}

pub(crate) fn draw_axes(c: &mut Canvas, a: &AxisDraw<'_>, m: &Metrics, image_w: u32) {
    let r = a.rect;
    c.outline(r, INK_RGB);
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
        );
        let at = (f64::from(r.left - tl) - m.gap, f64::from(y));
        c.text(label, m.tick, INK_RGB, at, HAlign::Right, VAlign::Center);
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
            );
            if a.x_labels {
                let half = 0.5 * fonts::text_width(label, m.tick);
                let cx = f64::from(x)
                    .max(half + 2.0)
                    .min(f64::from(image_w) - half - 2.0);
                let at = (cx, f64::from(r.bottom + tl) + m.gap);
                c.text(label, m.tick, INK_RGB, at, HAlign::Center, VAlign::Top);
            }
        }
    }
}

/// "no data" in the middle of a plotting area.
pub(crate) fn draw_no_data(c: &mut Canvas, r: PixelRect, m: &Metrics) {
    let center = (
        0.5 * f64::from(r.left + r.right),
        0.5 * f64::from(r.top + r.bottom),
    );
    c.text(
        "no data",
        m.label,
        ZERO_RGB,
        center,
        HAlign::Center,
        VAlign::Center,
    );
}

/// A y axis label reading upwards, at the left edge of the image and
/// centred on the plotting area `r`.
pub(crate) fn draw_y_label(c: &mut Canvas, text: &str, size: f64, r: PixelRect, m: &Metrics) {
    let cx = m.pad + 0.5 * CAP_HEIGHT * size;
    let cy = 0.5 * f64::from(r.top + r.bottom);
    c.text_vertical(text, size, INK_RGB, (cx, cy));
}

/// X ticks: as many as fit `plot_w` pixels without overlapping labels (every figure's x axis).
pub(crate) fn x_ticks(x: AxisRange, plot_w: f64, m: &Metrics) -> Ticks {
    let mut target = ((plot_w / (110.0 * m.s)).round() as usize).clamp(2, 12);
    loop {
        let t = ticks(x, target);
        let widest = t
            .labels
            .iter()
            .map(|l| fonts::text_width(l, m.tick))
            .fold(0.0, f64::max);
        let spacing = match t.values[..] {
            [a, b, ..] => (b - a) / x.span() * plot_w,
            _ => f64::INFINITY,
        };
        if widest + m.px(14.0) <= spacing || target <= 1 {
            return t;
        }
        target -= 1;
    }
}
