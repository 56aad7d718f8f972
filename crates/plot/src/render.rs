//! From a chart drawn by plotters to files: the SVG document plotters writes, finished (dashes,
//! the bundled font's name, pixel-centred strokes), and its pixels drawn by resvg with the
//! bundled font only.

use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use plotters::prelude::{DrawingArea, IntoDrawingArea, SVGBackend};
use plotters::style::FontStyle;
use resvg::{tiny_skia, usvg};

use crate::{png_io, DrawError, Invalid, PlotError};

/// DejaVu Sans (Bitstream Vera licence, see assets/DejaVuSans-LICENSE.txt).
static FONT_BYTES: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// The family name the charts ask for; plotters measures text with the bundled font under it.
pub(crate) const FAMILY: &str = "sans-serif";

/// The family the finished SVG names: the bundled font first, so that the PNG (and a viewer
/// that has it) shows the text as it was measured.
const SVG_FAMILY: &str = "DejaVu Sans, Verdana, sans-serif";

/// Opacity that marks a dashed stroke: plotters' SVG backend has no dash attribute, so dashed
/// lines are drawn with this opacity and [`finish_svg`] turns it into `stroke-dasharray`.
pub(crate) const DASH_MARK: f64 = 0.996_093_75;

/// Checks once per process that the bundled font can be parsed, and registers it for plotters.
pub(crate) fn ensure_font() -> Result<(), DrawError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FAMILY, FontStyle::Normal, FONT_BYTES).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(DrawError::Font)
    }
}

/// The font database of the rasteriser: the bundled font only, also as every generic family.
fn fontdb() -> Arc<usvg::fontdb::Database> {
    static DB: OnceLock<Arc<usvg::fontdb::Database>> = OnceLock::new();
    DB.get_or_init(|| {
        let mut db = usvg::fontdb::Database::new();
        db.load_font_data(FONT_BYTES.to_vec());
        db.set_sans_serif_family("DejaVu Sans");
        db.set_serif_family("DejaVu Sans");
        db.set_monospace_family("DejaVu Sans");
        Arc::new(db)
    })
    .clone()
}

/// An SVG document of `width` x `height` pixels drawn by `draw` on plotters' SVG backend,
/// finished by [`finish_svg`].
pub(crate) fn svg_of(
    width: u32,
    height: u32,
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, plotters::coord::Shift>) -> Result<(), Invalid>,
) -> Result<String, Invalid> {
    ensure_font().map_err(Invalid::Draw)?;
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (width, height)).into_drawing_area();
        draw(&root)?;
        root.present()
            .map_err(|e| Invalid::Draw(DrawError::Chart(e.to_string())))?;
    }
    Ok(finish_svg(&text))
}

/// The document plotters wrote, finished: strokes marked by [`DASH_MARK`] dashed, the font
/// named, and strokes (lines, polylines, outlines) and discs moved by half a pixel so that
/// plotters' whole-pixel coordinates fall on pixel centres: one-pixel grid lines and frames
/// stay sharp and markers are centred on their pixel, while filled boxes and polygons keep
/// their whole-pixel edges (neighbouring bins and bars meet without a seam).
fn finish_svg(svg: &str) -> String {
    let dash = format!("opacity=\"{DASH_MARK}\"");
    let family = format!("font-family=\"{SVG_FAMILY}\"");
    let mut out = String::with_capacity(svg.len() + svg.len() / 8);
    for line in xml_text(svg).lines() {
        let stroked = line.starts_with("<line ")
            || line.starts_with("<polyline ")
            || line.starts_with("<circle ")
            || (line.starts_with("<rect ") && line.contains("fill=\"none\""));
        let line = line
            .replace(&dash, "opacity=\"1\" stroke-dasharray=\"9 5\"")
            .replace("font-family=\"sans-serif\"", &family);
        match line.split_once(' ') {
            Some((tag, rest)) if stroked => {
                out.push_str(tag);
                out.push_str(" transform=\"translate(.5 .5)\" ");
                out.push_str(rest);
            }
            _ => out.push_str(&line),
        }
        out.push('\n');
    }
    out
}

/// `text` with the characters XML does not allow in a document shown as the Unicode pictures
/// of control characters (a test named with an escape character reads `␛`, as the terminal
/// output shows it escaped), and the two non-characters U+FFFE and U+FFFF as U+FFFD.
fn xml_text(text: &str) -> String {
    text.chars()
        .map(|c| match c {
            '\t' | '\n' | '\r' => c,
            '\u{0}'..='\u{1f}' => char::from_u32(0x2400 + c as u32).unwrap_or('\u{fffd}'),
            '\u{7f}' => '\u{2421}',
            '\u{fffe}' | '\u{ffff}' => '\u{fffd}',
            c => c,
        })
        .collect()
}

/// The pixels of an SVG document, as 8-bit RGB over white.
pub(crate) fn rasterise(svg: &str) -> Result<(u32, u32, Vec<u8>), DrawError> {
    let options = usvg::Options {
        fontdb: fontdb(),
        font_family: "DejaVu Sans".into(),
        ..usvg::Options::default()
    };
    let tree = usvg::Tree::from_str(svg, &options).map_err(|e| DrawError::Svg(e.to_string()))?;
    let size = tree.size().to_int_size();
    let (w, h) = (size.width(), size.height());
    let mut pixmap = tiny_skia::Pixmap::new(w, h).ok_or(DrawError::Canvas {
        width: w,
        height: h,
    })?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        tiny_skia::Transform::identity(),
        &mut pixmap.as_mut(),
    );
    // Drawn over opaque white: the premultiplied pixels are plain RGB.
    let rgb = pixmap
        .data()
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    Ok((w, h, rgb))
}

/// A figure of any kind: its size and its SVG document.
pub trait Chart {
    /// Image width and height in pixels.
    fn size(&self) -> (u32, u32);

    /// The SVG document, or why there is none.
    #[doc(hidden)]
    fn svg_document(&self) -> Result<String, Invalid>;
}

/// The SVG document of `chart` (what [`write_figure`] writes beside the PNG).
pub fn render_svg(chart: &impl Chart, path_for_errors: &Path) -> Result<String, PlotError> {
    chart
        .svg_document()
        .map_err(|e| e.with_path(path_for_errors))
}

/// Draws `chart` and writes it to `path` as an RGB PNG.
pub(crate) fn write_png(chart: &impl Chart, path: &Path) -> Result<(), PlotError> {
    let svg = render_svg(chart, path)?;
    png_from_svg(&svg, path)
}

fn png_from_svg(svg: &str, path: &Path) -> Result<(), PlotError> {
    let (w, h, rgb) = rasterise(svg).map_err(|e| Invalid::Draw(e).with_path(path))?;
    png_io::write_rgb_png(path, w, h, &rgb)
}

/// The files [`write_figure`] wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Written {
    /// The PNG.
    pub png: PathBuf,
    /// The SVG beside it (same name, `.svg`).
    pub svg: PathBuf,
}

/// Draws `chart` and writes it twice: as an RGB PNG at `png` and as SVG beside it (the same
/// name ending in `.svg`). Both are replaced in one step each (a temporary file renamed).
pub fn write_figure(chart: &impl Chart, png: &Path) -> Result<Written, PlotError> {
    let svg = render_svg(chart, png)?;
    png_from_svg(&svg, png)?;
    let svg_path = png.with_extension("svg");
    png_io::write_atomically(&svg_path, svg.as_bytes())?;
    Ok(Written {
        png: png.to_path_buf(),
        svg: svg_path,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_svg_is_finished_and_drawn_with_the_bundled_font() {
        let svg = "<svg width=\"40\" height=\"20\" viewBox=\"0 0 40 20\" xmlns=\"http://www.w3.org/2000/svg\">\n\
            <polyline fill=\"none\" opacity=\"0.99609375\" stroke=\"#000000\" stroke-width=\"2\" points=\"0,10 39,10 \"/>\n\
            <text x=\"1\" y=\"1\" dy=\"0.76em\" font-family=\"sans-serif\" font-size=\"12\" fill=\"#000000\">Ab</text>\n\
            </svg>\n";
        let done = finish_svg(svg);
        assert!(done.contains("stroke-dasharray=\"9 5\""), "{done}");
        assert!(done.contains("font-family=\"DejaVu Sans"), "{done}");
        assert!(
            done.contains("<polyline transform=\"translate(.5 .5)\"")
                && done.trim_end().ends_with("</svg>")
        );
        assert!(!done.contains("<text transform"));
        let (w, h, rgb) = rasterise(&done).unwrap();
        // Characters XML does not allow (a name with an escape character) are shown as the
        // pictures of those characters, and the document still reads.
        let odd = svg
            .replace(">Ab<", ">A\u{1b}b\u{7}<")
            .replace("Ab\n", "A\u{1b}b\u{7}\n");
        let odd = finish_svg(&odd);
        assert!(odd.contains("A\u{241b}b\u{2407}"), "{odd}");
        assert!(rasterise(&odd).is_ok());
        assert_eq!((w, h, rgb.len()), (40, 20, 40 * 20 * 3));
        // The dashes leave white gaps along the line (row 10, centred by the half-pixel move).
        let row: Vec<bool> = (0..40).map(|x| rgb[(10 * 40 + x) * 3] < 128).collect();
        let dashes = row.windows(2).filter(|w| !w[0] && w[1]).count();
        assert!(dashes >= 2, "{row:?}");
        // The text was laid out (no system font is asked for): dark pixels above the line.
        let text = (0..9 * 40).filter(|i| rgb[i * 3] < 128).count();
        assert!(text > 10, "{text} text pixels");
    }
}
