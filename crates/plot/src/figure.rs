//! Curve figures: a main panel, optionally a history and a residual panel below it sharing the
//! x axis, and optionally a zoom inside the main panel; each panel a plotters chart.

mod inset;
mod layout;
mod panels;
mod series;

use std::path::Path;

use plotters::prelude::*;

use crate::chart::{
    chart_err, plottable, shrink_to_fit, whole_numbers, AxisRange, Entry, Extent, Metrics, Ticks,
};
use crate::render::{self, Chart};
use crate::{check_size, DrawError, Figure, Invalid, Panel, PixelRect, PlotError, Series};

use layout::{entries, rows, PanelPlan};
use panels::draw_panels;
pub(crate) use panels::{stacked_panel_mesh, title};
pub(crate) use series::{draw_lines, legend_entry, strokes};

/// Where the parts of a [`Figure`] are drawn, in pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct FigureLayout {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Plotting area of the main panel (frame on its edge pixels); every
    /// curve of the main panel is drawn inside it.
    pub main: PixelRect,
    /// Plotting area of the residual panel, if any.
    pub residual: Option<PixelRect>,
    /// Plotting area of the history panel (between main and residual), if any.
    pub history: Option<PixelRect>,
    /// The zoom drawn inside the main panel, if any: its box (frame included).
    pub inset: Option<PixelRect>,
    /// Legend box of the main panel, if it has one (inside `main`).
    pub main_legend: Option<PixelRect>,
    /// Legend box of the residual panel, if it has one (inside `residual`).
    pub residual_legend: Option<PixelRect>,
    /// Shared x axis range.
    pub x_range: (f64, f64),
    /// Y axis range of the main panel.
    pub main_y_range: (f64, f64),
    /// Y axis range of the residual panel.
    pub residual_y_range: Option<(f64, f64)>,
    /// Points of each drawn line of the main panel after decimation, in drawing order.
    pub main_line_points: Vec<usize>,
}

fn validate(fig: &Figure) -> Result<(), Invalid> {
    check_size(fig.width, fig.height)?;
    for s in panels(fig).flat_map(|p| p.series.iter()) {
        if s.x.len() != s.y.len() {
            return Err(Invalid::Length {
                label: s.label.clone(),
                x_len: s.x.len(),
                y_len: s.y.len(),
            });
        }
        if let Some(c) = s.cycle.as_ref().filter(|c| c.len() != s.x.len()) {
            return Err(Invalid::Cycles {
                label: s.label.clone(),
                points: s.x.len(),
                cycles: c.len(),
            });
        }
    }
    Ok(())
}

fn panels(fig: &Figure) -> impl Iterator<Item = &Panel> {
    std::iter::once(&fig.main)
        .chain(fig.history.as_ref())
        .chain(fig.residual.as_ref())
}

pub(crate) fn points(s: &Series) -> impl Iterator<Item = (f64, f64)> + '_ {
    s.x.iter()
        .zip(&s.y)
        .map(|(&x, &y)| (x, y))
        .filter(|&(x, y)| plottable(x) && plottable(y))
}

/// Shared x range, and the y range of each panel in the order main, history, residual.
fn ranges(fig: &Figure) -> (AxisRange, Vec<AxisRange>) {
    let mut x = Extent::default();
    let ys = panels(fig)
        .map(|p| {
            let mut y = Extent::default();
            for (px, py) in p.series.iter().flat_map(points) {
                x.add(px);
                y.add(py);
            }
            y.padded(p.zero_line)
        })
        .collect();
    (x.padded(false), ys)
}

/// Whether every drawable point (both coordinates finite and within
/// [`crate::MAX_ABS_VALUE`]) lies inside the axis ranges the figure is drawn with.
pub fn series_inside(fig: &Figure) -> bool {
    let (x, ys) = ranges(fig);
    panels(fig).zip(ys).all(|(p, y)| {
        p.series
            .iter()
            .flat_map(points)
            .all(|(a, b)| x.contains(a) && y.contains(b))
    })
}

/// The whole figure planned, and drawn into an SVG document.
struct Drawn {
    svg: String,
    layout: FigureLayout,
}

fn draw(fig: &Figure) -> Result<Drawn, Invalid> {
    validate(fig)?;
    render::ensure_font().map_err(Invalid::Draw)?;
    let m = Metrics::new(fig.width, fig.height);
    let (x, ys) = ranges(fig);
    let list: Vec<&Panel> = panels(fig).collect();
    let n = list.len();
    let rows = rows(fig, &m, n)?;
    let integer_x = fig.whole_x
        || whole_numbers(
            list.iter()
                .flat_map(|p| p.series.iter())
                .flat_map(|s| s.x.iter()),
        );
    // Y ticks per panel, then the column left of the plotting areas that fits them all.
    let yticks: Vec<Ticks> = rows
        .heights
        .iter()
        .zip(&ys)
        .enumerate()
        .map(|(k, (h, y))| {
            let per = if k == 0 { 60.0 } else { 45.0 };
            let most = ((f64::from(*h) / (per * m.s)).round() as usize)
                .clamp(2, if k == 0 { 9 } else { 5 });
            Ticks::new(*y, most, false)
        })
        .collect();
    let tick_w = yticks.iter().map(|t| t.widest(m.tick)).max().unwrap_or(0);
    let has_ylabel = list.iter().any(|p| !p.y_label.trim().is_empty());
    let ylabel_col = if has_ylabel {
        (m.label / 1.24 * 1.25) as i32 + m.px(6.0)
    } else {
        0
    };
    let left =
        (m.pad + ylabel_col + tick_w + 2 * m.tick_len).min((f64::from(fig.width) * 0.45) as i32);
    let right_margin = m.px(30.0);
    let plot_w = fig.width as i32 - left - right_margin;
    if plot_w < 40 {
        return Err(Invalid::Draw(DrawError::TooNarrow {
            width: fig.width,
            height: fig.height,
        }));
    }
    let xticks = Ticks::fitting(
        x,
        plot_w,
        m.tick,
        ((f64::from(plot_w) / (110.0 * m.s)).round() as usize).clamp(2, 12),
        integer_x,
    );
    let mut top = rows.title_h;
    let mut plans: Vec<PanelPlan> = Vec::new();
    let mut skip: Vec<Entry> = Vec::new();
    for (k, ((p, y), yt)) in list.iter().zip(&ys).zip(yticks).enumerate() {
        let last = k + 1 == n;
        let height = rows.heights[k] + if last { rows.x_area } else { m.tick_len + 1 };
        let entries = entries(p, &m, &skip);
        skip.extend(entries.iter().cloned());
        plans.push(PanelPlan {
            panel: p,
            top,
            height,
            plot_h: rows.heights[k],
            x_labels: last,
            y: *y,
            yticks: yt,
            y_label: shrink_to_fit(&p.y_label, m.label, m.label * 0.7, rows.heights[k]),
            entries,
            legend: None,
        });
        top += height + rows.gap;
    }
    let mut svg_layout = None;
    let svg = render::svg_of(fig.width, fig.height, |root| {
        root.fill(&WHITE).map_err(chart_err)?;
        let layout = draw_panels(root, fig, &m, x, &xticks, left, right_margin, &mut plans)?;
        title(root, &fig.title, layout.main, fig.width, &m)?;
        svg_layout = Some(layout);
        Ok(())
    })?;
    let layout = svg_layout.ok_or(Invalid::Draw(DrawError::Chart("nothing drawn".into())))?;
    Ok(Drawn { svg, layout })
}

impl Chart for Figure {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn svg_document(&self) -> Result<String, Invalid> {
        draw(self).map(|d| d.svg)
    }
}

/// Where the parts of `fig` would be drawn, or `None` if `fig` is invalid
/// (see [`render_png`] for the checks).
pub fn figure_layout(fig: &Figure) -> Option<FigureLayout> {
    draw(fig).ok().map(|d| d.layout)
}

/// Draws `fig` and writes it to `path` as an RGB PNG (see [`crate::write_figure`] for the PNG
/// and the SVG).
///
/// Errors (each naming `path`): a size outside
/// [`crate::MIN_WIDTH`]x[`crate::MIN_HEIGHT`]..=[`crate::MAX_SIDE`]; a series whose x, y
/// (and cycle) lengths differ; a file that cannot be written. Series
/// without drawable points are allowed: the figure then shows "no data"
/// or the legend marks them "(no data)".
pub fn render_png(fig: &Figure, path: &Path) -> Result<(), PlotError> {
    render::write_png(fig, path)
}
