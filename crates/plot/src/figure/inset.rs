//! The zoom drawn inside the main panel, and the outline of the region it shows.

use plotters::prelude::*;

use crate::chart::{
    chart_err, dashed, frame, plot_rect, rgb, whole_numbers, Area, AxisRange, Chart2d, Extent,
    Metrics, Occupancy, Ticks,
};
use crate::colors::{self, INK_RGB, ZERO_RGB};
use crate::{Figure, Invalid, PixelRect};

use super::points;
use super::series::{draw_lines, strokes};

/// The region the zoom `inset` shows, `(x, y)`: its slip range within the panel's (`x`), and
/// the range of the main panel's data there (`y` padded); `None` when it holds no data or would
/// show most of the panel (`x`, `y`) anyway.
fn inset_region(
    fig: &Figure,
    inset: &crate::Inset,
    x: AxisRange,
    y: AxisRange,
) -> Option<(AxisRange, AxisRange)> {
    let (lo, hi) = inset.x_range;
    let (lo, hi) = (lo.min(hi).max(x.min), hi.max(lo).min(x.max));
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return None;
    }
    let mut ey = Extent::default();
    for (px, py) in fig.main.series.iter().flat_map(points) {
        if (lo..=hi).contains(&px) {
            ey.add(py);
        }
    }
    // No data in the zoom's slip range: nothing to show.
    ey.bounds?;
    let (zx, zy) = (AxisRange { min: lo, max: hi }, ey.padded(false));
    if zx.span() > 0.6 * x.span() && zy.span() > 0.6 * y.span() {
        return None;
    }
    Some((zx, zy))
}

/// Outlines the zoomed region `(zx, zy)` in the main panel (dashed), each side clipped to the
/// panel's ranges `x`, `y`; a side the clipping moved onto the panel's edge is left out (the
/// frame is there).
fn outline_zoom(
    main: &mut Chart2d<'_, '_>,
    (zx, zy): (AxisRange, AxisRange),
    x: AxisRange,
    y: AxisRange,
) -> Result<(), Invalid> {
    let outline = [
        (zx.min, zy.max),
        (zx.max, zy.max),
        (zx.max, zy.min),
        (zx.min, zy.min),
        (zx.min, zy.max),
    ];
    for w in outline.windows(2) {
        let Some((a, b)) = crate::chart::clip_segment(w[0], w[1], x, y) else {
            continue;
        };
        if (a.1 == b.1) && (a.1 == y.min || a.1 == y.max) {
            continue;
        }
        main.draw_series(std::iter::once(PathElement::new(
            vec![a, b],
            dashed(ZERO_RGB, 1),
        )))
        .map_err(chart_err)?;
    }
    Ok(())
}

/// Share of the main panel's width and height the inset takes.
const INSET_SHARE: (f64, f64) = (0.44, 0.46);

/// Draws the zoom `inset` in the emptiest corner of the main panel, with the zoomed region
/// outlined in the panel; returns its box, or `None` when the zoom holds no data, would show
/// most of the panel anyway, or has no room.
#[allow(clippy::too_many_arguments)]
pub(super) fn draw_inset(
    root: &Area<'_>,
    fig: &Figure,
    inset: &crate::Inset,
    main: &mut Chart2d<'_, '_>,
    x: AxisRange,
    y: AxisRange,
    occupancy: &mut Occupancy,
    m: &Metrics,
) -> Result<Option<PixelRect>, Invalid> {
    let Some((zx, zy)) = inset_region(fig, inset, x, y) else {
        return Ok(None);
    };
    let r = plot_rect(main);
    let (w, h) = (
        (f64::from(r.width()) * INSET_SHARE.0) as i32,
        (f64::from(r.height()) * INSET_SHARE.1) as i32,
    );
    if w < 120 || h < 90 {
        return Ok(None);
    }
    let margin = m.px(12.0);
    let (l, rr) = (r.left + margin, r.right - margin - w);
    let (t, b) = (r.top + margin, r.bottom - margin - h);
    let Some(outer) = [(rr, b), (rr, t), (l, b), (l, t)]
        .into_iter()
        .map(|(left, top)| PixelRect {
            left,
            top,
            right: left + w,
            bottom: top + h,
        })
        .min_by_key(|c| occupancy.count(*c))
    else {
        return Ok(None);
    };
    occupancy.mark_rect(outer);
    outline_zoom(main, (zx, zy), x, y)?;
    let sm = Metrics::new(
        (f64::from(fig.width) * 0.78) as u32,
        (f64::from(fig.height) * 0.78) as u32,
    );
    root.draw(&Rectangle::new(
        [(outer.left, outer.top), (outer.right, outer.bottom)],
        WHITE.filled(),
    ))
    .map_err(chart_err)?;
    frame(root, outer, ZERO_RGB)?;
    let area = root.clone().shrink(
        (outer.left + 1, outer.top + 1),
        ((w - 1) as u32, (h - 1) as u32),
    );
    let yticks = Ticks::new(zy, 4, false);
    let x_area = 2 * sm.tick_len + (sm.tick / 1.24 * 1.2) as i32 + sm.px(4.0);
    let y_area = yticks.widest(sm.tick) + 2 * sm.tick_len + sm.pad / 2;
    let inner_w = w - y_area - sm.px(14.0);
    let integer_x = fig.whole_x || whole_numbers(fig.main.series.iter().flat_map(|s| s.x.iter()));
    let xticks = Ticks::fitting(zx, inner_w, sm.tick, 4, integer_x);
    let title = crate::chart::fit_text(inset.title.trim(), sm.legend, w - 2 * sm.pad);
    let mut chart = ChartBuilder::on(&area)
        .caption(&title, crate::chart::font(sm.legend))
        .margin_right(sm.px(14.0))
        .margin_top(sm.pad / 2)
        .y_label_area_size(y_area)
        .x_label_area_size(x_area)
        .build_cartesian_2d(zx.min..zx.max, zy.min..zy.max)
        .map_err(chart_err)?;
    let xfmt = |v: &f64| xticks.label(*v);
    let yfmt = |v: &f64| yticks.label(*v);
    chart
        .configure_mesh()
        .x_labels(xticks.values.len().max(1))
        .y_labels(yticks.values.len().max(1))
        .x_label_formatter(&xfmt)
        .y_label_formatter(&yfmt)
        .bold_line_style(rgb(colors::GRID_RGB))
        .light_line_style(TRANSPARENT)
        .axis_style(BLACK)
        .set_all_tick_mark_size(sm.tick_len)
        .label_style(crate::chart::font(sm.tick))
        .draw()
        .map_err(chart_err)?;
    let inner = plot_rect(&chart);
    let to_px = crate::chart::pixel_mapping(&chart);
    let (lines, markers) = strokes(&fig.main.series, zx, zy, &to_px, &sm);
    draw_lines(&mut chart, lines, markers)?;
    frame(root, inner, INK_RGB)?;
    Ok(Some(outer))
}
