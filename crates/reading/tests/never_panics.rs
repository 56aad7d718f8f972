//! The loader, the importer, conditioning and segmentation never panic, whatever the input.

use proptest::prelude::*;
use subfric_data::set::parse_test;
use subfric_data::{
    import, load_set, parse_meta, ControlColumn, ImportSpec, StressUnit, TestData, TestSpec,
};
use subfric_reading::{condition_imposed, segment, SegmentOptions};

const VALID_CSV: &str = "# comment\ntime_s,slip_mm,shear_kpa,normal_kpa\n0,0,0,100\n0.5,0.005,20.5,100\n1.0,0.010,30.25,101\n1.5,0.0149,35,99\n2.0,0.0201,36.5,100\n";

const VALID_JSON: &str = r#"{
  "name": "s", "title": "t", "source": "src", "provenance": "p",
  "interface": {"soil": "sand", "surface": "steel", "roughness_rmax_um": 1.5},
  "tests": [{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}],
  "reference_parameters": {"mu_s": 0.5}
}"#;

/// Applies byte edits (replace, insert, delete) to a text.
fn mutate(base: &str, edits: &[(usize, u8, u8)]) -> Vec<u8> {
    let mut b = base.as_bytes().to_vec();
    for &(pos, op, byte) in edits {
        if b.is_empty() {
            b.push(byte);
            continue;
        }
        let p = pos % b.len();
        match op % 3 {
            0 => b[p] = byte,
            1 => b.insert(p, byte),
            _ => {
                b.remove(p);
            }
        }
    }
    b
}

/// Checks the invariants of a loaded test.
fn check_invariants(t: &TestData) {
    let n = t.len();
    assert!(n > 0);
    assert_eq!(t.slip_mm.len(), n);
    assert_eq!(t.shear_kpa.len(), n);
    assert_eq!(t.normal_kpa.len(), n);
    assert_eq!(t.line_of_row.len(), n);
    assert!(t.time_s.windows(2).all(|w| w[1] > w[0]));
    assert!(t
        .time_s
        .iter()
        .chain(&t.slip_mm)
        .chain(&t.shear_kpa)
        .all(|x| x.is_finite()));
    assert!(t.normal_kpa.iter().all(|x| *x > 0.0 && x.is_finite()));
    let seg = segment(t, &SegmentOptions::default());
    assert_eq!(seg.row_kind.len(), n);
    assert_eq!(seg.segments.last().map(|s| s.end), Some(n));
}

fn spec() -> TestSpec {
    TestSpec::new("a", "a.csv", ControlColumn::Slip, 100.0)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn csv_of_arbitrary_text(text in "\\PC{0,300}") {
        if let Ok(t) = parse_test(&text, "a.csv".as_ref(), &spec()) {
            check_invariants(&t);
        }
    }

    #[test]
    fn csv_of_csv_like_text(text in "(#[a-z ]{0,5}\n)?(time_s|slip_mm|shear_kpa|friction|normal_kpa|x)(,(time_s|slip_mm|shear_kpa|friction|normal_kpa|x)){0,4}\n([-0-9.eNaif ]{0,6}(,[-0-9.eNaif ]{0,6}){0,4}\n){0,8}") {
        if let Ok(t) = parse_test(&text, "a.csv".as_ref(), &spec()) {
            check_invariants(&t);
        }
    }

    #[test]
    fn csv_with_mutated_bytes(edits in prop::collection::vec((0usize..1000, 0u8..3, any::<u8>()), 0..12)) {
        let bytes = mutate(VALID_CSV, &edits);
        let text = String::from_utf8_lossy(&bytes);
        if let Ok(t) = parse_test(&text, "a.csv".as_ref(), &spec()) {
            check_invariants(&t);
        }
    }

    #[test]
    fn json_with_mutated_bytes(edits in prop::collection::vec((0usize..1000, 0u8..3, any::<u8>()), 0..8)) {
        let bytes = mutate(VALID_JSON, &edits);
        let text = String::from_utf8_lossy(&bytes);
        let _ = parse_meta(&text, "experiment.json".as_ref());
    }

    #[test]
    fn json_of_arbitrary_text(text in "\\PC{0,200}") {
        let _ = parse_meta(&text, "experiment.json".as_ref());
    }

    #[test]
    fn segment_of_arbitrary_numbers(
        ys in prop::collection::vec(prop_oneof![-1e6f64..1e6, Just(0.0), Just(1.0), Just(f64::NAN), Just(f64::INFINITY)], 0..80),
        dts in prop::collection::vec(prop_oneof![1e-6f64..100.0, Just(0.0), Just(-1.0)], 80),
        shear in any::<bool>(),
    ) {
        let n = ys.len();
        let mut t = Vec::with_capacity(n);
        let mut acc = 0.0;
        for dt in dts.iter().take(n) {
            t.push(acc);
            acc += dt;
        }
        let control = if shear { ControlColumn::Shear } else { ControlColumn::Slip };
        let d = TestData {
            spec: TestSpec::new("x", "x.csv", control, 100.0),
            path: "x.csv".into(),
            time_s: t,
            slip_mm: ys.clone(),
            shear_kpa: ys.iter().map(|y| y * 2.0).collect(),
            normal_kpa: vec![100.0; n],
            friction_given: false,
            line_of_row: (2..n + 2).collect(),
            comments: vec![],
            reading_notes: Vec::new(),
            channels: Vec::new(),
        };
        let c = condition_imposed(&d);
        prop_assert_eq!(c.values.len(), n);
        let s = segment(&d, &SegmentOptions::default());
        prop_assert_eq!(s.row_kind.len(), n);
        prop_assert_eq!(s.cycle_of_row.len(), n);
        let _ = subfric_reading::summary::summarize_test(&d, &SegmentOptions::default()).to_owned();
    }

    #[test]
    fn segment_of_noisy_valid_signals(
        steps in prop::collection::vec((-0.02f64..0.02, 0.01f64..5.0), 3..300),
        noise in prop::collection::vec(-0.001f64..0.001, 300),
    ) {
        let mut t = vec![0.0];
        let mut y = vec![0.0];
        for (k, (dy, dt)) in steps.iter().enumerate() {
            t.push(t[k] + dt);
            y.push(y[k] + dy);
        }
        let n = t.len();
        let ys: Vec<f64> = y.iter().zip(&noise).map(|(a, b)| a + b).collect();
        let d = TestData {
            spec: TestSpec::new("x", "x.csv", ControlColumn::Slip, 100.0),
            path: "x.csv".into(),
            time_s: t,
            slip_mm: ys,
            shear_kpa: vec![1.0; n],
            normal_kpa: vec![100.0; n],
            friction_given: false,
            line_of_row: (2..n + 2).collect(),
            comments: vec![],
            reading_notes: Vec::new(),
            channels: Vec::new(),
        };
        let s = segment(&d, &SegmentOptions::default());
        // covering segments, monotone conditioned runs
        let mut next = 0;
        for sg in &s.segments {
            prop_assert_eq!(sg.start, next);
            prop_assert!(sg.end > sg.start);
            next = sg.end;
        }
        prop_assert_eq!(next, n);
        let mut bounds = vec![0];
        bounds.extend(&s.reversals);
        bounds.push(n - 1);
        for w in bounds.windows(2) {
            prop_assert!(w[0] < w[1] || n == 1);
            let run = &s.conditioned.values[w[0]..=w[1]];
            let up = run[run.len() - 1] >= run[0];
            for p in run.windows(2) {
                let ok = if up { p[1] >= p[0] } else { p[1] <= p[0] };
                prop_assert!(ok, "spurious reversal");
            }
        }
        for &(a, b) in &s.holds {
            prop_assert!(a >= 1 && a < b && b <= n);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(60))]

    #[test]
    fn load_set_and_import_of_mutated_files(
        csv_edits in prop::collection::vec((0usize..1000, 0u8..3, any::<u8>()), 0..10),
        json_edits in prop::collection::vec((0usize..1000, 0u8..3, any::<u8>()), 0..3),
    ) {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("experiment.json"), mutate(VALID_JSON, &json_edits)).unwrap();
        std::fs::write(dir.path().join("a.csv"), mutate(VALID_CSV, &csv_edits)).unwrap();
        if let Ok(set) = load_set(dir.path()) {
            for t in &set.tests {
                check_invariants(t);
            }
            let _ = subfric_reading::summary(&set).to_string();
        }
        let lab = dir.path().join("a.csv");
        let spec = ImportSpec {
            shear: Some(("shear_kpa".into(), StressUnit::KPa)),
            normal_stress_kpa: Some(100.0),
            ..ImportSpec::default()
        };
        if let Ok(set) = import(&lab, &spec, &dir.path().join("out")) {
            for t in &set.tests {
                check_invariants(t);
            }
        }
    }
}
