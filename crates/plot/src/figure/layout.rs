//! The plan of a figure's panels: their vertical layout, ranges, ticks and legend entries.

use crate::chart::{AxisRange, Entry, Legend, Metrics, Ticks};
use crate::{DrawError, Figure, Invalid, Panel, PixelRect};

use super::series::legend_entry;
use super::FigureLayout;

/// Legend entries of a panel: one per label, leaving out labels listed in `skip`.
pub(super) fn entries(p: &Panel, m: &Metrics, skip: &[Entry]) -> Vec<Entry> {
    let mut out: Vec<Entry> = Vec::new();
    for e in p.series.iter().filter_map(|s| legend_entry(s, m)) {
        let seen = |l: &[Entry]| l.iter().any(|x| x.label == e.label);
        if !seen(skip) && !seen(&out) {
            out.push(e);
        }
    }
    out
}

/// One panel, planned: its place, ranges, ticks, lines and legend.
pub(super) struct PanelPlan<'f> {
    pub(super) panel: &'f Panel,
    /// Top of its area and the area's height (plotting area plus the x labels below it).
    pub(super) top: i32,
    pub(super) height: i32,
    pub(super) plot_h: i32,
    pub(super) x_labels: bool,
    pub(super) y: AxisRange,
    pub(super) yticks: Ticks,
    pub(super) y_label: (String, f64),
    pub(super) entries: Vec<Entry>,
    pub(super) legend: Option<Legend>,
}

/// The vertical layout: where each panel's area starts and how high it is.
pub(super) struct Rows {
    pub(super) title_h: i32,
    /// Height below the lowest plotting area: x tick labels and the x label.
    pub(super) x_area: i32,
    pub(super) heights: Vec<i32>,
    pub(super) gap: i32,
}

pub(super) fn rows(fig: &Figure, m: &Metrics, n: usize) -> Result<Rows, Invalid> {
    let title_h = if fig.title.trim().is_empty() {
        m.pad
    } else {
        m.pad + (m.title * 1.3) as i32
    };
    let mut x_area = 2 * m.tick_len + (m.tick / 1.24 * 1.1) as i32 + m.pad;
    if !fig.x_label.trim().is_empty() {
        x_area += (m.label / 1.24 * 1.3) as i32;
    }
    let gap = m.px(20.0);
    let tick_room = m.tick_len + 1;
    let avail = fig.height as i32 - title_h - x_area - (n as i32 - 1) * (gap + tick_room);
    let shares: &[f64] = match n {
        1 => &[1.0],
        2 if fig.history.is_some() => &[0.72, 0.28],
        2 => &[2.0 / 3.0, 1.0 / 3.0],
        _ => &[0.52, 0.2, 0.28],
    };
    let mut heights: Vec<i32> = shares
        .iter()
        .map(|s| (f64::from(avail) * s).round() as i32)
        .collect();
    let used: i32 = heights.iter().sum();
    heights[n - 1] += avail - used;
    if heights[0] < 20 || heights.iter().skip(1).any(|&h| h < 15) {
        return Err(Invalid::Draw(DrawError::TooLow {
            width: fig.width,
            height: fig.height,
        }));
    }
    Ok(Rows {
        title_h,
        x_area,
        heights,
        gap,
    })
}

/// Where the figure's parts went: its panels' boxes (`rects`, in the order of `plans`), the
/// inset's, the legends', the ranges, and how many points each of the main panel's lines kept.
pub(super) fn layout_of(
    fig: &Figure,
    plans: &[PanelPlan<'_>],
    (rects, inset): (&[PixelRect], Option<PixelRect>),
    x: AxisRange,
    line_points: Vec<usize>,
) -> FigureLayout {
    let residual_at = fig.residual.as_ref().map(|_| plans.len() - 1);
    let history_at = fig.history.as_ref().map(|_| 1);
    FigureLayout {
        width: fig.width,
        height: fig.height,
        main: rects[0],
        residual: residual_at.map(|k| rects[k]),
        history: history_at.map(|k| rects[k]),
        inset,
        main_legend: plans[0].legend.as_ref().map(|l| l.rect),
        residual_legend: residual_at.and_then(|k| plans[k].legend.as_ref().map(|l| l.rect)),
        x_range: (x.min, x.max),
        main_y_range: (plans[0].y.min, plans[0].y.max),
        residual_y_range: residual_at.map(|k| (plans[k].y.min, plans[k].y.max)),
        main_line_points: line_points,
    }
}
