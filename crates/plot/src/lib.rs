//! Headless, paper-style figures for subfric, as SVG and PNG.
//!
//! Every figure is a chart of [plotters](https://docs.rs/plotters) (`ChartBuilder`, mesh,
//! series, series labels) drawn on its SVG backend, with text measured in the bundled DejaVu
//! Sans (`assets/`). The SVG document is written as it is, and turned into pixels by
//! [resvg](https://docs.rs/resvg) with that font only (no system fonts: a fresh machine draws
//! the same pixels) and written as an RGB PNG with the `png` crate. The kinds:
//!
//! * [`Figure`]: curve overlays (measured, published and fitted series) in a main panel, with
//!   optional history and residual panels below it sharing the x axis and an optional zoom
//!   inside it. See [`render_png`].
//! * [`BarFigure`]: grouped bar charts with an optional reference line. See
//!   [`render_bars_png`].
//! * [`IntervalFigure`]: points with intervals, an end the data leave open drawn dashed. See
//!   [`render_interval_png`].
//! * [`posterior::CornerFigure`] and [`posterior::BandFigure`]: a posterior sample's corner
//!   plot and predictive band.
//!
//! [`write_figure`] writes any of them as PNG and SVG side by side; the `render_*_png`
//! functions write the PNG only. What plotters does not do is here: the emptiest corner for a
//! legend, decimation of long records (per pixel column, keeping the extremes), markers on the
//! data drawn over the models, cycle colours, tick labels, panels that share an x axis, and
//! text shortened to fit. Non-finite values (and values whose magnitude exceeds
//! [`MAX_ABS_VALUE`]) are skipped; lines are broken at such points. Axis ranges are computed
//! from all remaining data with 5 % padding.
//!
//! [`inspect_png`], [`read_rgb`] and [`figure_layout`] help tests (here and in other crates)
//! check what was drawn. Why the figures are made this way, and what it cost, is recorded in
//! `docs/plot-rasteriser.md`.
//!
//! ```
//! use subfric_plot::{render_png, inspect_png, Figure, Panel, Series, Style};
//!
//! let x: Vec<f64> = (0..100).map(|i| i as f64 * 0.05).collect();
//! let measured: Vec<f64> = x.iter().map(|d| 60.0 * (1.0 - (-d / 0.5).exp())).collect();
//! let fitted: Vec<f64> = x.iter().map(|d| 58.0 * (1.0 - (-d / 0.45).exp())).collect();
//! let residual: Vec<f64> = fitted.iter().zip(&measured).map(|(f, m)| f - m).collect();
//! let fig = Figure::new(
//!     "Interface shear test",
//!     "displacement (mm)",
//!     Panel::new(
//!         "shear stress (kPa)",
//!         vec![
//!             Series::new("measured", x.clone(), measured, Style::Measured),
//!             Series::new("fitted", x.clone(), fitted, Style::Fitted),
//!         ],
//!     ),
//! )
//! .with_residual(Panel::new("residual (kPa)", vec![Series::new("", x, residual, Style::Fitted)]).with_zero_line());
//! let path = std::env::temp_dir().join(format!("subfric-plot-doc-{}.png", std::process::id()));
//! render_png(&fig, &path)?;
//! let check = inspect_png(&path)?;
//! assert_eq!((check.width, check.height), (1000, 750));
//! # std::fs::remove_file(&path).ok();
//! # Ok::<(), subfric_plot::PlotError>(())
//! ```

#![warn(missing_docs)]

mod bars;
mod chart;
mod colors;
mod figure;
mod intervals;
mod png_io;
pub mod posterior;

mod render;

use std::path::PathBuf;

pub use bars::{bar_layout, render_bars_png, BarLayout};
pub use chart::MAX_ABS_VALUE;
pub use colors::{
    cycle_rgb, style_rgb, FITTED_RGB, MEASURED_LINE_RGB, MEASURED_RGB, PUBLISHED_RGB,
};
pub use figure::{figure_layout, render_png, series_inside, FigureLayout};
pub use intervals::{
    interval_layout, render_interval_png, IntervalEnd, IntervalFigure, IntervalLayout,
    IntervalPoint, PointGroup,
};
pub use png_io::{inspect_png, read_rgb, PngCheck, RgbImage};
pub use render::{render_svg, write_figure, Chart, Written};

/// A rectangle of pixels; all four edges are inclusive (the frame of a
/// plotting area is drawn on its edge pixels).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PixelRect {
    /// Leftmost pixel column.
    pub left: i32,
    /// Topmost pixel row.
    pub top: i32,
    /// Rightmost pixel column.
    pub right: i32,
    /// Bottom pixel row.
    pub bottom: i32,
}

impl PixelRect {
    /// Whether pixel (x, y) lies in the rectangle (edges included).
    pub fn contains(&self, x: i32, y: i32) -> bool {
        x >= self.left && x <= self.right && y >= self.top && y <= self.bottom
    }

    /// Number of pixel columns.
    pub fn width(&self) -> i32 {
        self.right - self.left + 1
    }

    /// Number of pixel rows.
    pub fn height(&self) -> i32 {
        self.bottom - self.top + 1
    }

    /// Whether the two rectangles share at least one pixel.
    pub fn intersects(&self, other: &PixelRect) -> bool {
        self.left <= other.right
            && other.left <= self.right
            && self.top <= other.bottom
            && other.top <= self.bottom
    }
}

/// Smallest accepted figure width in pixels.
pub const MIN_WIDTH: u32 = 200;
/// Smallest accepted figure height in pixels.
pub const MIN_HEIGHT: u32 = 150;
/// Largest accepted figure width or height in pixels.
pub const MAX_SIDE: u32 = 8192;

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Style {
    /// Laboratory data, drawn on top of the models: a thin light-grey line through every
    /// point beneath them, and dark markers drawn last — on every point of a short series
    /// (at most 60 finite points), on a sample of points about 11 pixels apart along a
    /// denser one — so that a model curve shows between the markers.
    Measured,
    /// A curve taken from a publication: a dashed blue line, beneath the data's markers.
    Published,
    /// The model fitted by subfric: a solid red line, beneath the data's markers.
    Fitted,
    /// Any other curve: a solid line with the given index into a palette
    /// (orange, green, purple, brown, pink, olive, cyan; wraps around).
    Other(usize),
}

/// One curve of a panel.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label; an empty label keeps the series out of the legend.
    pub label: String,
    /// X values (same length as `y`).
    pub x: Vec<f64>,
    /// Y values (same length as `x`).
    pub y: Vec<f64>,
    /// Line style.
    pub style: Style,
    /// Optional cycle number per point (same length as `x`). When present the
    /// curve is coloured by cycle with a sequential colormap (viridis for
    /// measured and other series, reds for fitted, blues for published) and
    /// the legend says "cycle a..b".
    pub cycle: Option<Vec<u32>>,
}

impl Series {
    /// A series without cycle colouring.
    pub fn new(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>, style: Style) -> Self {
        Self {
            label: label.into(),
            x,
            y,
            style,
            cycle: None,
        }
    }

    /// The same series coloured by the given per-point cycle numbers.
    pub fn with_cycles(mut self, cycle: Vec<u32>) -> Self {
        self.cycle = Some(cycle);
        self
    }
}

/// A set of series sharing one y axis.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Panel {
    /// Y axis label, with units (e.g. "shear stress τ (kPa)").
    pub y_label: String,
    /// Curves, drawn measured first and fitted last; the legend keeps this order.
    pub series: Vec<Series>,
    /// Draw a dashed horizontal line at y = 0 (and make sure 0 is in range).
    pub zero_line: bool,
}

impl Panel {
    /// A panel without a zero line.
    pub fn new(y_label: impl Into<String>, series: Vec<Series>) -> Self {
        Self {
            y_label: y_label.into(),
            series,
            zero_line: false,
        }
    }

    /// The same panel with a dashed line at y = 0.
    pub fn with_zero_line(mut self) -> Self {
        self.zero_line = true;
        self
    }
}

/// A curve figure: a main panel and an optional residual panel below it.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Title drawn above the main panel (may be empty).
    pub title: String,
    /// X axis label, with units (e.g. "displacement (mm)").
    pub x_label: String,
    /// The main panel.
    pub main: Panel,
    /// Optional residual panel, drawn below the main panel with the same x
    /// axis and about a third of the plotting height.
    pub residual: Option<Panel>,
    /// Optional history panel, drawn between the main and the residual panel with the same x
    /// axis: what the test imposed (e.g. the traction of a traction-controlled test).
    pub history: Option<Panel>,
    /// Optional zoom on part of the x range, drawn as an inset inside the main panel.
    pub inset: Option<Inset>,
    /// Image width in pixels ([`MIN_WIDTH`]..=[`MAX_SIDE`]).
    pub width: u32,
    /// Image height in pixels ([`MIN_HEIGHT`]..=[`MAX_SIDE`]).
    pub height: u32,
    /// The x axis counts things (velocity step 1, 2, 3): ticks at whole numbers only, even
    /// where a series is drawn beside them (at 1.15, 2.15 …). Otherwise whole-number ticks
    /// are taken when every x is a whole number.
    pub whole_x: bool,
}

impl Figure {
    /// A 1000x750 figure without residual panel.
    pub fn new(title: impl Into<String>, x_label: impl Into<String>, main: Panel) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            main,
            residual: None,
            history: None,
            inset: None,
            width: 1000,
            height: 750,
            whole_x: false,
        }
    }

    /// The same figure with its x axis counting things: ticks at whole numbers only.
    pub fn with_whole_x(mut self) -> Self {
        self.whole_x = true;
        self
    }

    /// The same figure with a history panel (what the test imposed).
    pub fn with_history(mut self, history: Panel) -> Self {
        self.history = Some(history);
        self
    }

    /// The same figure with a zoom on x in `lo..=hi` of the main panel, drawn as an inset in
    /// its emptiest corner and titled `title`; the zoomed region is outlined in the panel.
    pub fn with_inset(mut self, title: impl Into<String>, lo: f64, hi: f64) -> Self {
        self.inset = Some(Inset {
            title: title.into(),
            x_range: (lo, hi),
        });
        self
    }

    /// The same figure with a residual panel.
    pub fn with_residual(mut self, residual: Panel) -> Self {
        self.residual = Some(residual);
        self
    }

    /// The same figure with another size in pixels.
    pub fn with_size(mut self, width: u32, height: u32) -> Self {
        self.width = width;
        self.height = height;
        self
    }
}

/// A zoom on part of the main panel's x range, drawn inside the panel: the same series over
/// `x_range`, with a y range that fits them there.
#[derive(Debug, Clone, PartialEq)]
pub struct Inset {
    /// Title of the zoom (e.g. "first loading").
    pub title: String,
    /// X range shown.
    pub x_range: (f64, f64),
}

/// A grouped bar chart: one group of bars per category.
#[derive(Debug, Clone, PartialEq)]
pub struct BarFigure {
    /// Title drawn above the chart (may be empty).
    pub title: String,
    /// Y axis label, with units.
    pub y_label: String,
    /// Category names along the x axis.
    pub categories: Vec<String>,
    /// Named groups, each with one value per category (NaN: no bar, "n/a").
    pub groups: Vec<(String, Vec<f64>)>,
    /// Optional labelled horizontal dashed line, e.g. the noise level.
    pub reference_line: Option<(String, f64)>,
    /// Image width in pixels ([`MIN_WIDTH`]..=[`MAX_SIDE`]).
    pub width: u32,
    /// Image height in pixels ([`MIN_HEIGHT`]..=[`MAX_SIDE`]).
    pub height: u32,
}

impl BarFigure {
    /// A 1000x750 bar chart without groups or reference line.
    pub fn new(
        title: impl Into<String>,
        y_label: impl Into<String>,
        categories: Vec<String>,
    ) -> Self {
        Self {
            title: title.into(),
            y_label: y_label.into(),
            categories,
            groups: Vec::new(),
            reference_line: None,
            width: 1000,
            height: 750,
        }
    }

    /// The same chart with one more group of bars.
    pub fn with_group(mut self, name: impl Into<String>, values: Vec<f64>) -> Self {
        self.groups.push((name.into(), values));
        self
    }

    /// The same chart with a labelled horizontal reference line.
    pub fn with_reference_line(mut self, label: impl Into<String>, value: f64) -> Self {
        self.reference_line = Some((label.into(), value));
        self
    }

    /// The same chart with another size in pixels.
    pub fn with_size(mut self, width: u32, height: u32) -> Self {
        self.width = width;
        self.height = height;
        self
    }
}

/// Errors of rendering and inspecting figures; each names the file concerned.
#[derive(thiserror::Error, Debug)]
pub enum PlotError {
    /// The requested image size is outside the accepted bounds.
    #[error(
        "figure {path}: size {width}x{height} is outside {MIN_WIDTH}x{MIN_HEIGHT}..={MAX_SIDE}x{MAX_SIDE}"
    )]
    InvalidSize {
        /// Output path.
        path: PathBuf,
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// A series has different numbers of x and y values.
    #[error("figure {path}: series '{label}' has {x_len} x values but {y_len} y values")]
    LengthMismatch {
        /// Output path.
        path: PathBuf,
        /// Series label.
        label: String,
        /// Number of x values.
        x_len: usize,
        /// Number of y values.
        y_len: usize,
    },
    /// A series' cycle vector does not have one entry per point.
    #[error("figure {path}: series '{label}' has {points} points but {cycles} cycle numbers")]
    CycleLengthMismatch {
        /// Output path.
        path: PathBuf,
        /// Series label.
        label: String,
        /// Number of points.
        points: usize,
        /// Number of cycle numbers.
        cycles: usize,
    },
    /// A bar group does not have one value per category.
    #[error("bar chart {path}: group '{group}' has {values} values for {categories} categories")]
    GroupLengthMismatch {
        /// Output path.
        path: PathBuf,
        /// Group name.
        group: String,
        /// Number of values in the group.
        values: usize,
        /// Number of categories.
        categories: usize,
    },
    /// The figure could not be drawn; see [`DrawError`].
    #[error("figure {path}: drawing failed: {reason}")]
    Draw {
        /// Output path.
        path: PathBuf,
        /// What went wrong.
        reason: DrawError,
    },
    /// The file could not be created, written or read.
    #[error("cannot access {path}: {source}")]
    Io {
        /// File path.
        path: PathBuf,
        /// Underlying error.
        #[source]
        source: std::io::Error,
    },
    /// PNG encoding failed.
    #[error("cannot encode PNG {path}: {message}")]
    Encode {
        /// Output path.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The file is not a PNG image this crate can decode.
    #[error("cannot decode PNG {path}: {message}")]
    Decode {
        /// Input path.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// Why a valid figure could not be drawn (inside [`PlotError::Draw`]).
#[derive(thiserror::Error, Debug, Clone, PartialEq, Eq)]
pub enum DrawError {
    /// The bundled font could not be parsed.
    #[error("the bundled font could not be parsed")]
    Font,
    /// plotters could not draw the chart.
    #[error("the chart could not be drawn: {0}")]
    Chart(String),
    /// The SVG document could not be read back for its pixels.
    #[error("the SVG could not be rasterised: {0}")]
    Svg(String),
    /// No pixel buffer of this size could be made.
    #[error("cannot make a {width}x{height} pixel buffer")]
    Canvas {
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
    /// Title, axis labels and tick labels leave no room for the plotting
    /// area (below about 20 pixels high).
    #[error("{width}x{height} is too low for the labels of this figure")]
    TooLow {
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
    /// The y label and tick labels leave no room for the plotting area
    /// (below about 40 pixels wide).
    #[error("{width}x{height} is too narrow for the labels of this figure")]
    TooNarrow {
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
}

/// Problems found before a path is known; turned into [`PlotError`] later.
#[derive(Debug, Clone, PartialEq)]
#[doc(hidden)]
pub enum Invalid {
    Size(u32, u32),
    Length {
        label: String,
        x_len: usize,
        y_len: usize,
    },
    Cycles {
        label: String,
        points: usize,
        cycles: usize,
    },
    Group {
        group: String,
        values: usize,
        categories: usize,
    },
    Draw(DrawError),
}

impl Invalid {
    /// The error naming `path`.
    pub fn with_path(self, path: &std::path::Path) -> PlotError {
        let path = path.to_path_buf();
        match self {
            Invalid::Size(width, height) => PlotError::InvalidSize {
                path,
                width,
                height,
            },
            Invalid::Length {
                label,
                x_len,
                y_len,
            } => PlotError::LengthMismatch {
                path,
                label,
                x_len,
                y_len,
            },
            Invalid::Cycles {
                label,
                points,
                cycles,
            } => PlotError::CycleLengthMismatch {
                path,
                label,
                points,
                cycles,
            },
            Invalid::Group {
                group,
                values,
                categories,
            } => PlotError::GroupLengthMismatch {
                path,
                group,
                values,
                categories,
            },
            Invalid::Draw(reason) => PlotError::Draw { path, reason },
        }
    }
}

pub(crate) fn check_size(width: u32, height: u32) -> Result<(), Invalid> {
    if (MIN_WIDTH..=MAX_SIDE).contains(&width) && (MIN_HEIGHT..=MAX_SIDE).contains(&height) {
        Ok(())
    } else {
        Err(Invalid::Size(width, height))
    }
}
