//! The data rows of a lab file: read into s, mm and kPa, trimmed to the stretch kept.

use std::path::Path;

use super::columns::{Col, Columns};
use super::keep;
use super::text::{resolution, with_precision};
use super::{Delimiter, ImportSpec, Keep, KeepColumn, StressUnit};
use crate::error::Problems;
use crate::set::Channel;

/// Rows read from a lab file, in data units (s, mm, kPa).
#[derive(Default)]
pub(super) struct LabRows {
    pub(super) time_s: Vec<f64>,
    pub(super) slip_mm: Vec<f64>,
    pub(super) shear_kpa: Vec<f64>,
    pub(super) normal_kpa: Vec<f64>,
    pub(super) line_of_row: Vec<usize>,
    /// Rows without a value: their lines and the columns they miss.
    pub(super) gaps: Vec<(usize, Vec<String>)>,
    /// Each further channel's values (NaN where the logger missed a sample).
    pub(super) channels: Vec<Vec<f64>>,
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
pub(super) fn read_rows(
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
pub(super) fn spec_normal(spec: &ImportSpec, cols: &Columns, normal_kpa: &[f64]) -> f64 {
    match (&cols.normal, spec.normal_stress_kpa) {
        (_, Some(x)) => x,
        (Some(_), None) => {
            let mut v: Vec<f64> = normal_kpa
                .iter()
                .copied()
                .filter(|x| x.is_finite())
                .collect();
            // The upper median (subfric-reading's `stats::upper_median`, which this crate
            // sits below): the middle value, or the upper of the middle two.
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
        }
        (None, None) => f64::NAN,
    }
}

/// The further channels read (`values`, in the order of `cols.channels`), each under the name
/// it takes in the test CSV.
pub(super) fn named_channels(cols: &Columns, values: Vec<Vec<f64>>) -> Vec<Channel> {
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
pub(super) fn kept_rows(
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
