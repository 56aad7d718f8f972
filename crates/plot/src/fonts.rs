//! The bundled font and text metrics.

use std::sync::OnceLock;

use plotters::style::{register_font, FontDesc, FontFamily, FontStyle};

/// DejaVu Sans (Bitstream Vera licence, see assets/DejaVuSans-LICENSE.txt).
static FONT_BYTES: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Family name under which this crate draws; private so that other code
/// registering fonts cannot change our metrics.
pub(crate) const FAMILY: &str = "subfric-dejavu-sans";

static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();

/// Registers the bundled font once per process, under [`FAMILY`] and under
/// "sans-serif" (so plotters' defaults work without system fonts too).
pub(crate) fn ensure_fonts() -> Result<(), String> {
    REGISTERED
        .get_or_init(|| {
            for name in [FAMILY, "sans-serif"] {
                register_font(name, FontStyle::Normal, FONT_BYTES)
                    .map_err(|_| format!("bundled font could not be registered as {name}"))?;
            }
            Ok(())
        })
        .clone()
}

/// The font at a size in pixels (the size is the font's full line height,
/// ascent plus descent, as ab_glyph scales it).
pub(crate) fn font(size: f64) -> FontDesc<'static> {
    FontDesc::new(FontFamily::Name(FAMILY), size, FontStyle::Normal)
}

/// Height of capital letters as a fraction of the font size (DejaVu Sans).
pub(crate) const CAP_HEIGHT: f64 = 0.626;
/// Depth of descenders as a fraction of the font size (DejaVu Sans).
pub(crate) const DESCENT: f64 = 0.203;

/// Advance width of `text` in pixels.
pub(crate) fn text_width(text: &str, size: f64) -> f64 {
    match font(size).layout_box(text) {
        Ok(((x0, _), (x1, _))) => f64::from(x1 - x0).max(0.0),
        Err(_) => 0.6 * size * text.chars().count() as f64,
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
