//! Unit tests of `segment.rs` (kept beside it to keep that file short).

use super::*;
use subfric_data::meta::TestSpec;

pub(crate) fn data(control: ControlColumn, t: Vec<f64>, imposed: Vec<f64>) -> TestData {
    let n = t.len();
    let (slip, shear) = match control {
        ControlColumn::Slip => (imposed, vec![0.0; n]),
        ControlColumn::Shear => (vec![0.0; n], imposed),
    };
    TestData {
        spec: TestSpec::new("x", "x.csv", control, 100.0),
        path: "x.csv".into(),
        time_s: t,
        slip_mm: slip,
        shear_kpa: shear,
        normal_kpa: vec![100.0; n],
        friction_given: false,
        line_of_row: (2..n + 2).collect(),
        comments: vec![],
        reading_notes: Vec::new(),
        channels: Vec::new(),
    }
}

#[test]
fn clean_velocity_steps() {
    // 0.01 mm/s for 100 s, 0.1 mm/s for 10 s, 0.01 mm/s for 100 s, dt 1 s / 0.1 s
    let mut t = vec![0.0];
    let mut y = vec![0.0];
    let mut add = |dt: f64, rate: f64, steps: usize| {
        for _ in 0..steps {
            let (lt, ly) = (*t.last().unwrap(), *y.last().unwrap());
            t.push(lt + dt);
            y.push(ly + rate * dt);
        }
    };
    add(1.0, 0.01, 100);
    add(0.1, 0.1, 100);
    add(1.0, 0.01, 100);
    let d = data(ControlColumn::Slip, t, y);
    let s = segment(&d, &SegmentOptions::default());
    assert_eq!(s.rate_changes, vec![100, 200]);
    assert!(s.holds.is_empty());
    assert!(s.reversals.is_empty());
    assert_eq!(s.row_kind[110], SegmentKind::AfterVelocityStep);
    assert_eq!(s.row_kind[150], SegmentKind::SteadySliding);
    let rates = s.step_rates();
    assert!((rates[0].0 - 0.01).abs() < 1e-9 && (rates[0].1 - 0.1).abs() < 1e-9);
    assert!(!s.conditioned.changed);
}

#[test]
fn segments_cover_all_rows() {
    let t: Vec<f64> = (0..50).map(|i| i as f64).collect();
    let y: Vec<f64> = t.iter().map(|t| (t * 0.3).sin()).collect();
    let s = segment(&data(ControlColumn::Slip, t, y), &SegmentOptions::default());
    let mut next = 0;
    for sg in &s.segments {
        assert_eq!(sg.start, next);
        assert!(sg.end > sg.start);
        next = sg.end;
    }
    assert_eq!(next, 50);
}

/// A level of `rows` rows at `rate` mm/s read every `dt` s, with the second half's rows later
/// by `removed_s` (rows taken out) and short of the level's travel over that time by
/// `missing_mm`, smoothed with `window`: the rows beside the junction keep their readings.
fn assert_junction_rows_kept(
    rows: usize,
    dt: f64,
    rate: f64,
    removed_s: f64,
    missing_mm: f64,
    window: f64,
) {
    let mut t: Vec<f64> = (0..rows).map(|i| i as f64 * dt).collect();
    let mut y: Vec<f64> = t.iter().map(|t| rate * t).collect();
    let half = rows / 2;
    for i in half..rows {
        t[i] += removed_s;
        y[i] += rate * removed_s - missing_mm;
    }
    let raw = y.clone();
    let level = [RateLevel {
        start: 1,
        end: rows,
        rate,
    }];
    smooth_levels(&t, &mut y, &level, window);
    for i in half - 3..half + 3 {
        assert!(
            (y[i] - raw[i]).abs() < 2e-4,
            "row {i}: {} moved to {}",
            raw[i],
            y[i]
        );
    }
}

#[test]
fn rows_next_to_a_stretch_taken_out_of_a_level_keep_their_readings() {
    // A level at 0.0058 mm/s read every 0.8 s, from which the rows of 4 s were taken out
    // (a gap closing on a reload: the travel across them, 0.0059 mm, is not the level's
    // 0.028 mm). A line in time through the rows on either side would move the two rows next
    // to the junction by about 0.002 mm, ten times the resolution and 10 kPa of an elastic
    // reload; each side is smoothed on its own instead.
    assert_junction_rows_kept(40, 0.8, 0.0058, 4.1, 0.0218, 0.015);
}

#[test]
fn levels_are_smoothed_at_the_noise_scale_only() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    let t: Vec<f64> = (0..2001).map(|i| i as f64 * 0.1).collect();
    let truth: Vec<f64> = t.iter().map(|t| 0.001 * t).collect();
    // Conditioned columns are monotone within a run: noise, then isotonic.
    let noisy: Vec<f64> = crate::condition::pava_increasing(
        &truth
            .iter()
            .map(|u| u + 0.00005 * (rng.gen::<f64>() - 0.5) * 3.46)
            .collect::<Vec<f64>>(),
    );
    let level = [RateLevel {
        start: 1,
        end: 2001,
        rate: 0.001,
    }];
    // The window segmentation uses for this noise: 15 bands of 10 reading SDs (0.05 µm). (A
    // narrower window, 0.002 mm, made a band of 2.7 SDs, which isotonic noise crosses from one
    // interval to the next: no level of a segmented record is smoothed that way.)
    let mut y = noisy.clone();
    smooth_levels(&t, &mut y, &level, LEVEL_SMOOTHING_BANDS * 10.0 * 0.00005);
    let rms = |v: &[f64]| {
        (v.iter()
            .zip(&truth)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / v.len() as f64)
            .sqrt()
    };
    assert!(
        rms(&y) < 0.3 * rms(&noisy),
        "{} vs {}",
        rms(&y),
        rms(&noisy)
    );
    assert_eq!((y[0], y[2000]), (noisy[0], noisy[2000]), "the ends stay");
    assert!(y.windows(2).all(|w| w[1] >= w[0]), "monotone");
    // Rows farther apart than the window: nothing changes.
    let sparse: Vec<f64> = truth
        .iter()
        .map(|u| u + 0.00002 * (rng.gen::<f64>() - 0.5))
        .collect();
    let mut z = sparse.clone();
    smooth_levels(&t, &mut z, &level, 0.00005);
    assert!(z == sparse, "sparse rows were changed");
}

#[test]
fn tiny_inputs() {
    for n in 0..4 {
        let t: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let y = vec![1.0; n];
        let s = segment(
            &data(ControlColumn::Shear, t, y),
            &SegmentOptions::default(),
        );
        assert_eq!(s.row_kind.len(), n);
    }
}

/// A slip-controlled test from rest whose travel column counts a seating: fast while the shear
/// is low (its first rows as a generated record with a seating toe shows them: 0.07 mm/s,
/// settling to the drive's 0.01 mm/s over a few seconds), then a true step to 0.1 mm/s long
/// after the peak. `from_rest` false: the same travel with the shear at its sliding level from
/// the first row (a segment cut from a longer run).
fn seating_then_step(from_rest: bool) -> TestData {
    const SEATING: [f64; 20] = [
        0.0, 0.0139, 0.026, 0.0369, 0.0464, 0.0551, 0.0629, 0.0699, 0.0764, 0.0824, 0.0879, 0.0931,
        0.0978, 0.1022, 0.1064, 0.1104, 0.1142, 0.1178, 0.1212, 0.1245,
    ];
    let dt = 0.2;
    let mut y = SEATING.to_vec();
    let mut t: Vec<f64> = (0..y.len()).map(|i| i as f64 * dt).collect();
    let mut shear: Vec<f64> = Vec::new();
    for i in y.len()..3000 {
        let rate = if i < 2000 { 0.01 } else { 0.1 };
        t.push(i as f64 * dt);
        y.push(y[i - 1] + rate * dt);
    }
    for &time in &t {
        // The shear rises to its peak of 50 kPa over the first 30 s, then slides at 45.
        shear.push(if !from_rest {
            45.0
        } else if time < 30.0 {
            50.0 * time / 30.0
        } else {
            45.0
        });
    }
    // A transducer with 0.2 µm of noise (a deterministic wiggle): rates are read over chunks
    // of about 20 µm, a few of them in the seating.
    let y = y
        .iter()
        .enumerate()
        .map(|(i, v)| v + 2e-4 * ((i as f64 * 2.399).sin() + (i as f64 * 0.61).cos()) / 1.41)
        .collect();
    let mut d = data(ControlColumn::Slip, t, y);
    d.shear_kpa = shear;
    d
}

#[test]
fn a_seating_while_the_first_loading_rises_is_not_a_velocity_step() {
    let s = segment(&seating_then_step(true), &SegmentOptions::default());
    // Only the true step after the peak: the fast travel of the seating is part of the first
    // loading, at one drive rate.
    assert_eq!(s.rate_changes.len(), 1, "{:?}", s.rate_changes);
    assert!(
        (1990..=2010).contains(&s.rate_changes[0]),
        "{:?}",
        s.rate_changes
    );
    assert_eq!(s.row_kind[5], SegmentKind::InitialLoading);
    assert!(s.row_kind[..1990]
        .iter()
        .all(|k| *k != SegmentKind::AfterVelocityStep));
    // Already sliding at the first row: no rise from rest, and the change of rate in the first
    // seconds is read as the column shows it.
    let sliding = segment(&seating_then_step(false), &SegmentOptions::default());
    assert_eq!(sliding.rate_changes.len(), 2, "{:?}", sliding.rate_changes);
}

#[test]
fn a_test_that_starts_in_a_hold_or_with_no_shear_has_no_seating_rise() {
    // Rows 0..20 still, then sliding: the first hold starts at the second row, and the first
    // run before it is a single row.
    let t: Vec<f64> = (0..400).map(|i| i as f64).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| if t < 20.0 { 0.0 } else { 0.01 * (t - 20.0) })
        .collect();
    let mut d = data(ControlColumn::Slip, t, y);
    d.shear_kpa = (0..400).map(|i| (i as f64 * 0.2).min(40.0)).collect();
    let seg = segment(&d, &SegmentOptions::default());
    assert!(
        seg.holds.first().is_some_and(|h| h.0 <= 1),
        "{:?}",
        seg.holds
    );
    assert_eq!(seating_rise_end(&d, 400, &seg), 0);
    // A shear column shorter than the record (never a panic) and one that is all zero.
    d.shear_kpa.truncate(3);
    assert_eq!(seating_rise_end(&d, 400, &seg), 0);
    d.shear_kpa = vec![0.0; 400];
    assert_eq!(seating_rise_end(&d, 400, &seg), 0);
}
