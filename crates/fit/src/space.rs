//! The parameter space seen by the optimisers: which parameters are free, and a transformed
//! coordinate for each that keeps the model valid (logarithms for rates and moduli, a logit of
//! μ_k/μ_s so that μ_k ≤ μ_s always holds).

use serde::{Deserialize, Serialize};
use subfric_model::terms::{self, TermEffect, TermParam};
use subfric_model::Model;

/// A parameter of the model or of one of its extensions. In files it is its key
/// ([`Param::key`]: `mu_s`, `rate.d_c`, `slip_hardening.h`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Param {
    /// μ_s.
    MuS,
    /// μ_k.
    MuK,
    /// κ [1/mm].
    Kappa,
    /// ξ [1/s].
    Xi,
    /// ũ [1/mm].
    UTilde,
    /// α_t [kN/mm³] (α_n follows it).
    AlphaT,
    /// Parameter `index` of the registered family `family` (see `subfric_model::terms`).
    Term {
        /// Index of the family in `subfric_model::terms::FAMILIES`.
        family: u8,
        /// Index of the parameter in the family's `params()`.
        index: u8,
    },
}

impl Serialize for Param {
    fn serialize<S: serde::Serializer>(&self, ser: S) -> Result<S::Ok, S::Error> {
        ser.serialize_str(self.key())
    }
}

impl<'de> Deserialize<'de> for Param {
    fn deserialize<D: serde::Deserializer<'de>>(de: D) -> Result<Self, D::Error> {
        let s = String::deserialize(de)?;
        Param::from_key_or_old_name(&s).ok_or_else(|| {
            serde::de::Error::custom(format!(
                "unknown parameter `{s}` (expected one of: {})",
                Param::all()
                    .iter()
                    .map(|p| p.key())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })
    }
}

/// How a parameter is mapped to the optimiser's coordinate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// x = ln(value).
    Log,
    /// x = value.
    Linear,
    /// x = logit(μ_k / μ_s).
    RatioToMuS,
}

impl Param {
    /// The five parameters of the paper that a calibration frees by default.
    pub const BASE: [Param; 5] = [
        Param::MuS,
        Param::MuK,
        Param::Kappa,
        Param::Xi,
        Param::UTilde,
    ];

    /// The paper's parameters and α_t ([`Param::all`] adds those of the registered effect
    /// families).
    pub const ALL: [Param; 6] = [
        Param::MuS,
        Param::MuK,
        Param::Kappa,
        Param::Xi,
        Param::UTilde,
        Param::AlphaT,
    ];

    /// Every parameter: [`Param::ALL`] and those of each registered family (not its
    /// references, such as the reference normal stress, which the data set and no fit gives).
    pub fn all() -> Vec<Param> {
        let mut out = Param::ALL.to_vec();
        for (family, f) in terms::FAMILIES.iter().enumerate() {
            for (index, q) in f.params().iter().enumerate() {
                if q.reference {
                    continue;
                }
                out.push(Param::Term {
                    family: family as u8,
                    index: index as u8,
                });
            }
        }
        out
    }

    /// The description of a registered family's parameter (`None` for the others).
    pub fn term_param(self) -> Option<&'static TermParam> {
        match self {
            Param::Term { family, index } => terms::family(family).params().get(index as usize),
            _ => None,
        }
    }

    /// Key as in `params.json` (extension parameters as `effect.name`).
    pub fn key(self) -> &'static str {
        match self {
            Param::Term { .. } => self.term_param().map_or("term.?", |q| q.key),
            Param::MuS => "mu_s",
            Param::MuK => "mu_k",
            Param::Kappa => "kappa",
            Param::Xi => "xi",
            Param::UTilde => "u_tilde",
            Param::AlphaT => "alpha_t",
        }
    }

    /// Unit for display.
    pub fn unit(self) -> &'static str {
        match self {
            Param::Term { .. } => self.term_param().map_or("", |q| q.unit),
            Param::Kappa | Param::UTilde => "1/mm",
            Param::Xi => "1/s",
            Param::AlphaT => "kN/mm³",
            _ => "",
        }
    }

    /// Parses a key (as printed by [`Param::key`]).
    pub fn from_key(s: &str) -> Option<Param> {
        Param::all().into_iter().find(|p| p.key() == s)
    }

    /// Parses a key, or the name files written before the keys used (`rate_d_c`'s
    /// `rate_dc`, `slip_h`, ...).
    fn from_key_or_old_name(s: &str) -> Option<Param> {
        let key = match s {
            "rate_a" => "rate.a",
            "rate_vc" => "rate.v_c",
            "rate_b" => "rate.b",
            "rate_dc" => "rate.d_c",
            "rate_n" => "rate.n",
            "pressure_beta" => "pressure.beta",
            "pressure_beta_k" => "pressure.beta_k",
            "slip_h" => "slip_hardening.h",
            "slip_sh" => "slip_hardening.s_h",
            "heal_tc" => "healing.t_c",
            "heal_b" => "healing.b",
            "heal_n" => "healing.n",
            "heal_dh" => "healing.d_h",
            "direction_d" => "direction.d",
            "direction_dk" => "direction.d_k",
            other => other,
        };
        Param::from_key(key)
    }

    /// Why `lo..hi` (natural units) cannot bound this parameter, if it cannot: both finite,
    /// `lo < hi`, `lo > 0` for a parameter fitted on a logarithmic scale, `lo >= 0` for μ_k.
    ///
    /// ```
    /// use subfric_fit::Param;
    /// assert!(Param::Kappa.bounds_problem(0.1, 10.0).is_none());
    /// assert!(Param::Kappa.bounds_problem(-5.0, -1.0).unwrap().contains("> 0"));
    /// assert!(Param::MuS.bounds_problem(0.5, 0.1).unwrap().contains("below"));
    /// ```
    pub fn bounds_problem(self, lo: f64, hi: f64) -> Option<String> {
        if !(lo.is_finite() && hi.is_finite()) {
            return Some(format!(
                "bounds {lo}:{hi} are not finite (expected two finite numbers lo:hi)"
            ));
        }
        if lo >= hi {
            return Some(format!(
                "lower bound {lo} is not below the upper bound {hi} (expected lo < hi)"
            ));
        }
        match self.scale() {
            Scale::Log if lo <= 0.0 => Some(format!(
                "lower bound {lo} is not positive (expected bounds > 0: {} is fitted on a logarithmic scale{})",
                self.key(),
                if self.unit().is_empty() {
                    String::new()
                } else {
                    format!(", in {}", self.unit())
                }
            )),
            Scale::RatioToMuS if lo < 0.0 => Some(format!(
                "lower bound {lo} is negative (expected bounds >= 0: a friction coefficient)"
            )),
            _ => None,
        }
    }

    /// The coordinate transform.
    pub fn scale(self) -> Scale {
        match self {
            Param::Term { .. } => match self.term_param() {
                Some(q) if q.log_scale => Scale::Log,
                _ => Scale::Linear,
            },
            Param::MuK => Scale::RatioToMuS,
            _ => Scale::Log,
        }
    }

    /// Default bounds in natural units (for μ_k: bounds of the ratio μ_k/μ_s).
    pub fn default_bounds(self) -> (f64, f64) {
        match self {
            Param::Term { .. } => self.term_param().map_or((-1.0, 1.0), |q| q.bounds),
            Param::MuS => (0.02, 3.0),
            Param::MuK => (1e-3, 1.0 - 1e-6),
            Param::Kappa => (1e-3, 1e4),
            Param::Xi => (1e-7, 10.0),
            Param::UTilde => (0.1, 1e5),
            Param::AlphaT => (1e-6, 1e6),
        }
    }

    /// The value of this parameter in a model (μ_k itself, not the ratio). `None` when the
    /// extension it belongs to is inactive.
    pub fn get(self, m: &Model) -> Option<f64> {
        let e = &m.ext;
        Some(match self {
            Param::MuS => m.params.mu_s,
            Param::MuK => m.params.mu_k,
            Param::Kappa => m.params.kappa,
            Param::Xi => m.params.xi,
            Param::UTilde => m.params.u_tilde,
            Param::AlphaT => m.params.alpha_t,
            Param::Term { family, index } => {
                // A parameter the active form does not use is inactive, like an extension
                // that is off.
                let t = e.terms.of(family)?;
                if !t.form().params.contains(&(index as usize)) {
                    return None;
                }
                *t.p.get(index as usize)?
            }
        })
    }

    /// Sets this parameter in a model, activating its extension if needed (α_n follows α_t).
    pub fn set(self, m: &mut Model, v: f64) {
        let e = &mut m.ext;
        match self {
            Param::MuS => m.params.mu_s = v,
            Param::MuK => m.params.mu_k = v,
            Param::Kappa => m.params.kappa = v,
            Param::Xi => m.params.xi = v,
            Param::UTilde => m.params.u_tilde = v,
            Param::AlphaT => {
                m.params.alpha_t = v;
                m.params.alpha_n = v;
            }
            Param::Term { family, index } => {
                // Setting a parameter the family's form does not use switches to the first
                // form that does (the other values are kept).
                let i = index as usize;
                let first_using = terms::family(family)
                    .forms()
                    .iter()
                    .position(|f| f.params.contains(&i))
                    .unwrap_or(0) as u8;
                if e.terms.of(family).is_none() {
                    e.terms.insert(TermEffect::new(family, first_using));
                }
                let t = e.terms.of_mut(family).expect("just switched on");
                if !t.form().params.contains(&i) {
                    t.form = first_using;
                }
                if let Some(slot) = t.p.get_mut(i) {
                    *slot = v;
                }
            }
        }
    }
}

/// One coordinate of the optimiser.
///
/// When μ_k, κ and ξ are all free they are charted as identifiable combinations at a reference
/// slip rate v (the typical rate of the data): μ_ss/μ_s (steady friction), λ = κ + ξ/v (decay
/// rate with slip) and ψ, the share of λ due to recovery (scaled so that μ_k stays in [0, μ_ss]).
/// A single sliding rate determines the first two and leaves ψ flat, so the degeneracy the paper
/// points out lies along one axis instead of a curved valley.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Coord {
    /// A parameter in its own transformed scale.
    Natural(Param),
    /// logit(μ_ss(v)/μ_s).
    SteadyRatio,
    /// ln(κ + ξ/v).
    DecayRate,
    /// logit(ψ), ψ = φ/m with φ = ξ/(κv + ξ) and m = μ_ss/μ_s.
    RecoveryShare,
}

impl Coord {
    /// Display name.
    pub fn name(&self) -> String {
        match self {
            Coord::Natural(p) => p.key().to_string(),
            Coord::SteadyRatio => "mu_ss/mu_s".into(),
            Coord::DecayRate => "kappa+xi/v".into(),
            Coord::RecoveryShare => "recovery share".into(),
        }
    }
}

/// Share of a coordinate's box within which a fitted value counts as at its bound.
pub const AT_BOUND_SHARE: f64 = 1e-3;

/// A fitted coordinate at a bound of its box ([`Space::at_bounds`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AtBound {
    /// The coordinate's name (a parameter's key, or a combined chart's axis).
    pub coordinate: String,
    /// Its fitted value (natural units).
    pub value: f64,
    /// The bound it sits at (natural units).
    pub bound: f64,
    /// The upper bound (else the lower).
    pub upper: bool,
}

impl AtBound {
    /// "mu_s 2.9990 at its upper bound 3.0000".
    pub fn sentence(&self) -> String {
        let number = |v: f64| {
            if v != 0.0 && !(0.01..1e4).contains(&v.abs()) {
                format!("{v:.3e}")
            } else {
                format!("{v:.4}")
            }
        };
        format!(
            "{} {} at its {} bound {}",
            self.coordinate,
            number(self.value),
            if self.upper { "upper" } else { "lower" },
            number(self.bound)
        )
    }
}

/// Free parameters, the optimiser's coordinates with their boxes, and the model supplying the
/// fixed parameters.
#[derive(Clone, Debug)]
pub struct Space {
    /// Model providing every fixed parameter (and the extensions that are active).
    pub base: Model,
    /// Free parameters (natural), sorted.
    pub free: Vec<Param>,
    /// The optimiser's coordinates.
    pub coords: Vec<Coord>,
    /// Reference slip rate of the combined chart [mm/s].
    pub v_ref: f64,
    /// Lower bounds in the optimiser's coordinates.
    pub lo: Vec<f64>,
    /// Upper bounds in the optimiser's coordinates.
    pub hi: Vec<f64>,
}

fn forward(scale: Scale, v: f64) -> f64 {
    match scale {
        Scale::Log => v.ln(),
        Scale::Linear => v,
        Scale::RatioToMuS => logit(v),
    }
}

fn backward(scale: Scale, x: f64) -> f64 {
    match scale {
        Scale::Log => x.exp(),
        Scale::Linear => x,
        Scale::RatioToMuS => sigmoid(x),
    }
}

fn logit(v: f64) -> f64 {
    (v / (1.0 - v)).ln()
}

fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

const SHARE_BOUNDS: (f64, f64) = (1e-7, 1.0 - 1e-4);
const RATIO_BOUNDS: (f64, f64) = (1e-3, 1.0 - 1e-6);

impl Space {
    /// A space freeing `free` (duplicates removed, sorted) with default or given natural bounds.
    /// `v_ref` > 0 selects the combined chart when μ_k, κ and ξ are all free.
    pub fn new(base: Model, free: &[Param], bounds: &[(Param, f64, f64)]) -> Space {
        Space::with_rate(base, free, bounds, 0.0)
    }

    /// As [`Space::new`], charting μ_k, κ, ξ as combinations at slip rate `v_ref` [mm/s].
    ///
    /// # Panics
    ///
    /// On bounds that [`Space::try_with_rate`] refuses (give user bounds through that).
    ///
    /// ```
    /// use subfric_fit::{Param, Space};
    /// use subfric_model::{Model, Params};
    /// let m = Model::base(Params::sample()).unwrap();
    /// let space = Space::with_rate(m, &Param::BASE, &[], 0.01);
    /// assert_eq!(space.dim(), 5);
    /// // The chart is one-to-one: a model maps to a point and back.
    /// let back = space.model_at(&space.point_of(&m));
    /// assert!((back.params.mu_k - m.params.mu_k).abs() < 1e-12);
    /// assert!((back.params.xi - m.params.xi).abs() < 1e-12);
    /// assert!((back.params.kappa - m.params.kappa).abs() < 1e-12);
    /// ```
    pub fn with_rate(
        base: Model,
        free: &[Param],
        bounds: &[(Param, f64, f64)],
        v_ref: f64,
    ) -> Space {
        match Space::try_with_rate(base, free, bounds, v_ref) {
            Ok(s) => s,
            Err(e) => panic!("invalid bounds: {e}"),
        }
    }

    /// As [`Space::with_rate`], with bounds given by a user in natural units: every bound is
    /// honoured or refused with the reason (`Err` names the parameter). A bound on μ_k, κ or ξ
    /// keeps the optimiser in those parameters themselves instead of the combined chart; μ_k
    /// is charted as a share of μ_s, so it can be bounded only while μ_s is fixed.
    ///
    /// ```
    /// use subfric_fit::{Param, Space};
    /// use subfric_model::{Model, Params};
    /// let m = Model::base(Params::sample()).unwrap();
    /// let s = Space::try_with_rate(m, &Param::BASE, &[(Param::Kappa, 1.0, 2.0)], 0.01).unwrap();
    /// assert_eq!(s.v_ref, 0.0); // no combined chart: the bound on κ is kept as such
    /// assert!(Space::try_with_rate(m, &Param::BASE, &[(Param::MuK, 0.1, 0.2)], 0.01).is_err());
    /// let fixed_mu_s = [Param::MuK, Param::Kappa];
    /// let s = Space::try_with_rate(m, &fixed_mu_s, &[(Param::MuK, 0.1, 0.2)], 0.01).unwrap();
    /// let hi = s.model_at(&s.hi).params.mu_k;
    /// assert!((hi - 0.2).abs() < 1e-12);
    /// ```
    pub fn try_with_rate(
        base: Model,
        free: &[Param],
        bounds: &[(Param, f64, f64)],
        v_ref: f64,
    ) -> Result<Space, String> {
        let mut free: Vec<Param> = free.to_vec();
        free.sort();
        free.dedup();
        let bounds = user_bounds(&base, &free, bounds)?;
        let bounded = |p: Param| bounds.iter().any(|(q, _, _)| *q == p);
        let combined = v_ref > 0.0
            && [Param::MuK, Param::Kappa, Param::Xi]
                .iter()
                .all(|p| free.contains(p) && !bounded(*p));
        let mut coords = Vec::new();
        let mut lo = Vec::new();
        let mut hi = Vec::new();
        let nat_bounds = |p: Param| {
            bounds
                .iter()
                .find(|(q, _, _)| *q == p)
                .map(|&(_, a, b)| (a, b))
                .unwrap_or_else(|| p.default_bounds())
        };
        for &p in &free {
            if combined && matches!(p, Param::MuK | Param::Kappa | Param::Xi) {
                continue;
            }
            let (a, b) = nat_bounds(p);
            coords.push(Coord::Natural(p));
            lo.push(forward(p.scale(), a));
            hi.push(forward(p.scale(), b));
        }
        if combined {
            let (ka, kb) = nat_bounds(Param::Kappa);
            let (xa, xb) = nat_bounds(Param::Xi);
            for (c, a, b) in [
                (
                    Coord::SteadyRatio,
                    logit(RATIO_BOUNDS.0),
                    logit(RATIO_BOUNDS.1),
                ),
                (
                    Coord::DecayRate,
                    (ka + xa / v_ref).ln(),
                    (kb + xb / v_ref).ln(),
                ),
                (
                    Coord::RecoveryShare,
                    logit(SHARE_BOUNDS.0),
                    logit(SHARE_BOUNDS.1),
                ),
            ] {
                coords.push(c);
                lo.push(a);
                hi.push(b);
            }
        }
        Ok(Space {
            base,
            free,
            coords,
            v_ref: if combined { v_ref } else { 0.0 },
            lo,
            hi,
        })
    }

    /// Number of optimiser coordinates.
    pub fn dim(&self) -> usize {
        self.coords.len()
    }

    /// The model at a point of the optimiser's space.
    pub fn model_at(&self, x: &[f64]) -> Model {
        let mut m = self.base;
        for (i, c) in self.coords.iter().enumerate() {
            if let Coord::Natural(p) = *c {
                if p != Param::MuK {
                    p.set(&mut m, backward(p.scale(), x[i]));
                }
            }
        }
        if let Some(i) = self
            .coords
            .iter()
            .position(|c| *c == Coord::Natural(Param::MuK))
        {
            m.params.mu_k = m.params.mu_s * sigmoid(x[i]);
        }
        if self.v_ref > 0.0 {
            let get = |c: Coord| {
                self.coords
                    .iter()
                    .position(|d| *d == c)
                    .map(|i| x[i])
                    .unwrap_or(0.0)
            };
            let ratio = sigmoid(get(Coord::SteadyRatio));
            let lambda = get(Coord::DecayRate).exp();
            let psi = sigmoid(get(Coord::RecoveryShare));
            let phi = psi * ratio;
            m.params.kappa = (1.0 - phi) * lambda;
            m.params.xi = phi * lambda * self.v_ref;
            // μ_ss = (1 − φ) μ_k + φ μ_s  ⇒  μ_k / μ_s = m (1 − ψ) / (1 − φ).
            m.params.mu_k = m.params.mu_s * ratio * (1.0 - psi) / (1.0 - phi);
        }
        if m.params.mu_k > m.params.mu_s {
            m.params.mu_k = m.params.mu_s;
        }
        if let Some(m0) = m.params.mu_0 {
            m.params.mu_0 = Some(m0.clamp(m.params.mu_k, m.params.mu_s));
        }
        m
    }

    /// The optimiser's coordinates of a model, clamped into the box.
    pub fn point_of(&self, m: &Model) -> Vec<f64> {
        let mu_s = m.params.mu_s;
        let q = (m.params.mu_k / mu_s).clamp(1e-12, 1.0 - 1e-12);
        let (kappa, xi, v) = (
            m.params.kappa.max(1e-12),
            m.params.xi.max(1e-15),
            self.v_ref,
        );
        let phi = xi / (kappa * v + xi);
        let ratio = ((1.0 - phi) * q + phi).clamp(RATIO_BOUNDS.0, RATIO_BOUNDS.1);
        let mut x: Vec<f64> = self
            .coords
            .iter()
            .map(|c| match *c {
                Coord::Natural(Param::MuK) => logit(q),
                Coord::Natural(p) => forward(p.scale(), p.get(m).unwrap_or_else(|| neutral(p))),
                Coord::SteadyRatio => logit(ratio),
                Coord::DecayRate => (kappa + xi / v).ln(),
                Coord::RecoveryShare => logit((phi / ratio).clamp(SHARE_BOUNDS.0, SHARE_BOUNDS.1)),
            })
            .collect();
        self.clamp(&mut x);
        x
    }

    /// The coordinates of `m` that sit at a bound of the box (within [`AT_BOUND_SHARE`] of its
    /// width): a fit that ends there has been stopped by the box, not by the data, and its
    /// other parameters may make up for it.
    pub fn at_bounds(&self, m: &Model) -> Vec<AtBound> {
        let x = self.point_of(m);
        (0..self.dim())
            .filter_map(|k| {
                let tolerance = AT_BOUND_SHARE * (self.hi[k] - self.lo[k]);
                let upper = if x[k] >= self.hi[k] - tolerance {
                    true
                } else if x[k] <= self.lo[k] + tolerance {
                    false
                } else {
                    return None;
                };
                let mut at = x.clone();
                at[k] = if upper { self.hi[k] } else { self.lo[k] };
                Some(AtBound {
                    coordinate: self.coords[k].name(),
                    value: self.coord_value(k, &x),
                    bound: self.coord_value(k, &at),
                    upper,
                })
            })
            .collect()
    }

    /// Natural values of the free parameters at `x`, in the order of `free`.
    pub fn natural(&self, x: &[f64]) -> Vec<f64> {
        let m = self.model_at(x);
        self.free
            .iter()
            .map(|p| p.get(&m).unwrap_or(f64::NAN))
            .collect()
    }

    /// Display value of coordinate `k` at `x`: the parameter itself, μ_ss at v_ref, λ, or ψ.
    pub fn coord_value(&self, k: usize, x: &[f64]) -> f64 {
        match self.coords[k] {
            Coord::Natural(p) => {
                let m = self.model_at(x);
                p.get(&m).unwrap_or(f64::NAN)
            }
            Coord::SteadyRatio => sigmoid(x[k]) * self.model_at(x).params.mu_s,
            Coord::DecayRate => x[k].exp(),
            Coord::RecoveryShare => sigmoid(x[k]),
        }
    }

    /// Natural box of a free parameter.
    pub fn natural_bounds(&self, p: Param) -> (f64, f64) {
        match p {
            Param::MuK => (0.0, self.base.params.mu_s.max(3.0)),
            _ => p.default_bounds(),
        }
    }

    /// Clamps a point into the box.
    pub fn clamp(&self, x: &mut [f64]) {
        for (i, v) in x.iter_mut().enumerate() {
            *v = if v.is_nan() {
                0.5 * (self.lo[i] + self.hi[i])
            } else {
                v.clamp(self.lo[i], self.hi[i])
            };
        }
    }
}

/// Checks user bounds (natural units) and converts those of μ_k to the chart's μ_k/μ_s.
fn user_bounds(
    base: &Model,
    free: &[Param],
    bounds: &[(Param, f64, f64)],
) -> Result<Vec<(Param, f64, f64)>, String> {
    let mut out = Vec::with_capacity(bounds.len());
    for &(p, lo, hi) in bounds {
        let key = p.key();
        if let Some(msg) = p.bounds_problem(lo, hi) {
            return Err(format!("{key}: {msg}"));
        }
        if !free.contains(&p) {
            return Err(format!(
                "{key} is not free, so a bound on it would have no effect (expected bounds on free parameters only)"
            ));
        }
        if p != Param::MuK {
            out.push((p, lo, hi));
            continue;
        }
        if free.contains(&Param::MuS) {
            return Err(format!(
                "{key}: the optimiser works in mu_k/mu_s while mu_s is free, so bounds on mu_k itself cannot be kept (expected mu_s fixed, e.g. --fix mu_s=VALUE, or no bound on mu_k)"
            ));
        }
        let mu_s = base.params.mu_s;
        let rhi = RATIO_BOUNDS.1;
        if lo / mu_s >= rhi {
            return Err(format!(
                "{key}: lower bound {lo} is not below mu_s = {mu_s} (expected mu_k < mu_s)"
            ));
        }
        out.push((p, (lo / mu_s).max(1e-9), (hi / mu_s).min(rhi)));
    }
    Ok(out)
}

/// A neutral value for an extension parameter not yet in the model.
fn neutral(p: Param) -> f64 {
    let (a, b) = p.default_bounds();
    match p.scale() {
        Scale::Linear => 0.0f64.clamp(a, b),
        _ => (a * b).sqrt(),
    }
}

#[cfg(test)]
mod at_bound_tests {
    use super::*;
    use subfric_model::Params;

    #[test]
    fn a_parameter_at_its_bound_is_flagged_and_one_inside_the_box_is_not() {
        let mut m = Model::base(Params::sample()).unwrap();
        let space = Space::new(m, &[Param::MuS, Param::UTilde], &[]);
        assert!(space.at_bounds(&m).is_empty(), "{:?}", space.at_bounds(&m));
        // mu_s at its default upper bound (3), u_tilde at its lower one (0.1).
        m.params.mu_s = 3.0;
        m.params.u_tilde = 0.1;
        let hits = space.at_bounds(&m);
        assert_eq!(hits.len(), 2, "{hits:?}");
        let mu_s = hits.iter().find(|h| h.coordinate == "mu_s").unwrap();
        assert!(mu_s.upper && (mu_s.bound - 3.0).abs() < 1e-9);
        let u = hits.iter().find(|h| h.coordinate == "u_tilde").unwrap();
        assert!(!u.upper && (u.bound - 0.1).abs() < 1e-12);
        assert!(
            mu_s.sentence().contains("upper bound 3.0000"),
            "{}",
            mu_s.sentence()
        );
        assert!(
            u.sentence().contains("lower bound 0.1000"),
            "{}",
            u.sentence()
        );
    }
}
