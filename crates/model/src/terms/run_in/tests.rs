use crate::contact1::{Contact1, State1};
use crate::extensions::Extensions;
use crate::simulate::{simulate, Control, Protocol};
use crate::terms::{TermEffect, Terms};
use crate::{Model, Params};

const RUN_IN: [f64; 3] = [0.05, 0.4, 50.0];

fn run_in(g: f64) -> TermEffect {
    TermEffect::named("run-in", "exponential", &[g, RUN_IN[1], RUN_IN[2]]).unwrap()
}

fn model(terms: Terms) -> Model {
    Model::new(Params::sample(), Extensions { terms }).unwrap()
}

/// φ of a 1-D state, read through the family.
fn phi(m: &Model, st: &State1) -> f64 {
    m.ext.terms.state_value(&st.slots, "run_in").unwrap()
}

#[test]
fn its_state_wears_off_with_slip_and_comes_back_at_rest_as_its_law_says() {
    // Beside rate and state, so that its slot is not the first: the slots are the family's
    // wherever the registry puts them. Locked at rest, so that a hold is a rest (a creeping
    // form would slide through it).
    let rate = TermEffect::named(
        "rate",
        "state-slip-locked",
        &[0.01, 0.012, 0.05, 1e-6, 0.01],
    )
    .unwrap();
    let m = model(Terms::one(rate).with(run_in(RUN_IN[0])));
    assert_eq!(m.ext.terms.slot_of("run_in"), Some(3));
    let (g, l, t_r) = (RUN_IN[0], RUN_IN[1], RUN_IN[2]);
    let mut c = Contact1::new(&m);
    let mut st = State1::virgin(&m, 0.0);
    assert_eq!(phi(&m, &st), 1.0);
    let p = 100.0;
    // A slide of 1.5 mm at 0.01 mm/s: φ = e^(−s/L) over the plastic slip s, whatever the
    // steps, and the friction carries g φ on top of μ and the rate terms.
    let dt = 0.1;
    for k in 1..=1500 {
        st = c.step_slip(&st, k as f64 * 1e-3, p, dt).unwrap();
        let want = (-st.slip_path / l).exp();
        assert!((phi(&m, &st) - want).abs() < 1e-12 * want, "step {k}");
    }
    let worn = phi(&m, &st);
    assert!((worn - (-1.5 / l).exp()).abs() < 1e-3, "{worn}");
    // A hold of 40 s (the slip kept): φ comes back as 1 − (1 − φ₀) e^(−t/t_r), step by step.
    let slip = st.slip;
    for k in 1..=40 {
        st = c.step_slip(&st, slip, p, 1.0).unwrap();
        let want = 1.0 - (1.0 - worn) * (-(k as f64) / t_r).exp();
        assert!((phi(&m, &st) - want).abs() < 1e-12, "hold {k}");
    }
    let healed = phi(&m, &st);
    // Reloading wears it off again from there: e^(−Δs/L) of the new plastic slip.
    let (s0, mut u) = (st.slip_path, slip);
    for _ in 0..500 {
        u += 1e-3;
        st = c.step_slip(&st, u, p, dt).unwrap();
    }
    let want = healed * (-(st.slip_path - s0) / l).exp();
    assert!((phi(&m, &st) - want).abs() < 1e-12 * want);
    // What friction it adds: the run-in model slides above the same model without it by
    // g φ (to the elastic slip by which the two slides differ).
    let without = model(Terms::one(rate).with(run_in(0.0)));
    let mut c0 = Contact1::new(&without);
    let mut s0 = State1::virgin(&without, 0.0);
    let mut s1 = State1::virgin(&m, 0.0);
    for k in 1..=800 {
        let u = k as f64 * 1e-3;
        s0 = c0.step_slip(&s0, u, p, dt).unwrap();
        s1 = c.step_slip(&s1, u, p, dt).unwrap();
    }
    let gain = (s1.shear - s0.shear) / p;
    let want = g * (-s1.slip_path / l).exp();
    assert!((gain - want).abs() < 1e-3 * want, "{gain} vs {want}");
}

#[test]
fn a_record_through_simulate_shows_the_run_in_friction_at_a_known_slip() {
    // Slip control from rest, 2 mm at 0.01 mm/s: the friction the record shows exceeds the
    // base model's by g e^(−s/L) at slip s (to the elastic slip, α_t = 1000 kN/mm³).
    let n = 2000;
    let time: Vec<f64> = (0..=n).map(|i| i as f64 * 0.1).collect();
    let slip: Vec<f64> = (0..=n).map(|i| i as f64 * 1e-3).collect();
    let normal = vec![100.0; n + 1];
    let proto = Protocol {
        control: Control::Slip,
        time: &time,
        imposed: &slip,
        normal: &normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    let with = simulate(&model(Terms::one(run_in(RUN_IN[0]))), &proto).unwrap();
    let base = simulate(&model(Terms::NONE), &proto).unwrap();
    for i in [500, 1000, 2000] {
        let s = slip[i];
        let want = RUN_IN[0] * (-s / RUN_IN[1]).exp();
        let got = (with.shear[i] - base.shear[i]) / normal[i];
        assert!(
            (got - want).abs() < 1e-3 * RUN_IN[0],
            "at {s} mm: {got} vs {want}"
        );
    }
}

#[test]
fn a_state_it_cannot_have_is_refused_by_its_name_and_too_many_states_by_the_family() {
    let m = model(Terms::one(run_in(RUN_IN[0])));
    let c = crate::Contact3::new(&m, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    let mut st = crate::State3::virgin(&m, [0.0; 3]);
    c.check_state(&st).unwrap();
    st.slots.0[0] = 1.5;
    let e = c.check_state(&st).unwrap_err();
    assert_eq!(
        (e.field, e.expected.as_str()),
        ("run_in", "a share in [0, 1]")
    );
    // Rate (three variables) and time healing (two) fill the contact's slots: a third family
    // with a state is refused, named.
    let rate = TermEffect::named("rate", "state-slip", &[0.01, 0.012, 0.05, 1e-6, 0.01]).unwrap();
    let healing = TermEffect::named("healing", "log", &[0.01, 10.0]).unwrap();
    let full = Terms::one(rate).with(healing);
    let issues = full.with(run_in(RUN_IN[0])).issues();
    assert!(
        issues
            .iter()
            .any(|(key, _, why)| *key == "run_in.g" && why.contains("slots")),
        "{issues:?}"
    );
}
