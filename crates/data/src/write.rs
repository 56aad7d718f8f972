//! Writing experiment sets: the CSV text of a test, `experiment.json`, and a whole set written
//! atomically (every file staged, then committed).

use std::collections::HashSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::error::{DataError, InputProblem, Problems};
use crate::fsio::{commit_file, stage_file};
use crate::meta::{file_name_problem, ExperimentMeta};
use crate::set::{validate_data, ExperimentSet, TestData, EXPERIMENT_JSON};

/// Writes the CSV text of a test: comments, header `time_s,slip_mm,shear_kpa` (plus
/// `normal_kpa` when the normal stress varies), one row per line (through the `csv` crate's
/// writer, [`crate::csvio::writer`]). A comment holding line breaks is written as one comment
/// line per line, so that no part of it is read as data.
pub fn test_csv_text(test: &TestData) -> String {
    let mut s = String::new();
    for c in &test.comments {
        for line in crate::text::lines(c).chain(c.is_empty().then_some("")) {
            if line.is_empty() {
                s.push_str("#\n");
            } else {
                let _ = writeln!(s, "# {line}");
            }
        }
    }
    let with_normal = test.normal_varies();
    let mut header = vec!["time_s", "slip_mm", "shear_kpa"];
    if with_normal {
        header.push("normal_kpa");
    }
    header.extend(test.channels.iter().map(|c| c.name.as_str()));
    let value = |v: &[f64], i: usize| v.get(i).copied().unwrap_or(f64::NAN).to_string();
    // A channel's missing sample is written as an empty cell, which reads back as missing.
    let channel_value = |v: &[f64], i: usize| match v.get(i) {
        Some(x) if x.is_finite() => x.to_string(),
        _ => String::new(),
    };
    let rows = (0..test.len()).map(|i| {
        let mut row = vec![
            test.time_s[i].to_string(),
            value(&test.slip_mm, i),
            value(&test.shear_kpa, i),
        ];
        if with_normal {
            row.push(value(&test.normal_kpa, i));
        }
        row.extend(test.channels.iter().map(|c| channel_value(&c.values, i)));
        row
    });
    let header = header.into_iter().map(String::from).collect::<Vec<_>>();
    s.push_str(&crate::csvio::text_of(std::iter::once(header).chain(rows)));
    s
}

/// Pretty JSON text of an `experiment.json`.
pub fn meta_json_text(meta: &ExperimentMeta) -> Result<String, DataError> {
    serde_json::to_string_pretty(meta)
        .map(|mut s| {
            s.push('\n');
            s
        })
        .map_err(|e| {
            DataError::Problems(vec![InputProblem::new(
                EXPERIMENT_JSON,
                None,
                None,
                format!("cannot serialise the description: {e}"),
            )])
        })
}

/// Creates the folder of `file` (inside `dir`) and checks that it does not lead out of `dir`
/// through a symbolic link.
pub(crate) fn prepare_parent(dir: &Path, file: &Path) -> Result<(), DataError> {
    let Some(parent) = file.parent() else {
        return Ok(());
    };
    std::fs::create_dir_all(parent).map_err(|e| DataError::io(parent, e))?;
    let inside = match (std::fs::canonicalize(dir), std::fs::canonicalize(parent)) {
        (Ok(d), Ok(p)) => p.starts_with(d),
        _ => false,
    };
    if inside {
        Ok(())
    } else {
        Err(DataError::Problems(vec![InputProblem::new(
            parent,
            None,
            None,
            format!(
                "the folder leads outside the set folder {} through a symbolic link (expected a folder inside the set)",
                dir.display()
            ),
        )]))
    }
}

/// Writes an experiment set to `dir` (created if needed): `experiment.json` from `set.meta` and
/// one CSV per test (named by its spec's `file`), keeping the comment lines.
///
/// Friction data are written as `shear_kpa`; the `normal_kpa` column is written only when the
/// normal stress varies. Every file is first written in full to a temporary file beside it,
/// then the CSVs and last `experiment.json` replace their old versions by renaming: a failure
/// (a full disk, a kill) leaves each file either as it was or complete, and a symbolic link in
/// the folder is replaced, never written through. Whether replacing an existing set is wanted
/// is the caller's decision.
pub fn write_set(set: &ExperimentSet, dir: &Path) -> Result<(), DataError> {
    let mut pr = Problems::default();
    let json = dir.join(EXPERIMENT_JSON);
    let mut files = HashSet::new();
    for t in &set.tests {
        if let Some(msg) = file_name_problem(&t.spec.file) {
            pr.add(
                &json,
                None,
                Some("file"),
                format!("test `{}`: {msg}", t.spec.name),
            );
        } else if !files.insert(t.spec.file.clone()) {
            pr.add(
                &json,
                None,
                Some("file"),
                format!(
                    "file `{}` is used by two tests (expected one CSV per test)",
                    t.spec.file
                ),
            );
        }
    }
    for t in &set.tests {
        let target = dir.join(&t.spec.file);
        let mut copy = t.clone();
        copy.path = target;
        pr.extend(validate_data(&copy, true));
    }
    pr.into_result(())?;
    std::fs::create_dir_all(dir).map_err(|e| DataError::io(dir, e))?;
    let mut staged: Vec<(PathBuf, PathBuf)> = Vec::new();
    let mut stage = |path: PathBuf, text: String| -> Result<(), DataError> {
        prepare_parent(dir, &path)?;
        let tmp = stage_file(&path, text.as_bytes())?;
        staged.push((tmp, path));
        Ok(())
    };
    let mut result = Ok(());
    for t in &set.tests {
        result = stage(dir.join(&t.spec.file), test_csv_text(t));
        if result.is_err() {
            break;
        }
    }
    if result.is_ok() {
        // The CSVs are written in kPa, mm and s whatever units the set was read in: a `units`
        // block kept in experiment.json would convert them a second time on the next load.
        let mut meta = set.meta.clone();
        meta.units = None;
        for t in &mut meta.tests {
            t.units = None;
        }
        result = meta_json_text(&meta).and_then(|text| stage(json.clone(), text));
    }
    if let Err(e) = result {
        for (tmp, _) in &staged {
            let _ = std::fs::remove_file(tmp);
        }
        return Err(e);
    }
    // experiment.json is staged last, so it is committed last.
    let mut staged = staged.into_iter();
    for (tmp, path) in staged.by_ref() {
        if let Err(e) = commit_file(&tmp, &path) {
            for (tmp, _) in staged {
                let _ = std::fs::remove_file(tmp);
            }
            return Err(e);
        }
    }
    Ok(())
}
