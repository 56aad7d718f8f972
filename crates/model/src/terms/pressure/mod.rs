//! Pressure dependence: friction changes with the normal stress p — a curved failure envelope of
//! the sand, crushing or flattening of the grains against the metal under load. A factor P(p) on
//! μ as a whole, on μ_s or μ_k only, or on μ_s and μ_k each with its own size (β and β_k: the
//! general form, which holds the others as special cases), with P one at the reference normal
//! stress p_ref of the data set:
//!
//! - power law, P = (p/p_ref)^(−β);
//! - linear, P = 1 − β (p/p_ref − 1), kept above 0.05;
//! - exponential, P = exp(−β (p/p_ref − 1)).
//!
//! β > 0: friction falls as the normal stress rises. In parameter files the shape is the field
//! `form` and what it scales the field `target` (`"pressure": {"beta": 0.1, "form": "power",
//! "target": "mu-s", "p_ref": 100}`), as they have always been written.

use super::{
    DataScales, FormGuess, Shows, TermEvidence, TermFile, TermForm, TermGuess, TermLaw, TermParam,
    MAX_TERM_PARAMS,
};
use crate::Target;

/// The pressure family (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct Pressure;

const BETA: usize = 0;
const BETA_K: usize = 1;
const P_REF: usize = 2;

const PARAMS: [TermParam; 3] = [
    TermParam {
        key: "pressure.beta",
        name: "beta",
        unit: "",
        log_scale: false,
        bounds: (-1.0, 1.0),
        default: 0.0,
        expected: "a finite number in (-5, 5)",
        within: (-5.0, 5.0),
        reference: false,
    },
    TermParam {
        key: "pressure.beta_k",
        name: "beta_k",
        unit: "",
        log_scale: false,
        bounds: (-1.0, 1.0),
        default: 0.0,
        expected: "a finite number in (-5, 5)",
        within: (-5.0, 5.0),
        reference: false,
    },
    TermParam {
        key: "pressure.p_ref",
        name: "p_ref",
        unit: "kPa",
        log_scale: true,
        bounds: (1e-3, 1e7),
        default: crate::extensions::PRESSURE_REF_KPA,
        expected: "a finite stress > 0 [kPa]",
        within: (0.0, f64::INFINITY),
        reference: true,
    },
];

/// The shape of P.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Shape {
    Power,
    Linear,
    Exponential,
}

impl Shape {
    fn key(self) -> &'static str {
        match self {
            Shape::Power => "power",
            Shape::Linear => "linear",
            Shape::Exponential => "exponential",
        }
    }

    /// P at x = p/p_ref with size β.
    fn factor(self, beta: f64, x: f64) -> f64 {
        match self {
            Shape::Power => x.powf(-beta),
            Shape::Linear => (1.0 - beta * (x - 1.0)).max(0.05),
            Shape::Exponential => (-beta * (x - 1.0)).exp(),
        }
    }

    /// Least and greatest P over every p > 0 (P is monotone in p: its limits at p → 0 and
    /// p → ∞).
    fn range(self, beta: f64) -> (f64, f64) {
        if beta == 0.0 {
            return (1.0, 1.0);
        }
        match (self, beta > 0.0) {
            (Shape::Power, _) => (0.0, f64::INFINITY),
            (Shape::Linear, true) => (0.05, (1.0 + beta).max(0.05)),
            (Shape::Linear, false) => ((1.0 + beta).max(0.05), f64::INFINITY),
            (Shape::Exponential, true) => (0.0, beta.exp()),
            (Shape::Exponential, false) => (beta.exp(), f64::INFINITY),
        }
    }
}

/// Shape and target of each form, in the order of [`FORMS`]: the eight the diagnosis tries
/// first, then the combinations only a parameter file may ask for.
const SHAPES: [(Shape, Target); 12] = [
    (Shape::Power, Target::Friction),
    (Shape::Linear, Target::Friction),
    (Shape::Exponential, Target::Friction),
    (Shape::Power, Target::MuS),
    (Shape::Power, Target::MuK),
    (Shape::Linear, Target::MuS),
    (Shape::Linear, Target::MuK),
    (Shape::Power, Target::Bounds),
    (Shape::Exponential, Target::MuS),
    (Shape::Exponential, Target::MuK),
    (Shape::Linear, Target::Bounds),
    (Shape::Exponential, Target::Bounds),
];

/// How many of the forms the diagnosis tries.
const TRIED: usize = 8;

const ONE: &[usize] = &[BETA, P_REF];
const TWO: &[usize] = &[BETA, BETA_K, P_REF];

const FORMS: [TermForm; 12] = [
    TermForm {
        key: "power-friction",
        describe: "power law on mu, (p/p_ref)^-beta",
        params: ONE,
    },
    TermForm {
        key: "linear-friction",
        describe: "linear on mu, 1 - beta (p/p_ref - 1)",
        params: ONE,
    },
    TermForm {
        key: "exponential-friction",
        describe: "exponential on mu, exp(-beta (p/p_ref - 1))",
        params: ONE,
    },
    TermForm {
        key: "power-mu-s",
        describe: "power law on mu_s only",
        params: ONE,
    },
    TermForm {
        key: "power-mu-k",
        describe: "power law on mu_k only",
        params: ONE,
    },
    TermForm {
        key: "linear-mu-s",
        describe: "linear on mu_s only",
        params: ONE,
    },
    TermForm {
        key: "linear-mu-k",
        describe: "linear on mu_k only",
        params: ONE,
    },
    TermForm {
        key: "power-bounds",
        describe: "power law on mu_s and mu_k, each its own beta",
        params: TWO,
    },
    TermForm {
        key: "exponential-mu-s",
        describe: "exponential on mu_s only",
        params: ONE,
    },
    TermForm {
        key: "exponential-mu-k",
        describe: "exponential on mu_k only",
        params: ONE,
    },
    TermForm {
        key: "linear-bounds",
        describe: "linear on mu_s and mu_k, each its own beta",
        params: TWO,
    },
    TermForm {
        key: "exponential-bounds",
        describe: "exponential on mu_s and mu_k, each its own beta",
        params: TWO,
    },
];

/// A relative change of a stress ratio per e-fold of normal stress that the tests rule out
/// when its interval lies within ±this: 2 %, twice the reproducibility of one test's reading
/// (repeat specimens differ by 1 %) and below the weakest pressure dependence the literature
/// reports for sand on steel (an exponent of 0.03).
const NEUTRAL_PER_EFOLD: f64 = 0.02;

/// Largest |β| a first guess read off the tests takes (the bounds are ±1).
const READ_BETA: f64 = 0.9;

/// β (and β_k) of a form scaling `on`, read off the tests' stress ratios: every shape has
/// d ln P / d ln p = −β at the reference stress (the power law's exponent, the linear and the
/// exponential laws' slope there), so −β is the relative change of the peak (μ_s), of the
/// residual (μ_k) or of both (μ as a whole: their mean) per e-fold of normal stress. `None`
/// when the tests show neither.
fn read_off_tests(on: Target, t: &super::StressReading) -> Option<Vec<f64>> {
    let beta = |r: Option<f64>| {
        r.filter(|v| v.is_finite())
            .map(|v| (-v).clamp(-READ_BETA, READ_BETA))
    };
    let (peak, residual) = (beta(t.peak), beta(t.residual));
    match on {
        Target::MuS => peak.map(|b| vec![b]),
        Target::MuK => residual.map(|b| vec![b]),
        Target::Bounds => (peak.is_some() || residual.is_some())
            .then(|| vec![peak.unwrap_or(0.0), residual.unwrap_or(0.0)]),
        _ => match (peak, residual) {
            (Some(a), Some(b)) => Some(vec![0.5 * (a + b)]),
            (a, b) => a.or(b).map(|v| vec![v]),
        },
    }
}

/// The name of a target in files.
fn target_key(t: Target) -> &'static str {
    match t {
        Target::Friction => "friction",
        Target::MuS => "mu-s",
        Target::MuK => "mu-k",
        Target::Kappa => "kappa",
        Target::UTilde => "u-tilde",
        Target::Bounds => "bounds",
    }
}

impl TermLaw for Pressure {
    fn name(&self) -> &'static str {
        "pressure"
    }

    fn describe(&self) -> &'static str {
        "pressure dependence: friction changes with the normal stress"
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

    fn targets(&self, form: usize) -> &'static [Target] {
        match SHAPES[form].1 {
            Target::Friction => &[Target::Friction],
            Target::MuS => &[Target::MuS],
            Target::MuK => &[Target::MuK],
            _ => &[Target::Bounds],
        }
    }

    fn factor_on(
        &self,
        form: usize,
        p: &[f64; MAX_TERM_PARAMS],
        target: Target,
        normal_kpa: f64,
        _cos_forward: f64,
    ) -> f64 {
        let (shape, on) = SHAPES[form];
        let x = normal_kpa / p[P_REF];
        // β scales the form's target (μ_s under the general form), β_k μ_k.
        super::size_on(on, target).map_or(1.0, |i| shape.factor(p[[BETA, BETA_K][i]], x))
    }

    fn range_on(&self, form: usize, p: &[f64; MAX_TERM_PARAMS], target: Target) -> (f64, f64) {
        let (shape, on) = SHAPES[form];
        super::size_on(on, target).map_or((1.0, 1.0), |i| shape.range(p[[BETA, BETA_K][i]]))
    }

    fn reads_normal_stress(&self) -> bool {
        true
    }
}

impl TermFile for Pressure {
    fn read_form(&self, obj: &serde_json::Map<String, serde_json::Value>) -> Result<usize, String> {
        let field = |name: &str, default: &'static str| match obj.get(name) {
            None => Ok(default.to_string()),
            Some(serde_json::Value::String(s)) => Ok(s.clone()),
            Some(v) => Err(format!("`pressure.{name}` is {v} (expected a string)")),
        };
        let (shape, target) = (field("form", "power")?, field("target", "friction")?);
        if !SHAPES.iter().any(|(s, _)| s.key() == shape) {
            return Err(format!(
                "`pressure.form` is \"{shape}\" (expected one of: power, linear, exponential)"
            ));
        }
        SHAPES
            .iter()
            .position(|&(s, t)| s.key() == shape && target_key(t) == target)
            .ok_or_else(|| {
                format!(
                    "`pressure.target` is \"{target}\" (expected one of: friction, mu-s, mu-k, bounds)"
                )
            })
    }

    fn form_fields(&self, form: usize) -> Vec<(&'static str, serde_json::Value)> {
        let (shape, target) = SHAPES[form];
        vec![
            ("form", shape.key().into()),
            ("target", target_key(target).into()),
        ]
    }
}

impl TermGuess for Pressure {
    fn guess(&self, form: usize, data: &DataScales) -> FormGuess {
        let mut starts = if SHAPES[form].1 == Target::Bounds {
            vec![vec![0.1, 0.1], vec![-0.1, -0.1], vec![0.1, -0.1]]
        } else {
            vec![vec![0.1], vec![-0.1]]
        };
        if let Some(read) = read_off_tests(SHAPES[form].1, &data.stress_trend) {
            starts.insert(0, read);
        }
        FormGuess {
            neutral: vec![0.0; starts[0].len()],
            starts,
            bounds: vec![],
            references: vec![(P_REF, data.p_ref)],
        }
    }
}

impl TermEvidence for Pressure {
    fn shows(&self) -> &'static [Shows] {
        &[Shows::AwayFromReferenceStress]
    }

    fn tried_by_default(&self) -> bool {
        true
    }

    fn applies(&self, data: &DataScales) -> bool {
        // One normal stress says nothing of a change with it.
        data.pressure_levels > 1
    }

    fn tries(&self, form: usize) -> bool {
        form < TRIED
    }

    fn shown(&self, events: &super::EventReadings) -> bool {
        // The peak or the residual changes with the normal stress beyond its interval.
        [
            events.peak_change_per_efold,
            events.residual_change_per_efold,
        ]
        .iter()
        .flatten()
        .any(|r| r.excludes_zero())
    }

    fn follows_readings(
        &self,
        form: usize,
        p: &[f64; MAX_TERM_PARAMS],
        events: &super::EventReadings,
    ) -> bool {
        // The relative change per e-fold of normal stress at the reference that the form gives
        // μ_s (read as the peak) and μ_k (read as the residual): −β for each it scales (every
        // shape's slope in ln p at p = p_ref).
        let Some(&(_, target)) = SHAPES.get(form) else {
            return false;
        };
        let (on_s, on_k) = match target {
            Target::Friction => (-p[BETA], -p[BETA]),
            Target::MuS => (-p[BETA], 0.0),
            Target::MuK => (0.0, -p[BETA]),
            Target::Bounds => (-p[BETA], -p[BETA_K]),
            // No pressure form scales κ or ũ: such a law moves neither reading.
            Target::Kappa | Target::UTilde => (0.0, 0.0),
        };
        let shown = [
            (events.peak_change_per_efold, on_s),
            (events.residual_change_per_efold, on_k),
        ];
        let shown: Vec<(f64, f64)> = shown
            .iter()
            .filter_map(|(r, change)| r.filter(|r| r.excludes_zero()).map(|r| (r.value, *change)))
            .collect();
        // One reading that changes followed in its sign, and none moved against its sign.
        shown.iter().any(|(read, law)| read * law > 0.0)
            && shown.iter().all(|(read, law)| read * law >= 0.0)
    }

    fn shown_in(&self) -> &'static [Shows] {
        // The peak and residual stress ratios are read on the tests' first loadings.
        &[Shows::FirstLoadings]
    }

    fn contradicted(&self, events: &super::EventReadings) -> bool {
        // Both the peak and the residual read over two stresses or more, and neither can
        // change by as much as NEUTRAL_PER_EFOLD: every form scales μ, μ_s or μ_k, so a
        // pressure effect moves one of them.
        match (
            events.peak_change_per_efold,
            events.residual_change_per_efold,
        ) {
            (Some(p), Some(r)) => [p, r]
                .iter()
                .all(|x| x.lo > -NEUTRAL_PER_EFOLD && x.hi < NEUTRAL_PER_EFOLD),
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests;
