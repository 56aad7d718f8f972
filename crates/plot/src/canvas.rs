//! A thin drawing layer over plotters' in-memory bitmap backend.

use plotters::backend::{BitMapBackend, DrawingBackend, RGBPixel};
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{Color, FontTransform, RGBColor, ShapeStyle};

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
}

impl<'a> Canvas<'a> {
    /// A canvas over `buf` (3 bytes per pixel, row-major), which the caller
    /// fills with the background colour.
    pub fn new(buf: &'a mut [u8], width: u32, height: u32) -> Result<Self, String> {
        let backend = BitMapBackend::<RGBPixel>::with_buffer_and_format(buf, (width, height))
            .map_err(|e| e.to_string())?;
        Ok(Canvas { backend })
    }

    /// Flushes the backend.
    pub fn finish(mut self) -> Result<(), String> {
        self.backend.present().map_err(|e| e.to_string())
    }

    /// A straight line with anti-aliased edges; widths above one pixel are
    /// drawn as parallel one-pixel lines.
    pub fn line(&mut self, a: Pt, b: Pt, color: [u8; 3], width: u32) -> Result<(), String> {
        let (ax, ay, bx, by) = (coord(a.0), coord(a.1), coord(b.0), coord(b.1));
        let style = rgb(color);
        let width = width.max(1) as i32;
        let mostly_horizontal = (bx - ax).abs() >= (by - ay).abs();
        for k in 0..width {
            let o = k - (width - 1) / 2;
            let (dx, dy) = if mostly_horizontal { (0, o) } else { (o, 0) };
            self.backend
                .draw_line((ax + dx, ay + dy), (bx + dx, by + dy), &style)
                .map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    /// A polyline; a single point is drawn as a dot of the line width.
    pub fn polyline(&mut self, pts: &[Pt], color: [u8; 3], width: u32) -> Result<(), String> {
        match pts {
            [] => Ok(()),
            [p] => self.dot(*p, width.max(2) / 2, color),
            _ => {
                let mut prev = pts[0];
                for &p in &pts[1..] {
                    if coord(p.0) == coord(prev.0) && coord(p.1) == coord(prev.1) {
                        continue;
                    }
                    self.line(prev, p, color, width)?;
                    prev = p;
                }
                if coord(prev.0) == coord(pts[0].0) && coord(prev.1) == coord(pts[0].1) {
                    // Everything fell onto one pixel.
                    self.dot(pts[0], width.max(2) / 2, color)?;
                }
                Ok(())
            }
        }
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
        // plotters' ab_glyph text puts the baseline half a size below the
        // top-left anchor.
        let style = fonts::font(size)
            .color(&rgb(color))
            .pos(Pos::new(HPos::Left, VPos::Top));
        self.backend
            .draw_text(text, &style, (coord(left), coord(baseline - 0.5 * size)))
            .map_err(|e| e.to_string())
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
        // Rotated by 270°: a glyph pixel at (x, y) lands at pos + (y, -x).
        let pos_x = center.0 - 0.5 * size + 0.5 * CAP_HEIGHT * size;
        let pos_y = center.1 + 0.5 * w;
        let style = fonts::font(size)
            .transform(FontTransform::Rotate270)
            .color(&rgb(color))
            .pos(Pos::new(HPos::Left, VPos::Top));
        self.backend
            .draw_text(text, &style, (coord(pos_x), coord(pos_y)))
            .map_err(|e| e.to_string())
    }
}
