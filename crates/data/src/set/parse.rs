//! Reading a test CSV's text: the header's columns, each row's numbers, the test they make.

use std::collections::HashMap;
use std::path::Path;

use super::validate::validate_data;
use super::{Channel, TestData, ACCEPTED_COLUMNS, CHANNEL_COLUMNS};
use crate::csvio::{Item, Separator};
use crate::error::{DataError, InputProblem, Problems};
use crate::meta::TestSpec;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Col {
    Time,
    Slip,
    Shear,
    Friction,
    Normal,
    /// A further channel: its index in [`CHANNEL_COLUMNS`].
    Channel(usize),
}

impl Col {
    fn from_name(s: &str) -> Option<Col> {
        let s = s.to_ascii_lowercase();
        match s.as_str() {
            "time_s" => Some(Col::Time),
            "slip_mm" => Some(Col::Slip),
            "shear_kpa" => Some(Col::Shear),
            "friction" => Some(Col::Friction),
            "normal_kpa" => Some(Col::Normal),
            _ => CHANNEL_COLUMNS
                .iter()
                .position(|c| *c == s)
                .map(Col::Channel),
        }
    }
}

/// Parses one numeric cell (as the CSV reader gives it: unquoted); `Err` holds the message,
/// which shows the cell with its control characters visible (a quoted cell may hold a line
/// break).
pub(crate) fn parse_number(cell: &str) -> Result<f64, String> {
    let c = cell.trim();
    if c.is_empty() {
        return Err("empty cell (expected a number)".into());
    }
    match c.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(format!(
            "`{}` is not a finite number (expected a finite decimal number)",
            crate::visible(c)
        )),
        Err(_) => Err(format!(
            "`{}` is not a number (expected a decimal number)",
            crate::visible(c)
        )),
    }
}

/// Text of a comment line without the `#` and one following space.
pub(crate) fn comment_text(trimmed: &str) -> String {
    let body = trimmed.strip_prefix('#').unwrap_or(trimmed);
    body.strip_prefix(' ')
        .unwrap_or(body)
        .trim_end()
        .to_string()
}

/// Parses and validates the text of a test CSV, as [`load_test`](super::load_test) does for a
/// file; problems name `path`.
///
/// ```
/// use subfric_data::{set::parse_test, ControlColumn, TestSpec};
/// let spec = TestSpec::new("a", "a.csv", ControlColumn::Slip, 50.0);
/// let t = parse_test("time_s,slip_mm,shear_kpa\n0,0,0\n1,0.5,20\n", "a.csv".as_ref(), &spec).unwrap();
/// assert_eq!(t.normal_kpa, vec![50.0, 50.0]);
/// let e = parse_test("time_s,slip_mm,shear_kpa\n1,0,0\n1,0.5,20\n", "a.csv".as_ref(), &spec).unwrap_err();
/// assert!(e.to_string().contains("a.csv:3: field `time_s`: time 1 is not after time 1 on line 2"));
/// ```
pub fn parse_test(text: &str, path: &Path, spec: &TestSpec) -> Result<TestData, DataError> {
    parse_test_csv(text, path, spec).map_err(DataError::Problems)
}

/// The header line of a test CSV: which known column each cell is.
struct Header {
    /// 1-based line.
    line: usize,
    /// Known column of each cell (`None`: unknown name, already reported).
    cols: Vec<Option<Col>>,
    /// Names as written.
    names: Vec<String>,
}

impl Header {
    fn idx(&self, c: Col) -> Option<usize> {
        self.cols.iter().position(|x| *x == Some(c))
    }

    /// Parses the header record, reporting unknown, empty, repeated and missing columns.
    fn parse(line_no: usize, names: Vec<String>, path: &Path, pr: &mut Problems) -> Header {
        let mut cols = Vec::with_capacity(names.len());
        let mut seen: HashMap<Col, (usize, &str)> = HashMap::new();
        let expected = format!(
            "{}, or a further channel: {}",
            ACCEPTED_COLUMNS.join(", "),
            CHANNEL_COLUMNS.join(", ")
        );
        for (k, name) in names.iter().enumerate() {
            let col = Col::from_name(name);
            if name.is_empty() {
                pr.add(
                    path,
                    Some(line_no),
                    None,
                    format!("empty column name in the header (expected one of {expected})"),
                );
            } else if col.is_none() {
                pr.add(
                    path,
                    Some(line_no),
                    Some(name),
                    format!("unknown column `{name}` (expected one of {expected})"),
                );
            } else if let Some(c) = col {
                if let Some((first, as_named)) = seen.get(&c) {
                    pr.add(
                        path,
                        Some(line_no),
                        Some(name),
                        format!(
                            "column `{name}` appears twice, as columns {} (`{as_named}`) and {} (expected each column once)",
                            first + 1,
                            k + 1
                        ),
                    );
                } else {
                    seen.insert(c, (k, name));
                }
            }
            cols.push(col);
        }
        let h = Header {
            line: line_no,
            cols,
            names,
        };
        let required = "(expected a header with time_s, slip_mm and shear_kpa or friction)";
        for (c, name) in [(Col::Time, "time_s"), (Col::Slip, "slip_mm")] {
            if h.idx(c).is_none() {
                pr.add(
                    path,
                    Some(line_no),
                    Some(name),
                    format!("missing required column `{name}` {required}"),
                );
            }
        }
        if h.idx(Col::Shear).is_none() && h.idx(Col::Friction).is_none() {
            pr.add(
                path,
                Some(line_no),
                Some("shear_kpa"),
                format!("missing required column `shear_kpa` {required}"),
            );
        }
        h
    }

    /// Parses a data record: its values, a gap (every cell that is not a number is a missing
    /// sample: the columns it misses), or refused (a bad cell, reported).
    fn row(&self, line_no: usize, cells: &[String], path: &Path, pr: &mut Problems) -> RowRead {
        if cells.len() != self.cols.len() {
            pr.add(
                path,
                Some(line_no),
                None,
                format!(
                    "row has {} cell{} (expected {}: {}){}",
                    cells.len(),
                    if cells.len() == 1 { "" } else { "s" },
                    self.cols.len(),
                    self.names.join(","),
                    if cells.iter().any(|c| c.contains(['\n', '\r'])) {
                        "; a quoted cell runs over several lines here: is a closing `\"` missing?"
                    } else {
                        ""
                    }
                ),
            );
            return RowRead::Refused;
        }
        let mut values = vec![f64::NAN; self.cols.len()];
        let mut ok = true;
        let mut missing = Vec::new();
        for (k, cell) in cells.iter().enumerate() {
            if self.cols[k].is_none() {
                continue;
            }
            if crate::gaps::is_missing(cell) {
                // A further channel's missing sample is its own (the row stays); a missing
                // time, slip or stress makes the row a gap.
                if !matches!(self.cols[k], Some(Col::Channel(_))) {
                    missing.push(self.names[k].clone());
                }
                continue;
            }
            match parse_number(cell) {
                Ok(x) => values[k] = x,
                Err(msg) => {
                    ok = false;
                    pr.add(path, Some(line_no), Some(&self.names[k]), msg);
                }
            }
        }
        if !ok {
            return RowRead::Refused;
        }
        if !missing.is_empty() {
            return RowRead::Gap(missing);
        }
        {
            if let (Some(ks), Some(kf)) = (self.idx(Col::Shear), self.idx(Col::Friction)) {
                let normal = self
                    .idx(Col::Normal)
                    .map(|k| (values[k], cells[k].as_str()));
                if let Some(msg) =
                    friction_disagrees((values[kf], &cells[kf]), (values[ks], &cells[ks]), normal)
                {
                    pr.add(path, Some(line_no), Some("friction"), msg);
                }
            }
        }
        RowRead::Values(values)
    }
}

/// A data record as [`Header::row`] reads it.
enum RowRead {
    /// Every known column's value.
    Values(Vec<f64>),
    /// A row without a value in these columns (see [`crate::gaps`]): left out.
    Gap(Vec<String>),
    /// A bad cell, reported.
    Refused,
}

/// Half a unit in the last written digit of a number cell: how far rounding may have moved it.
fn rounding_half_unit(cell: &str) -> f64 {
    let c = cell.trim();
    let (mantissa, exponent) = match c.find(['e', 'E']) {
        Some(i) => (&c[..i], c[i + 1..].parse::<i32>().unwrap_or(0)),
        None => (c, 0),
    };
    let decimals = mantissa
        .find('.')
        .map_or(0, |i| mantissa.len() - i - 1)
        .min(300) as i32;
    0.5 * 10f64.powi(exponent - decimals)
}

/// When a row gives both `friction` and `shear_kpa`, they must agree (friction × normal =
/// shear) within the rounding of the written digits. `normal` is the row's `normal_kpa` cell,
/// if any; the check is done at the end for the spec's constant normal stress.
fn friction_disagrees(
    friction: (f64, &str),
    shear: (f64, &str),
    normal: Option<(f64, &str)>,
) -> Option<String> {
    // Without a normal column the spec's normal stress is applied later (see `check_pairs`).
    let (n, n_cell) = normal?;
    pair_problem(friction, shear, (n, rounding_half_unit(n_cell)))
}

/// The message when friction × normal and shear disagree beyond rounding.
fn pair_problem(friction: (f64, &str), shear: (f64, &str), normal: (f64, f64)) -> Option<String> {
    let (f, n) = (friction.0, normal.0);
    let s = shear.0;
    let tol = rounding_half_unit(friction.1) * n.abs()
        + f.abs() * normal.1
        + rounding_half_unit(shear.1)
        + 1e-9 * s.abs().max(1.0);
    let implied = f * n;
    ((implied - s).abs() > tol).then(|| {
        format!(
            "friction {f} × normal stress {n} kPa = {implied} kPa, but shear_kpa is {s} (expected the two columns to agree within their rounding; give only one of them)"
        )
    })
}

/// Parses and validates the text of a test CSV. Problems name `path`.
pub(crate) fn parse_test_csv(
    text: &str,
    path: &Path,
    spec: &TestSpec,
) -> Result<TestData, Vec<InputProblem>> {
    let mut pr = Problems::default();
    let scale = match spec.column_scale() {
        Ok(s) => s,
        Err((field, msg)) => {
            pr.add(
                path,
                None,
                Some(&format!("units.{field}")),
                format!("test `{}`: {msg}", spec.name),
            );
            return Err(pr.into_vec());
        }
    };
    let mut comments = Vec::new();
    let mut header: Option<Header> = None;
    let mut rows: Vec<(usize, Vec<f64>)> = Vec::new();
    // Rows giving both friction and shear without a normal column: checked against the spec.
    let mut pairs: Vec<(usize, String, String)> = Vec::new();
    // Rows without a value: their lines and the columns they miss.
    let mut gaps: Vec<(usize, Vec<String>)> = Vec::new();
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let read = crate::csvio::read(text, 0, Separator::Byte(b','), |item| match item {
        Item::Comment(_, c) => comments.push(comment_text(&c)),
        Item::Record(line_no, cells) => match &header {
            None => header = Some(Header::parse(line_no, cells.to_vec(), path, &mut pr)),
            Some(h) => match h.row(line_no, cells, path, &mut pr) {
                RowRead::Values(values) => {
                    if let (Some(ks), Some(kf), None) =
                        (h.idx(Col::Shear), h.idx(Col::Friction), h.idx(Col::Normal))
                    {
                        pairs.push((line_no, cells[kf].clone(), cells[ks].clone()));
                    }
                    rows.push((line_no, values));
                }
                RowRead::Gap(columns) => gaps.push((line_no, columns)),
                RowRead::Refused => {}
            },
        },
    });
    if let Err((line, why)) = read {
        pr.add(
            path,
            Some(line),
            None,
            format!(
                "the CSV cannot be read from this line on: {why} (expected comma-separated text)"
            ),
        );
        return Err(pr.into_vec());
    }
    let Some(header) = header else {
        pr.add(
            path,
            None,
            None,
            "no header line (expected a first non-comment line such as `time_s,slip_mm,shear_kpa`)",
        );
        return Err(pr.into_vec());
    };
    for (line, f, s) in &pairs {
        let (fv, sv) = (parse_number(f), parse_number(s));
        if let (Ok(fv), Ok(sv)) = (fv, sv) {
            let normal = (spec.normal_stress_kpa, 0.0);
            if let Some(msg) = pair_problem((fv, f), (sv * scale.stress, s), normal) {
                pr.add(path, Some(*line), Some("friction"), msg);
            }
        }
    }
    assemble_test(header, rows, (comments, gaps), path, spec, scale, pr)
}

/// Builds the test from parsed rows and validates its numbers.
fn assemble_test(
    header: Header,
    rows: Vec<(usize, Vec<f64>)>,
    (comments, gaps): (Vec<String>, Vec<(usize, Vec<String>)>),
    path: &Path,
    spec: &TestSpec,
    scale: crate::meta::ColumnScale,
    mut pr: Problems,
) -> Result<TestData, Vec<InputProblem>> {
    let (Some(it), Some(is)) = (header.idx(Col::Time), header.idx(Col::Slip)) else {
        return Err(pr.into_vec());
    };
    let shear_idx = header.idx(Col::Shear);
    let friction_idx = header.idx(Col::Friction);
    if shear_idx.is_none() && friction_idx.is_none() {
        return Err(pr.into_vec());
    }
    let normal_idx = header.idx(Col::Normal);
    if rows.is_empty() {
        if pr.is_empty() {
            pr.add(
                path,
                Some(header.line),
                None,
                if gaps.is_empty() {
                    "the test has a header but no data rows (expected at least one row of numbers)"
                } else {
                    "the test has a header but every row misses a value (expected at least one row with a number in every column)"
                },
            );
        }
        return Err(pr.into_vec());
    }
    let n = rows.len();
    let mut td = TestData {
        spec: spec.clone(),
        path: path.to_path_buf(),
        time_s: Vec::with_capacity(n),
        slip_mm: Vec::with_capacity(n),
        shear_kpa: Vec::with_capacity(n),
        normal_kpa: Vec::with_capacity(n),
        friction_given: shear_idx.is_none(),
        line_of_row: Vec::with_capacity(n),
        comments,
        reading_notes: Vec::new(),
        channels: header
            .cols
            .iter()
            .enumerate()
            .filter_map(|(k, c)| match c {
                Some(Col::Channel(j)) => Some(Channel {
                    name: CHANNEL_COLUMNS[*j].to_string(),
                    // The normal displacement is a displacement: the set's unit applies.
                    values: rows
                        .iter()
                        .map(|(_, v)| {
                            v[k] * if CHANNEL_COLUMNS[*j] == "normal_disp_mm" {
                                scale.displacement
                            } else {
                                1.0
                            }
                        })
                        .collect(),
                }),
                _ => None,
            })
            .collect(),
    };
    // Columns in the units the set declares are taken to kPa, mm and s here; experiment.json's
    // own normal_stress_kpa is kPa already.
    for (line, v) in &rows {
        let normal = normal_idx.map_or(spec.normal_stress_kpa, |k| v[k] * scale.stress);
        let shear = match shear_idx {
            Some(k) => v[k] * scale.stress,
            None => friction_idx.map_or(f64::NAN, |k| v[k] * normal),
        };
        td.time_s.push(v[it] * scale.time);
        td.slip_mm.push(v[is] * scale.displacement);
        td.shear_kpa.push(shear);
        td.normal_kpa.push(normal);
        td.line_of_row.push(*line);
    }
    // What the reader made of the file: the gaps left out, a coarse clock spread.
    td.reading_notes =
        crate::gaps::reading_notes(path, &gaps, &mut td.time_s, &td.line_of_row, "line");
    pr.extend(validate_data(&td, normal_idx.is_some()));
    pr.into_result(td).map_err(|e| match e {
        DataError::Problems(p) => p,
        other => vec![InputProblem::new(path, None, None, other.to_string())],
    })
}
