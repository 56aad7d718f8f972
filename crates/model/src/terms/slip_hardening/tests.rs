use super::*;

#[test]
fn a_change_with_slip_beyond_what_specimens_differ_by_shows_it_and_one_read_flat_rules_it_out() {
    let with = |lo: f64, hi: f64| super::super::EventReadings {
        slip_change_relative: Some(super::super::Reading {
            value: 0.5 * (lo + hi),
            lo,
            hi,
        }),
        ..Default::default()
    };
    let f = SlipHardening;
    // Softening by 11 % over the slide, hardening by 5 %: shown.
    assert!(f.shown(&with(-0.112, -0.107)));
    assert!(f.shown(&with(0.03, 0.07)));
    // Clear of zero but within what a second specimen (or a load cell's drift over a
    // test) could show: not shown; nor an interval that reaches into the band.
    assert!(!f.shown(&with(0.015, 0.018)));
    assert!(!f.shown(&with(-0.08, -0.01)));
    // Nothing read: nothing shown.
    assert!(!f.shown(&super::super::EventReadings::default()));
    // The reading lives on the first loadings.
    assert_eq!(f.shown_in(), &[Shows::FirstLoadings]);
    // Read flat within what specimens differ by, the whole interval: ruled out. An interval
    // reaching past the band leaves room; a change clear of zero, however small over a short
    // slide, is none; a change shown is none; nothing read rules nothing out.
    assert!(f.contradicted(&with(-0.007, 0.007)));
    assert!(!f.contradicted(&with(-0.01, 0.03)));
    assert!(!f.contradicted(&with(0.011, 0.015)));
    assert!(!f.contradicted(&with(-0.015, -0.002)));
    assert!(!f.contradicted(&with(-0.112, -0.107)));
    assert!(!f.contradicted(&super::super::EventReadings::default()));
}

#[test]
fn every_form_starts_at_zero_with_slope_h_or_delayed_and_saturates() {
    let mut p = [0.0; MAX_TERM_PARAMS];
    p[0] = 0.02;
    p[1] = 2.0;
    for (form, shape) in FORMS.iter().enumerate() {
        let f = SlipHardening;
        let (h0, d0) = f.term(form, &p, 0.0, 0.0);
        assert_eq!(h0, 0.0);
        // The delayed form sets in with no slope; the others with slope h.
        let slope0 = if shape.key == "delayed" { 0.0 } else { 0.02 };
        assert!((d0 - slope0).abs() < 1e-12, "{}", shape.key);
        let (h_far, d_far) = f.term(form, &p, 1e4, 0.0);
        assert!(
            h_far > 0.0 && h_far <= 0.04 + 1e-9,
            "{}: {h_far}",
            shape.key
        );
        assert!(d_far.abs() < 1e-6, "{}: {d_far}", shape.key);
        // dH/ds by a central difference.
        let (a, _) = f.term(form, &p, 0.9, 0.0);
        let (b, _) = f.term(form, &p, 1.1, 0.0);
        let (_, d) = f.term(form, &p, 1.0, 0.0);
        assert!(((b - a) / 0.2 - d).abs() < 1e-4, "{}", shape.key);
        // Time plays no part.
        assert_eq!(f.term(form, &p, 1.0, 0.0), f.term(form, &p, 1.0, 1e5));
    }
}

#[test]
fn each_form_has_its_closed_form() {
    let mut p = [0.0; MAX_TERM_PARAMS];
    p[0] = -0.03;
    p[1] = 0.5;
    let f = SlipHardening;
    let s = 0.8_f64;
    let exp = -0.03 * 0.5 * (1.0 - (-s / 0.5).exp());
    assert!((f.term(0, &p, s, 0.0).0 - exp).abs() < 1e-15);
    assert!((f.term(1, &p, s, 0.0).0 - -0.03 * 0.5).abs() < 1e-15);
    assert!((f.term(1, &p, 0.2, 0.0).0 - -0.03 * 0.2).abs() < 1e-15);
    let hyp = -0.03 * s / (1.0 + s / 0.5);
    assert!((f.term(2, &p, s, 0.0).0 - hyp).abs() < 1e-15);
    let delayed = -0.03 * 0.5 * (1.0 - (-(s / 0.5).powi(2)).exp());
    assert!((f.term(3, &p, s, 0.0).0 - delayed).abs() < 1e-15);
    // Steepest at s_h/√2, with 0.86 h there.
    let (_, steepest) = f.term(3, &p, 0.5 / 2f64.sqrt(), 0.0);
    assert!((steepest / -0.03 - (2.0f64).sqrt() * (-0.5f64).exp()).abs() < 1e-12);
}

#[test]
fn first_guesses_scale_with_the_slip_of_a_test() {
    let data = |slip_span_mm| DataScales {
        slip_span_mm,
        ..crate::terms::tests::one_rate_one_stress()
    };
    let short = SlipHardening.guess(0, &data(1.0));
    let long = SlipHardening.guess(0, &data(10.0));
    // Each start changes friction by the same amount over the slip of its test.
    assert!((short.starts[0][0] * 1.0 - long.starts[0][0] * 10.0).abs() < 1e-15);
    assert!((short.starts[0][1] * 10.0 - long.starts[0][1]).abs() < 1e-12);
    // A test that barely slides still gets a usable saturation slip.
    assert!(SlipHardening.guess(0, &data(0.0)).neutral[1] > 0.0);
    // A slope read off the tests' residual comes first, its saturation beyond the test.
    let read = DataScales {
        slip_slope_per_mm: Some(-0.004),
        ..data(5.0)
    };
    let g = SlipHardening.guess(1, &read);
    assert_eq!(g.starts[0], vec![-0.004, 10.0]);
    assert_eq!(g.starts.len(), 5);
}

#[test]
fn the_delayed_form_sets_in_after_the_tests_peak() {
    let data = |slip_to_peak_mm| DataScales {
        slip_span_mm: 4.0,
        slip_to_peak_mm,
        ..crate::terms::tests::one_rate_one_stress()
    };
    let delayed = FORMS.iter().position(|f| f.key == "delayed").unwrap();
    let g = SlipHardening.guess(delayed, &data(Some(1.0)));
    // s_h (fitted index 1) at least where a tenth of the plateau is reached at the peak.
    let lo = 1.0 / (-(0.9f64).ln()).sqrt();
    assert_eq!(g.bounds.len(), 1);
    let (i, b_lo, b_hi) = g.bounds[0];
    assert_eq!(i, 1);
    assert!((b_lo - lo).abs() < 1e-12 && b_hi == 1000.0);
    let mut p = [0.0; MAX_TERM_PARAMS];
    p[0] = 0.02;
    p[1] = b_lo;
    let (at_peak, _) = SlipHardening.term(delayed, &p, 1.0, 0.0);
    assert!((at_peak / (0.02 * b_lo) - 0.1).abs() < 1e-12);
    // Every start and the neutral lie within it.
    assert!(g.starts.iter().all(|s| s[1] >= b_lo));
    assert!(g.neutral[1] >= b_lo);
    // No peak read: the default bounds.
    assert!(SlipHardening.guess(delayed, &data(None)).bounds.is_empty());
}

#[test]
fn every_form_has_most_of_its_change_past_the_tests_peak() {
    let data = DataScales {
        slip_span_mm: 4.0,
        slip_to_peak_mm: Some(0.2),
        ..crate::terms::tests::one_rate_one_stress()
    };
    for (form, f) in FORMS.iter().enumerate() {
        let g = SlipHardening.guess(form, &data);
        assert_eq!(g.bounds.len(), 1, "{}", f.key);
        let (i, lo, hi) = g.bounds[0];
        assert_eq!((i, hi), (1, 1000.0), "{}", f.key);
        let share_at_peak = |s_h: f64| {
            let mut p = [0.0; MAX_TERM_PARAMS];
            p[0] = 0.05;
            p[1] = s_h;
            let (at_peak, _) = SlipHardening.term(form, &p, 0.2, 0.0);
            let (plateau, _) = SlipHardening.term(form, &p, 1e9, 0.0);
            at_peak / plateau
        };
        // At the bound the term has reached at most half of its change at the peak (a tenth
        // for the delayed form); any smaller scale would reach more.
        let most = if f.key == "delayed" { 0.1 } else { 0.5 };
        assert!(
            (share_at_peak(lo) - most).abs() < 1e-6,
            "{}: {}",
            f.key,
            share_at_peak(lo)
        );
        assert!(share_at_peak(0.5 * lo) > most + 0.05, "{}", f.key);
        assert!(
            g.starts.iter().all(|s| s[1] >= lo) && g.neutral[1] >= lo,
            "{}",
            f.key
        );
    }
    // No peak read: the default bounds for every form.
    let unread = DataScales {
        slip_to_peak_mm: None,
        ..data
    };
    assert!((0..FORMS.len()).all(|k| SlipHardening.guess(k, &unread).bounds.is_empty()));
}
