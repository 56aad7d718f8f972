//! Loading a set from its folder: `experiment.json` first, then every test's CSV.

use std::path::Path;

use super::parse::parse_test_csv;
use super::validate::repeated_tests;
use super::{ExperimentSet, TestData, EXPERIMENT_JSON, MAX_MAGNITUDE};
use crate::error::{DataError, InputProblem, Problems};
use crate::fsio::set_file_problem;
use crate::meta::{file_name_problem, parse_meta, TestSpec};

fn read_text(path: &Path, what: &str, max: u64) -> Result<String, DataError> {
    crate::fsio::read_user_text(path, what, max)
}

/// Loads and validates an experiment set folder: `experiment.json` and every test CSV.
///
/// All problems of all files are collected before an error is returned.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// std::fs::write(dir.path().join("experiment.json"), r#"{"name": "demo", "title": "Demo", "source": "doc",
///   "tests": [{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}]}"#)?;
/// std::fs::write(dir.path().join("a.csv"), "# made up\ntime_s,slip_mm,friction\n0,0,0\n1,0.01,0.3\n")?;
/// let set = subfric_data::load_set(dir.path())?;
/// assert_eq!(set.tests[0].shear_kpa, vec![0.0, 30.0]);
/// assert!(set.tests[0].friction_given);
/// assert_eq!(set.tests[0].comments, vec!["made up".to_string()]);
/// # Ok(()) }
/// ```
pub fn load_set(dir: &Path) -> Result<ExperimentSet, DataError> {
    if let Some(p) = crate::fsio::file_not_folder(dir) {
        return Err(DataError::Problems(vec![p]));
    }
    let json_path = dir.join(EXPERIMENT_JSON);
    if dir.is_dir() {
        if let Some(msg) = set_file_problem(dir, &json_path).filter(|_| json_path.exists()) {
            return Err(DataError::Problems(vec![InputProblem::new(
                &json_path,
                None,
                None,
                format!("{EXPERIMENT_JSON} {msg}"),
            )]));
        }
    }
    let text = match read_text(
        &json_path,
        EXPERIMENT_JSON,
        crate::fsio::MAX_SETTINGS_FILE_BYTES,
    ) {
        Ok(t) => t,
        Err(DataError::Io { path, source }) if source.kind() == std::io::ErrorKind::NotFound => {
            let what = if dir.is_dir() {
                format!("no {EXPERIMENT_JSON} in folder {}", dir.display())
            } else {
                format!("folder {} does not exist", dir.display())
            };
            return Err(DataError::Problems(vec![InputProblem::new(
                path,
                None,
                None,
                format!("{what} (expected an experiment set folder holding {EXPERIMENT_JSON} and one CSV per test)"),
            )]));
        }
        Err(e) => return Err(e),
    };
    let meta = parse_meta(&text, &json_path)?;
    let positions = crate::jsonpos::value_positions(&text);
    // each file's problems are capped on their own; the set keeps them all
    let mut problems: Vec<InputProblem> = Vec::new();
    let mut tests = Vec::with_capacity(meta.tests.len());
    for (i, spec) in meta.tests.iter().enumerate() {
        let csv_path = dir.join(&spec.file);
        if let Some(msg) = set_file_problem(dir, &csv_path) {
            let field = format!("tests[{i}].file");
            let line = positions.get(&field).map(|p| p.0);
            problems.push(InputProblem::new(
                &json_path,
                line,
                Some(&field),
                format!(
                    "file `{}` of test `{}` {msg} (expected a CSV file {})",
                    spec.file,
                    spec.name,
                    csv_path.display()
                ),
            ));
            continue;
        }
        match load_test_inner(dir, spec, false) {
            Ok(t) => tests.push(t),
            Err(DataError::Problems(ps)) => problems.extend(ps),
            Err(e) => return Err(e),
        }
    }
    if problems.is_empty() {
        problems.extend(repeated_tests(&tests, &json_path, &positions));
    }
    if !problems.is_empty() {
        return Err(DataError::Problems(problems));
    }
    Ok(ExperimentSet {
        dir: dir.to_path_buf(),
        meta,
        tests,
    })
}

/// Loads and validates the CSV of one test of the set in `dir`.
///
/// All problems of the file are collected before an error is returned.
pub fn load_test(dir: &Path, spec: &TestSpec) -> Result<TestData, DataError> {
    load_test_inner(dir, spec, true)
}

fn load_test_inner(dir: &Path, spec: &TestSpec, check_spec: bool) -> Result<TestData, DataError> {
    let mut problems = Problems::default();
    if check_spec {
        let json = dir.join(EXPERIMENT_JSON);
        if let Some(msg) = file_name_problem(&spec.file) {
            problems.add(
                &json,
                None,
                Some("file"),
                format!("test `{}`: {msg}", spec.name),
            );
            return Err(DataError::Problems(problems.into_vec()));
        }
        if !(spec.normal_stress_kpa > 0.0 && spec.normal_stress_kpa <= MAX_MAGNITUDE) {
            let n = spec.normal_stress_kpa;
            problems.add(
                &json,
                None,
                Some("normal_stress_kpa"),
                format!(
                    "test `{}`: normal stress {} kPa is {} (expected a normal stress > 0 kPa, at most 1e12)",
                    spec.name,
                    crate::text::short_number(n),
                    if n > MAX_MAGNITUDE { "beyond 1e12" } else { "not positive" }
                ),
            );
        }
    }
    let path = dir.join(&spec.file);
    if let Some(msg) = set_file_problem(dir, &path) {
        problems.add(
            &path,
            None,
            Some("file"),
            format!(
                "file `{}` named in {EXPERIMENT_JSON} for test `{}` {msg} (expected a CSV file)",
                spec.file, spec.name
            ),
        );
        return Err(DataError::Problems(problems.into_vec()));
    }
    let text = read_text(&path, "the test's CSV", crate::fsio::MAX_DATA_FILE_BYTES)?;
    let result = parse_test_csv(&text, &path, spec);
    match result {
        Ok(t) => problems.into_result(t),
        Err(ps) => {
            let mut all = problems.into_vec();
            all.extend(ps);
            Err(DataError::Problems(all))
        }
    }
}
