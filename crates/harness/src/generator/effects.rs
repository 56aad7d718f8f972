//! Effects the paper's base model lacks, in forms taken from the friction literature, written
//! here from their equations (none of subfric_model's extension code is used).
//!
//! Every effect enters through the effective friction coefficient μ_eff that replaces μ in the
//! sliding condition ‖f_t‖ = r μ_eff f_n, or through the constants μ_s, μ_k, κ of Eq. (24):
//!
//! ```text
//! μ_eff = [(μ + rate_add + slip_add + healed) · slip_mult · rate_mult] · pressure_mult · direction_mult
//! ```
//!
//! - **Rate** (`v` the sliding rate, floored at `v_min`):
//!   rate and state (Dieterich–Ruina), `+ a ln(v/v*) + b ln(v* θ/D_c)` with the ageing law
//!   θ̇ = 1 − vθ/D_c or the slip law θ̇ = −(vθ/D_c) ln(vθ/D_c), θ₀ = D_c/v*;
//!   a power law, `× (v/v*)^n`; a log-rate direct effect without state, `+ A ln(v/v*)`.
//!   Two readings of the rate terms at rest ([`Reading`]).
//! - **Pressure** of the normal stress p: power law `(p/p_ref)^(−n)`, linear
//!   `1 − c (p/p_ref − 1)`, exponential `1 − Δ (1 − exp(−(p − p_ref)/p_c))`, on μ as a whole, on
//!   μ_s or on μ_k.
//! - **Slip** hardening (+) or softening (−) with the accumulated slip s: exponential
//!   `1 − exp(−s/λ)`, hyperbolic `s/(s + λ)`, capped linear `min(s/λ, 1)`, added to μ (`Δ φ`)
//!   or multiplying it (`1 + δ φ`).
//! - **Healing** at rest, a friction gain that grows with the time t the rig holds still, log
//!   `β log₁₀(1 + t/τ)` or power `c ((1 + t/τ)^m − 1)`, and is wiped out by slip over `d_h`.
//! - **Direction**: backward sliding (negative shear) multiplies μ, μ_k or κ by `1 + δ`.
//! - **Gaps** outside any effect family, on the recorded shear only: a linear drift in time
//!   and a slow sinusoidal vibration of the load cell.

use serde_json::{json, Map, Value};

/// The smallest effective friction coefficient an effect may leave (keeps the sliding condition
/// meaningful whatever the draw).
pub const MIN_MU_EFF: f64 = 0.02;

/// How the rate terms behave while the contact is not driven forward.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reading {
    /// Spring-slider reading: the rate is the plastic slip rate the sliding condition gives, at
    /// every instant; in a hold the contact keeps creeping and the shear relaxes through the
    /// rig's stiffness, down to the floor `v_min`.
    Creep,
    /// Locked reading: the rate is the rate the rig drives the contact at while it drives it
    /// forward; while the rig holds, unloads or reverses, the direct terms keep their last value
    /// and the state variable ages at zero rate (θ̇ = 1 for the ageing law, θ̇ = 0 for the slip
    /// law). No creep in holds.
    Locked,
}

impl Reading {
    fn name(self) -> &'static str {
        match self {
            Reading::Creep => "creep",
            Reading::Locked => "locked",
        }
    }
}

/// The evolution law of the rate-and-state variable θ.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StateLaw {
    /// Dieterich's ageing law θ̇ = 1 − vθ/D_c.
    Ageing,
    /// Ruina's slip law θ̇ = −(vθ/D_c) ln(vθ/D_c).
    Slip,
}

/// A rate effect's form and parameters (rates in mm/s, lengths in mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RateForm {
    /// Rate and state: `+ a ln(v/v*) + b ln(v* θ/D_c)`.
    State {
        /// Evolution law of θ.
        law: StateLaw,
        /// Direct-effect coefficient a.
        a: f64,
        /// Evolution coefficient b.
        b: f64,
        /// Characteristic slip distance D_c [mm].
        dc: f64,
    },
    /// Power law: `× (v/v*)^n`.
    Power {
        /// Exponent n (negative: rate weakening).
        n: f64,
    },
    /// Log-rate direct effect without state: `+ A ln(v/v*)`.
    Log {
        /// Coefficient A (negative: rate weakening).
        a: f64,
    },
}

/// A rate effect.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rate {
    /// Form and its coefficients.
    pub form: RateForm,
    /// Reference rate v* where the effect is neutral [mm/s].
    pub v_star: f64,
    /// Floor of the rate in the friction [mm/s].
    pub v_min: f64,
    /// Reading at rest.
    pub reading: Reading,
}

impl Rate {
    /// θ at the start of a test: steady at v* (the rate terms neutral).
    pub fn theta0(&self) -> f64 {
        match self.form {
            RateForm::State { dc, .. } => dc / self.v_star,
            _ => 0.0,
        }
    }

    /// θ after `dt` seconds at the constant rate `v` from `theta` (exact for constant v).
    pub fn evolve_theta(&self, theta: f64, v: f64, dt: f64) -> f64 {
        let RateForm::State { law, dc, .. } = self.form else {
            return theta;
        };
        let x = v.max(0.0) * dt / dc;
        match law {
            // θ₁ = θ₀ e^(−x) + dt (1 − e^(−x))/x: the exact solution, written so that v → 0
            // gives pure ageing θ₀ + dt.
            StateLaw::Ageing => {
                let decay = (-x).exp();
                let gain = if x > 1e-8 {
                    -(-x).exp_m1() / x
                } else {
                    1.0 - x / 2.0
                };
                theta * decay + dt * gain
            }
            // ln(vθ/D_c) decays as e^(−x) at constant v; at rest θ stays.
            StateLaw::Slip => {
                if v <= 0.0 || x == 0.0 {
                    return theta;
                }
                let phi = (v * theta / dc).ln() * (-x).exp();
                dc / v * phi.exp()
            }
        }
    }

    /// Additive rate terms at rate `v` and state `theta`.
    fn additive(&self, v: f64, theta: f64) -> f64 {
        let lv = (v.max(self.v_min) / self.v_star).ln();
        match self.form {
            RateForm::State { a, b, dc, .. } => {
                a * lv + b * (self.v_star * theta.max(1e-300) / dc).ln()
            }
            RateForm::Log { a } => a * lv,
            RateForm::Power { .. } => 0.0,
        }
    }

    /// Multiplicative rate factor at rate `v`.
    fn factor(&self, v: f64) -> f64 {
        match self.form {
            RateForm::Power { n } => (v.max(self.v_min) / self.v_star).powf(n),
            _ => 1.0,
        }
    }

    /// Form name as written to `truth.json`.
    pub fn name(&self) -> String {
        let base = match self.form {
            RateForm::State {
                law: StateLaw::Ageing,
                ..
            } => "rsf-ageing",
            RateForm::State {
                law: StateLaw::Slip,
                ..
            } => "rsf-slip",
            RateForm::Power { .. } => "rate-power",
            RateForm::Log { .. } => "rate-log",
        };
        format!("{base}-{}", self.reading.name())
    }

    fn kw(&self, m: &mut Map<String, Value>) {
        match self.form {
            RateForm::State { a, b, dc, .. } => {
                m.insert("a".into(), json!(a));
                m.insert("b".into(), json!(b));
                m.insert("dc".into(), json!(dc));
            }
            RateForm::Power { n } => {
                m.insert("n".into(), json!(n));
            }
            RateForm::Log { a } => {
                m.insert("a".into(), json!(a));
            }
        }
        m.insert("v_star".into(), json!(self.v_star));
        m.insert("v_min".into(), json!(self.v_min));
    }
}

/// What a pressure or direction effect acts on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// μ_eff as a whole.
    Mu,
    /// The static coefficient μ_s (and so μ₀).
    MuS,
    /// The kinetic coefficient μ_k.
    MuK,
    /// The decay rate κ.
    Kappa,
}

impl Target {
    fn name(self) -> &'static str {
        match self {
            Target::Mu => "mu",
            Target::MuS => "mu_s",
            Target::MuK => "mu_k",
            Target::Kappa => "kappa",
        }
    }
}

/// Shape of a pressure dependence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PressureShape {
    /// `(p/p_ref)^(−n)`.
    Power {
        /// Exponent n (positive: friction falls with stress).
        n: f64,
    },
    /// `1 − c (p/p_ref − 1)`.
    Linear {
        /// Slope c per p_ref.
        c: f64,
    },
    /// `1 − Δ (1 − exp(−(p − p_ref)/p_c))`: a drop Δ approached over the stress scale p_c.
    Exponential {
        /// Drop Δ (negative: a rise).
        drop: f64,
        /// Stress scale p_c [kPa].
        p_c: f64,
    },
}

/// A pressure dependence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pressure {
    /// Its shape.
    pub shape: PressureShape,
    /// What it multiplies: μ, μ_s or μ_k.
    pub target: Target,
    /// Stress where the factor is 1 [kPa].
    pub p_ref: f64,
}

impl Pressure {
    /// The factor at normal stress `p`.
    pub fn factor(&self, p: f64) -> f64 {
        let x = p / self.p_ref;
        let g = match self.shape {
            PressureShape::Power { n } => x.powf(-n),
            PressureShape::Linear { c } => 1.0 - c * (x - 1.0),
            PressureShape::Exponential { drop, p_c } => {
                1.0 - drop * (1.0 - (-(p - self.p_ref) / p_c).exp())
            }
        };
        g.max(0.1)
    }

    /// Form name as written to `truth.json`.
    pub fn name(&self) -> String {
        let shape = match self.shape {
            PressureShape::Power { .. } => "power",
            PressureShape::Linear { .. } => "linear",
            PressureShape::Exponential { .. } => "exp",
        };
        format!("pressure-{shape}-{}", self.target.name())
    }

    fn kw(&self, m: &mut Map<String, Value>) {
        match self.shape {
            PressureShape::Power { n } => m.insert("p_exponent".into(), json!(n)),
            PressureShape::Linear { c } => m.insert("p_slope".into(), json!(c)),
            PressureShape::Exponential { drop, p_c } => {
                m.insert("p_scale_kpa".into(), json!(p_c));
                m.insert("p_drop".into(), json!(drop))
            }
        };
        m.insert("p_ref".into(), json!(self.p_ref));
    }
}

/// Shape φ(s) of a slip dependence, 0 at s = 0 and 1 for long slip.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SlipShape {
    /// `1 − exp(−s/λ)`.
    Exponential,
    /// `s/(s + λ)`.
    Hyperbolic,
    /// `min(s/λ, 1)`.
    LinearCapped,
}

/// How a slip dependence enters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Combine {
    /// `μ + Δ φ(s)`.
    Additive,
    /// `μ (1 + δ φ(s))`.
    Multiplicative,
}

/// Slip hardening (positive amount) or softening (negative).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slip {
    /// Shape.
    pub shape: SlipShape,
    /// Additive or multiplicative.
    pub combine: Combine,
    /// Δ (additive) or δ (multiplicative), signed.
    pub amount: f64,
    /// Length λ [mm].
    pub length: f64,
}

impl Slip {
    /// φ(s).
    pub fn shape_at(&self, s: f64) -> f64 {
        let x = s.max(0.0) / self.length;
        match self.shape {
            SlipShape::Exponential => -(-x).exp_m1(),
            SlipShape::Hyperbolic => x / (1.0 + x),
            SlipShape::LinearCapped => x.min(1.0),
        }
    }

    /// Form name as written to `truth.json`.
    pub fn name(&self) -> String {
        let kind = if self.amount >= 0.0 {
            "hardening"
        } else {
            "softening"
        };
        let shape = match self.shape {
            SlipShape::Exponential => "exp",
            SlipShape::Hyperbolic => "hyp",
            SlipShape::LinearCapped => "capped",
        };
        let combine = match self.combine {
            Combine::Additive => "add",
            Combine::Multiplicative => "mult",
        };
        format!("slip-{kind}-{shape}-{combine}")
    }

    fn kw(&self, m: &mut Map<String, Value>) {
        m.insert("h".into(), json!(self.amount));
        m.insert("lambda_c".into(), json!(self.length));
    }
}

/// Shape of the healing gain with time at rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HealShape {
    /// `β log₁₀(1 + t/τ)`.
    Log {
        /// Gain per decade of hold time β.
        per_decade: f64,
    },
    /// `c ((1 + t/τ)^m − 1)`.
    Power {
        /// Coefficient c.
        c: f64,
        /// Exponent m.
        m: f64,
    },
}

/// Time healing at rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Healing {
    /// Shape.
    pub shape: HealShape,
    /// Onset time τ [s].
    pub tau: f64,
    /// Slip that wipes the gain out, e-fold [mm].
    pub d_h: f64,
}

impl Healing {
    /// Gain after `t` seconds at rest.
    pub fn gain(&self, t: f64) -> f64 {
        let x = t.max(0.0) / self.tau;
        match self.shape {
            HealShape::Log { per_decade } => per_decade * (1.0 + x).log10(),
            HealShape::Power { c, m } => c * ((1.0 + x).powf(m) - 1.0),
        }
    }

    /// Form name as written to `truth.json`.
    pub fn name(&self) -> String {
        match self.shape {
            HealShape::Log { .. } => "healing-log".into(),
            HealShape::Power { .. } => "healing-power".into(),
        }
    }

    fn kw(&self, m: &mut Map<String, Value>) {
        match self.shape {
            HealShape::Log { per_decade } => {
                m.insert("beta_per_decade".into(), json!(per_decade));
            }
            HealShape::Power { c, m: exponent } => {
                m.insert("heal_coefficient".into(), json!(c));
                m.insert("heal_exponent".into(), json!(exponent));
            }
        }
        m.insert("tau".into(), json!(self.tau));
        m.insert("d_heal".into(), json!(self.d_h));
    }
}

/// Backward sliding differs from forward sliding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Direction {
    /// μ, μ_k or κ.
    pub target: Target,
    /// Backward factor − 1.
    pub delta: f64,
}

impl Direction {
    /// Form name as written to `truth.json`.
    pub fn name(&self) -> String {
        format!("direction-{}", self.target.name())
    }
}

/// A gap in the recorded shear that no physical effect makes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Gap {
    /// The load cell drifts linearly in time from the start of the run.
    Drift {
        /// Drift [kPa/s].
        kpa_per_s: f64,
    },
    /// The load cell vibrates slowly.
    Vibration {
        /// Amplitude [kPa].
        amplitude_kpa: f64,
        /// Period [s].
        period_s: f64,
        /// Phase [rad].
        phase: f64,
    },
    /// The load cell creeps: its reading approaches (1 + share) × the load with a first-order
    /// lag of `tau_s` (a step of load F₀ reads F₀ (1 + share (1 − e^(−t/τ)))), and recovers as
    /// the load comes off.
    Creep {
        /// Share of the load the creep reaches.
        share: f64,
        /// Time constant [s].
        tau_s: f64,
    },
}

impl Gap {
    /// What it adds to the shear recorded at each time `t` of a run whose shear is `f`.
    pub fn offsets(&self, t: &[f64], f: &[f64]) -> Vec<f64> {
        match *self {
            Gap::Creep { share, tau_s } => {
                let mut lagged = 0.0;
                (0..t.len())
                    .map(|i| {
                        if i > 0 {
                            let a = -(-(t[i] - t[i - 1]).max(0.0) / tau_s).exp_m1();
                            lagged += a * (f[i] - lagged);
                        }
                        share * lagged
                    })
                    .collect()
            }
            _ => t.iter().map(|&ti| self.offset(ti)).collect(),
        }
    }

    /// What a gap that depends on time alone adds to the shear recorded at time `t` of the run
    /// (a creep, which depends on the load's history, adds nothing here: see
    /// [`Gap::offsets`]).
    fn offset(&self, t: f64) -> f64 {
        match *self {
            Gap::Creep { .. } => 0.0,
            Gap::Drift { kpa_per_s } => kpa_per_s * t,
            Gap::Vibration {
                amplitude_kpa,
                period_s,
                phase,
            } => amplitude_kpa * (std::f64::consts::TAU * t / period_s + phase).sin(),
        }
    }

    /// Form name as written to `truth.json`.
    pub fn name(&self) -> String {
        match self {
            Gap::Drift { .. } => "drift-linear".into(),
            Gap::Vibration { .. } => "vibration".into(),
            Gap::Creep { .. } => "load-cell-creep".into(),
        }
    }

    fn kw(&self, m: &mut Map<String, Value>) {
        match *self {
            Gap::Drift { kpa_per_s } => {
                m.insert("drift_kpa_per_s".into(), json!(kpa_per_s));
            }
            Gap::Creep { share, tau_s } => {
                m.insert("share".into(), json!(share));
                m.insert("tau_s".into(), json!(tau_s));
            }
            Gap::Vibration {
                amplitude_kpa,
                period_s,
                phase,
            } => {
                m.insert("A".into(), json!(amplitude_kpa));
                m.insert("P".into(), json!(period_s));
                m.insert("phase".into(), json!(phase));
            }
        }
    }
}

/// The effects of one generated set (all `None`: the base model).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Effects {
    /// Rate dependence.
    pub rate: Option<Rate>,
    /// Pressure dependence.
    pub pressure: Option<Pressure>,
    /// Slip hardening or softening.
    pub slip: Option<Slip>,
    /// Healing at rest.
    pub healing: Option<Healing>,
    /// Direction dependence.
    pub direction: Option<Direction>,
    /// A gap in the recorded shear.
    pub gap: Option<Gap>,
}

/// The constants of Eq. (24) at one normal stress and sliding direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Local {
    /// μ_s.
    pub mu_s: f64,
    /// μ_k.
    pub mu_k: f64,
    /// κ [1/mm].
    pub kappa: f64,
}

/// What μ_eff depends on besides μ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Condition {
    /// Normal stress [kPa].
    pub p: f64,
    /// Sliding direction, +1 or −1.
    pub dir: f64,
    /// Rate the rate terms see [mm/s].
    pub v: f64,
    /// Rate-and-state variable θ [s].
    pub theta: f64,
    /// Accumulated plastic slip [mm].
    pub path: f64,
    /// Healing gain.
    pub healed: f64,
}

impl Effects {
    /// μ_s, μ_k, κ at normal stress `p` sliding in direction `dir`.
    pub fn local(&self, mu_s: f64, mu_k: f64, kappa: f64, p: f64, dir: f64) -> Local {
        let mut l = Local { mu_s, mu_k, kappa };
        if let Some(pr) = self.pressure {
            match pr.target {
                Target::MuS => l.mu_s *= pr.factor(p),
                Target::MuK => l.mu_k *= pr.factor(p),
                Target::Mu | Target::Kappa => {}
            }
        }
        if let Some(d) = self.direction.filter(|_| dir < 0.0) {
            match d.target {
                Target::MuK => l.mu_k *= 1.0 + d.delta,
                Target::Kappa => l.kappa *= 1.0 + d.delta,
                Target::Mu | Target::MuS => {}
            }
        }
        // μ_k below μ_s whatever the factors (Eq. 24 needs μ_k ≤ μ ≤ μ_s).
        l.mu_k = l.mu_k.min(0.98 * l.mu_s);
        l
    }

    /// The effective friction coefficient of the sliding condition.
    pub fn mu_eff(&self, mu: f64, c: &Condition) -> f64 {
        let mut add = mu + c.healed;
        let mut mult = 1.0;
        if let Some(r) = self.rate {
            add += r.additive(c.v, c.theta);
            mult *= r.factor(c.v);
        }
        if let Some(s) = self.slip {
            let phi = s.shape_at(c.path);
            match s.combine {
                Combine::Additive => add += s.amount * phi,
                Combine::Multiplicative => mult *= 1.0 + s.amount * phi,
            }
        }
        if let Some(pr) = self.pressure.filter(|p| p.target == Target::Mu) {
            mult *= pr.factor(c.p);
        }
        if let Some(d) = self
            .direction
            .filter(|d| d.target == Target::Mu && c.dir < 0.0)
        {
            mult *= 1.0 + d.delta;
        }
        (add * mult).max(MIN_MU_EFF)
    }

    /// The families built in, by the names `subfric selfcheck --sets` reads.
    pub fn families(&self) -> Vec<&'static str> {
        let mut out = Vec::new();
        if self.rate.is_some() {
            out.push("rate");
        }
        if self.pressure.is_some() {
            out.push("pressure");
        }
        if self.slip.is_some() {
            out.push("slip-hardening");
        }
        if self.healing.is_some() {
            out.push("log-healing");
        }
        if self.direction.is_some() {
            out.push("direction");
        }
        if self.gap.is_some() {
            out.push("unexplained");
        }
        out
    }

    /// Each effect built in: (family, form name, its parameters).
    pub fn described(&self) -> Vec<(&'static str, String, Map<String, Value>)> {
        let mut out = Vec::new();
        let mut m = Map::new();
        if let Some(r) = self.rate {
            r.kw(&mut m);
            out.push(("rate", r.name(), std::mem::take(&mut m)));
        }
        if let Some(p) = self.pressure {
            p.kw(&mut m);
            out.push(("pressure", p.name(), std::mem::take(&mut m)));
        }
        if let Some(s) = self.slip {
            s.kw(&mut m);
            out.push(("slip-hardening", s.name(), std::mem::take(&mut m)));
        }
        if let Some(h) = self.healing {
            h.kw(&mut m);
            out.push(("log-healing", h.name(), std::mem::take(&mut m)));
        }
        if let Some(d) = self.direction {
            m.insert("delta".into(), json!(d.delta));
            out.push(("direction", d.name(), std::mem::take(&mut m)));
        }
        if let Some(g) = self.gap {
            g.kw(&mut m);
            out.push(("unexplained", g.name(), std::mem::take(&mut m)));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rsf(law: StateLaw) -> Rate {
        Rate {
            form: RateForm::State {
                law,
                a: 0.01,
                b: 0.012,
                dc: 0.05,
            },
            v_star: 0.01,
            v_min: 1e-9,
            reading: Reading::Locked,
        }
    }

    #[test]
    fn theta_steps_solve_the_state_laws() {
        // Many small explicit Euler steps of each law agree with the closed-form step.
        for law in [StateLaw::Ageing, StateLaw::Slip] {
            let r = rsf(law);
            let (v, dt, theta0): (f64, f64, f64) = (0.1, 3.0, 20.0);
            let mut th = theta0;
            let n = 200_000;
            let h = dt / n as f64;
            for _ in 0..n {
                let rate = match law {
                    StateLaw::Ageing => 1.0 - v * th / 0.05,
                    StateLaw::Slip => -(v * th / 0.05) * (v * th / 0.05).ln(),
                };
                th += h * rate;
            }
            let exact = r.evolve_theta(theta0, v, dt);
            assert!((exact / th - 1.0).abs() < 1e-4, "{law:?}: {exact} vs {th}");
        }
        // At rest the ageing law ages by the time held; the slip law does not heal.
        assert!((rsf(StateLaw::Ageing).evolve_theta(5.0, 0.0, 100.0) - 105.0).abs() < 1e-9);
        assert_eq!(rsf(StateLaw::Slip).evolve_theta(5.0, 0.0, 100.0), 5.0);
    }

    #[test]
    fn forms_are_neutral_at_their_reference_and_differ_elsewhere() {
        let base = Condition {
            p: 100.0,
            dir: 1.0,
            v: 0.01,
            theta: 5.0,
            path: 0.0,
            healed: 0.0,
        };
        let fx = Effects {
            rate: Some(rsf(StateLaw::Ageing)),
            ..Effects::default()
        };
        assert!((fx.mu_eff(0.5, &base) - 0.5).abs() < 1e-12);
        let p = |shape| Pressure {
            shape,
            target: Target::Mu,
            p_ref: 100.0,
        };
        let shapes = [
            PressureShape::Power { n: 0.1 },
            PressureShape::Linear { c: 0.1 },
            PressureShape::Exponential {
                drop: 0.2,
                p_c: 200.0,
            },
        ];
        let at400: Vec<f64> = shapes.iter().map(|&s| p(s).factor(400.0)).collect();
        for (s, f) in shapes.iter().zip(&at400) {
            assert!((p(*s).factor(100.0) - 1.0).abs() < 1e-12);
            assert!(*f < 1.0, "{s:?} falls with stress");
        }
        assert!((at400[0] - at400[1]).abs() > 0.02 && (at400[1] - at400[2]).abs() > 0.02);
        let slip = |shape| Slip {
            shape,
            combine: Combine::Additive,
            amount: 0.1,
            length: 2.0,
        };
        let at2: Vec<f64> = [
            SlipShape::Exponential,
            SlipShape::Hyperbolic,
            SlipShape::LinearCapped,
        ]
        .iter()
        .map(|&s| slip(s).shape_at(2.0))
        .collect();
        assert!((at2[0] - 0.632).abs() < 1e-3 && at2[1] == 0.5 && at2[2] == 1.0);
    }
}
