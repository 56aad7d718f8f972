//! Material parameters of the subloading-friction model and their validation.

use serde::{Deserialize, Serialize};

/// 1 kN/mm³ expressed in kPa/mm: the unit factor of the elastic moduli α_t, α_n.
pub const KN_PER_MM3_IN_KPA_PER_MM: f64 = 1.0e6;

/// Largest accepted elastic modulus α_t, α_n [kN/mm³].
///
/// The step adds α Δu to the traction, so a traction is resolved only to α ε u, ε = 2.2·10⁻¹⁶
/// the relative resolution of a slip u: at this limit (10¹⁴ kPa/mm) that is 0.02 kPa per mm of
/// slip; a stiffer contact's elastic slip is lost in rounding and its shear comes out wrong (at
/// 10¹⁴ kN/mm³ every shear is 0). Sand–metal interfaces lie near 10²–10⁴ kN/mm³.
pub const MAX_ALPHA: f64 = 1.0e8;

/// Parameters of the subloading-friction model (Table 1–4 of the paper use these keys).
///
/// Units: κ and ũ in 1/mm, ξ in 1/s, α_t and α_n in kN/mm³ (= 10⁶ kPa/mm).
/// Unknown keys (such as `source`) are ignored when deserialising, so a published
/// `reference_parameters` object and a fit result can both be read.
///
/// ```
/// let p: subfric_model::Params = serde_json::from_str(
///     r#"{"source":"Table 1","mu_s":0.2,"mu_k":0.1,"kappa":100,"xi":0.05,"u_tilde":200,"alpha_t":2000}"#,
/// ).unwrap();
/// assert_eq!(p.alpha_n, 2000.0); // defaults to alpha_t
/// assert_eq!(p.initial_mu(), 0.2); // μ₀ = μ_s by default
/// assert!(p.validate().is_ok());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Params {
    /// Static friction coefficient μ_s (upper bound of μ, reached by full recovery).
    pub mu_s: f64,
    /// Kinetic friction coefficient μ_k (lower bound of μ, reached by long sliding).
    pub mu_k: f64,
    /// Decay rate of μ with plastic slip, κ in Eq. (24) [1/mm].
    pub kappa: f64,
    /// Recovery rate of μ with time, ξ in Eq. (24) [1/s].
    pub xi: f64,
    /// Growth rate of the normal-yield ratio, ũ in Eq. (29) [1/mm].
    pub u_tilde: f64,
    /// Tangential elastic modulus α_t of Eq. (15) [kN/mm³].
    pub alpha_t: f64,
    /// Normal elastic modulus α_n of Eq. (15) [kN/mm³].
    pub alpha_n: f64,
    /// Initial friction coefficient μ₀; `None` means μ₀ = μ_s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mu_0: Option<f64>,
}

#[derive(Deserialize)]
struct RawParams {
    mu_s: f64,
    mu_k: f64,
    kappa: f64,
    xi: f64,
    u_tilde: f64,
    alpha_t: f64,
    alpha_n: Option<f64>,
    mu_0: Option<f64>,
}

impl<'de> Deserialize<'de> for Params {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let r = RawParams::deserialize(d)?;
        Ok(Params {
            mu_s: r.mu_s,
            mu_k: r.mu_k,
            kappa: r.kappa,
            xi: r.xi,
            u_tilde: r.u_tilde,
            alpha_t: r.alpha_t,
            alpha_n: r.alpha_n.unwrap_or(r.alpha_t),
            mu_0: r.mu_0,
        })
    }
}

/// One invalid parameter: its name, its value and what was expected.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamIssue {
    /// Parameter key, as in `params.json`.
    pub name: &'static str,
    /// The offending value.
    pub value: f64,
    /// What a valid value looks like.
    pub expected: String,
}

/// All invalid parameters of a set, reported at once.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("invalid parameters: {}", .0.iter().map(|i| format!("{} = {} (expected {})", i.name, value_text(i.value), i.expected)).collect::<Vec<_>>().join("; "))]
pub struct ParamError(pub Vec<ParamIssue>);

/// A value as a user would write it: very large or small magnitudes with an exponent.
fn value_text(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && a.is_finite() && !(1e-4..1e6).contains(&a) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

impl Params {
    /// A sample parameter set (sand on mild steel, of the order of Table 3).
    pub fn sample() -> Self {
        Params {
            mu_s: 0.45,
            mu_k: 0.30,
            kappa: 1.2,
            xi: 0.003,
            u_tilde: 15.0,
            alpha_t: 1000.0,
            alpha_n: 1000.0,
            mu_0: None,
        }
    }

    /// μ₀: the initial friction coefficient (μ_s unless given).
    pub fn initial_mu(&self) -> f64 {
        self.mu_0.unwrap_or(self.mu_s)
    }

    /// α_t in kPa/mm.
    pub fn alpha_t_kpa_per_mm(&self) -> f64 {
        self.alpha_t * KN_PER_MM3_IN_KPA_PER_MM
    }

    /// α_n in kPa/mm.
    pub fn alpha_n_kpa_per_mm(&self) -> f64 {
        self.alpha_n * KN_PER_MM3_IN_KPA_PER_MM
    }

    /// Checks every parameter and reports all the invalid ones together.
    ///
    /// ```
    /// let mut p = subfric_model::Params::sample();
    /// p.mu_k = 0.9; // above μ_s
    /// p.kappa = -1.0;
    /// let err = p.validate().unwrap_err();
    /// assert_eq!(err.0.len(), 2);
    /// assert!(err.to_string().contains("kappa"));
    /// ```
    pub fn validate(&self) -> Result<(), ParamError> {
        let mut issues = Vec::new();
        let mut need = |name: &'static str, value: f64, ok: bool, expected: &str| {
            if !ok || !value.is_finite() {
                issues.push(ParamIssue {
                    name,
                    value,
                    expected: expected.to_string(),
                });
            }
        };
        need("mu_s", self.mu_s, self.mu_s > 0.0, "a finite number > 0");
        need(
            "mu_k",
            self.mu_k,
            self.mu_k >= 0.0 && self.mu_k <= self.mu_s,
            &format!("a finite number in [0, mu_s = {}]", self.mu_s),
        );
        need(
            "kappa",
            self.kappa,
            self.kappa >= 0.0,
            "a finite number >= 0 [1/mm]",
        );
        need("xi", self.xi, self.xi >= 0.0, "a finite number >= 0 [1/s]");
        need(
            "u_tilde",
            self.u_tilde,
            self.u_tilde > 0.0,
            "a finite number > 0 [1/mm]",
        );
        let alpha_expected = format!(
            "a finite number in (0, {MAX_ALPHA:e}] [kN/mm^3]: a stiffer contact has an elastic \
             slip below the floating-point resolution of the slip, and its shear would be lost"
        );
        need(
            "alpha_t",
            self.alpha_t,
            self.alpha_t > 0.0 && self.alpha_t <= MAX_ALPHA,
            &alpha_expected,
        );
        need(
            "alpha_n",
            self.alpha_n,
            self.alpha_n > 0.0 && self.alpha_n <= MAX_ALPHA,
            &alpha_expected,
        );
        if let Some(m0) = self.mu_0 {
            need(
                "mu_0",
                m0,
                m0 >= self.mu_k && m0 <= self.mu_s,
                &format!(
                    "a finite number in [mu_k = {}, mu_s = {}]",
                    self.mu_k, self.mu_s
                ),
            );
        }
        if issues.is_empty() {
            Ok(())
        } else {
            Err(ParamError(issues))
        }
    }

    /// Steady-state friction coefficient at a constant slip rate `v` [mm/s]:
    /// μ_ss = (κ v μ_k + ξ μ_s) / (κ v + ξ), the fixed point of Eq. (24).
    pub fn steady_mu(&self, v: f64) -> f64 {
        let kv = self.kappa * v.abs();
        if kv + self.xi == 0.0 {
            return self.mu_s;
        }
        (kv * self.mu_k + self.xi * self.mu_s) / (kv + self.xi)
    }
}
