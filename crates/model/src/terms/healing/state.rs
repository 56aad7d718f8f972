//! The state time healing integrates: the contact's age (the time since it last slid), which
//! its laws read, and the gain of its own that the erased forms add on top of μ and slip wipes
//! out.

use super::TimeHealing;
use crate::terms::{StateLaw, StateTerms, StateVar, MAX_TERM_PARAMS};

const AGE: usize = 0;
const HEALED: usize = 1;

const VARS: [StateVar; 2] = [
    StateVar {
        name: "age",
        describe: "time since plastic sliding last occurred [s]",
    },
    StateVar {
        name: "healed",
        describe: "healing gain of its own on top of μ (the erased forms; 0 otherwise)",
    },
];

impl StateLaw for TimeHealing {
    fn vars(&self) -> &'static [StateVar] {
        &VARS
    }

    fn initial(&self, _form: usize, _p: &[f64; MAX_TERM_PARAMS], x: &mut [f64]) {
        x[AGE] = 0.0;
        x[HEALED] = 0.0;
    }

    fn invalid(
        &self,
        _form: usize,
        _p: &[f64; MAX_TERM_PARAMS],
        x: &[f64],
    ) -> Option<(usize, &'static str)> {
        // What only accumulates cannot be negative.
        if x[AGE] < 0.0 {
            Some((AGE, "a time >= 0 [s]"))
        } else if x[HEALED] < 0.0 {
            Some((HEALED, "a healing gain >= 0"))
        } else {
            None
        }
    }

    #[inline]
    fn rest(&self, form: usize, p: &[f64; MAX_TERM_PARAMS], x: &mut [f64], dt: f64) -> Option<f64> {
        let gain = self.rest_gain(form, p, x[AGE], dt);
        x[AGE] += dt;
        if self.erased_over(form, p).is_some() {
            // A gain of its own, on top of μ.
            x[HEALED] += gain;
            None
        } else {
            // μ itself heals.
            x[HEALED] = 0.0;
            Some(gain)
        }
    }

    #[inline]
    fn at_rest(&self, _form: usize, _p: &[f64; MAX_TERM_PARAMS], x: &[f64]) -> StateTerms {
        StateTerms {
            own: x[HEALED],
            ..StateTerms::NONE
        }
    }

    #[inline]
    fn slide(
        &self,
        form: usize,
        p: &[f64; MAX_TERM_PARAMS],
        start: &[f64],
        _dt: f64,
        lam: f64,
        end: &mut [f64],
    ) -> StateTerms {
        self.settle(form, p, start, lam, end);
        let d_h = self.erased_over(form, p).unwrap_or(f64::INFINITY);
        StateTerms {
            own: end[HEALED],
            down: -end[HEALED] / d_h,
            ..StateTerms::NONE
        }
    }

    /// The gain of its own decays in closed form: evaluated at the settled λ itself.
    #[inline]
    fn settle(
        &self,
        form: usize,
        p: &[f64; MAX_TERM_PARAMS],
        start: &[f64],
        lam: f64,
        end: &mut [f64],
    ) {
        end[AGE] = 0.0;
        end[HEALED] = match self.erased_over(form, p) {
            Some(d_h) => start[HEALED] * (-lam / d_h).exp(),
            None => 0.0,
        };
    }
}
