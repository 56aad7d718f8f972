//! Extensions of the base model: effects the paper's model lacks, each a family with the forms
//! used in the friction literature. The diagnosis refits the model with each form in turn.
//!
//! All act on the friction in the Coulomb cone ‖f_t‖ = r μ_eff f_n (Eqs. 21–22):
//!
//! μ_eff = μ · P(p) · D(dir) · V(v) + R(v, θ) + Σ T(s, t)
//!
//! with μ from Eq. (24) between bounds μ_s′, μ_k′ that a pressure or direction effect may move,
//! P and D the factors of the registered families that scale (pressure, direction:
//! [`crate::terms`]), V a power law in the plastic slip rate v and R the log-rate and
//! rate-and-state terms (θ the state variable) of the rate family ([`crate::terms::Rate`]),
//! and T the term of each registered family that adds one (slip hardening H(s) in the
//! accumulated plastic slip s, a time trend, ...).
//! Time healing ([`crate::terms::TimeHealing`]) gains friction at rest in place of the
//! exponential recovery ξ(μ_s − μ) of Eq. (24), beside it, or as a gain of its own.
//! Every term is zero (or one) at its reference, so μ_s and μ_k keep their meaning.

use crate::terms::{RateEffect, Terms};
use serde::{Deserialize, Serialize};

/// Reference normal stress of the pressure effect when none is given [kPa].
pub const PRESSURE_REF_KPA: f64 = 100.0;

/// Lowest μ_eff as a fraction of μ_s: additive terms may not make friction vanish or turn
/// negative (the return mapping needs a positive surface).
pub const MIN_MU_EFF_FRACTION: f64 = 1e-3;

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

/// The set of active extensions; the default is the base model of the paper.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Extensions {
    /// The registered families (see [`crate::terms`]): rate, time healing, slip hardening, the
    /// direction effect and the others, each under its key.
    #[serde(flatten)]
    pub terms: Terms,
}

impl Extensions {
    /// True when the exponential recovery ξ(μ_s − μ) of Eq. (24) acts: always, except under a
    /// time healing that replaces it.
    #[inline]
    pub fn recovery(&self) -> bool {
        self.terms.recovery()
    }

    /// The slip-rate law of the rate family, when it is on.
    #[inline]
    pub fn rate(&self) -> Option<RateEffect> {
        self.terms.rate_law()
    }

    /// These extensions with the rate family on, its law `law` (in place of any other).
    pub fn with_rate(mut self, law: RateEffect) -> Extensions {
        self.terms.insert(law.effect());
        self
    }

    /// True when no extension is active (the base model).
    pub fn is_base(&self) -> bool {
        *self == Extensions::default()
    }

    /// Checks the extension parameters; returns (name, value, expected) of every invalid one.
    pub fn issues(&self) -> Vec<(&'static str, f64, &'static str)> {
        let mut v = Vec::new();
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
    fn factors_apply_only_to_their_target() {
        let on_mu = crate::TermEffect::named("pressure", "power-friction", &[0.1, 100.0]).unwrap();
        let mut ext = Extensions {
            terms: Terms::one(on_mu),
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
