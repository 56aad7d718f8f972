use super::*;

fn law(form: RateForm, at_rest: AtRest) -> RateEffect {
    RateEffect {
        form,
        a: 0.011,
        v_c: 2e-6,
        b: 0.013,
        d_c: 0.04,
        n: 0.05,
        v_ref: 0.01,
        at_rest,
    }
}

#[test]
fn every_law_goes_to_its_form_and_back() {
    for form in [
        RateForm::LogDirect,
        RateForm::StateAgeing,
        RateForm::StateSlip,
        RateForm::Power,
    ] {
        for at_rest in [AtRest::Creep, AtRest::Locked] {
            let r = law(form, at_rest);
            let e = r.effect();
            assert_eq!(
                Rate.slip_rate_law(e.form as usize, &e.p),
                Some(r),
                "{form:?} {at_rest:?}"
            );
            assert_eq!(r.locked(), at_rest == AtRest::Locked);
        }
    }
    // The steady-state form has nothing to lock: it reads as itself, creeping.
    let e = law(RateForm::SteadyState, AtRest::Locked).effect();
    let back = Rate.slip_rate_law(e.form as usize, &e.p).unwrap();
    assert_eq!(back.form, RateForm::SteadyState);
    assert!(!back.locked());
}

#[test]
fn files_name_the_form_and_the_reading_at_rest() {
    let obj = |s: &str| serde_json::from_str::<Map<String, Value>>(s).unwrap();
    let read = |s: &str| Rate.read_form(&obj(s)).map(|k| FORMS[k].key);
    assert_eq!(read("{}"), Ok("log-direct"));
    assert_eq!(
        read(r#"{"form":"state-slip","at_rest":"locked"}"#),
        Ok("state-slip-locked")
    );
    assert_eq!(
        read(r#"{"form":"steady-state","at_rest":"locked"}"#),
        Ok("steady-state")
    );
    assert!(read(r#"{"form":"cubic"}"#)
        .unwrap_err()
        .contains("state-ageing"));
    assert!(read(r#"{"at_rest":"asleep"}"#)
        .unwrap_err()
        .contains("locked"));
    for form in 0..FORMS.len() {
        let mut o = Map::new();
        for (field, value) in Rate.form_fields(form) {
            o.insert(field.into(), value);
        }
        assert_eq!(Rate.read_form(&o), Ok(form));
    }
}

#[test]
fn the_terms_vanish_at_the_reference_rate_and_follow_the_rate() {
    // Over one step at v = v_ref from the steady state at v_ref, every term is zero.
    let dt = 1.0;
    for form in [
        RateForm::LogDirect,
        RateForm::StateAgeing,
        RateForm::StateSlip,
    ] {
        let r = law(form, AtRest::Creep);
        let t = r.plastic_terms(r.steady_theta(r.v_ref), dt, r.v_ref * dt);
        // ln(1 + v/v_c) − ln(1 + v_ref/v_c) = 0; θ stays steady.
        assert!(t.add.abs() < 1e-12, "{form:?}: {}", t.add);
        assert!((t.theta / r.steady_theta(r.v_ref) - 1.0).abs() < 1e-9);
        // Faster: the direct effect a ln(10) at once (θ barely moved over a short step).
        let fast = r.plastic_terms(r.steady_theta(r.v_ref), 1e-3, 10.0 * r.v_ref * 1e-3);
        assert!(
            (fast.add - 0.011 * 10f64.ln()).abs() < 2e-3,
            "{form:?}: {}",
            fast.add
        );
    }
    let power = law(RateForm::Power, AtRest::Creep).plastic_terms(1.0, dt, 0.01);
    assert!((power.factor - 1.0).abs() < 1e-12);
    let steady = law(RateForm::SteadyState, AtRest::Creep).plastic_terms(1.0, dt, 0.1);
    let want = 0.011 * ((0.1f64 + 2e-6) / (0.01 + 2e-6)).ln();
    assert!((steady.mu_k_shift - want).abs() < 1e-15);
    // The derivatives are those of the terms (central differences).
    let r = law(RateForm::StateAgeing, AtRest::Creep);
    let (lam, h) = (0.02, 1e-7);
    let (lo, hi, mid) = (
        r.plastic_terms(5.0, dt, lam - h),
        r.plastic_terms(5.0, dt, lam + h),
        r.plastic_terms(5.0, dt, lam),
    );
    assert!(((hi.add - lo.add) / (2.0 * h) - mid.dadd).abs() < 1e-5 * mid.dadd.abs());
}

#[test]
fn steps_that_mostly_show_a_direct_effect_show_the_family_outright() {
    let mut events = EventReadings::default();
    assert!(!Rate.shown(&events), "no step read, nothing shown");
    (events.steps_read, events.steps_with_direct_effect) = (5, 5);
    events.steps_agree_on_rate_and_state = Some(true);
    assert!(Rate.shown(&events));
    assert_eq!(Rate.shown_in(), &[Shows::VelocitySteps]);
    // The steps disagree (too few of those resolved show one): not shown, whatever the count.
    events.steps_agree_on_rate_and_state = Some(false);
    assert!(!Rate.shown(&events));
    // One step alone is one reading.
    events.steps_agree_on_rate_and_state = Some(true);
    (events.steps_read, events.steps_with_direct_effect) = (1, 1);
    assert!(!Rate.shown(&events));
}

#[test]
fn the_steps_single_out_the_state_forms_and_must_show_a_direct_effect() {
    let mut events = EventReadings::default();
    assert!(Rate.corroborated(&events));
    assert!(Rate.singled_out(&events).is_empty());
    events.steps_agree_on_rate_and_state = Some(false);
    assert!(!Rate.corroborated(&events));
    // Not corroborated is not contradicted: one step in four shows a direct effect.
    (events.steps_read, events.steps_with_direct_effect) = (4, 1);
    assert!(!Rate.contradicted(&events));
    // Contradicted: steps read, and none shows one.
    events.steps_with_direct_effect = 0;
    assert!(Rate.contradicted(&events));
    events.steps_read = 1;
    assert!(
        !Rate.contradicted(&events),
        "one step alone does not speak against it"
    );
    events.steps_agree_on_rate_and_state = Some(true);
    assert!(Rate.corroborated(&events));
    let keys: Vec<_> = Rate
        .singled_out(&events)
        .into_iter()
        .map(|k| FORMS[k].key)
        .collect();
    assert_eq!(
        keys,
        [
            "state-ageing",
            "state-slip",
            "state-ageing-locked",
            "state-slip-locked"
        ]
    );
}

#[test]
fn the_largest_change_between_two_rates_is_what_the_law_does_there() {
    let (lo, hi) = (0.01, 0.1);
    // Steady sliding at each rate through the law's own terms (θ at its steady state).
    let steady_add = |r: &RateEffect, v: f64| {
        let dt = 1.0;
        r.plastic_terms(r.steady_theta(v), dt, v * dt).add
    };
    let direct = law(RateForm::LogDirect, AtRest::Creep);
    let want = steady_add(&direct, hi) - steady_add(&direct, lo);
    assert!((direct.largest_change_between(lo, hi, 0.4) - want.abs()).abs() < 1e-12);
    // Rate and state: the direct jump a ln 10 exceeds the steady change (a − b) ln 10
    // and the evolution b ln 10 is larger still.
    let state = law(RateForm::StateAgeing, AtRest::Creep);
    let steady = steady_add(&state, hi) - steady_add(&state, lo);
    assert!(
        (steady - (0.011 - 0.013) * 10f64.ln()).abs() < 1e-5,
        "{steady}"
    );
    let largest = state.largest_change_between(lo, hi, 0.4);
    assert!((largest - 0.013 * 10f64.ln()).abs() < 1e-9, "{largest}");
    // The order of the rates does not matter.
    assert_eq!(largest, state.largest_change_between(hi, lo, 0.4));
    // Steady state only: the shift of μ_k between the rates.
    let ss = law(RateForm::SteadyState, AtRest::Creep);
    let shift = |v: f64| ss.plastic_terms(1.0, 1.0, v).mu_k_shift;
    let got = ss.largest_change_between(lo, hi, 0.4);
    assert!((got - (shift(hi) - shift(lo)).abs()).abs() < 1e-15);
    // The power law scales μ: μ_k times the change of its factor.
    let power = law(RateForm::Power, AtRest::Creep);
    let factor = |v: f64| power.plastic_terms(1.0, 1.0, v).factor;
    let got = power.largest_change_between(lo, hi, 0.4);
    assert!((got - 0.4 * (factor(hi) - factor(lo))).abs() < 1e-12);
    // A law whose term lives below the rates slid at: a tiny slope with a cut-off far below
    // them moves μ_k by a fraction of a thousandth between 0.01 and 0.02 mm/s, though at a
    // near stop (1e-8 mm/s) it is ten times larger and more.
    let stop_only = RateEffect {
        a: -3e-4,
        v_c: 2e-9,
        v_ref: 0.01,
        ..ss
    };
    let within = stop_only.largest_change_between(0.01, 0.02, 0.4);
    assert!(within < 3e-4, "{within}");
    assert!(stop_only.largest_change_between(1e-8, 0.01, 0.4) > 10.0 * within);
}
