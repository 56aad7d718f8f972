//! Time healing: friction regained at rest as a law of the time θ since the contact last slid
//! (contact ageing: asperity creep, chemical bonding, grain rearrangement), as slide-hold-slide
//! tests show it — a peak on reloading that grows with the hold time. Three laws of θ:
//!
//! - log time, Δμ = b ln(1 + θ/t_c);
//! - power-law time, Δμ = b (θ / 1 s)^n;
//! - general, Δμ = b ((1 + θ/t_c)^n − 1)/n: the log law as n → 0, a power law for θ ≫ t_c,
//!   linear at n = 1, and for n < 0 a gain that levels off at b/|n| after a few t_c (n = −1:
//!   b θ/(θ + t_c)), as healing saturates at long holds — one law that holds the others, for
//!   healing laws none of them names.
//!
//! Each in three roles, the form's second half:
//!
//! - in place of the exponential recovery ξ(μ_s − μ) of Eq. (24): μ heals at rest by Δμ(θ), up
//!   to μ_s, and does not recover while it slides, so steady friction no longer depends on the
//!   rate through ξ;
//! - added to the recovery, which acts as in Eq. (24): the base model is the case b = 0, so
//!   the form cannot fit worse than it, and a contact that recovers as it slides and ages at
//!   rest is described without giving either up;
//! - a gain of its own on top of μ (which keeps the recovery), not capped at μ_s and erased by
//!   slip as exp(−Δs/d_h): the peak after a hold that sliding wipes out within a short slip,
//!   which neither the recovery of μ nor κ can shape.
//!
//! In a parameter file: `"healing": {"form": "log", "recovery": false, "b": 0.01, "t_c": 10}`;
//! a positive `d_h` makes the gain one of its own (older files wrote every field, `"d_h": 0`
//! for none).

use super::{
    DataScales, EventReadings, FormGuess, Shows, TermEvidence, TermFile, TermForm, TermGuess,
    TermLaw, TermParam, ANY, MAX_TERM_PARAMS,
};
use serde_json::{Map, Value};

/// The time-healing family (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct TimeHealing;

// t_c before b: a fit orders its free parameters by index, and healing's have always been
// in this order (t_c, b, n, d_h).
const T_C: usize = 0;
const B: usize = 1;
const N: usize = 2;
const D_H: usize = 3;

const PARAMS: [TermParam; 4] = [
    TermParam {
        key: "healing.t_c",
        name: "t_c",
        unit: "s",
        log_scale: true,
        bounds: (1e-3, 1e6),
        default: 10.0,
        expected: "a finite time > 0 [s]",
        within: ANY,
        reference: false,
    },
    TermParam {
        key: "healing.b",
        name: "b",
        unit: "",
        log_scale: false,
        bounds: (0.0, 0.3),
        default: 0.0,
        expected: "a finite number >= 0",
        within: ANY,
        reference: false,
    },
    TermParam {
        key: "healing.n",
        name: "n",
        unit: "",
        log_scale: false,
        bounds: (0.05, 1.0),
        default: 0.5,
        expected: "an exponent in (0, 1]",
        // The interval depends on the law (see `issues`).
        within: ANY,
        reference: false,
    },
    TermParam {
        key: "healing.d_h",
        name: "d_h",
        unit: "mm",
        log_scale: true,
        bounds: (1e-4, 10.0),
        default: 0.0,
        expected: "a finite slip > 0 [mm]",
        within: ANY,
        reference: false,
    },
];

/// The law of θ.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Law {
    Log,
    Power,
    General,
}

impl Law {
    fn key(self) -> &'static str {
        match self {
            Law::Log => "log",
            Law::Power => "power",
            Law::General => "general",
        }
    }
}

/// What the gain does beside the recovery of Eq. (24).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Role {
    /// In place of the recovery.
    Replaces,
    /// Added to μ beside the recovery.
    Added,
    /// A gain of its own, erased by slip over d_h.
    Erased,
}

/// Law and role of each form, in the order of [`FORMS`].
const SHAPES: [(Law, Role); 9] = [
    (Law::Log, Role::Replaces),
    (Law::Power, Role::Replaces),
    (Law::Log, Role::Added),
    (Law::Power, Role::Added),
    (Law::Log, Role::Erased),
    (Law::General, Role::Erased),
    (Law::General, Role::Replaces),
    (Law::General, Role::Added),
    (Law::Power, Role::Erased),
];

// In the order the diagnosis has always tried them; the last two are read from files and not
// tried (the general law holds them).
const FORMS: [TermForm; 9] = [
    TermForm {
        key: "log",
        describe: "log time, b ln(1 + t/t_c) at rest",
        params: &[B, T_C],
    },
    TermForm {
        key: "power",
        describe: "power-law time, b t^n at rest",
        params: &[B, N],
    },
    TermForm {
        key: "log-added",
        describe: "log time at rest, added to the recovery xi",
        params: &[B, T_C],
    },
    TermForm {
        key: "power-added",
        describe: "power-law time at rest, added to the recovery xi",
        params: &[B, N],
    },
    TermForm {
        key: "log-erased",
        describe: "log time at rest, a gain of its own erased by slip over d_h",
        params: &[B, T_C, D_H],
    },
    TermForm {
        key: "general-erased",
        describe: "general time at rest, a gain of its own erased by slip over d_h",
        params: &[B, T_C, N, D_H],
    },
    TermForm {
        key: "general",
        describe: "general time, b ((1 + t/t_c)^n - 1)/n at rest",
        params: &[B, T_C, N],
    },
    TermForm {
        key: "general-added",
        describe: "general time at rest, added to the recovery xi",
        params: &[B, T_C, N],
    },
    TermForm {
        key: "power-erased",
        describe: "power-law time at rest, a gain of its own erased by slip over d_h",
        params: &[B, N, D_H],
    },
];

/// The exponent of the general law: from a gain that levels off at b after a few t_c (−1)
/// through the log law (0) to a linear one (1).
const GENERAL_N: (f64, f64) = (-1.0, 1.0);

/// Forms the diagnosis tries (the first seven).
const TRIED: usize = 7;

/// Δμ(θ) of the general law; expm1 keeps it exact as n → 0, where it becomes b ln(1 + θ/t_c).
#[inline]
fn general(b: f64, t_c: f64, n: f64, theta: f64) -> f64 {
    let l = (theta / t_c).ln_1p();
    if n.abs() < 1e-12 {
        b * l
    } else {
        b * (n * l).exp_m1() / n
    }
}

impl TermLaw for TimeHealing {
    fn name(&self) -> &'static str {
        "log-healing"
    }

    fn describe(&self) -> &'static str {
        "time healing: friction regains strength at rest as a law of time, not by exponential recovery"
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
        form: usize,
        p: &[f64; MAX_TERM_PARAMS],
    ) -> Vec<(&'static str, f64, &'static str)> {
        let mut out = Vec::new();
        let (law, role) = SHAPES[form];
        if !(p[B] >= 0.0 && p[B].is_finite()) {
            out.push((PARAMS[B].key, p[B], PARAMS[B].expected));
        }
        if law != Law::Power && !PARAMS[T_C].valid(p[T_C]) {
            out.push((PARAMS[T_C].key, p[T_C], PARAMS[T_C].expected));
        }
        match law {
            Law::General if !(GENERAL_N.0..=GENERAL_N.1).contains(&p[N]) => {
                out.push((PARAMS[N].key, p[N], "an exponent in [-1, 1]"));
            }
            Law::Power if !(p[N] > 0.0 && p[N] <= 1.0) => {
                out.push((PARAMS[N].key, p[N], PARAMS[N].expected));
            }
            _ => {}
        }
        if role == Role::Erased && !PARAMS[D_H].valid(p[D_H]) {
            out.push((PARAMS[D_H].key, p[D_H], PARAMS[D_H].expected));
        }
        out
    }

    fn gains_at_rest(&self) -> bool {
        true
    }

    fn replaces_recovery(&self, form: usize) -> bool {
        SHAPES[form].1 == Role::Replaces
    }
}

impl TermFile for TimeHealing {
    fn aliases(&self) -> &'static [&'static str] {
        &["healing", "time-healing"]
    }

    fn key(&self) -> String {
        "healing".into()
    }

    fn read_form(&self, obj: &Map<String, Value>) -> Result<usize, String> {
        let law = match obj.get("form") {
            None => Law::Log,
            Some(v) => match v.as_str() {
                Some("log") => Law::Log,
                Some("power") => Law::Power,
                Some("general") => Law::General,
                _ => {
                    return Err(format!(
                        "unknown form {v} of `log-healing` (expected one of: log, power, general)"
                    ))
                }
            },
        };
        let recovery = match obj.get("recovery") {
            None => false,
            Some(v) => v
                .as_bool()
                .ok_or_else(|| format!("`healing.recovery` is {v} (expected true or false)"))?,
        };
        let erased = obj
            .get("d_h")
            .and_then(Value::as_f64)
            .is_some_and(|d| d != 0.0);
        let role = if erased {
            Role::Erased
        } else if recovery {
            Role::Added
        } else {
            Role::Replaces
        };
        Ok(SHAPES
            .iter()
            .position(|&s| s == (law, role))
            .expect("every law in every role"))
    }

    fn form_fields(&self, form: usize) -> Vec<(&'static str, Value)> {
        let (law, role) = SHAPES[form];
        vec![
            ("form", law.key().into()),
            ("recovery", (role != Role::Replaces).into()),
        ]
    }

    fn older_files_wrote_every_param(&self) -> bool {
        true
    }
}

impl TermGuess for TimeHealing {
    fn guess(&self, form: usize, data: &DataScales) -> FormGuess {
        // b of b ln(1 + t/t_c) from the gain per decade the holds show (ln 10 per decade).
        let b0 = data
            .healing_per_decade
            .map_or(0.005, |d| (d / std::f64::consts::LN_10).clamp(1e-4, 0.1));
        let guess =
            |starts: Vec<Vec<f64>>, neutral: Vec<f64>, bounds: Vec<(usize, f64, f64)>| FormGuess {
                starts,
                neutral,
                bounds,
                references: vec![],
            };
        match SHAPES[form] {
            (Law::Log, Role::Replaces) => guess(
                vec![vec![0.01, 1.0], vec![0.01, 30.0], vec![0.03, 10.0]],
                vec![0.0, 10.0],
                vec![],
            ),
            (Law::Power, Role::Replaces) => guess(
                vec![vec![0.005, 0.3], vec![0.002, 0.6], vec![0.01, 0.15]],
                vec![0.0, 0.3],
                vec![],
            ),
            (Law::Log, Role::Added) => guess(
                vec![vec![0.005, 1.0], vec![0.005, 30.0], vec![0.02, 10.0]],
                vec![0.0, 10.0],
                vec![],
            ),
            (Law::Power, Role::Added) => guess(
                vec![vec![0.003, 0.3], vec![0.001, 0.6], vec![0.005, 0.15]],
                vec![0.0, 0.3],
                vec![],
            ),
            (Law::Log, Role::Erased) => guess(
                vec![
                    vec![b0, 1.0, 0.02],
                    vec![b0, 10.0, 0.1],
                    vec![0.5 * b0, 1.0, 0.005],
                ],
                vec![0.0, 10.0, 0.02],
                vec![(2, 1e-4, 1.0)],
            ),
            // Each general form also starts saturating (n < 0: the gain levels off after a
            // few t_c), where the peaks of long holds gain less per decade than short ones.
            (Law::General, Role::Erased) => guess(
                vec![
                    vec![b0, 1.0, 0.05, 0.02],
                    vec![b0, 10.0, 0.3, 0.1],
                    vec![0.5 * b0, 1.0, 0.6, 0.005],
                    vec![4.0 * b0, 30.0, -0.5, 0.05],
                ],
                vec![0.0, 10.0, 0.3, 0.02],
                vec![(2, GENERAL_N.0, GENERAL_N.1), (3, 1e-4, 1.0)],
            ),
            (Law::General, _) => guess(
                vec![
                    vec![0.01, 1.0, 0.05],
                    vec![0.01, 10.0, 0.3],
                    vec![0.003, 1.0, 0.6],
                    vec![0.02, 30.0, -0.5],
                ],
                vec![0.0, 10.0, 0.3],
                vec![(2, GENERAL_N.0, GENERAL_N.1)],
            ),
            (Law::Power, Role::Erased) => guess(
                vec![
                    vec![b0, 0.3, 0.02],
                    vec![b0, 0.6, 0.1],
                    vec![0.5 * b0, 0.15, 0.005],
                ],
                vec![0.0, 0.3, 0.02],
                vec![(2, 1e-4, 1.0)],
            ),
        }
    }
}

impl TermEvidence for TimeHealing {
    fn shows(&self) -> &'static [Shows] {
        &[Shows::Holds]
    }

    fn tried_by_default(&self) -> bool {
        true
    }

    fn applies(&self, data: &DataScales) -> bool {
        data.holds > 0
    }

    fn tries(&self, form: usize) -> bool {
        form < TRIED
    }

    fn corroborated(&self, events: &EventReadings) -> bool {
        // A healing rate read over the holds must be positive.
        events.healing_per_decade.is_none_or(|h| h.value > 0.0)
    }

    fn contradicted(&self, events: &EventReadings) -> bool {
        // Friction read to fall with the hold time, the whole interval below zero.
        events.healing_per_decade.is_some_and(|h| h.hi < 0.0)
    }

    fn shown(&self, events: &EventReadings) -> bool {
        // The holds' peaks on reloading gain with the log of the hold time, the rate read over
        // them clear of zero, on two holds or more with a peak of their own. Each hold is one
        // reading of the law (a smooth misfit, a few independent rows: three holds cannot reach
        // the held-out evidence one long test can), so the readings carry the significance.
        // The base's own exponential recovery ξ gains with the hold time as well: the credit
        // still asks that most held-out holds be predicted better than the base predicts them
        // and that enough of their misfit be explained, which a base that recovers as the
        // holds show leaves no room for.
        events.holds_with_peak >= 2 && events.healing_per_decade.is_some_and(|h| h.lo > 0.0)
    }

    fn singled_out(&self, events: &EventReadings) -> Vec<usize> {
        // Two or more holds with a peak clear of zero point to a gain erased by slip — unless
        // the steps agree on rate and state, whose ageing law heals at rest itself.
        if events.holds_with_peak >= 2 && events.steps_agree_on_rate_and_state != Some(true) {
            (0..TRIED)
                .filter(|&k| SHAPES[k].1 == Role::Erased)
                .collect()
        } else {
            Vec::new()
        }
    }
}

impl TimeHealing {
    /// The friction form `form` gains at rest between contact ages `age` and `age + dt` [s].
    #[inline]
    pub(crate) fn rest_gain(
        &self,
        form: usize,
        p: &[f64; MAX_TERM_PARAMS],
        age: f64,
        dt: f64,
    ) -> f64 {
        let (b, t_c, n) = (p[B], p[T_C], p[N]);
        match SHAPES[form].0 {
            Law::Log => b * ((t_c + age + dt) / (t_c + age)).ln(),
            Law::Power => b * ((age + dt).powf(n) - age.max(0.0).powf(n)),
            Law::General => general(b, t_c, n, age + dt) - general(b, t_c, n, age.max(0.0)),
        }
    }

    /// The slip [mm] over which form `form`'s gain at rest, a friction of its own on top of μ,
    /// decays (e-fold) while the contact slides; `None` when the gain adds to μ itself, up to
    /// μ_s.
    #[inline]
    pub(crate) fn erased_over(&self, form: usize, p: &[f64; MAX_TERM_PARAMS]) -> Option<f64> {
        (SHAPES[form].1 == Role::Erased).then_some(p[D_H])
    }
}

mod state;

#[cfg(test)]
mod tests;
