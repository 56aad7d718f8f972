//! A thin drawing layer over plotters' in-memory bitmap backend: crisp
//! rectangles, anti-aliased lines of any width and anti-aliased text.

use plotters::backend::{BitMapBackend, DrawingBackend, RGBPixel};
use plotters::style::{Color, RGBColor, ShapeStyle};

use crate::fonts::{self, CAP_HEIGHT, DESCENT};
use crate::geom::{PixelRect, Pt};

/// Horizontal text alignment relative to the anchor point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum HAlign {
    Left,
    Center,
    Right,
}

/// Vertical text alignment: `Top` puts the top of capitals at the anchor,
/// `Center` the middle of capitals, `Bottom` the bottom of descenders.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum VAlign {
    Top,
    Center,
    Bottom,
}

pub(crate) fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

fn coord(v: f64) -> i32 {
    if v.is_finite() {
        v.round().clamp(-1e6, 1e6) as i32
    } else {
        -1_000_000
    }
}

/// Drawing target: an RGB buffer wrapped by plotters' bitmap backend.
pub(crate) struct Canvas<'a> {
    backend: BitMapBackend<'a, RGBPixel>,
    width: u32,
    height: u32,
    /// Coverage of the stroke being drawn, per pixel (allocated on first use).
    coverage: Vec<f32>,
    /// Pixels with non-zero coverage in `coverage`.
    touched: Vec<u32>,
}

impl<'a> Canvas<'a> {
    /// A canvas over `buf` (3 bytes per pixel, row-major), which the caller
    /// fills with the background colour.
    pub fn new(buf: &'a mut [u8], width: u32, height: u32) -> Result<Self, String> {
        let backend = BitMapBackend::<RGBPixel>::with_buffer_and_format(buf, (width, height))
            .map_err(|e| e.to_string())?;
        Ok(Canvas {
            backend,
            width,
            height,
            coverage: Vec::new(),
            touched: Vec::new(),
        })
    }

    /// Flushes the backend.
    pub fn finish(mut self) -> Result<(), String> {
        self.backend.present().map_err(|e| e.to_string())
    }

    /// Blends `color` over pixel (x, y) with the given coverage.
    fn blend(&mut self, x: i32, y: i32, color: [u8; 3], coverage: f64) -> Result<(), String> {
        if coverage < 0.02 {
            return Ok(());
        }
        let c = rgb(color).mix(coverage.min(1.0)).to_backend_color();
        self.backend
            .draw_pixel((x, y), c)
            .map_err(|e| e.to_string())
    }

    /// Adds coverage for pixel (x, y) to the current stroke (maximum, not
    /// sum, so that joints and self-overlaps are not darker).
    fn cover(&mut self, x: i32, y: i32, cov: f64) {
        if cov < 0.02 || x < 0 || y < 0 || x >= self.width as i32 || y >= self.height as i32 {
            return;
        }
        let i = y as usize * self.width as usize + x as usize;
        let c = &mut self.coverage[i];
        if *c == 0.0 {
            self.touched.push(i as u32);
        }
        *c = c.max(cov.min(1.0) as f32);
    }

    /// Accumulates a straight segment of `width` pixels (measured across the
    /// line) with anti-aliased edges. Coordinates are pixel centres.
    fn cover_segment(&mut self, a: Pt, b: Pt, width: f64) {
        let finite = [a.0, a.1, b.0, b.1]
            .iter()
            .all(|v| v.is_finite() && v.abs() < 1e6);
        if !finite {
            return;
        }
        let width = width.max(0.5);
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let x_major = dx.abs() >= dy.abs();
        // Walk the major axis one pixel at a time, covering a span across it.
        let (a, b) = if x_major {
            (a, b)
        } else {
            ((a.1, a.0), (b.1, b.0))
        };
        let (a, b) = if a.0 <= b.0 { (a, b) } else { (b, a) };
        let grad = if b.0 > a.0 {
            (b.1 - a.1) / (b.0 - a.0)
        } else {
            0.0
        };
        let hw = 0.5 * width * (1.0 + grad * grad).sqrt();
        let (i0, i1) = (a.0.round() as i32, b.0.round() as i32);
        for i in i0..=i1 {
            let t = f64::from(i).clamp(a.0, b.0);
            let c = a.1 + grad * (t - a.0);
            let (lo, hi) = (c - hw, c + hw);
            let j0 = (lo + 0.5).floor() as i32;
            let j1 = (hi + 0.5).floor() as i32;
            for j in j0..=j1 {
                let cov = (hi.min(f64::from(j) + 0.5) - lo.max(f64::from(j) - 0.5)).clamp(0.0, 1.0);
                if x_major {
                    self.cover(i, j, cov);
                } else {
                    self.cover(j, i, cov);
                }
            }
        }
    }

    /// A polyline of `width` pixels with anti-aliased edges, composited once
    /// so that joints look like the rest of the line; a single point is
    /// drawn as a dot of the line width.
    pub fn polyline(&mut self, pts: &[Pt], color: [u8; 3], width: f64) -> Result<(), String> {
        match pts {
            [] => Ok(()),
            [p] => self.dot(*p, (0.5 * width).round().max(1.0) as u32, color),
            _ => {
                if self.coverage.is_empty() {
                    self.coverage = vec![0.0; self.width as usize * self.height as usize];
                }
                for w in pts.windows(2) {
                    self.cover_segment(w[0], w[1], width);
                }
                let touched = std::mem::take(&mut self.touched);
                let mut result = Ok(());
                for &i in &touched {
                    let cov = std::mem::replace(&mut self.coverage[i as usize], 0.0);
                    if result.is_ok() {
                        let (x, y) = (i % self.width, i / self.width);
                        result = self.blend(x as i32, y as i32, color, f64::from(cov));
                    }
                }
                self.touched = touched;
                self.touched.clear();
                result
            }
        }
    }

    /// A straight line; see [`Canvas::polyline`].
    pub fn line(&mut self, a: Pt, b: Pt, color: [u8; 3], width: f64) -> Result<(), String> {
        self.polyline(&[a, b], color, width)
    }

    /// A filled circle.
    pub fn dot(&mut self, c: Pt, radius: u32, color: [u8; 3]) -> Result<(), String> {
        let style = ShapeStyle {
            color: rgb(color).to_rgba(),
            filled: true,
            stroke_width: 1,
        };
        self.backend
            .draw_circle((coord(c.0), coord(c.1)), radius, &style, true)
            .map_err(|e| e.to_string())
    }

    /// A filled rectangle (edges included).
    pub fn fill(&mut self, r: PixelRect, color: [u8; 3]) -> Result<(), String> {
        if r.right < r.left || r.bottom < r.top {
            return Ok(());
        }
        self.backend
            .draw_rect(
                (r.left, r.top),
                (r.right + 1, r.bottom + 1),
                &rgb(color),
                true,
            )
            .map_err(|e| e.to_string())
    }

    /// A one-pixel rectangle outline on the edge pixels of `r`.
    pub fn outline(&mut self, r: PixelRect, color: [u8; 3]) -> Result<(), String> {
        let edges = [
            PixelRect { bottom: r.top, ..r },
            PixelRect { top: r.bottom, ..r },
            PixelRect { right: r.left, ..r },
            PixelRect { left: r.right, ..r },
        ];
        for e in edges {
            self.fill(e, color)?;
        }
        Ok(())
    }

    /// Horizontal text; see [`HAlign`] and [`VAlign`].
    pub fn text(
        &mut self,
        text: &str,
        size: f64,
        color: [u8; 3],
        at: Pt,
        h: HAlign,
        v: VAlign,
    ) -> Result<(), String> {
        if text.is_empty() || size.is_nan() || size <= 1.0 {
            return Ok(());
        }
        let w = fonts::text_width(text, size);
        let left = match h {
            HAlign::Left => at.0,
            HAlign::Center => at.0 - 0.5 * w,
            HAlign::Right => at.0 - w,
        };
        let baseline = match v {
            VAlign::Top => at.1 + CAP_HEIGHT * size,
            VAlign::Center => at.1 + 0.5 * CAP_HEIGHT * size,
            VAlign::Bottom => at.1 - DESCENT * size,
        };
        let mut result = Ok(());
        // Whole-pixel baseline keeps horizontal strokes crisp.
        fonts::rasterize(text, size, (left, baseline.round()), |x, y, c| {
            if result.is_ok() {
                result = self.blend(x, y, color, f64::from(c));
            }
        });
        result
    }

    /// Text reading upwards, centred on `center` (for y axis labels).
    pub fn text_vertical(
        &mut self,
        text: &str,
        size: f64,
        color: [u8; 3],
        center: Pt,
    ) -> Result<(), String> {
        if text.is_empty() || size.is_nan() || size <= 1.0 {
            return Ok(());
        }
        let w = fonts::text_width(text, size);
        // Rotated by 90° counter-clockwise: the text's local (x, y), with
        // the origin at the start of the baseline, lands at (bx + y, by - x).
        let bx = (center.0 + 0.5 * CAP_HEIGHT * size).round() as i32;
        let by = (center.1 + 0.5 * w).round() as i32;
        let mut result = Ok(());
        fonts::rasterize(text, size, (0.0, 0.0), |x, y, c| {
            if result.is_ok() {
                result = self.blend(bx + y, by - x, color, f64::from(c));
            }
        });
        result
    }
}
