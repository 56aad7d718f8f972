//! The set an imported test joins: the folder's description with the test added, or a new one.

use std::path::Path;

use serde_json::Map;

use super::ImportSpec;
use crate::error::{DataError, InputProblem, Problems};
use crate::fsio::PathKind;
use crate::meta::{ExperimentMeta, Interface};
use crate::set::{load_set, TestData, EXPERIMENT_JSON};

/// The description of the set `test` joins: the existing one (refusing a duplicate test name
/// or file), or a new one.
pub(super) fn set_meta_for(
    lab_file: &Path,
    spec: &ImportSpec,
    out_dir: &Path,
    test: &TestData,
) -> Result<ExperimentMeta, DataError> {
    let json_path = out_dir.join(EXPERIMENT_JSON);
    let csv_path = out_dir.join(&test.spec.file);
    let csv_taken = PathKind::of(&csv_path) != PathKind::Absent;
    match PathKind::of(&json_path) {
        PathKind::Absent => {}
        PathKind::File | PathKind::DanglingLink => {
            let existing = load_set(out_dir)?;
            let mut pr = Problems::default();
            if existing.meta.tests.iter().any(|t| t.name == test.spec.name) {
                pr.add(
                    &json_path,
                    None,
                    Some("tests"),
                    format!(
                        "the set already has a test named `{}` (expected a new test name)",
                        test.spec.name
                    ),
                );
            }
            let hash = test.content_hash();
            if let Some(same) = existing.tests.iter().find(|t| t.content_hash() == hash) {
                pr.add(
                    &json_path,
                    None,
                    Some("tests"),
                    format!(
                        "the lab file holds the same {} rows as test `{}` ({}) of the set, value for value (expected a new record: the same rows twice would count twice and every interval would be too narrow by √2)",
                        test.len(),
                        same.spec.name,
                        same.spec.file
                    ),
                );
            }
            if existing.meta.tests.iter().any(|t| t.file == test.spec.file) || csv_taken {
                pr.add(
                    &csv_path,
                    None,
                    Some("file"),
                    format!(
                        "file `{}` already exists (expected a new test name, or remove the file)",
                        test.spec.file
                    ),
                );
            }
            pr.into_result(())?;
            return Ok(existing.meta);
        }
        kind => {
            return Err(DataError::Problems(vec![InputProblem::new(
                &json_path,
                None,
                None,
                format!(
                    "{EXPERIMENT_JSON} {} (expected a file, or nothing for a new set)",
                    kind.describe()
                ),
            )]))
        }
    }
    if csv_taken {
        return Err(DataError::Problems(vec![InputProblem::new(
            &csv_path,
            None,
            Some("file"),
            "file already exists (expected an empty or new folder)",
        )]));
    }
    let file_name = lab_file
        .file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    Ok(ExperimentMeta {
        name: spec.set_name.clone(),
        title: spec.title.clone().unwrap_or_else(|| spec.set_name.clone()),
        source: spec
            .source
            .clone()
            .unwrap_or_else(|| format!("lab file `{file_name}`")),
        provenance: Some(format!("imported with subfric from lab file `{file_name}`")),
        interface: Interface {
            soil: spec.soil.clone(),
            surface: spec.surface.clone(),
            roughness_rmax_um: None,
            extra: Map::new(),
        },
        tests: Vec::new(),
        reference_parameters: None,
        units: None,
        extra: Map::new(),
    })
}

/// The text of the existing `experiment.json` at `json_path` with `spec` added at the end of
/// its `tests`: the rest of the text as written, so that every value keeps its digits
/// (`98765432109876543210` is not rewritten as `9.876543210987654e+19`, nor `1e-400` as `0.0`),
/// and its key order, spacing and comments-by-field stay. Refused, naming the file, when the
/// edited text would not read back as the set with the test added.
pub(super) fn with_test_appended(
    json_path: &Path,
    meta: &ExperimentMeta,
    spec: &crate::meta::TestSpec,
) -> Result<String, DataError> {
    let text = crate::fsio::read_user_text(
        json_path,
        EXPERIMENT_JSON,
        crate::fsio::MAX_SETTINGS_FILE_BYTES,
    )?;
    let refuse = |why: &str| {
        DataError::Problems(vec![InputProblem::new(
            json_path,
            None,
            Some("tests"),
            format!("cannot add the test to this description without rewriting it: {why} (expected an experiment.json whose `tests` is an array; add the test by hand, or import into a new folder)"),
        )])
    };
    let end = crate::jsonpos::value_end(&text, "tests")
        .ok_or_else(|| refuse("no `tests` array found"))?;
    let chars: Vec<char> = text.chars().collect();
    if end == 0 || chars.get(end - 1) != Some(&']') {
        return Err(refuse("`tests` is not an array"));
    }
    let close = end - 1;
    let last = chars[..close].iter().rposition(|c| !c.is_whitespace());
    let empty = last.is_none_or(|i| chars[i] == '[');
    let entry = serde_json::to_string(spec).map_err(|e| refuse(&e.to_string()))?;
    let before: String = chars[..last.map_or(close, |i| i + 1)].iter().collect();
    let after: String = chars[close..].iter().collect();
    let edited = format!(
        "{before}{}\n    {entry}\n  {after}",
        if empty { "" } else { "," }
    );
    match crate::meta::parse_meta(&edited, json_path) {
        Ok(back) if back == *meta => Ok(edited),
        _ => Err(refuse(
            "the edited text does not read back as the set with the test added",
        )),
    }
}
