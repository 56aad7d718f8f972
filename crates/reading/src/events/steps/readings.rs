//! What a step's window shows before any slider is fitted: the trend of the sliding before the
//! step, the measured change of steady friction, and first guesses of a, b, D_c and the spring.

use super::Window;
use crate::events::Estimate;
use crate::stats::LineFit;

/// The least-squares line of `y` on `x`; a level (slope 0 through the mean) when x does not
/// vary.
fn line(x: &[f64], y: &[f64]) -> LineFit {
    crate::stats::fit_line(x, y).unwrap_or_else(|| {
        let n = y.len().max(1) as f64;
        let mean = y.iter().sum::<f64>() / n;
        LineFit {
            intercept: mean,
            slope: 0.0,
            r2: f64::NAN,
            x_mean: x.iter().sum::<f64>() / n,
            sxx: 0.0,
            residual_ss: y.iter().map(|v| (v - mean).powi(2)).sum(),
            points: y.len(),
        }
    })
}

/// The change of steady friction measured on the record (the steadystate routine's reading):
/// the mean over the last 20 % of the new rate minus the extrapolation, to that time, of the
/// line through the friction before the step; its uncertainty from both, the residuals'
/// correlation counted.
pub(super) fn measured_change(w: &Window) -> Estimate {
    // Extrapolated in time, as the steadystate routine does (Giacomel et al. 2024).
    let pre_t = &w.time[..=w.step];
    let pre_mu = &w.mu[..=w.step];
    let pre = line(pre_t, pre_mu);
    let (p, q, sd, sxx, mt) = (
        pre.intercept,
        pre.slope,
        pre.residual_sd(),
        pre.sxx,
        pre.x_mean,
    );
    let n_post = w.mu.len() - w.step - 1;
    let tail = (n_post / 5).max(3).min(n_post);
    let tail_mu = &w.mu[w.mu.len() - tail..];
    let tail_t = &w.time[w.time.len() - tail..];
    let mean = tail_mu.iter().sum::<f64>() / tail as f64;
    let t_mid = tail_t.iter().sum::<f64>() / tail as f64;
    let extrapolated = p + q * t_mid;
    // Both parts share the record's noise, white plus a slow wander that the noise estimate
    // (from neighbouring rows) does not see: n correlated rows carry the information of n/τ.
    // The tail is short and sees only a piece of a wander, so its own spread and correlation
    // time understate them; the larger of the two parts' values is used for both.
    let pre_residuals = pre.residuals(pre_t, pre_mu);
    let tail_residuals: Vec<f64> = tail_mu.iter().map(|m| m - mean).collect();
    let tail_sd = {
        let v: f64 = tail_residuals.iter().map(|r| r * r).sum();
        (v / (tail as f64 - 1.0).max(1.0)).sqrt()
    };
    let sd = sd.max(tail_sd).max(w.sigma);
    let tau = crate::stats::correlation_time(&pre_residuals)
        .max(crate::stats::correlation_time(&tail_residuals));
    // A mean over fewer rows than τ varies as a single row does.
    let se_mean = sd * (tau / tail as f64).min(1.0).sqrt();
    let n_pre = pre_t.len() as f64;
    let se_extra = sd * (tau * (1.0 / n_pre + (t_mid - mt).powi(2) / sxx.max(1e-300))).sqrt();
    let value = mean - extrapolated;
    let se = (se_mean * se_mean + se_extra * se_extra).sqrt();
    Estimate::symmetric(value, 1.96 * se)
}

/// The trend of the sliding before the step, a line in load-point travel through the rows
/// before it: (friction at the step, slope per mm, standard error of the slope with the
/// residuals' correlation counted).
pub(super) fn pre_step_trend(w: &Window) -> (f64, f64, f64) {
    let pre_s = &w.travel[..=w.step];
    let pre_mu = &w.mu[..=w.step];
    let pre = line(pre_s, pre_mu);
    let (p, q, sd, sxx) = (pre.intercept, pre.slope, pre.residual_sd(), pre.sxx);
    let tau = crate::stats::correlation_time(&pre.residuals(pre_s, pre_mu));
    let se = sd.max(w.sigma) * (tau / sxx.max(1e-300)).sqrt();
    (p, q, se)
}

/// First guesses read off the window: (a, b, D_c, μ₀), the trend (p, q) removed.
pub(super) fn guesses(w: &Window, change: &Estimate, p: f64, q: f64) -> (f64, f64, f64, f64) {
    let ln = (w.v1 / w.v0).ln();
    let detrended: Vec<f64> = w
        .travel
        .iter()
        .zip(&w.mu)
        .map(|(s, m)| m - p - q * s)
        .collect();
    let post = &detrended[w.step + 1..];
    // The direct effect: the extreme excursion in the direction of the rate change, early on.
    let early = &post[..(post.len() / 3).max(3).min(post.len())];
    let extreme = if ln > 0.0 {
        early.iter().cloned().fold(f64::MIN, f64::max)
    } else {
        early.iter().cloned().fold(f64::MAX, f64::min)
    };
    let a = (extreme / ln).clamp(1e-4, 0.1);
    let b = a - change.value / ln;
    // D_c: slip over which the excursion falls by e towards the new level.
    let peak_at = early
        .iter()
        .position(|&v| v == extreme)
        .map_or(0, |k| k + w.step + 1);
    let target = change.value + (extreme - change.value) / std::f64::consts::E;
    let s_peak = w.travel[peak_at];
    let d_c = detrended[peak_at..]
        .iter()
        .position(|&v| (v - target) * ln.signum() <= 0.0)
        .map_or(0.2 * w.travel.last().copied().unwrap_or(1.0), |k| {
            (w.travel[peak_at + k] - s_peak).max(1e-4)
        });
    (a, b, d_c, p)
}

/// A first guess of the spring stiffness: the steepest rise of friction with load-point travel
/// over the first rows after the step (an elastic loading before the block speeds up).
pub(super) fn initial_slope(w: &Window) -> f64 {
    let base = w.mu[w.step];
    let sign = (w.v1 / w.v0).ln().signum();
    let k = w.travel[w.step + 1..]
        .iter()
        .zip(&w.mu[w.step + 1..])
        .take(8)
        .filter(|(s, _)| **s > 0.0)
        .map(|(s, m)| sign * (m - base) / s)
        .fold(0.0, f64::max);
    if k.is_finite() && k > 0.0 {
        k.clamp(0.1, 1e6)
    } else {
        1e3
    }
}
