//! PNG encoding and decoding with the `png` crate, and simple image checks.

use std::fs::File;
use std::io::{BufReader, Write};
use std::path::Path;

use crate::PlotError;

/// Writes an 8-bit RGB buffer (3 bytes per pixel, row-major) as a PNG file.
pub(crate) fn write_rgb_png(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u8],
) -> Result<(), PlotError> {
    let enc_err = |e: png::EncodingError| PlotError::Encode {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::Balanced);
        encoder.set_filter(png::Filter::Adaptive);
        let mut writer = encoder.write_header().map_err(enc_err)?;
        writer.write_image_data(rgb).map_err(enc_err)?;
        writer.finish().map_err(enc_err)?;
    }
    write_atomically(path, &bytes)
}

/// Writes `bytes` in full to a temporary file beside `path`, flushed, then renamed over it: a
/// full disk or a kill leaves the previous file whole, and a symbolic link at `path` is
/// replaced, never written through.
pub(crate) fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), PlotError> {
    let io_err = |source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    };
    let tmp = temp_beside(path);
    let written = (|| {
        let mut file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
            .map_err(io_err)?;
        file.write_all(bytes).map_err(io_err)?;
        file.sync_all().map_err(io_err)?;
        drop(file);
        std::fs::rename(&tmp, path).map_err(io_err)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// A hidden temporary file name in the folder of `path`, unique to this process and call.
fn temp_beside(path: &Path) -> std::path::PathBuf {
    static COUNTER: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "figure.png".into());
    path.with_file_name(format!(".{name}.subfric-tmp-{}-{n}", std::process::id()))
}

/// A decoded image as 8-bit RGB (alpha composited over white).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RgbImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixels, row-major, 3 bytes each.
    pub data: Vec<u8>,
}

impl RgbImage {
    /// The colour at (x, y), or `None` outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> Option<[u8; 3]> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let i = (y as usize * self.width as usize + x as usize) * 3;
        Some([self.data[i], self.data[i + 1], self.data[i + 2]])
    }

    /// All pixels with their coordinates.
    pub fn pixels(&self) -> impl Iterator<Item = (u32, u32, [u8; 3])> + '_ {
        let w = self.width.max(1);
        self.data
            .chunks_exact(3)
            .enumerate()
            .map(move |(i, c)| ((i as u32) % w, (i as u32) / w, [c[0], c[1], c[2]]))
    }
}

/// Decodes a PNG file of any colour type and bit depth into 8-bit RGB.
pub fn read_rgb(path: &Path) -> Result<RgbImage, PlotError> {
    let dec_err = |message: String| PlotError::Decode {
        path: path.to_path_buf(),
        message,
    };
    let file = File::open(path).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut decoder = png::Decoder::new(BufReader::new(file));
    decoder.set_transformations(png::Transformations::normalize_to_color8());
    let mut reader = decoder.read_info().map_err(|e| dec_err(e.to_string()))?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| dec_err("the image is too large to decode".into()))?;
    let mut buf = vec![0u8; size];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| dec_err(e.to_string()))?;
    let (width, height) = (info.width, info.height);
    let buf = &buf[..info.buffer_size()];
    let channels = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => return Err(dec_err("indexed colour was not expanded".into())),
    };
    let line = info.line_size;
    let mut data = Vec::with_capacity(width as usize * height as usize * 3);
    for row in buf.chunks(line).take(height as usize) {
        for px in row.chunks_exact(channels).take(width as usize) {
            let (rgb, alpha) = match channels {
                1 => ([px[0]; 3], 255),
                2 => ([px[0]; 3], px[1]),
                3 => ([px[0], px[1], px[2]], 255),
                _ => ([px[0], px[1], px[2]], px[3]),
            };
            let a = u32::from(alpha);
            for c in rgb {
                data.push(((u32::from(c) * a + 255 * (255 - a) + 127) / 255) as u8);
            }
        }
    }
    if data.len() != width as usize * height as usize * 3 {
        return Err(dec_err("truncated image data".into()));
    }
    Ok(RgbImage {
        width,
        height,
        data,
    })
}

/// Summary of a PNG image, to check that a figure is not blank.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PngCheck {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Fraction of pixels that are not (nearly) white: some channel below 245.
    pub inked_fraction: f64,
    /// Number of distinct RGB colours.
    pub distinct_colors: usize,
}

/// Decodes a PNG file and summarises it.
pub fn inspect_png(path: &Path) -> Result<PngCheck, PlotError> {
    let img = read_rgb(path)?;
    let total = img.width as usize * img.height as usize;
    let mut inked = 0usize;
    // One bit per possible 24-bit colour (2 MiB), fast even unoptimised.
    let mut seen = vec![0u64; 1 << 18];
    let mut distinct = 0usize;
    for c in img.data.chunks_exact(3) {
        if c.iter().any(|&v| v < 245) {
            inked += 1;
        }
        let key = (usize::from(c[0]) << 16) | (usize::from(c[1]) << 8) | usize::from(c[2]);
        let (word, bit) = (key >> 6, 1u64 << (key & 63));
        if seen[word] & bit == 0 {
            seen[word] |= bit;
            distinct += 1;
        }
    }
    Ok(PngCheck {
        width: img.width,
        height: img.height,
        inked_fraction: if total == 0 {
            0.0
        } else {
            inked as f64 / total as f64
        },
        distinct_colors: distinct,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roundtrip_and_errors() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.png");
        let mut buf = vec![255u8; 4 * 3 * 3];
        buf[0] = 0;
        write_rgb_png(&p, 4, 3, &buf).unwrap();
        let img = read_rgb(&p).unwrap();
        assert_eq!((img.width, img.height), (4, 3));
        assert_eq!(img.pixel(0, 0), Some([0, 255, 255]));
        assert_eq!(img.pixel(4, 0), None);
        let check = inspect_png(&p).unwrap();
        assert_eq!(check.distinct_colors, 2);
        assert!((check.inked_fraction - 1.0 / 12.0).abs() < 1e-12);

        // 16-bit grey with alpha decodes to RGB composited over white.
        let grey = dir.path().join("grey16.png");
        {
            let file = File::create(&grey).unwrap();
            let mut enc = png::Encoder::new(std::io::BufWriter::new(file), 2, 1);
            enc.set_color(png::ColorType::GrayscaleAlpha);
            enc.set_depth(png::BitDepth::Sixteen);
            let mut w = enc.write_header().unwrap();
            // (black, opaque), (black, transparent)
            w.write_image_data(&[0, 0, 255, 255, 0, 0, 0, 0]).unwrap();
        }
        let img = read_rgb(&grey).unwrap();
        assert_eq!(img.data, vec![0, 0, 0, 255, 255, 255]);

        let missing = dir.path().join("missing.png");
        let e = inspect_png(&missing).unwrap_err();
        assert!(e.to_string().contains("missing.png"));
        let junk = dir.path().join("junk.png");
        std::fs::write(&junk, b"not a png").unwrap();
        assert!(matches!(inspect_png(&junk), Err(PlotError::Decode { .. })));
        let bad_dir = dir.path().join("no/such/dir/out.png");
        assert!(matches!(
            write_rgb_png(&bad_dir, 4, 3, &buf),
            Err(PlotError::Io { .. })
        ));
    }

    #[test]
    fn a_figure_replaces_its_file_in_one_step() {
        let dir = tempfile::tempdir().unwrap();
        let buf = vec![200u8; 4 * 3 * 3];
        let p = dir.path().join("fig.png");
        // Over a symbolic link: the link is replaced, its target untouched.
        #[cfg(unix)]
        {
            let victim = dir.path().join("victim.txt");
            std::fs::write(&victim, "precious").unwrap();
            std::os::unix::fs::symlink(&victim, &p).unwrap();
            write_rgb_png(&p, 4, 3, &buf).unwrap();
            assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
            assert!(std::fs::symlink_metadata(&p).unwrap().file_type().is_file());
        }
        write_rgb_png(&p, 4, 3, &buf).unwrap();
        assert_eq!(read_rgb(&p).unwrap().width, 4);
        // A failed write (the target is a folder) leaves no temporary file behind.
        let folder = dir.path().join("folder.png");
        std::fs::create_dir(&folder).unwrap();
        assert!(write_rgb_png(&folder, 4, 3, &buf).is_err());
        let left: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .filter(|n| n.contains("subfric-tmp"))
            .collect();
        assert!(left.is_empty(), "{left:?}");
    }
}
