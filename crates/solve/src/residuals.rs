//! What the hand-written solvers need from a problem, and nothing more (argmin's
//! capability-trait style): the solvers can then be tested on small problems with known
//! answers (the MINPACK set) instead of only through slow end-to-end calibrations.

/// How an evaluation given a ceiling ended ([`Residuals::residuals_unless_above`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bounded {
    /// Every residual was computed.
    Computed,
    /// The evaluation stopped once its sum of squares was sure to end above the ceiling (or to
    /// be NaN); the residuals it wrote mean nothing.
    Above,
}

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

    /// The residuals at `x` as [`Residuals::residuals_at`] writes them, unless their sum of
    /// squares (added in order, as the solvers add it) is sure to end above `ceiling` or to
    /// be NaN: then [`Bounded::Above`], possibly before the whole model has run. An optimiser
    /// that only asks whether a trial point beats its current one stops a trial that already
    /// does not; the answer, and every point it accepts, are those of the full evaluation.
    /// The default computes everything.
    fn residuals_unless_above(&self, x: &[f64], out: &mut Vec<f64>, ceiling: f64) -> Bounded {
        let _ = ceiling;
        self.residuals_at(x, out);
        Bounded::Computed
    }

    /// The sum of squared residuals at `x`, or `None` where
    /// [`Residuals::residuals_unless_above`] stops above `ceiling`.
    fn sum_of_squares_unless_above(&self, x: &[f64], ceiling: f64) -> Option<f64> {
        let mut r = Vec::new();
        match self.residuals_unless_above(x, &mut r, ceiling) {
            Bounded::Computed => Some(r.iter().map(|v| v * v).sum()),
            Bounded::Above => None,
        }
    }

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
