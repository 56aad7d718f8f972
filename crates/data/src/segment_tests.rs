//! Unit tests of `segment.rs` (kept beside it to keep that file short).

use super::*;
use crate::meta::TestSpec;

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
