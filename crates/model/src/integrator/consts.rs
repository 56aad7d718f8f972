//! The constants of a model and what they give at each step: the step constants under the
//! pressure and direction effects, friction at rest (recovery, healing), the additive terms of
//! slip and time, and the surfaces of elastic steps and of steady sliding.

use super::{RateHeld, RETURN_TOLERANCE};
use crate::extensions::{Extensions, Target, MIN_MU_EFF_FRACTION};
use crate::params::Params;
use crate::terms::{RateEffect, RateForm, TermEffect};
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
    /// The family that gains friction at rest (time healing), read once.
    rest_gain: Option<RestGain>,
    /// Whether the recovery ξ(μ_s − μ) of Eq. (24) acts ([`Extensions::recovery`]).
    recovery: bool,
    /// The slip-rate law of the family that reads the slip rate (rate), read once.
    pub rate: Option<RateEffect>,
    /// Whether a family adds a term T(s, t) (read once: the return mapping asks at every
    /// iteration).
    path_terms: bool,
}

/// A family that gains friction at rest, and where its gain goes.
#[derive(Clone, Copy, Debug)]
struct RestGain {
    effect: TermEffect,
    /// The slip that erases a gain of its own (e-fold) [mm]; `None`: the gain adds to μ.
    erased_over: Option<f64>,
}

impl RestGain {
    #[inline]
    fn gain(&self, age: f64, dt: f64) -> f64 {
        let e = &self.effect;
        e.family().rest_gain(e.form as usize, &e.p, age, dt)
    }
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
            rest_gain: ext.terms.rest_gain().map(|effect| RestGain {
                effect,
                erased_over: effect.family().erased_over(effect.form as usize, &effect.p),
            }),
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

    /// μ after an elastic step (no sliding) of `dt` at contact age `age`: exponential recovery
    /// towards μ_s (Eq. 24), time healing instead, or time healing on top of it.
    #[inline]
    pub fn rest_mu(&self, l: &Local, mu: f64, age: f64, dt: f64, exp_xi_dt: f64) -> f64 {
        let recovered = if self.recovery {
            l.mu_s - (l.mu_s - mu) * exp_xi_dt
        } else {
            mu
        };
        match self.rest_gain {
            Some(h) if h.erased_over.is_none() => (recovered + h.gain(age, dt)).min(l.mu_s),
            _ => recovered,
        }
    }

    /// The healing gain of its own ([`crate::TermFamily::erased_over`]) after an elastic step
    /// of `dt` at contact age `age` (zero without one).
    #[inline]
    pub fn rest_healed(&self, healed: f64, age: f64, dt: f64) -> f64 {
        match self.rest_gain {
            Some(h) if h.erased_over.is_some() => healed + h.gain(age, dt),
            _ => 0.0,
        }
    }

    /// The healing gain of its own after a plastic slip `lam` (it decays as exp(−λ/d_h)), and
    /// its derivative in λ.
    #[inline]
    pub fn slid_healed(&self, healed: f64, lam: f64) -> (f64, f64) {
        match self.rest_gain.and_then(|h| h.erased_over) {
            Some(d_h) => {
                let v = healed * (-lam / d_h).exp();
                (v, -v / d_h)
            }
            None => (0.0, 0.0),
        }
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

    /// Lowest bound of μ after a plastic step (the steady-state rate form moves μ_k with v).
    #[inline]
    pub fn mu_floor(&self, l: &Local) -> f64 {
        match self.rate {
            Some(r) if r.form == RateForm::SteadyState => 0.0,
            _ => l.mu_k,
        }
    }

    /// The state variable θ after an elastic step of `dt` (ageing law: the contact ages).
    #[inline]
    pub fn rest_theta(&self, theta: f64, dt: f64) -> f64 {
        match self.rate {
            Some(r) if r.form == RateForm::StateAgeing => theta + dt,
            _ => theta,
        }
    }

    /// The terms of μ_eff = μ · factor + add of a contact sliding steadily at rate `v` with
    /// θ = θ_ss(v), after an accumulated plastic slip `slip_path` at time `time`.
    fn sliding_terms(&self, l: &Local, v: f64, slip_path: f64, time: f64) -> (f64, f64) {
        let mut add = self.path_terms(slip_path, time).0;
        let mut factor = l.mult;
        if let Some(rate) = self.rate {
            match rate.form {
                RateForm::LogDirect | RateForm::StateAgeing | RateForm::StateSlip => {
                    add += rate.a * ((v / rate.v_c).ln_1p() - rate.direct_at_ref());
                    if rate.has_state() {
                        add += rate.b * (rate.steady_theta(v) * rate.state_ref() / rate.d_c).ln();
                    }
                }
                RateForm::Power => {
                    factor *= ((v + rate.v_c) / (rate.v_ref + rate.v_c)).powf(rate.n);
                }
                RateForm::SteadyState => {}
            }
        }
        (factor, add)
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
        let mut mu_k = l.mu_k;
        if let Some(rate) = self.rate {
            if rate.form == RateForm::SteadyState {
                mu_k = (mu_k + rate.a * ((v + rate.v_c) / (rate.v_ref + rate.v_c)).ln())
                    .clamp(0.0, l.mu_s);
            }
        }
        let xi = if self.recovery { self.xi } else { 0.0 };
        let kv = l.kappa * v;
        if kv + xi > 0.0 {
            (kv * mu_k + xi * l.mu_s) / (kv + xi)
        } else {
            l.mu_s
        }
    }

    /// With a family whose term grows monotonically with slip alone (slip hardening,
    /// [`crate::TermFamily::monotone_in_slip`]): the steady μ at rate `v` and the accumulated
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

    /// The rate terms (additive R, factor V) of a contact sliding steadily at rate `v` with
    /// θ = θ_ss(v): what a locked rate form keeps at rest after such a slide.
    pub fn steady_rate_terms(&self, v: f64) -> RateHeld {
        let Some(rate) = self.rate else {
            return RateHeld::NEUTRAL;
        };
        let mut held = RateHeld::NEUTRAL;
        match rate.form {
            RateForm::LogDirect | RateForm::StateAgeing | RateForm::StateSlip => {
                held.add = rate.a * ((v / rate.v_c).ln_1p() - rate.direct_at_ref());
                if rate.has_state() {
                    held.add += rate.b * (rate.steady_theta(v) * rate.state_ref() / rate.d_c).ln();
                }
            }
            RateForm::Power => {
                held.factor = ((v + rate.v_c) / (rate.v_ref + rate.v_c)).powf(rate.n);
            }
            RateForm::SteadyState => {}
        }
        held
    }

    /// μ_eff of an elastic step (plastic slip rate zero) from μ at the step's end (time
    /// `time`); `held` are the rate terms of the last plastic step, which a locked rate form
    /// keeps at rest.
    /// `healed` is the healing gain of its own at the step's end.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn elastic_mu_eff(
        &self,
        l: &Local,
        mu: f64,
        theta: f64,
        slip_path: f64,
        time: f64,
        healed: f64,
        held: RateHeld,
    ) -> f64 {
        let mut mu_eff = mu * l.mult;
        if let Some(rate) = self.rate {
            if rate.locked() {
                mu_eff = mu_eff * held.factor + held.add;
                mu_eff += self.path_terms(slip_path, time).0 + healed;
                return mu_eff.max(MIN_MU_EFF_FRACTION * l.mu_s);
            }
            match rate.form {
                RateForm::LogDirect => mu_eff -= rate.a * rate.direct_at_ref(),
                RateForm::StateAgeing | RateForm::StateSlip => {
                    mu_eff += -rate.a * rate.direct_at_ref()
                        + rate.b * (theta * rate.state_ref() / rate.d_c).ln();
                }
                RateForm::Power => {
                    mu_eff *= (rate.v_c / (rate.v_ref + rate.v_c)).powf(rate.n);
                }
                RateForm::SteadyState => {}
            }
        }
        mu_eff += self.path_terms(slip_path, time).0 + healed;
        mu_eff.max(MIN_MU_EFF_FRACTION * l.mu_s)
    }
}
