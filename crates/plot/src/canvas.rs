//! The drawing layer: tiny-skia draws rectangles, anti-aliased strokes
//! (solid or dashed) and dots into an RGBA pixmap; text is rasterised by
//! ab_glyph (see [`crate::fonts`]) and blended into the same pixmap.
//!
//! Coordinates are in pixels with pixel (i, j) centred on (i, j): a
//! one-pixel line along y = j covers exactly row j.

use tiny_skia::{
    FillRule, LineCap, LineJoin, Paint, Path, PathBuilder, PathSegment, Pixmap, Rect, Stroke,
    StrokeDash, Transform,
};

use crate::fonts::{self, CAP_HEIGHT, DESCENT};
use crate::geom::{PixelRect, Pt};
use crate::DrawError;

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

/// Dash and gap lengths in pixels.
pub(crate) type Dash = (f64, f64);

/// Segments per stroked piece of a long polyline (see [`Canvas::polyline`]).
const PIECE: usize = 64;

/// A polyline as paths of [`PIECE`] segments each (the last one shorter),
/// each starting where the one before ends.
fn solid_pieces(pts: &[(f32, f32)]) -> Vec<Path> {
    let mut out = Vec::with_capacity(pts.len() / PIECE + 1);
    let mut start = 0;
    while start + 1 < pts.len() {
        let end = (start + PIECE).min(pts.len() - 1);
        let mut pb = PathBuilder::with_capacity(end - start + 1, end - start + 1);
        pb.move_to(pts[start].0, pts[start].1);
        for &(x, y) in &pts[start + 1..=end] {
            pb.line_to(x, y);
        }
        out.extend(pb.finish());
        start = end;
    }
    out
}

/// The dashes of a polyline (`dash` pixels on, `gap` off), grouped into
/// paths of at least [`PIECE`] segments unless the line ends first.
fn dashed_pieces(pts: &[(f32, f32)], dash: f32, gap: f32) -> Vec<Path> {
    let mut pb = PathBuilder::with_capacity(pts.len(), pts.len());
    pb.move_to(pts[0].0, pts[0].1);
    for &(x, y) in &pts[1..] {
        pb.line_to(x, y);
    }
    let dashed = StrokeDash::new(vec![dash, gap], 0.0)
        .zip(pb.finish())
        .and_then(|(pattern, path)| path.dash(&pattern, 1.0));
    let Some(dashed) = dashed else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let mut group = PathBuilder::new();
    let mut segments = 0;
    for seg in dashed.segments() {
        match seg {
            PathSegment::MoveTo(p) => {
                if segments >= PIECE {
                    out.extend(std::mem::take(&mut group).finish());
                    segments = 0;
                }
                group.move_to(p.x, p.y);
            }
            PathSegment::LineTo(p) => {
                group.line_to(p.x, p.y);
                segments += 1;
            }
            // Dashes of straight segments are straight and open.
            PathSegment::QuadTo(..) | PathSegment::CubicTo(..) | PathSegment::Close => {}
        }
    }
    out.extend(group.finish());
    out
}

/// Largest coordinate handed to tiny-skia; callers clip to the image, so
/// this only guards against non-finite or absurd values.
const COORD_LIMIT: f64 = 1e6;

fn paint(color: [u8; 3], anti_alias: bool) -> Paint<'static> {
    let mut p = Paint {
        anti_alias,
        ..Paint::default()
    };
    p.set_color_rgba8(color[0], color[1], color[2], 255);
    p
}

/// tiny-skia coordinate of the centre of the pixel at `v`.
fn centre(v: f64) -> Option<f32> {
    (v.is_finite() && v.abs() < COORD_LIMIT).then_some((v + 0.5) as f32)
}

/// Drawing target: a white, opaque pixmap.
pub(crate) struct Canvas {
    pixmap: Pixmap,
}

impl Canvas {
    /// A white canvas of `width` x `height` pixels.
    pub fn new(width: u32, height: u32) -> Result<Self, DrawError> {
        let mut pixmap = Pixmap::new(width, height).ok_or(DrawError::Canvas { width, height })?;
        pixmap.fill(tiny_skia::Color::WHITE);
        Ok(Canvas { pixmap })
    }

    /// The image as 8-bit RGB, 3 bytes per pixel, row-major. Every paint is
    /// opaque, so the premultiplied RGBA pixels are plain RGB.
    pub fn into_rgb(self) -> Vec<u8> {
        self.pixmap
            .data()
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect()
    }

    /// A polyline of `width` pixels with anti-aliased edges, solid or dashed
    /// (the pattern runs on along the whole line); a single point is drawn
    /// as a dot of the line width.
    ///
    /// Joins are bevelled: on a dense, noisy curve round joins cost 40 % more
    /// time, and miter joins stick out past the data. Long lines are stroked
    /// in pieces of about [`PIECE`] segments, since tiny-skia's scan
    /// converter keeps the edges crossing each row sorted and a noisy curve
    /// stroked as one path puts thousands of edges into every row (35 % less
    /// time on `examples/measure.rs`). Solid pieces get round caps, so that
    /// they meet without a notch; dashed lines are cut between dashes.
    pub fn polyline(&mut self, pts: &[Pt], color: [u8; 3], width: f64, dash: Option<Dash>) {
        let pts: Vec<(f32, f32)> = pts
            .iter()
            .filter_map(|&(x, y)| Some((centre(x)?, centre(y)?)))
            .collect();
        match pts[..] {
            [] => return,
            [p] => {
                let r = (0.5 * width).round().max(1.0) as f32;
                self.disc(p, r, color);
                return;
            }
            _ => {}
        }
        let mut stroke = Stroke {
            width: width.max(0.5) as f32,
            line_cap: LineCap::Round,
            line_join: LineJoin::Bevel,
            ..Stroke::default()
        };
        let pieces = match dash {
            None => solid_pieces(&pts),
            Some((d, g)) => {
                stroke.line_cap = LineCap::Butt;
                dashed_pieces(&pts, d as f32, g as f32)
            }
        };
        let paint = paint(color, true);
        for path in pieces {
            self.pixmap
                .stroke_path(&path, &paint, &stroke, Transform::identity(), None);
        }
    }

    /// A straight line; see [`Canvas::polyline`].
    pub fn line(&mut self, a: Pt, b: Pt, color: [u8; 3], width: f64, dash: Option<Dash>) {
        self.polyline(&[a, b], color, width, dash);
    }

    /// A filled, anti-aliased disc.
    pub fn dot(&mut self, c: Pt, radius: f64, color: [u8; 3]) {
        if let (Some(x), Some(y)) = (centre(c.0), centre(c.1)) {
            self.disc((x, y), radius as f32, color);
        }
    }

    fn disc(&mut self, (x, y): (f32, f32), radius: f32, color: [u8; 3]) {
        if let Some(path) = PathBuilder::from_circle(x, y, radius) {
            self.pixmap.fill_path(
                &path,
                &paint(color, true),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
    }

    /// A filled rectangle (edges included), without anti-aliasing.
    pub fn fill(&mut self, r: PixelRect, color: [u8; 3]) {
        let rect = Rect::from_ltrb(
            r.left as f32,
            r.top as f32,
            (r.right + 1) as f32,
            (r.bottom + 1) as f32,
        );
        if let Some(rect) = rect {
            self.pixmap
                .fill_rect(rect, &paint(color, false), Transform::identity(), None);
        }
    }

    /// A one-pixel rectangle outline on the edge pixels of `r`.
    pub fn outline(&mut self, r: PixelRect, color: [u8; 3]) {
        let edges = [
            PixelRect { bottom: r.top, ..r },
            PixelRect { top: r.bottom, ..r },
            PixelRect { right: r.left, ..r },
            PixelRect { left: r.right, ..r },
        ];
        for e in edges {
            self.fill(e, color);
        }
    }

    /// Blends `color` over pixel (x, y) with the given coverage.
    fn blend(&mut self, x: i32, y: i32, color: [u8; 3], coverage: f32) {
        let (w, h) = (self.pixmap.width(), self.pixmap.height());
        if coverage < 0.02 || x < 0 || y < 0 || x as u32 >= w || y as u32 >= h {
            return;
        }
        let a = coverage.min(1.0);
        let i = (y as usize * w as usize + x as usize) * 4;
        let px = &mut self.pixmap.data_mut()[i..i + 3];
        for (d, &c) in px.iter_mut().zip(&color) {
            *d = (f32::from(*d) + (f32::from(c) - f32::from(*d)) * a).round() as u8;
        }
    }

    /// Horizontal text; see [`HAlign`] and [`VAlign`].
    pub fn text(&mut self, text: &str, size: f64, color: [u8; 3], at: Pt, h: HAlign, v: VAlign) {
        if text.is_empty() || size.is_nan() || size <= 1.0 {
            return;
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
        // Whole-pixel baseline keeps horizontal strokes crisp.
        fonts::rasterize(text, size, (left, baseline.round()), |x, y, c| {
            self.blend(x, y, color, c);
        });
    }

    /// Text reading upwards, centred on `center` (for y axis labels).
    pub fn text_vertical(&mut self, text: &str, size: f64, color: [u8; 3], center: Pt) {
        if text.is_empty() || size.is_nan() || size <= 1.0 {
            return;
        }
        let w = fonts::text_width(text, size);
        // Rotated by 90° counter-clockwise: the text's local (x, y), with
        // the origin at the start of the baseline, lands at (bx + y, by - x).
        let bx = (center.0 + 0.5 * CAP_HEIGHT * size).round() as i32;
        let by = (center.1 + 0.5 * w).round() as i32;
        fonts::rasterize(text, size, (0.0, 0.0), |x, y, c| {
            self.blend(bx + y, by - x, color, c);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixel(c: &Canvas, x: u32, y: u32) -> [u8; 3] {
        let i = ((y * c.pixmap.width() + x) * 4) as usize;
        let d = c.pixmap.data();
        [d[i], d[i + 1], d[i + 2]]
    }

    #[test]
    fn one_pixel_lines_and_rects_are_crisp() {
        let mut c = Canvas::new(20, 10).unwrap();
        c.line((2.0, 4.0), (17.0, 4.0), [0, 0, 0], 1.0, None);
        c.fill(
            PixelRect {
                left: 3,
                top: 7,
                right: 5,
                bottom: 8,
            },
            [214, 39, 40],
        );
        assert_eq!(pixel(&c, 10, 4), [0, 0, 0]);
        assert_eq!(pixel(&c, 10, 3), [255, 255, 255]);
        assert_eq!(pixel(&c, 10, 5), [255, 255, 255]);
        assert_eq!(pixel(&c, 3, 7), [214, 39, 40]);
        assert_eq!(pixel(&c, 5, 8), [214, 39, 40]);
        assert_eq!(pixel(&c, 6, 8), [255, 255, 255]);
        assert_eq!(c.into_rgb().len(), 20 * 10 * 3);
    }

    #[test]
    fn dashes_leave_gaps_and_diagonals_are_smooth() {
        let mut c = Canvas::new(60, 30).unwrap();
        c.line((0.0, 5.0), (59.0, 5.0), [0, 0, 0], 2.0, Some((9.0, 5.0)));
        let row: Vec<bool> = (0..60).map(|x| pixel(&c, x, 5)[0] < 128).collect();
        let runs = row.windows(2).filter(|w| w[0] && !w[1]).count();
        assert!((3..=5).contains(&runs), "{runs} dashes in {row:?}");
        // A diagonal line has partly covered pixels (anti-aliasing).
        c.line((0.0, 10.0), (40.0, 29.0), [0, 0, 0], 2.0, None);
        let grey = (10..30)
            .flat_map(|y| (0..60).map(move |x| (x, y)))
            .filter(|&(x, y)| (30..225).contains(&pixel(&c, x, y)[0]))
            .count();
        assert!(grey > 20, "{grey} anti-aliased pixels");
        // Non-finite points are skipped, not drawn at the origin.
        c.line((f64::NAN, 0.0), (f64::INFINITY, 0.0), [0, 0, 0], 3.0, None);
        c.line(
            (f64::NAN, 0.0),
            (f64::NAN, 0.0),
            [0, 0, 0],
            3.0,
            Some((9.0, 5.0)),
        );
        c.polyline(&[], [0, 0, 0], 3.0, Some((9.0, 5.0)));
        assert_eq!(pixel(&c, 0, 0), [255, 255, 255]);
    }

    #[test]
    fn long_lines_are_stroked_in_pieces_without_seams() {
        // 301 points: four full pieces and a last, short one.
        let pts: Vec<Pt> = (0..301).map(|i| (i as f64 * 0.5 + 10.0, 5.0)).collect();
        let f32_pts: Vec<(f32, f32)> = pts.iter().map(|p| (p.0 as f32, p.1 as f32)).collect();
        assert_eq!(solid_pieces(&f32_pts).len(), 5);
        assert_eq!(solid_pieces(&f32_pts[..257]).len(), 4);
        assert_eq!(solid_pieces(&f32_pts[..2]).len(), 1);
        // 150 pixels of 9-pixel dashes, each over 18 points: about 11 dashes
        // of 18 segments in groups of at least 64 segments.
        assert_eq!(dashed_pieces(&f32_pts, 9.0, 5.0).len(), 3);
        let mut c = Canvas::new(200, 20).unwrap();
        c.polyline(&pts, [214, 39, 40], 2.0, None);
        c.polyline(&pts, [0, 0, 0], 2.0, Some((9.0, 5.0)));
        // The solid line covers every column from start (x = 10) to end
        // (x = 160) fully, in red, black or a blend of both: no notch
        // where pieces meet would let the white show through.
        let inked = |x: u32| {
            let [r, g, b] = pixel(&c, x, 5);
            r <= 214 && g <= 39 && b <= 40
        };
        assert!((10..=160).all(inked));
        assert!((0..8)
            .chain(163..200)
            .all(|x| pixel(&c, x, 5) == [255, 255, 255]));
        // The dashes go on evenly across pieces: 9 pixels on, 5 off.
        let black: Vec<bool> = (0..200).map(|x| pixel(&c, x, 5) == [0, 0, 0]).collect();
        let starts: Vec<usize> = (1..200).filter(|&x| black[x] && !black[x - 1]).collect();
        let steps: Vec<usize> = starts.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(starts.len() >= 9, "{starts:?}");
        assert!(steps.iter().all(|&d| d == 14), "dash period {steps:?}");
    }

    #[test]
    fn an_empty_canvas_is_an_error() {
        assert_eq!(
            Canvas::new(0, 10).err(),
            Some(DrawError::Canvas {
                width: 0,
                height: 10
            })
        );
    }

    #[test]
    fn text_is_blended_inside_the_image_only() {
        let mut c = Canvas::new(80, 30).unwrap();
        c.text("Tg", 20.0, [0, 0, 0], (2.0, 2.0), HAlign::Left, VAlign::Top);
        c.text(
            "x",
            20.0,
            [0, 0, 0],
            (-50.0, -50.0),
            HAlign::Left,
            VAlign::Top,
        );
        c.text_vertical("edge", 20.0, [0, 0, 0], (79.0, 15.0));
        let dark = c.into_rgb().chunks_exact(3).filter(|p| p[0] < 100).count();
        assert!(dark > 20, "{dark} dark pixels");
    }
}
