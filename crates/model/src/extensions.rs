//! Extensions of the base model: effects the paper's model lacks, each a family with the forms
//! used in the friction literature. The diagnosis refits the model with each form in turn.
//!
//! All act on the friction in the Coulomb cone ‖f_t‖ = r μ_eff f_n (Eqs. 21–22):
//!
//! μ_eff = μ · P(p) · D(dir) · V(v) + R(v, θ) + Σ T(s, t)
//!
//! with μ from Eq. (24) between bounds μ_s′, μ_k′ that a pressure or direction effect may move,
//! P and D the factors of the registered families that scale (pressure, direction:
//! [`crate::terms`]), V a power law in the plastic slip rate v, R the log-rate and
//! rate-and-state terms (θ the state variable), and T the term of each registered family that
//! adds one (slip hardening H(s) in the accumulated plastic slip s, a time trend, ...).
//! [`Healing`] replaces the exponential recovery ξ(μ_s − μ) of Eq. (24) at rest.
//! Every term is zero (or one) at its reference, so μ_s and μ_k keep their meaning.

use crate::terms::Terms;
use serde::{Deserialize, Serialize};

/// Reference normal stress of the pressure effect when none is given [kPa].
pub const PRESSURE_REF_KPA: f64 = 100.0;

/// Lowest μ_eff as a fraction of μ_s: additive terms may not make friction vanish or turn
/// negative (the return mapping needs a positive surface).
pub const MIN_MU_EFF_FRACTION: f64 = 1e-3;

/// How the friction depends on the plastic slip rate v.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
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

/// Rate dependence of friction (one of [`RateForm`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RateEffect {
    /// The form.
    pub form: RateForm,
    /// Direct-effect coefficient a (per e-fold of rate); the μ_k slope for `SteadyState`.
    #[serde(default)]
    pub a: f64,
    /// Cut-off rate v_c [mm/s]: below it the direct effect fades (creep at rest is finite).
    pub v_c: f64,
    /// Evolution-effect coefficient b (rate and state).
    #[serde(default)]
    pub b: f64,
    /// Characteristic slip distance D_c of the state evolution [mm].
    #[serde(default = "one")]
    pub d_c: f64,
    /// Power-law exponent n.
    #[serde(default)]
    pub n: f64,
    /// Reference rate v_ref where every rate term vanishes [mm/s]; 0 means "not centred"
    /// (the direct effect is then a ln(1 + v/v_c)).
    #[serde(default)]
    pub v_ref: f64,
    /// What the rate terms do while the contact is at rest (see [`AtRest`]).
    #[serde(default)]
    pub at_rest: AtRest,
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
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AtRest {
    /// The rate terms at a vanishing slip rate: relaxation by creep.
    #[default]
    Creep,
    /// The rate terms of the last plastic step: no creep, the state still evolves.
    Locked,
}

fn one() -> f64 {
    1.0
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

    /// True when the rate terms keep their last sliding values at rest ([`AtRest::Locked`]);
    /// the steady-state form has no term that could creep.
    #[inline]
    pub fn locked(&self) -> bool {
        self.at_rest == AtRest::Locked && self.form != RateForm::SteadyState
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
}

/// Which friction bound a pressure or direction effect scales.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Target {
    /// μ as a whole (μ_s, μ_k and the current μ alike).
    Friction,
    /// μ_s only.
    MuS,
    /// μ_k only.
    MuK,
    /// κ only (direction effect).
    Kappa,
    /// ũ only (direction effect).
    UTilde,
    /// μ_s and μ_k, each by its own size (β and β_k, or d and d_k): a form that holds μ as a
    /// whole (equal sizes), μ_s only and μ_k only as special cases.
    Bounds,
}

/// How friction heals at rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum HealingForm {
    /// Δμ = b ln(1 + θ/t_c) after a time θ at rest.
    Log,
    /// Δμ = b (θ / 1 s)^n after a time θ at rest.
    Power,
    /// Δμ = b ((1 + θ/t_c)^n − 1)/n: the log form as n → 0, a power law in θ for θ ≫ t_c, linear
    /// at n = 1 — one form that holds the others, for healing laws none of them names.
    General,
}

/// Time healing at rest instead of the exponential recovery ξ(μ_s − μ) of Eq. (24): a contact
/// at rest for a time θ (since sliding last stopped) regains Δμ(θ), up to μ_s; while it slides
/// it does not heal, so steady friction no longer depends on the sliding rate through ξ. With
/// `recovery` the healing adds to the recovery instead (which then acts as in Eq. 24, sliding
/// and at rest): the base model is the case b = 0.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Healing {
    /// Healing amplitude b.
    pub b: f64,
    /// Cut-off time t_c of the log form [s].
    #[serde(default = "ten")]
    pub t_c: f64,
    /// Exponent n of the power form.
    #[serde(default = "half")]
    pub n: f64,
    /// The form.
    #[serde(default = "log_form")]
    pub form: HealingForm,
    /// Keep the exponential recovery ξ(μ_s − μ) of Eq. (24) and add the healing to it at rest.
    /// Always written (as is `d_h`): a file that states the default is read back, not refused
    /// as naming an unknown field.
    #[serde(default)]
    pub recovery: bool,
    /// Slip that erases the healing, e-fold [mm]; 0: none of its own. When > 0 the healing is
    /// a friction gain of its own (the contact state's `healed`) on top of μ, which keeps the
    /// recovery of Eq. (24): it grows at rest by Δμ(θ), is not capped at μ_s, and decays as
    /// exp(−Δs/d_h) with plastic slip — the peak after a hold that sliding wipes out over a
    /// short distance, as in slide-hold-slide tests.
    #[serde(default, rename = "d_h")]
    pub erase_mm: f64,
}

fn ten() -> f64 {
    10.0
}
fn half() -> f64 {
    0.5
}
fn log_form() -> HealingForm {
    HealingForm::Log
}

impl Healing {
    /// True when the healing is a gain of its own, erased by slip (`erase_mm` > 0).
    #[inline]
    pub fn own_state(&self) -> bool {
        self.erase_mm > 0.0
    }

    /// Healing gained between contact ages `age` and `age + dt` [s].
    #[inline]
    pub fn gain(&self, age: f64, dt: f64) -> f64 {
        match self.form {
            HealingForm::Log => self.b * ((self.t_c + age + dt) / (self.t_c + age)).ln(),
            HealingForm::Power => self.b * ((age + dt).powf(self.n) - age.max(0.0).powf(self.n)),
            HealingForm::General => self.general(age + dt) - self.general(age.max(0.0)),
        }
    }

    /// Δμ(θ) of the general form; expm1 keeps it exact as n → 0, where it becomes b ln(1 + θ/t_c).
    #[inline]
    fn general(&self, theta: f64) -> f64 {
        let l = (theta / self.t_c).ln_1p();
        if self.n.abs() < 1e-12 {
            self.b * l
        } else {
            self.b * (self.n * l).exp_m1() / self.n
        }
    }
}

/// The set of active extensions; the default is the base model of the paper.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Extensions {
    /// Rate dependence.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate: Option<RateEffect>,
    /// Time healing at rest.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub healing: Option<Healing>,
    /// The registered families (see [`crate::terms`]): slip hardening, the direction effect
    /// and the others, each under its key.
    #[serde(flatten)]
    pub terms: Terms,
}

fn finite_positive(v: f64) -> bool {
    v > 0.0 && v.is_finite()
}

impl Extensions {
    /// True when the exponential recovery ξ(μ_s − μ) of Eq. (24) acts: always, except under a
    /// time healing that replaces it.
    #[inline]
    pub fn recovery(&self) -> bool {
        self.healing.is_none_or(|h| h.recovery || h.own_state())
    }

    /// True when no extension is active (the base model).
    pub fn is_base(&self) -> bool {
        *self == Extensions::default()
    }

    /// Checks the extension parameters; returns (name, value, expected) of every invalid one.
    pub fn issues(&self) -> Vec<(&'static str, f64, &'static str)> {
        let mut v = Vec::new();
        if let Some(e) = self.rate {
            for (name, x) in [("rate.a", e.a), ("rate.b", e.b), ("rate.n", e.n)] {
                if !x.is_finite() {
                    v.push((name, x, "a finite number"));
                }
            }
            if !finite_positive(e.v_c) {
                v.push(("rate.v_c", e.v_c, "a finite rate > 0 [mm/s]"));
            }
            if !finite_positive(e.d_c) {
                v.push(("rate.d_c", e.d_c, "a finite slip distance > 0 [mm]"));
            }
            if !(e.v_ref >= 0.0 && e.v_ref.is_finite()) {
                v.push(("rate.v_ref", e.v_ref, "a finite rate >= 0 [mm/s]"));
            }
            if e.n.abs() >= 2.0 {
                v.push(("rate.n", e.n, "an exponent in (-2, 2)"));
            }
        }
        if let Some(e) = self.healing {
            if !(e.b >= 0.0 && e.b.is_finite()) {
                v.push(("healing.b", e.b, "a finite number >= 0"));
            }
            if !finite_positive(e.t_c) {
                v.push(("healing.t_c", e.t_c, "a finite time > 0 [s]"));
            }
            if !(e.erase_mm >= 0.0 && e.erase_mm.is_finite()) {
                v.push(("healing.d_h", e.erase_mm, "a finite slip >= 0 [mm]"));
            }
            if e.form == HealingForm::General {
                if !(0.0..=1.0).contains(&e.n) {
                    v.push(("healing.n", e.n, "an exponent in [0, 1]"));
                }
            } else if !(e.n > 0.0 && e.n <= 1.0) {
                v.push(("healing.n", e.n, "an exponent in (0, 1]"));
            }
        }
        v.extend(self.terms.issues());
        v
    }

    /// True when μ_s, μ_k, κ or ũ change with the normal stress or the sliding direction, so the
    /// integrator must build its constants per step.
    #[inline]
    pub fn varies_bounds(&self) -> bool {
        self.terms.varies_bounds()
    }

    /// Multiplier of μ as a whole at normal stress `p` [kPa] and a sliding direction whose cosine
    /// with the forward axis is `cos_forward` (±1 in 1-D).
    #[inline]
    pub fn friction_factor(&self, p: f64, cos_forward: f64) -> f64 {
        self.terms.factor_on(Target::Friction, p, cos_forward)
    }

    /// The least and greatest factor on `target` (μ_s or μ_k) over every normal stress and
    /// sliding direction: μ_s and μ_k lie within these multiples of the parameters.
    pub fn bound_factor_range(&self, target: Target) -> (f64, f64) {
        self.terms.range_on(target)
    }

    /// Factor on `target` (μ_s, μ_k, κ or ũ) at normal stress `p` and direction `cos_forward`.
    #[inline]
    pub fn bound_factor(&self, target: Target, p: f64, cos_forward: f64) -> f64 {
        self.terms.factor_on(target, p, cos_forward)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn healing_gains_add_up_over_split_steps() {
        for form in [HealingForm::Log, HealingForm::Power] {
            let h = Healing {
                b: 0.01,
                t_c: 5.0,
                n: 0.4,
                form,
                recovery: false,
                erase_mm: 0.0,
            };
            let whole = h.gain(3.0, 100.0);
            let split = h.gain(3.0, 40.0) + h.gain(43.0, 60.0);
            assert!((whole - split).abs() < 1e-14, "{form:?}");
            assert!(whole > 0.0);
        }
    }

    #[test]
    fn general_healing_holds_the_log_form_and_a_linear_law() {
        let h = |form, n| Healing {
            b: 0.01,
            t_c: 5.0,
            n,
            form,
            recovery: false,
            erase_mm: 0.0,
        };
        for (age, dt) in [(0.0, 1.0), (3.0, 10.0), (100.0, 500.0)] {
            let log = h(HealingForm::Log, 0.5).gain(age, dt);
            let general = h(HealingForm::General, 0.0).gain(age, dt);
            assert!((log - general).abs() < 1e-15, "{log} vs {general}");
            let near_zero = h(HealingForm::General, 1e-9).gain(age, dt);
            assert!((near_zero - log).abs() < 1e-9, "{near_zero} vs {log}");
            let linear = h(HealingForm::General, 1.0).gain(age, dt);
            assert!((linear - 0.01 * dt / 5.0).abs() < 1e-15);
        }
        let e = Extensions {
            healing: Some(h(HealingForm::General, 0.0)),
            ..Extensions::default()
        };
        assert!(e.issues().is_empty());
    }

    #[test]
    fn factors_apply_only_to_their_target() {
        let on_mu = crate::TermEffect::named("pressure", "power-friction", &[0.1, 100.0]).unwrap();
        let mut ext = Extensions {
            terms: Terms::one(on_mu),
            ..Extensions::default()
        };
        assert!(!ext.varies_bounds());
        ext.terms = ext
            .terms
            .with(crate::TermEffect::named("direction", "mu-k", &[0.2]).unwrap());
        assert!(ext.varies_bounds());
        // Away from it, μ as a whole is scaled, whatever the direction.
        let want = 2f64.powf(-0.1);
        assert!((ext.friction_factor(200.0, 1.0) - want).abs() < 1e-15);
        assert!((ext.bound_factor(Target::MuK, 200.0, -1.0) - 0.8).abs() < 1e-15);
        let (lo, hi) = ext.bound_factor_range(Target::MuK);
        assert_eq!((lo, hi), (0.8, 1.0));
        // At the reference stress the pressure factor is one.
        assert_eq!(ext.friction_factor(100.0, -1.0), 1.0);
        assert!((ext.bound_factor(Target::MuK, 100.0, -1.0) - 0.8).abs() < 1e-15);
        assert_eq!(ext.bound_factor(Target::MuK, 100.0, 1.0), 1.0);
        assert_eq!(ext.bound_factor(Target::MuS, 100.0, -1.0), 1.0);
    }
}
