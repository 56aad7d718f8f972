//! The state time healing integrates: the contact's age (the time since it last slid), which
//! its laws read, and the gain of its own that the erased forms add on top of μ and slip wipes
//! out.

use super::TimeHealing;
use crate::terms::{StateFamily, StateLaw, StateTerms, StateVar, MAX_TERM_PARAMS};

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

/// Time healing's law for one form and parameters ([`StateFamily::law`]).
#[derive(Clone, Copy, Debug)]
pub struct HealingLaw {
    form: usize,
    p: [f64; MAX_TERM_PARAMS],
    /// The slip over which a gain of its own decays ([`TimeHealing::erased_over`]); `None`
    /// when the form heals μ itself.
    erased_over: Option<f64>,
}

impl StateFamily for TimeHealing {
    type Law = HealingLaw;

    fn law(&self, form: usize, p: &[f64; MAX_TERM_PARAMS]) -> HealingLaw {
        HealingLaw {
            form,
            p: *p,
            erased_over: self.erased_over(form, p),
        }
    }
}

impl StateLaw for HealingLaw {
    #[inline]
    fn vars(&self) -> &'static [StateVar] {
        &VARS
    }

    fn initial(&self, x: &mut [f64]) {
        x[AGE] = 0.0;
        x[HEALED] = 0.0;
    }

    fn invalid(&self, x: &[f64]) -> Option<(usize, &'static str)> {
        // What only accumulates cannot be negative.
        if x[AGE] < 0.0 {
            Some((AGE, "a time >= 0 [s]"))
        } else if x[HEALED] < 0.0 {
            Some((HEALED, "a healing gain >= 0"))
        } else {
            None
        }
    }

    #[inline(always)]
    fn rest(&self, x: &mut [f64], dt: f64) -> Option<f64> {
        let gain = TimeHealing.rest_gain(self.form, &self.p, x[AGE], dt);
        x[AGE] += dt;
        if self.erased_over.is_some() {
            // A gain of its own, on top of μ.
            x[HEALED] += gain;
            None
        } else {
            // μ itself heals.
            x[HEALED] = 0.0;
            Some(gain)
        }
    }

    #[inline(always)]
    fn at_rest(&self, x: &[f64]) -> StateTerms {
        StateTerms {
            own: x[HEALED],
            ..StateTerms::NONE
        }
    }

    #[inline(always)]
    fn slide(&self, start: &[f64], _dt: f64, lam: f64, end: &mut [f64]) -> StateTerms {
        // No gain of its own to erase: none at any λ (the step's end settles it all the same).
        end[AGE] = 0.0;
        end[HEALED] = 0.0;
        if start[HEALED] != 0.0 {
            self.settle(start, lam, end);
        }
        let d_h = self.erased_over.unwrap_or(f64::INFINITY);
        StateTerms {
            own: end[HEALED],
            down: -end[HEALED] / d_h,
            ..StateTerms::NONE
        }
    }

    /// The gain of its own decays in closed form: evaluated at the settled λ itself.
    #[inline(always)]
    fn settle(&self, start: &[f64], lam: f64, end: &mut [f64]) {
        end[AGE] = 0.0;
        end[HEALED] = match self.erased_over {
            Some(d_h) => start[HEALED] * (-lam / d_h).exp(),
            None => 0.0,
        };
    }
}
