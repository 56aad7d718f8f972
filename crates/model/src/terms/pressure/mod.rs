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

use super::{DataScales, FormGuess, Shows, TermFamily, TermForm, TermParam, MAX_TERM_PARAMS};
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

impl TermFamily for Pressure {
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

    fn adds_term(&self) -> bool {
        false
    }

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
mod tests {
    use super::*;

    fn with(beta: f64, beta_k: f64, p_ref: f64) -> [f64; MAX_TERM_PARAMS] {
        let mut p = [0.0; MAX_TERM_PARAMS];
        p[BETA] = beta;
        p[BETA_K] = beta_k;
        p[P_REF] = p_ref;
        p
    }

    #[test]
    fn every_form_is_one_at_the_reference_and_follows_its_law_away_from_it() {
        let f = Pressure;
        let p = with(0.2, -0.1, 50.0);
        for (form, &(shape, on)) in SHAPES.iter().enumerate() {
            let scaled = if on == Target::Bounds {
                Target::MuS
            } else {
                on
            };
            assert_eq!(
                f.factor_on(form, &p, scaled, 50.0, -1.0),
                1.0,
                "{}",
                FORMS[form].key
            );
            let want = match shape {
                Shape::Power => 4f64.powf(-0.2),
                Shape::Linear => 1.0 - 0.2 * 3.0,
                Shape::Exponential => (-0.2f64 * 3.0).exp(),
            };
            let got = f.factor_on(form, &p, scaled, 200.0, 1.0);
            assert!(
                (got - want).abs() < 1e-15,
                "{}: {got} vs {want}",
                FORMS[form].key
            );
            // The general form scales μ_k by its own β_k; the others leave it alone.
            let on_k = f.factor_on(form, &p, Target::MuK, 200.0, 1.0);
            match on {
                Target::Bounds => assert!((on_k - shape.factor(-0.1, 4.0)).abs() < 1e-15),
                Target::MuK => assert_eq!(on_k, got),
                _ => assert_eq!(on_k, 1.0),
            }
            let (lo, hi) = f.range_on(form, &p, scaled);
            assert!(lo <= got && got <= hi, "{}", FORMS[form].key);
        }
        // The linear law is kept above 0.05.
        assert_eq!(f.factor_on(1, &p, Target::Friction, 1e4, 1.0), 0.05);
    }

    #[test]
    fn a_file_names_the_form_by_its_shape_and_target() {
        let f = Pressure;
        let obj = |text: &str| serde_json::from_str::<serde_json::Map<_, _>>(text).unwrap();
        assert_eq!(f.read_form(&obj("{}")), Ok(0));
        let k = f
            .read_form(&obj(r#"{"form": "linear", "target": "mu-k"}"#))
            .unwrap();
        assert_eq!(FORMS[k].describe, "linear on mu_k only");
        assert_eq!(
            f.form_fields(k),
            vec![("form", "linear".into()), ("target", "mu-k".into())]
        );
        // Every combination reads back from what it writes.
        for form in 0..FORMS.len() {
            let mut o = serde_json::Map::new();
            for (field, value) in f.form_fields(form) {
                o.insert(field.into(), value);
            }
            assert_eq!(f.read_form(&o), Ok(form));
        }
        let e = f.read_form(&obj(r#"{"target": "kappa"}"#)).unwrap_err();
        assert!(e.contains("`pressure.target` is \"kappa\""), "{e}");
        let e = f.read_form(&obj(r#"{"form": "cubic"}"#)).unwrap_err();
        assert!(e.contains("`pressure.form` is \"cubic\""), "{e}");
    }

    /// A data set of three normal stresses about `p_ref`, nothing read test by test.
    fn three_stresses(p_ref: f64) -> DataScales {
        DataScales {
            v_ref: 0.01,
            p_ref,
            slip_span_mm: 5.0,
            duration_s: 100.0,
            holds: 0,
            reversals: 0,
            pressure_levels: 3,
            sliding_rates: 1,
            traction_tests: 0,
            healing_per_decade: None,
            steps: crate::terms::StepReading::default(),
            rate_and_state: None,
            stress_trend: Default::default(),
            slip_slope_per_mm: None,
        }
    }

    #[test]
    fn the_diagnosis_tries_its_eight_forms_at_the_data_sets_reference_stress() {
        let data = three_stresses(196.0);
        assert_eq!((0..FORMS.len()).filter(|&k| Pressure.tries(k)).count(), 8);
        assert_eq!(Pressure.guess(3, &data).references, vec![(P_REF, 196.0)]);
        assert!(!Pressure.applies(&DataScales {
            pressure_levels: 1,
            ..data
        }));
    }

    #[test]
    fn the_first_start_is_read_off_the_tests_peaks_and_residuals() {
        let mut data = three_stresses(100.0);
        // Nothing read: the generic starts only.
        assert_eq!(Pressure.guess(3, &data).starts, vec![vec![0.1], vec![-0.1]]);
        // Peaks falling 8 % per e-fold of stress, residuals 2 %: β 0.08 on μ_s, 0.02 on μ_k.
        data.stress_trend = crate::terms::StressReading {
            peak: Some(-0.08),
            residual: Some(-0.02),
        };
        let first = |form: usize| Pressure.guess(form, &data).starts[0].clone();
        let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
        let key = |k: &str| FORMS.iter().position(|f| f.key == k).unwrap();
        assert!(close(&first(key("power-mu-s")), &[0.08]));
        assert!(close(&first(key("linear-mu-k")), &[0.02]));
        assert!(close(&first(key("power-bounds")), &[0.08, 0.02]));
        assert!(close(&first(key("exponential-friction")), &[0.05]));
        // The generic starts stay behind it.
        assert_eq!(Pressure.guess(key("power-mu-s"), &data).starts.len(), 3);
    }

    #[test]
    fn the_tests_readings_show_a_change_with_stress_or_rule_it_out() {
        use super::super::{EventReadings, Reading};
        let read = |value: f64, half: f64| Reading {
            value,
            lo: value - half,
            hi: value + half,
        };
        let events = |peak, residual| EventReadings {
            peak_change_per_efold: peak,
            residual_change_per_efold: residual,
            ..EventReadings::default()
        };
        // Peaks falling 10 % per e-fold: shown.
        let falling = events(Some(read(-0.1, 0.02)), Some(read(0.0, 0.01)));
        assert!(Pressure.shown(&falling) && !Pressure.contradicted(&falling));
        // Both flat within ±2 %: ruled out.
        let flat = events(Some(read(-0.003, 0.007)), Some(read(-0.001, 0.008)));
        assert!(!Pressure.shown(&flat) && Pressure.contradicted(&flat));
        // Flat but too uncertain to rule out 2 %, or only the peak read: neither.
        for e in [
            events(Some(read(0.0, 0.03)), Some(read(0.0, 0.01))),
            events(Some(read(0.0, 0.01)), None),
            EventReadings::default(),
        ] {
            assert!(!Pressure.shown(&e) && !Pressure.contradicted(&e), "{e:?}");
        }
    }
    #[test]
    fn a_law_follows_the_readings_when_it_moves_what_they_show_moving_their_way() {
        let read = |lo: f64, hi: f64| super::super::Reading {
            value: 0.5 * (lo + hi),
            lo,
            hi,
        };
        let events = |peak, residual| super::super::EventReadings {
            peak_change_per_efold: peak,
            residual_change_per_efold: residual,
            ..super::super::EventReadings::default()
        };
        let form = |key: &str| FORMS.iter().position(|f| f.key == key).unwrap();
        let law = |beta: f64, beta_k: f64| {
            let mut p = [0.0; MAX_TERM_PARAMS];
            (p[BETA], p[BETA_K], p[P_REF]) = (beta, beta_k, 100.0);
            p
        };
        // Peaks flat, residuals rising 3.5 % per e-fold (`lab-like` pair-42).
        let rising = events(Some(read(-0.021, 0.019)), Some(read(0.015, 0.055)));
        // A law on μ_s only moves what is read flat: it does not follow them, whatever β.
        assert!(!Pressure.follows_readings(form("power-mu-s"), &law(0.05, 0.0), &rising));
        assert!(!Pressure.follows_readings(form("power-mu-s"), &law(-0.05, 0.0), &rising));
        // On μ_k, rising with the stress (β < 0): it does; falling: it does not.
        assert!(Pressure.follows_readings(form("power-mu-k"), &law(-0.03, 0.0), &rising));
        assert!(!Pressure.follows_readings(form("power-mu-k"), &law(0.03, 0.0), &rising));
        // Both falling 6 % per e-fold: a law on μ falling follows; one on both with μ_k rising
        // moves a reading against its sign.
        let falling = events(Some(read(-0.075, -0.049)), Some(read(-0.076, -0.049)));
        assert!(Pressure.follows_readings(form("power-friction"), &law(0.06, 0.0), &falling));
        assert!(!Pressure.follows_readings(form("power-bounds"), &law(0.06, -0.02), &falling));
        // Nothing read changing: nothing followed.
        assert!(!Pressure.follows_readings(
            form("power-friction"),
            &law(0.06, 0.0),
            &super::super::EventReadings::default()
        ));
    }
}
