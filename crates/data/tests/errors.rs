//! Every validation error names the file, the line and the field, and says what was expected.

use std::path::Path;

use subfric_data::{load_set, load_test, ControlColumn, DataError, InputProblem, TestSpec};

const JSON_ONE: &str = r#"{
  "name": "s",
  "title": "t",
  "source": "unit test",
  "tests": [
    {"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}
  ]
}"#;

/// The set of [`JSON_ONE`] with `csv` as its test, loaded (its folder kept alive with it).
fn loaded(
    csv: &str,
) -> (
    tempfile::TempDir,
    Result<subfric_data::ExperimentSet, DataError>,
) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("experiment.json"), JSON_ONE).unwrap();
    std::fs::write(dir.path().join("a.csv"), csv).unwrap();
    let set = load_set(dir.path());
    (dir, set)
}

fn set_with_csv(csv: &str) -> (tempfile::TempDir, Vec<InputProblem>) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("experiment.json"), JSON_ONE).unwrap();
    std::fs::write(dir.path().join("a.csv"), csv).unwrap();
    let problems = match load_set(dir.path()) {
        Err(DataError::Problems(p)) => p,
        Err(e) => panic!("unexpected error kind: {e}"),
        Ok(_) => panic!("accepted invalid data:\n{csv}"),
    };
    (dir, problems)
}

/// Asserts one problem is in `a.csv` at `line`, about `field`, containing `words`.
fn assert_problem(
    problems: &[InputProblem],
    line: Option<usize>,
    field: Option<&str>,
    words: &[&str],
) {
    let found = problems.iter().any(|p| {
        p.file.ends_with("a.csv")
            && p.line == line
            && p.field.as_deref() == field
            && words.iter().all(|w| p.message.contains(w))
    });
    let all: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
    assert!(
        found,
        "no problem at line {line:?} field {field:?} with {words:?} in:\n{}",
        all.join("\n")
    );
    for p in problems {
        assert!(
            p.message.contains("expected"),
            "message without expectation: {p}"
        );
    }
}

#[test]
fn missing_required_column() {
    let (_d, p) = set_with_csv("# c\ntime_s,shear_kpa\n0,1\n");
    assert_problem(
        &p,
        Some(2),
        Some("slip_mm"),
        &["missing required column `slip_mm`"],
    );
    let (_d, p) = set_with_csv("time_s,slip_mm\n0,1\n");
    assert_problem(
        &p,
        Some(1),
        Some("shear_kpa"),
        &["missing required column", "friction"],
    );
}

#[test]
fn unknown_column_lists_the_accepted_ones() {
    let (_d, p) = set_with_csv("time_s,slip_mm,shear_kpa,temperature\n0,0,0,20\n");
    assert_problem(
        &p,
        Some(1),
        Some("temperature"),
        &[
            "unknown column `temperature`",
            "time_s, slip_mm, shear_kpa, friction, normal_kpa",
        ],
    );
    let text = DataError::Problems(p).to_string();
    assert!(
        text.contains("a.csv:1: field `temperature`: unknown column"),
        "{text}"
    );
}

#[test]
fn duplicate_column() {
    let (_d, p) = set_with_csv("time_s,slip_mm,shear_kpa,slip_mm\n0,0,0,0\n");
    assert_problem(&p, Some(1), Some("slip_mm"), &["appears twice"]);
}

#[test]
fn wrong_number_of_cells() {
    let (_d, p) = set_with_csv("time_s,slip_mm,shear_kpa\n0,0,0\n1,0.1\n2,0.2,3,4\n");
    assert_problem(
        &p,
        Some(3),
        None,
        &["row has 2 cells", "expected 3: time_s,slip_mm,shear_kpa"],
    );
    assert_problem(&p, Some(4), None, &["row has 4 cells"]);
}

#[test]
fn non_numeric_and_non_finite_cells() {
    // NaN and an empty cell are a logger's missing samples (gaps, see `missing_samples_...`);
    // text and an overflow beside them are refused, each at its line.
    let (_d, p) = set_with_csv(
        "time_s,slip_mm,shear_kpa\n0,0,0\n1,abc,1\n2,0.2,NaN\n3,inf,1\n4,0.4,\n5,x,\n",
    );
    assert_problem(
        &p,
        Some(3),
        Some("slip_mm"),
        &["`abc` is not a number", "decimal number"],
    );
    assert_problem(
        &p,
        Some(5),
        Some("slip_mm"),
        &["`inf` is not a finite number"],
    );
    assert_problem(&p, Some(7), Some("slip_mm"), &["`x` is not a number"]);
    assert_eq!(p.len(), 3, "all problems collected, no gap among them");
}

#[test]
fn missing_samples_are_gaps_left_out_and_said() {
    let (_dir, set) =
        loaded("time_s,slip_mm,shear_kpa\n0,0,0\n1,0.1,NaN\n2,0.2,\n3,0.3,30\n4,NA,40\n5,0.5,50\n");
    let set = set.unwrap();
    let t = &set.tests[0];
    // The rows of lines 3, 4 and 6 are left out; the others keep their values and lines.
    assert_eq!(t.time_s, vec![0.0, 3.0, 5.0]);
    assert_eq!(t.shear_kpa, vec![0.0, 30.0, 50.0]);
    assert_eq!(t.line_of_row, vec![2, 5, 7]);
    let warnings = subfric_data::plausibility(&set);
    let gap = warnings
        .iter()
        .find(|w| w.message.contains("read as gaps"))
        .expect("the gaps are said");
    assert!(gap.message.starts_with("3 rows"), "{}", gap.message);
    assert!(gap.message.contains("lines 3–4 and 6"), "{}", gap.message);
    assert_eq!(gap.field, "shear_kpa, slip_mm");
    // A file whose every row misses a value is refused, saying so.
    let (_d, e) = loaded("time_s,slip_mm,shear_kpa\n0,0,\n1,0.1,NaN\n");
    let e = e.unwrap_err().to_string();
    assert!(
        e.contains("a.csv:1: the test has a header but every row misses a value"),
        "{e}"
    );
}

#[test]
fn a_coarse_clock_is_spread_over_its_ticks_and_said() {
    // A one-second clock at 2 Hz.
    let (_dir, set) = loaded(
        "time_s,slip_mm,shear_kpa\n0,0,0\n0,0.05,5\n1,0.1,10\n1,0.15,15\n2,0.2,20\n2,0.25,25\n",
    );
    let set = set.unwrap();
    assert_eq!(set.tests[0].time_s, vec![0.0, 0.5, 1.0, 1.5, 2.0, 2.5]);
    let warnings = subfric_data::plausibility(&set);
    assert!(
        warnings
            .iter()
            .any(|w| w.field == "time_s" && w.message.contains("repeats its stamp on 3 rows")),
        "{warnings:?}"
    );
}

#[test]
fn time_not_increasing_names_both_values() {
    let (_d, p) =
        set_with_csv("time_s,slip_mm,shear_kpa\n0,0,0\n# note\n1.5,0.1,1\n1.5,0.2,1\n1.2,0.3,1\n");
    assert_problem(
        &p,
        Some(5),
        Some("time_s"),
        &[
            "time 1.5 is not after time 1.5 on line 4",
            "strictly increasing",
        ],
    );
    assert_problem(
        &p,
        Some(6),
        Some("time_s"),
        &["time 1.2 is not after time 1.5 on line 5"],
    );
}

#[test]
fn non_positive_normal_stress_from_column() {
    let (_d, p) =
        set_with_csv("time_s,slip_mm,shear_kpa,normal_kpa\n0,0,0,100\n1,0.1,1,0\n2,0.2,1,-5\n");
    assert_problem(
        &p,
        Some(3),
        Some("normal_kpa"),
        &["normal stress 0 kPa is not positive", "> 0"],
    );
    assert_problem(&p, Some(4), Some("normal_kpa"), &["normal stress -5 kPa"]);
}

#[test]
fn non_positive_normal_stress_from_spec() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("experiment.json"),
        JSON_ONE.replace("\"normal_stress_kpa\": 100", "\"normal_stress_kpa\": 0"),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("a.csv"),
        "time_s,slip_mm,shear_kpa\n0,0,0\n",
    )
    .unwrap();
    let e = load_set(dir.path()).unwrap_err();
    let p = &e.problems()[0];
    assert!(p.file.ends_with("experiment.json"));
    assert_eq!(p.line, Some(6));
    assert_eq!(p.field.as_deref(), Some("tests[0].normal_stress_kpa"));
    assert!(p.message.contains("not positive") && p.message.contains("expected"));
    // load_test checks the spec too
    let spec = TestSpec::new("a", "a.csv", ControlColumn::Slip, -1.0);
    let e = load_test(dir.path(), &spec).unwrap_err();
    assert!(e.to_string().contains("field `normal_stress_kpa`"), "{e}");
}

#[test]
fn absent_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("experiment.json"), JSON_ONE).unwrap();
    let e = load_set(dir.path()).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains(
            "experiment.json:6: field `tests[0].file`: file `a.csv` of test `a` is absent"
        ),
        "{text}"
    );
    let spec = TestSpec::new("b", "b.csv", ControlColumn::Shear, 50.0);
    let e = load_test(dir.path(), &spec).unwrap_err();
    assert!(e.to_string().contains("b.csv: field `file`"), "{e}");
}

#[test]
fn empty_test() {
    let (_d, p) = set_with_csv("# only a header\ntime_s,slip_mm,shear_kpa\n\n");
    assert_problem(&p, Some(2), None, &["header but no data rows"]);
    let (_d, p) = set_with_csv("# nothing at all\n");
    assert_problem(&p, None, None, &["no header line"]);
}

#[test]
fn duplicate_test_names_and_bad_control() {
    let dir = tempfile::tempdir().unwrap();
    let json = r#"{
  "name": "s", "title": "t", "source": "x",
  "tests": [
    {"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100},
    {"name": "a", "file": "b.csv", "control": "displacement", "normal_stress_kpa": 100}
  ]
}"#;
    std::fs::write(dir.path().join("experiment.json"), json).unwrap();
    let e = load_set(dir.path()).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("experiment.json:5: field `tests[1].name`: duplicate test name `a`"),
        "{text}"
    );
    assert!(
        text.contains("experiment.json:5: field `tests[1].control`: unknown control `displacement` (expected \"slip\" or \"shear\")"),
        "{text}"
    );
}

#[test]
fn missing_and_mistyped_json_fields() {
    let dir = tempfile::tempdir().unwrap();
    let json = "{\n  \"name\": \"s\",\n  \"source\": [1],\n  \"tests\": [\n    {\"name\": \"a\", \"control\": \"slip\", \"normal_stress_kpa\": \"100\"}\n  ]\n}";
    std::fs::write(dir.path().join("experiment.json"), json).unwrap();
    let e = load_set(dir.path()).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("experiment.json:1: field `title`: missing required field `title`"),
        "{text}"
    );
    assert!(
        text.contains("experiment.json:3: field `source`: found an array (expected a string)"),
        "{text}"
    );
    assert!(
        text.contains("experiment.json:5: field `tests[0].file`: missing required field"),
        "{text}"
    );
    assert!(
        text.contains("experiment.json:5: field `tests[0].normal_stress_kpa`: found a string (expected a number, kPa)"),
        "{text}"
    );
}

#[test]
fn json_syntax_error_has_file_line_column() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("experiment.json"),
        "{\n  \"name\": \"s\",\n  \"title\": \"t\"\n  \"source\": \"x\"\n}",
    )
    .unwrap();
    match load_set(dir.path()) {
        Err(DataError::Json {
            path,
            line,
            column,
            message,
            ..
        }) => {
            assert!(path.ends_with("experiment.json"));
            assert_eq!(line, 4);
            assert!(column >= 3);
            assert!(message.contains("expected"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn missing_folder_and_missing_json() {
    let e = load_set(Path::new("/nonexistent/set")).unwrap_err();
    assert!(e.to_string().contains("does not exist"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let e = load_set(dir.path()).unwrap_err();
    assert!(e.to_string().contains("no experiment.json"), "{e}");
}

#[test]
fn problems_of_all_files_are_collected() {
    let dir = tempfile::tempdir().unwrap();
    let json = r#"{"name": "s", "title": "t", "source": "x", "tests": [
      {"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100},
      {"name": "b", "file": "b.csv", "control": "shear", "normal_stress_kpa": 100},
      {"name": "c", "file": "c.csv", "control": "shear", "normal_stress_kpa": 100}]}"#;
    std::fs::write(dir.path().join("experiment.json"), json).unwrap();
    std::fs::write(
        dir.path().join("a.csv"),
        "time_s,slip_mm,shear_kpa\n0,x,0\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("b.csv"),
        "time_s,slip_mm,shear_kpa\n1,0,0\n0,0,0\n",
    )
    .unwrap();
    let e = load_set(dir.path()).unwrap_err();
    let files: Vec<String> = e
        .problems()
        .iter()
        .map(|p| p.file.file_name().unwrap().to_string_lossy().to_string())
        .collect();
    assert_eq!(files, vec!["a.csv", "b.csv", "experiment.json"]);
}

#[test]
fn many_bad_rows_are_capped() {
    let mut csv = String::from("time_s,slip_mm,shear_kpa\n");
    for _ in 0..500 {
        csv.push_str("x,0,0\n");
    }
    let (_d, p) = set_with_csv(&csv);
    assert!(p.len() <= 61);
    assert!(p
        .last()
        .unwrap()
        .message
        .contains("more problems not shown"));
}

#[test]
fn not_utf8() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("experiment.json"), JSON_ONE).unwrap();
    std::fs::write(
        dir.path().join("a.csv"),
        b"time_s,slip_mm,shear_kpa\n0,0,\xff\n",
    )
    .unwrap();
    let e = load_set(dir.path()).unwrap_err();
    assert!(
        e.to_string()
            .contains("a.csv:2: the file is not valid UTF-8"),
        "{e}"
    );
}

#[test]
fn lenient_on_harmless_variations() {
    // CRLF, BOM, blank lines, spaces, quoted header, comments between rows, friction + normal
    let csv = "\u{feff}# c1\r\n\"time_s\", slip_mm ,friction,normal_kpa\r\n\r\n0, 0, 0.5, 100\r\n# c2\r\n1,0.1,0.5,200\r\n";
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("experiment.json"), JSON_ONE).unwrap();
    std::fs::write(dir.path().join("a.csv"), csv).unwrap();
    let set = load_set(dir.path()).unwrap_or_else(|e| panic!("{e}"));
    let t = &set.tests[0];
    assert_eq!(t.shear_kpa, vec![50.0, 100.0]);
    assert_eq!(t.normal_kpa, vec![100.0, 200.0]);
    assert_eq!(t.line_of_row, vec![4, 6]);
    assert_eq!(t.comments, vec!["c1", "c2"]);
    assert!(t.friction_given && t.normal_varies());
}

#[test]
fn further_channels_are_carried_as_read_and_written_back() {
    // Dilation and a temperature beside the stresses; one temperature sample missing keeps its
    // row (only a missing time, slip or stress makes a gap).
    let (dir, set) = loaded(
        "time_s,slip_mm,shear_kpa,normal_disp_mm,temperature_c\n0,0,0,0,20.1\n1,0.1,10,-0.002,\n2,0.2,20,-0.005,20.3\n",
    );
    let set = set.unwrap();
    let t = &set.tests[0];
    assert_eq!(t.len(), 3);
    let names: Vec<&str> = t.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["normal_disp_mm", "temperature_c"]);
    assert_eq!(t.channels[0].values, vec![0.0, -0.002, -0.005]);
    assert!(t.channels[1].values[1].is_nan());
    // Written back and read again: the same channels, the missing sample still missing.
    let out = dir.path().join("copy");
    subfric_data::write_set(&set, &out).unwrap();
    let back = load_set(&out).unwrap();
    assert_eq!(back.tests[0].channels[0], t.channels[0]);
    assert!(back.tests[0].channels[1].values[1].is_nan());
    // A column of neither kind is refused, the message listing the channels.
    let (_d, p) = set_with_csv("time_s,slip_mm,shear_kpa,dilation\n0,0,0,0\n");
    assert_problem(
        &p,
        Some(1),
        Some("dilation"),
        &["unknown column", "normal_disp_mm"],
    );
}
