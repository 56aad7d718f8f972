use super::*;

#[test]
fn the_linear_form_grows_with_time_and_the_saturating_one_levels_off() {
    let mut p = [0.0; MAX_TERM_PARAMS];
    p[0] = 1e-4;
    p[1] = 0.05;
    p[2] = 100.0;
    let f = TimeTrend;
    assert_eq!(f.term(0, &p, 7.0, 0.0), (0.0, 0.0));
    assert!((f.term(0, &p, 0.0, 300.0).0 - 0.03).abs() < 1e-15);
    let early = f.term(1, &p, 0.0, 1.0).0;
    assert!((early - 0.05 * (1.0 - (-0.01f64).exp())).abs() < 1e-15);
    assert!((f.term(1, &p, 0.0, 1e5).0 - 0.05).abs() < 1e-12);
}

#[test]
fn steady_sliding_carries_the_trend_times_the_normal_stress() {
    // Closed form: once a contact slides steadily (r = 1, μ at its steady value) the shear
    // is p (μ_ss + T(t)); with and without the trend it differs by p c t exactly.
    use crate::{simulate, Control, Extensions, Initial, Model, Params, Protocol};
    let time: Vec<f64> = (0..=2000).map(|i| i as f64 * 0.5).collect();
    let imposed: Vec<f64> = time.iter().map(|t| 0.01 * t).collect();
    let normal = vec![200.0; time.len()];
    let proto = Protocol {
        control: Control::Slip,
        time: &time,
        imposed: &imposed,
        normal: &normal,
        initial_slip: 0.0,
        initial: Initial::Rest,
    };
    let base = Model::base(Params::sample()).unwrap();
    let (index, _) = crate::terms::family_named("time-trend").unwrap();
    let mut trend = crate::terms::TermEffect::new(index, 0);
    trend.p[0] = 2e-5;
    let with = Model {
        ext: Extensions {
            terms: crate::terms::Terms::one(trend),
        },
        ..base
    };
    let a = simulate(&base, &proto).unwrap();
    let b = simulate(&with, &proto).unwrap();
    // From 10 mm of slip on the contact slides steadily (κ s ≫ 1, ũ s ≫ 1).
    for i in (2000..time.len()).step_by(100) {
        let expected = 200.0 * 2e-5 * time[i];
        let got = b.shear[i] - a.shear[i];
        assert!(
            (got - expected).abs() < 1e-3 * expected,
            "t {}: {got} vs {expected}",
            time[i]
        );
    }
}

#[test]
fn first_guesses_scale_with_the_duration() {
    let data = |duration_s| DataScales {
        duration_s,
        ..crate::terms::tests::one_rate_one_stress()
    };
    let short = TimeTrend.guess(0, &data(100.0));
    let long = TimeTrend.guess(0, &data(10_000.0));
    // Each start changes friction by the same amount over its test.
    assert!((short.starts[0][0] * 100.0 - long.starts[0][0] * 10_000.0).abs() < 1e-15);
    assert!(!TimeTrend.applies(&data(0.0)));
}
