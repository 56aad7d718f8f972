//! `check` says what it read of a set in units of its own: each converted column with its
//! factor (the conversions themselves: crates/data/tests/units.rs).

use subfric_data::{load_set, ExperimentSet};
use subfric_reading::summary;

/// One test at 100 kPa, in the format's own units.
const OWN_CSV: &str =
    "time_s,slip_mm,shear_kpa,normal_kpa\n0,0,0,100\n60,0.5,42.5,100\n120,1.0,40.25,101\n";

/// The same rows as a logger in MPa, µm and minutes writes them.
const LOGGER_CSV: &str =
    "time_s,slip_mm,shear_kpa,normal_kpa\n0,0,0,0.1\n1,500,0.0425,0.1\n2,1000,0.04025,0.101\n";

fn load(units: &str, csv: &str) -> ExperimentSet {
    let json = format!(
        r#"{{"name": "s", "title": "t", "source": "unit test",{units}
  "tests": [{{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}}]}}"#
    );
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("experiment.json"), json).unwrap();
    std::fs::write(dir.path().join("a.csv"), csv).unwrap();
    load_set(dir.path()).unwrap()
}

#[test]
fn check_says_which_columns_it_read_in_the_sets_units() {
    let own = load("", OWN_CSV);
    let units = r#" "units": {"stress": "MPa", "displacement": "um", "time": "min"},"#;
    let logger = load(units, LOGGER_CSV);
    let text = summary(&logger).to_string();
    assert!(
        text.contains("a: columns read in the set's units: stress MPa → kPa ×1000, displacement um → mm ×0.001, time min → s ×60"),
        "{text}"
    );
    assert!(!summary(&own).to_string().contains("units"));
}
