//! The least-squares straight line, for the readings of a record that are lines: the motion
//! either side of an event boundary, an elastic unload.

/// A least-squares line y = intercept + slope · x.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineFit {
    /// Value at x = 0.
    pub intercept: f64,
    /// Slope dy/dx.
    pub slope: f64,
    /// Share of the variance of y the line explains (R²; NaN when y does not vary).
    pub r2: f64,
}

/// The least-squares line through the points (x[i], y[i]); `None` for fewer than two points
/// or when x does not vary.
///
/// ```
/// let l = subfric_data::line::fit_line(&[0.0, 1.0, 2.0], &[1.0, 3.0, 5.0]).unwrap();
/// assert_eq!((l.intercept, l.slope, l.r2), (1.0, 2.0, 1.0));
/// assert!(subfric_data::line::fit_line(&[1.0, 1.0], &[0.0, 1.0]).is_none());
/// ```
pub fn fit_line(x: &[f64], y: &[f64]) -> Option<LineFit> {
    let n = x.len().min(y.len());
    if n < 2 {
        return None;
    }
    let (x, y) = (&x[..n], &y[..n]);
    let (xm, ym) = (
        x.iter().sum::<f64>() / n as f64,
        y.iter().sum::<f64>() / n as f64,
    );
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxx += (a - xm) * (a - xm);
        sxy += (a - xm) * (b - ym);
        syy += (b - ym) * (b - ym);
    }
    if sxx <= 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    Some(LineFit {
        intercept: ym - slope * xm,
        slope,
        r2: sxy * sxy / (sxx * syy),
    })
}
