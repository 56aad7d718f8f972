//! The state the rate family integrates: θ of the rate-and-state forms, and the rate terms of
//! the last plastic step, which a locked form keeps while the contact rests.

use super::law::RateConstants;
use super::{Rate, RateEffect, RateForm};
use crate::terms::{StateFamily, StateLaw, StateTerms, StateVar, TermLaw, MAX_TERM_PARAMS};

const THETA: usize = 0;
const HELD_ADD: usize = 1;
const HELD_FACTOR: usize = 2;

const VARS: [StateVar; 3] = [
    StateVar {
        name: "theta",
        describe: "state variable θ of the rate-and-state forms [s] (unused by the others)",
    },
    StateVar {
        name: "rate_add",
        describe: "additive rate term R of the last plastic step (kept at rest by a locked form)",
    },
    StateVar {
        name: "rate_factor",
        describe: "rate factor V of the last plastic step (as rate_add; 1 for a new contact)",
    },
];

impl StateFamily for Rate {
    type Law = RateLaw;

    fn law(&self, form: usize, p: &[f64; MAX_TERM_PARAMS]) -> RateLaw {
        let effect = self
            .slip_rate_law(form, p)
            .expect("every form of the rate family is a slip-rate law");
        RateLaw {
            effect,
            constants: effect.constants(),
        }
    }
}

/// The rate law as the return mapping integrates it: the effect with its constants worked out
/// once per model.
#[derive(Clone, Copy, Debug)]
pub struct RateLaw {
    effect: RateEffect,
    constants: RateConstants,
}

impl std::ops::Deref for RateLaw {
    type Target = RateEffect;

    #[inline(always)]
    fn deref(&self) -> &RateEffect {
        &self.effect
    }
}

/// The rate law as the return mapping solves it keeps its state.
impl StateLaw for RateLaw {
    #[inline]
    fn vars(&self) -> &'static [StateVar] {
        &VARS
    }

    fn initial(&self, x: &mut [f64]) {
        // θ steady at the reference rate; no rate term held.
        x[THETA] = self.neutral_theta();
        x[HELD_ADD] = 0.0;
        x[HELD_FACTOR] = 1.0;
    }

    fn steady(&self, v: f64, x: &mut [f64]) {
        if self.has_state() && v > 0.0 {
            x[THETA] = self.steady_theta(v);
        }
        (x[HELD_FACTOR], x[HELD_ADD]) = self.steady_terms(v, 1.0, 0.0);
    }

    fn invalid(&self, x: &[f64]) -> Option<(usize, &'static str)> {
        if !(x[HELD_FACTOR] > 0.0 && x[HELD_FACTOR].is_finite()) {
            return Some((
                HELD_FACTOR,
                "a finite number > 0 (1 for a new contact point)",
            ));
        }
        if self.has_state() && x[THETA] <= 0.0 {
            return Some((
                THETA,
                "a state variable > 0 [s] (the model has a rate-and-state form)",
            ));
        }
        None
    }

    #[inline(always)]
    fn rest(&self, x: &mut [f64], dt: f64) -> Option<f64> {
        // The ageing law ages the contact at rest (θ̇ = 1); the slip law's θ does not move,
        // and the held terms are kept.
        if self.form == RateForm::StateAgeing {
            x[THETA] += dt;
        }
        None
    }

    #[inline(always)]
    fn at_rest(&self, x: &[f64]) -> StateTerms {
        if self.locked() {
            StateTerms {
                factor: x[HELD_FACTOR],
                add: x[HELD_ADD],
                ..StateTerms::NONE
            }
        } else {
            self.creep_terms(x[THETA])
        }
    }

    /// θ from the ln θ the return's last iterate left ([`StateLaw::slide`] below).
    #[inline(always)]
    fn settle(&self, _start: &[f64], _lam: f64, end: &mut [f64]) {
        end[THETA] = self.theta_from(end[THETA], end[THETA]);
    }

    #[inline(always)]
    fn slide(&self, start: &[f64], dt: f64, lam: f64, end: &mut [f64]) -> StateTerms {
        let t = self
            .effect
            .plastic_terms_with(&self.constants, start[THETA], dt, lam);
        // ln θ until the return settles (the exponential once, not at every iterate).
        end[THETA] = if self.has_state() { t.ln_theta } else { t.theta };
        end[HELD_ADD] = t.add;
        end[HELD_FACTOR] = t.factor;
        StateTerms {
            factor: t.factor,
            dfactor: t.dfactor,
            add: t.add,
            dadd: t.dadd,
            mu_k_shift: t.mu_k_shift,
            dmu_k: t.dmu_k,
            ..StateTerms::NONE
        }
    }
}
