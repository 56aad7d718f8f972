//! Extensions of the base model: effects the paper's model lacks, each a small piece with one
//! or two parameters. The diagnosis refits the model with each in turn.
//!
//! All act on the friction coefficient in the Coulomb cone ‖f_t‖ = r μ_eff f_n:
//! μ_eff = μ · P(p) · D(direction) + R(v) + H(s), and [`LogHealing`] replaces the exponential
//! recovery of Eq. (24) during holds.

use serde::{Deserialize, Serialize};

/// Reference normal stress of the pressure effect [kPa].
pub const PRESSURE_REF_KPA: f64 = 100.0;

/// Direct rate dependence: R(v) = a ln(1 + v / v_c), v the plastic slip rate [mm/s].
/// Friction rises with the log of the slip rate above v_c and vanishes when sliding stops.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RateEffect {
    /// Rate sensitivity a (dimensionless, per e-fold of rate).
    pub a: f64,
    /// Cut-off rate v_c [mm/s].
    pub v_c: f64,
}

/// Pressure dependence: P(p) = (p / 100 kPa)^(−β), scaling μ_s, μ_k and μ alike.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PressureEffect {
    /// Exponent β: positive when friction falls with normal stress.
    pub beta: f64,
}

/// Slip hardening (h > 0) or softening (h < 0) with accumulated plastic slip s: an initial slope
/// h per mm that saturates after the slip s_h, either gradually, H(s) = h s_h (1 − exp(−s/s_h)),
/// or at once (`capped`), H(s) = h min(s, s_h).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SlipHardening {
    /// Initial rate of change of the friction coefficient with slip h [1/mm].
    pub h: f64,
    /// Saturation slip s_h [mm].
    pub s_h: f64,
    /// Linear up to s_h, then constant (instead of an exponential approach).
    #[serde(default)]
    pub capped: bool,
}

/// Logarithmic time healing instead of the exponential recovery ξ(μ_s − μ) of Eq. (24): a
/// contact at rest for a time θ (since sliding last stopped) regains
/// Δμ = b ln(1 + θ/t_c), up to μ_s; while it slides it does not heal, so steady friction no
/// longer depends on the sliding rate through ξ.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LogHealing {
    /// Healing per e-fold of time b.
    pub b: f64,
    /// Cut-off time t_c [s].
    pub t_c: f64,
}

/// Forward/backward asymmetry: D = 1 for forward sliding, 1 − d for backward
/// (smoothly in 3-D: D = 1 − d (1 − t̂·e₁)/2).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DirectionEffect {
    /// Relative weakening d of backward sliding (negative: backward is stronger).
    pub d: f64,
}

/// The set of active extensions; the default is the base model of the paper.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Extensions {
    /// Direct rate dependence.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate: Option<RateEffect>,
    /// Pressure dependence.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure: Option<PressureEffect>,
    /// Slip hardening or softening.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slip_hardening: Option<SlipHardening>,
    /// Logarithmic healing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub log_healing: Option<LogHealing>,
    /// Forward/backward asymmetry.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<DirectionEffect>,
}

impl Extensions {
    /// True when no extension is active (the base model).
    pub fn is_base(&self) -> bool {
        *self == Extensions::default()
    }

    /// Checks the extension parameters; returns (name, value, expected) of every invalid one.
    pub fn issues(&self) -> Vec<(&'static str, f64, &'static str)> {
        let mut v = Vec::new();
        if let Some(e) = self.rate {
            if !e.a.is_finite() {
                v.push(("rate.a", e.a, "a finite number"));
            }
            if !(e.v_c > 0.0 && e.v_c.is_finite()) {
                v.push(("rate.v_c", e.v_c, "a finite rate > 0 [mm/s]"));
            }
        }
        if let Some(e) = self.pressure {
            if !(e.beta.is_finite() && e.beta.abs() < 5.0) {
                v.push(("pressure.beta", e.beta, "a finite exponent in (-5, 5)"));
            }
        }
        if let Some(e) = self.slip_hardening {
            if !e.h.is_finite() {
                v.push(("slip_hardening.h", e.h, "a finite number"));
            }
            if !(e.s_h > 0.0 && e.s_h.is_finite()) {
                v.push(("slip_hardening.s_h", e.s_h, "a finite slip > 0 [mm]"));
            }
        }
        if let Some(e) = self.log_healing {
            if !(e.b >= 0.0 && e.b.is_finite()) {
                v.push(("log_healing.b", e.b, "a finite number >= 0"));
            }
            if !(e.t_c > 0.0 && e.t_c.is_finite()) {
                v.push(("log_healing.t_c", e.t_c, "a finite time > 0 [s]"));
            }
        }
        if let Some(e) = self.direction {
            if !(e.d.is_finite() && e.d < 1.0 && e.d > -1.0) {
                v.push(("direction.d", e.d, "a number in (-1, 1)"));
            }
        }
        v
    }

    /// Multiplier P(p) of the pressure effect at normal stress `p` [kPa].
    #[inline]
    pub fn pressure_factor(&self, p: f64) -> f64 {
        match self.pressure {
            Some(e) if e.beta != 0.0 => (p / PRESSURE_REF_KPA).powf(-e.beta),
            _ => 1.0,
        }
    }

    /// Multiplier D of the direction effect for a sliding direction whose cosine with the
    /// forward axis is `cos_forward` (±1 in 1-D).
    #[inline]
    pub fn direction_factor(&self, cos_forward: f64) -> f64 {
        match self.direction {
            Some(e) => 1.0 - e.d * 0.5 * (1.0 - cos_forward),
            None => 1.0,
        }
    }
}
