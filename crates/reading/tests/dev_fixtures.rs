//! Segmentation and conditioning on a lab-style set (noise on both columns): a copy of
//! `withheld-dev/pair-01` (without its truth file), the golden data in `tests/golden/pair-01`.

use std::path::PathBuf;

use subfric_data::load_set;
use subfric_reading::{condition_imposed, segment, summary, SegmentKind, SegmentOptions};

fn fixture() -> subfric_data::ExperimentSet {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/golden/pair-01");
    load_set(&dir).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn loads_four_tests() {
    let set = fixture();
    let rows: Vec<usize> = set.tests.iter().map(|t| t.len()).collect();
    assert_eq!(rows, vec![1101, 1181, 3401, 801]);
    assert_eq!(set.tests[2].normal_kpa[0], 200.0);
    assert!(set
        .meta
        .provenance
        .as_deref()
        .is_some_and(|p| p.contains("withheld-dev/pair-01")));
}

#[test]
fn velocity_steps_found_at_the_rate_changes() {
    let set = fixture();
    let t = set.test("velocity-steps").unwrap();
    let seg = segment(t, &SegmentOptions::default());
    let times: Vec<f64> = seg.rate_changes.iter().map(|&r| t.time_s[r]).collect();
    // rates 0.01 → 0.1 → 0.01 → 0.001 → 0.01 mm/s; in this file the steps are at 200, 210, 310
    // and 810 s (the row spacing changes with the rate there too)
    assert_eq!(
        times,
        vec![200.0, 210.0, 310.0, 810.0],
        "{:?}",
        seg.rate_changes
    );
    let expected = [(0.01, 0.1), (0.1, 0.01), (0.01, 0.001), (0.001, 0.01)];
    for ((a, b), (ea, eb)) in seg.step_rates().into_iter().zip(expected) {
        assert!(
            (a / ea - 1.0).abs() < 0.02 && (b / eb - 1.0).abs() < 0.02,
            "{a} {b}"
        );
    }
    assert!(seg.holds.is_empty() && seg.reversals.is_empty());
    assert_eq!(seg.cycles(), 0);
    // the row after each step starts an after-velocity-step segment
    for &r in &seg.rate_changes {
        assert_eq!(seg.row_kind[r + 1], SegmentKind::AfterVelocityStep);
    }
    assert_eq!(seg.row_kind[1], SegmentKind::InitialLoading);
    assert_eq!(seg.row_kind[300], SegmentKind::SteadySliding);
}

#[test]
fn slide_hold_slide_holds_are_found_and_flat() {
    let set = fixture();
    let t = set.test("slide-hold-slide").unwrap();
    let seg = segment(t, &SegmentOptions::default());
    let durations = seg.hold_durations(t);
    assert_eq!(seg.holds.len(), 3, "{:?}", seg.holds);
    for (d, e) in durations.iter().zip([30.0, 300.0, 3000.0]) {
        assert!((d - e).abs() < 1e-9, "{durations:?}");
    }
    let starts: Vec<f64> = seg.holds.iter().map(|h| t.time_s[h.0 - 1]).collect();
    assert_eq!(starts, vec![200.0, 330.0, 730.0]);
    assert!(
        seg.reversals.is_empty(),
        "jitter is not a reversal: {:?}",
        seg.reversals
    );
    assert!(seg.rate_changes.is_empty(), "{:?}", seg.rate_changes);
    for &(s, e) in &seg.holds {
        assert!(seg.row_kind[s..e].iter().all(|k| *k == SegmentKind::Hold));
        assert_eq!(seg.row_kind[e], SegmentKind::AfterHold);
    }
    // conditioning: no backward step anywhere, holds exactly flat
    let c = condition_imposed(t);
    assert!(c.changed);
    assert!(c.noise_sd > 1e-4 && c.noise_sd < 4e-4, "{}", c.noise_sd);
    assert!(c.values.windows(2).all(|w| w[1] >= w[0]));
    for &(s, e) in &seg.holds {
        let v = &c.values[s - 1..e];
        assert!(v.iter().all(|x| *x == v[0]), "hold not flat");
    }
    // the raw column does go backwards during the holds
    assert!(t.slip_mm.windows(2).any(|w| w[1] < w[0]));
    // sliding parts are barely touched
    let max_change = c
        .values
        .iter()
        .zip(&t.slip_mm)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(max_change < 0.002, "{max_change}");
}

#[test]
fn two_way_cyclic_reversals_and_cycles() {
    let set = fixture();
    let t = set.test("two-way-cyclic").unwrap();
    let seg = segment(t, &SegmentOptions::default());
    let times: Vec<f64> = seg.reversals.iter().map(|&r| t.time_s[r]).collect();
    assert_eq!(times.len(), 8, "{times:?}");
    for (k, &tr) in times.iter().enumerate() {
        let expect = 100.0 + 200.0 * k as f64;
        assert!(
            (tr - expect).abs() <= 1.0,
            "reversal {k} at {tr}, expected {expect}"
        );
    }
    assert_eq!(seg.cycles(), 4);
    assert_eq!(seg.cycle_of_row[0], 0);
    assert_eq!(seg.cycle_of_row[*seg.reversals.first().unwrap()], 0);
    assert_eq!(seg.cycle_of_row[seg.reversals[0] + 1], 1);
    assert_eq!(seg.cycle_of_row[seg.reversals[2] + 1], 2);
    assert_eq!(*seg.cycle_of_row.last().unwrap(), 4);
    assert!(seg.holds.is_empty() && seg.rate_changes.is_empty());
    for &r in &seg.reversals {
        assert_eq!(seg.row_kind[r + 1], SegmentKind::AfterReversal);
    }
    // no spurious reversal remains in the conditioned column
    let c = &seg.conditioned;
    let mut bounds = vec![0];
    bounds.extend(&seg.reversals);
    bounds.push(t.len() - 1);
    for w in bounds.windows(2) {
        let run = &c.values[w[0]..=w[1]];
        let up = run[run.len() - 1] > run[0];
        assert!(run
            .windows(2)
            .all(|p| if up { p[1] >= p[0] } else { p[1] <= p[0] }));
    }
}

#[test]
fn monotonic_has_nothing_but_sliding() {
    let set = fixture();
    let t = set.test("monotonic-400kPa").unwrap();
    let seg = segment(t, &SegmentOptions::default());
    assert!(seg.holds.is_empty() && seg.reversals.is_empty() && seg.rate_changes.is_empty());
    let kinds: Vec<SegmentKind> = seg.segments.iter().map(|s| s.kind).collect();
    assert_eq!(
        kinds,
        vec![SegmentKind::InitialLoading, SegmentKind::SteadySliding]
    );
    assert!((seg.segments[1].rate - 0.01).abs() < 1e-4);
}

#[test]
fn summary_table_mentions_everything() {
    let s = summary(&fixture());
    let text = s.to_string();
    for needle in [
        "velocity-steps",
        "slide-hold-slide",
        "two-way-cyclic",
        "3000 s at t=730",
        "at t=810",
    ] {
        assert!(text.contains(needle), "{needle} missing in\n{text}");
    }
    let shs = &s.tests[1];
    assert_eq!(shs.holds.len(), 3);
    assert!(shs.imposed_conditioned);
    assert_eq!(s.tests[0].velocity_steps.len(), 4);
    assert_eq!(s.tests[0].sliding_rates.len(), 3);
    assert_eq!((s.tests[2].reversals, s.tests[2].cycles), (8, 4));
    let json = serde_json::to_value(&s).unwrap();
    assert_eq!(json["tests"][2]["cycles"], 4);
}
