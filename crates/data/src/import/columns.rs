//! The columns an import reads, resolved against the header of the lab file.

use std::path::Path;

use super::{ColumnRef, ImportSpec, StressUnit};
use crate::error::{DataError, Problems};
use crate::set::CHANNEL_COLUMNS;

/// A resolved column: 0-based index and its label for messages.
pub(super) type Col = (usize, String);

/// The columns an import reads, resolved against the header.
pub(super) struct Columns {
    pub(super) time: Col,
    pub(super) slip: Col,
    pub(super) shear: Option<(Col, StressUnit)>,
    pub(super) friction: Option<Col>,
    pub(super) normal: Option<(Col, StressUnit)>,
    /// Further channels: their names in a test CSV and their columns.
    pub(super) channels: Vec<(String, Col)>,
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
pub(super) fn resolve_columns(
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
