//! Segmentation of records made like real laboratory files: a clock that jitters, a sampling
//! rate that follows the sliding rate (10 Hz to 1 kHz), displacement quantised at 0.1 µm with
//! sensor noise, files that start mid-run. The records are generated here with known steps and
//! holds, and the segmentation must give back exactly those.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use subfric_data::{ControlColumn, TestData, TestSpec};
use subfric_reading::{segment, SegmentOptions, StartKind};

/// One stage of a generated protocol: slide at `rate` mm/s over `distance` mm, or hold.
#[derive(Clone, Copy, Debug)]
enum LabStage {
    Slide { rate: f64, distance: f64 },
    Hold { seconds: f64 },
}

/// What the record was built with: the times of the velocity steps and of the holds.
struct Built {
    test: TestData,
    step_times: Vec<f64>,
    holds: Vec<(f64, f64)>,
}

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// Sampling rate of the logger for a sliding rate (as in the Penn State records): 10 Hz up to
/// 3 µm/s, 100 Hz up to 30 µm/s, 1 kHz above; 2 Hz in holds.
fn sampling_hz(rate: f64) -> f64 {
    match rate {
        r if r <= 0.0 => 2.0,
        r if r <= 0.0035 => 10.0,
        r if r <= 0.035 => 100.0,
        _ => 1000.0,
    }
}

/// Generates a record: the true load-point path through the stages, sampled by a jittering
/// adaptive clock, read with noise and quantisation; friction that follows the rate (so the
/// start is a loaded, sliding interface).
fn generate(stages: &[LabStage], seed: u64, start_offset_mm: f64) -> Built {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let quantum = 1e-4; // 0.1 µm
    let noise = 3e-5; // 0.03 µm
    let (mut t, mut u) = (Vec::new(), Vec::new());
    let mut step_times = Vec::new();
    let mut holds = Vec::new();
    let (mut t0, mut u0) = (0.0, start_offset_mm);
    let mut last_rate: Option<f64> = None;
    for st in stages {
        let (duration, rate) = match *st {
            LabStage::Slide { rate, distance } => (distance / rate, rate),
            LabStage::Hold { seconds } => (seconds, 0.0),
        };
        if let (Some(prev), LabStage::Slide { .. }) = (last_rate, st) {
            if prev > 0.0 && (rate / prev - 1.0).abs() > 0.01 {
                step_times.push(t0);
            }
        }
        if let LabStage::Hold { seconds } = st {
            holds.push((t0, *seconds));
        }
        let dt = 1.0 / sampling_hz(rate);
        let mut k = 0.0;
        while k * dt < duration - 1e-9 {
            // Jitter of ±30 % of the sampling interval, never reordering the rows.
            let tj = t0 + (k + 0.3 * (rng.gen::<f64>() - 0.5)) * dt;
            if t.last().is_none_or(|&l| tj > l) {
                t.push(tj);
                u.push(u0 + rate * (tj - t0));
            }
            k += 1.0;
        }
        t0 += duration;
        u0 += rate * duration;
        last_rate = Some(rate);
    }
    t.push(t0);
    u.push(u0);
    let n = t.len();
    let slip: Vec<f64> = u
        .iter()
        .map(|x| ((x + noise * gauss(&mut rng)) / quantum).round() * quantum)
        .collect();
    // Friction 0.6 while sliding (a segment of a longer run), relaxing in holds.
    let shear: Vec<f64> = (0..n).map(|_| 6000.0 + 5.0 * gauss(&mut rng)).collect();
    let test = TestData {
        spec: TestSpec::new("lab", "lab.csv", ControlColumn::Slip, 10_000.0),
        path: "lab.csv".into(),
        time_s: t,
        slip_mm: slip,
        shear_kpa: shear,
        normal_kpa: vec![10_000.0; n],
        friction_given: false,
        line_of_row: (2..n + 2).collect(),
        comments: vec![],
        reading_notes: Vec::new(),
        channels: Vec::new(),
    };
    Built {
        test,
        step_times,
        holds,
    }
}

fn ladder() -> Vec<LabStage> {
    let um = 1e-3;
    let mut v = vec![LabStage::Slide {
        rate: 10.0 * um,
        distance: 0.6,
    }];
    v.push(LabStage::Hold { seconds: 200.0 });
    for r in [
        1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 100.0, 30.0, 10.0, 3.0, 1.0,
    ] {
        v.push(LabStage::Slide {
            rate: r * um,
            distance: 0.4,
        });
    }
    v.push(LabStage::Hold { seconds: 30.0 });
    v.push(LabStage::Slide {
        rate: 10.0 * um,
        distance: 0.3,
    });
    v
}

fn check(built: &Built) {
    let test = &built.test;
    let seg = segment(test, &SegmentOptions::default());
    let found: Vec<f64> = seg.rate_changes.iter().map(|&r| test.time_s[r]).collect();
    assert_eq!(
        found.len(),
        built.step_times.len(),
        "steps found at {found:?}, built at {:?}",
        built.step_times
    );
    for (f, b) in found.iter().zip(&built.step_times) {
        // Within the time the slower side needs to move 3 µm.
        assert!((f - b).abs() < 3.0, "step found at {f} s, built at {b} s");
    }
    let holds: Vec<(f64, f64)> = seg
        .holds
        .iter()
        .zip(seg.hold_durations(test))
        .map(|(h, d)| (test.time_s[h.0 - 1], d))
        .collect();
    assert_eq!(
        holds.len(),
        built.holds.len(),
        "holds found {holds:?}, built {:?}",
        built.holds
    );
    for ((fs, fd), (bs, bd)) in holds.iter().zip(&built.holds) {
        assert!(
            (fs - bs).abs() < 2.0,
            "hold found at {fs} s, built at {bs} s"
        );
        assert!(
            (fd - bd).abs() < 0.05 * bd + 2.0,
            "hold of {fd} s, built {bd} s"
        );
    }
    assert!(seg.reversals.is_empty(), "{:?}", seg.reversals);
    assert!(
        seg.conditioned.noise.quantum > 0.9e-4 && seg.conditioned.noise.quantum < 1.1e-4,
        "{:?}",
        seg.conditioned.noise
    );
}

#[test]
fn jittered_adaptive_quantised_ladder_gives_back_its_steps_and_holds() {
    for seed in [1, 2, 3] {
        check(&generate(&ladder(), seed, 0.0));
    }
}

#[test]
fn a_record_cut_out_of_a_run_starts_sliding() {
    // Starts at 7.3 mm of load-point displacement, at 10 µm/s, friction 0.6.
    let built = generate(&ladder(), 9, 7.3);
    check(&built);
    let seg = segment(&built.test, &SegmentOptions::default());
    assert_eq!(seg.start.kind, StartKind::Sliding, "{}", seg.start.reason);
    assert!((seg.start.rate - 0.01).abs() < 0.001, "{:?}", seg.start);
    assert!(
        (seg.start.shear_kpa - 6000.0).abs() < 20.0,
        "{:?}",
        seg.start
    );
}

#[test]
fn a_record_that_starts_in_a_hold_under_load_starts_loaded() {
    let mut stages = vec![LabStage::Hold { seconds: 60.0 }];
    stages.extend(ladder());
    let built = generate(&stages, 4, 2.0);
    let seg = segment(&built.test, &SegmentOptions::default());
    assert_eq!(seg.start.kind, StartKind::Loaded, "{}", seg.start.reason);
    assert!(seg.holds[0].0 <= 1);
}

#[test]
fn the_initial_field_overrides_the_decision() {
    let mut built = generate(&ladder(), 5, 7.3);
    built.test.spec.initial = Some(subfric_data::InitialSpec::Rest);
    let seg = segment(&built.test, &SegmentOptions::default());
    assert_eq!(seg.start.kind, StartKind::Rest);
    assert!(seg.start.from_spec);
}

#[test]
fn a_stiff_curve_printed_to_five_decimals_starts_at_rest() {
    // The shear jumps within the first row (a stiff contact) and the slip column, printed to
    // 1e-5 mm, looks like a grid: the start is still the first row's traction, zero.
    let n = 400;
    let time: Vec<f64> = (0..n).map(|i| i as f64 * 0.06).collect();
    let slip: Vec<f64> = (0..n)
        .map(|i| ((i as f64 / 60.0 * 0.06) * 1e5).round() / 1e5)
        .collect();
    let shear: Vec<f64> = (0..n)
        .map(|i| {
            if i == 0 {
                -0.02
            } else {
                28.6 + 0.01 * i as f64
            }
        })
        .collect();
    let test = TestData {
        spec: TestSpec::new("mono", "mono.csv", ControlColumn::Slip, 78.4),
        path: "mono.csv".into(),
        time_s: time,
        slip_mm: slip,
        shear_kpa: shear,
        normal_kpa: vec![78.4; n],
        friction_given: false,
        line_of_row: (2..n + 2).collect(),
        comments: vec![],
        reading_notes: Vec::new(),
        channels: Vec::new(),
    };
    let seg = segment(&test, &SegmentOptions::default());
    assert_eq!(seg.start.kind, StartKind::Rest, "{}", seg.start.reason);
}
