//! The standards every named effect meets, on sets made by the independent generator of
//! `subfric-harness` (issue 38): the variable an effect acts through must vary in the data,
//! and an effect of the normal stress is judged on the tests away from where most were run.

use subfric_app::selfcheck::diagnose_generated;
use subfric_diagnose::{diagnose, prepare_for_diagnosis, DiagnoseOptions, Effect};
use subfric_harness::generator::{generate_seeded, Form, Generated, Options, Profile};

fn set(name: &str, class: &[Form], seed: u64) -> Generated {
    generate_seeded(name, class, Profile::Clean, &Options::rows(0.6), seed).expect("generates")
}

/// `g` without its velocity-step test: every test left slides at the campaign's one rate.
fn without_velocity_steps(g: &mut Generated) {
    g.set
        .tests
        .retain(|t| !t.spec.name.starts_with("vel-steps"));
    g.set
        .meta
        .tests
        .retain(|t| !t.name.starts_with("vel-steps"));
}

#[test]
fn rate_and_state_slid_at_one_rate_is_never_named_rate_and_rate_stays_an_alternative() {
    // A rate-and-state interface (ageing law) recorded without its velocity steps: every test
    // slides at one rate; the state heals in the holds, which a healing law describes as well.
    // Nothing in the record tells rate from healing, so rate is not named; it stays among the
    // alternatives with the test that would tell them apart.
    let rate = Effect::from_name("rate").unwrap();
    // Seed 2: before the standard, rate was named here at confidence 0.94.
    let mut g = set("rsf-one-rate", &[Form::RsfAgeing], 2);
    let with_steps = g.set.tests.len();
    without_velocity_steps(&mut g);
    assert_eq!(
        g.set.tests.len(),
        with_steps - 1,
        "the set had one velocity-step test"
    );
    let prepared = prepare_for_diagnosis(&g.set);
    let d = diagnose(&prepared, &DiagnoseOptions::default()).expect("diagnoses");
    assert_eq!(
        d.data.sliding_rates, 1,
        "every test left slides at one rate"
    );
    assert!(d.data.holds > 0, "the slide-hold-slide test is left");
    let named = d.verdict.named();
    assert!(
        !named.contains(&rate),
        "rate named at one sliding rate: {named:?}"
    );
    // Rate was fitted and weighed: it is an alternative, and the verdict is not confident.
    let alternatives = &d.verdict.alternatives;
    assert!(
        alternatives.iter().any(|a| a.effects.contains(&rate)),
        "rate is not among the alternatives: {alternatives:?}"
    );
    assert!(
        d.verdict.confidence.is_some_and(|c| c < 0.9),
        "{:?}",
        d.verdict.confidence
    );

    // The same interface with its velocity steps: rate is named.
    let c = diagnose_generated(
        &set("rsf-steps", &[Form::RsfAgeing], 2),
        &Default::default(),
    )
    .expect("diagnoses");
    assert!(c.verdict.contains(&rate), "{:?}", c.verdict);
}

#[test]
fn log_healing_slid_at_one_rate_is_not_taken_for_a_rate_and_state_law() {
    // Log healing recorded without the velocity steps: a rate-and-state law fits its holds as
    // well, and before the standard it was named `rate` at confidence 0.94 (seed 3). Rate is
    // not named; it stays an alternative, with the test that would tell it apart.
    let rate = Effect::from_name("rate").unwrap();
    let mut g = set("healing-one-rate", &[Form::HealLog], 3);
    without_velocity_steps(&mut g);
    let d =
        diagnose(&prepare_for_diagnosis(&g.set), &DiagnoseOptions::default()).expect("diagnoses");
    assert_eq!(d.data.sliding_rates, 1);
    assert!(
        !d.verdict.named().contains(&rate),
        "{:?}",
        d.verdict.named()
    );
    let alternative = d
        .verdict
        .alternatives
        .iter()
        .find(|a| a.effects.contains(&rate))
        .expect("rate is an alternative");
    assert!(
        alternative.tell_apart.contains("velocity step"),
        "{alternative:?}"
    );
}
