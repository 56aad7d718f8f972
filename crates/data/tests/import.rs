//! Import of lab files: delimiters, units, friction, appending to a set, and round trips.

use std::path::Path;

use subfric_data::{
    import, load_set, write_set, ColumnRef, ControlColumn, DataError, Delimiter, ImportSpec,
    LengthUnit, StressUnit, TimeUnit,
};

fn close(a: &[f64], b: &[f64]) {
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert!((x - y).abs() <= 1e-9 * (1.0 + y.abs()), "{a:?} vs {b:?}");
    }
}

const TAB_FILE: &str = "Lab X direct shear export\r\nOperator: nobody\r\nTime (min)\tDisplacement (µm)\tShear (MPa)\tComment\r\n0\t0\t0\tstart\r\n0.5\t150\t0.012\t\r\n1.0\t300\t0.0305\tx\r\n1,5\t450\t0,0402\t\r\n";

fn tab_spec() -> ImportSpec {
    ImportSpec {
        delimiter: Delimiter::Tab,
        skip_lines: 2,
        has_header: true,
        time: "Time (min)".parse().unwrap(),
        time_unit: TimeUnit::Min,
        slip: "displacement (µm)".parse().unwrap(),
        slip_unit: LengthUnit::Um,
        shear: Some(("3".parse().unwrap(), StressUnit::MPa)),
        friction: None,
        normal: None,
        normal_stress_kpa: Some(100.0),
        area_mm2: None,
        control: ControlColumn::Slip,
        test_name: "monotonic 100 kPa".into(),
        set_name: "lab-x".into(),
        title: Some("Lab X: sand on steel".into()),
        soil: Some("silica sand".into()),
        surface: Some("mild steel".into()),
        source: None,
        keep: None,
        ..ImportSpec::default()
    }
}

#[test]
fn tab_file_in_micrometres_megapascals_minutes() {
    let dir = tempfile::tempdir().unwrap();
    let lab = dir.path().join("export.txt");
    std::fs::write(&lab, TAB_FILE).unwrap();
    let out = dir.path().join("lab-x");
    let set = import(&lab, &tab_spec(), &out).unwrap_or_else(|e| panic!("{e}"));
    // the returned set is the one loaded back from disk
    assert_eq!(set, load_set(&out).unwrap());
    let t = &set.tests[0];
    assert_eq!(t.spec.name, "monotonic 100 kPa");
    assert_eq!(t.spec.file, "monotonic-100-kPa.csv");
    assert_eq!(t.spec.control, ControlColumn::Slip);
    close(&t.time_s, &[0.0, 30.0, 60.0, 90.0]);
    close(&t.slip_mm, &[0.0, 0.15, 0.3, 0.45]);
    close(&t.shear_kpa, &[0.0, 12.0, 30.5, 40.2]);
    close(&t.normal_kpa, &[100.0; 4]);
    assert!(!t.normal_varies());
    assert!(t.comments.iter().any(|c| c.contains("export.txt")));
    assert_eq!(set.meta.title, "Lab X: sand on steel");
    assert_eq!(set.meta.interface.soil.as_deref(), Some("silica sand"));
    assert!(set
        .meta
        .provenance
        .as_deref()
        .unwrap()
        .contains("export.txt"));
    assert!(out.join("experiment.json").is_file());
}

#[test]
fn whitespace_file_with_friction_and_normal_columns() {
    let dir = tempfile::tempdir().unwrap();
    let lab = dir.path().join("ring.dat");
    std::fs::write(
        &lab,
        "# ring shear, normal stress ramps\n t   u     mu    sn\n 0   0.0   0.00  100\n 2   0.01  0.30  100\n 4   0.02  0.35  150\n 6   0.03  0.36  200\n",
    )
    .unwrap();
    let spec = ImportSpec {
        delimiter: Delimiter::Auto,
        time: ColumnRef::Name("t".into()),
        slip: ColumnRef::Name("u".into()),
        shear: None,
        friction: Some(ColumnRef::Name("mu".into())),
        normal: Some((ColumnRef::Index(4), StressUnit::KPa)),
        test_name: "ring".into(),
        set_name: "ring-set".into(),
        ..ImportSpec::default()
    };
    let out = dir.path().join("ring-set");
    let set = import(&lab, &spec, &out).unwrap_or_else(|e| panic!("{e}"));
    let t = &set.tests[0];
    close(&t.shear_kpa, &[0.0, 30.0, 52.5, 72.0]);
    close(&t.normal_kpa, &[100.0, 100.0, 150.0, 200.0]);
    assert!(t.normal_varies());
    // written with a normal_kpa column; spec takes the median normal stress
    let text = std::fs::read_to_string(out.join("ring.csv")).unwrap();
    assert!(
        text.contains("time_s,slip_mm,shear_kpa,normal_kpa"),
        "{text}"
    );
    assert!(text.starts_with("# ring shear, normal stress ramps\n"));
    assert_eq!(t.spec.normal_stress_kpa, 150.0);
    close(&t.friction(), &[0.0, 0.3, 0.35, 0.36]);
}

#[test]
fn headerless_file_by_index_and_semicolon_decimal_comma() {
    let dir = tempfile::tempdir().unwrap();
    let lab = dir.path().join("creep.csv");
    std::fs::write(&lab, "0;0,000;0\n1000;0,001;10\n2000;0,003;20\n").unwrap();
    let spec = ImportSpec {
        has_header: false,
        time: ColumnRef::Index(1),
        time_unit: TimeUnit::Ms,
        slip: ColumnRef::Index(2),
        slip_unit: LengthUnit::M,
        shear: Some((ColumnRef::Index(3), StressUnit::Pa)),
        normal_stress_kpa: Some(50.0),
        control: ControlColumn::Shear,
        test_name: "creep".into(),
        ..ImportSpec::default()
    };
    let set = import(&lab, &spec, &dir.path().join("out")).unwrap_or_else(|e| panic!("{e}"));
    let t = &set.tests[0];
    assert_eq!(t.spec.control, ControlColumn::Shear);
    close(&t.time_s, &[0.0, 1.0, 2.0]);
    close(&t.slip_mm, &[0.0, 1.0, 3.0]);
    close(&t.shear_kpa, &[0.0, 0.01, 0.02]);
}

#[test]
fn appends_to_an_existing_set_and_refuses_duplicates() {
    let dir = tempfile::tempdir().unwrap();
    let lab = dir.path().join("export.txt");
    std::fs::write(&lab, TAB_FILE).unwrap();
    let out = dir.path().join("lab-x");
    import(&lab, &tab_spec(), &out).unwrap();
    let first_csv = std::fs::read_to_string(out.join("monotonic-100-kPa.csv")).unwrap();
    let mut second = tab_spec();
    second.test_name = "repeat".into();
    second.normal_stress_kpa = Some(200.0);
    second.set_name = "ignored-when-appending".into();
    let set = import(&lab, &second, &out).unwrap();
    assert_eq!(set.tests.len(), 2);
    assert_eq!(set.meta.name, "lab-x");
    assert_eq!(set.tests[1].spec.normal_stress_kpa, 200.0);
    assert_eq!(
        std::fs::read_to_string(out.join("monotonic-100-kPa.csv")).unwrap(),
        first_csv
    );
    // the same name again is refused, nothing is written
    let e = import(&lab, &second, &out).unwrap_err();
    assert!(
        e.to_string().contains("already has a test named `repeat`"),
        "{e}"
    );
    assert_eq!(load_set(&out).unwrap().tests.len(), 2);
}

#[test]
fn lab_file_problems_name_the_lab_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let lab = dir.path().join("bad.txt");
    std::fs::write(&lab, "t,u,tau\n0,0,0\n1,zero,1\n1,0.2,2\n3,0.3\n").unwrap();
    let spec = ImportSpec {
        time: "t".into(),
        slip: "u".into(),
        shear: Some(("tau".into(), StressUnit::KPa)),
        normal_stress_kpa: Some(100.0),
        ..ImportSpec::default()
    };
    let e = import(&lab, &spec, &dir.path().join("out")).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("bad.txt:3: field `u`: `zero` is not a number"),
        "{text}"
    );
    assert!(
        text.contains("bad.txt:5: field `tau`: row has 2 cells"),
        "{text}"
    );
    assert!(!dir.path().join("out").exists(), "nothing written on error");
    // time problems are checked like load_set does, with the lab file's lines
    std::fs::write(&lab, "t,u,tau\n0,0,0\n1,0.1,1\n1,0.2,2\n0.5,0.3,3\n").unwrap();
    let e = import(&lab, &spec, &dir.path().join("out")).unwrap_err();
    assert!(
        e.to_string()
            .contains("bad.txt:4: field `time_s`: time 1 is not after time 1 on line 3"),
        "{e}"
    );
    assert!(
        e.to_string()
            .contains("bad.txt:5: field `time_s`: time 0.5 is not after time 1 on line 4"),
        "{e}"
    );
    // unknown column and missing normal stress
    let spec2 = ImportSpec {
        time: "time".into(),
        normal_stress_kpa: None,
        ..spec.clone()
    };
    let e = import(&lab, &spec2, &dir.path().join("out")).unwrap_err();
    assert!(
        e.to_string()
            .contains("field `normal`: the normal stress is unknown"),
        "{e}"
    );
    let spec3 = ImportSpec {
        time: "time".into(),
        ..spec
    };
    let e = import(&lab, &spec3, &dir.path().join("out")).unwrap_err();
    assert!(
        e.to_string().contains(
            "bad.txt:1: field `time`: no column `time` in the header (expected one of: t, u, tau)"
        ),
        "{e}"
    );
}

#[test]
fn parse_units_and_refs() {
    assert_eq!("µm".parse::<LengthUnit>().unwrap(), LengthUnit::Um);
    assert_eq!("MPa".parse::<StressUnit>().unwrap(), StressUnit::MPa);
    assert_eq!("min".parse::<TimeUnit>().unwrap(), TimeUnit::Min);
    assert_eq!("tab".parse::<Delimiter>().unwrap(), Delimiter::Tab);
    assert!("furlong".parse::<LengthUnit>().is_err());
    assert_eq!(ColumnRef::from("12"), ColumnRef::Index(12));
    assert!((StressUnit::Psi.to_kpa() - 6.894757).abs() < 1e-6);
    assert_eq!(LengthUnit::In.to_mm(), 25.4);
}

#[test]
fn write_set_then_load_set_round_trips() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/golden/pair-01");
    let set = load_set(&src).unwrap();
    let dir = tempfile::tempdir().unwrap();
    write_set(&set, dir.path()).unwrap();
    let back = load_set(dir.path()).unwrap();
    assert_eq!(back.meta, set.meta);
    for (a, b) in set.tests.iter().zip(&back.tests) {
        assert_eq!(a.time_s, b.time_s);
        assert_eq!(a.slip_mm, b.slip_mm);
        assert_eq!(a.shear_kpa, b.shear_kpa);
        assert_eq!(a.normal_kpa, b.normal_kpa);
        assert_eq!(a.comments, b.comments);
        assert_eq!(a.line_of_row, b.line_of_row);
    }
    // comments and provenance of the bundled sets survive too
    let exp = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../experiments/table3-pulsating");
    let set = load_set(&exp).unwrap();
    write_set(&set, &dir.path().join("t3")).unwrap();
    let back = load_set(&dir.path().join("t3")).unwrap();
    assert_eq!(back.meta, set.meta);
    assert_eq!(back.tests[0].comments, set.tests[0].comments);
    assert_eq!(back.tests[0].shear_kpa, set.tests[0].shear_kpa);
}

#[test]
fn write_set_refuses_invalid_data() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/golden/pair-01");
    let mut set = load_set(&src).unwrap();
    set.tests[0].time_s[5] = set.tests[0].time_s[4];
    set.tests[1].spec.file = "../escape.csv".into();
    let dir = tempfile::tempdir().unwrap();
    match write_set(&set, &dir.path().join("w")) {
        Err(DataError::Problems(p)) => {
            let text: Vec<String> = p.iter().map(|p| p.to_string()).collect();
            let text = text.join("\n");
            assert!(text.contains("not a plain relative path"), "{text}");
            assert!(
                text.contains("velocity-steps.csv:8: field `time_s`"),
                "{text}"
            );
        }
        other => panic!("{other:?}"),
    }
    assert!(!dir.path().join("w").exists());
}

/// A comma file `t,u,tau` in s, mm and kPa, imported as test `name` of set `set`.
fn comma_spec(name: &str, set: &str) -> ImportSpec {
    ImportSpec {
        delimiter: Delimiter::Comma,
        skip_lines: 0,
        time: "t".parse().unwrap(),
        time_unit: TimeUnit::S,
        slip: "u".parse().unwrap(),
        slip_unit: LengthUnit::Mm,
        shear: Some(("tau".parse().unwrap(), StressUnit::KPa)),
        test_name: name.into(),
        set_name: set.into(),
        ..tab_spec()
    }
}

#[test]
fn a_logger_export_with_missing_samples_and_a_coarse_clock_imports_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let lab = dir.path().join("logger.csv");
    // A one-second clock at 2 Hz, a sample lost (empty) and one written NaN.
    std::fs::write(
        &lab,
        "t,u,tau\n0,0,0\n0,0.05,\n1,0.1,10\n1,0.15,15\n2,NaN,20\n2,0.25,25\n3,0.3,30\n",
    )
    .unwrap();
    let spec = comma_spec("logger", "gaps");
    let out = dir.path().join("gaps");
    let set = import(&lab, &spec, &out).unwrap_or_else(|e| panic!("{e}"));
    let t = &set.tests[0];
    // Lines 3 and 6 are gaps; the stamps left repeat at 1 s (lines 4, 5), spread over the tick.
    close(&t.time_s, &[0.0, 1.0, 1.5, 2.0, 3.0]);
    close(&t.shear_kpa, &[0.0, 10.0, 15.0, 25.0, 30.0]);
    // What the reader did is kept in the written test as provenance.
    let said = t.comments.join("\n");
    assert!(said.contains("2 rows without a value"), "{said}");
    assert!(said.contains("lines 3 and 6"), "{said}");
    assert!(
        said.contains("repeats its stamp on 1 row (line 5)"),
        "{said}"
    );
}

#[test]
fn an_aborted_stage_and_the_end_of_travel_are_trimmed_off_as_asked() {
    let dir = tempfile::tempdir().unwrap();
    let lab = dir.path().join("box.csv");
    // An aborted first stage (t < 10 s), the real stage, and the box's end-of-travel drop
    // once the slip passes 1.0 mm.
    std::fs::write(
        &lab,
        "t,u,tau\n0,0,0\n5,0.02,8\n10,0,0\n20,0.4,30\n30,0.8,32\n40,1.05,12\n50,0.95,4\n",
    )
    .unwrap();
    let spec = |keep: &str| ImportSpec {
        keep: Some(keep.parse().unwrap()),
        ..comma_spec(keep, "box")
    };
    let out = dir.path().join("box");
    let set = import(&lab, &spec("time=10:"), &out).unwrap_or_else(|e| panic!("{e}"));
    close(&set.tests[0].time_s, &[10.0, 20.0, 30.0, 40.0, 50.0]);
    let said = set.tests[0].comments.join("\n");
    assert!(
        said.contains("trimmed as asked (--keep time=10:): 5 of 7 rows kept; lines 2–3 before time_s reached 10 s left out"),
        "{said}"
    );
    let set = import(&lab, &spec("slip=:1"), &out).unwrap_or_else(|e| panic!("{e}"));
    // Cut where the slip first passes 1 mm: the drop back to 0.95 mm is not kept.
    close(&set.tests[1].slip_mm, &[0.0, 0.02, 0.0, 0.4, 0.8]);
    // A stretch the record never reaches is refused, naming the column.
    let e = import(&lab, &spec("time=100:"), &out)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("field `time_s`: --keep time=100: keeps no row"),
        "{e}"
    );
}
