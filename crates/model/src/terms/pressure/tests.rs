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
        p_ref,
        pressure_levels: 3,
        ..crate::terms::tests::one_rate_one_stress()
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
