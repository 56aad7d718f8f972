//! A zoom drawn inside the main panel of a curve figure: the same series over part of the x
//! range, with a y range that fits them there, in the emptiest corner of the panel, and the
//! zoomed region outlined in the panel. A monotonic test decides its peak and decay in its
//! first few hundredths of the slip, which the full range squeezes into a few pixels.

use crate::canvas::{Canvas, HAlign, VAlign};
use crate::chrome::{dash_pattern, draw_axes, AxisDraw, Metrics};
use crate::colors::{INK_RGB, ZERO_RGB};
use crate::figure::points;
use crate::fonts::{self, CAP_HEIGHT, DESCENT};
use crate::geom::{ClipBox, Mapper, Occupancy, PixelRect, Pt};
use crate::scale::{ticks, AxisRange, Extent, Ticks};
use crate::strokes::{series_strokes, z_order, Stroke};
use crate::{Figure, Inset};

/// Share of the main panel's width and height the inset takes.
const INSET_SHARE: (f64, f64) = (0.44, 0.46);

/// Text of the inset relative to the figure's.
const INSET_TEXT_SCALE: f64 = 0.78;

/// A planned inset.
pub(crate) struct InsetPlan {
    /// Its box, frame included.
    pub(crate) outer: PixelRect,
    inner: PixelRect,
    x: AxisRange,
    y: AxisRange,
    xticks: Ticks,
    yticks: Ticks,
    strokes: Vec<Stroke>,
    markers: Vec<(Pt, f64, [u8; 3])>,
    title: String,
    m: Metrics,
}

/// The inset `inset` of `fig` in the main panel `main` (x range `x`, y range `y`), in the
/// corner with the least ink; `None` when the zoom holds no data or there is no room.
pub(crate) fn plan_inset(
    fig: &Figure,
    inset: &Inset,
    main: &PixelRect,
    x: AxisRange,
    y: AxisRange,
    occupancy: &Occupancy,
    m: &Metrics,
) -> Option<InsetPlan> {
    let (lo, hi) = inset.x_range;
    let (lo, hi) = (lo.min(hi).max(x.min), hi.max(lo).min(x.max));
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return None;
    }
    let mut ey = Extent::default();
    for s in &fig.main.series {
        for (px, py) in points(s) {
            if (lo..=hi).contains(&px) {
                ey.add(py);
            }
        }
    }
    ey.bounds?;
    let yr = ey.padded(false);
    let xr = AxisRange { min: lo, max: hi };
    // Nothing to zoom on: the region is most of the panel already.
    if xr.span() > 0.6 * x.span() && yr.span() > 0.6 * y.span() {
        return None;
    }
    let sm = Metrics::new(
        (f64::from(fig.width) * INSET_TEXT_SCALE) as u32,
        (f64::from(fig.height) * INSET_TEXT_SCALE) as u32,
    );
    let w = (f64::from(main.width()) * INSET_SHARE.0) as i32;
    let h = (f64::from(main.height()) * INSET_SHARE.1) as i32;
    let margin = m.px(12.0) as i32;
    if w < 120 || h < 90 {
        return None;
    }
    let (l, r) = (main.left + margin, main.right - margin - w + 1);
    let (t, b) = (main.top + margin, main.bottom - margin - h + 1);
    let outer = [(r, b), (r, t), (l, b), (l, t)]
        .iter()
        .map(|&(left, top)| PixelRect {
            left,
            top,
            right: left + w - 1,
            bottom: top + h - 1,
        })
        .min_by_key(|c| occupancy.count(*c))?;
    let title = fonts::fit_text(inset.title.trim(), sm.legend, f64::from(w) - 2.0 * sm.pad);
    let yticks = ticks(yr, 4);
    let tick_w = yticks
        .labels
        .iter()
        .map(|t| fonts::text_width(t, sm.tick))
        .fold(0.0, f64::max);
    let text_h = (CAP_HEIGHT + DESCENT) * sm.tick;
    let inner = PixelRect {
        left: outer.left + (sm.pad + tick_w + sm.gap + sm.tick_len).ceil() as i32,
        right: outer.right - sm.px(14.0) as i32,
        top: outer.top + (sm.pad + (CAP_HEIGHT + DESCENT) * sm.legend + sm.px(6.0)) as i32,
        bottom: outer.bottom - (sm.tick_len + sm.gap + text_h + sm.px(6.0)).ceil() as i32,
    };
    if inner.width() < 40 || inner.height() < 30 {
        return None;
    }
    let xticks = fitting_x_ticks(xr, inner.width(), &sm);
    let mapper = Mapper {
        rect: inner,
        x: xr,
        y: yr,
    };
    let mut order: Vec<usize> = (0..fig.main.series.len()).collect();
    order.sort_by_key(|&i| (z_order(fig.main.series[i].style), i));
    let (mut strokes, mut markers) = (Vec::new(), Vec::new());
    for i in order {
        series_strokes(
            &fig.main.series[i],
            &mapper,
            &sm,
            &mut strokes,
            &mut markers,
        );
    }
    Some(InsetPlan {
        outer,
        inner,
        x: xr,
        y: yr,
        xticks,
        yticks,
        strokes,
        markers,
        title,
        m: sm,
    })
}

/// X ticks of the inset: as many as fit without overlapping labels (at most four).
fn fitting_x_ticks(x: AxisRange, width: i32, m: &Metrics) -> Ticks {
    let mut target = 4;
    loop {
        let t = ticks(x, target);
        let widest = t
            .labels
            .iter()
            .map(|l| fonts::text_width(l, m.tick))
            .fold(0.0, f64::max);
        let spacing = if t.values.len() > 1 {
            (t.values[1] - t.values[0]) / x.span() * f64::from(width)
        } else {
            f64::INFINITY
        };
        if widest + m.px(10.0) <= spacing || target <= 2 {
            return t;
        }
        target -= 1;
    }
}

/// Draws the outline of the zoomed region in the main panel (x range `x`, y range `y`, area
/// `main`), then the inset over it.
pub(crate) fn draw_inset(
    c: &mut Canvas,
    p: &InsetPlan,
    x: AxisRange,
    y: AxisRange,
    main: &PixelRect,
    m: &Metrics,
) {
    let mapper = Mapper { rect: *main, x, y };
    let (x0, x1) = (mapper.px(p.x.min), mapper.px(p.x.max));
    let (y0, y1) = (mapper.py(p.y.max), mapper.py(p.y.min));
    let clip = ClipBox::inside(*main, 1.0);
    let dash = Some(dash_pattern(m));
    for (a, b) in [
        ((x0, y0), (x1, y0)),
        ((x1, y0), (x1, y1)),
        ((x1, y1), (x0, y1)),
        ((x0, y1), (x0, y0)),
    ] {
        if let Some((a, b)) = clip.clip_segment(a, b) {
            c.line(a, b, ZERO_RGB, 1.0, dash);
        }
    }
    c.fill(p.outer, [255, 255, 255]);
    c.outline(p.outer, ZERO_RGB);
    for s in &p.strokes {
        let dash = s.dashed.then(|| dash_pattern(&p.m));
        c.polyline(&s.pts, s.color, s.width, dash);
    }
    for &(pt, r, color) in &p.markers {
        c.dot(pt, r, color);
    }
    let axes = AxisDraw {
        rect: p.inner,
        x: Some((p.x, &p.xticks)),
        x_labels: true,
        y: p.y,
        yticks: &p.yticks,
    };
    draw_axes(
        c,
        &axes,
        &p.m,
        u32::try_from(p.outer.right + 1).unwrap_or(0),
    );
    c.text(
        &p.title,
        p.m.legend,
        INK_RGB,
        (
            0.5 * f64::from(p.outer.left + p.outer.right),
            f64::from(p.outer.top) + 0.5 * p.m.pad,
        ),
        HAlign::Center,
        VAlign::Top,
    );
}
