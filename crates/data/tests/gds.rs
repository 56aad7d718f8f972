//! GDS exports (the `.ini` channel file and the tabular GDSLAB export) and stages, on files
//! each test writes: the channels found by their names, the units their names state, the
//! time reckoned from the rate, the stage kept and said, and every refusal located.

use std::path::{Path, PathBuf};

use subfric_data::{import, load_set, DataError, ImportFormat, ImportSpec, RateUnit};

fn list(v: impl IntoIterator<Item = f64>) -> String {
    v.into_iter()
        .map(|x| format!("{x}"))
        .collect::<Vec<_>>()
        .join(",")
}

/// An aborted 7-row shear stage (0.06 mm), then the real one (30 rows to 2.9 mm); stage
/// numbers as a channel, no time, a rate without a unit, a force and the box's area.
fn ini_text() -> String {
    let mut stage = Vec::new();
    let mut h = Vec::new();
    let mut v = Vec::new();
    let mut f = Vec::new();
    for i in 0..7 {
        stage.push(1.0);
        h.push(0.01 * i as f64);
        v.push(-0.001 * i as f64);
        f.push(0.05 * i as f64);
    }
    for i in 0..30 {
        stage.push(2.0);
        h.push((i as f64 * 0.1 * 1e3).round() / 1e3);
        v.push((i as f64 * 0.002 * 1e4).round() / 1e4);
        f.push(0.36 * (i as f64 / 29.0));
    }
    let f: Vec<f64> = f.iter().map(|x| (x * 1e4).round() / 1e4).collect();
    format!(
        "[Test Data]\nSpecimen=\"dense sand, on steel\"\nArea=\"3600\"\nRate=\"0.5\"\nStage Number=\"{}\"\nHorizontal Displacement=\"{}\"\nVertical Displacement=\"{}\"\nShear Force=\"{}\"\nNormal Stress=\"{}\"\n",
        list(stage),
        list(h),
        list(v),
        list(f.clone()),
        list(std::iter::repeat_n(100.0, 37)),
    )
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn problems(e: DataError) -> Vec<String> {
    match e {
        DataError::Problems(v) => v.iter().map(ToString::to_string).collect(),
        e => panic!("expected located problems, got {e}"),
    }
}

fn spec(name: &str) -> ImportSpec {
    ImportSpec {
        test_name: name.into(),
        ..ImportSpec::default()
    }
}

#[test]
fn an_ini_file_without_time_needs_the_rate_unit_and_then_imports_its_real_stage() {
    let dir = tempfile::tempdir().unwrap();
    let lab = write(dir.path(), "run.ini", &ini_text());
    let out = dir.path().join("set");
    // No time and a rate without a unit: refused, naming the rate's line.
    let e = problems(import(&lab, &spec("r1"), &out).unwrap_err());
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(
        e[0].contains("run.ini:4: field `Rate`") && e[0].contains("--rate-unit"),
        "{e:?}"
    );
    assert!(!out.exists(), "nothing written on refusal");

    let with_unit = ImportSpec {
        rate_unit: Some("mm/min".parse::<RateUnit>().unwrap()),
        ..spec("r1")
    };
    let set = import(&lab, &with_unit, &out).unwrap_or_else(|e| panic!("{e}"));
    let t = &set.tests[0];
    // The written test reads back as imported.
    let back = load_set(&out).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        (&back.tests[0].time_s, &back.tests[0].shear_kpa),
        (&t.time_s, &t.shear_kpa)
    );
    assert_eq!(back.tests[0].channels, t.channels);
    // The real stage only, its clock from 0 at 0.5 mm/min: 0.1 mm takes 12 s.
    assert_eq!(t.slip_mm.len(), 30);
    assert_eq!(t.time_s[0], 0.0);
    assert!((t.time_s[1] - 12.0).abs() < 1e-9, "{:?}", &t.time_s[..3]);
    assert!((t.time_s[29] - 29.0 * 12.0).abs() < 1e-6);
    // The force over the 3600 mm² box: 0.36 kN is 100 kPa.
    assert!(
        (t.shear_kpa[29] - 100.0).abs() < 1e-6,
        "{}",
        t.shear_kpa[29]
    );
    assert_eq!(t.spec.normal_stress_kpa, 100.0);
    // The vertical displacement and the force travel with the test.
    let names: Vec<&str> = t.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["normal_disp_mm", "shear_force_kn"]);
    assert!((t.channels[0].values[29] - 0.058).abs() < 1e-12);
    // Every choice is said: the stage kept, the time reckoned, the units assumed.
    let said = t
        .reading_notes
        .iter()
        .map(|w| w.message.clone())
        .collect::<Vec<_>>()
        .join("\n");
    assert!(said.contains("2 stages (1: 7 rows, 0.06 mm of slip; 2: 30 rows, 2.9 mm of slip); stage 2 is kept, the one with the longest shear travel"), "{said}");
    assert!(said.contains("values 1–7"), "{said}");
    assert!(said.contains("over the stated rate 0.5 mm/min"), "{said}");
    assert!(
        said.contains("`Shear Force` in kN") && said.contains("`Area` in mm²"),
        "{said}"
    );
    // A text with a comma in it is a single value, not a channel of two values.
    assert!(!said.contains("Specimen"), "{said}");
    let csv = std::fs::read_to_string(out.join("r1.csv")).unwrap();
    assert!(csv.contains("# the record holds 2 stages"), "{csv}");
}

#[test]
fn a_stage_is_chosen_by_number_and_an_unknown_one_is_refused_with_the_list() {
    let dir = tempfile::tempdir().unwrap();
    let lab = write(dir.path(), "run.ini", &ini_text());
    let base = ImportSpec {
        rate_unit: Some("mm/min".parse().unwrap()),
        ..spec("aborted")
    };
    let first = ImportSpec {
        stage: Some("1".into()),
        ..base.clone()
    };
    let set = import(&lab, &first, &dir.path().join("a")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(set.tests[0].slip_mm.len(), 7);
    let ninth = ImportSpec {
        stage: Some("9".into()),
        ..base
    };
    let e = problems(import(&lab, &ninth, &dir.path().join("b")).unwrap_err());
    assert!(
        e[0].contains("--stage 9 is not among the file's stages (1: 7 rows"),
        "{e:?}"
    );
}

#[test]
fn sections_are_stages_and_a_channel_of_another_length_is_refused_on_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let sec = |name: &str, n: usize, travel: f64| {
        let h: Vec<f64> = (0..n)
            .map(|i| (travel * i as f64 / (n - 1) as f64 * 1e3).round() / 1e3)
            .collect();
        let t: Vec<f64> = (0..n).map(|i| 10.0 * i as f64).collect();
        let q: Vec<f64> = (0..n).map(|i| 0.1 * i as f64 / n as f64).collect();
        let q: Vec<f64> = q.iter().map(|x| (x * 1e4).round() / 1e4).collect();
        format!(
            "[{name}]\nTime (min)=\"{}\"\nHorizontal Displacement (mm)=\"{}\"\nShear Stress (MPa)=\"{}\"\n",
            list(t.iter().map(|x| x / 60.0).map(|x| (x * 1e4).round() / 1e4)),
            list(h),
            list(q)
        )
    };
    let text = format!("{}{}", sec("Stage 1", 5, 0.2), sec("Stage 2", 12, 5.0));
    let lab = write(dir.path(), "sections.ini", &text);
    let s = ImportSpec {
        normal_stress_kpa: Some(150.0),
        ..spec("s")
    };
    let set = import(&lab, &s, &dir.path().join("a")).unwrap_or_else(|e| panic!("{e}"));
    let t = &set.tests[0];
    assert_eq!(t.slip_mm.len(), 12, "the section that travels furthest");
    // MPa in the name: 0.0917 MPa is 91.7 kPa; minutes in the name: 0.1667 min is 10 s.
    assert!((t.shear_kpa[11] - 91.7).abs() < 1e-9, "{}", t.shear_kpa[11]);
    assert!((t.time_s[1] - 10.002).abs() < 1e-9, "{}", t.time_s[1]);
    let said: String = t.reading_notes.iter().map(|w| w.message.clone()).collect();
    assert!(said.contains("stage Stage 2 is kept"), "{said}");
    assert!(
        !said.contains("units not stated"),
        "every unit stated: {said}"
    );
    // By number: `2` names `Stage 2`.
    let two = ImportSpec {
        stage: Some("1".into()),
        ..s.clone()
    };
    let set = import(&lab, &two, &dir.path().join("b")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(set.tests[0].slip_mm.len(), 5);

    // One channel a value short: refused on its own line, naming the longer one.
    let short = text.replacen("\"0,0.05,", "\"0.05,", 1);
    let lab = write(dir.path(), "short.ini", &short);
    let e = problems(import(&lab, &s, &dir.path().join("c")).unwrap_err());
    assert!(
        e[0].contains("short.ini:3: field `Horizontal Displacement (mm)`: 4 values (expected 5"),
        "{e:?}"
    );
    // A value that is not a number: its line, its channel and its place in the list.
    let bad = text.replacen(",0.1,", ",0.1x,", 1);
    let lab = write(dir.path(), "bad.ini", &bad);
    let e = problems(import(&lab, &s, &dir.path().join("d")).unwrap_err());
    assert!(
        e.iter()
            .any(|p| p
                .contains("bad.ini:3: field `Horizontal Displacement (mm)`: value 3 of the list")),
        "{e:?}"
    );
    assert!(!dir.path().join("c").exists() && !dir.path().join("d").exists());
}

#[test]
fn a_gdslab_table_with_a_header_block_and_an_area_corrected_force() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from(
        "\"Test Name\",\"DS-12\"\n\"Operator\",\"JB\"\n\n\"Stage Number\",\"Time since start of test (s)\",\"Time since start of stage (s)\",\"Horizontal Displacement (mm)\",\"Vertical Displacement (mm)\",\"Horizontal Load (N)\",\"Normal Stress (kPa)\",\"Corrected Area (mm²)\",\"Back Pressure (kPa)\"\n",
    );
    for i in 0..4 {
        text.push_str(&format!(
            "1,{},{},0,{},0,100,3600,0\n",
            60 * i,
            60 * i,
            -0.01 * i as f64
        ));
    }
    for i in 0..20 {
        let x = 0.25 * i as f64;
        // Area shrinks with travel in a 60 mm box: 60 × (60 − x) mm².
        let a = 60.0 * (60.0 - x);
        text.push_str(&format!(
            "2,{},{},{x},0.01,{},100,{a},0\n",
            240 + 30 * i,
            30 * i,
            360.0 * (i.min(6)) as f64 / 6.0
        ));
    }
    let lab = write(dir.path(), "ds12.csv", &text);
    let set = import(&lab, &spec("ds12"), &dir.path().join("a")).unwrap_or_else(|e| panic!("{e}"));
    let t = &set.tests[0];
    assert_eq!(t.slip_mm.len(), 20);
    // The test's clock (not the stage's): the shear stage starts at 240 s.
    assert_eq!(t.time_s[0], 240.0);
    // 360 N over the area of its own row: at 4 mm, 60 × 56 mm².
    let at4 = t
        .slip_mm
        .iter()
        .position(|&x| x == 4.0)
        .unwrap_or(usize::MAX);
    assert!(at4 < 20, "{:?}", t.slip_mm);
    // (to the digits a 1 N reading carries there)
    assert!(
        (t.shear_kpa[at4] - 360.0 / 3360.0 * 1e3).abs() < 1e-2,
        "{}",
        t.shear_kpa[at4]
    );
    let names: Vec<&str> = t.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["normal_disp_mm", "shear_force_kn", "area_mm2"]);
    let said: String = t.reading_notes.iter().map(|w| w.message.clone()).collect();
    // The channels the test does not carry are named, never dropped unsaid.
    assert!(
        said.contains("`Time since start of stage (s)`") && said.contains("`Back Pressure (kPa)`"),
        "{said}"
    );
    assert!(said.contains("lines 5–8"), "the consolidation rows: {said}");
    // The same file read as a plain table does not know these columns.
    let plain = ImportSpec {
        format: ImportFormat::Delimited,
        ..spec("ds12")
    };
    assert!(import(&lab, &plain, &dir.path().join("b")).is_err());
}

#[test]
fn a_delimited_file_keeps_named_channels_and_its_stage_column() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from("stage,time_s,slip_mm,shear_kpa,dilation (mm),T (C)\n");
    for i in 0..3 {
        text.push_str(&format!("consolidation,{i},0,0,-0.0{i},20.5\n"));
    }
    for i in 0..12 {
        let temp = if i == 4 { String::new() } else { "20.5".into() };
        text.push_str(&format!(
            "shear,{},{},{},0.0{i},{temp}\n",
            3 + i,
            0.1 * i as f64,
            5 * i
        ));
    }
    let lab = write(dir.path(), "plain.csv", &text);
    let s = ImportSpec {
        normal_stress_kpa: Some(50.0),
        channels: vec![
            ("normal_disp_mm".into(), "dilation (mm)".parse().unwrap()),
            ("temperature_c".into(), "6".parse().unwrap()),
        ],
        ..spec("p")
    };
    let set = import(&lab, &s, &dir.path().join("a")).unwrap_or_else(|e| panic!("{e}"));
    let t = &set.tests[0];
    assert_eq!(t.slip_mm.len(), 12, "the shear stage");
    assert_eq!(t.channels[0].name, "normal_disp_mm");
    assert_eq!(t.channels[0].values[3], 0.03);
    // A channel's missing sample is a missing value, not a gap of the row.
    assert!(t.channels[1].values[4].is_nan() && t.channels[1].values[5] == 20.5);
    let wrong = ImportSpec {
        channels: vec![("dilation".into(), "5".parse().unwrap())],
        ..s.clone()
    };
    let e = problems(import(&lab, &wrong, &dir.path().join("b")).unwrap_err());
    assert!(
        e[0].contains(
            "`dilation` is not a channel a test carries (expected one of: normal_disp_mm"
        ),
        "{e:?}"
    );
    let no_stages = write(
        dir.path(),
        "nostage.csv",
        "time_s,slip_mm,shear_kpa\n0,0,0\n1,0.1,3\n",
    );
    let asked = ImportSpec {
        stage: Some("2".into()),
        ..s
    };
    let e = problems(
        import(
            &no_stages,
            &ImportSpec {
                channels: vec![],
                ..asked
            },
            &dir.path().join("c"),
        )
        .unwrap_err(),
    );
    assert!(e[0].contains("has no stage column"), "{e:?}");
}

/// An `.ini` file of two sections, each with its own rate and its channels.
fn two_section_ini(rate1: &str, rate2: &str, bad: bool) -> String {
    let sec = |name: &str, rate: &str, n: usize, step: f64, bad: bool| {
        let h: Vec<String> = (0..n)
            .map(|i| {
                if bad && i == 1 {
                    "x".into()
                } else {
                    format!("{:.3}", step * i as f64)
                }
            })
            .collect();
        let q: Vec<String> = (0..n).map(|i| format!("{:.1}", 2.0 * i as f64)).collect();
        format!(
            "[{name}]\n{rate}\nHorizontal Displacement (mm)=\"{}\"\nShear Stress (kPa)=\"{}\"\nNormal Stress (kPa)=\"{}\"\n",
            h.join(","),
            q.join(","),
            vec!["100"; n].join(",")
        )
    };
    format!(
        "{}{}",
        sec("Stage 1", rate1, 4, 0.01, false),
        sec("Stage 2", rate2, 12, 0.1, bad)
    )
}

#[test]
fn each_section_s_own_rate_times_its_rows_and_a_contradicting_rate_unit_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let lab = write(
        dir.path(),
        "r.ini",
        &two_section_ini("Rate (mm/min)=\"1.0\"", "Rate (mm/min)=\"0.1\"", false),
    );
    let set = import(&lab, &spec("r"), &dir.path().join("a")).unwrap_or_else(|e| panic!("{e}"));
    let t = &set.tests[0];
    assert_eq!(t.slip_mm.len(), 12, "stage 2");
    // 0.1 mm at 0.1 mm/min (stage 2's own rate, not stage 1's 1.0) is 60 s.
    assert!((t.time_s[1] - 60.0).abs() < 1e-9, "{:?}", &t.time_s[..2]);
    let wrong = ImportSpec {
        rate_unit: Some("mm/s".parse().unwrap()),
        ..spec("r")
    };
    let e = problems(import(&lab, &wrong, &dir.path().join("b")).unwrap_err());
    assert!(
        e[0].contains("the file states the rate in mm/min, --rate-unit says mm/s"),
        "{e:?}"
    );
    // A bad value of the second section is placed on its own line, at its place in the list.
    let lab = write(
        dir.path(),
        "bad.ini",
        &two_section_ini("Rate (mm/min)=\"1.0\"", "Rate (mm/min)=\"0.1\"", true),
    );
    let e = problems(import(&lab, &spec("r"), &dir.path().join("c")).unwrap_err());
    assert!(
        e.iter()
            .any(|p| p
                .contains("bad.ini:8: field `Horizontal Displacement (mm)`: value 2 of the list")),
        "{e:?}"
    );
}

#[test]
fn stages_by_words_a_missing_stage_cell_ties_and_ambiguous_names() {
    let dir = tempfile::tempdir().unwrap();
    // Stage labels as words, one stage cell missing inside the shear stage.
    let labels = "Consolidation,Consolidation,Shear,Shear,,Shear,Shear,Shear";
    let text = format!(
        "[Test]\nArea=\"3600\"\nRate (mm/min)=\"0.6\"\nStage=\"{labels}\"\nHorizontal Displacement (mm)=\"0,0,0,0.1,0.2,0.3,0.4,0.5\"\nShear Stress (kPa)=\"0,0,0,10,20,25,27,28\"\nNormal Stress (kPa)=\"{}\"\n",
        ["50"; 8].join(",")
    );
    let lab = write(dir.path(), "words.ini", &text);
    let set = import(&lab, &spec("w"), &dir.path().join("a")).unwrap_or_else(|e| panic!("{e}"));
    let t = &set.tests[0];
    assert_eq!(
        t.slip_mm.len(),
        6,
        "the shear rows, the one without its stage cell kept"
    );
    // One clock through the stage: 0.1 mm at 0.6 mm/min is 10 s a row.
    let want: Vec<f64> = (0..6).map(|i| 10.0 * i as f64).collect();
    assert_eq!(t.time_s, want);
    // Two stages of equal travel: the later is kept; `--stage 1` among `Consolidation 1` and
    // `Shear 1` names two and is refused.
    let text = "Stage,time_s,slip_mm,shear_kpa\nShear 1,0,0,0\nShear 1,1,1,5\nRepeat 1,2,0,0\nRepeat 1,3,1,5\n";
    let lab = write(dir.path(), "tie.csv", text);
    let s = ImportSpec {
        normal_stress_kpa: Some(50.0),
        ..spec("t")
    };
    let set = import(&lab, &s, &dir.path().join("b")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        set.tests[0].time_s,
        vec![2.0, 3.0],
        "the later of two as far"
    );
    let one = ImportSpec {
        stage: Some("1".into()),
        ..s.clone()
    };
    let e = problems(import(&lab, &one, &dir.path().join("c")).unwrap_err());
    assert!(
        e[0].contains("--stage 1 names more than one of the file's stages"),
        "{e:?}"
    );
    // A decimal comma in a semicolon file counts in the travel that ranks the stages.
    let text =
        "Stage;time_s;slip_mm;shear_kpa\n1;0;0;0\n1;1;0,01;5\n2;2;0;0\n2;3;2,5;5\n2;4;5,0;6\n";
    let lab = write(dir.path(), "comma.csv", text);
    let set = import(&lab, &s, &dir.path().join("d")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(set.tests[0].slip_mm, vec![0.0, 2.5, 5.0]);
}

#[test]
fn an_area_is_checked_and_a_second_channel_of_a_role_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let text = "\"Stage Number\",\"Time since start of test (s)\",\"Horizontal Displacement (mm)\",\"Shear Stress (kPa)\",\"Corrected Shear Stress (kPa)\",\"Normal Stress (kPa)\"\n1,0,0,0,0,100\n1,10,0.1,20,21,100\n1,20,0.2,30,31,100\n";
    let lab = write(dir.path(), "two.csv", text);
    let set = import(&lab, &spec("x"), &dir.path().join("a")).unwrap_or_else(|e| panic!("{e}"));
    let said: String = set.tests[0]
        .reading_notes
        .iter()
        .map(|w| w.message.clone())
        .collect();
    assert!(said.contains("`Corrected Shear Stress (kPa)`"), "{said}");
    // An area for a file of stresses, or one that is not positive, is refused.
    for (area, words) in [
        (
            3600.0,
            "--area was given but the file's shear and normal channels are stresses",
        ),
        (0.0, "--area 0 mm²"),
    ] {
        let s = ImportSpec {
            area_mm2: Some(area),
            ..spec("x")
        };
        let e = problems(import(&lab, &s, &dir.path().join("b")).unwrap_err());
        assert!(e.iter().any(|p| p.contains(words)), "{area}: {e:?}");
    }
}
