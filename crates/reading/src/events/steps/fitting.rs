//! A spring-slider fitted to one step's window: both state laws, rigid and with a fitted
//! spring, the trend's uncertainty carried into the intervals of a, b and D_c, and the evidence
//! over the null model.

use super::null::fit_null;
use super::readings::{guesses, initial_slope, measured_change, pre_step_trend};
use super::rows::{resolved_dc_floor, row_travel, thin};
use super::{StepFit, Window};
use crate::events::slider::{Slider, StateLaw};
use crate::events::Estimate;
use subfric_solve::lm::{jacobian, levenberg_marquardt, LmOptions};
use subfric_solve::Residuals;

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

/// The 95 % intervals of a, b, D_c and a − b at the optimum `x` of `prob` (every row of the
/// window; `r` its residuals there, `s2` their variance scale): from the covariance with the
/// trend's own uncertainty `trend_se` added, widened to cover the reading with the trend fitted
/// over the whole window instead (from this optimum) — a wander after the step can pass for a
/// trend there, and one before it here; the record does not say which. The two are independent
/// refits on the `thinned` window and run side by side.
fn intervals_at_optimum(
    prob: &RsfProblem,
    thinned: &Window,
    f: &StepFitting,
    (x, law, compliant): (&[f64], StateLaw, bool),
    r: &[f64],
    s2: f64,
    trend_se: f64,
) -> (Estimate, Estimate, Estimate, Estimate) {
    let (cov, free_trend) = rayon::join(
        || {
            let mut cov = covariance(prob, x, r, s2);
            if let Some(c) = cov.as_mut() {
                add_trend_uncertainty(c, thinned, f, (x, law, compliant), trend_se);
            }
            cov
        },
        || readings_with_free_trend(prob.w, thinned, f, (x, law, compliant)),
    );
    let (mut a_est, mut b_est, mut dc_est, mut a_minus_b) = intervals(x, cov.as_deref());
    if let Some((a_j, b_j, dc_j, amb_j)) = free_trend {
        a_est = a_est.covering(&a_j);
        b_est = b_est.covering(&b_j);
        dc_est = dc_est.covering(&dc_j);
        a_minus_b = a_minus_b.covering(&amb_j);
    }
    (a_est, b_est, dc_est, a_minus_b)
}

/// Fits the rate-and-state slider to the window (both laws; rigid, and with a fitted spring
/// when `compliant_start` is given) and compares with the null model.
pub(in crate::events) fn fit_step(
    test: &str,
    w: &Window,
    compliant_start: Option<f64>,
) -> Option<StepFit> {
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
    // The intervals and the null model are independent fits from the optimum: they run side
    // by side (with a compliant slider and a short D_c each takes seconds on one core).
    let ((a_est, b_est, dc_est, a_minus_b), (null, null_length_mm)) = rayon::join(
        || {
            intervals_at_optimum(
                &prob,
                &thinned,
                &fitting,
                (&x, law, compliant),
                &r,
                s2,
                trend_se,
            )
        },
        || fit_null(w, mu0, trend, &change, span),
    );
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

/// The residuals of `p` at `x` on every row, their SSR, and the variance scale s² of the
/// covariance: the reduced χ² (at least 1) times the residuals' correlation time.
fn residuals_and_scale<R: Residuals>(p: &R, x: &[f64]) -> (Vec<f64>, f64, f64) {
    let mut r = Vec::new();
    p.residuals_at(x, &mut r);
    let ssr: f64 = r.iter().map(|v| v * v).sum();
    let tau = crate::stats::correlation_time(&r);
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
