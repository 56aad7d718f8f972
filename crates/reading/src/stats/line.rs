//! The least-squares straight line, for the readings of a record that are lines: the motion
//! either side of an event boundary, an elastic unload, the friction before a velocity step,
//! a residual stress ratio past the peak, the peak gain of holds against log hold time, a
//! stress ratio against the normal stress. One place, so that every reading's line and its
//! standard errors are computed alike.

/// A least-squares line y = intercept + slope · x, with what its standard errors need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineFit {
    /// Value at x = 0.
    pub intercept: f64,
    /// Slope dy/dx.
    pub slope: f64,
    /// Share of the variance of y the line explains (R²; NaN when y does not vary).
    pub r2: f64,
    /// Mean of x.
    pub x_mean: f64,
    /// Σ (x − x̄)².
    pub sxx: f64,
    /// Sum of squared residuals y − line.
    pub residual_ss: f64,
    /// Number of points.
    pub points: usize,
}

impl LineFit {
    /// The line's value at `x`.
    pub fn at(&self, x: f64) -> f64 {
        self.intercept + self.slope * x
    }

    /// Residual standard deviation, √(SS / (n − 2)) (the divisor at least 1).
    pub fn residual_sd(&self) -> f64 {
        (self.residual_ss / (self.points as f64 - 2.0).max(1.0)).sqrt()
    }

    /// Residuals y − line, point by point.
    pub fn residuals(&self, x: &[f64], y: &[f64]) -> Vec<f64> {
        x.iter().zip(y).map(|(a, b)| b - self.at(*a)).collect()
    }
}

/// The least-squares line through the points (x[i], y[i]); `None` for fewer than two points
/// or when x does not vary.
///
/// ```
/// let l = subfric_reading::stats::fit_line(&[0.0, 1.0, 2.0], &[1.0, 3.0, 5.0]).unwrap();
/// assert_eq!((l.intercept, l.slope, l.r2), (1.0, 2.0, 1.0));
/// assert_eq!((l.x_mean, l.sxx, l.residual_ss, l.points), (1.0, 2.0, 0.0, 3));
/// assert!(subfric_reading::stats::fit_line(&[1.0, 1.0], &[0.0, 1.0]).is_none());
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
    let intercept = ym - slope * xm;
    let residual_ss = x
        .iter()
        .zip(y)
        .map(|(a, b)| (b - intercept - slope * a).powi(2))
        .sum();
    Some(LineFit {
        intercept,
        slope,
        r2: sxy * sxy / (sxx * syy),
        x_mean: xm,
        sxx,
        residual_ss,
        points: n,
    })
}

/// A weighted least-squares line y = intercept + slope · x with its covariance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WeightedLine {
    /// Value at x = 0.
    pub intercept: f64,
    /// Slope dy/dx.
    pub slope: f64,
    /// Variance of the intercept.
    pub var_intercept: f64,
    /// Variance of the slope.
    pub var_slope: f64,
    /// Covariance of intercept and slope.
    pub cov: f64,
}

/// Weighted least squares through (x[i], y[i]) with weights w[i] (inverse variances): the
/// covariance is inflated by the scatter beyond the points' own errors (χ²/(n − 2), never
/// below 1) when there are more points than parameters. `None` when x does not vary or the
/// weights sum to nothing.
///
/// ```
/// let l = subfric_reading::stats::fit_weighted_line(&[0.0, 1.0], &[1.0, 3.0], &[1.0, 1.0]).unwrap();
/// assert_eq!((l.intercept, l.slope), (1.0, 2.0));
/// // Two points of unit variance: var(slope) = 1/Σw(x − x̄)² = 2.
/// assert_eq!(l.var_slope, 2.0);
/// ```
pub fn fit_weighted_line(x: &[f64], y: &[f64], w: &[f64]) -> Option<WeightedLine> {
    let sw: f64 = w.iter().sum();
    let mx = x.iter().zip(w).map(|(x, w)| x * w).sum::<f64>() / sw;
    let my = y.iter().zip(w).map(|(y, w)| y * w).sum::<f64>() / sw;
    let sxx: f64 = x.iter().zip(w).map(|(x, w)| w * (x - mx) * (x - mx)).sum();
    if !(sxx > 0.0 && sw > 0.0) {
        return None;
    }
    let b = x
        .iter()
        .zip(y)
        .zip(w)
        .map(|((x, y), w)| w * (x - mx) * (y - my))
        .sum::<f64>()
        / sxx;
    let a = my - b * mx;
    let n = x.len();
    let inflation = if n > 2 {
        let chi2: f64 = x
            .iter()
            .zip(y)
            .zip(w)
            .map(|((x, y), w)| w * (y - a - b * x).powi(2))
            .sum();
        (chi2 / (n - 2) as f64).max(1.0)
    } else {
        1.0
    };
    Some(WeightedLine {
        intercept: a,
        slope: b,
        var_intercept: inflation * (1.0 / sw + mx * mx / sxx),
        var_slope: inflation / sxx,
        cov: -inflation * mx / sxx,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_residual_sd_of_a_noisy_line_is_its_scatter() {
        // Residuals ±1 alternating around y = 2x: SS = n, SD = √(n/(n − 2)).
        let x: Vec<f64> = (0..10).map(f64::from).collect();
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, v)| 2.0 * v + if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let l = fit_line(&x, &y).unwrap();
        assert!(
            (l.residual_ss - l.residuals(&x, &y).iter().map(|r| r * r).sum::<f64>()).abs() < 1e-12
        );
        assert!((l.residual_sd() - (l.residual_ss / 8.0).sqrt()).abs() < 1e-12);
        assert!((l.slope - 2.0).abs() < 0.1, "{l:?}");
    }

    #[test]
    fn weights_pull_the_line_towards_the_sure_points() {
        // Two sure points on y = x and one unsure point far off: the line keeps to y = x, and
        // the scatter of the unsure point beyond its error inflates the covariance.
        let l = fit_weighted_line(&[0.0, 1.0, 2.0], &[0.0, 1.0, 10.0], &[1e6, 1e6, 1e-6]).unwrap();
        assert!(
            (l.slope - 1.0).abs() < 1e-3 && l.intercept.abs() < 1e-3,
            "{l:?}"
        );
        let none = fit_weighted_line(&[1.0, 1.0], &[0.0, 1.0], &[1.0, 1.0]);
        assert!(none.is_none());
    }
}
