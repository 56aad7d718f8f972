//! The damping λ of Levenberg–Marquardt and how it moves between trials: by how well the
//! linearisation predicted the decrease the step achieved (the gain ratio), not by fixed
//! factors — Nielsen's rule (H. B. Nielsen, "Damping parameter in Marquardt's method",
//! IMM-REP-1999-05, DTU, 1999; Madsen, Nielsen and Tingleff, "Methods for non-linear least
//! squares problems", 2004, Section 3.2).
//!
//! Fixed factors (divide after a success, multiply after a failure) make the damping swing
//! across the value the problem needs: every other trial then fails, and each failed trial is a
//! whole evaluation of the residuals (a model run in a calibration). The gain ratio
//! ρ = actual decrease / predicted decrease tells how far to trust the linearisation: a step
//! predicted well (ρ near 1) lowers λ by up to 3, one predicted badly but still downhill
//! (ρ near 0) raises it by up to 2, so the next trial is already damped enough. After a failure
//! λ grows by ν, and ν doubles with every failure in a row, so a run at a kink reaches the
//! damping limit in a few trials instead of a long ladder of equal factors.

/// The damping of the next trial and the factor of the next failure.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Damping {
    /// λ, relative to D² = diag JᵀJ.
    pub(crate) lambda: f64,
    /// Factor of λ after the next failed trial.
    nu: f64,
}

/// ν after a success: the first failure after it doubles λ.
const FIRST_FAILURE_FACTOR: f64 = 2.0;

/// The most a well-predicted step lowers λ by.
const MOST_DECREASE: f64 = 3.0;

impl Damping {
    /// Damping `lambda` before any trial.
    pub(crate) fn new(lambda: f64) -> Damping {
        Damping {
            lambda,
            nu: FIRST_FAILURE_FACTOR,
        }
    }

    /// After a step that lowered the cost with gain ratio `rho` (> 0): λ times
    /// max(1/3, 1 − (2ρ − 1)³), floored at `min`.
    pub(crate) fn accepted(&mut self, rho: f64, min: f64) {
        let rho = if rho.is_finite() { rho } else { 0.0 };
        let factor = (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / MOST_DECREASE);
        self.lambda = (self.lambda * factor).max(min);
        self.nu = FIRST_FAILURE_FACTOR;
    }

    /// After a trial that did not lower the cost (or could not be computed): λ times ν, and ν
    /// doubles.
    pub(crate) fn rejected(&mut self) {
        self.lambda *= self.nu;
        self.nu *= 2.0;
    }
}

/// The gain ratio of a step: the decrease of the cost it achieved, `ssr − ssr_trial`, over the
/// decrease its linearisation predicted, `ssr − ‖r + J δ‖²` (`linear_ssr`); 0 when the
/// linearisation predicted none (a step taken only because the box cut it, say).
pub(crate) fn gain_ratio(ssr: f64, ssr_trial: f64, linear_ssr: f64) -> f64 {
    let predicted = ssr - linear_ssr;
    if predicted > 0.0 {
        (ssr - ssr_trial) / predicted
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_predicted_exactly_lowers_the_damping_by_three_and_a_poor_one_raises_it() {
        let mut d = Damping::new(1.0);
        d.accepted(1.0, 1e-12);
        assert!((d.lambda - 1.0 / 3.0).abs() < 1e-15, "{d:?}");
        // Half the predicted decrease: λ stays.
        let mut d = Damping::new(1.0);
        d.accepted(0.5, 1e-12);
        assert!((d.lambda - 1.0).abs() < 1e-15, "{d:?}");
        // Downhill but barely as predicted: λ nearly doubles.
        let mut d = Damping::new(1.0);
        d.accepted(1e-6, 1e-12);
        assert!(d.lambda > 1.99 && d.lambda < 2.0, "{d:?}");
        // Better than predicted (ρ > 1) is trusted no more than an exact prediction.
        let mut d = Damping::new(1.0);
        d.accepted(5.0, 1e-12);
        assert!((d.lambda - 1.0 / 3.0).abs() < 1e-15, "{d:?}");
        // The floor holds.
        let mut d = Damping::new(1e-12);
        d.accepted(1.0, 1e-12);
        assert_eq!(d.lambda, 1e-12);
    }

    #[test]
    fn failures_in_a_row_grow_the_damping_faster_and_a_success_resets_the_growth() {
        let mut d = Damping::new(1.0);
        for want in [2.0, 8.0, 64.0, 1024.0] {
            d.rejected();
            assert_eq!(d.lambda, want);
        }
        d.accepted(0.5, 0.0);
        d.rejected();
        assert_eq!(
            d.lambda, 2048.0,
            "after a success the next failure only doubles λ"
        );
    }

    #[test]
    fn the_gain_ratio_compares_the_actual_decrease_with_the_predicted_one() {
        assert_eq!(gain_ratio(10.0, 4.0, 4.0), 1.0);
        assert_eq!(gain_ratio(10.0, 7.0, 4.0), 0.5);
        assert!(
            gain_ratio(10.0, 11.0, 4.0) < 0.0,
            "a rise is a negative ratio"
        );
        assert_eq!(gain_ratio(10.0, 9.0, 10.0), 0.0, "no predicted decrease");
    }
}
