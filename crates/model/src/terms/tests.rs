//! Tests of the registry, over every registered family, and the data scales the families'
//! tests start from.
use super::*;

/// A data set slid at one rate (0.01 mm/s) and one normal stress (100 kPa), its tests sliding
/// 5 mm over 100 s, no hold, reversal or step, nothing read test by test: what the families'
/// tests override field by field.
pub(crate) fn one_rate_one_stress() -> DataScales {
    DataScales {
        v_ref: 0.01,
        p_ref: 100.0,
        slip_span_mm: 5.0,
        duration_s: 100.0,
        holds: 0,
        reversals: 0,
        pressure_levels: 1,
        sliding_rates: 1,
        traction_tests: 0,
        healing_per_decade: None,
        steps: StepReading::default(),
        rate_and_state: None,
        stress_trend: Default::default(),
        slip_slope_per_mm: None,
        slip_to_peak_mm: None,
    }
}

#[test]
fn every_family_is_consistent() {
    assert!(FAMILIES.len() <= MAX_FAMILIES, "raise MAX_FAMILIES");
    let mut names = Vec::new();
    for (index, fam) in FAMILIES.iter().enumerate() {
        assert!(!names.contains(&fam.name()), "{} twice", fam.name());
        names.push(fam.name());
        assert!(fam.params().len() <= MAX_TERM_PARAMS, "{}", fam.name());
        assert!(!fam.forms().is_empty() && !fam.shows().is_empty());
        for q in fam.params() {
            let (lo, hi) = q.bounds;
            assert!(lo < hi && q.valid(lo) && q.valid(hi), "{}", q.key);
            assert!(q.key.ends_with(q.name), "{}", q.key);
        }
        let scales = DataScales {
            duration_s: 600.0,
            holds: 1,
            reversals: 1,
            pressure_levels: 2,
            sliding_rates: 2,
            ..one_rate_one_stress()
        };
        for (k, form) in fam.forms().iter().enumerate() {
            let g = fam.guess(k, &scales);
            assert!(!g.starts.is_empty());
            let fitted = fam.fitted(k);
            for v in g.starts.iter().chain([&g.neutral]) {
                assert_eq!(v.len(), fitted.len(), "{}", form.key);
            }
            // Every reference of the form gets its value from the data.
            for &i in form.params.iter().filter(|&&i| fam.params()[i].reference) {
                assert!(g.references.iter().any(|&(j, _)| j == i), "{}", form.key);
            }
            // The neutral values switch the term and every factor off everywhere.
            let mut e = TermEffect::new(index as u8, k as u8);
            for (&i, &v) in fitted.iter().zip(&g.neutral) {
                e.p[i] = v;
            }
            for &(i, v) in &g.references {
                e.p[i] = v;
            }
            for (s, t) in [(0.0, 0.0), (3.0, 100.0), (10.0, 1e4)] {
                assert_eq!(fam.term(k, &e.p, s, t).0, 0.0, "{}", form.key);
            }
            let targets = [
                Target::Friction,
                Target::MuS,
                Target::MuK,
                Target::Kappa,
                Target::UTilde,
            ];
            for (target, p, cos) in [(targets[0], 30.0, -1.0), (targets[4], 400.0, 0.3)] {
                assert_eq!(fam.factor_on(k, &e.p, target, p, cos), 1.0, "{}", form.key);
            }
            for target in targets {
                assert_eq!(fam.range_on(k, &e.p, target), (1.0, 1.0), "{}", form.key);
            }
            // A family that adds no term says what it scales, gains at rest or reads the rate,
            // or acts through a state of its own.
            assert!(
                fam.adds_term()
                    || !fam.targets(k).is_empty()
                    || fam.gains_at_rest()
                    || fam.reads_slip_rate()
                    || FamilyLaw::of(&e).is_some(),
                "{}",
                form.key
            );
        }
    }
}

#[test]
fn a_term_reads_back_what_it_writes_and_refuses_an_unknown_family() {
    for (index, fam) in FAMILIES.iter().enumerate() {
        for k in 0..fam.forms().len() {
            let mut e = TermEffect::new(index as u8, k as u8);
            for (i, q) in fam.params().iter().enumerate() {
                // A valid value away from the default, so a lost field shows.
                e.p[i] = 0.5 * (q.bounds.0 + q.bounds.1) + 0.25 * (q.bounds.1 - q.bounds.0);
            }
            let text = serde_json::to_string(&e).unwrap();
            let back: TermEffect = serde_json::from_str(&text).unwrap();
            for &i in fam.forms()[k].params {
                // serde_json reads a written number back to within an ulp or so.
                let (a, b) = (back.p[i], e.p[i]);
                assert!((a - b).abs() <= 4.0 * f64::EPSILON * b.abs(), "{text}");
            }
            assert_eq!((back.family, back.form), (e.family, e.form), "{text}");
        }
    }
    let err = serde_json::from_str::<TermEffect>(r#"{"family": "no-such-family"}"#)
        .unwrap_err()
        .to_string();
    assert!(err.contains("unknown family `no-such-family`"), "{err}");
    assert!(serde_json::from_str::<TermEffect>(r#"{"form": "linear"}"#).is_err());
}

#[test]
fn several_families_are_written_under_their_keys_and_read_back() {
    let mut terms = Terms::NONE;
    for (index, fam) in FAMILIES.iter().enumerate() {
        let k = fam.forms().len() - 1;
        let e = terms.insert(TermEffect::new(index as u8, k as u8));
        for &i in fam.forms()[k].params {
            let q = &fam.params()[i];
            e.p[i] = 0.25 * q.bounds.0 + 0.75 * q.bounds.1;
        }
    }
    let text = serde_json::to_string(&terms).unwrap();
    for fam in FAMILIES {
        assert!(
            text.contains(&format!("\"{}\":{{\"{}\"", fam.key(), fam.form_field())),
            "{text}"
        );
    }
    let back: Terms = serde_json::from_str(&text).unwrap();
    // serde_json reads a written number back to within an ulp or so.
    assert_eq!(back.iter().count(), terms.iter().count());
    for (a, b) in back.iter().zip(terms.iter()) {
        assert_eq!((a.family, a.form), (b.family, b.form), "{text}");
        for (x, y) in a.p.iter().zip(&b.p) {
            assert!((x - y).abs() <= 4.0 * f64::EPSILON * y.abs(), "{text}");
        }
    }
    // The `term` object of older files reads as the family's own key.
    let trend = family_named("time-trend").unwrap().0;
    let old: Terms =
        serde_json::from_str(r#"{"term": {"family": "time-trend", "c": 2e-5}}"#).unwrap();
    assert_eq!(old.of(trend).unwrap().p[0], 2e-5);
    let twice = r#"{"term": {"family": "time-trend"}, "time_trend": {"c": 1e-5}}"#;
    let err = serde_json::from_str::<Terms>(twice)
        .unwrap_err()
        .to_string();
    assert!(err.contains("given twice"), "{err}");
    // Other keys are not this reader's business; a family's key holding no object is.
    assert!(serde_json::from_str::<Terms>(r#"{"not_a_family": 3}"#)
        .unwrap()
        .is_empty());
    assert!(serde_json::from_str::<Terms>(r#"{"slip_hardening": 3}"#).is_err());
    // The sum of the terms is the sum of each.
    let (s, t) = (0.7, 40.0);
    let sum: f64 = terms.iter().map(|e| e.term(s, t).0).sum();
    assert_eq!(terms.total(s, t).0, sum);
}

#[test]
fn every_state_is_declared_once_and_starts_as_its_law_allows() {
    let mut names: Vec<&str> = Vec::new();
    for (index, fam) in FAMILIES.iter().enumerate() {
        // Every form of a family with a state declares the same variables.
        let Some(law) = FamilyLaw::of(&TermEffect::new(index as u8, 0)) else {
            continue;
        };
        let vars = law.vars();
        assert!(
            !vars.is_empty() && vars.len() <= MAX_STATE_SLOTS,
            "{}",
            fam.name()
        );
        for v in vars {
            // Messages and `Terms::slot_of` find a variable by its name: one family's each.
            assert!(
                !names.contains(&v.name),
                "state variable `{}` twice",
                v.name
            );
            names.push(v.name);
        }
        for (k, form) in fam.forms().iter().enumerate() {
            let e = TermEffect::new(index as u8, k as u8);
            let form_vars = FamilyLaw::of(&e).map(|law| law.vars());
            assert_eq!(form_vars.map(<[_]>::len), Some(vars.len()), "{}", form.key);
            let terms = Terms::one(e);
            let start = terms.initial_state();
            assert_eq!(terms.invalid_state(&start), None, "{}", form.key);
            for (i, v) in vars.iter().enumerate() {
                assert_eq!(terms.slot_of(v.name), Some(i), "{}", form.key);
            }
            // Unused slots stay zero, and are named by their place.
            assert!(start.0[vars.len()..].iter().all(|&x| x == 0.0));
            assert_eq!(
                terms.slot_names()[MAX_STATE_SLOTS - 1],
                if vars.len() < MAX_STATE_SLOTS {
                    "slots[4]"
                } else {
                    vars[MAX_STATE_SLOTS - 1].name
                }
            );
        }
    }
    // Rate and time healing are the families with a state.
    assert!(
        names.contains(&"theta") && names.contains(&"age"),
        "{names:?}"
    );
}
