//! What the hand-written solvers need from a problem, and nothing more (argmin's
//! capability-trait style): the solvers can then be tested on small problems with known
//! answers (the MINPACK set) instead of only through slow end-to-end calibrations.

/// A bounded nonlinear least-squares problem: minimise Σ rᵢ(x)² over lo ≤ x ≤ hi.
///
/// `Sync` because the global stage and the profiles evaluate points in parallel.
pub trait Residuals: Sync {
    /// Number of coordinates.
    fn dim(&self) -> usize;

    /// The box (lower, upper), each of length [`Residuals::dim`].
    fn bounds(&self) -> (&[f64], &[f64]);

    /// Writes the residual vector at `x` into `out` (cleared first). Its length must not
    /// depend on `x`.
    fn residuals_at(&self, x: &[f64], out: &mut Vec<f64>);

    /// Residuals that carry information, for degrees of freedom (residuals that are zero by
    /// construction, such as held-out rows, excluded). All of them unless overridden.
    fn observations(&self) -> usize {
        let mid: Vec<f64> = {
            let (lo, hi) = self.bounds();
            lo.iter().zip(hi).map(|(a, b)| 0.5 * (a + b)).collect()
        };
        let mut r = Vec::new();
        self.residuals_at(&mid, &mut r);
        r.len()
    }

    /// Sum of squared residuals at `x`.
    fn sum_of_squares(&self, x: &[f64]) -> f64 {
        let mut r = Vec::new();
        self.residuals_at(x, &mut r);
        r.iter().map(|v| v * v).sum()
    }

    /// Clamps `x` into the box; a NaN coordinate goes to the middle of its range. Written
    /// with `max`/`min` rather than `f64::clamp`, which panics on an inverted box.
    fn clamp_into_box(&self, x: &mut [f64]) {
        let (lo, hi) = self.bounds();
        for (i, v) in x.iter_mut().enumerate() {
            *v = if v.is_nan() {
                0.5 * (lo[i] + hi[i])
            } else {
                v.max(lo[i]).min(hi[i])
            };
        }
    }
}

/// The problem argmin's `Executor` hands a solver (this crate's, and `subfric-fit`'s
/// Nelder–Mead and differential evolution): an error, never a panic, should it hold none.
pub fn given<O>(problem: &argmin::core::Problem<O>) -> Result<&O, argmin::core::Error> {
    problem.problem.as_ref().ok_or_else(|| {
        argmin::core::ArgminError::NotInitialized {
            text: "the problem".into(),
        }
        .into()
    })
}
