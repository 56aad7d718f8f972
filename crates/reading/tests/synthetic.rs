//! Conditioning and segmentation on synthetic signals with known answers.

use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use subfric_data::{ControlColumn, TestData, TestSpec};
use subfric_reading::{condition_imposed, segment, SegmentKind, SegmentOptions};

fn gauss(rng: &mut impl Rng) -> f64 {
    StandardNormal.sample(rng)
}

fn data(control: ControlColumn, time: Vec<f64>, imposed: Vec<f64>) -> TestData {
    let n = time.len();
    let (slip, shear) = match control {
        ControlColumn::Slip => (imposed, vec![0.0; n]),
        ControlColumn::Shear => (vec![0.0; n], imposed),
    };
    TestData {
        spec: TestSpec::new("syn", "syn.csv", control, 100.0),
        path: "syn.csv".into(),
        time_s: time,
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

/// Triangle 0 → +a → −a → … with `legs` legs after the first, sampled every `dt` s at `rate` mm/s.
fn triangle(a: f64, legs: usize, dt: f64, rate: f64) -> (Vec<f64>, Vec<f64>, Vec<usize>) {
    let mut t = vec![0.0];
    let mut y = vec![0.0];
    let mut revs = Vec::new();
    let step = rate * dt;
    let push_to = |target: f64, t: &mut Vec<f64>, y: &mut Vec<f64>| {
        let start = *y.last().unwrap();
        let n = ((target - start).abs() / step).round() as usize;
        for k in 1..=n {
            t.push(t.last().unwrap() + dt);
            y.push(start + (target - start) * k as f64 / n as f64);
        }
    };
    push_to(a, &mut t, &mut y);
    let mut sign = -1.0;
    for _ in 0..legs {
        revs.push(y.len() - 1);
        push_to(sign * a, &mut t, &mut y);
        sign = -sign;
    }
    (t, y, revs)
}

fn assert_monotone_runs(values: &[f64], reversals: &[usize]) {
    let mut bounds = vec![0];
    bounds.extend(reversals);
    bounds.push(values.len() - 1);
    for w in bounds.windows(2) {
        let run = &values[w[0]..=w[1]];
        let up = run[run.len() - 1] >= run[0];
        for p in run.windows(2) {
            assert!(
                if up { p[1] >= p[0] } else { p[1] <= p[0] },
                "spurious reversal in run {w:?}"
            );
        }
    }
}

#[test]
fn noisy_triangle_keeps_real_reversals_only() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(1);
    let (t, truth, revs) = triangle(1.0, 7, 0.5, 0.01);
    let sd = 0.0003;
    let noisy: Vec<f64> = truth.iter().map(|y| y + sd * gauss(&mut rng)).collect();
    let d = data(ControlColumn::Slip, t, noisy.clone());
    let seg = segment(&d, &SegmentOptions::default());
    assert_eq!(seg.reversals.len(), revs.len());
    for (found, want) in seg.reversals.iter().zip(&revs) {
        assert!(
            found.abs_diff(*want) <= 2,
            "reversal at {found}, expected {want}"
        );
    }
    assert_eq!(seg.cycles(), 4);
    assert!(
        seg.holds.is_empty() && seg.rate_changes.is_empty(),
        "{:?} {:?}",
        seg.holds,
        seg.rate_changes
    );
    let c = condition_imposed(&d);
    assert!(
        (c.noise_sd / sd - 1.0).abs() < 0.2,
        "noise sd {}",
        c.noise_sd
    );
    assert_monotone_runs(&c.values, &seg.reversals);
    let err = c
        .values
        .iter()
        .zip(&truth)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(err < 6.0 * sd, "max error {err}");
    // the raw signal has no spurious reversal at this sampling either, so it is kept as is
    assert_eq!(c.changed, c.values != noisy);
}

#[test]
fn oversampled_noisy_triangle_is_made_monotone() {
    // 0.0005 mm per row with 0.0003 mm noise: the raw column goes backwards all the time
    let mut rng = rand::rngs::StdRng::seed_from_u64(2);
    let (t, truth, revs) = triangle(0.5, 3, 0.5, 0.001);
    let sd = 0.0003;
    let noisy: Vec<f64> = truth.iter().map(|y| y + sd * gauss(&mut rng)).collect();
    assert!(noisy.windows(2).filter(|w| w[1] < w[0]).count() > 100);
    let d = data(ControlColumn::Slip, t, noisy);
    let seg = segment(&d, &SegmentOptions::default());
    assert_eq!(seg.reversals.len(), revs.len());
    for (found, want) in seg.reversals.iter().zip(&revs) {
        assert!(
            found.abs_diff(*want) <= 15,
            "reversal at {found}, expected {want}"
        );
    }
    assert!(seg.conditioned.changed);
    assert_monotone_runs(&seg.conditioned.values, &seg.reversals);
    assert!(seg.holds.is_empty(), "{:?}", seg.holds);
    assert!(seg.rate_changes.is_empty(), "{:?}", seg.rate_changes);
}

#[test]
fn noisy_ramp_hold_ramp() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let dt = 0.5;
    let mut t = Vec::new();
    let mut truth = Vec::new();
    for i in 0..=600 {
        let ti = i as f64 * dt;
        t.push(ti);
        truth.push(if ti <= 100.0 {
            0.01 * ti
        } else if ti <= 200.0 {
            1.0
        } else {
            1.0 + 0.01 * (ti - 200.0)
        });
    }
    let sd = 0.0003;
    let noisy: Vec<f64> = truth.iter().map(|y| y + sd * gauss(&mut rng)).collect();
    let d = data(ControlColumn::Slip, t.clone(), noisy.clone());
    let seg = segment(&d, &SegmentOptions::default());
    assert!(seg.reversals.is_empty(), "{:?}", seg.reversals);
    assert_eq!(seg.holds.len(), 1);
    let (s, e) = seg.holds[0];
    assert!(
        (t[s - 1] - 100.0).abs() <= 1.0 && (t[e - 1] - 200.0).abs() <= 1.0,
        "{:?}",
        (t[s - 1], t[e - 1])
    );
    let c = &seg.conditioned;
    assert!(c.changed);
    assert!(c.values.windows(2).all(|w| w[1] >= w[0]));
    assert!(
        c.values[s..e].iter().all(|v| *v == c.values[s]),
        "hold flat"
    );
    assert!((c.values[s] - 1.0).abs() < 3.0 * sd);
    let kinds: Vec<SegmentKind> = seg.segments.iter().map(|s| s.kind).collect();
    assert_eq!(
        kinds,
        vec![
            SegmentKind::InitialLoading,
            SegmentKind::SteadySliding,
            SegmentKind::Hold,
            SegmentKind::AfterHold,
            SegmentKind::SteadySliding
        ]
    );
    let after = &seg.segments[3];
    assert!(
        (t[after.end - 1] - 220.0).abs() <= 1.0,
        "after-hold covers 0.2 mm"
    );
}

#[test]
fn clean_signals_are_not_changed() {
    let (t, y, revs) = triangle(1.5, 4, 0.5, 0.02);
    let d = data(ControlColumn::Slip, t, y.clone());
    let c = condition_imposed(&d);
    assert!(!c.changed);
    assert_eq!(c.values, y);
    assert_eq!(c.noise_sd, 0.0);
    assert_eq!(segment(&d, &SegmentOptions::default()).reversals, revs);
}

#[test]
fn a_single_spike_is_not_a_reversal() {
    let t: Vec<f64> = (0..400).map(|i| i as f64).collect();
    let mut rng = rand::rngs::StdRng::seed_from_u64(4);
    let mut y: Vec<f64> = t
        .iter()
        .map(|t| 0.005 * t + 0.0002 * gauss(&mut rng))
        .collect();
    y[200] += 0.05;
    let d = data(ControlColumn::Slip, t, y);
    let seg = segment(&d, &SegmentOptions::default());
    assert!(seg.reversals.is_empty(), "{:?}", seg.reversals);
    assert!(seg.conditioned.values.windows(2).all(|w| w[1] >= w[0]));
}

#[test]
fn shear_controlled_creep_hold_and_unloading() {
    // shear 0 → 50 kPa at 1 kPa/s, creep at 50 kPa for 500 s, unload to 0
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    let mut t = Vec::new();
    let mut tau = Vec::new();
    let mut slip = Vec::new();
    for i in 0..=1200 {
        let ti = i as f64 * 0.5;
        t.push(ti);
        let s = if ti <= 50.0 {
            ti
        } else if ti <= 550.0 {
            50.0
        } else {
            (50.0 - (ti - 550.0)).max(0.0)
        };
        tau.push(s + 0.02 * gauss(&mut rng));
        slip.push(if ti <= 50.0 {
            0.001 * ti
        } else {
            0.05 + 0.0005 * (ti.min(550.0) - 50.0)
        });
    }
    // end at rest at zero shear for a while
    let n = t.len();
    let mut d = data(ControlColumn::Shear, t.clone(), tau);
    d.slip_mm = slip;
    assert_eq!(d.len(), n);
    let seg = segment(&d, &SegmentOptions::default());
    assert!(seg.reversals.len() <= 1, "{:?}", seg.reversals);
    let creep = seg
        .holds
        .iter()
        .find(|h| (t[h.0 - 1] - 50.0).abs() <= 1.5)
        .unwrap_or_else(|| panic!("creep hold not found in {:?}", seg.holds));
    assert!(
        (t[creep.1 - 1] - 550.0).abs() <= 1.5,
        "{:?} {:?}",
        seg.holds,
        seg.reversals
    );
    assert_eq!(seg.row_kind[50], SegmentKind::InitialLoading);
    assert_eq!(seg.row_kind[600], SegmentKind::Hold);
    assert_eq!(seg.row_kind[1120], SegmentKind::Unloading);
    // the creep slip (0.25 mm) is not an imposed quantity: holds stay holds
    assert!(seg.of_kind(SegmentKind::Unloading).all(|s| s.rate < 0.0));
}

#[test]
fn noisy_pulsating_shear_counts_cycles() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(6);
    let mut t = Vec::new();
    let mut tau = Vec::new();
    for i in 0..=1200 {
        let ti = i as f64 * 0.5;
        let phase = ti % 60.0;
        let s = if phase <= 30.0 { phase } else { 60.0 - phase };
        t.push(ti);
        tau.push(1.6 * s + 0.05 * gauss(&mut rng));
    }
    let d = data(ControlColumn::Shear, t, tau);
    let seg = segment(&d, &SegmentOptions::default());
    assert_eq!(seg.reversals.len(), 19, "{:?}", seg.reversals);
    assert_eq!(seg.cycles(), 10);
    assert!(seg.holds.is_empty());
    assert_eq!(seg.of_kind(SegmentKind::Unloading).count(), 10);
}

#[test]
fn velocity_steps_with_noise() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let mut t = vec![0.0];
    let mut y = vec![0.0];
    let plan = [
        (0.5, 0.01, 200),
        (0.5, 0.03, 200),
        (0.5, 0.01, 200),
        (0.5, 0.003, 200),
    ];
    let mut steps = Vec::new();
    for (k, (dt, rate, rows)) in plan.iter().enumerate() {
        if k > 0 {
            steps.push(t.len() - 1);
        }
        for _ in 0..*rows {
            let (lt, ly) = (*t.last().unwrap(), *y.last().unwrap());
            t.push(lt + dt);
            y.push(ly + rate * dt);
        }
    }
    let noisy: Vec<f64> = y.iter().map(|v| v + 0.0002 * gauss(&mut rng)).collect();
    let seg = segment(
        &data(ControlColumn::Slip, t, noisy),
        &SegmentOptions::default(),
    );
    assert_eq!(seg.rate_changes.len(), 3, "{:?}", seg.rate_changes);
    for (f, w) in seg.rate_changes.iter().zip(&steps) {
        assert!(f.abs_diff(*w) <= 2, "{f} vs {w}");
    }
    // a factor below rate_ratio is not a step
    let opts = SegmentOptions {
        rate_ratio: 4.0,
        ..SegmentOptions::default()
    };
    let seg4 = segment(
        &data(
            ControlColumn::Slip,
            seg.conditioned
                .values
                .iter()
                .enumerate()
                .map(|(i, _)| i as f64 * 0.5)
                .collect(),
            seg.conditioned.values.clone(),
        ),
        &opts,
    );
    assert!(seg4.rate_changes.is_empty(), "{:?}", seg4.rate_changes);
}
