//! The few statistics every crate of subfric reads records with, in one place: the median
//! (the mean of the middle two of an even count) and the upper median (a value of the data
//! itself: the middle one, or the upper of the middle two), NaN sorting last by `total_cmp`;
//! and the autocorrelation of a series by FFT with its integrated time (Sokal's window), which
//! the fit's correlated-residual intervals, the velocity steps' readings and the posterior's
//! convergence read (`correlation_time`); the mean and unbiased variance, the two-sided 95 %
//! quantiles of the normal and of Student's t; the
//! least-squares straight line ([`line`]).

pub mod line;

pub use line::{fit_line, fit_weighted_line, LineFit, WeightedLine};

/// The median of `v` (sorted in place): the middle value, the mean of the middle two for an
/// even count; `None` when empty.
///
/// ```
/// use subfric_reading::stats::median;
/// assert_eq!(median(&mut [3.0, 1.0, 2.0]), Some(2.0));
/// assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), Some(2.5));
/// assert_eq!(median(&mut []), None);
/// ```
pub fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    Some(if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    })
}

/// The upper median of `v` (sorted in place): the middle value, the upper of the middle two
/// for an even count — always one of the values, where a reading of the record itself is
/// wanted rather than a point between two; `None` when empty.
///
/// ```
/// use subfric_reading::stats::upper_median;
/// assert_eq!(upper_median(&mut [4.0, 1.0, 3.0, 2.0]), Some(3.0));
/// assert_eq!(upper_median(&mut [3.0, 1.0, 2.0]), Some(2.0));
/// ```
pub fn upper_median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

/// The `q` quantile of `sorted` (ascending), linear between order statistics (the 0.25 of
/// four values lies three quarters of the way from the first to the second); `q` is clamped to
/// 0..=1; NaN when empty.
///
/// ```
/// use subfric_reading::stats::quantile;
/// assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0], 0.5), 2.5);
/// assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0], 0.25), 1.75);
/// assert_eq!(quantile(&[7.0], 0.9), 7.0);
/// assert!(quantile(&[], 0.5).is_nan());
/// ```
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let pos = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let i = pos.floor() as usize;
    let f = pos - i as f64;
    match sorted.get(i + 1) {
        Some(next) => sorted[i] + f * (next - sorted[i]),
        None => sorted[i],
    }
}

/// Sokal's window constant: the autocorrelation function is summed up to the first lag M with
/// M ≥ c·τ(M) (emcee's `c = 5`).
pub const SOKAL_WINDOW: f64 = 5.0;

/// Integrated autocorrelation time of an ensemble's series (one slice per walker, equal
/// lengths), as emcee's `integrated_time`: the normalised autocorrelation function of each
/// walker, averaged over the walkers, summed as τ(M) = 1 + 2 Σ_{k=1}^{M} ρ_k up to Sokal's
/// window (the first M with M ≥ 5 τ(M)). A walker that never moves counts as perfectly
/// correlated (ρ_k = 1); if none moves, τ is infinite.
///
/// ```
/// use subfric_reading::stats::integrated_time;
/// // White noise has τ = 1.
/// let mut state = 7u64;
/// let mut next = || { state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407); (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5 };
/// let walkers: Vec<Vec<f64>> = (0..8).map(|_| (0..4000).map(|_| next()).collect()).collect();
/// let views: Vec<&[f64]> = walkers.iter().map(|w| w.as_slice()).collect();
/// assert!((integrated_time(&views) - 1.0).abs() < 0.2);
/// ```
pub fn integrated_time(walkers: &[&[f64]]) -> f64 {
    let n = walkers.iter().map(|w| w.len()).min().unwrap_or(0);
    integrated_time_within(walkers, n)
}

/// [`integrated_time`] with the sum stopped at lag `max_lag` at the latest (where Sokal's
/// window has not closed by then, τ so far).
pub fn integrated_time_within(walkers: &[&[f64]], max_lag: usize) -> f64 {
    let n = walkers.iter().map(|w| w.len()).min().unwrap_or(0);
    if n < 2 || walkers.is_empty() {
        return f64::INFINITY;
    }
    let mut mean_acf = vec![0.0; n];
    let mut moving = 0;
    for w in walkers {
        match autocorrelation(&w[..n]) {
            Some(acf) => {
                moving += 1;
                for (m, a) in mean_acf.iter_mut().zip(&acf) {
                    *m += a;
                }
            }
            None => mean_acf.iter_mut().for_each(|m| *m += 1.0),
        }
    }
    if moving == 0 {
        return f64::INFINITY;
    }
    let count = walkers.len() as f64;
    let mut tau = 1.0;
    for (k, a) in mean_acf.iter().enumerate().take(max_lag).skip(1) {
        tau += 2.0 * a / count;
        if k as f64 >= SOKAL_WINDOW * tau {
            return tau;
        }
    }
    tau
}

/// The mean and the unbiased variance (n − 1 in the denominator; 0 for a single value) of
/// `x`; the mean is NaN when `x` is empty.
pub fn mean_var(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = if x.len() > 1 {
        x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    (m, v)
}

/// Two-sided 95 % quantile of the normal distribution.
pub const Z95: f64 = 1.959_964;

/// Two-sided 95 % quantile of Student's t with `dof` degrees of freedom (a table to 10, then
/// an approximation; infinite at none).
pub fn student_t95(dof: usize) -> f64 {
    const TABLE: [f64; 10] = [
        12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
    ];
    match dof {
        0 => f64::INFINITY,
        1..=10 => TABLE[dof - 1],
        11..=20 => 2.2 - 0.01 * (dof as f64 - 10.0).min(10.0) * 1.14,
        _ => 1.96 + 2.4 / dof as f64,
    }
}

/// Fewest residuals of a test for its autocorrelation to be estimated (fewer: taken as
/// independent).
const MIN_CORRELATION_ROWS: usize = 20;

/// Integrated autocorrelation time τ = 1 + 2 Σ_{k=1}^{W} ρ_k of a residual sequence (rows, in
/// row order), with Sokal's automatic window ([`integrated_time`], the one
/// the posterior's convergence reads, summed to half the series at most); at least 1. For independent residuals τ ≈ 1;
/// for residuals correlated over many rows τ is the number of rows that carry as much
/// information as one independent row: n_eff = n/τ (for an AR(1) sequence of lag-one
/// correlation ρ, τ = (1 + ρ)/(1 − ρ)).
///
/// ```
/// use subfric_reading::stats::correlation_time;
/// // An AR(1) sequence with ρ = 0.8 (τ = 9), from a small deterministic generator.
/// let mut state = 12345u64;
/// let mut uniform = || { state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407); (state >> 11) as f64 / (1u64 << 53) as f64 };
/// let mut r = vec![0.0f64];
/// for _ in 0..20_000 {
///     let u: f64 = (0..12).map(|_| uniform()).sum::<f64>() - 6.0;
///     let last = *r.last().unwrap();
///     r.push(0.8 * last + 0.6 * u);
/// }
/// let tau = correlation_time(&r);
/// assert!((tau - 9.0).abs() < 1.5, "{tau}");
/// ```
pub fn correlation_time(r: &[f64]) -> f64 {
    let v: Vec<f64> = r.iter().copied().filter(|x| x.is_finite()).collect();
    let n = v.len();
    if n < MIN_CORRELATION_ROWS {
        return 1.0;
    }
    let tau = integrated_time_within(&[&v], n / 2);
    // A constant sequence has no autocorrelation to read: independent.
    if tau.is_finite() {
        tau.max(1.0)
    } else {
        1.0
    }
}

/// Normalised autocorrelation ρ_k (k = 0..n) of a series by FFT (the `realfft` crate: the
/// power spectrum of the zero-padded series, transformed back); `None` when it is constant.
pub fn autocorrelation(x: &[f64]) -> Option<Vec<f64>> {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    // Zero-padded to at least 2n: the circular correlation then holds the linear one.
    let size = (2 * n).next_power_of_two();
    let mut planner = realfft::RealFftPlanner::<f64>::new();
    let forward = planner.plan_fft_forward(size);
    let inverse = planner.plan_fft_inverse(size);
    let mut series = forward.make_input_vec();
    for (r, v) in series.iter_mut().zip(x) {
        *r = v - mean;
    }
    let mut spectrum = forward.make_output_vec();
    forward.process(&mut series, &mut spectrum).ok()?;
    for c in spectrum.iter_mut() {
        *c = realfft::num_complex::Complex::new(c.norm_sqr(), 0.0);
    }
    // The inverse is unnormalised: dividing by lag 0 cancels the scale.
    let mut correlation = inverse.make_output_vec();
    inverse.process(&mut spectrum, &mut correlation).ok()?;
    let c0 = correlation[0];
    if !(c0 > 0.0 && c0.is_finite()) {
        return None;
    }
    Some(correlation[..n].iter().map(|c| c / c0).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_t_quantile_falls_towards_the_normal_one() {
        assert!(student_t95(1) > student_t95(5));
        assert!(student_t95(15) > student_t95(40));
        assert!((student_t95(1000) - 1.96).abs() < 0.01);
        assert!((student_t95(20) - 2.086).abs() < 0.05);
    }

    #[test]
    fn the_integrated_time_sums_the_autocorrelation_up_to_its_lag_limit() {
        // A deterministic, strongly correlated series (a slow sine with a small wiggle).
        let x: Vec<f64> = (0..400)
            .map(|i| (i as f64 / 40.0).sin() + 0.1 * ((i * 7919 % 13) as f64 - 6.0) / 6.0)
            .collect();
        let rho = autocorrelation(&x).unwrap();
        // The direct sum of the normalised autocorrelation at lag 1 and 2.
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let d: Vec<f64> = x.iter().map(|v| v - mean).collect();
        let c = |k: usize| -> f64 {
            d[..d.len() - k]
                .iter()
                .zip(&d[k..])
                .map(|(a, b)| a * b)
                .sum()
        };
        for (k, r) in rho.iter().enumerate().take(3).skip(1) {
            assert!((r - c(k) / c(0)).abs() < 1e-12, "lag {k}");
        }
        // Stopped at lag 3 (lags 1 and 2 summed): τ = 1 + 2 (ρ₁ + ρ₂), the window still open.
        let tau = integrated_time_within(&[&x], 3);
        assert!(
            (tau - (1.0 + 2.0 * (rho[1] + rho[2]))).abs() < 1e-12,
            "{tau}"
        );
        // Without the limit the sum goes on until Sokal's window closes, or to the end.
        assert!(integrated_time(&[&x]) > tau);
        // A constant series has no autocorrelation: infinite time.
        assert!(integrated_time(&[&[1.0; 30][..]]).is_infinite());
    }
}
