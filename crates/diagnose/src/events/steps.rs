//! Each velocity step fitted on its own, as friction labs read a record: a window from the
//! steady sliding before the step to the end of the new rate, a linear trend in load-point
//! travel read off the sliding before the step and removed (the detrend window of xlook and of
//! the steadystate routine), then a spring-slider with rate and state ([`super::slider`]) in the
//! better of the ageing and slip laws, the spring stiffness fitted when the record resolves it.
//! The trend is not fitted with a, b and D_c: over the new rate a free trend trades against
//! a − b (a slow wander of the record after the transient reads as either), so the record
//! before the step decides it, and its uncertainty is carried into a, b and D_c. The null
//! model has no direct effect: a smooth change of level over a slip distance, which is all the
//! base model can do at a velocity step.

use super::slider::{Slider, StateLaw};
use super::{Estimate, TestView};
use serde::Serialize;
use subfric_data::line::LineFit;
use subfric_fit::lm::{jacobian, levenberg_marquardt, LmOptions};
use subfric_fit::Residuals;

/// One velocity step fitted on its own.
#[derive(Clone, Debug, Serialize)]
pub struct StepFit {
    /// Test.
    pub test: String,
    /// Row of the record where the step happens (last row at the old rate).
    pub row: usize,
    /// Time of the step [s].
    pub time_s: f64,
    /// Load-point rate before and after [mm/s].
    pub rate_before: f64,
    /// Rate after [mm/s].
    pub rate_after: f64,
    /// Rows of the window fitted.
    pub rows: usize,
    /// The state law that fits it better.
    pub law: StateLaw,
    /// Direct effect a (95 % interval).
    pub a: Estimate,
    /// Evolution effect b.
    pub b: Estimate,
    /// Characteristic slip D_c [mm].
    pub d_c_mm: Estimate,
    /// a − b: the change of steady friction per e-fold of rate.
    pub a_minus_b: Estimate,
    /// Spring stiffness [friction per mm] (infinite: the record does not resolve a compliance).
    pub stiffness_per_mm: f64,
    /// Normal stress of the window [kPa] (median), which turns the stiffness into kPa/mm.
    pub normal_kpa: f64,
    /// Slope of the linear trend removed, read off the sliding before the step [friction per
    /// mm of travel].
    pub trend_per_mm: f64,
    /// RMS misfit of the fit over the noise.
    pub rms_over_noise: f64,
    /// Evidence for a direct effect: (SSR of the null model − SSR of the rate-and-state fit)
    /// over the fit's variance scale (deviance units, like the diagnosis's D).
    pub evidence: f64,
    /// The change of steady friction measured on the record: the mean over the last 20 % of
    /// the new rate minus what the trend before the step extrapolates to at that time.
    pub measured_steady_change: Estimate,
    /// Whether the sign of (a − b) ln(v₁/v₀) agrees with the measured change, where that change
    /// exceeds its 95 % uncertainty and the fit determines a − b (a direct effect shown, the
    /// interval of a − b clear of zero); `None` elsewhere.
    pub sign_agrees: Option<bool>,
    /// The measured change of steady friction exceeds its 95 % uncertainty.
    pub steady_change_measured: bool,
    /// The least-squares runs converged.
    pub converged: bool,
    /// The load-point travel between two rows after the step (median) [mm].
    pub row_travel_mm: f64,
    /// The slip over which the best fit without a direct effect (the null model behind
    /// `evidence`) moves friction to its new level [mm].
    pub null_length_mm: f64,
}

impl StepFit {
    /// Whether (a − b) ln(v₁/v₀), by its value, has the sign of the measured change of steady
    /// friction (whether or not either is clear of zero).
    pub fn a_minus_b_agrees_with_measured_change(&self) -> bool {
        let ln = (self.rate_after / self.rate_before).ln();
        (self.a_minus_b.value * ln).signum() == self.measured_steady_change.value.signum()
    }

    /// A direct effect the record shows: strong evidence over the null model, and an a the
    /// step determines (its interval closed and within a factor of ten).
    pub fn significant(&self) -> bool {
        self.evidence >= super::STEP_EVIDENCE
            && self.a.lo > 0.0
            && self.a.hi.is_finite()
            && self.a.hi < 10.0 * self.a.lo
    }

    /// Whether the step can show a direct effect or its absence. Where either fit moves
    /// friction within a row — the best fit without a direct effect (an e-folding slip
    /// shorter than the travel between two rows), or the rate-and-state fit, its state
    /// relaxing within a row (D_c within twice the shortest the rows resolve: only a − b is
    /// read) — a jump of a ln(v₁/v₀) and an evolution that fast look the same, and the step
    /// counts neither way. A step that shows a direct effect resolves it.
    pub fn resolves_transient(&self) -> bool {
        self.significant()
            || (self.null_length_mm > self.row_travel_mm
                && self.d_c_mm.value > 2.0 * dc_floor_for(self.row_travel_mm))
    }
}

/// A velocity step's window in friction units: time, load-point travel from the step, rate.
pub(super) struct Window {
    pub time: Vec<f64>,
    pub travel: Vec<f64>,
    pub v_lp: Vec<f64>,
    pub mu: Vec<f64>,
    /// Index of the last row at the old rate.
    pub step: usize,
    pub v0: f64,
    pub v1: f64,
    /// Noise SD in friction.
    pub sigma: f64,
    /// Row of the record of the window's first row.
    pub first_row: usize,
    /// Median normal stress over the window [kPa].
    pub normal: f64,
}

/// The window of the step at row `c` of `t` (from the last half of the level before, at most
/// as long as the level after, to the end of the level after); `None` when the step is not a
/// change of sliding rate in one direction.
pub(super) fn window(t: &TestView, c: usize) -> Option<Window> {
    let seg = t.segmentation;
    let before = seg.levels.iter().find(|l| l.end == c + 1)?;
    let after = seg.levels.iter().find(|l| l.start == c + 1)?;
    let (v0, v1) = (before.rate, after.rate);
    if v0 * v1 <= 0.0 || !(v0.is_finite() && v1.is_finite()) || (v1 / v0).ln().abs() < 0.3 {
        return None;
    }
    let sign = v0.signum();
    let u = t.slip;
    let travel_after = (u[after.end - 1] - u[c]).abs();
    let travel_before = (u[c] - u[before.start]).abs();
    let pre = (0.5 * travel_before).min(travel_after.max(1e-9));
    let mut first = c;
    while first > before.start && (u[c] - u[first - 1]).abs() <= pre {
        first -= 1;
    }
    let end = after.end;
    if c - first < 5 || end - c < 10 {
        return None;
    }
    let rows = first..end;
    let time: Vec<f64> = rows.clone().map(|i| t.time[i]).collect();
    let travel: Vec<f64> = rows.clone().map(|i| sign * (u[i] - u[c])).collect();
    let mu: Vec<f64> = rows.clone().map(|i| sign * t.friction(i)).collect();
    let step = c - first;
    let v_lp: Vec<f64> = (0..time.len())
        .map(|k| if k <= step { v0.abs() } else { v1.abs() })
        .collect();
    let mut normals: Vec<f64> = rows.clone().map(|i| t.normal[i]).collect();
    normals.sort_by(f64::total_cmp);
    let normal = normals[normals.len() / 2];
    Some(Window {
        normal,
        time,
        travel,
        v_lp,
        mu,
        step,
        v0: v0.abs(),
        v1: v1.abs(),
        sigma: t.noise_friction,
        first_row: first,
    })
}

/// Coordinates of the rate-and-state fit: ln a, b, ln D_c, μ₀, the trend when it is fitted,
/// and ln k when the spring is fitted.
struct RsfProblem<'a> {
    w: &'a Window,
    law: StateLaw,
    compliant: bool,
    /// Slope of the trend removed [friction per mm of travel], when it is given.
    trend: f64,
    /// The trend is fitted (coordinate 4) rather than given.
    free_trend: bool,
    lo: Vec<f64>,
    hi: Vec<f64>,
}

impl RsfProblem<'_> {
    fn trend(&self, x: &[f64]) -> f64 {
        if self.free_trend {
            x[4]
        } else {
            self.trend
        }
    }
    fn k_index(&self) -> usize {
        4 + usize::from(self.free_trend)
    }
    fn slider(&self, x: &[f64]) -> Slider {
        Slider {
            law: self.law,
            a: x[0].exp(),
            b: x[1],
            d_c: x[2].exp(),
            k: if self.compliant {
                x[self.k_index()].exp()
            } else {
                f64::INFINITY
            },
            v0: self.w.v0,
            mu0: x[3],
        }
    }
}

/// Residual of a row the slider could not simulate (noise units): large but finite.
const FAILED: f64 = 1e3;

impl Residuals for RsfProblem<'_> {
    fn dim(&self) -> usize {
        self.lo.len()
    }
    fn bounds(&self) -> (&[f64], &[f64]) {
        (&self.lo, &self.hi)
    }
    fn residuals_at(&self, x: &[f64], out: &mut Vec<f64>) {
        out.clear();
        let w = self.w;
        let trend = self.trend(x);
        match self.slider(x).friction(&w.time, &w.v_lp) {
            Some(mu) => out.extend(
                mu.iter()
                    .zip(&w.travel)
                    .zip(&w.mu)
                    .map(|((m, s), y)| (m + trend * s - y) / w.sigma),
            ),
            None => out.extend(std::iter::repeat_n(FAILED, w.mu.len())),
        }
    }
}

/// The null model: μ₀ + trend·s before the step, plus Δ(1 − e^(−s/L)) after it; coordinates
/// μ₀, Δ, ln L (the trend is the rate-and-state fit's).
struct NullProblem<'a> {
    w: &'a Window,
    trend: f64,
    lo: Vec<f64>,
    hi: Vec<f64>,
}

impl Residuals for NullProblem<'_> {
    fn dim(&self) -> usize {
        3
    }
    fn bounds(&self) -> (&[f64], &[f64]) {
        (&self.lo, &self.hi)
    }
    fn residuals_at(&self, x: &[f64], out: &mut Vec<f64>) {
        out.clear();
        let w = self.w;
        let l = x[2].exp();
        out.extend(w.travel.iter().zip(&w.mu).map(|(&s, y)| {
            let change = if s > 0.0 {
                x[1] * (1.0 - (-s / l).exp())
            } else {
                0.0
            };
            (x[0] + self.trend * s + change - y) / w.sigma
        }));
    }
}

/// The least-squares line of `y` on `x`; a level (slope 0 through the mean) when x does not
/// vary.
fn line(x: &[f64], y: &[f64]) -> LineFit {
    subfric_data::line::fit_line(x, y).unwrap_or_else(|| {
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
fn measured_change(w: &Window) -> Estimate {
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
    let tau = subfric_fit::uncertainty::correlation_time(&pre_residuals)
        .max(subfric_fit::uncertainty::correlation_time(&tail_residuals));
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
fn pre_step_trend(w: &Window) -> (f64, f64, f64) {
    let pre_s = &w.travel[..=w.step];
    let pre_mu = &w.mu[..=w.step];
    let pre = line(pre_s, pre_mu);
    let (p, q, sd, sxx) = (pre.intercept, pre.slope, pre.residual_sd(), pre.sxx);
    let tau = subfric_fit::uncertainty::correlation_time(&pre.residuals(pre_s, pre_mu));
    let se = sd.max(w.sigma) * (tau / sxx.max(1e-300)).sqrt();
    (p, q, se)
}

/// First guesses read off the window: (a, b, D_c, μ₀), the trend (p, q) removed.
fn guesses(w: &Window, change: &Estimate, p: f64, q: f64) -> (f64, f64, f64, f64) {
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

/// What every fit of one step's slider shares: the bounds of its coordinates, the trend of the
/// sliding before the step (held fixed), and the solver's options.
struct StepFitting {
    /// μ₀ read off the window (the trend's value at the step).
    mu0: f64,
    /// Least D_c the record resolves [mm].
    dc_floor: f64,
    /// Load-point travel over the window [mm].
    span: f64,
    /// Slope of the trend before the step [1/mm].
    trend: f64,
    lm: LmOptions,
}

impl StepFitting {
    /// Bounds of (ln a, b, ln D_c, μ₀), and ln k for a compliant slider.
    fn bounds(&self, compliant: bool) -> (Vec<f64>, Vec<f64>) {
        let mut lo = vec![(1e-5f64).ln(), -0.2, self.dc_floor.ln(), self.mu0 - 0.3];
        let mut hi = vec![
            (0.2f64).ln(),
            0.2,
            (5.0 * self.span).max(2.0 * self.dc_floor).ln(),
            self.mu0 + 0.3,
        ];
        if compliant {
            lo.push((1e-2f64).ln());
            hi.push((1e7f64).ln());
        }
        (lo, hi)
    }

    /// The slider on window `w` with the trend `trend` held (or fitted, `free_trend`), within
    /// the bounds of [`Self::bounds`].
    fn problem<'w>(
        &self,
        w: &'w Window,
        law: StateLaw,
        compliant: bool,
        trend: f64,
    ) -> RsfProblem<'w> {
        let (lo, hi) = self.bounds(compliant);
        RsfProblem {
            w,
            law,
            compliant,
            trend,
            free_trend: false,
            lo,
            hi,
        }
    }
}

/// The best slider on the thinned window `w`: each law rigid from three D_c, then the law the
/// rigid fits prefer with a fitted spring (from its rigid optimum and the spring's first guess
/// `k_start`), which must pay for its parameter (BIC on the rows). Returns the coordinates,
/// the law, whether the spring was kept and whether its fit converged.
fn best_slider(
    w: &Window,
    f: &StepFitting,
    (a0, b0, dc0): (f64, f64, f64),
    k_start: f64,
) -> Option<(Vec<f64>, StateLaw, bool, bool)> {
    let mut best: Option<(f64, Vec<f64>, StateLaw, bool, bool)> = None;
    let mut consider = |cost: f64, x: Vec<f64>, law, compliant, converged| {
        if cost.is_finite() && best.as_ref().is_none_or(|b| cost < b.0) {
            best = Some((cost, x, law, compliant, converged));
        }
    };
    let mut rigid_optima = Vec::new();
    for law in [StateLaw::Ageing, StateLaw::Slip] {
        // The rigid slider integrates exactly per row: cheap, so it is started from three D_c.
        let rigid = f.problem(w, law, false, f.trend);
        let mut rigid_best: Option<(f64, Vec<f64>)> = None;
        for dc in [dc0, 3.0 * dc0, dc0 / 3.0] {
            let x0 = vec![
                a0.ln(),
                b0.clamp(-0.19, 0.19),
                dc.clamp(f.dc_floor, f.span.max(f.dc_floor)).ln(),
                f.mu0,
            ];
            let r = levenberg_marquardt(&rigid, &x0, None, &f.lm);
            if r.ssr.is_finite() && rigid_best.as_ref().is_none_or(|b| r.ssr < b.0) {
                rigid_best = Some((r.ssr, r.x.clone()));
            }
            consider(r.ssr, r.x, law, false, r.termination.converged());
        }
        if let Some((ssr, x)) = rigid_best {
            rigid_optima.push((ssr, x, law));
        }
    }
    // The compliant slider substeps within rows, which costs several rigid fits: it is fitted
    // once, for the law the rigid fits prefer, from that law's optimum (where the data put a,
    // b and D_c) with the spring's first guess.
    rigid_optima.sort_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((_, x_rigid, law)) = rigid_optima.into_iter().next() {
        let compliant = f.problem(w, law, true, f.trend);
        let mut x0 = x_rigid;
        x0.push(k_start.clamp(1.1e-2, 0.9e7).ln());
        let r = levenberg_marquardt(&compliant, &x0, None, &f.lm);
        // A fitted spring costs one parameter: it must pay for it (BIC on the rows).
        let penalty = (w.mu.len() as f64).ln();
        consider(r.ssr + penalty, r.x, law, true, r.termination.converged());
    }
    best.map(|(_, x, law, compliant, converged)| (x, law, compliant, converged))
}

/// Adds the trend's own uncertainty to the covariance `cov` of the optimum `x`: the fit on the
/// thinned window redone with the trend one standard error `trend_se` steeper moves every
/// coordinate together, by d; its share of the covariance is d dᵀ.
fn add_trend_uncertainty(
    cov: &mut [Vec<f64>],
    thinned: &Window,
    f: &StepFitting,
    (x, law, compliant): (&[f64], StateLaw, bool),
    trend_se: f64,
) {
    let shifted = f.problem(thinned, law, compliant, f.trend + trend_se);
    let refit = levenberg_marquardt(&shifted, x, None, &f.lm);
    if refit.ssr.is_finite() && refit.x.iter().all(|v| v.is_finite()) {
        let d: Vec<f64> = refit.x.iter().zip(x).map(|(s, v)| s - v).collect();
        for (i, row) in cov.iter_mut().enumerate() {
            for (k, v) in row.iter_mut().enumerate() {
                *v += d[i] * d[k];
            }
        }
    }
}

/// The intervals of a, b, D_c and a − b read with the trend fitted over the whole window
/// instead (from the optimum `x`, refitted on the thinned window, judged on every row of
/// `full`); `None` when that refit fails.
fn readings_with_free_trend(
    full: &Window,
    thinned: &Window,
    f: &StepFitting,
    (x, law, compliant): (&[f64], StateLaw, bool),
) -> Option<(Estimate, Estimate, Estimate, Estimate)> {
    let (mut lo, mut hi) = f.bounds(compliant);
    lo.insert(4, -2.0);
    hi.insert(4, 2.0);
    let mut x0 = x.to_vec();
    x0.insert(4, f.trend.clamp(-1.99, 1.99));
    let free = RsfProblem {
        w: thinned,
        law,
        compliant,
        trend: f.trend,
        free_trend: true,
        lo,
        hi,
    };
    let refit = levenberg_marquardt(&free, &x0, None, &f.lm);
    if !(refit.ssr.is_finite() && refit.x.iter().all(|v| v.is_finite())) {
        return None;
    }
    let on_all = RsfProblem { w: full, ..free };
    let (r, _, s2) = residuals_and_scale(&on_all, &refit.x);
    let mut xj = refit.x.clone();
    let cov_j = covariance(&on_all, &xj, &r, s2).map(|mut c| {
        // Drop the trend's row and column: the four shared coordinates stay in place.
        c.remove(4);
        c.iter_mut().for_each(|row| {
            row.remove(4);
        });
        c
    });
    xj.remove(4);
    Some(intervals(&xj, cov_j.as_deref()))
}

/// Fits the rate-and-state slider to the window (both laws; rigid, and with a fitted spring
/// when `compliant_start` is given) and compares with the null model.
pub(super) fn fit_step(test: &str, w: &Window, compliant_start: Option<f64>) -> Option<StepFit> {
    let change = measured_change(w);
    let (p_pre, trend, trend_se) = pre_step_trend(w);
    let (a0, b0, dc0, mu0) = guesses(w, &change, p_pre, trend);
    let span = w.travel.last().copied().unwrap_or(1.0).max(1e-3);
    let fitting = StepFitting {
        mu0,
        // D_c below a tenth of the slip between two rows is beyond what the record resolves
        // (the state would relax within one row); that floor also bounds the compliant
        // integration's substeps per row.
        dc_floor: resolved_dc_floor(w),
        span,
        trend,
        lm: LmOptions {
            max_iterations: 60,
            ..LmOptions::default()
        },
    };
    let k_start = compliant_start.unwrap_or_else(|| initial_slope(w));
    // The fits run on the window thinned: dense just after the step, where the transient is,
    // spaced as a share of the travel since the step further on (the guesses, the resolution
    // and the measured change above read every row).
    let full = w;
    let thinned = thin(full);
    let (x, law, compliant, converged) = best_slider(&thinned, &fitting, (a0, b0, dc0), k_start)?;
    // The optimum is judged on every row of the window: its misfit, the covariance and the
    // evidence against the null model (the thinned rows found it; all rows measure it).
    let w = full;
    let prob = RsfProblem {
        w,
        law,
        compliant,
        trend,
        free_trend: false,
        lo: vec![f64::NEG_INFINITY; x.len()],
        hi: vec![f64::INFINITY; x.len()],
    };
    let (r, ssr, s2) = residuals_and_scale(&prob, &x);
    let n = r.len();
    let mut cov = covariance(&prob, &x, &r, s2);
    if let Some(c) = cov.as_mut() {
        add_trend_uncertainty(c, &thinned, &fitting, (&x, law, compliant), trend_se);
    }
    let (mut a_est, mut b_est, mut dc_est, mut a_minus_b) = intervals(&x, cov.as_deref());
    // The reading with the trend fitted over the whole window instead (from this optimum): a
    // wander after the step can pass for a trend there, and one before it here; the record
    // does not say which, so each interval covers both readings.
    if let Some((a_j, b_j, dc_j, amb_j)) =
        readings_with_free_trend(full, &thinned, &fitting, (&x, law, compliant))
    {
        a_est = a_est.covering(&a_j);
        b_est = b_est.covering(&b_j);
        dc_est = dc_est.covering(&dc_j);
        a_minus_b = a_minus_b.covering(&amb_j);
    }
    let (null, null_length_mm) = fit_null(w, mu0, trend, &change, span);
    let evidence = (null - ssr) / s2;
    let change_measured = change.excludes_zero();
    let mut fit = StepFit {
        test: test.to_string(),
        row: full.first_row + full.step,
        time_s: full.time[full.step],
        rate_before: w.v0,
        rate_after: w.v1,
        rows: n,
        law,
        a: a_est,
        b: b_est,
        d_c_mm: dc_est,
        a_minus_b,
        stiffness_per_mm: if compliant {
            x[prob.k_index()].exp()
        } else {
            f64::INFINITY
        },
        normal_kpa: w.normal,
        trend_per_mm: trend,
        rms_over_noise: (ssr / n.max(1) as f64).sqrt(),
        evidence,
        measured_steady_change: change,
        sign_agrees: None,
        steady_change_measured: change_measured,
        converged,
        row_travel_mm: row_travel(full),
        null_length_mm,
    };
    // The fit claims a sign of a − b only where it determines it: a direct effect shown (a
    // fit that finds none has no a and b to speak of) and the interval of a − b clear of zero.
    if change_measured && fit.significant() && fit.a_minus_b.excludes_zero() {
        fit.sign_agrees = Some(fit.a_minus_b_agrees_with_measured_change());
    }
    Some(fit)
}

/// 95 % intervals of a, b, D_c and a − b at the coordinates `x` (ln a, b, ln D_c, …) with
/// covariance `cov` (unbounded where it is `None`).
fn intervals(x: &[f64], cov: Option<&[Vec<f64>]>) -> (Estimate, Estimate, Estimate, Estimate) {
    let z = 1.96;
    let se = |k: usize| cov.map_or(f64::INFINITY, |c| c[k][k].max(0.0).sqrt());
    let a = x[0].exp();
    let log_interval = |k: usize| Estimate {
        value: x[k].exp(),
        lo: (x[k] - z * se(k)).exp(),
        hi: (x[k] + z * se(k)).exp(),
    };
    // Var(a − b) with a = e^x₀: ∂/∂x₀ = a, ∂/∂x₁ = −1.
    let amb_se = cov.map_or(f64::INFINITY, |c| {
        (a * a * c[0][0] + c[1][1] - 2.0 * a * c[0][1])
            .max(0.0)
            .sqrt()
    });
    (
        log_interval(0),
        Estimate::symmetric(x[1], z * se(1)),
        log_interval(2),
        Estimate::symmetric(a - x[1], z * amb_se),
    )
}

/// Rows of the window kept before the step, at most.
const THIN_BEFORE: usize = 80;
/// After the step a row is kept once the travel since the last kept row reaches this share of
/// the travel since the step: about 100 rows per e-fold of travel.
const THIN_SHARE: f64 = 0.01;

/// The window with its rows thinned (see [`THIN_BEFORE`], [`THIN_SHARE`]); the step's rows and
/// the last row are always kept.
fn thin(w: &Window) -> Window {
    let stride = (w.step + 1).div_ceil(THIN_BEFORE).max(1);
    let mut keep: Vec<usize> = (0..=w.step).rev().step_by(stride).collect();
    keep.reverse();
    let n = w.travel.len();
    if w.step + 1 < n {
        let mut last = w.step + 1;
        keep.push(last);
        for i in w.step + 2..n {
            let since = w.travel[i].abs();
            if (w.travel[i] - w.travel[last]).abs() >= THIN_SHARE * since || i + 1 == n {
                keep.push(i);
                last = i;
            }
        }
    }
    let pick = |v: &[f64]| keep.iter().map(|&i| v[i]).collect::<Vec<f64>>();
    Window {
        time: pick(&w.time),
        travel: pick(&w.travel),
        v_lp: pick(&w.v_lp),
        mu: pick(&w.mu),
        step: keep.iter().position(|&i| i == w.step).unwrap_or(0),
        v0: w.v0,
        v1: w.v1,
        sigma: w.sigma,
        first_row: w.first_row,
        normal: w.normal,
    }
}

/// A tenth of the travel between two rows after the step: the shortest D_c the record can
/// tell from zero.
fn resolved_dc_floor(w: &Window) -> f64 {
    dc_floor_for(row_travel(w))
}

/// The shortest D_c resolved where the rows lie `row_travel` mm apart (a tenth of it, at least
/// 10 nm).
fn dc_floor_for(row_travel: f64) -> f64 {
    (0.1 * row_travel).max(1e-5)
}

/// The median load-point travel between two rows after the step (0 when the rows do not
/// move).
fn row_travel(w: &Window) -> f64 {
    let mut steps: Vec<f64> = w.travel[w.step..]
        .windows(2)
        .map(|p| (p[1] - p[0]).abs())
        .filter(|d| *d > 0.0)
        .collect();
    if steps.is_empty() {
        return 0.0;
    }
    steps.sort_by(f64::total_cmp);
    steps[steps.len() / 2]
}

/// A first guess of the spring stiffness: the steepest rise of friction with load-point travel
/// over the first rows after the step (an elastic loading before the block speeds up).
fn initial_slope(w: &Window) -> f64 {
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

/// SSR of the best null model (no direct effect) and the slip over which its change happens
/// [mm].
fn fit_null(w: &Window, mu0: f64, trend: f64, change: &Estimate, span: f64) -> (f64, f64) {
    let prob = NullProblem {
        w,
        trend,
        lo: vec![mu0 - 0.3, -0.3, (1e-5f64).ln()],
        hi: vec![mu0 + 0.3, 0.3, (10.0 * span).ln()],
    };
    let lm = LmOptions {
        max_iterations: 60,
        ..LmOptions::default()
    };
    [0.02, 0.1, 0.5]
        .iter()
        .map(|f| {
            let x0 = vec![mu0, change.value.clamp(-0.29, 0.29), (f * span).ln()];
            let r = levenberg_marquardt(&prob, &x0, None, &lm);
            (r.ssr, r.x[2].exp())
        })
        .fold((f64::INFINITY, f64::NAN), |best, r| {
            if r.0 < best.0 {
                r
            } else {
                best
            }
        })
}

/// The residuals of `p` at `x` on every row, their SSR, and the variance scale s² of the
/// covariance: the reduced χ² (at least 1) times the residuals' correlation time.
fn residuals_and_scale<R: Residuals>(p: &R, x: &[f64]) -> (Vec<f64>, f64, f64) {
    let mut r = Vec::new();
    p.residuals_at(x, &mut r);
    let ssr: f64 = r.iter().map(|v| v * v).sum();
    let tau = subfric_fit::uncertainty::correlation_time(&r);
    let s2 = (ssr / (r.len().saturating_sub(x.len())).max(1) as f64).max(1.0) * tau;
    (r, ssr, s2)
}

/// s² (JᵀJ)⁻¹ at `x`, or `None` when JᵀJ is singular.
fn covariance<R: Residuals>(p: &R, x: &[f64], r: &[f64], s2: f64) -> Option<Vec<Vec<f64>>> {
    let j = jacobian(p, x, r, None);
    let jtj = j.transpose() * &j;
    let inv = jtj.try_inverse()?;
    let m = x.len();
    Some(
        (0..m)
            .map(|i| (0..m).map(|k| s2 * inv[(i, k)]).collect())
            .collect(),
    )
}

#[cfg(test)]
#[path = "steps_tests.rs"]
mod tests;
