use super::*;

fn family(name: &str) -> Effect {
    Effect::from_name(name).unwrap()
}

fn option(effects: Vec<Effect>, evidence: f64, chi2: f64, chosen: bool) -> WeighedOption {
    WeighedOption {
        effects,
        evidence,
        chi2,
        chosen,
        probability: 0.0,
    }
}

#[test]
fn decisive_evidence_is_confident_and_close_evidence_is_not() {
    let rate = family("rate");
    let healing = family("log-healing");
    let decisive = weigh(
        vec![vec![
            option(vec![Effect::Unexplained], 0.0, 40.0, false),
            option(vec![rate], 2000.0, 1.1, true),
            option(vec![healing], 300.0, 20.0, false),
        ]],
        1.0,
    );
    let c = path_certainty(decisive, &[rate]);
    assert!(c.confidence > 0.99, "{c:?}");
    // Two explanations with nearly the same evidence: neither is sure.
    let close = weigh(
        vec![vec![
            option(vec![Effect::Unexplained], 0.0, 40.0, false),
            option(vec![rate], 2000.0, 1.1, true),
            option(vec![healing], 1999.0, 1.1, false),
        ]],
        1.0,
    );
    let c = path_certainty(close, &[rate]);
    assert!((0.4..0.7).contains(&c.confidence), "{c:?}");
    assert_eq!(c.alternatives[0].effects, vec![healing]);
    let s = Certainty {
        confidence: 0.45,
        ..c.clone()
    }
    .sentence("rate");
    assert!(
        s.starts_with("uncertain between rate (45 %) and log-healing"),
        "{s}"
    );
    assert!(s.contains("velocity step"), "{s}");
}

#[test]
fn a_verdict_leads_with_the_word_its_confidence_earns() {
    let healing = family("log-healing");
    let alternative = Alternative {
        effects: vec![healing],
        label: "log-healing".into(),
        probability: 0.3,
        tell_apart: "holds of 10, 100 and 1000 s".into(),
    };
    let at = |confidence: f64, alternatives: Vec<Alternative>| {
        Certainty {
            confidence,
            alternatives,
            stages: Vec::new(),
        }
        .sentence("rate")
    };
    let alt = || vec![alternative.clone()];
    assert_eq!(Standing::of(0.95), Standing::Confident);
    assert_eq!(Standing::of(CONFIDENT), Standing::Confident);
    assert_eq!(Standing::of(0.7), Standing::Probable);
    assert_eq!(Standing::of(PROBABLE), Standing::Probable);
    assert_eq!(Standing::of(0.02), Standing::Uncertain);
    assert_eq!(Standing::of(f64::NAN), Standing::Uncertain);
    assert!(at(0.95, alt()).starts_with("confident (95 %"));
    let probable = at(0.7, alt());
    assert!(
        probable.starts_with("probably (70 %")
            && probable.contains("else log-healing (30 %): holds of 10"),
        "{probable}"
    );
    assert!(at(0.02, alt()).starts_with("uncertain between rate (2 %) and log-healing (30 %)"));
    // No alternative weighed does not make a low confidence "confident".
    let alone = at(0.3, Vec::new());
    assert!(alone.starts_with("uncertain (30 %"), "{alone}");
    assert!(at(0.6, Vec::new()).starts_with("probably (60 %"));
}

#[test]
fn evidence_is_tempered_by_the_misfit_that_remains() {
    let rate = family("rate");
    let stage = |chi2: f64| {
        vec![vec![
            option(vec![Effect::Unexplained], 0.0, 50.0, false),
            option(vec![rate], 20.0, chi2, true),
        ]]
    };
    let near_noise = path_certainty(weigh(stage(1.0), 1.0), &[rate]).confidence;
    let far = path_certainty(weigh(stage(10.0), 1.0), &[rate]).confidence;
    assert!(near_noise > 0.99 && far < 0.8, "{near_noise} {far}");
}

#[test]
fn a_further_effect_the_path_took_but_the_verdict_did_not_name_is_an_alternative() {
    // Pressure named; log-healing taken tentatively at the second stage and dropped (too
    // little on its own); the third stage stops there. The path's end, pressure +
    // log-healing, is what the evidence walked to: it must be among the alternatives, with
    // the weight of the path.
    let pressure = family("pressure");
    let healing = family("log-healing");
    let rate = family("rate");
    let stages = weigh(
        vec![
            vec![
                option(vec![Effect::Unexplained], 0.0, 290.0, false),
                option(vec![pressure], 480.0, 5.3, true),
            ],
            vec![
                option(vec![pressure], 0.0, 5.3, false),
                option(vec![pressure, healing], 27.0, 5.1, true),
            ],
            vec![
                option(vec![pressure, healing], 0.0, 5.1, true),
                option(vec![pressure, healing, rate], 9.0, 5.0, false),
            ],
        ],
        1.0,
    );
    let c = path_certainty(stages.clone(), &[pressure]);
    let end = c
        .alternatives
        .iter()
        .find(|a| same(&a.effects, &[pressure, healing]))
        .expect("the path's end is an alternative");
    assert!((end.probability - c.confidence).abs() < 1e-12, "{c:?}");
    let path: f64 = c
        .stages
        .iter()
        .map(|st| st.options.iter().find(|o| o.chosen).unwrap().probability)
        .product();
    assert!(
        (end.probability - path).abs() < 1e-12 && path > 0.2,
        "{c:?}"
    );
    // A verdict that is the path's end adds nothing.
    let c = path_certainty(stages, &[pressure, healing]);
    assert!(c
        .alternatives
        .iter()
        .all(|a| !same(&a.effects, &[pressure, healing])));
}

#[test]
fn confidence_multiplies_over_stages_and_alternatives_carry_the_prefix() {
    let rate = family("rate");
    let slip = family("slip-hardening");
    let stages = weigh(
        vec![
            vec![
                option(vec![Effect::Unexplained], 0.0, 30.0, false),
                option(vec![rate], 500.0, 3.0, true),
            ],
            vec![
                option(vec![rate], 0.0, 3.0, false),
                option(vec![rate, slip], 6.0, 1.0, true),
            ],
        ],
        1.0,
    );
    let c = path_certainty(stages, &[rate, slip]);
    let second = 1.0 / (1.0 + (-3.0_f64).exp());
    assert!((c.confidence - second).abs() < 1e-6, "{c:?}");
    assert_eq!(c.alternatives[0].effects, vec![rate]);
    assert!((c.alternatives[0].probability - (1.0 - second)).abs() < 1e-6);
}

#[test]
fn the_calibrated_confidence_and_its_alternatives_share_one() {
    let rate = family("rate");
    let healing = family("log-healing");
    let stages = || {
        weigh(
            vec![vec![
                option(vec![Effect::Unexplained], 0.0, 40.0, false),
                option(vec![rate], 60.0, 1.5, true),
                option(vec![healing], 55.0, 1.6, false),
            ]],
            TEMPERATURE,
        )
    };
    let c = certainty(stages(), &[rate], Some(&[rate]));
    let f = VerdictFeatures::of(&c.stages, &[rate], Some(&[rate]));
    assert!((c.confidence - calibrated(&f)).abs() < 1e-12);
    assert!(c.confidence > 0.0 && c.confidence < 1.0);
    // Two options not taken, one of them with no weight left: the other takes the rest.
    let total = c.confidence + c.alternatives.iter().map(|a| a.probability).sum::<f64>();
    assert!((total - 1.0).abs() < 1e-6, "{c:?}");
    assert_eq!(c.alternatives[0].effects, vec![healing]);
    // The features read what they say.
    assert!(!f.none && !f.unexplained && !f.several && !f.first_loadings_disagree);
    assert!((f.remaining - 1.5_f64.ln()).abs() < 1e-12);
    let elsewhere = VerdictFeatures::of(&c.stages, &[rate], Some(&[healing]));
    assert!(elsewhere.first_loadings_disagree);
    let none = VerdictFeatures::of(&c.stages, &[], None);
    assert!(none.none && !none.unexplained);
}

#[test]
fn many_alternatives_alike_share_the_rest_without_being_blown_up() {
    // Five options of equal evidence: the four not taken share what the verdict leaves
    // alike, and the three reported keep their share (not the whole rest between them).
    let names = [
        "rate",
        "log-healing",
        "pressure",
        "slip-hardening",
        "direction",
    ];
    let options: Vec<WeighedOption> = names
        .iter()
        .enumerate()
        .map(|(i, n)| option(vec![family(n)], 50.0, 2.0, i == 0))
        .collect();
    let c = certainty(weigh(vec![options], TEMPERATURE), &[family("rate")], None);
    assert_eq!(c.alternatives.len(), MAX_ALTERNATIVES);
    for a in &c.alternatives {
        let share = (1.0 - c.confidence) / 4.0;
        assert!((a.probability - share).abs() < 1e-9, "{a:?} {c:?}");
    }
}

#[test]
fn the_test_that_tells_them_apart_is_one_that_only_one_of_them_shows_in() {
    let rate = family("rate");
    let healing = family("log-healing");
    let pressure = family("pressure");
    assert!(tell_apart(&[rate], &[healing]).contains("velocity step"));
    assert!(tell_apart(&[pressure], &[]).contains("normal stresses"));
    let slip = family("slip-hardening");
    let trend = family("time-trend");
    assert!(tell_apart(&[slip], &[trend]).contains("sliding rate 10× apart"));
    assert!(tell_apart(&[Effect::Unexplained], &[rate]).contains("fresh specimen"));
    // Each test named once, however many of the families differing show in it.
    let both = tell_apart(&[pressure], &[pressure, healing, rate]);
    assert_eq!(
        both.matches("holds of 10, 100 and 1000 s").count(),
        1,
        "{both}"
    );
    assert!(both.contains("velocity step"), "{both}");
}
