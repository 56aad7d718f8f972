//! Figures of a posterior sample (issue 23): the corner plot ([`CornerFigure`]: 1-D histograms
//! on the diagonal, 2-D histograms of every pair below it, so that a valley such as κ against
//! ξ shows as a long band) and the predictive-band overlay ([`BandFigure`]: the 95 % band of the
//! model curves over the measured curve).

mod band;
mod corner;

pub use band::{band_layout, render_band_png, BandFigure, BandLayout};
pub use corner::{corner_layout, render_corner_png, CornerFigure, CornerLayout, CornerMarker};
