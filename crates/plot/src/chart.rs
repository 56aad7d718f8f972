//! What plotters does not do and every figure kind needs: sizes derived from the image size,
//! axis ranges, tick labels, text that fits, the emptiest corner for a legend, legend swatches,
//! decimation of long records, and a frame around a plotting area.

mod axes;
mod legend;
mod polyline;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::render::{DASH_MARK, FAMILY};
use crate::{DrawError, Invalid, PixelRect};

pub(crate) use axes::{typographic_minus, whole_numbers, AxisRange, Extent, Ticks};
pub(crate) use legend::{draw_legend, place_legend, Entry, Legend, Occupancy, Swatch};
pub(crate) use polyline::{clip_polyline, clip_segment, decimate, distinct_pixels, Pt};

/// The drawing area every figure is drawn on.
pub(crate) type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// A chart of two f64 axes on the SVG backend, as every figure draws.
pub(crate) type Chart2d<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Where plotters draws a data point `(x, y)` of `chart`, in pixels: a mapping of its own
/// (the chart's coordinates copied), for what is placed by hand beside the drawn series —
/// markers, labels, the cells of the legend's occupancy.
pub(crate) fn pixel_mapping(chart: &Chart2d<'_, '_>) -> impl Fn((f64, f64)) -> (f64, f64) {
    let spec = chart.as_coord_spec().clone();
    move |q| {
        let c = spec.translate(&q);
        (f64::from(c.0), f64::from(c.1))
    }
}

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
