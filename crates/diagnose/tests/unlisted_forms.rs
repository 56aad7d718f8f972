//! Effects in forms the candidate library does not list: the generator's forms map onto the
//! library by name (so `selfcheck --unlisted` really removes the form that made the data), and a
//! diagnosis without that form still names the family through another of its forms.

use subfric_diagnose::features::data_features;
use subfric_diagnose::selfcheck::{all_classes, selfcheck, SelfcheckOptions};
use subfric_diagnose::synth::{
    form_names, generate_set, library_name, random_truth, rng, Built, SynthOptions,
};
use subfric_diagnose::{library, prepare_for_diagnosis, Effect};

#[test]
fn every_generated_form_is_named_in_the_library_of_a_set_that_shows_all_families() {
    let truth = random_truth(&[], &mut rng(3));
    let set = generate_set(
        "all-families",
        &truth,
        &SynthOptions::default(),
        &mut rng(4),
    );
    let lib = library(&data_features(&prepare_for_diagnosis(&set)));
    let names: Vec<&str> = lib.iter().map(|f| f.name).collect();
    let families = [
        Effect::Rate,
        Effect::Pressure,
        Effect::SlipHardening,
        Effect::LogHealing,
        Effect::Direction,
    ];
    let mut checked = 0;
    for effect in families {
        for form in 0..form_names(effect).len() {
            let b = Built { effect, form };
            let name = library_name(b).unwrap_or_else(|| panic!("{b:?} has no library name"));
            let entry = lib.iter().find(|f| f.name == name);
            assert!(
                entry.is_some_and(|f| f.effect == effect),
                "{b:?}: {name:?} is not a {effect} form of the library {names:?}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 20);
    assert_eq!(lib.len(), 29, "the library's forms: {names:?}");
    assert_eq!(
        library_name(Built {
            effect: Effect::Rate,
            form: 5
        }),
        None
    );
}

#[test]
fn a_family_is_named_through_another_form_when_its_own_is_not_a_candidate() {
    // A pressure power law on μ_s only and log-time healing, each diagnosed without its own
    // form: the families' general forms (two exponents; ((1 + t/t_c)^n - 1)/n) hold them.
    let all = all_classes();
    let pick = |effect: Effect, form: usize| {
        all.iter()
            .find(|c| c.len() == 1 && c[0].effect == effect && c[0].form == form)
            .expect("the class is generated")
            .clone()
    };
    let opts = SelfcheckOptions {
        classes: vec![pick(Effect::Pressure, 3), pick(Effect::LogHealing, 0)],
        per_class: 1,
        seed: 2026,
        synth: SynthOptions {
            slip_per_row: 0.01,
            ..SynthOptions::default()
        },
        unlisted: true,
        ..SelfcheckOptions::default()
    };
    let (cases, _) = selfcheck(&opts, &|c| eprintln!("{c:?}"), &|_, _| {});
    assert_eq!(cases.len(), 2);
    for c in &cases {
        assert!(
            c.right(),
            "{} ({}): named {:?}",
            c.name,
            c.truth_label,
            c.verdict
        );
    }
}
