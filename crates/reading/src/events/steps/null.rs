//! The null model of a step: friction moving to its new level over a slip, with no direct
//! effect, which is all the base model can do at a velocity step.

use super::Window;
use crate::events::Estimate;
use subfric_solve::lm::{levenberg_marquardt, LmOptions};
use subfric_solve::Residuals;

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

/// SSR of the best null model (no direct effect) and the slip over which its change happens
/// [mm].
pub(super) fn fit_null(
    w: &Window,
    mu0: f64,
    trend: f64,
    change: &Estimate,
    span: f64,
) -> (f64, f64) {
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
