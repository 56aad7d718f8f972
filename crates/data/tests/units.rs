//! The `units` block of experiment.json: a logger that writes MPa, µm or minutes is read in kPa,
//! mm and s, never 1000× wrong; a unit the reader does not know is refused at its line.

use subfric_data::{load_set, write_set, ExperimentSet};

/// One test at 100 kPa, in the format's own units.
const OWN_CSV: &str =
    "time_s,slip_mm,shear_kpa,normal_kpa\n0,0,0,100\n60,0.5,42.5,100\n120,1.0,40.25,101\n";

/// The same rows as a logger in MPa, µm and minutes writes them (the column names are the
/// format's; the set's `units` say what the numbers are in).
const LOGGER_CSV: &str =
    "time_s,slip_mm,shear_kpa,normal_kpa\n0,0,0,0.1\n1,500,0.0425,0.1\n2,1000,0.04025,0.101\n";

fn json(units: &str) -> String {
    format!(
        r#"{{"name": "s", "title": "t", "source": "unit test",{units}
  "tests": [{{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}}]}}"#
    )
}

fn write(dir: &std::path::Path, json: &str, csv: &str) {
    std::fs::write(dir.join("experiment.json"), json).unwrap();
    std::fs::write(dir.join("a.csv"), csv).unwrap();
}

fn load(json: &str, csv: &str) -> Result<ExperimentSet, String> {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), json, csv);
    load_set(dir.path()).map_err(|e| e.to_string())
}

fn close(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-12 * y.abs().max(1.0))
}

#[test]
fn a_logger_in_mpa_um_and_minutes_reads_as_the_same_test_in_kpa_mm_and_s() {
    let own = load(&json(""), OWN_CSV).unwrap();
    let units = r#" "units": {"stress": "MPa", "displacement": "um", "time": "min"},"#;
    let logger = load(&json(units), LOGGER_CSV).unwrap();
    let (a, b) = (&own.tests[0], &logger.tests[0]);
    assert!(close(&b.time_s, &a.time_s), "{:?}", b.time_s);
    assert!(close(&b.slip_mm, &a.slip_mm), "{:?}", b.slip_mm);
    assert!(close(&b.shear_kpa, &a.shear_kpa), "{:?}", b.shear_kpa);
    assert!(close(&b.normal_kpa, &a.normal_kpa), "{:?}", b.normal_kpa);
    // What `check` says it read (each converted column with its factor) is
    // subfric-reading's summary: crates/reading/tests/units_read.rs.
}

#[test]
fn a_tests_own_units_take_precedence_over_the_sets() {
    let text = r#"{"name": "s", "title": "t", "source": "unit test",
  "units": {"stress": "Pa"},
  "tests": [{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100,
             "units": {"stress": "MPa", "displacement": "um", "time": "min"}}]}"#;
    let set = load(text, LOGGER_CSV).unwrap();
    assert!(close(&set.tests[0].shear_kpa, &[0.0, 42.5, 40.25]));
}

#[test]
fn a_friction_column_stays_a_ratio_and_the_jsons_normal_stress_stays_kpa() {
    let csv = "time_s,slip_mm,friction\n0,0,0\n1,0.5,0.425\n";
    let set = load(&json(r#" "units": {"stress": "MPa"},"#), csv).unwrap();
    assert!(close(&set.tests[0].shear_kpa, &[0.0, 42.5]));
    assert!(close(&set.tests[0].normal_kpa, &[100.0, 100.0]));
}

#[test]
fn an_unknown_unit_a_force_or_an_unknown_field_is_refused_at_its_line() {
    let bad = r#"{"name": "s", "title": "t", "source": "unit test",
  "units": {
    "stress": "bar",
    "time": "fortnight",
    "pressure": "kPa"
  },
  "tests": [{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}]}"#;
    let e = load(bad, OWN_CSV).unwrap_err();
    assert!(
        e.contains("experiment.json:3: field `units.stress`: unknown stress unit `bar` (expected kPa, MPa, Pa or psi)"),
        "{e}"
    );
    assert!(
        e.contains("experiment.json:4: field `units.time`: unknown time unit `fortnight` (expected s, min, h or ms)"),
        "{e}"
    );
    assert!(
        e.contains("experiment.json:5: field `units.pressure`: unknown unit field `pressure`"),
        "{e}"
    );
    let force = load(&json(r#" "units": {"stress": "kN"},"#), OWN_CSV).unwrap_err();
    assert!(
        force.contains("field `units.stress`: `kN` is a force, not a stress"),
        "{force}"
    );
    let not_object = load(&json(r#" "units": "MPa","#), OWN_CSV).unwrap_err();
    assert!(
        not_object.contains("field `units`: found a string (expected an object"),
        "{not_object}"
    );
}

#[test]
fn a_set_read_in_its_units_and_written_again_is_not_converted_twice() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        &json(r#" "units": {"stress": "MPa", "displacement": "um", "time": "min"},"#),
        LOGGER_CSV,
    );
    let set = load_set(dir.path()).unwrap();
    let out = tempfile::tempdir().unwrap();
    write_set(&set, out.path()).unwrap();
    let again = load_set(out.path()).unwrap();
    assert!(close(&again.tests[0].shear_kpa, &set.tests[0].shear_kpa));
    assert!(close(&again.tests[0].time_s, &set.tests[0].time_s));
    let written = std::fs::read_to_string(out.path().join("experiment.json")).unwrap();
    assert!(!written.contains("units"), "{written}");
}
