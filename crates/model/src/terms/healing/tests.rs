use super::*;

fn p(b: f64, t_c: f64, n: f64, d_h: f64) -> [f64; MAX_TERM_PARAMS] {
    let mut out = [0.0; MAX_TERM_PARAMS];
    (out[B], out[T_C], out[N], out[D_H]) = (b, t_c, n, d_h);
    out
}

#[test]
fn peaks_that_gain_with_the_log_of_the_hold_time_show_healing_outright() {
    let with = |holds_with_peak: usize, lo: f64, hi: f64| super::super::EventReadings {
        healing_per_decade: Some(super::super::Reading {
            value: 0.5 * (lo + hi),
            lo,
            hi,
        }),
        holds_with_peak,
        ..Default::default()
    };
    let f = TimeHealing;
    // 0.029 [0.014, 0.044] per decade over three holds with peaks: shown.
    assert!(f.shown(&with(3, 0.014, 0.044)));
    // A rate whose interval reaches zero, or one hold with a peak of its own: not shown.
    assert!(!f.shown(&with(3, -0.002, 0.03)));
    assert!(!f.shown(&with(1, 0.014, 0.044)));
    assert!(!f.shown(&super::super::EventReadings::default()));
    // The readings live on the holds.
    assert_eq!(f.shown_in(), &[Shows::Holds]);
}

#[test]
fn gains_add_up_over_split_steps() {
    let q = p(0.01, 5.0, 0.4, 0.0);
    for (form, shape) in FORMS.iter().enumerate() {
        let whole = TimeHealing.rest_gain(form, &q, 3.0, 100.0);
        let split = TimeHealing.rest_gain(form, &q, 3.0, 40.0)
            + TimeHealing.rest_gain(form, &q, 43.0, 60.0);
        assert!((whole - split).abs() < 1e-14, "{}", shape.key);
        assert!(whole > 0.0);
    }
}

#[test]
fn the_general_law_holds_the_log_law_and_a_linear_one() {
    let (log, general) = (0, 6);
    for (age, dt) in [(0.0, 1.0), (3.0, 10.0), (100.0, 500.0)] {
        let l = TimeHealing.rest_gain(log, &p(0.01, 5.0, 0.5, 0.0), age, dt);
        let g = TimeHealing.rest_gain(general, &p(0.01, 5.0, 0.0, 0.0), age, dt);
        assert!((l - g).abs() < 1e-15, "{l} vs {g}");
        let near_zero = TimeHealing.rest_gain(general, &p(0.01, 5.0, 1e-9, 0.0), age, dt);
        assert!((near_zero - l).abs() < 1e-9);
        let linear = TimeHealing.rest_gain(general, &p(0.01, 5.0, 1.0, 0.0), age, dt);
        assert!((linear - 0.01 * dt / 5.0).abs() < 1e-15);
    }
    // n = 0 is valid for the general law only.
    assert!(TimeHealing
        .issues(general, &p(0.01, 5.0, 0.0, 0.0))
        .is_empty());
    assert_eq!(TimeHealing.issues(1, &p(0.01, 5.0, 0.0, 0.0)).len(), 1);
}

#[test]
fn the_general_law_below_zero_levels_off_as_saturating_healing_does() {
    let general = 6;
    // n = −1: b θ/(θ + t_c), summed over steps from rest.
    let (b, t_c) = (0.02, 30.0);
    let gain = |theta: f64| {
        let mut total = 0.0;
        let (mut age, dt) = (0.0, theta / 1000.0);
        while age < theta - 1e-9 {
            total += TimeHealing.rest_gain(general, &p(b, t_c, -1.0, 0.0), age, dt);
            age += dt;
        }
        total
    };
    for theta in [10.0, 100.0, 1000.0] {
        let exact = b * theta / (theta + t_c);
        assert!(
            (gain(theta) - exact).abs() < 1e-12,
            "{theta}: {}",
            gain(theta)
        );
    }
    // The last decade gains less than the one before it (a log law gains the same).
    assert!(gain(1000.0) - gain(100.0) < 0.5 * (gain(100.0) - gain(10.0)));
    assert!(TimeHealing
        .issues(general, &p(b, t_c, -1.0, 0.0))
        .is_empty());
    assert_eq!(TimeHealing.issues(general, &p(b, t_c, -1.5, 0.0)).len(), 1);
}

#[test]
fn the_general_forms_are_tried_saturating_as_well() {
    let scales = super::super::DataScales {
        duration_s: 2000.0,
        holds: 3,
        healing_per_decade: Some(0.02),
        ..crate::terms::tests::one_rate_one_stress()
    };
    let fam: &dyn crate::terms::TermFamily = &TimeHealing;
    for (k, &(law, _)) in SHAPES.iter().enumerate().take(TRIED) {
        if law != Law::General {
            continue;
        }
        let g = fam.guess(k, &scales);
        let at = fam.fitted(k).iter().position(|&i| i == N).unwrap();
        // The exponent may go below zero, down to a gain that levels off at b.
        assert!(g
            .bounds
            .iter()
            .any(|&(i, lo, hi)| i == at && lo == -1.0 && hi == 1.0));
        // And one start is saturating, valid for the law.
        let saturating = g
            .starts
            .iter()
            .find(|v| v[at] < 0.0)
            .expect("a start below zero");
        let mut q = [0.0; MAX_TERM_PARAMS];
        for (&i, &v) in fam.fitted(k).iter().zip(saturating) {
            q[i] = v;
        }
        assert!(
            TimeHealing.issues(k, &q).is_empty(),
            "{:?}",
            TimeHealing.issues(k, &q)
        );
    }
}

#[test]
fn each_role_acts_on_the_recovery_and_on_slip_as_its_form_says() {
    let q = p(0.01, 5.0, 0.5, 0.05);
    for (form, &(law, role)) in SHAPES.iter().enumerate() {
        assert_eq!(TimeHealing.replaces_recovery(form), role == Role::Replaces);
        assert_eq!(
            TimeHealing.erased_over(form, &q),
            (role == Role::Erased).then_some(0.05)
        );
        // Each law once in each role.
        assert_eq!(
            SHAPES.iter().filter(|s| **s == (law, role)).count(),
            1,
            "{}",
            FORMS[form].key
        );
    }
    // An erased gain needs its slip, the others do not use it.
    assert_eq!(TimeHealing.issues(4, &p(0.01, 5.0, 0.5, 0.0)).len(), 1);
    assert!(TimeHealing.issues(2, &p(0.01, 5.0, 0.5, 0.0)).is_empty());
    assert_eq!(TimeHealing.issues(0, &p(-0.01, 5.0, 0.5, 0.0)).len(), 1);
}

#[test]
fn older_files_read_as_the_form_they_describe() {
    let obj = |s: &str| serde_json::from_str::<Map<String, Value>>(s).unwrap();
    let read = |s: &str| TimeHealing.read_form(&obj(s)).map(|k| FORMS[k].key);
    assert_eq!(read("{}"), Ok("log"));
    assert_eq!(
        read(r#"{"form":"power","recovery":false,"d_h":0}"#),
        Ok("power")
    );
    assert_eq!(read(r#"{"form":"log","recovery":true}"#), Ok("log-added"));
    // A gain of its own keeps the recovery whatever `recovery` says.
    assert_eq!(
        read(r#"{"form":"general","recovery":false,"d_h":0.02}"#),
        Ok("general-erased")
    );
    assert!(read(r#"{"form":"cubic"}"#)
        .unwrap_err()
        .contains("log, power"));
    assert!(read(r#"{"recovery":"yes"}"#)
        .unwrap_err()
        .contains("true or false"));
    // Every form reads back from the fields it is written with (and its d_h).
    for (form, &(_, role)) in SHAPES.iter().enumerate() {
        let mut o = Map::new();
        for (field, value) in TimeHealing.form_fields(form) {
            o.insert(field.into(), value);
        }
        if role == Role::Erased {
            o.insert("d_h".into(), 0.05.into());
        }
        assert_eq!(TimeHealing.read_form(&o), Ok(form));
    }
}

#[test]
fn only_friction_read_to_fall_with_hold_time_speaks_against_healing() {
    let read = |lo: f64, hi: f64| EventReadings {
        healing_per_decade: Some(crate::terms::Reading {
            value: 0.5 * (lo + hi),
            lo,
            hi,
        }),
        ..EventReadings::default()
    };
    assert!(!TimeHealing.contradicted(&EventReadings::default()));
    // Uncertain, or healing: not contradicted (an interval about zero only fails to
    // corroborate when its value is not positive).
    assert!(!TimeHealing.contradicted(&read(-0.01, 0.002)));
    assert!(!TimeHealing.corroborated(&read(-0.01, 0.002)));
    assert!(!TimeHealing.contradicted(&read(0.001, 0.01)));
    // Friction falls with the hold time, the whole interval below zero.
    assert!(TimeHealing.contradicted(&read(-0.01, -0.002)));
}

#[test]
fn the_holds_single_out_the_erased_forms_unless_the_steps_agree_on_rate_and_state() {
    let mut events = EventReadings {
        holds_with_peak: 2,
        ..EventReadings::default()
    };
    let erased = TimeHealing.singled_out(&events);
    assert_eq!(
        erased.iter().map(|&k| FORMS[k].key).collect::<Vec<_>>(),
        ["log-erased", "general-erased"]
    );
    events.steps_agree_on_rate_and_state = Some(true);
    assert!(TimeHealing.singled_out(&events).is_empty());
    events.steps_agree_on_rate_and_state = Some(false);
    assert_eq!(TimeHealing.singled_out(&events).len(), 2);
    events.holds_with_peak = 1;
    assert!(TimeHealing.singled_out(&events).is_empty());
}
