//! What plotters does not do and every figure kind needs: sizes derived from the image size,
//! axis ranges, tick labels, text that fits, the emptiest corner for a legend, legend swatches,
//! decimation of long records, and a frame around a plotting area.

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::render::{DASH_MARK, FAMILY};
use crate::{DrawError, Invalid, PixelRect};

use plotters_backend::BackendCoord;

/// The drawing area every figure is drawn on.
pub(crate) type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// A chart of two f64 axes on the SVG backend, as every figure draws.
pub(crate) type Chart2d<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Values whose magnitude exceeds this are treated like NaN (skipped), so
/// that ranges and their padding stay finite.
pub const MAX_ABS_VALUE: f64 = 1e300;

/// Whether a value can be drawn.
pub(crate) fn plottable(v: f64) -> bool {
    v.is_finite() && v.abs() <= MAX_ABS_VALUE
}

/// A plotters error as a [`DrawError`].
pub(crate) fn chart_err<E: std::fmt::Display>(e: E) -> Invalid {
    Invalid::Draw(DrawError::Chart(e.to_string()))
}

/// Sizes in pixels derived from the image size (font sizes in plotters' units: the SVG's
/// font size is 1/1.24 of them).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Metrics {
    /// Overall scale: 1 for 1000x750.
    pub s: f64,
    pub title: f64,
    pub label: f64,
    pub tick: f64,
    pub legend: f64,
    pub pad: i32,
    pub tick_len: i32,
}

impl Metrics {
    pub fn new(width: u32, height: u32) -> Self {
        let s = (f64::from(width) / 1000.0)
            .min(f64::from(height) / 750.0)
            .clamp(0.45, 4.0);
        Metrics {
            s,
            title: 27.0 * s,
            label: 22.0 * s,
            tick: 18.5 * s,
            legend: 18.0 * s,
            pad: (12.0 * s).round() as i32,
            tick_len: (5.0 * s).round().max(3.0) as i32,
        }
    }

    pub fn px(&self, v: f64) -> i32 {
        (v * self.s).round() as i32
    }

    /// A line width in whole pixels (plotters' strokes are whole pixels wide).
    pub fn width(&self, v: f64) -> u32 {
        (v * self.s).round().max(1.0) as u32
    }
}

/// An opaque plotters colour.
pub(crate) fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

/// A solid stroke.
pub(crate) fn stroke(c: [u8; 3], width: u32) -> ShapeStyle {
    rgb(c).stroke_width(width)
}

/// A dashed stroke (see [`crate::render::DASH_MARK`]).
pub(crate) fn dashed(c: [u8; 3], width: u32) -> ShapeStyle {
    rgb(c).mix(DASH_MARK).stroke_width(width)
}

/// Black text of `size` with the bundled font.
pub(crate) fn font(size: f64) -> TextStyle<'static> {
    (FAMILY, size.max(1.0)).into_font().color(&BLACK)
}

/// Text of `size` placed by `h` and `v` at the anchor.
pub(crate) fn anchored(size: f64, color: [u8; 3], h: HPos, v: VPos) -> TextStyle<'static> {
    (FAMILY, size.max(1.0))
        .into_font()
        .color(&rgb(color))
        .pos(Pos::new(h, v))
}

/// Width of `text` at `size`, as plotters measures it.
pub(crate) fn text_width(text: &str, size: f64) -> i32 {
    (FAMILY, size.max(1.0))
        .into_font()
        .box_size(text)
        .map_or(0, |(w, _)| w as i32)
}

/// `text` shortened with an ellipsis so that it is at most `max_width` wide.
pub(crate) fn fit_text(text: &str, size: f64, max_width: i32) -> String {
    if text_width(text, size) <= max_width {
        return text.to_string();
    }
    let chars: Vec<char> = text.chars().collect();
    let mut n = chars.len();
    while n > 0 {
        n -= 1;
        let candidate = chars[..n].iter().collect::<String>().trim_end().to_string() + "…";
        if text_width(&candidate, size) <= max_width {
            return candidate;
        }
    }
    String::new()
}

/// The largest size in `[min_size, size]` (5 % steps) at which `text` fits `max_width`, and the
/// text (shortened if even `min_size` is too wide).
pub(crate) fn shrink_to_fit(text: &str, size: f64, min_size: f64, max_width: i32) -> (String, f64) {
    let mut s = size;
    while s > min_size && text_width(text, s) > max_width {
        s = (s * 0.95).max(min_size);
    }
    (fit_text(text.trim(), s, max_width), s)
}

/// A closed axis range with `min < max`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AxisRange {
    pub min: f64,
    pub max: f64,
}

impl AxisRange {
    pub fn span(&self) -> f64 {
        self.max - self.min
    }

    pub fn contains(&self, v: f64) -> bool {
        v >= self.min && v <= self.max
    }
}

/// Running minimum and maximum of plottable values.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Extent {
    pub bounds: Option<(f64, f64)>,
}

impl Extent {
    pub fn add(&mut self, v: f64) {
        if !plottable(v) {
            return;
        }
        self.bounds = Some(match self.bounds {
            None => (v, v),
            Some((lo, hi)) => (lo.min(v), hi.max(v)),
        });
    }

    /// The padded axis range: 5 % of the span on each side; an all-equal extent gets ±5 % of
    /// its value (±1 around 0); no data gives 0..1 (−1..1 when zero must be inside).
    pub fn padded(&self, include_zero: bool) -> AxisRange {
        let Some((mut lo, mut hi)) = self.bounds else {
            let min = if include_zero { -1.0 } else { 0.0 };
            return AxisRange { min, max: 1.0 };
        };
        if include_zero {
            lo = lo.min(0.0);
            hi = hi.max(0.0);
        }
        let span = hi - lo;
        let magnitude = lo.abs().max(hi.abs());
        if span <= magnitude * 1e-9 || span <= f64::MIN_POSITIVE {
            let c = 0.5 * (lo + hi);
            let half = if c.abs() > 1e-290 {
                c.abs() * 0.05
            } else {
                1.0
            };
            return AxisRange {
                min: c - half,
                max: c + half,
            };
        }
        let pad = 0.05 * span;
        AxisRange {
            min: lo - pad,
            max: hi + pad,
        }
    }
}

/// Tick values of `range`, at most `max` of them, as plotters' mesh chooses them (steps of 1,
/// 2 or 5 times a power of ten); on an axis of whole numbers (`integer`) no tick falls between
/// two of them.
pub(crate) fn tick_values(range: AxisRange, max: usize, integer: bool) -> Vec<f64> {
    if integer {
        return whole_tick_values(range, max);
    }
    let coord: RangedCoordf64 = (range.min..range.max).into();
    coord.key_points(max.max(1))
}

/// Whole-number ticks within `range`, at most `max` of them (at least one where the range
/// holds a whole number): the smallest step of 1, 2 or 5 times a power of ten that keeps
/// their count within `max`.
fn whole_tick_values(range: AxisRange, max: usize) -> Vec<f64> {
    let max = max.max(1);
    let mut unit = 1.0f64;
    loop {
        for m in [1.0, 2.0, 5.0] {
            let step = m * unit;
            let first = (range.min / step).ceil() * step;
            let count = ((range.max - first) / step).floor() + 1.0;
            if count <= max as f64 || step >= range.span().max(1.0) {
                let n = count.max(0.0) as usize;
                return (0..n).map(|k| first + k as f64 * step).collect();
            }
        }
        unit *= 10.0;
    }
}

/// Labels of tick values: plain decimals, as many as the step needs, or scientific notation
/// for very large or very small magnitudes; a typographic minus sign.
pub(crate) fn tick_labels(values: &[f64]) -> Vec<String> {
    let step = values
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(f64::INFINITY, f64::min);
    let max_abs = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scientific = max_abs >= 1e5 || (max_abs > 0.0 && max_abs < 1e-3);
    let decimals = |scale: f64| -> usize {
        if !(step.is_finite() && step > 0.0) {
            return if scale == 1.0 { 2 } else { 1 };
        }
        let mut d = 0usize;
        while d < 12 {
            let s = step / scale * 10f64.powi(d as i32);
            if (s - s.round()).abs() <= 1e-6 * s.max(1.0) {
                break;
            }
            d += 1;
        }
        d
    };
    values
        .iter()
        .map(|&v| {
            let v = if v.abs() < step * 1e-9 { 0.0 } else { v };
            let s = if v == 0.0 && scientific {
                "0".to_string()
            } else if scientific {
                let e = max_abs.log10().floor();
                let d = decimals(10f64.powf(e));
                format!("{:.d$}e{}", v / 10f64.powf(e), e as i32)
            } else {
                let d = decimals(1.0);
                format!("{v:.d$}")
            };
            typographic_minus(s)
        })
        .collect()
}

/// Uses a typographic minus sign (U+2212) for negative numbers.
pub(crate) fn typographic_minus(s: String) -> String {
    match s.strip_prefix('-') {
        Some(rest) => format!("\u{2212}{rest}"),
        None => s,
    }
}

/// The tick label of `v` among `values` and their `labels` (empty off the ticks).
pub(crate) fn label_of(values: &[f64], labels: &[String], v: f64) -> String {
    values
        .iter()
        .position(|t| (t - v).abs() <= 1e-9 * (t.abs() + v.abs()).max(1e-300))
        .map(|i| labels[i].clone())
        .unwrap_or_default()
}

/// Ticks of an axis: values and labels.
#[derive(Debug, Clone)]
pub(crate) struct Ticks {
    pub values: Vec<f64>,
    pub labels: Vec<String>,
}

impl Ticks {
    /// About `target` ticks: plotters' steps (1, 2 or 5 times a power of ten) can give half
    /// as many as asked for, so the count nearest `target` of those up to `target` + 3 is taken
    /// (the larger one of two as near).
    pub fn new(range: AxisRange, target: usize, integer: bool) -> Self {
        let values = (target..=target + 3)
            .map(|max| tick_values(range, max, integer))
            .min_by_key(|v| ((v.len() as i64 - target as i64).abs(), -(v.len() as i64)))
            .unwrap_or_default();
        let labels = tick_labels(&values);
        Ticks { values, labels }
    }

    pub fn widest(&self, size: f64) -> i32 {
        self.labels
            .iter()
            .map(|l| text_width(l, size))
            .max()
            .unwrap_or(0)
    }

    pub fn label(&self, v: f64) -> String {
        label_of(&self.values, &self.labels, v)
    }

    /// X ticks: as many as fit `width` pixels without overlapping labels.
    pub fn fitting(range: AxisRange, width: i32, size: f64, most: usize, integer: bool) -> Self {
        let mut target = most;
        loop {
            let t = Ticks::new(range, target, integer);
            let spacing = match t.values[..] {
                [a, b, ..] => (b - a) / range.span() * f64::from(width),
                _ => f64::INFINITY,
            };
            if f64::from(t.widest(size)) + 0.7 * size <= spacing || target <= 2 {
                return t;
            }
            target -= 1;
        }
    }
}

/// Whether every finite x of `xs` is a whole number and they span at least one.
pub(crate) fn whole_numbers<'a>(xs: impl Iterator<Item = &'a f64>) -> bool {
    let mut e = Extent::default();
    let mut all = true;
    for &x in xs.filter(|x| plottable(**x)) {
        all &= x.fract() == 0.0;
        e.add(x);
    }
    all && e.bounds.is_some_and(|(a, b)| b - a >= 1.0)
}

/// A point in pixels.
pub(crate) type Pt = (f64, f64);

/// Min/max decimation per pixel column ("M4"): of each run of consecutive points in the same
/// pixel column keeps the first, the lowest, the highest and the last, in their original order.
/// Works for x that goes back and forth (loops) and never loses an extreme, so the line drawn
/// covers the same pixels as the full record.
pub(crate) fn decimate<T: Copy>(pts: &[T], pixel: impl Fn(&T) -> Pt) -> Vec<T> {
    if pts.len() <= 4 {
        return pts.to_vec();
    }
    let mut out = Vec::with_capacity(pts.len().min(8192));
    let mut start = 0usize;
    while start < pts.len() {
        let col = pixel(&pts[start]).0.floor();
        let mut end = start + 1;
        let (mut lo, mut hi) = (start, start);
        let (mut ylo, mut yhi) = (pixel(&pts[start]).1, pixel(&pts[start]).1);
        while end < pts.len() {
            let (x, y) = pixel(&pts[end]);
            if x.floor() != col {
                break;
            }
            if y < ylo {
                (lo, ylo) = (end, y);
            }
            if y > yhi {
                (hi, yhi) = (end, y);
            }
            end += 1;
        }
        let mut keep = [start, lo, hi, end - 1];
        keep.sort_unstable();
        let mut prev = usize::MAX;
        for k in keep {
            if k != prev {
                out.push(pts[k]);
                prev = k;
            }
        }
        start = end;
    }
    out
}

/// `pts` without the points that land on the same whole pixel as the point before them
/// (plotters draws at whole pixels, so the line drawn is the same; the SVG gets shorter).
pub(crate) fn distinct_pixels<T: Copy>(mut pts: Vec<T>, pixel: impl Fn(&T) -> Pt) -> Vec<T> {
    pts.dedup_by(|b, a| pixel(a) == pixel(b));
    pts
}

/// The part of segment a–b inside the box (Liang–Barsky), if any.
pub(crate) fn clip_segment(a: Pt, b: Pt, x: AxisRange, y: AxisRange) -> Option<(Pt, Pt)> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - x.min),
        (dx, x.max - a.0),
        (-dy, a.1 - y.min),
        (dy, y.max - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
            if t0 > t1 {
                return None;
            }
        }
    }
    Some((
        (a.0 + t0 * dx, a.1 + t0 * dy),
        (a.0 + t1 * dx, a.1 + t1 * dy),
    ))
}

/// The runs of a polyline inside the box.
pub(crate) fn clip_polyline(pts: &[Pt], x: AxisRange, y: AxisRange) -> Vec<Vec<Pt>> {
    let inside = |p: &Pt| x.contains(p.0) && y.contains(p.1);
    if pts.iter().all(inside) {
        return vec![pts.to_vec()];
    }
    let mut out: Vec<Vec<Pt>> = Vec::new();
    let mut cur: Vec<Pt> = Vec::new();
    for w in pts.windows(2) {
        match clip_segment(w[0], w[1], x, y) {
            Some((a, b)) => {
                if cur.last() != Some(&a) {
                    if cur.len() > 1 {
                        out.push(std::mem::take(&mut cur));
                    }
                    cur = vec![a];
                }
                cur.push(b);
            }
            None => {
                if cur.len() > 1 {
                    out.push(std::mem::take(&mut cur));
                }
                cur.clear();
            }
        }
    }
    if cur.len() > 1 {
        out.push(cur);
    }
    out
}

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

/// A one-pixel frame around the plotting area `r` (image pixels): its left and bottom sides on
/// the axis lines plotters' mesh draws just outside the area, its top and right sides on the
/// area's edge pixels.
pub(crate) fn frame(root: &Area<'_>, r: PixelRect, color: [u8; 3]) -> Result<(), Invalid> {
    root.draw(&PathElement::new(
        vec![
            (r.left - 1, r.top),
            (r.right, r.top),
            (r.right, r.bottom + 1),
            (r.left - 1, r.bottom + 1),
            (r.left - 1, r.top),
        ],
        stroke(color, 1),
    ))
    .map_err(chart_err)
}

/// The pixel rectangle of a chart's plotting area (edges included).
pub(crate) fn plot_rect<
    X: plotters::coord::ranged1d::Ranged,
    Y: plotters::coord::ranged1d::Ranged,
>(
    chart: &ChartContext<'_, SVGBackend<'_>, Cartesian2d<X, Y>>,
) -> PixelRect {
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    PixelRect {
        left: xs.start,
        top: ys.start,
        right: xs.end - 1,
        bottom: ys.end - 1,
    }
}

/// "no data" in the middle of a plotting area.
pub(crate) fn no_data(root: &Area<'_>, r: PixelRect, m: &Metrics) -> Result<(), Invalid> {
    root.draw(&Text::new(
        "no data",
        ((r.left + r.right) / 2, (r.top + r.bottom) / 2),
        anchored(m.label, crate::colors::ZERO_RGB, HPos::Center, VPos::Center),
    ))
    .map_err(chart_err)
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

#[cfg(test)]
mod tests {
    use super::*;

    fn range(lo: f64, hi: f64) -> AxisRange {
        AxisRange { min: lo, max: hi }
    }

    #[test]
    fn ticks_are_round_and_whole_on_whole_number_axes() {
        crate::render::ensure_font().unwrap();
        let t = Ticks::new(range(-0.5, 10.5), 6, false);
        assert_eq!(t.values, vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        assert_eq!(t.labels, vec!["0", "2", "4", "6", "8", "10"]);
        // Step numbers 1..4 padded: never a tick at 1.5 or 2.5.
        let t = Ticks::new(range(0.85, 4.15), 8, true);
        assert!(t.values.iter().all(|v| v.fract() == 0.0), "{:?}", t.values);
        assert!(t.values.len() >= 2, "{:?}", t.values);
        let t = Ticks::new(range(0.85, 4.15), 8, false);
        assert!(t.values.iter().any(|v| v.fract() != 0.0), "{:?}", t.values);
        let t = Ticks::new(range(-0.13, 0.13), 5, false);
        assert!(t.labels[0].starts_with('\u{2212}'), "{:?}", t.labels);
        // Zero with the decimals of its neighbours, never a negative zero.
        assert!(t.labels.contains(&"0.00".to_string()), "{:?}", t.labels);
        let t = Ticks::new(range(0.0, 2.5e-4), 5, false);
        assert!(
            t.labels.iter().all(|l| l == "0" || l.contains('e')),
            "{:?}",
            t.labels
        );
        let t = Ticks::new(range(0.0, 2e6), 4, false);
        assert!(t.labels.iter().any(|l| l.contains("e6")), "{:?}", t.labels);
        assert!(whole_numbers([1.0, 2.0, 3.0, f64::NAN].iter()));
        assert!(!whole_numbers([1.0, 1.5].iter()));
        assert!(!whole_numbers([3.0, 3.0].iter()));
    }

    #[test]
    fn padded_ranges() {
        let mut e = Extent::default();
        assert_eq!(e.padded(false), range(0.0, 1.0));
        assert_eq!(e.padded(true), range(-1.0, 1.0));
        e.add(f64::NAN);
        e.add(1e308);
        assert_eq!(e.padded(false), range(0.0, 1.0));
        e.add(0.0);
        e.add(10.0);
        assert_eq!(e.padded(false), range(-0.5, 10.5));
        let mut z = Extent::default();
        z.add(0.0);
        assert_eq!(z.padded(false), range(-1.0, 1.0));
    }

    #[test]
    fn decimation_keeps_extremes_and_clipping_keeps_inside() {
        let pts: Vec<Pt> = (0..100_000)
            .map(|i| {
                let y = if i == 54_321 {
                    -500.0
                } else {
                    (i as f64 * 0.37).sin() * 10.0
                };
                (i as f64 / 100.0, y)
            })
            .collect();
        let d = decimate(&pts, |p| *p);
        assert!(d.len() <= 4 * 1000);
        assert!(d.iter().any(|p| p.1 == -500.0));
        assert_eq!((d.first(), d.last()), (pts.first(), pts.last()));
        let (x, y) = (range(0.0, 10.0), range(0.0, 10.0));
        let parts = clip_polyline(
            &[
                (-5.0, 5.0),
                (5.0, 5.0),
                (15.0, 5.0),
                (15.0, 8.0),
                (5.0, 8.0),
            ],
            x,
            y,
        );
        assert_eq!(parts.len(), 2);
        assert!(parts
            .iter()
            .flatten()
            .all(|p| x.contains(p.0) && y.contains(p.1)));
    }
}
