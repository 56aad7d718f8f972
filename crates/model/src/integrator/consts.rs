//! The constants of a model and what they give at each step: the step constants under the
//! pressure and direction effects, friction at rest (recovery, healing), the additive terms of
//! slip and time, and the surfaces of elastic steps and of steady sliding.

use super::states::{StateStep, States, WithStates};
use super::{max_likely_above, RETURN_TOLERANCE};
use crate::extensions::{Extensions, Target, MIN_MU_EFF_FRACTION};
use crate::params::Params;
use crate::terms::{RateEffect, StateSlots, StateTerms};
use std::f64::consts::FRAC_PI_2;

/// Constants of a model, precomputed once (units: kPa, mm, s).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Consts {
    pub mu_s: f64,
    pub mu_k: f64,
    pub kappa: f64,
    pub xi: f64,
    pub u_tilde: f64,
    /// α_t [kPa/mm].
    pub alpha: f64,
    pub ext: Extensions,
    /// Whether a registered family scales μ or its bounds (read once: the step's constants
    /// are then the parameters themselves, without a look at the families).
    scaled: bool,
    /// Whether one scales μ_s, μ_k, κ or ũ ([`Extensions::varies_bounds`]).
    varies_bounds: bool,
    /// The families that integrate a state (rate, time healing), their laws built once.
    states: States,
    /// Whether the recovery ξ(μ_s − μ) of Eq. (24) acts ([`Extensions::recovery`]).
    recovery: bool,
    /// The slip-rate law of the family that reads the slip rate (rate), read once.
    pub rate: Option<RateEffect>,
    /// Whether a family adds a term T(s, t) (read once: the return mapping asks at every
    /// iteration).
    path_terms: bool,
}

/// The constants of one step: μ_s, μ_k, κ, ũ after the pressure and direction effects that act
/// on them, and the multiplier on μ as a whole.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Local {
    pub mu_s: f64,
    pub mu_k: f64,
    pub kappa: f64,
    pub u_tilde: f64,
    /// (π/2) ũ: decay rate of cos(πr/2) with plastic slip.
    pub kr: f64,
    /// Multiplier P(p)·D(direction) on μ.
    pub mult: f64,
}

impl Consts {
    pub fn new(p: &Params, ext: &Extensions) -> Self {
        Consts {
            mu_s: p.mu_s,
            mu_k: p.mu_k,
            kappa: p.kappa,
            xi: p.xi,
            u_tilde: p.u_tilde,
            alpha: p.alpha_t_kpa_per_mm(),
            ext: *ext,
            scaled: ext
                .terms
                .iter()
                .any(|e| !e.family().targets(e.form as usize).is_empty()),
            varies_bounds: ext.varies_bounds(),
            states: States::new(&ext.terms),
            recovery: ext.recovery(),
            rate: ext.rate(),
            path_terms: ext.terms.adds_terms(),
        }
    }

    /// True when the recovery ξ(μ_s − μ) of Eq. (24) acts: always, but under a time healing
    /// that replaces it.
    #[inline]
    pub fn recovery(&self) -> bool {
        self.recovery
    }

    /// The step constants at normal stress `p` for a sliding direction whose cosine with the
    /// forward axis is `cos_forward`.
    #[inline]
    pub fn local(&self, p: f64, cos_forward: f64) -> Local {
        let mult = if self.scaled {
            self.ext.friction_factor(p, cos_forward)
        } else {
            1.0
        };
        if !self.varies_bounds {
            return Local {
                mu_s: self.mu_s,
                mu_k: self.mu_k,
                kappa: self.kappa,
                u_tilde: self.u_tilde,
                kr: FRAC_PI_2 * self.u_tilde,
                mult,
            };
        }
        let f = |t: Target| self.ext.bound_factor(t, p, cos_forward);
        let mu_s = self.mu_s * f(Target::MuS);
        let u_tilde = self.u_tilde * f(Target::UTilde);
        Local {
            mu_s,
            mu_k: (self.mu_k * f(Target::MuK)).min(mu_s),
            kappa: self.kappa * f(Target::Kappa),
            u_tilde,
            kr: FRAC_PI_2 * u_tilde,
            mult,
        }
    }

    /// μ after an elastic step (no sliding) whose recovery towards μ_s (Eq. 24) is
    /// `exp_xi_dt` = exp(−ξΔt), and in which a family gains `gain` at rest (time healing, see
    /// [`Consts::rest_state`]): the recovery, the gain instead, or the gain on top of it.
    #[inline]
    pub fn rest_mu(&self, l: &Local, mu: f64, gain: Option<f64>, exp_xi_dt: f64) -> f64 {
        let recovered = if self.recovery {
            l.mu_s - (l.mu_s - mu) * exp_xi_dt
        } else {
            mu
        };
        match gain {
            Some(g) => (recovered + g).min(l.mu_s),
            None => recovered,
        }
    }

    /// True when a family on integrates a state.
    #[inline]
    pub fn has_state(&self) -> bool {
        self.states.any()
    }

    /// The families that integrate a state.
    #[inline(always)]
    pub fn states(&self) -> &States {
        &self.states
    }

    /// The state after an elastic step of `dt` from `slots`, and the friction μ itself gains
    /// over it, if a family adds to μ at rest (see [`Consts::rest_mu`]). Slots no family uses
    /// come out zero. `STATE` false: the caller knows the model has no state, and the step
    /// carries no trace of one (see [`super::return_slip_as`]).
    #[inline(always)]
    pub fn rest_state<const STATE: bool>(
        &self,
        slots: &StateSlots,
        dt: f64,
    ) -> (StateSlots, Option<f64>) {
        if !STATE || !self.has_state() {
            return (StateSlots::default(), None);
        }
        self.states.with(RestOver { slots, dt })
    }

    /// The state of a contact that has slid steadily at rate `v`, from `slots`.
    pub fn steady_state(&self, slots: &mut StateSlots, v: f64) {
        self.states.steady(slots, v);
    }

    /// The additive terms of accumulated plastic slip `s` and time `t` (each registered
    /// family's T(s, t): slip hardening, ...), and their slope in s.
    #[inline]
    pub fn path_terms(&self, s: f64, t: f64) -> (f64, f64) {
        if !self.path_terms {
            return (0.0, 0.0);
        }
        self.ext.terms.total(s, t)
    }

    /// True when [`Consts::path_terms`] can be non-zero.
    #[inline]
    pub(super) fn has_path_terms(&self) -> bool {
        self.path_terms
    }

    /// ξΔt of a plastic step: no recovery while sliding under a time healing that replaces it.
    #[inline]
    pub fn plastic_recovery(&self, dt: f64) -> f64 {
        if self.recovery {
            self.xi * dt
        } else {
            0.0
        }
    }

    /// Lowest bound of μ after a plastic step (a rate law may move μ_k with v).
    #[inline]
    pub fn mu_floor(&self, l: &Local) -> f64 {
        match self.rate {
            Some(r) if r.moves_kinetic_bound() => 0.0,
            _ => l.mu_k,
        }
    }

    /// The terms of μ_eff = μ · factor + add of a contact sliding steadily at rate `v` with
    /// θ = θ_ss(v), after an accumulated plastic slip `slip_path` at time `time`.
    fn sliding_terms(&self, l: &Local, v: f64, slip_path: f64, time: f64) -> (f64, f64) {
        let add = self.path_terms(slip_path, time).0;
        match self.rate {
            Some(rate) => rate.steady_terms(v, l.mult, add),
            None => (l.mult, add),
        }
    }

    /// μ that puts a contact sliding steadily at rate `v` with θ = θ_ss(v) on a surface of
    /// friction `mu_eff` (the inverse of μ_eff(μ) at that rate), within [μ floor, μ_s].
    pub fn sliding_mu(&self, l: &Local, mu_eff: f64, v: f64) -> f64 {
        let (factor, add) = self.sliding_terms(l, v, 0.0, 0.0);
        ((mu_eff - add) / factor).clamp(self.mu_floor(l), l.mu_s)
    }

    /// Steady μ at slip rate `v` (Eq. 24 at its fixed point; no recovery while sliding under
    /// time healing).
    pub fn steady_mu(&self, l: &Local, v: f64) -> f64 {
        let mu_k = self
            .rate
            .map_or(l.mu_k, |rate| rate.steady_kinetic(l.mu_k, v, l.mu_s));
        let xi = if self.recovery { self.xi } else { 0.0 };
        let kv = l.kappa * v;
        if kv + xi > 0.0 {
            (kv * mu_k + xi * l.mu_s) / (kv + xi)
        } else {
            l.mu_s
        }
    }

    /// With a family whose term grows monotonically with slip alone (slip hardening,
    /// [`crate::TermLaw::monotone_in_slip`]): the steady μ at rate `v` and the accumulated
    /// slip s₀ ≥ 0 whose terms make the steady surface carry friction `mu_eff`; `None` without
    /// such a family, with one that depends on time too, or when no slip reaches it.
    pub fn steady_history(&self, l: &Local, mu_eff: f64, v: f64) -> Option<(f64, f64)> {
        let terms = self.ext.terms;
        if !terms.adds_terms()
            || !terms
                .iter()
                .all(|e| e.family().monotone_in_slip() || !e.family().adds_term())
        {
            return None;
        }
        let mu = self.steady_mu(l, v);
        let (factor, add) = self.sliding_terms(l, v, 0.0, 0.0);
        // Σ T(s₀) = what the steady surface lacks; T(0) = 0 is part of `add`.
        let need = mu_eff - (mu * factor + add);
        if need == 0.0 {
            return Some((mu, 0.0));
        }
        // Each T is monotone in s with the sign of its slope at 0; bracket s₀ by doubling,
        // then bisect.
        let sign = terms.total(0.0, 0.0).1.signum();
        if terms
            .iter()
            .filter(|e| e.family().adds_term())
            .any(|e| e.term(0.0, 0.0).1.signum() != sign)
        {
            // Terms of opposite senses: their sum need not be monotone.
            return None;
        }
        let target = need * sign;
        let value = |s: f64| terms.total(s, 0.0).0 * sign;
        // NaN counts as "no positive target" too.
        if target.is_nan() || target <= 0.0 || sign == 0.0 {
            return None;
        }
        let mut hi = 1e-3;
        let mut k = 0;
        while value(hi) < target {
            hi *= 2.0;
            k += 1;
            if k > 80 {
                return None;
            }
        }
        let mut lo = 0.0;
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if value(mid) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some((mu, 0.5 * (lo + hi)))
    }

    /// μ_eff of a contact sliding steadily at rate `v` with friction coefficient `mu`, after an
    /// accumulated plastic slip `slip_path` at time `time`.
    pub fn sliding_mu_eff(&self, l: &Local, mu: f64, v: f64, slip_path: f64, time: f64) -> f64 {
        let (factor, add) = self.sliding_terms(l, v, slip_path, time);
        (mu * factor + add).max(MIN_MU_EFF_FRACTION * l.mu_s)
    }

    /// How far a traction may lie outside the surface of an elastic step and still count as on
    /// it. Zero, but for a locked rate form: there the surface at rest is the one the last
    /// plastic step returned to, to the return's tolerance, and a hold must not turn that
    /// round-off into a plastic step, whose rate terms at a vanishing rate would make it creep.
    #[inline]
    pub fn rest_tolerance(&self, traction: f64, p: f64) -> f64 {
        match self.rate {
            Some(rate) if rate.locked() => RETURN_TOLERANCE * p + 8.0 * f64::EPSILON * traction,
            _ => 0.0,
        }
    }

    /// μ_eff of an elastic step (plastic slip rate zero) from μ at the step's end (time
    /// `time`), with the state `slots` at the step's end (the families' terms at rest: a rate
    /// law's, a healing gain of its own, ...).
    /// `STATE` as for [`Consts::rest_state`].
    #[inline(always)]
    pub fn elastic_mu_eff<const STATE: bool>(
        &self,
        l: &Local,
        mu: f64,
        slots: &StateSlots,
        slip_path: f64,
        time: f64,
    ) -> f64 {
        // μ of the last step runs through here to the next step's plastic excess, on the
        // step's critical path: a multiplier of 1 and terms of 0 are skipped, not applied
        // (the same value: μ·1 = μ, and the floor below absorbs the sign of a zero).
        let mut mu_eff = if self.scaled { mu * l.mult } else { mu };
        let with_state = STATE && self.has_state();
        if with_state || self.path_terms {
            let mut own = 0.0;
            if with_state {
                let t = self.states.with(AtRestWith { slots });
                mu_eff = mu_eff * t.factor + t.add;
                own = t.own;
            }
            mu_eff += self.path_terms(slip_path, time).0 + own;
        }
        max_likely_above(mu_eff, MIN_MU_EFF_FRACTION * l.mu_s)
    }
}

/// [`Consts::rest_state`] of a model with a state, as [`WithStates`].
struct RestOver<'a> {
    slots: &'a StateSlots,
    dt: f64,
}

impl WithStates for RestOver<'_> {
    type Output = (StateSlots, Option<f64>);

    #[inline(always)]
    fn run<S: StateStep>(self, states: S) -> Self::Output {
        let mut out = *self.slots;
        let gain = states.rest(&mut out, self.dt);
        (out, gain)
    }
}

/// The families' terms of friction at rest with the state `slots`, as [`WithStates`].
struct AtRestWith<'a> {
    slots: &'a StateSlots,
}

impl WithStates for AtRestWith<'_> {
    type Output = StateTerms;

    #[inline(always)]
    fn run<S: StateStep>(self, states: S) -> StateTerms {
        states.at_rest(self.slots)
    }
}
