use super::*;
use crate::terms::Reading;

fn with(d: f64, d_k: f64) -> [f64; MAX_TERM_PARAMS] {
    let mut p = [0.0; MAX_TERM_PARAMS];
    p[0] = d;
    p[1] = d_k;
    p
}

#[test]
fn backward_sliding_scales_its_target_by_one_minus_d() {
    let f = Direction;
    let p = with(0.2, -0.1);
    for (form, &target) in TARGETS.iter().enumerate() {
        if target == Target::Bounds {
            continue;
        }
        assert_eq!(f.factor_on(form, &p, target, 100.0, 1.0), 1.0);
        assert!((f.factor_on(form, &p, target, 100.0, -1.0) - 0.8).abs() < 1e-15);
        // Sideways in 3-D: half of it.
        assert!((f.factor_on(form, &p, target, 100.0, 0.0) - 0.9).abs() < 1e-15);
        // Nothing else is scaled.
        for &other in TARGETS.iter().filter(|&&o| o != target) {
            assert_eq!(f.factor_on(form, &p, other, 100.0, -1.0), 1.0);
        }
        assert_eq!(f.range_on(form, &p, target), (0.8, 1.0));
    }
    // The general form: μ_s by d, μ_k by d_k, μ as a whole not at all.
    assert!((f.factor_on(BOUNDS, &p, Target::MuS, 100.0, -1.0) - 0.8).abs() < 1e-15);
    assert!((f.factor_on(BOUNDS, &p, Target::MuK, 100.0, -1.0) - 1.1).abs() < 1e-15);
    assert_eq!(f.factor_on(BOUNDS, &p, Target::Friction, 100.0, -1.0), 1.0);
    assert_eq!(f.range_on(BOUNDS, &p, Target::MuK), (1.0, 1.1));
}

#[test]
fn only_a_clear_asymmetry_of_the_reversals_corroborates_it() {
    let read = |lo, hi| EventReadings {
        backward_weakening: Some(Reading {
            value: 0.5 * (lo + hi),
            lo,
            hi,
        }),
        ..EventReadings::default()
    };
    assert!(Direction.corroborated(&EventReadings::default()));
    assert!(Direction.corroborated(&read(0.02, 0.1)));
    assert!(Direction.corroborated(&read(-0.1, -0.02)));
    assert!(!Direction.corroborated(&read(-0.02, 0.1)));
}
