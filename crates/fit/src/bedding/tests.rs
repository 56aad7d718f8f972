use super::*;
use subfric_model::{simulate, Params, Protocol};

/// A monotonic test of the sample parameters at 100 kPa, its recorded travel the
/// interface slip plus `toe` mm closed exponentially in the running
/// peak shear.
fn seated(toe: f64, rows: usize) -> PreparedTest {
    seated_by(rows, &|share| toe * (1.0 - (-share / 0.2).exp()))
}

/// As [`seated`], the travel taken up by seating `closed(share)` [mm] at a running peak
/// share `share` of the test's peak shear.
fn seated_by(rows: usize, closed: &dyn Fn(f64) -> f64) -> PreparedTest {
    let model = Model::base(Params::sample()).unwrap();
    let time: Vec<f64> = (0..rows).map(|i| i as f64).collect();
    let slip: Vec<f64> = (0..rows)
        .map(|i| 3.0 * i as f64 / (rows - 1) as f64)
        .collect();
    let normal = vec![100.0; rows];
    let proto = Protocol {
        control: Control::Slip,
        time: &time,
        imposed: &slip,
        normal: &normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    let shear = simulate(&model, &proto).unwrap().shear;
    let peak = shear.iter().fold(0.0f64, |m, v| m.max(*v));
    let mut running = 0.0f64;
    let recorded: Vec<f64> = slip
        .iter()
        .zip(&shear)
        .map(|(u, s)| {
            running = running.max(*s);
            u + closed(running / peak)
        })
        .collect();
    // Noise of 0.1 % of the peak from a fixed linear congruential sequence.
    let mut state = 12345u64;
    let measured: Vec<f64> = shear
        .iter()
        .map(|s| {
            let mut u = 0.0;
            for _ in 0..12 {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                u += (state >> 11) as f64 / (1u64 << 53) as f64;
            }
            s + 1e-3 * peak * (u - 6.0)
        })
        .collect();
    let n = time.len();
    let spec =
        subfric_data::TestSpec::new("mono", "mono.csv", subfric_data::ControlColumn::Slip, 100.0);
    let data = subfric_data::TestData {
        spec,
        path: "mono.csv".into(),
        time_s: time.clone(),
        slip_mm: recorded.clone(),
        shear_kpa: measured.clone(),
        normal_kpa: normal.clone(),
        friction_given: false,
        line_of_row: (2..n + 2).collect(),
        comments: vec![],
        reading_notes: Vec::new(),
        channels: Vec::new(),
    };
    let segmentation = subfric_reading::segment(&data, &Default::default());
    let t = FitTest::new("mono", Control::Slip, time, recorded, measured, normal);
    PreparedTest {
        full: t.clone(),
        kept: (0..t.len()).collect(),
        fit: t,
        segmentation,
        toe: None,
        source: data,
    }
}

#[test]
fn pool_adjacent_violators_gives_the_closest_non_decreasing_sequence() {
    assert_eq!(
        isotonic(&[1.0, 3.0, 2.0, 4.0], &[1.0; 4]),
        vec![1.0, 2.5, 2.5, 4.0]
    );
    // A heavier row pulls the pooled value towards itself.
    let v = isotonic(&[3.0, 1.0], &[3.0, 1.0]);
    assert!((v[0] - 2.5).abs() < 1e-12 && (v[1] - 2.5).abs() < 1e-12);
    let curve = [(0.1, 0.0), (0.5, 0.04), (0.9, 0.06)];
    assert_eq!(closure_at(&curve, 0.0), 0.0);
    assert!((closure_at(&curve, 0.3) - 0.02).abs() < 1e-12);
    assert_eq!(closure_at(&curve, 2.0), 0.06);
}

#[test]
fn a_seating_toe_is_fitted_and_taken_out_of_the_travel() {
    let model = Model::base(Params::sample()).unwrap();
    for toe in [0.03, 0.08, 0.15] {
        let p = seated(toe, 400);
        let refit = |_: &[FitTest], m: &Model| *m;
        let (out, kept) = fit_bedding(std::slice::from_ref(&p), &model, &refit);
        assert_eq!(kept.len(), 1, "{kept:?}");
        let b = &kept[0];
        assert!(b.misfit_with < 0.1 * b.misfit_without, "{b:?}");
        assert!(b.misfit_with < 3.0, "{b:?}");
        // The travel after the peak moves back by about the toe (it closed by e⁻⁵ of
        // itself at the peak, and the curve is read to 95 % of it).
        let last = p.full.len() - 1;
        let shift = p.full.imposed[last] - out[0].full.imposed[last];
        assert!((shift - toe).abs() < 0.1 * toe, "toe {toe}: shift {shift}");
    }
}

#[test]
fn a_toe_of_one_row_is_seated_as_a_long_one_is() {
    // Issue 38: a toe of one row below 5 % of the peak that reaches 25 % within a few rows
    // escaped a rule that wanted three rows below 5 %. Here the 0.1 mm of seating close
    // almost at once: by 5 % of the peak shear, within the first two rows of a 60-row test.
    let model = Model::base(Params::sample()).unwrap();
    let toe = 0.1;
    let p = seated_by(60, &|share| toe * (share / 0.05).min(1.0));
    let first_rows_below_5_percent = p
        .full
        .measured
        .iter()
        .take_while(|&&s| s < 0.05 * p.full.measured.iter().cloned().fold(0.0, f64::max))
        .count();
    assert!(
        first_rows_below_5_percent <= 2,
        "{first_rows_below_5_percent}"
    );
    let refit = |_: &[FitTest], m: &Model| *m;
    let (out, kept) = fit_bedding(std::slice::from_ref(&p), &model, &refit);
    assert_eq!(kept.len(), 1, "{kept:?}");
    let b = &kept[0];
    assert!(b.misfit_with < 0.2 * b.misfit_without, "{b:?}");
    let last = p.full.len() - 1;
    let shift = p.full.imposed[last] - out[0].full.imposed[last];
    assert!((shift - toe).abs() < 0.15 * toe, "shift {shift}");
}

#[test]
fn a_toe_is_seated_on_a_test_whose_level_the_base_misses() {
    // A pressure effect the base lacks puts this test's friction 10 % below the base's.
    let mut base = Model::base(Params::sample()).unwrap();
    base.params.mu_s *= 1.1;
    base.params.mu_k *= 1.1;
    let p = seated(0.08, 400);
    let refit = |_: &[FitTest], m: &Model| *m;
    let (out, kept) = fit_bedding(std::slice::from_ref(&p), &base, &refit);
    assert_eq!(kept.len(), 1, "{kept:?}");
    let last = p.full.len() - 1;
    let shift = p.full.imposed[last] - out[0].full.imposed[last];
    assert!((shift - 0.08).abs() < 0.01, "shift {shift}");
}

#[test]
fn a_closure_that_closes_only_near_the_peak_is_no_seating() {
    // Concave, half closed by a fifth of the peak: a seating; closing mostly past half the
    // peak (convex): the rise's own shape, not a gap.
    assert!(closes_as_it_loads(&[
        (0.0, 0.0),
        (0.2, 0.05),
        (0.5, 0.08),
        (0.95, 0.1)
    ]));
    assert!(!closes_as_it_loads(&[
        (0.0, 0.0),
        (0.5, 0.02),
        (0.8, 0.06),
        (0.95, 0.1)
    ]));
    // Read on coarse rows: closed within the second row, whatever share that row is at.
    assert!(closes_as_it_loads(&[(0.02, 0.0), (0.5, 0.1), (0.95, 0.1)]));
    assert!(!closes_as_it_loads(&[]));
}

#[test]
fn a_loading_without_a_toe_keeps_its_travel() {
    let model = Model::base(Params::sample()).unwrap();
    let p = seated(0.0, 400);
    let refit = |_: &[FitTest], m: &Model| *m;
    let (out, kept) = fit_bedding(std::slice::from_ref(&p), &model, &refit);
    assert!(kept.is_empty(), "{kept:?}");
    assert_eq!(out[0].full.imposed, p.full.imposed);
}

#[test]
fn a_test_that_starts_sliding_has_no_first_loading_to_seat() {
    let mut p = seated(0.08, 200);
    p.fit.initial = Initial::Sliding {
        shear_kpa: 10.0,
        rate_mm_s: 0.01,
    };
    assert!(first_loading(&p.fit).is_none());
    p.fit.initial = Initial::Rest;
    p.fit.control = Control::Shear;
    assert!(first_loading(&p.fit).is_none());
}
