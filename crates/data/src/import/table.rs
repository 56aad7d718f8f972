//! A lab file as a table of cells, whatever its layout, and the test the table holds.

use std::path::Path;

use serde_json::Map;

use super::columns::resolve_columns;
use super::rows::{kept_rows, named_channels, read_rows, spec_normal};
use super::text::{content_lines, detect, separator, skip_hint};
use super::{file_name_for, stage, Delimiter, ImportSpec};
use crate::csvio::Item;
use crate::error::{DataError, InputProblem, Problems};
use crate::meta::TestSpec;
use crate::plausible::Warning;
use crate::set::{comment_text, validate_data, TestData};

/// A lab file read as a table of cells, whatever its layout: the header's names (empty
/// without one), the line of the header (or of the first record), the data records with the
/// place each came from, the file's comments, and the notes of what the format's reader did.
pub(super) struct LabTable {
    pub(super) names: Vec<String>,
    pub(super) first_line: usize,
    pub(super) records: Vec<(usize, Vec<String>)>,
    pub(super) delim: Delimiter,
    pub(super) comments: Vec<String>,
    pub(super) notes: Vec<Warning>,
    /// What a record's place counts: a `line` of a text table, or a `value` of a GDS `.ini`
    /// file's channel lists (one line holds a channel's every value).
    pub(super) place: &'static str,
}

/// A delimited lab file as a table: the comments kept, the header split off when it has one.
pub(super) fn delimited_table(
    lf: &Path,
    spec: &ImportSpec,
    text: &str,
) -> Result<LabTable, DataError> {
    let no_data = || {
        DataError::Problems(vec![InputProblem::new(
            lf,
            None,
            None,
            "no data in the file (expected a header line and rows of numbers)",
        )])
    };
    let first = content_lines(text, spec.skip_lines).next();
    let Some((_, first)) = first else {
        return Err(no_data());
    };
    let delim = match spec.delimiter {
        Delimiter::Auto => detect(first),
        d => d,
    };
    let mut comments = Vec::new();
    let mut records: Vec<(usize, Vec<String>)> = Vec::new();
    crate::csvio::read(text, spec.skip_lines, separator(delim), |item| match item {
        Item::Comment(_, c) => comments.push(comment_text(&c)),
        Item::Record(line, cells) => records.push((line, cells.to_vec())),
    })
    .map_err(|(line, why)| {
        DataError::Problems(vec![InputProblem::new(
            lf,
            Some(line),
            None,
            format!("the file cannot be read from this line on: {why} (expected delimited text)"),
        )])
    })?;
    let Some(first_line) = records.first().map(|r| r.0) else {
        return Err(no_data());
    };
    let names = if spec.has_header {
        records.remove(0).1
    } else {
        Vec::new()
    };
    Ok(LabTable {
        names,
        first_line,
        records,
        delim,
        comments,
        notes: Vec::new(),
        place: "line",
    })
}

/// The test a table holds, read through the columns `spec` names; `text` is the file's text
/// when it is a delimited file (for the hint at `--skip` on a header block).
pub(super) fn test_from_table(
    lf: &Path,
    spec: &ImportSpec,
    table: LabTable,
    target: &Path,
    text: Option<&str>,
) -> Result<TestData, DataError> {
    let LabTable {
        names,
        first_line,
        records,
        delim,
        mut comments,
        notes,
        place,
    } = table;
    let hinted = |e: DataError| match (
        e,
        text.and_then(|t| skip_hint(t, spec.skip_lines, spec.has_header, spec.delimiter)),
    ) {
        (DataError::Problems(mut v), Some(hint)) => {
            v.insert(0, InputProblem::new(lf, None, None, hint));
            DataError::Problems(v)
        }
        (e, _) => e,
    };
    let cols = resolve_columns(lf, spec, first_line, &names).map_err(hinted)?;
    let layout = stage::Layout {
        names: &names,
        first_line,
        place,
        decimal_comma: delim != Delimiter::Comma,
    };
    let (records, stage_note) = stage::choose(lf, spec, &layout, &cols.slip, records)?;
    let mut pr = Problems::default();
    let rows = read_rows(lf, spec, &cols, &records, delim, &mut pr);
    if records.is_empty() && stage_note.is_none() {
        pr.add(
            lf,
            Some(first_line),
            None,
            "the file has a header but no data rows (expected rows of numbers)",
        );
    }
    let file_name = lf
        .file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    comments.push(format!("imported from lab file `{file_name}`"));
    let rows = match &spec.keep {
        Some(keep) => kept_rows(lf, keep, rows, place, (&mut comments, &mut pr)),
        None => rows,
    };
    let mut time_s = rows.time_s;
    let mut reading_notes = notes;
    reading_notes.extend(stage_note);
    reading_notes.extend(crate::gaps::reading_notes(
        lf,
        &rows.gaps,
        &mut time_s,
        &rows.line_of_row,
        place,
    ));
    // The written test keeps what the reader did as provenance (a gap, a spread clock, the
    // stage kept, the units a GDS file left unsaid).
    comments.extend(reading_notes.iter().map(|n| n.message.clone()));
    let channels = named_channels(&cols, rows.channels);
    let td = TestData {
        spec: TestSpec {
            name: spec.test_name.trim().to_string(),
            file: file_name_for(&spec.test_name),
            control: spec.control,
            normal_stress_kpa: spec_normal(spec, &cols, &rows.normal_kpa),
            initial: None,
            units: None,
            extra: Map::new(),
        },
        path: lf.to_path_buf(),
        time_s,
        slip_mm: rows.slip_mm,
        shear_kpa: rows.shear_kpa,
        normal_kpa: rows.normal_kpa,
        friction_given: cols.shear.is_none(),
        line_of_row: rows.line_of_row,
        comments,
        reading_notes,
        channels,
    };
    if pr.is_empty() {
        pr.extend(validate_data(&td, cols.normal.is_some()));
    }
    let mut td = pr
        .into_result(td)
        .map_err(hinted)
        .map_err(|e| at_place(e, lf, place))?;
    td.path = target.join(&td.spec.file);
    Ok(td)
}

/// Problems whose place is a value of a GDS `.ini` file's channel lists rather than a line:
/// said as such, so that no message points at a line that holds something else.
fn at_place(e: DataError, lf: &Path, place: &str) -> DataError {
    match e {
        DataError::Problems(v) if place != "line" => DataError::Problems(
            v.into_iter()
                .map(|mut p| {
                    if let (true, Some(k)) = (p.file == lf, p.line) {
                        p.line = None;
                        p.message = format!("{place} {k} of the channel lists: {}", p.message);
                    }
                    p
                })
                .collect(),
        ),
        e => e,
    }
}
