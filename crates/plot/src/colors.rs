//! Colours of styles, palettes and sequential colormaps.

use crate::Style;

/// Colour of [`Style::Measured`] markers (near-black), drawn on top of every curve.
pub const MEASURED_RGB: [u8; 3] = [40, 40, 40];
/// Colour of the thin line through every point of a [`Style::Measured`] series (light grey),
/// drawn beneath the models.
pub const MEASURED_LINE_RGB: [u8; 3] = [170, 170, 170];
/// Colour of [`Style::Published`] lines (blue).
pub const PUBLISHED_RGB: [u8; 3] = [31, 119, 180];
/// Colour of [`Style::Fitted`] lines (red).
pub const FITTED_RGB: [u8; 3] = [214, 39, 40];

/// Palette of [`Style::Other`]: no red or blue, so fitted and published
/// curves stay recognisable.
const OTHER_PALETTE: [[u8; 3]; 7] = [
    [255, 127, 14],
    [44, 160, 44],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [188, 189, 34],
    [23, 190, 207],
];

/// Bar colours of the groups of a bar chart.
pub(crate) const BAR_PALETTE: [[u8; 3]; 8] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [23, 190, 207],
];

/// Light grey of grid lines.
pub(crate) const GRID_RGB: [u8; 3] = [228, 228, 228];
/// Black of frames and text.
pub(crate) const INK_RGB: [u8; 3] = [0, 0, 0];
/// Grey of the zero line and reference lines.
pub(crate) const ZERO_RGB: [u8; 3] = [90, 90, 90];
/// Border of legend boxes.
pub(crate) const LEGEND_BORDER_RGB: [u8; 3] = [160, 160, 160];

/// The line colour of a style.
pub fn style_rgb(style: Style) -> [u8; 3] {
    match style {
        Style::Measured => MEASURED_RGB,
        Style::Published => PUBLISHED_RGB,
        Style::Fitted => FITTED_RGB,
        Style::Other(i) => OTHER_PALETTE[i % OTHER_PALETTE.len()],
    }
}

/// Viridis at 0, 0.1, ..., 1.
const VIRIDIS: [[u8; 3]; 11] = [
    [68, 1, 84],
    [72, 36, 117],
    [65, 68, 135],
    [53, 95, 141],
    [42, 120, 142],
    [33, 145, 140],
    [34, 168, 132],
    [68, 191, 112],
    [122, 209, 81],
    [189, 223, 38],
    [253, 231, 37],
];
const REDS: [[u8; 3]; 2] = [[251, 106, 74], [103, 0, 13]];
const BLUES: [[u8; 3]; 2] = [[107, 174, 214], [8, 48, 107]];

fn interpolate(stops: &[[u8; 3]], t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    if stops.len() < 2 {
        return stops.first().copied().unwrap_or(INK_RGB);
    }
    let pos = t * (stops.len() - 1) as f64;
    let i = (pos.floor() as usize).min(stops.len() - 2);
    let f = pos - i as f64;
    let mut out = [0u8; 3];
    for (c, o) in out.iter_mut().enumerate() {
        let a = f64::from(stops[i][c]);
        let b = f64::from(stops[i + 1][c]);
        *o = (a + (b - a) * f).round().clamp(0.0, 255.0) as u8;
    }
    out
}

/// Colour of cycle position `t` in 0..=1 (first to last cycle) for a style:
/// viridis (without its palest yellow) for measured and other series, reds
/// for fitted and blues for published series.
pub fn cycle_rgb(style: Style, t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    match style {
        Style::Measured | Style::Other(_) => interpolate(&VIRIDIS, t * 0.9),
        Style::Fitted => interpolate(&REDS, t),
        Style::Published => interpolate(&BLUES, t),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colormaps_are_sane() {
        assert_eq!(cycle_rgb(Style::Measured, 0.0), VIRIDIS[0]);
        assert_eq!(cycle_rgb(Style::Fitted, 1.0), REDS[1]);
        assert_eq!(cycle_rgb(Style::Published, f64::NAN), BLUES[0]);
        assert_eq!(
            cycle_rgb(Style::Other(3), 2.0),
            cycle_rgb(Style::Other(3), 1.0)
        );
        assert_eq!(style_rgb(Style::Other(7)), style_rgb(Style::Other(0)));
        for i in 0..20 {
            let t = i as f64 / 19.0;
            assert_ne!(cycle_rgb(Style::Measured, t), FITTED_RGB);
            assert_ne!(cycle_rgb(Style::Fitted, t), FITTED_RGB);
            assert_ne!(style_rgb(Style::Other(i)), FITTED_RGB);
        }
    }
}
