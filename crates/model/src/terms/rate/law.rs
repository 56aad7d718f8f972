//! The rate law as the return mapping solves it ([`RateEffect`]): its terms at a plastic
//! increment, and what they are while the contact slides steadily or rests.

use super::{Rate, TermLaw, A, B, D_C, N, SHAPES, V_C, V_REF};
use crate::integrator::{exp_neg, relax_weight};
use crate::terms::{StateTerms, TermEffect};

/// How the friction depends on the plastic slip rate v.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RateForm {
    /// Direct effect only: R = a [ln(1 + v/v_c) − ln(1 + v_ref/v_c)].
    LogDirect,
    /// Rate and state, ageing law θ̇ = 1 − vθ/D_c: R = direct + b ln(θ v_ref/D_c).
    StateAgeing,
    /// Rate and state, slip law θ̇ = −(vθ/D_c) ln(vθ/D_c): R = direct + b ln(θ v_ref/D_c).
    StateSlip,
    /// Power law: V = ((v + v_c)/(v_ref + v_c))^n multiplies μ.
    Power,
    /// Steady-state only: the kinetic bound of Eq. (24) becomes
    /// μ_k(v) = μ_k + a ln((v + v_c)/(v_ref + v_c)); transients follow κ, not a direct effect.
    SteadyState,
}

impl RateForm {
    pub(super) fn key(self) -> &'static str {
        match self {
            RateForm::LogDirect => "log-direct",
            RateForm::StateAgeing => "state-ageing",
            RateForm::StateSlip => "state-slip",
            RateForm::Power => "power",
            RateForm::SteadyState => "steady-state",
        }
    }
}

/// What the rate terms of friction do while the contact does not slide plastically.
///
/// Two readings of the same laws are common. In the spring-slider reading (`Creep`) the rate
/// terms hold at every instant: a contact at rest has a vanishing slip rate, so its strength
/// falls by the direct effect a ln(1 + v_ref/v_c) and a held traction relaxes by creep. In the
/// reading of a stiff interface that is locked between slides (`Locked`), the rate terms are
/// those of the last plastic step while no slip occurs — the traction stays where the slide left
/// it — and only the state variable evolves (it ages under the ageing law); the next slide
/// starts from the aged state, so the healing shows at once as a peak.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AtRest {
    /// The rate terms at a vanishing slip rate: relaxation by creep.
    #[default]
    Creep,
    /// The rate terms of the last plastic step: no creep, the state still evolves.
    Locked,
}

/// A rate law as the return mapping solves it (one of [`RateForm`], with its coefficients).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RateEffect {
    /// The form.
    pub form: RateForm,
    /// Direct-effect coefficient a (per e-fold of rate); the μ_k slope for `SteadyState`.
    pub a: f64,
    /// Cut-off rate v_c [mm/s]: below it the direct effect fades (creep at rest is finite).
    pub v_c: f64,
    /// Evolution-effect coefficient b (rate and state).
    pub b: f64,
    /// Characteristic slip distance D_c of the state evolution [mm].
    pub d_c: f64,
    /// Power-law exponent n.
    pub n: f64,
    /// Reference rate v_ref where every rate term vanishes [mm/s]; 0 means "not centred"
    /// (the direct effect is then a ln(1 + v/v_c)).
    pub v_ref: f64,
    /// What the rate terms do while the contact is at rest (see [`AtRest`]).
    pub at_rest: AtRest,
}

/// The rate terms at a plastic increment: the additive R and its derivative in λ, the factor V
/// on μ and its derivative, the shift of μ_k (steady-state form) and its derivative, and the
/// state at the end of the step. A rate-and-state form gives that state as ln θ: the return
/// evaluates the terms at each of its iterates and keeps only the last, so the exponential is
/// taken once, when it settles ([`RateEffect::theta_from`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct RateTerms {
    pub add: f64,
    pub dadd: f64,
    pub factor: f64,
    pub dfactor: f64,
    pub mu_k_shift: f64,
    pub dmu_k: f64,
    /// θ at the end of the step of a form without a state (the θ it started from); not
    /// updated by a rate-and-state form, whose end state is `ln_theta`.
    pub theta: f64,
    /// ln θ at the end of the step (rate-and-state forms; NaN for the others).
    pub ln_theta: f64,
}

/// The constants of a rate law's terms, functions of its parameters alone.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RateConstants {
    /// ln(1 + v_ref/v_c) ([`RateEffect::direct_at_ref`]).
    direct_at_ref: f64,
    /// ln(v_ref/D_c), the state's reference (v_c when not centred).
    ln_state_ref_over_dc: f64,
}

impl RateEffect {
    /// A log-rate direct effect a ln(1 + v/v_c), not centred.
    pub fn log_direct(a: f64, v_c: f64) -> Self {
        RateEffect {
            form: RateForm::LogDirect,
            a,
            v_c,
            b: 0.0,
            d_c: 1.0,
            n: 0.0,
            v_ref: 0.0,
            at_rest: AtRest::Creep,
        }
    }

    /// The registered family's effect that carries this law (see [`Rate`]).
    pub fn effect(&self) -> TermEffect {
        let (family, _) = crate::terms::family_named(Rate.name()).expect("rate is registered");
        let locked = self.at_rest == AtRest::Locked && self.form != RateForm::SteadyState;
        let form = SHAPES
            .iter()
            .position(|&s| s == (self.form, locked))
            .expect("every form in both readings") as u8;
        let mut e = TermEffect::new(family, form);
        (e.p[A], e.p[V_C], e.p[B], e.p[D_C], e.p[N], e.p[V_REF]) =
            (self.a, self.v_c, self.b, self.d_c, self.n, self.v_ref);
        e
    }

    /// True when the rate terms keep their last sliding values at rest ([`AtRest::Locked`]);
    /// the steady-state form has no term that could creep.
    #[inline]
    pub fn locked(&self) -> bool {
        self.at_rest == AtRest::Locked && self.form != RateForm::SteadyState
    }

    /// The largest change of the friction coefficient this law makes between sliding at
    /// `v_lo` and at `v_hi` [mm/s] (both > 0), with μ_k `mu_k` for the forms that scale μ: the
    /// jump of the direct effect, the evolution effect b ln(v_hi/v_lo) and the change of the
    /// steady state, whichever is largest. What a record slid at those rates can see of the
    /// law; what it does below them (the creep of a hold, the turnaround of a reversal) is not
    /// a dependence on the rate the record shows.
    pub fn largest_change_between(&self, v_lo: f64, v_hi: f64, mu_k: f64) -> f64 {
        let ln_rates = (v_hi / v_lo).ln();
        match self.form {
            RateForm::LogDirect | RateForm::StateAgeing | RateForm::StateSlip => {
                let direct = self.a * ((v_hi / self.v_c).ln_1p() - (v_lo / self.v_c).ln_1p());
                if self.has_state() {
                    let evolution = self.b * ln_rates;
                    direct
                        .abs()
                        .max(evolution.abs())
                        .max((direct - evolution).abs())
                } else {
                    direct.abs()
                }
            }
            RateForm::Power => {
                let factor = |v: f64| ((v + self.v_c) / (self.v_ref + self.v_c)).powf(self.n);
                (mu_k * (factor(v_hi) - factor(v_lo))).abs()
            }
            RateForm::SteadyState => (self.a * ((v_hi + self.v_c) / (v_lo + self.v_c)).ln()).abs(),
        }
    }

    /// True for the forms with a state variable.
    pub fn has_state(&self) -> bool {
        matches!(self.form, RateForm::StateAgeing | RateForm::StateSlip)
    }

    /// ln(1 + v_ref/v_c): the direct term at the reference rate.
    #[inline]
    pub(crate) fn direct_at_ref(&self) -> f64 {
        (self.v_ref / self.v_c).ln_1p()
    }

    /// The reference rate used for the state variable (v_ref, or v_c when not centred).
    #[inline]
    pub(crate) fn state_ref(&self) -> f64 {
        if self.v_ref > 0.0 {
            self.v_ref
        } else {
            self.v_c
        }
    }

    /// Steady-state value of θ at slip rate v [s] (the initial state of a sliding start).
    pub fn steady_theta(&self, v: f64) -> f64 {
        self.d_c / v.abs().max(1e-12 * self.state_ref())
    }

    /// θ of a contact with no slip history: steady at the reference rate.
    pub fn neutral_theta(&self) -> f64 {
        self.d_c / self.state_ref()
    }

    /// The constants of the rate terms (logarithms of the parameters alone), worked out once.
    #[inline]
    pub(crate) fn constants(&self) -> RateConstants {
        RateConstants {
            direct_at_ref: self.direct_at_ref(),
            ln_state_ref_over_dc: (self.state_ref() / self.d_c).ln(),
        }
    }

    /// The rate terms at plastic increment `lam` over a step of `dt` from state `theta` (the
    /// integrator calls [`RateEffect::plastic_terms_with`] with constants built once).
    /// Its θ is the state at the end of the step, whatever the form.
    #[cfg(test)]
    pub(crate) fn plastic_terms(&self, theta: f64, dt: f64, lam: f64) -> RateTerms {
        let mut t = self.plastic_terms_with(&self.constants(), theta, dt, lam);
        t.theta = self.theta_from(t.theta, t.ln_theta);
        t
    }

    /// θ at the end of a plastic step from what [`RateEffect::plastic_terms_with`] gave: `theta`
    /// for a form without a state, e^`ln_theta` for a rate-and-state form.
    #[inline]
    pub(crate) fn theta_from(&self, theta: f64, ln_theta: f64) -> f64 {
        if self.has_state() {
            ln_theta.exp()
        } else {
            theta
        }
    }

    /// [`RateEffect::plastic_terms`] with the law's constants `c` given: the integrator builds
    /// them once per model, where each step would otherwise take two of its five logarithms
    /// and exponentials of the parameters alone.
    #[inline]
    pub(crate) fn plastic_terms_with(
        &self,
        c: &RateConstants,
        theta: f64,
        dt: f64,
        lam: f64,
    ) -> RateTerms {
        let vdt = self.v_c * dt;
        let mut t = RateTerms {
            add: 0.0,
            dadd: 0.0,
            factor: 1.0,
            dfactor: 0.0,
            mu_k_shift: 0.0,
            dmu_k: 0.0,
            theta,
            ln_theta: f64::NAN,
        };
        match self.form {
            RateForm::LogDirect | RateForm::StateAgeing | RateForm::StateSlip => {
                t.add = self.a * ((lam / vdt).ln_1p() - c.direct_at_ref);
                t.dadd = self.a / (vdt + lam);
                if self.has_state() {
                    // Constant v = λ/Δt over the step: both laws integrate in closed form.
                    let x = lam / self.d_c;
                    let e = exp_neg(x);
                    let (g, dg) = relax_weight(x, e);
                    let (ln_theta, dln_theta) = if self.form == RateForm::StateAgeing {
                        let th = theta * e + dt * g;
                        (th.ln(), (-theta * e + dt * dg) / (self.d_c * th))
                    } else {
                        let lam = lam.max(1e-30 * self.d_c);
                        let ln_ss = (self.d_c * dt / lam).ln();
                        let ln0 = theta.ln();
                        (
                            e * ln0 + (1.0 - e) * ln_ss,
                            (e * (ln_ss - ln0) - g) / self.d_c,
                        )
                    };
                    t.ln_theta = ln_theta;
                    t.add += self.b * (ln_theta + c.ln_state_ref_over_dc);
                    t.dadd += self.b * dln_theta;
                }
            }
            RateForm::Power => {
                t.factor = ((lam / dt + self.v_c) / (self.v_ref + self.v_c)).powf(self.n);
                t.dfactor = self.n * t.factor / (lam + vdt);
            }
            RateForm::SteadyState => {
                t.mu_k_shift = self.a * ((lam / dt + self.v_c) / (self.v_ref + self.v_c)).ln();
                t.dmu_k = self.a / (lam + vdt);
            }
        }
        t
    }

    /// True when the law moves the kinetic bound μ_k with the rate (the steady-state form): μ
    /// may then fall below μ_k, down to 0.
    #[inline]
    pub fn moves_kinetic_bound(&self) -> bool {
        self.form == RateForm::SteadyState
    }

    /// The kinetic bound `mu_k` of a contact sliding steadily at rate `v`, within [0, `mu_s`]:
    /// moved by the steady-state form, kept by the others.
    #[inline]
    pub(crate) fn steady_kinetic(&self, mu_k: f64, v: f64, mu_s: f64) -> f64 {
        if self.moves_kinetic_bound() {
            (mu_k + self.a * ((v + self.v_c) / (self.v_ref + self.v_c)).ln()).clamp(0.0, mu_s)
        } else {
            mu_k
        }
    }

    /// `(factor, add)` with the rate terms of a contact sliding steadily at rate `v` (θ at its
    /// steady state) applied: `factor` times V, `add` plus R (in that order of additions, so
    /// that a caller's sums come out as they always have).
    #[inline]
    pub(crate) fn steady_terms(&self, v: f64, factor: f64, add: f64) -> (f64, f64) {
        let (mut factor, mut add) = (factor, add);
        match self.form {
            RateForm::LogDirect | RateForm::StateAgeing | RateForm::StateSlip => {
                add += self.a * ((v / self.v_c).ln_1p() - self.direct_at_ref());
                if self.has_state() {
                    add += self.b * (self.steady_theta(v) * self.state_ref() / self.d_c).ln();
                }
            }
            RateForm::Power => {
                factor *= ((v + self.v_c) / (self.v_ref + self.v_c)).powf(self.n);
            }
            RateForm::SteadyState => {}
        }
        (factor, add)
    }

    /// The rate terms of a creeping form at rest (plastic slip rate zero) with state `theta`:
    /// the direct effect at a vanishing rate, the state term, the power law's factor at v = 0.
    #[inline(always)]
    pub(crate) fn creep_terms(&self, theta: f64) -> StateTerms {
        let mut t = StateTerms::NONE;
        match self.form {
            RateForm::LogDirect => t.add = -(self.a * self.direct_at_ref()),
            RateForm::StateAgeing | RateForm::StateSlip => {
                t.add = -self.a * self.direct_at_ref()
                    + self.b * (theta * self.state_ref() / self.d_c).ln();
            }
            RateForm::Power => t.factor = (self.v_c / (self.v_ref + self.v_c)).powf(self.n),
            RateForm::SteadyState => {}
        }
        t
    }
}
