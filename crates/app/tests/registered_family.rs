//! A registered effect family (`subfric_model::terms`) goes through the whole chain without any
//! other crate naming it: a parameter file switches it on, the model integrates its term, the
//! calibration frees its parameters, and `diagnose --with-family` fits its forms through the
//! engine of the base model and names it.
//!
//! The sets are those of the independent generator with no effect (its own forward model,
//! noise and sampling); the time trend is added to each test as the difference our model makes
//! with and without it. The term itself is checked against a closed form in
//! `subfric-model`'s tests (steady sliding: the shear rises by p c t).

use subfric_diagnose::{prepare_for_diagnosis, DiagnoseOptions, Effect};
use subfric_harness::generator::{generate_seeded, Options, Profile};
use subfric_model::terms::{family_named, TermEffect};
use subfric_model::{model_from_json, Control, Model};

/// The generator's no-effect set with a friction trend of `rise` over its longest test added
/// by our model; returns the set and the trend's rate c [1/s].
fn set_with_a_time_trend(rise: f64) -> (subfric_data::ExperimentSet, f64) {
    let g = generate_seeded("time-trend", &[], Profile::Clean, &Options::rows(0.6), 2026)
        .expect("the set generates");
    let params = serde_json::json!({ "params": g.truth.json["params"] }).to_string();
    let base = model_from_json(&params).expect("the generator's parameters are a model");
    let longest = g
        .set
        .tests
        .iter()
        .map(|t| t.time_s.last().unwrap() - t.time_s[0])
        .fold(0.0, f64::max);
    let c = rise / longest;
    let (index, _) = family_named("time-trend").expect("registered");
    let mut trend = TermEffect::new(index, 0);
    trend.p[0] = c;
    let with = Model {
        ext: subfric_model::Extensions {
            terms: base.ext.terms.with(trend),
        },
        ..base
    };
    let mut set = g.set.clone();
    let prepared = subfric_reading::prepare_set(&set, false);
    for (t, p) in set.tests.iter_mut().zip(&prepared) {
        assert!(p.toe.is_none(), "the clean profile has no seating toe");
        let (a, b) = (
            p.full.predict(&base).unwrap(),
            p.full.predict(&with).unwrap(),
        );
        let column = match p.full.control {
            Control::Slip => &mut t.shear_kpa,
            Control::Shear => &mut t.slip_mm,
        };
        for (x, (a, b)) in column.iter_mut().zip(a.iter().zip(&b)) {
            *x += b - a;
        }
    }
    (set, c)
}

#[test]
fn a_parameter_file_switches_a_registered_family_on_and_reads_back() {
    let text = r#"{"params": {"mu_s": 0.45, "mu_k": 0.3, "kappa": 1.2, "xi": 0.003,
        "u_tilde": 15, "alpha_t": 1000},
        "ext": {"time_trend": {"form": "saturating", "delta": 0.04, "t_s": 300}}}"#;
    let m = model_from_json(text).expect("a registered family is a valid extension");
    let (index, _) = family_named("time-trend").unwrap();
    let t = m.ext.terms.of(index).expect("switched on");
    // The `term` object of older files reads as the same model.
    let old = text.replace(r#""time_trend": {"#, r#""term": {"family": "time-trend", "#);
    assert_eq!(model_from_json(&old).expect("the older shape reads"), m);
    assert_eq!(t.form().key, "saturating");
    let back = serde_json::json!({ "params": m.params, "ext": m.ext }).to_string();
    assert_eq!(model_from_json(&back).unwrap(), m);
    // Its parameters are the calibration's, by key.
    let q = subfric_fit::Param::from_key("time_trend.delta").expect("a parameter key");
    assert_eq!(q.get(&m), Some(0.04));
    // A parameter of the other form is refused as unknown, not silently dropped.
    let err = model_from_json(&text.replace("\"t_s\"", "\"c\"")).unwrap_err();
    assert!(err.to_string().contains("c"), "{err}");
}

#[test]
fn a_time_trend_is_named_when_asked_for_and_not_tried_otherwise() {
    let (set, c) = set_with_a_time_trend(0.04);
    let prepared = prepare_for_diagnosis(&set);
    let trend = Effect::from_name("time-trend").expect("a registered family is an effect");

    let named = |d: &subfric_diagnose::Diagnosis| -> Vec<Effect> {
        d.verdict.effects.iter().map(|e| e.effect).collect()
    };
    let plain = subfric_diagnose::diagnose(&prepared, &DiagnoseOptions::default()).unwrap();
    assert!(
        !named(&plain).contains(&trend),
        "tried without being asked: {:?}",
        named(&plain)
    );
    assert!(
        plain.forms.iter().all(|f| f.effect != trend),
        "a form of the family was fitted without being asked"
    );

    let asked = DiagnoseOptions {
        with_families: vec!["time-trend".into()],
        ..DiagnoseOptions::default()
    };
    let d = subfric_diagnose::diagnose(&prepared, &asked).unwrap();
    assert_eq!(named(&d), vec![trend], "{:#?}", d.verdict);
    let json = serde_json::to_value(&d).unwrap();
    assert_eq!(json["verdict"]["effect"], "time-trend");
    // diagnosis.json's top-level verdict lists every effect named.
    let file = subfric_app::diagnose::diagnosis_json("trend", &d);
    assert_eq!(
        file["verdict"]["effects"],
        serde_json::json!(["time-trend"])
    );
    assert_eq!(file["verdict"]["effect"], "time-trend");
    // The fitted rate is the one added, within a fifth.
    let fitted = subfric_fit::Param::from_key("time_trend.c")
        .and_then(|q| q.get(&d.final_model))
        .expect("the final model holds the trend");
    eprintln!(
        "plain {:?}, asked {:?}, c {fitted} for {c}",
        named(&plain),
        named(&d)
    );
    assert!((fitted / c - 1.0).abs() < 0.2, "c {fitted} for {c}");
}
