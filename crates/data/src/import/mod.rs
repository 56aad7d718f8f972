//! Import of laboratory files (any delimiter, units and column names) into an experiment set.

mod columns;
mod gds;
mod join;
mod keep;
mod rows;
mod spec;
mod stage;
mod table;
mod text;
mod units;

pub use keep::{Keep, KeepColumn};
pub use spec::ImportSpec;
pub use units::{ColumnRef, Delimiter, ImportFormat, LengthUnit, RateUnit, StressUnit, TimeUnit};

use std::path::{Path, PathBuf};

use crate::error::DataError;
use crate::fsio::{commit_file, stage_file};
use crate::set::{
    load_set, meta_json_text, prepare_parent, test_csv_text, ExperimentSet, TestData,
    EXPERIMENT_JSON,
};
use join::{set_meta_for, with_test_appended};
use spec::spec_problems;
use table::{delimited_table, test_from_table};
use text::read_lab_text;

/// Longest file name stem [`file_name_for`] makes before it shortens the name: well below a
/// file system's 255 bytes, with room for the temporary name of an atomic write.
const MAX_FILE_STEM: usize = 100;

/// File name for a test: the name with characters outside `[A-Za-z0-9._-]` replaced by `-`; a
/// name longer than 100 characters is cut there and given a short hash of the whole name, so
/// that two long names sharing their start still get two files.
///
/// ```
/// use subfric_data::import::file_name_for;
/// assert_eq!(file_name_for("run 3"), "run-3.csv");
/// let (a, b) = (file_name_for(&"x".repeat(300)), file_name_for(&("x".repeat(299) + "y")));
/// assert!(a.len() < 120 && a != b);
/// ```
pub fn file_name_for(test_name: &str) -> String {
    let mut s: String = test_name
        .trim()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-') {
                c
            } else {
                '-'
            }
        })
        .collect();
    while s.starts_with('.') {
        s.remove(0);
    }
    if s.is_empty() {
        s.push_str("test");
    }
    if s.len() > MAX_FILE_STEM {
        s.truncate(MAX_FILE_STEM);
        s.push_str(&format!(
            "-{:08x}",
            crate::text::stable_hash(test_name) as u32
        ));
    }
    s.push_str(".csv");
    s
}

/// Reads a lab file into a test (not yet written); problems name the lab file and its lines.
pub fn read_lab_file(
    lab_file: &Path,
    spec: &ImportSpec,
    target: &Path,
) -> Result<TestData, DataError> {
    let lf = lab_file;
    if spec.format == ImportFormat::Delimited {
        spec_problems(lf, spec).into_result(())?;
    }
    let text = read_lab_text(lf)?;
    let gds = match spec.format {
        ImportFormat::Gds => true,
        ImportFormat::Delimited => false,
        ImportFormat::Auto => gds::looks_like_gds(lf, &text),
    };
    if gds {
        // The channels are found by their names: the columns the options name are not used.
        let (table, read_spec) = gds::read(lf, &text, spec)?;
        spec_problems(lf, &read_spec).into_result(())?;
        return test_from_table(lf, &read_spec, table, target, None);
    }
    if spec.format == ImportFormat::Auto {
        spec_problems(lf, spec).into_result(())?;
    }
    let table = delimited_table(lf, spec, &text)?;
    test_from_table(lf, spec, table, target, Some(&text))
}

/// Imports a lab file as a test of the experiment set in `out_dir`.
///
/// Units are converted to mm, s and kPa; shear is computed as friction × normal when only
/// friction is given. The result is validated like [`load_set`] does. If `out_dir` already
/// holds an `experiment.json`, the test is appended to that set (a duplicate test name or an
/// existing file of the same name is refused); otherwise a new set is created. Nothing is
/// overwritten, and the write is all or nothing: the CSV and the new `experiment.json` are
/// written in full to temporary files first, then renamed into place, the description last
/// (if that fails the new CSV is removed again). Returns the set as loaded back from `out_dir`.
pub fn import(
    lab_file: &Path,
    spec: &ImportSpec,
    out_dir: &Path,
) -> Result<ExperimentSet, DataError> {
    let test = read_lab_file(lab_file, spec, out_dir)?;
    let json_path = out_dir.join(EXPERIMENT_JSON);
    let csv_path: PathBuf = out_dir.join(&test.spec.file);
    let mut meta = set_meta_for(lab_file, spec, out_dir, &test)?;
    let existing = meta.tests.len();
    meta.tests.push(test.spec.clone());
    let json_text = if existing == 0 {
        meta_json_text(&meta)?
    } else {
        with_test_appended(&json_path, &meta, &test.spec)?
    };
    std::fs::create_dir_all(out_dir).map_err(|e| DataError::io(out_dir, e))?;
    prepare_parent(out_dir, &csv_path)?;
    let csv_tmp = stage_file(&csv_path, test_csv_text(&test).as_bytes())?;
    let json_tmp = match stage_file(&json_path, json_text.as_bytes()) {
        Ok(t) => t,
        Err(e) => {
            let _ = std::fs::remove_file(&csv_tmp);
            return Err(e);
        }
    };
    if let Err(e) = commit_file(&csv_tmp, &csv_path) {
        let _ = std::fs::remove_file(&json_tmp);
        return Err(e);
    }
    if let Err(e) = commit_file(&json_tmp, &json_path) {
        let _ = std::fs::remove_file(&csv_path);
        return Err(e);
    }
    // The set as written, with what the reader made of the lab file (gaps, a spread clock, a
    // trim) on its new test: the written file holds it as comments, the caller shows it.
    let mut set = load_set(out_dir)?;
    if let Some(t) = set.tests.iter_mut().find(|t| t.spec.name == test.spec.name) {
        t.reading_notes = test.reading_notes;
    }
    Ok(set)
}
