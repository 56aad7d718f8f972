//! Issue 25, items 6 and 7: a start or a state the model cannot have is refused with the field
//! named and what is allowed, instead of being computed into a wrong answer (NaN slips from a
//! NaN `initial_slip`, a contact "at rest" under 1000 kPa with a capacity of 45 kPa, 4137 kPa
//! of traction from a state with μ = 100).

use subfric_model::{
    check_start, simulate, Contact3, Control, Extensions, Initial, Model, Params, Protocol,
    SimError, State3, StateSlots, TermEffect, Terms,
};

/// μ_s = 0.45 at 100 kPa: a capacity of 45 kPa.
fn sample() -> Model {
    Model::base(Params::sample()).unwrap()
}

const T: [f64; 4] = [0.0, 1.0, 2.0, 3.0];
const N: [f64; 4] = [100.0; 4];

fn proto<'a>(control: Control, x: &'a [f64], initial_slip: f64, initial: Initial) -> Protocol<'a> {
    Protocol {
        control,
        time: &T,
        imposed: x,
        normal: &N,
        initial_slip,
        initial,
    }
}

fn input_error(r: Result<impl std::fmt::Debug, SimError>) -> (usize, &'static str, String) {
    match r {
        Err(SimError::Input {
            row,
            field,
            message,
        }) => (row, field, message),
        other => panic!("expected a refusal naming a field, got {other:?}"),
    }
}

#[test]
fn a_non_finite_initial_slip_is_refused_by_name() {
    let m = sample();
    let slip = [0.0, 0.001, 0.002, 0.003];
    let shear = [0.0, 10.0, 20.0, 10.0];
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for (control, x) in [(Control::Shear, &shear), (Control::Slip, &slip)] {
            let (row, field, message) =
                input_error(simulate(&m, &proto(control, x, bad, Initial::Rest)));
            assert_eq!((row, field), (0, "initial_slip"), "{message}");
            assert!(message.contains(&bad.to_string()) && message.contains("finite"));
        }
    }
}

#[test]
fn a_start_with_a_non_finite_traction_or_a_negative_rate_is_refused_by_name() {
    let m = sample();
    let slip = [0.0, 0.001, 0.002, 0.003];
    let cases = [
        (
            Initial::Sliding {
                shear_kpa: 40.0,
                rate_mm_s: -1.0,
            },
            "initial.rate_mm_s",
        ),
        (
            Initial::Sliding {
                shear_kpa: 40.0,
                rate_mm_s: f64::NAN,
            },
            "initial.rate_mm_s",
        ),
        (
            Initial::Sliding {
                shear_kpa: 40.0,
                rate_mm_s: f64::INFINITY,
            },
            "initial.rate_mm_s",
        ),
        (
            Initial::Sliding {
                shear_kpa: f64::NAN,
                rate_mm_s: 0.01,
            },
            "initial.shear_kpa",
        ),
        (
            Initial::Loaded {
                shear_kpa: f64::NEG_INFINITY,
            },
            "initial.shear_kpa",
        ),
    ];
    for (initial, expected) in cases {
        let (row, field, message) =
            input_error(simulate(&m, &proto(Control::Slip, &slip, 0.0, initial)));
        assert_eq!((row, field), (0, expected), "{initial:?}: {message}");
        assert!(message.contains("expected"), "{message}");
    }
    // The sign of sliding is the traction's: a backward slide is a negative traction.
    let back = Initial::Sliding {
        shear_kpa: -30.0,
        rate_mm_s: 0.01,
    };
    let back_slip = [0.0, -0.001, -0.002, -0.003];
    assert!(simulate(&m, &proto(Control::Slip, &back_slip, 0.0, back)).is_ok());
}

#[test]
fn a_start_given_by_hand_above_the_capacity_is_refused_with_the_capacity() {
    let m = sample();
    let slip = [0.0, 0.001, 0.002, 0.003];
    let at = |initial| proto(Control::Slip, &slip, 0.0, initial);
    // Within the capacity: accepted.
    for ok in [
        Initial::Rest,
        Initial::Loaded { shear_kpa: 40.0 },
        Initial::Loaded { shear_kpa: -44.9 },
        Initial::Sliding {
            shear_kpa: 30.0,
            rate_mm_s: 0.01,
        },
    ] {
        check_start(&m, &at(ok)).unwrap_or_else(|e| panic!("{ok:?}: {e}"));
    }
    for (bad, what) in [
        (Initial::Loaded { shear_kpa: 1000.0 }, "at rest"),
        (
            Initial::Sliding {
                shear_kpa: 1e308,
                rate_mm_s: 1.0,
            },
            "sliding",
        ),
        (
            Initial::Sliding {
                shear_kpa: -46.0,
                rate_mm_s: 0.01,
            },
            "sliding",
        ),
    ] {
        let (row, field, message) = input_error(check_start(&m, &at(bad)));
        assert_eq!((row, field), (0, "initial.shear_kpa"), "{message}");
        assert!(
            message.contains("capacity 45.0") && message.contains(what),
            "{bad:?}: {message}"
        );
    }
    // Traction control: the first imposed shear is the start.
    let tau = [50.0, 40.0, 30.0, 20.0];
    let e = check_start(&m, &proto(Control::Shear, &tau, 0.0, Initial::Rest)).unwrap_err();
    assert!(
        matches!(e, SimError::Runaway { row: 0, capacity_kpa, .. } if (capacity_kpa - 45.0).abs() < 1e-9),
        "{e}"
    );
    // A record's first row may lie above the surface of the parameters a fit tries: simulate
    // itself starts on the surface there, as before.
    assert!(simulate(&m, &at(Initial::Loaded { shear_kpa: 50.0 })).is_ok());
}

#[test]
fn a_state_the_model_cannot_have_is_refused_and_its_own_states_are_not() {
    let m = sample();
    let c = Contact3::new(&m, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    let zero = State3 {
        slip: [0.0; 3],
        shear: [0.0; 3],
        mu: 0.0,
        r: 0.0,
        cos_r: 0.0,
        sin_r: 0.0,
        slip_path: 0.0,
        time: 0.0,
        slots: StateSlots::default(),
    };
    let e = c.check_state(&zero).unwrap_err();
    assert!(
        e.to_string().contains("cos_r") && e.to_string().contains("virgin"),
        "{e}"
    );
    let virgin = State3::virgin(&m, [0.0; 3]);
    c.check_state(&virgin).unwrap();
    let e = c
        .check_state(&State3 {
            mu: 100.0,
            ..virgin
        })
        .unwrap_err();
    assert_eq!(e.field, "mu");
    assert!(e.expected.contains("[0.3, 0.45]"), "{e}");
    for (field, st) in [
        ("r", State3 { r: 1.5, ..virgin }),
        (
            "slip_path",
            State3 {
                slip_path: -1.0,
                ..virgin
            },
        ),
        (
            "time",
            State3 {
                time: -1.0,
                ..virgin
            },
        ),
        (
            "shear",
            State3 {
                shear: [1e200, 1e200, 0.0],
                ..virgin
            },
        ),
        ("mu", State3 { mu: 0.1, ..virgin }),
    ] {
        assert_eq!(c.check_state(&st).unwrap_err().field, field);
    }
    // Every state of a path with reversals, holds and a pressure that changes is accepted.
    let pressure_bounds = Model::new(
        Params::sample(),
        Extensions {
            terms: Terms::one(
                TermEffect::named("pressure", "power-bounds", &[0.3, 0.1, 100.0]).unwrap(),
            ),
        },
    )
    .unwrap();
    for model in [m, pressure_bounds] {
        let c = Contact3::new(&model, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
        let mut st = State3::virgin(&model, [0.0; 3]);
        for k in 0..600 {
            let phase = (k / 100) % 3;
            let du = match phase {
                0 => [0.01, 0.002, 0.0],
                1 => [-0.012, 0.0, 0.0],
                _ => [0.0; 3],
            };
            let p = 50.0 + 40.0 * (k as f64 * 0.05).sin();
            st = c.step_increment(&st, &du, p, 1.0).unwrap();
            c.check_state(&st)
                .unwrap_or_else(|e| panic!("step {k}: the model's own state is refused: {e}"));
        }
    }
}

#[test]
fn a_family_names_its_own_state_variables_and_says_what_they_allow() {
    // Rate and state beside time healing: θ, the rate terms held and the contact's age live in
    // the families' slots, and a state that breaks their law is refused by the name the family
    // gives the variable.
    let rate = TermEffect::named("rate", "state-ageing", &[0.01, 0.012, 0.05, 1e-6, 0.01]).unwrap();
    let healing = TermEffect::named("healing", "log-erased", &[0.02, 1.0, 0.01]).unwrap();
    let m = Model::new(
        Params::sample(),
        Extensions {
            terms: Terms::one(rate).with(healing),
        },
    )
    .unwrap();
    let terms = &m.ext.terms;
    let c = Contact3::new(&m, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    let virgin = State3::virgin(&m, [0.0; 3]);
    c.check_state(&virgin).unwrap();
    // θ starts steady at the reference rate, D_c / v_ref.
    let theta = terms.state_value(&virgin.slots, "theta").unwrap();
    assert!((theta - 0.05 / 0.01).abs() < 1e-12, "{theta}");
    for (name, bad, expected) in [
        ("theta", 0.0, "> 0 [s]"),
        ("rate_factor", -1.0, "> 0"),
        ("age", -1.0, "a time >= 0"),
        ("healed", -0.5, "a healing gain >= 0"),
        ("theta", f64::NAN, "a finite number"),
    ] {
        let mut st = virgin;
        st.slots.0[terms.slot_of(name).unwrap()] = bad;
        let e = c.check_state(&st).unwrap_err();
        assert_eq!(e.field, name, "{e}");
        assert!(e.expected.contains(expected), "{e}");
    }
    // A slot no family on uses is named by its place.
    let base = sample();
    let mut st = State3::virgin(&base, [0.0; 3]);
    st.slots.0[2] = f64::INFINITY;
    let e = Contact3::new(&base, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
        .check_state(&st)
        .unwrap_err();
    assert_eq!(e.field, "slots[2]", "{e}");
    // The age counts the time at rest (a hold), and a slide resets it.
    let st = c.step_slip(&virgin, &[0.0; 3], 100.0, 2.5).unwrap();
    assert_eq!(terms.state_value(&st.slots, "age"), Some(2.5));
    let st = c.step_slip(&st, &[1.0, 0.0, 0.0], 100.0, 1.0).unwrap();
    assert_eq!(terms.state_value(&st.slots, "age"), Some(0.0));
}
