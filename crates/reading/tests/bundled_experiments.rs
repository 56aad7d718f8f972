//! Every set bundled under the workspace's `experiments/` folder loads and segments as
//! expected.

use std::path::PathBuf;

use subfric_data::{load_set, ControlColumn, ExperimentSet};
use subfric_reading::{segment, SegmentKind, SegmentOptions};

fn experiments_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../experiments")
}

fn load(name: &str) -> ExperimentSet {
    load_set(&experiments_dir().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn every_bundled_set_loads() {
    let mut names: Vec<String> = std::fs::read_dir(experiments_dir())
        .expect("experiments/ folder")
        .filter_map(|e| e.ok())
        .filter(|e| e.path().join("experiment.json").is_file())
        .map(|e| e.file_name().to_string_lossy().to_string())
        .collect();
    names.sort();
    let expected = [
        ("table1-medium", "monotonic", 481, ControlColumn::Slip),
        ("table1-rough", "monotonic", 481, ControlColumn::Slip),
        ("table1-smooth", "monotonic", 481, ControlColumn::Slip),
        (
            "table2-ring-torsion",
            "monotonic",
            1151,
            ControlColumn::Slip,
        ),
        ("table3-pulsating", "pulsating", 2401, ControlColumn::Shear),
        (
            "table4-two-way",
            "two-way-cyclic",
            3151,
            ControlColumn::Slip,
        ),
    ];
    assert_eq!(
        names,
        expected.iter().map(|e| e.0.to_string()).collect::<Vec<_>>()
    );
    for (set_name, test, rows, control) in expected {
        let set = load(set_name);
        assert_eq!(set.meta.name, set_name);
        assert_eq!(set.tests.len(), 1);
        let t = &set.tests[0];
        assert_eq!(t.spec.name, test);
        assert_eq!(t.len(), rows, "{set_name}");
        assert_eq!(t.spec.control, control);
        assert!(!t.friction_given && !t.normal_varies());
        // provenance text is kept, in experiment.json and as CSV comments
        let prov = set.meta.provenance.as_deref().unwrap_or("");
        assert!(prov.contains("NOT the original measurements"), "{set_name}");
        assert_eq!(
            t.comments,
            vec![
                "reconstructed curve (reference model + noise), not an original measurement"
                    .to_string()
            ]
        );
        assert!(set.meta.reference_parameters.is_some());
        assert_eq!(t.line_of_row[0], 3);
        // clean imposed column: conditioning leaves it alone
        let seg = segment(t, &SegmentOptions::default());
        assert!(!seg.conditioned.changed, "{set_name}");
        assert!(
            seg.holds.is_empty() && seg.rate_changes.is_empty(),
            "{set_name}"
        );
    }
}

#[test]
fn table3_is_shear_controlled_pulsating() {
    let set = load("table3-pulsating");
    let t = &set.tests[0];
    assert_eq!(t.spec.control, ControlColumn::Shear);
    assert_eq!(t.imposed(), &t.shear_kpa[..]);
    assert_eq!(t.spec.normal_stress_kpa, 98.0);
    let seg = segment(t, &SegmentOptions::default());
    // 20 pulses 0 → 49 kPa → 0: 20 peaks and 19 valleys in between
    assert_eq!(seg.reversals.len(), 39);
    assert_eq!(seg.cycles(), 20);
    for (k, &r) in seg.reversals.iter().enumerate() {
        assert_eq!(r, 60 * (k + 1), "reversal {k}");
    }
    assert_eq!(seg.row_kind[30], SegmentKind::InitialLoading);
    assert_eq!(seg.row_kind[90], SegmentKind::Unloading);
    assert_eq!(seg.row_kind[150], SegmentKind::AfterReversal);
    assert_eq!(seg.cycle_of_row[60], 0);
    assert_eq!(seg.cycle_of_row[61], 1);
    assert_eq!(seg.cycle_of_row[180], 1);
    assert_eq!(seg.cycle_of_row[181], 2);
    assert_eq!(*seg.cycle_of_row.last().unwrap(), 20);
    let unloading = seg.of_kind(SegmentKind::Unloading).count();
    assert_eq!(unloading, 20);
    assert!(seg
        .of_kind(SegmentKind::Unloading)
        .all(|s| (s.rate + 1.6333).abs() < 0.01));
}

#[test]
fn table4_two_way_reversals() {
    let set = load("table4-two-way");
    let t = &set.tests[0];
    let seg = segment(t, &SegmentOptions::default());
    let expected: Vec<usize> = (0..10).map(|k| 150 + 300 * k).collect();
    assert_eq!(seg.reversals, expected);
    for &r in &seg.reversals {
        assert!((t.slip_mm[r].abs() - 1.5).abs() < 1e-12);
    }
    assert_eq!(seg.cycles(), 5);
    let kinds: Vec<SegmentKind> = seg.segments.iter().take(4).map(|s| s.kind).collect();
    assert_eq!(
        kinds,
        vec![
            SegmentKind::InitialLoading,
            SegmentKind::SteadySliding,
            SegmentKind::AfterReversal,
            SegmentKind::SteadySliding
        ]
    );
    assert!((seg.segments[1].rate - 0.02).abs() < 1e-9);
    assert!((seg.segments[3].rate + 0.02).abs() < 1e-9);
}

#[test]
fn rate_changes_of_sampling_are_not_velocity_steps() {
    // table1/table2 change the row spacing (0.06 → 0.6 s) at constant rate
    for name in ["table1-smooth", "table2-ring-torsion"] {
        let set = load(name);
        let seg = segment(&set.tests[0], &SegmentOptions::default());
        assert!(seg.rate_changes.is_empty(), "{name}");
        assert_eq!(seg.levels.len(), 1);
    }
}
