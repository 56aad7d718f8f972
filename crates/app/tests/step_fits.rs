//! The per-event reading of velocity steps (`subfric_reading::events`, at
//! `subfric_diagnose::events`: a spring-slider fitted to each step on its own, as friction labs
//! do with xlook or RSFit3000) on steps made by the independent generator of `subfric-harness`
//! (its own forward model of the subloading model with a rate-and-state effect; no code shared
//! with the slider). Every step of a velocity-step ladder must give back a, b and D_c within
//! 10 %, and the sign of a − b that the record's steady-state change shows.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use subfric_data::{ExperimentMeta, ExperimentSet, Interface};
use subfric_diagnose::events::analyse;
use subfric_diagnose::prepare_for_diagnosis;
use subfric_harness::generator::effects::{Effects, Rate, RateForm, Reading, StateLaw};
use subfric_harness::generator::forward::{Base, Contact, Rig};
use subfric_harness::generator::path::{run, Sampling, Segment};
use subfric_harness::generator::record::{record, test_data, Noise, Resolution};

const UM: f64 = 1e-3;

/// A velocity-step ladder (×10 and ×3 up and down around 10 µm/s) at 100 kPa with the given
/// rate-and-state effect, on a base at its residual (the rate effect alone changes friction
/// after the first millimetres), recorded with white noise of `noise_kpa` and a 0.1 µm encoder.
fn ladder(law: StateLaw, a: f64, b: f64, dc: f64, noise_kpa: f64, seed: u64) -> ExperimentSet {
    let p = 100.0;
    let base = Base {
        mu_s: 0.6,
        mu_k: 0.45,
        kappa: 5.0,
        xi: 1e-12,
        u_tilde: 3000.0,
        alpha_t: 1000.0,
    };
    let fx = Effects {
        rate: Some(Rate {
            form: RateForm::State { law, a, b, dc },
            v_star: 10.0 * UM,
            v_min: 1e-9,
            reading: Reading::Locked,
        }),
        ..Effects::default()
    };
    let mut segs = vec![Segment::Slide {
        rate: 10.0 * UM,
        distance: 3.0,
    }];
    // Each level slides 25 D_c or more: the state reaches its new steady state.
    let distance = (25.0 * dc).max(0.3);
    for v in [100.0, 10.0, 1.0, 3.0, 10.0] {
        segs.push(Segment::Slide {
            rate: v * UM,
            distance,
        });
    }
    let sampling = Sampling::RateAdaptive {
        slip_per_row: dc / 40.0,
        min_dt: 1e-3,
        max_dt: 10.0,
        min_hold_dt: 1.0,
        hold_growth: 1.5,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut contact = Contact::new(base, fx, Rig::default(), p, 1.0);
    let r = run(&mut contact, &segs, p, &sampling, 0.0, &mut rng).expect("the run resolves");
    let noise = Noise {
        white_kpa: noise_kpa,
        ar1_kpa: 0.0,
        ar1_tau_s: 1.0,
        slip_mm: 0.0,
    };
    let res = Resolution {
        slip_mm: 1e-4,
        shear_kpa: 1e-4,
        time_s: 1e-4,
    };
    let rec = record(&r, None, &noise, &res, None, &mut rng);
    let test = test_data("velocity-steps", p, rec, Vec::new());
    ExperimentSet {
        dir: "ladder".into(),
        meta: ExperimentMeta {
            name: "ladder".into(),
            title: "generated velocity-step ladder".into(),
            source: "subfric-harness generator".into(),
            provenance: Some("synthetic".into()),
            interface: Interface::default(),
            tests: vec![test.spec.clone()],
            reference_parameters: None,
            units: None,
            extra: Default::default(),
        },
        tests: vec![test],
    }
}

fn within(got: f64, want: f64, share: f64) -> bool {
    (got - want).abs() <= share * want.abs()
}

#[test]
fn every_step_of_a_ladder_gives_back_a_b_and_dc_within_ten_percent() {
    // Velocity weakening and strengthening, both state laws, D_c from 10 to 50 µm: inside the
    // literature's ranges (a 0.002–0.02, b − a within ±0.01, D_c 1 µm–1 mm).
    let cases = [
        (StateLaw::Ageing, 0.008, 0.012, 0.02),
        (StateLaw::Slip, 0.010, 0.006, 0.05),
        (StateLaw::Ageing, 0.005, 0.009, 0.01),
    ];
    let mut a_misses = Vec::new();
    let mut steps = 0;
    for (k, &(law, a, b, dc)) in cases.iter().enumerate() {
        // Noise of 0.03 kPa at 100 kPa: 3e-4 in friction, a tenth of a ln 3 or less.
        let set = ladder(law, a, b, dc, 0.03, 11 + k as u64);
        let prepared = prepare_for_diagnosis(&set);
        let events = analyse(&prepared, None);
        assert_eq!(
            events.steps.len(),
            5,
            "{law:?}: the five steps of the ladder are found ({:?})",
            events
                .steps
                .iter()
                .map(|s| (s.rate_before, s.rate_after))
                .collect::<Vec<_>>()
        );
        steps += events.steps.len();
        for s in &events.steps {
            let what = format!(
                "{law:?} a {a} b {b} D_c {dc}, step {:.0} → {:.0} µm/s: a {:.5} b {:.5} D_c {:.5} mm ({:?}, {})",
                s.rate_before / UM,
                s.rate_after / UM,
                s.a.value,
                s.b.value,
                s.d_c_mm.value,
                s.law,
                s.rms_over_noise
            );
            eprintln!("{what}");
            assert!(within(s.a.value, a, 0.10), "a: {what}");
            assert!(within(s.b.value, b, 0.10), "b: {what}");
            assert!(within(s.d_c_mm.value, dc, 0.10), "D_c: {what}");
            if !(s.a.lo <= a && a <= s.a.hi) {
                a_misses.push(what.clone());
            }
            // a − b has the sign of the truth, and of the steady change the record shows.
            assert_eq!(
                s.a_minus_b.value.signum(),
                (a - b).signum(),
                "a − b: {what}"
            );
            assert_eq!(s.sign_agrees, Some(true), "steady change: {what}");
        }
        let rate = events.rate.expect("a consensus of the steps");
        assert!(rate.consistent, "{rate:?}");
    }
    // The 95 % intervals of a: of 15, three or more missing the truth has a chance of 3.6 %
    // when they are right.
    assert!(
        a_misses.len() <= 2,
        "{} of {steps} intervals of a miss the truth: {a_misses:#?}",
        a_misses.len()
    );
}

#[test]
fn the_steps_of_a_rate_neutral_record_show_no_direct_effect() {
    // The same ladder with a vanishing rate effect: no step may claim one.
    let set = ladder(StateLaw::Ageing, 1e-6, 1e-6, 0.02, 0.05, 5);
    let prepared = prepare_for_diagnosis(&set);
    let events = analyse(&prepared, None);
    assert!(!events.steps.is_empty());
    for s in &events.steps {
        assert!(
            !s.significant(),
            "a step {:.0} → {:.0} µm/s claims a direct effect on a neutral record: a {:?}, evidence {}",
            s.rate_before / UM,
            s.rate_after / UM,
            s.a,
            s.evidence
        );
    }
}
