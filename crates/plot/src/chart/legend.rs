//! Legends: the occupancy grid that finds a plot's emptiest corner, the legend, its swatches.

use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;

use super::{chart_err, dashed, fit_text, font, plot_rect, rgb, stroke, Metrics, Pt};
use crate::{Invalid, PixelRect};

use plotters_backend::BackendCoord;

/// Coarse grid over a plotting area marking where something is drawn, to find its emptiest
/// corner for a legend.
pub(crate) struct Occupancy {
    rect: PixelRect,
    cell: i32,
    cols: usize,
    rows: usize,
    cells: Vec<bool>,
}

impl Occupancy {
    pub fn new(rect: PixelRect, cell: i32) -> Self {
        let cell = cell.max(1);
        let cols = (rect.width().max(1) / cell + 1) as usize;
        let rows = (rect.height().max(1) / cell + 1) as usize;
        Occupancy {
            rect,
            cell,
            cols,
            rows,
            cells: vec![false; cols * rows],
        }
    }

    pub fn mark_point(&mut self, p: Pt) {
        let c = ((p.0 - f64::from(self.rect.left)) / f64::from(self.cell)).floor();
        let r = ((p.1 - f64::from(self.rect.top)) / f64::from(self.cell)).floor();
        if c >= 0.0 && r >= 0.0 && (c as usize) < self.cols && (r as usize) < self.rows {
            self.cells[r as usize * self.cols + c as usize] = true;
        }
    }

    pub fn mark_polyline(&mut self, pts: &[Pt]) {
        if let Some(&p) = pts.first() {
            self.mark_point(p);
        }
        let step = f64::from(self.cell) * 0.5;
        for w in pts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let n = (((b.0 - a.0).hypot(b.1 - a.1) / step).ceil() as usize).min(10_000);
            for k in 1..=n {
                let t = k as f64 / n as f64;
                self.mark_point((a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t));
            }
        }
    }

    pub fn mark_rect(&mut self, r: PixelRect) {
        let mut y = r.top;
        while y < r.bottom + self.cell {
            let mut x = r.left;
            while x < r.right + self.cell {
                self.mark_point((f64::from(x.min(r.right)), f64::from(y.min(r.bottom))));
                x += self.cell;
            }
            y += self.cell;
        }
    }

    /// Number of marked cells touching the rectangle.
    pub fn count(&self, r: PixelRect) -> usize {
        let c0 = ((r.left - self.rect.left) / self.cell).max(0) as usize;
        let r0 = ((r.top - self.rect.top) / self.cell).max(0) as usize;
        let c1 = (((r.right - self.rect.left) / self.cell).max(0) as usize).min(self.cols - 1);
        let r1 = (((r.bottom - self.rect.top) / self.cell).max(0) as usize).min(self.rows - 1);
        (r0..=r1)
            .flat_map(|row| (c0..=c1).map(move |col| (row, col)))
            .filter(|(row, col)| self.cells[row * self.cols + col])
            .count()
    }

    /// Fraction of the cells touching the rectangle that are marked.
    pub fn fraction(&self, r: PixelRect) -> f64 {
        let cols = (r.right.min(self.rect.right) - r.left.max(self.rect.left)) / self.cell + 1;
        let rows = (r.bottom.min(self.rect.bottom) - r.top.max(self.rect.top)) / self.cell + 1;
        if cols <= 0 || rows <= 0 {
            return 0.0;
        }
        self.count(r) as f64 / f64::from(cols * rows)
    }
}

/// What a legend entry shows left of its label.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Swatch {
    /// A line (dashed or not), with a marker of this radius and colour on it.
    Line {
        color: [u8; 3],
        width: u32,
        dashed: bool,
        marker: Option<(u32, [u8; 3])>,
    },
    /// A line in four colours (a colormap).
    Gradient { colors: [[u8; 3]; 4], width: u32 },
    /// A filled box.
    Patch { color: [u8; 3] },
}

/// One row of a legend.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Entry {
    pub label: String,
    pub swatch: Swatch,
}

/// A placed legend: its box (in image pixels), font, and entries (labels fitted).
#[derive(Debug, Clone)]
pub(crate) struct Legend {
    pub rect: PixelRect,
    pub font: f64,
    pub swatch_w: i32,
    pub margin: i32,
    pub entries: Vec<Entry>,
}

/// The legend of `entries` in the corner of `area` where `occupancy` shows the least ink
/// (upper right preferred, then lower right, upper left, lower left); none when it would hide
/// much of a small plot.
pub(crate) fn place_legend(
    mut entries: Vec<Entry>,
    area: PixelRect,
    occupancy: &Occupancy,
    m: &Metrics,
) -> Option<Legend> {
    if entries.is_empty() {
        return None;
    }
    let font_size = m.legend;
    let swatch_w = m.px(40.0);
    let margin = m.px(8.0);
    let inset = m.px(10.0);
    let text_max = area.width() - 2 * inset - 2 * margin - swatch_w;
    if f64::from(text_max) < font_size * 2.0 {
        return None;
    }
    let row_h = (font_size * 1.25).round() as i32;
    let rows = ((area.height() - 2 * inset - 2 * margin - (font_size / 1.24) as i32) / row_h.max(1)
        + 1)
    .max(0) as usize;
    if area.height() - 2 * inset - 2 * margin < (font_size / 1.24) as i32 {
        return None;
    }
    entries.truncate(rows);
    for e in &mut entries {
        e.label = fit_text(&e.label, font_size, text_max);
    }
    let (text_w, text_h) = text_box(&entries, font_size);
    let (w, h) = (text_w + swatch_w + 2 * margin, text_h + 2 * margin);
    if f64::from(w * h) > 0.4 * f64::from(area.width() * area.height()) {
        return None;
    }
    let (l, r) = (area.left + inset, area.right - inset - w);
    let (t, b) = (area.top + inset, area.bottom - inset - h);
    let pad = m.px(3.0);
    let rect = [(r, t), (r, b), (l, t), (l, b)]
        .into_iter()
        .map(|(x, y)| PixelRect {
            left: x,
            top: y,
            right: x + w,
            bottom: y + h,
        })
        .min_by_key(|c| {
            occupancy.count(PixelRect {
                left: c.left - pad,
                top: c.top - pad,
                right: c.right + pad,
                bottom: c.bottom + pad,
            })
        })?;
    Some(Legend {
        rect,
        font: font_size,
        swatch_w,
        margin,
        entries,
    })
}

/// Width and height of the legend's text as plotters lays it out.
fn text_box(entries: &[Entry], size: f64) -> (i32, i32) {
    let style = font(size);
    let mut t = MultiLineText::<_, &str>::new((0, 0), &style);
    for e in entries {
        t.push_line(e.label.as_str());
    }
    t.estimate_dimension().unwrap_or((0, 0))
}

/// The element plotters draws for a legend swatch: the swatch `w` pixels wide from its anchor
/// (the left middle of its slot).
pub(crate) struct SwatchGlyph {
    swatch: Swatch,
    w: i32,
    at: [BackendCoord; 1],
}

impl SwatchGlyph {
    pub fn new(swatch: Swatch, w: i32, at: BackendCoord) -> Self {
        SwatchGlyph {
            swatch,
            w,
            at: [at],
        }
    }
}

impl<'a> PointCollection<'a, BackendCoord> for &'a SwatchGlyph {
    type Point = &'a BackendCoord;
    type IntoIter = &'a [BackendCoord];
    fn point_iter(self) -> &'a [BackendCoord] {
        &self.at
    }
}

impl<DB: DrawingBackend> Drawable<DB> for SwatchGlyph {
    fn draw<I: Iterator<Item = BackendCoord>>(
        &self,
        mut pos: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> Result<(), plotters_backend::DrawingErrorKind<DB::ErrorType>> {
        let Some((x, y)) = pos.next() else {
            return Ok(());
        };
        let w = self.w;
        match &self.swatch {
            Swatch::Line {
                color,
                width,
                dashed: d,
                marker,
            } => {
                let style = if *d {
                    dashed(*color, *width)
                } else {
                    stroke(*color, *width)
                };
                backend.draw_path(vec![(x, y), (x + w, y)], &style)?;
                if let Some((r, c)) = marker {
                    backend.draw_circle((x + w / 2, y), *r, &rgb(*c).filled(), true)?;
                }
            }
            Swatch::Gradient { colors, width } => {
                for (k, c) in (0..).zip(colors) {
                    let (a, b) = (x + w * k / 4, x + w * (k + 1) / 4);
                    backend.draw_path(vec![(a, y), (b, y)], &stroke(*c, *width))?;
                }
            }
            Swatch::Patch { color } => {
                let h = (w / 5).max(3);
                let (ul, br) = ((x + w / 6, y - h), (x + w - w / 6, y + h));
                backend.draw_rect(ul, br, &rgb(*color).filled(), true)?;
                backend.draw_rect(ul, br, &BLACK.stroke_width(1), false)?;
            }
        }
        Ok(())
    }
}
/// Draws legend `l` on `chart` with plotters' series labels: one labelled series without points
/// per entry, the box at the planned place.
pub(crate) fn draw_legend<'a, 'b: 'a, X, Y>(
    chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>,
    l: &Legend,
) -> Result<(), Invalid>
where
    X: plotters::coord::ranged1d::Ranged,
    Y: plotters::coord::ranged1d::Ranged,
    X::ValueType: 'static,
    Y::ValueType: 'static,
{
    let plot = plot_rect(chart);
    for e in &l.entries {
        let s = e.swatch.clone();
        let w = l.swatch_w - l.margin;
        chart
            .draw_series(std::iter::empty::<Circle<(X::ValueType, Y::ValueType), i32>>())
            .map_err(chart_err)?
            .label(e.label.clone())
            .legend(move |c| SwatchGlyph::new(s.clone(), w, c));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::Coordinate(
            l.rect.left - plot.left,
            l.rect.top - plot.top,
        ))
        .margin(l.margin)
        .legend_area_size(l.swatch_w)
        .label_font(font(l.font))
        .background_style(WHITE.filled())
        .border_style(rgb(crate::colors::LEGEND_BORDER_RGB))
        .draw()
        .map_err(chart_err)
}
