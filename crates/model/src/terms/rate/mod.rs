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
//! ([`TermLaw::slip_rate_law`]): R, V and the μ_k shift enter the consistency condition,
//! which is solved for the plastic slip of the step with θ integrated in closed form over it.
//!
//! In a parameter file: `"rate": {"form": "state-ageing", "at_rest": "creep", "a": 0.01,
//! "b": 0.012, "d_c": 0.05, "v_c": 1e-6, "v_ref": 0.01}` (older files wrote every field).

use super::{
    DataScales, EventReadings, FormGuess, Shows, TermEvidence, TermFile, TermForm, TermGuess,
    TermLaw, TermParam, ANY, MAX_TERM_PARAMS,
};
use serde_json::{Map, Value};

mod law;
mod state;

pub use law::{AtRest, RateEffect, RateForm};

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

impl TermLaw for Rate {
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

    fn adds_term(&self) -> bool {
        false
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

impl TermFile for Rate {
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
}

impl TermGuess for Rate {
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
}

impl TermEvidence for Rate {
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
}

#[cfg(test)]
mod tests;
