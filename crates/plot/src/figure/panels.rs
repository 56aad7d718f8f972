//! Drawing the planned panels: title, shared-axis meshes, curves, frames and legends.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use crate::chart::{
    anchored, chart_err, dashed, draw_legend, frame, no_data, place_legend, plot_rect, rgb,
    shrink_to_fit, Area, AxisRange, Chart2d, Entry, Metrics, Occupancy, Pt, Ticks,
};
use crate::colors::{self, INK_RGB, ZERO_RGB};
use crate::{Figure, Invalid, PixelRect};

use super::inset::draw_inset;
use super::layout::{layout_of, PanelPlan};
use super::series::{draw_lines, strokes, Line, Marker};
use super::{points, FigureLayout};

/// The title over the plotting area, shifted or shrunk to stay inside the image.
pub(crate) fn title(
    root: &Area<'_>,
    text: &str,
    plot: PixelRect,
    width: u32,
    m: &Metrics,
) -> Result<(), Invalid> {
    if text.trim().is_empty() {
        return Ok(());
    }
    let max_w = width as i32 - 2 * m.pad;
    let (text, size) = shrink_to_fit(text, m.title, m.title * 0.6, max_w);
    let half = crate::chart::text_width(&text, size) / 2;
    let cx = ((plot.left + plot.right) / 2)
        .max(m.pad + half)
        .min(width as i32 - m.pad - half);
    root.draw(&Text::new(
        text,
        (cx, m.pad),
        anchored(size, INK_RGB, HPos::Center, VPos::Top),
    ))
    .map_err(chart_err)
}

/// The grid, ticks and axis labels of one panel of a stack sharing its x axis (the figures'
/// data and residual panels, a band and its difference): the x ticks' labels (`xticks`) and the x
/// axis's label (`x_label`) only on the panel that shows them (`x_labels`: the bottom one), the
/// y ticks and label its own.
pub(crate) fn stacked_panel_mesh(
    chart: &mut Chart2d<'_, '_>,
    (xticks, x_labels, x_label): (&Ticks, bool, &(String, f64)),
    (yticks, y_label): (&Ticks, &(String, f64)),
    m: &Metrics,
) -> Result<(), Invalid> {
    let xfmt = |v: &f64| {
        if x_labels {
            xticks.label(*v)
        } else {
            String::new()
        }
    };
    let yfmt = |v: &f64| yticks.label(*v);
    let mut mesh = chart.configure_mesh();
    mesh.x_labels(xticks.values.len().max(1))
        .y_labels(yticks.values.len().max(1))
        .x_label_formatter(&xfmt)
        .y_label_formatter(&yfmt)
        .bold_line_style(rgb(colors::GRID_RGB))
        .light_line_style(TRANSPARENT)
        .axis_style(BLACK)
        .set_all_tick_mark_size(m.tick_len)
        .label_style(crate::chart::font(m.tick))
        .axis_desc_style(crate::chart::font(y_label.1))
        .y_desc(y_label.0.clone());
    if x_labels && !x_label.0.is_empty() {
        mesh.x_desc(x_label.0.clone());
    }
    mesh.draw().map_err(chart_err)?;
    Ok(())
}

/// What a panel's plotting box `rect` holds once its `lines` and `markers` are drawn (`to_px`:
/// data to pixels): where a legend would cover them.
fn occupancy_of(
    rect: PixelRect,
    (lines, markers): (&[Line], &[Marker]),
    to_px: &dyn Fn(Pt) -> Pt,
    m: &Metrics,
) -> Occupancy {
    let mut occupancy = Occupancy::new(rect, m.px(6.0).max(3));
    for l in lines {
        let px: Vec<Pt> = l.pts.iter().map(|q| to_px(*q)).collect();
        occupancy.mark_polyline(&px);
    }
    for (q, _, _) in markers {
        occupancy.mark_point(to_px(*q));
    }
    occupancy
}

/// Each panel's legend after the first placed in its emptiest corner (kept in `plans`); one that
/// would cover much of a short panel's data joins the main legend. Returns the main legend's
/// entries.
fn place_panel_legends(
    plans: &mut [PanelPlan<'_>],
    rects: &[PixelRect],
    occupancies: &[Occupancy],
    m: &Metrics,
) -> Vec<Entry> {
    let mut main_entries = plans[0].entries.clone();
    for k in 1..plans.len() {
        let l = place_legend(plans[k].entries.clone(), rects[k], &occupancies[k], m);
        if l.as_ref()
            .is_some_and(|l| occupancies[k].fraction(l.rect) > 0.15)
        {
            main_entries.extend(plans[k].entries.iter().cloned());
        } else {
            plans[k].legend = l;
        }
    }
    main_entries
}

#[allow(clippy::too_many_arguments)]
pub(super) fn draw_panels(
    root: &Area<'_>,
    fig: &Figure,
    m: &Metrics,
    x: AxisRange,
    xticks: &Ticks,
    left: i32,
    right_margin: i32,
    plans: &mut [PanelPlan],
) -> Result<FigureLayout, Invalid> {
    let mut rects = Vec::new();
    let mut charts = Vec::new();
    let mut occupancies = Vec::new();
    let mut line_points = Vec::new();
    let x_label = shrink_to_fit(
        &fig.x_label,
        m.label,
        m.label * 0.7,
        fig.width as i32 - 2 * m.pad,
    );
    for p in plans.iter() {
        let area = root
            .clone()
            .shrink((0, p.top), (fig.width, p.height as u32));
        let x_area = p.height - p.plot_h;
        let mut chart = ChartBuilder::on(&area)
            .margin_right(right_margin)
            .margin_left(m.pad)
            .y_label_area_size(left - m.pad)
            .x_label_area_size(x_area)
            .build_cartesian_2d(x.min..x.max, p.y.min..p.y.max)
            .map_err(chart_err)?;
        stacked_panel_mesh(
            &mut chart,
            (xticks, p.x_labels, &x_label),
            (&p.yticks, &p.y_label),
            m,
        )?;
        let rect = plot_rect(&chart);
        let to_px = crate::chart::pixel_mapping(&chart);
        if p.panel.zero_line && p.y.contains(0.0) {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x.min, 0.0), (x.max, 0.0)],
                    dashed(ZERO_RGB, 1),
                )))
                .map_err(chart_err)?;
        }
        let (lines, markers) = strokes(&p.panel.series, x, p.y, &to_px, m);
        let occupancy = occupancy_of(rect, (&lines, &markers), &to_px, m);
        if line_points.is_empty() {
            line_points = lines.iter().map(|l| l.pts.len()).collect();
        }
        draw_lines(&mut chart, lines, markers)?;
        if !p.panel.series.iter().any(|s| points(s).next().is_some()) {
            no_data(root, rect, m)?;
        }
        frame(root, rect, INK_RGB)?;
        rects.push(rect);
        occupancies.push(occupancy);
        charts.push(chart);
    }
    let main_entries = place_panel_legends(plans, &rects, &occupancies, m);
    let inset = match &fig.inset {
        Some(i) => draw_inset(
            root,
            fig,
            i,
            &mut charts[0],
            x,
            plans[0].y,
            &mut occupancies[0],
            m,
        )?,
        None => None,
    };
    plans[0].legend = place_legend(main_entries, rects[0], &occupancies[0], m);
    for (chart, p) in charts.iter_mut().zip(plans.iter()) {
        if let Some(l) = &p.legend {
            draw_legend(chart, l)?;
        }
    }
    Ok(layout_of(fig, plans, (&rects, inset), x, line_points))
}
