//! Generated sets as files: what is written reads back through the data crate as it was made
//! and passes its checks, the truth names what the data hold in the shared dev families'
//! schema, and the logger's artifacts (quantised displacement, millisecond clock, jitter,
//! files cut from a longer run, seating toes) are in the data as the truth says.

use serde_json::Value;
use subfric_data::{load_set, plausibility};
use subfric_harness::generator::campaign::{profile_of, MIN_VISIBILITY};
use subfric_harness::generator::{
    all_classes, campaign_set, classes_of, write_campaign, Form, Generated, Layout, Options,
    Profile,
};
use subfric_reading::summary;

fn set(class_index: usize, k: usize) -> Generated {
    let classes = all_classes();
    campaign_set(
        11,
        class_index,
        k,
        &classes[class_index],
        &Options::default(),
    )
    .expect("the set generates")
}

/// Class index of a single form.
fn single(form: Form) -> usize {
    all_classes()
        .iter()
        .position(|c| c == &vec![form])
        .expect("every form has its class")
}

/// The set of class `ci` recorded with `profile` (the first k that gives it).
fn with_profile(ci: usize, profile: Profile) -> Generated {
    let k = (0..4).find(|k| profile_of(ci, *k) == profile).unwrap();
    set(ci, k)
}

#[test]
fn sets_read_back_as_written_and_pass_the_checks() {
    let dir = tempfile::tempdir().unwrap();
    let none = 0;
    let sets = vec![
        with_profile(none, Profile::Lab),
        with_profile(single(Form::RsfAgeing), Profile::Logger),
        with_profile(single(Form::PressureExp), Profile::Rig),
        with_profile(single(Form::Drift), Profile::Clean),
    ];
    write_campaign(dir.path(), &sets).unwrap();
    let truth: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("truth.json")).unwrap())
            .unwrap();
    for g in &sets {
        let name = &g.set.meta.name;
        let back = load_set(&dir.path().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(back.meta.tests, g.set.meta.tests, "{name}");
        for (a, b) in back.tests.iter().zip(&g.set.tests) {
            assert_eq!(a.time_s, b.time_s, "{name}/{}", a.spec.name);
            assert_eq!(a.slip_mm, b.slip_mm, "{name}/{}", a.spec.name);
            assert_eq!(a.shear_kpa, b.shear_kpa, "{name}/{}", a.spec.name);
        }
        let warnings = plausibility(&back);
        assert!(warnings.is_empty(), "{name}: {warnings:?}");
        let s = summary(&back);
        assert_eq!(s.tests.len(), g.set.tests.len());
        // The truth, in the dev families' schema.
        let entry = &truth[name.as_str()];
        for key in [
            "effect",
            "form",
            "kw",
            "params",
            "effects",
            "midrun",
            "artifacts",
        ] {
            assert!(!entry[key].is_null(), "{name}: no `{key}` in truth.json");
        }
        for key in [
            "mu_s", "mu_k", "kappa", "xi", "u_tilde", "alpha_t", "alpha_n",
        ] {
            assert!(
                entry["params"][key].as_f64().is_some(),
                "{name}: params.{key}"
            );
        }
        for key in ["effect", "form", "effects", "midrun"] {
            assert_eq!(entry[key], g.truth.json[key], "{name}: {key}");
        }
    }
    assert_eq!(truth["gen-01-1"]["effects"], serde_json::json!(["none"]));
    assert_eq!(truth["gen-01-1"]["midrun"], Value::Bool(true));
}

#[test]
fn the_same_seed_makes_the_same_set_and_another_seed_another() {
    let classes = all_classes();
    let a = campaign_set(5, 3, 1, &classes[3], &Options::default()).unwrap();
    let b = campaign_set(5, 3, 1, &classes[3], &Options::default()).unwrap();
    let c = campaign_set(6, 3, 1, &classes[3], &Options::default()).unwrap();
    assert_eq!(a.set, b.set);
    assert_eq!(a.truth, b.truth);
    assert_ne!(a.set.tests[0].shear_kpa, c.set.tests[0].shear_kpa);
}

#[test]
fn a_loggers_displacement_is_quantised_and_its_clock_jitters_at_the_millisecond() {
    let g = with_profile(single(Form::SlipExp), Profile::Logger);
    let jitter = g.truth.json["artifacts"]["jitter"].as_f64().unwrap();
    assert!(jitter > 0.0);
    for t in &g.set.tests {
        for (i, u) in t.slip_mm.iter().enumerate() {
            let steps = u / 1e-4;
            assert!(
                (steps - steps.round()).abs() < 1e-6,
                "{}: row {i}: {u}",
                t.spec.name
            );
            // Written as a decimal of at most four places.
            let text = format!("{u}");
            let places = text.split('.').nth(1).map_or(0, str::len);
            assert!(places <= 4, "{}: row {i}: {text}", t.spec.name);
        }
        let ms: Vec<i64> = t
            .time_s
            .iter()
            .map(|x| (x * 1000.0).round() as i64)
            .collect();
        for (x, m) in t.time_s.iter().zip(&ms) {
            assert!(
                (x * 1000.0 - *m as f64).abs() < 1e-6,
                "{}: {x}",
                t.spec.name
            );
        }
        assert!(
            ms.windows(2).all(|w| w[1] > w[0]),
            "{}: time not increasing",
            t.spec.name
        );
    }
    // While sliding at one rate the intervals of a jittering clock differ; a clean logger's
    // do not (beyond its millisecond).
    let spread = |g: &Generated| {
        let t = &g
            .set
            .tests
            .iter()
            .find(|t| t.spec.name.starts_with("mono"))
            .unwrap()
            .time_s;
        let d: Vec<f64> = t
            .windows(2)
            .skip(200)
            .take(200)
            .map(|w| w[1] - w[0])
            .collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        d.iter().map(|x| (x - mean).abs()).fold(0.0, f64::max) / mean
    };
    assert!(
        spread(&g) > 0.3 * jitter,
        "jitter {jitter}, spread {}",
        spread(&g)
    );
    assert!(
        spread(&g) <= 1.0 + 1e-9,
        "a jittered interval beyond its slot: {}",
        spread(&g)
    );
    let clean = with_profile(single(Form::SlipExp), Profile::Clean);
    assert!(
        spread(&clean) < 0.01,
        "clean clock spread {}",
        spread(&clean)
    );
}

#[test]
fn files_cut_from_a_run_start_sliding_and_seating_toes_start_flat() {
    let g = with_profile(0, Profile::Lab);
    let arts = &g.truth.json["artifacts"];
    let cut: Vec<&str> = arts["midrun"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["test"].as_str().unwrap())
        .collect();
    assert!(!cut.is_empty());
    for t in &g.set.tests {
        let peak = t.shear_kpa.iter().cloned().fold(0.0, f64::max);
        if cut.contains(&t.spec.name.as_str()) {
            assert!(
                t.shear_kpa[0] > 0.6 * peak,
                "{}: a file from mid-run starts at {} kPa (peak {peak})",
                t.spec.name,
                t.shear_kpa[0]
            );
        }
    }
    let toes = arts["seating_toes"].as_array().unwrap();
    assert!(!toes.is_empty());
    for toe in toes {
        let name = toe["test"].as_str().unwrap();
        let gap = toe["gap_mm"].as_f64().unwrap();
        let t = g.set.tests.iter().find(|t| t.spec.name == name).unwrap();
        assert_eq!(t.shear_kpa.len(), t.slip_mm.len());
        let peak = t.shear_kpa.iter().cloned().fold(0.0, f64::max);
        let noise = 5.0
            * g.truth.json["artifacts"]["noise"]["white_kpa"]
                .as_f64()
                .unwrap()
            + 5.0
                * g.truth.json["artifacts"]["noise"]["ar1_kpa"]
                    .as_f64()
                    .unwrap();
        let in_toe = t
            .slip_mm
            .iter()
            .zip(&t.shear_kpa)
            .take_while(|(u, _)| **u <= 0.9 * gap)
            .map(|(_, f)| *f)
            .fold(f64::MIN, f64::max);
        assert!(
            in_toe < 0.03 * peak + noise,
            "{name}: {in_toe} kPa within the toe of {gap} mm (peak {peak})"
        );
        if name.starts_with("mono") {
            let reach = t.slip_mm[t.shear_kpa.iter().position(|f| *f > 0.5 * peak).unwrap()];
            assert!(
                reach > gap,
                "{name}: half the peak at {reach} mm, inside the {gap} mm toe"
            );
        }
    }
}

#[test]
fn every_class_shows_its_effects_in_the_data() {
    // Each effect moves rows of some test by MIN_VISIBILITY noise SDs at least; none: nothing.
    for (ci, class) in all_classes().iter().enumerate() {
        let g = campaign_set(2, ci, 0, class, &Options::default()).unwrap();
        let seen: Vec<f64> = g.truth.json["visibility"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(seen.len(), class.len(), "class {}", ci + 1);
        assert_eq!(g.truth.families.len(), class.len(), "class {}", ci + 1);
        for (form, v) in class.iter().zip(&seen) {
            assert!(
                *v >= MIN_VISIBILITY,
                "class {} ({form:?}): visibility {v}",
                ci + 1
            );
        }
        for (form, family) in class.iter().zip(&g.truth.families) {
            assert_eq!(form.family(), *family);
        }
    }
}

#[test]
fn a_direct_shear_programme_slides_one_way_through_a_soft_rig() {
    // Every class the layout keeps, every profile: three or four tests at distinct normal
    // stresses, each sliding forward (an unload and hold at most),
    // the series stiffness 100–1000 kPa/mm, no file cut from a run; and only effects such tests
    // can show (none of rate, healing or direction).
    let opts = Options {
        layout: Layout::DirectShear,
        ..Options::default()
    };
    let kept = classes_of(Layout::DirectShear);
    assert_eq!(kept.len(), 10, "{kept:?}");
    for (ci, class) in &kept {
        assert!(class
            .iter()
            .all(|f| matches!(f.family(), "pressure" | "slip-hardening" | "unexplained")));
        for k in 0..4 {
            let g = campaign_set(3, *ci, k, class, &opts).expect("the set generates");
            let tests = &g.set.tests;
            assert!((3..=4).contains(&tests.len()), "{}", tests.len());
            let mut stresses: Vec<f64> = tests.iter().map(|t| t.spec.normal_stress_kpa).collect();
            stresses.dedup();
            assert_eq!(stresses.len(), tests.len(), "{stresses:?}");
            let arts = &g.truth.json["artifacts"];
            let series = arts["series_kpa_per_mm"].as_f64().unwrap();
            assert!((99.0..=1001.0).contains(&series), "{series}");
            assert!(arts["midrun"].as_array().unwrap().is_empty());
            for t in tests {
                // Forward overall, and back (by more than the displacement noise) in one
                // stretch at most: the unload.
                let (first, last) = (t.slip_mm[0], *t.slip_mm.last().unwrap());
                assert!(last - first > 4.0, "{}: {first} → {last}", t.spec.name);
                let (mut top, mut backward, mut stretches) = (f64::MIN, false, 0);
                for &u in &t.slip_mm {
                    if u >= top {
                        top = u;
                        backward = false;
                    } else if top - u > 0.01 && !backward {
                        backward = true;
                        stretches += 1;
                    }
                }
                assert!(
                    stretches <= 1,
                    "{}: {stretches} stretches back",
                    t.spec.name
                );
            }
        }
    }
}
