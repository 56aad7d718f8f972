//! Import of laboratory files (any delimiter, units and column names) into an experiment set.

mod gds;
mod keep;
mod stage;
mod text;
mod units;

pub use keep::{Keep, KeepColumn};
pub use units::{ColumnRef, Delimiter, ImportFormat, LengthUnit, RateUnit, StressUnit, TimeUnit};

use std::path::{Path, PathBuf};

use serde_json::Map;

use crate::csvio::Item;
use crate::error::{DataError, InputProblem, Problems};
use crate::fsio::{commit_file, stage_file, PathKind};
use crate::meta::{ControlColumn, ExperimentMeta, Interface, TestSpec};
use crate::plausible::Warning;
use crate::set::comment_text;
use crate::set::{
    load_set, meta_json_text, prepare_parent, test_csv_text, validate_data, Channel, ExperimentSet,
    TestData, CHANNEL_COLUMNS, EXPERIMENT_JSON, MAX_MAGNITUDE,
};
use text::{
    content_lines, detect, read_lab_text, resolution, separator, skip_hint, with_precision,
};

/// How to read a lab file.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportSpec {
    /// Cell delimiter.
    pub delimiter: Delimiter,
    /// Lines to skip at the top before the header (or the first data line).
    pub skip_lines: usize,
    /// Whether the first non-comment line after `skip_lines` is a header.
    pub has_header: bool,
    /// Time column.
    pub time: ColumnRef,
    /// Unit of the time column.
    pub time_unit: TimeUnit,
    /// Slip column.
    pub slip: ColumnRef,
    /// Unit of the slip column.
    pub slip_unit: LengthUnit,
    /// Shear column and its unit (or give `friction`).
    pub shear: Option<(ColumnRef, StressUnit)>,
    /// Friction (shear / normal) column, used when `shear` is `None`.
    pub friction: Option<ColumnRef>,
    /// Normal stress column and its unit.
    pub normal: Option<(ColumnRef, StressUnit)>,
    /// Constant normal stress, kPa, when there is no normal column.
    pub normal_stress_kpa: Option<f64>,
    /// Contact area [mm²] a force column (N, kN, lbf) is divided by (3600 for a 60 mm square
    /// shear box).
    pub area_mm2: Option<f64>,
    /// Which column the apparatus imposed.
    pub control: ControlColumn,
    /// Name of the test (unique within the set); the CSV is named after it.
    pub test_name: String,
    /// Name of the set (used when a new set is created).
    pub set_name: String,
    /// Title of a new set (default: the set name).
    pub title: Option<String>,
    /// Soil of a new set.
    pub soil: Option<String>,
    /// Surface of a new set.
    pub surface: Option<String>,
    /// Source of a new set (default: the lab file's name).
    pub source: Option<String>,
    /// The stretch of the record to keep (an aborted stage, the end-of-travel drop trimmed
    /// off); `None` keeps every row.
    pub keep: Option<Keep>,
    /// How the file is laid out: a delimited table read through the columns above, or a GDS
    /// export whose channels are mapped by their names; `Auto` tells them apart.
    pub format: ImportFormat,
    /// The stage to keep, by its number or name, when the file holds several (a stage
    /// column, or a GDS file's stages); `None` keeps the one with the longest shear travel and
    /// says so.
    pub stage: Option<String>,
    /// Further channels to carry with the test: a name of [`crate::CHANNEL_COLUMNS`] and the
    /// column holding it, in that name's unit (a delimited file; a GDS file's are found by
    /// their names).
    pub channels: Vec<(String, ColumnRef)>,
    /// Unit of the rate of shear displacement a GDS file states without one (the time is
    /// then the displacement over that rate).
    pub rate_unit: Option<RateUnit>,
}

impl Default for ImportSpec {
    /// Comma-or-auto file with a header `time_s, slip_mm, shear_kpa`, slip control.
    fn default() -> Self {
        ImportSpec {
            delimiter: Delimiter::Auto,
            skip_lines: 0,
            has_header: true,
            time: ColumnRef::Name("time_s".into()),
            time_unit: TimeUnit::S,
            slip: ColumnRef::Name("slip_mm".into()),
            slip_unit: LengthUnit::Mm,
            shear: Some((ColumnRef::Name("shear_kpa".into()), StressUnit::KPa)),
            friction: None,
            normal: None,
            normal_stress_kpa: None,
            area_mm2: None,
            control: ControlColumn::Slip,
            test_name: "test".into(),
            set_name: "imported".into(),
            title: None,
            soil: None,
            surface: None,
            source: None,
            keep: None,
            format: ImportFormat::Auto,
            stage: None,
            channels: Vec::new(),
            rate_unit: None,
        }
    }
}

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

/// A force column needs the contact area, and an area is only for a force column (given
/// without one, the force would likely be read as a stress).
fn area_problems(lf: &Path, spec: &ImportSpec, pr: &mut Problems) {
    let forces: Vec<(&str, StressUnit)> = [("shear", &spec.shear), ("normal", &spec.normal)]
        .into_iter()
        .filter_map(|(what, c)| c.as_ref().map(|(_, u)| (what, *u)))
        .filter(|(_, u)| u.is_force())
        .collect();
    match spec.area_mm2 {
        None => {
            for (what, u) in &forces {
                pr.add(
                    lf,
                    None,
                    Some(what),
                    format!(
                        "the {what} column is a force in {} (expected the contact area in mm² to turn it into a stress: --area, e.g. 3600 for a 60 mm square shear box)",
                        u.name()
                    ),
                );
            }
        }
        Some(a) if !(a > 0.0 && a.is_finite()) => pr.add(
            lf,
            None,
            Some("area"),
            format!(
                "contact area {} mm² is {} (expected the area in mm², a finite number > 0)",
                crate::text::short_number(a),
                if a.is_nan() { "not a number" } else if a <= 0.0 { "not positive" } else { "infinite" }
            ),
        ),
        Some(a) if forces.iter().any(|(_, u)| !u.kpa_per_unit(Some(a)).is_some_and(|k| k.is_finite() && k > 0.0)) => pr.add(
            lf,
            None,
            Some("area"),
            format!(
                "contact area {} mm² is so small that a force over it is beyond the doubles (expected the area in mm², e.g. 3600 for a 60 mm square shear box)",
                crate::text::short_number(a)
            ),
        ),
        Some(a) if forces.is_empty() => pr.add(
            lf,
            None,
            Some("area"),
            format!(
                "a contact area of {a} mm² was given but no column is a force (expected --shear-unit or --normal-unit N, kN or lbf with --area; a stress needs no area)"
            ),
        ),
        Some(_) => {}
    }
}

/// Problems of the import options themselves, before the file is read.
fn spec_problems(lf: &Path, spec: &ImportSpec) -> Problems {
    let mut pr = Problems::default();
    if spec.test_name.trim().is_empty() {
        pr.add(
            lf,
            None,
            Some("test_name"),
            "empty test name (expected a name for the test)",
        );
    }
    if spec.shear.is_some() && spec.friction.is_some() {
        pr.add(
            lf,
            None,
            Some("friction"),
            "both a shear and a friction column were given (expected one of them: the test is written with the one given, and the other would be dropped)",
        );
    }
    if spec.shear.is_none() && spec.friction.is_none() {
        pr.add(
            lf,
            None,
            Some("shear"),
            "neither a shear nor a friction column was given (expected one of them)",
        );
    }
    if spec.normal.is_none() && spec.normal_stress_kpa.is_none() {
        pr.add(
            lf,
            None,
            Some("normal"),
            "the normal stress is unknown (expected a normal column or a constant normal stress in kPa)",
        );
    }
    for (name, field, what) in [
        (&spec.test_name, "test_name", "a test name"),
        (&spec.set_name, "set_name", "a set name"),
    ] {
        if let Some(msg) = crate::text::name_too_long(name.trim(), what) {
            pr.add(lf, None, Some(field), msg);
        }
    }
    area_problems(lf, spec, &mut pr);
    if let Some(x) = spec.normal_stress_kpa {
        if x > MAX_MAGNITUDE {
            pr.add(
                lf,
                None,
                Some("normal_stress_kpa"),
                format!("normal stress {x:e} kPa is beyond {MAX_MAGNITUDE:e} kPa (expected a measured normal stress in kPa)"),
            );
        } else if !(x > 0.0 && x.is_finite()) {
            pr.add(
                lf,
                None,
                Some("normal_stress_kpa"),
                format!("normal stress {x} kPa is not positive (expected > 0)"),
            );
        }
    }
    pr
}

/// A resolved column: 0-based index and its label for messages.
type Col = (usize, String);

/// The columns an import reads, resolved against the header.
struct Columns {
    time: Col,
    slip: Col,
    shear: Option<(Col, StressUnit)>,
    friction: Option<Col>,
    normal: Option<(Col, StressUnit)>,
    /// Further channels: their names in a test CSV and their columns.
    channels: Vec<(String, Col)>,
}

/// Resolves one column reference against the header `names` (empty without a header).
fn resolve(
    lf: &Path,
    header_line: usize,
    names: &[String],
    has_header: bool,
    c: &ColumnRef,
    what: &str,
    pr: &mut Problems,
) -> Option<Col> {
    match c {
        ColumnRef::Index(i) => {
            let label = names
                .get(i.wrapping_sub(1))
                .cloned()
                .unwrap_or_else(|| format!("column {i}"));
            Some((i.saturating_sub(1), label))
        }
        ColumnRef::Name(n) if !has_header => {
            pr.add(
                lf,
                Some(header_line),
                Some(what),
                format!("column `{n}` named but the file has no header (expected a 1-based column index)"),
            );
            None
        }
        ColumnRef::Name(n) => match names
            .iter()
            .position(|h| h.trim().eq_ignore_ascii_case(n.trim()))
        {
            Some(k) => {
                let same = |h: &String| h.trim().eq_ignore_ascii_case(n.trim());
                if let Some(j) = names[k + 1..].iter().position(same) {
                    pr.add(
                        lf,
                        Some(header_line),
                        Some(what),
                        format!(
                            "columns {} (`{}`) and {} (`{}`) are both named `{n}` (expected one column of that name, or the column's 1-based index)",
                            k + 1,
                            names[k],
                            k + j + 2,
                            names[k + j + 1]
                        ),
                    );
                    return None;
                }
                Some((k, names[k].clone()))
            }
            None => {
                pr.add(
                    lf,
                    Some(header_line),
                    Some(what),
                    format!(
                        "no column `{n}` in the header (expected one of: {})",
                        names.join(", ")
                    ),
                );
                None
            }
        },
    }
}

/// Resolves every column the spec names; all problems are reported together.
fn resolve_columns(
    lf: &Path,
    spec: &ImportSpec,
    header_line: usize,
    names: &[String],
) -> Result<Columns, DataError> {
    let mut pr = Problems::default();
    let res = |c: &ColumnRef, what: &str, pr: &mut Problems| {
        resolve(lf, header_line, names, spec.has_header, c, what, pr)
    };
    let time = res(&spec.time, "time", &mut pr);
    let slip = res(&spec.slip, "slip", &mut pr);
    let shear = spec
        .shear
        .as_ref()
        .map(|(c, u)| (res(c, "shear", &mut pr), *u));
    let friction = match (&spec.shear, &spec.friction) {
        (None, Some(c)) => Some(res(c, "friction", &mut pr)),
        _ => None,
    };
    let normal = spec
        .normal
        .as_ref()
        .map(|(c, u)| (res(c, "normal", &mut pr), *u));
    let mut channels = Vec::new();
    for (name, c) in &spec.channels {
        let name = name.trim();
        if !CHANNEL_COLUMNS.contains(&name) {
            pr.add(
                lf,
                None,
                Some(name),
                format!(
                    "`{name}` is not a channel a test carries (expected one of: {})",
                    CHANNEL_COLUMNS.join(", ")
                ),
            );
        } else if channels.iter().any(|(n, _)| n == name) {
            pr.add(
                lf,
                None,
                Some(name),
                format!("channel `{name}` given twice (expected one column for it)"),
            );
        } else if let Some(col) = res(c, name, &mut pr) {
            channels.push((name.to_string(), col));
        }
    }
    match (time, slip) {
        (Some(time), Some(slip)) if pr.is_empty() => Ok(Columns {
            time,
            slip,
            shear: shear.and_then(|(c, u)| c.map(|c| (c, u))),
            friction: friction.flatten(),
            normal: normal.and_then(|(c, u)| c.map(|c| (c, u))),
            channels,
        }),
        _ => Err(DataError::Problems(pr.into_vec())),
    }
}

/// Rows read from a lab file, in data units (s, mm, kPa).
#[derive(Default)]
struct LabRows {
    time_s: Vec<f64>,
    slip_mm: Vec<f64>,
    shear_kpa: Vec<f64>,
    normal_kpa: Vec<f64>,
    line_of_row: Vec<usize>,
    /// Rows without a value: their lines and the columns they miss.
    gaps: Vec<(usize, Vec<String>)>,
    /// Each further channel's values (NaN where the logger missed a sample).
    channels: Vec<Vec<f64>>,
}

impl LabRows {
    /// Rows `kept` only (the gaps are kept as read: they are said either way).
    fn within(self, kept: std::ops::Range<usize>) -> LabRows {
        let cut = |v: Vec<f64>| v[kept.clone()].to_vec();
        LabRows {
            line_of_row: self.line_of_row[kept.clone()].to_vec(),
            time_s: cut(self.time_s),
            slip_mm: cut(self.slip_mm),
            shear_kpa: cut(self.shear_kpa),
            normal_kpa: cut(self.normal_kpa),
            gaps: self.gaps,
            channels: self.channels.into_iter().map(cut).collect(),
        }
    }
}

/// Reads one cell of a row: its number and the resolution of its digits; a missing or bad
/// cell is reported and gives `None`.
fn cell_reading(
    lf: &Path,
    line_no: usize,
    cells: &[String],
    col: &Col,
    decimal_comma: bool,
    pr: &mut Problems,
) -> Option<(f64, Option<f64>)> {
    let Some(cell) = cells.get(col.0) else {
        pr.add(
            lf,
            Some(line_no),
            Some(&col.1),
            format!(
                "row has {} cells (expected at least {} to reach {})",
                cells.len(),
                col.0 + 1,
                col.1
            ),
        );
        return None;
    };
    let mut c = cell.clone();
    if decimal_comma && c.contains(',') && !c.contains('.') {
        c = c.replace(',', ".");
    }
    match crate::set::parse_number(&c) {
        Ok(x) => Some((x, resolution(&c))),
        Err(_) => {
            // The message quotes the cell as the file has it, not its decimal-comma reading.
            let msg = crate::set::parse_number(cell)
                .err()
                .unwrap_or_else(|| format!("`{cell}` is not a number (expected a decimal number)"));
            pr.add(lf, Some(line_no), Some(&col.1), msg);
            None
        }
    }
}

/// Reads every data line; rows with a bad cell are reported and left out. Values are
/// converted to s, mm and kPa and written with the precision of the input (a conversion
/// adds no digits the lab did not record: 4.93 µm is 0.00493 mm).
fn read_rows(
    lf: &Path,
    spec: &ImportSpec,
    cols: &Columns,
    data_records: &[(usize, Vec<String>)],
    delim: Delimiter,
    pr: &mut Problems,
) -> LabRows {
    let mut rows = LabRows {
        channels: vec![Vec::new(); cols.channels.len()],
        ..LabRows::default()
    };
    let decimal_comma = delim != Delimiter::Comma;
    let stress = |u: StressUnit| u.kpa_per_unit(spec.area_mm2).unwrap_or(f64::NAN);
    for (line_no, cells) in data_records {
        let (line_no, cells) = (*line_no, cells.as_slice());
        // A row without a value in a column the test reads is a logger's missing sample: a
        // gap, left out and said (see crate::gaps).
        let used = [Some(&cols.time), Some(&cols.slip)]
            .into_iter()
            .chain([
                cols.shear.as_ref().map(|c| &c.0),
                cols.friction.as_ref(),
                cols.normal.as_ref().map(|c| &c.0),
            ])
            .flatten();
        let missing: Vec<String> = used
            .filter(|c| cells.get(c.0).is_some_and(|x| crate::gaps::is_missing(x)))
            .map(|c| c.1.clone())
            .collect();
        if !missing.is_empty() {
            rows.gaps.push((line_no, missing));
            continue;
        }
        let get = |col: &Col, factor: f64, pr: &mut Problems| {
            cell_reading(lf, line_no, cells, col, decimal_comma, pr)
                .map(|(x, q)| with_precision(x, q, factor))
        };
        let tv = get(&cols.time, spec.time_unit.to_s(), pr);
        let sv = get(&cols.slip, spec.slip_unit.to_mm(), pr);
        let nv = match &cols.normal {
            Some((c, u)) => get(c, stress(*u), pr),
            None => Some(spec.normal_stress_kpa.unwrap_or(f64::NAN)),
        };
        let qv = match (&cols.shear, &cols.friction) {
            (Some((c, u)), _) => get(c, stress(*u), pr),
            (None, Some(c)) => cell_reading(lf, line_no, cells, c, decimal_comma, pr)
                .zip(nv)
                .map(|((f, q), n)| with_precision(f, q, n)),
            (None, None) => Some(f64::NAN),
        };
        // A further channel's missing sample is a missing value, not a gap of the row.
        let channel_values: Vec<Option<f64>> = cols
            .channels
            .iter()
            .map(|(_, c)| match cells.get(c.0) {
                Some(x) if crate::gaps::is_missing(x) => Some(f64::NAN),
                _ => cell_reading(lf, line_no, cells, c, decimal_comma, pr).map(|(x, _)| x),
            })
            .collect();
        if channel_values.iter().any(Option::is_none) {
            continue;
        }
        if let (Some(tv), Some(sv), Some(qv), Some(nv)) = (tv, sv, qv, nv) {
            for (values, v) in rows.channels.iter_mut().zip(&channel_values) {
                values.push(v.unwrap_or(f64::NAN));
            }
            rows.time_s.push(tv);
            rows.slip_mm.push(sv);
            rows.shear_kpa.push(qv);
            rows.normal_kpa.push(nv);
            rows.line_of_row.push(line_no);
        }
    }
    rows
}

/// The test's constant normal stress: the given one, else the median of the normal column.
fn spec_normal(spec: &ImportSpec, cols: &Columns, normal_kpa: &[f64]) -> f64 {
    match (&cols.normal, spec.normal_stress_kpa) {
        (_, Some(x)) => x,
        (Some(_), None) => {
            let mut v: Vec<f64> = normal_kpa
                .iter()
                .copied()
                .filter(|x| x.is_finite())
                .collect();
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
        }
        (None, None) => f64::NAN,
    }
}

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

/// A delimited lab file as a table: the comments kept, the header split off when it has one.
fn delimited_table(lf: &Path, spec: &ImportSpec, text: &str) -> Result<LabTable, DataError> {
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

/// The further channels read (`values`, in the order of `cols.channels`), each under the name
/// it takes in the test CSV.
fn named_channels(cols: &Columns, values: Vec<Vec<f64>>) -> Vec<Channel> {
    cols.channels
        .iter()
        .zip(values)
        .map(|((name, _), values)| Channel {
            name: name.clone(),
            values,
        })
        .collect()
}

/// The rows of `rows` that `--keep` (`keep`) keeps, with a note of the trim among the test's
/// `comments`, and a problem in `pr` when it keeps none of a record that has rows.
fn kept_rows(
    lf: &Path,
    keep: &Keep,
    rows: LabRows,
    place: &str,
    (comments, pr): (&mut Vec<String>, &mut Problems),
) -> LabRows {
    let kept = keep.rows(match keep.column {
        KeepColumn::Time => &rows.time_s,
        KeepColumn::Slip => &rows.slip_mm,
    });
    if kept.is_empty() && !rows.time_s.is_empty() {
        pr.add(
            lf,
            None,
            Some(keep.column.name()),
            format!("--keep {keep} keeps no row (expected a stretch the record reaches)"),
        );
    }
    comments.push(keep::trim_note(keep, &rows.line_of_row, &kept, place));
    rows.within(kept)
}

/// The test a table holds, read through the columns `spec` names; `text` is the file's text
/// when it is a delimited file (for the hint at `--skip` on a header block).
fn test_from_table(
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

/// The description of the set `test` joins: the existing one (refusing a duplicate test name
/// or file), or a new one.
fn set_meta_for(
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
fn with_test_appended(
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
