//! Rate dependence: friction changes with the plastic slip rate v — the direct effect of a
//! faster slide, and, in rate-and-state friction, its evolution with a state variable θ over a
//! slip D_c. The forms of the literature:
//!
//! - direct effect only, R = a [ln(1 + v/v_c) − ln(1 + v_ref/v_c)];
//! - rate and state with the ageing law θ̇ = 1 − vθ/D_c or the slip law
//!   θ̇ = −(vθ/D_c) ln(vθ/D_c): R = direct + b ln(θ v_ref/D_c);
//! - a power law, V = ((v + v_c)/(v_ref + v_c))^n multiplying μ;
//! - steady state only: the kinetic bound of Eq. (24) becomes μ_k + a ln((v + v_c)/(v_ref + v_c)),
//!   transients following κ rather than a direct effect.
//!
//! The first four either creep at rest (the spring-slider reading: the rate terms hold at every
//! instant) or are locked (the rate terms of the last slide are kept while the contact rests,
//! only θ evolves) — see [`AtRest`]. Every term vanishes at v_ref, so μ_s and μ_k keep their
//! meaning at the set's typical rate.
//!
//! The family gives the return mapping its law as a [`RateEffect`]
//! ([`TermFamily::slip_rate_law`]): R, V and the μ_k shift enter the consistency condition,
//! which is solved for the plastic slip of the step with θ integrated in closed form over it.
//!
//! In a parameter file: `"rate": {"form": "state-ageing", "at_rest": "creep", "a": 0.01,
//! "b": 0.012, "d_c": 0.05, "v_c": 1e-6, "v_ref": 0.01}` (older files wrote every field).

use super::{
    DataScales, EventReadings, FormGuess, Shows, TermEffect, TermFamily, TermForm, TermParam, ANY,
    MAX_TERM_PARAMS,
};
use crate::integrator::{exp_neg, relax_weight};
use serde_json::{Map, Value};

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
    fn key(self) -> &'static str {
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
/// on μ and its derivative, the shift of μ_k (steady-state form) and its derivative, and θ at
/// the end of the step.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RateTerms {
    pub add: f64,
    pub dadd: f64,
    pub factor: f64,
    pub dfactor: f64,
    pub mu_k_shift: f64,
    pub dmu_k: f64,
    pub theta: f64,
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
        let (family, _) = super::family_named(Rate.name()).expect("rate is registered");
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

    /// The rate terms at plastic increment `lam` over a step of `dt` from state `theta`.
    #[inline]
    pub(crate) fn plastic_terms(&self, theta: f64, dt: f64, lam: f64) -> RateTerms {
        let vdt = self.v_c * dt;
        let mut t = RateTerms {
            add: 0.0,
            dadd: 0.0,
            factor: 1.0,
            dfactor: 0.0,
            mu_k_shift: 0.0,
            dmu_k: 0.0,
            theta,
        };
        match self.form {
            RateForm::LogDirect | RateForm::StateAgeing | RateForm::StateSlip => {
                t.add = self.a * ((lam / vdt).ln_1p() - self.direct_at_ref());
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
                    t.theta = ln_theta.exp();
                    t.add += self.b * (ln_theta + (self.state_ref() / self.d_c).ln());
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
}

/// The rate family (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct Rate;

// In the order a fit has always ordered them (a, v_c, b, D_c, n); v_ref is the set's.
const A: usize = 0;
const V_C: usize = 1;
const B: usize = 2;
const D_C: usize = 3;
const N: usize = 4;
const V_REF: usize = 5;

const PARAMS: [TermParam; 6] = [
    TermParam {
        key: "rate.a",
        name: "a",
        unit: "",
        log_scale: false,
        bounds: (-0.2, 0.2),
        default: 0.0,
        expected: "a finite number",
        within: ANY,
        reference: false,
    },
    TermParam {
        key: "rate.v_c",
        name: "v_c",
        unit: "mm/s",
        log_scale: true,
        bounds: (1e-9, 10.0),
        default: 1e-4,
        expected: "a finite rate > 0 [mm/s]",
        within: ANY,
        reference: false,
    },
    TermParam {
        key: "rate.b",
        name: "b",
        unit: "",
        log_scale: false,
        bounds: (-0.2, 0.2),
        default: 0.0,
        expected: "a finite number",
        within: ANY,
        reference: false,
    },
    TermParam {
        key: "rate.d_c",
        name: "d_c",
        unit: "mm",
        log_scale: true,
        bounds: (1e-4, 10.0),
        default: 1.0,
        expected: "a finite slip distance > 0 [mm]",
        within: ANY,
        reference: false,
    },
    TermParam {
        key: "rate.n",
        name: "n",
        unit: "",
        log_scale: false,
        bounds: (-0.5, 0.5),
        default: 0.0,
        expected: "an exponent in (-2, 2)",
        within: (-2.0, 2.0),
        reference: false,
    },
    TermParam {
        key: "rate.v_ref",
        name: "v_ref",
        unit: "mm/s",
        log_scale: false,
        bounds: (0.0, 10.0),
        default: 0.0,
        expected: "a finite rate >= 0 [mm/s]",
        within: ANY,
        reference: true,
    },
];

/// Form and reading at rest (locked) of each form, in the order of [`FORMS`].
const SHAPES: [(RateForm, bool); 9] = [
    (RateForm::LogDirect, false),
    (RateForm::StateAgeing, false),
    (RateForm::StateSlip, false),
    (RateForm::Power, false),
    (RateForm::LogDirect, true),
    (RateForm::StateAgeing, true),
    (RateForm::StateSlip, true),
    (RateForm::Power, true),
    (RateForm::SteadyState, false),
];

// In the order the diagnosis has always tried them.
const FORMS: [TermForm; 9] = [
    TermForm {
        key: "log-direct",
        describe: "direct effect a ln(1 + v/v_c)",
        params: &[A, V_C, V_REF],
    },
    TermForm {
        key: "state-ageing",
        describe: "rate and state, ageing law",
        params: &[A, B, D_C, V_C, V_REF],
    },
    TermForm {
        key: "state-slip",
        describe: "rate and state, slip law",
        params: &[A, B, D_C, V_C, V_REF],
    },
    TermForm {
        key: "power",
        describe: "power law ((v + v_c)/v_ref)^n",
        params: &[N, V_C, V_REF],
    },
    TermForm {
        key: "log-direct-locked",
        describe: "direct effect, locked at rest",
        params: &[A, V_C, V_REF],
    },
    TermForm {
        key: "state-ageing-locked",
        describe: "rate and state, ageing law, locked at rest",
        params: &[A, B, D_C, V_C, V_REF],
    },
    TermForm {
        key: "state-slip-locked",
        describe: "rate and state, slip law, locked at rest",
        params: &[A, B, D_C, V_C, V_REF],
    },
    TermForm {
        key: "power-locked",
        describe: "power law, locked at rest",
        params: &[N, V_C, V_REF],
    },
    TermForm {
        key: "steady-state",
        describe: "steady state only, mu_k + a ln(v/v_ref)",
        params: &[A, V_C, V_REF],
    },
];

impl TermFamily for Rate {
    fn name(&self) -> &'static str {
        "rate"
    }

    fn describe(&self) -> &'static str {
        "rate dependence: friction changes with the slip rate"
    }

    fn params(&self) -> &'static [TermParam] {
        &PARAMS
    }

    fn forms(&self) -> &'static [TermForm] {
        &FORMS
    }

    fn shows(&self) -> &'static [Shows] {
        &[Shows::VelocitySteps, Shows::Holds]
    }

    fn tried_by_default(&self) -> bool {
        true
    }

    fn applies(&self, data: &DataScales) -> bool {
        data.sliding_rates > 1 || data.holds > 0
    }

    fn varies(&self, data: &DataScales) -> bool {
        // Holds alone at one sliding rate: a rate-and-state state that ages at rest and a
        // healing law both raise the peak on reloading, and nothing in the record tells them
        // apart (a velocity step would).
        data.sliding_rates > 1 || data.traction_tests > 0
    }

    fn adds_term(&self) -> bool {
        false
    }

    fn guess(&self, form: usize, data: &DataScales) -> FormGuess {
        // The velocity steps' signature: their jump gives a, their decay length D_c, the
        // steady change a − b.
        let v = data.v_ref;
        let g = &data.steps;
        let a0 = g.direct.clamp(0.002, 0.05);
        let b0 = (g.direct - g.steady).clamp(0.0, 0.05);
        let dc0 = g.decay_mm.clamp(1e-3, 1.0);
        let ss0 = g.steady.clamp(-0.03, 0.03);
        let cut = [1e-4 * v, 1e-2 * v];
        let (starts, neutral, v_c_hi) = match SHAPES[form].0 {
            RateForm::StateAgeing | RateForm::StateSlip => {
                let mut starts = vec![
                    vec![a0, b0, dc0, cut[0]],
                    vec![a0, b0, dc0, cut[1]],
                    vec![0.01, 0.008, 0.05, cut[0]],
                    vec![0.5 * a0, 0.0, dc0, cut[1]],
                ];
                // The velocity steps fitted one by one give the best first guess when they
                // could.
                if let Some((a, b, dc)) = data.rate_and_state {
                    let (a, b, dc) = (a.clamp(1e-4, 0.1), b.clamp(-0.05, 0.1), dc.clamp(1e-4, 1.0));
                    starts.push(vec![a, b, dc, cut[0]]);
                    starts.push(vec![a, b, dc, cut[1]]);
                }
                (starts, vec![0.0, 0.0, dc0, cut[1]], 0.3 * v)
            }
            RateForm::LogDirect => (
                vec![
                    vec![a0, cut[0]],
                    vec![a0, cut[1]],
                    vec![ss0, cut[1]],
                    vec![-0.01, 0.1 * v],
                ],
                vec![0.0, cut[1]],
                10.0 * v,
            ),
            RateForm::Power => (
                vec![
                    vec![(a0 / 0.6).min(0.1), cut[0]],
                    vec![(ss0 / 0.6).clamp(-0.1, 0.1), cut[1]],
                    vec![-0.02, cut[1]],
                ],
                vec![0.0, cut[1]],
                10.0 * v,
            ),
            RateForm::SteadyState => (
                vec![vec![ss0, cut[0]], vec![0.01, cut[0]], vec![-0.01, cut[0]]],
                vec![0.0, cut[0]],
                0.3 * v,
            ),
        };
        // v_c is the last fitted parameter of every form.
        let v_c_index = neutral.len() - 1;
        FormGuess {
            starts,
            neutral,
            bounds: vec![(v_c_index, 1e-7 * v, v_c_hi)],
            references: vec![(V_REF, v)],
        }
    }

    fn read_form(&self, obj: &Map<String, Value>) -> Result<usize, String> {
        let form = match obj.get("form") {
            None => RateForm::LogDirect,
            Some(v) => {
                let forms = [
                    RateForm::LogDirect,
                    RateForm::StateAgeing,
                    RateForm::StateSlip,
                    RateForm::Power,
                    RateForm::SteadyState,
                ];
                let key = v.as_str().unwrap_or_default();
                *forms.iter().find(|f| f.key() == key).ok_or_else(|| {
                    format!(
                        "unknown form {v} of `rate` (expected one of: log-direct, state-ageing, state-slip, power, steady-state)"
                    )
                })?
            }
        };
        let locked = match obj.get("at_rest").map(|v| (v, v.as_str())) {
            None | Some((_, Some("creep"))) => false,
            Some((_, Some("locked"))) => true,
            Some((v, _)) => {
                return Err(format!(
                    "`rate.at_rest` is {v} (expected \"creep\" or \"locked\")"
                ))
            }
        };
        // The steady-state form has no term that could creep or lock.
        let locked = locked && form != RateForm::SteadyState;
        Ok(SHAPES
            .iter()
            .position(|&s| s == (form, locked))
            .expect("every form in both readings"))
    }

    fn form_fields(&self, form: usize) -> Vec<(&'static str, Value)> {
        let (rate_form, locked) = SHAPES[form];
        vec![
            ("form", rate_form.key().into()),
            ("at_rest", if locked { "locked" } else { "creep" }.into()),
        ]
    }

    fn older_files_wrote_every_param(&self) -> bool {
        true
    }

    fn issues(
        &self,
        _form: usize,
        p: &[f64; MAX_TERM_PARAMS],
    ) -> Vec<(&'static str, f64, &'static str)> {
        // Every parameter, whatever the form, as files have always been checked.
        let mut out: Vec<_> = [A, B, N]
            .into_iter()
            .filter(|&i| !p[i].is_finite())
            .map(|i| (PARAMS[i].key, p[i], "a finite number"))
            .collect();
        for i in [V_C, D_C] {
            if !(p[i] > 0.0 && p[i].is_finite()) {
                out.push((PARAMS[i].key, p[i], PARAMS[i].expected));
            }
        }
        if !(p[V_REF] >= 0.0 && p[V_REF].is_finite()) {
            out.push((PARAMS[V_REF].key, p[V_REF], PARAMS[V_REF].expected));
        }
        if p[N].abs() >= 2.0 {
            out.push((PARAMS[N].key, p[N], PARAMS[N].expected));
        }
        out
    }

    fn corroborated(&self, events: &EventReadings) -> bool {
        // Velocity steps that were read must mostly show a direct effect.
        events
            .steps_agree_on_rate_and_state
            .is_none_or(|agree| agree)
    }

    fn contradicted(&self, events: &EventReadings) -> bool {
        // Two or more steps read, and not one shows a direct effect.
        events.steps_read >= 2 && events.steps_with_direct_effect == 0
    }

    fn shown(&self, events: &EventReadings) -> bool {
        // The velocity steps, each fitted on its own with a spring-slider, mostly show a direct
        // effect (two at least, and two thirds of those whose rows resolve the transient): each
        // step is one reading of the law, and its own fit weighs every row of its transient,
        // where the held-out pieces weigh a step as one piece predicted from the others — after
        // a first effect, five steps each read at D 40–1100 left the rate law D 13 on their
        // held-out pieces (misfit 15.9 → 2.8× the noise), below what a piece must show alone.
        events.steps_agree_on_rate_and_state == Some(true) && events.steps_with_direct_effect >= 2
    }

    fn shown_in(&self) -> &'static [Shows] {
        // What shows it outright is read on the steps; a hold's reload is not a step.
        &[Shows::VelocitySteps]
    }

    fn singled_out(&self, events: &EventReadings) -> Vec<usize> {
        // When the steps agree on rate and state, every rate-and-state form: on a base that
        // lacks another effect they may rank low, and the steps say they are the ones to try.
        if events.steps_agree_on_rate_and_state == Some(true) {
            (0..FORMS.len())
                .filter(|&k| matches!(SHAPES[k].0, RateForm::StateAgeing | RateForm::StateSlip))
                .collect()
        } else {
            Vec::new()
        }
    }

    fn reads_slip_rate(&self) -> bool {
        true
    }

    fn slip_rate_law(&self, form: usize, p: &[f64; MAX_TERM_PARAMS]) -> Option<RateEffect> {
        let (rate_form, locked) = SHAPES[form];
        Some(RateEffect {
            form: rate_form,
            a: p[A],
            v_c: p[V_C],
            b: p[B],
            d_c: p[D_C],
            n: p[N],
            v_ref: p[V_REF],
            at_rest: if locked {
                AtRest::Locked
            } else {
                AtRest::Creep
            },
        })
    }
}

#[cfg(test)]
mod tests;
