//! The bundled font: registration, metrics and rasterisation.

use std::sync::OnceLock;

use ab_glyph::{point, Font, FontRef, PxScale, ScaleFont};

use crate::DrawError;

/// DejaVu Sans (Bitstream Vera licence, see assets/DejaVuSans-LICENSE.txt).
static FONT_BYTES: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

static FACE: OnceLock<Option<FontRef<'static>>> = OnceLock::new();

/// Checks once per process that the bundled font can be parsed.
pub(crate) fn ensure_fonts() -> Result<(), DrawError> {
    face().map(|_| ()).ok_or(DrawError::Font)
}

/// The bundled font face. Text is laid out here (kerning, glyph bearings,
/// sub-pixel positions) and rasterised by ab_glyph.
fn face() -> Option<&'static FontRef<'static>> {
    FACE.get_or_init(|| FontRef::try_from_slice(FONT_BYTES).ok())
        .as_ref()
}

/// Height of capital letters as a fraction of the font size (DejaVu Sans;
/// the size is the font's full line height, ascent plus descent).
pub(crate) const CAP_HEIGHT: f64 = 0.626;
/// Depth of descenders as a fraction of the font size (DejaVu Sans).
pub(crate) const DESCENT: f64 = 0.203;

fn scale(size: f64) -> PxScale {
    PxScale::from(size.clamp(0.0, 4096.0) as f32)
}

/// Advance width of `text` in pixels.
pub(crate) fn text_width(text: &str, size: f64) -> f64 {
    let Some(font) = face() else {
        return 0.6 * size * text.chars().count() as f64;
    };
    let font = font.as_scaled(scale(size));
    let mut x = 0.0f32;
    let mut prev = None;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = prev {
            x += font.kern(p, id);
        }
        x += font.h_advance(id);
        prev = Some(id);
    }
    f64::from(x.max(0.0))
}

/// Rasterises `text` with its baseline starting at `origin` (sub-pixel
/// precise) and calls `put(x, y, coverage)` for every touched pixel.
pub(crate) fn rasterize(
    text: &str,
    size: f64,
    origin: (f64, f64),
    mut put: impl FnMut(i32, i32, f32),
) {
    let Some(font) = face() else {
        return;
    };
    let px = scale(size);
    let scaled = font.as_scaled(px);
    let (ox, oy) = (origin.0.floor(), origin.1.floor());
    let (fx, fy) = ((origin.0 - ox) as f32, (origin.1 - oy) as f32);
    let (ox, oy) = (ox.clamp(-1e6, 1e6) as i32, oy.clamp(-1e6, 1e6) as i32);
    let mut x = 0.0f32;
    let mut prev = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = prev {
            x += scaled.kern(p, id);
        }
        let glyph = id.with_scale_and_position(px, point(fx + x, fy));
        if let Some(outline) = font.outline_glyph(glyph) {
            let b = outline.px_bounds();
            let (bx, by) = (b.min.x as i32, b.min.y as i32);
            outline.draw(|gx, gy, cov| put(ox + bx + gx as i32, oy + by + gy as i32, cov));
        }
        x += scaled.h_advance(id);
        prev = Some(id);
    }
}

/// `text` shortened with an ellipsis so that it is at most `max_width` wide.
pub(crate) fn fit_text(text: &str, size: f64, max_width: f64) -> String {
    if text_width(text, size) <= max_width {
        return text.to_string();
    }
    // No glyph is narrower than a fifth of the size: bound the search.
    let cap = (max_width.max(0.0) / (0.2 * size.max(1.0))).ceil() as usize + 1;
    let chars: Vec<char> = text.chars().take(cap + 1).collect();
    let mut n = chars.len();
    while n > 0 {
        n -= 1;
        let candidate: String = chars[..n].iter().collect::<String>().trim_end().to_string() + "…";
        if text_width(&candidate, size) <= max_width {
            return candidate;
        }
    }
    String::new()
}

/// The largest size in `[min_size, size]` (in 5 % steps) at which `text` fits
/// into `max_width`, and the text (shortened if even `min_size` is too wide).
pub(crate) fn shrink_to_fit(text: &str, size: f64, min_size: f64, max_width: f64) -> (String, f64) {
    let mut s = size;
    while s > min_size && text_width(text, s) > max_width {
        s = (s * 0.95).max(min_size);
    }
    (fit_text(text, s, max_width), s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn font_registers_and_measures() {
        ensure_fonts().unwrap();
        ensure_fonts().unwrap();
        let w = text_width("displacement (mm)", 20.0);
        assert!(w > 100.0 && w < 250.0, "width {w}");
        assert!(text_width("", 20.0) == 0.0);
        let short = fit_text("a rather long label that will not fit", 16.0, 80.0);
        assert!(short.ends_with('…'));
        assert!(text_width(&short, 16.0) <= 80.0);
        assert_eq!(fit_text("abc", 16.0, 0.0), "");
    }
}
