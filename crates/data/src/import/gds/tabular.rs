//! The tabular GDSLAB export: a block of `key,value` lines, then a header row and the rows.

use std::path::Path;

use super::names::{role_of, Role};
use super::{RawChannel, RawFile};
use crate::error::DataError;
use crate::import::Delimiter;

/// The header line of a tabular GDSLAB export: its index among the lines, its cells and its
/// delimiter. A header names a stage number and a displacement (the key-value block above it
/// names neither in one line).
pub(super) fn table_header(text: &str) -> Option<(usize, Vec<String>, Delimiter)> {
    for (i, line) in crate::text::lines(text).enumerate().take(200) {
        let delim = match crate::import::text::detect(line) {
            Delimiter::Tab => Delimiter::Tab,
            Delimiter::Semicolon => Delimiter::Semicolon,
            _ => Delimiter::Comma,
        };
        let cells = cells_of(line, delim);
        let stage = crate::import::stage::column(&cells).is_some();
        let disp = cells.iter().any(|c| matches!(role_of(c), Some(Role::Slip)));
        if stage && disp {
            return Some((i, cells, delim));
        }
    }
    None
}

/// The cells of one line as the CSV reader reads them (quotes removed), trimmed.
fn cells_of(line: &str, delim: Delimiter) -> Vec<String> {
    crate::csvio::cells_of_line(line, crate::import::text::separator(delim))
        .into_iter()
        .map(|c| c.trim().to_string())
        .collect()
}

/// Reads a tabular GDSLAB export: the `key,value` lines above the header are single values.
pub(super) fn read_table(lf: &Path, text: &str) -> Result<RawFile, DataError> {
    let Some((header, names, delim)) = table_header(text) else {
        return Err(DataError::Problems(vec![crate::error::InputProblem::new(
            lf,
            None,
            None,
            "no header naming a stage number and a horizontal displacement (expected a GDS .ini channel file or a GDSLAB table)",
        )]));
    };
    let mut single = Vec::new();
    let mut channels: Vec<RawChannel> = names
        .iter()
        .map(|n| RawChannel {
            name: n.clone(),
            line: header + 1,
            cells: Vec::new(),
            origin: Vec::new(),
        })
        .collect();
    let mut places = Vec::new();
    for (i, line) in crate::text::lines(text).enumerate() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let cells = cells_of(l, delim);
        if i < header {
            if cells.len() >= 2 && !cells[0].is_empty() {
                single.push((cells[0].clone(), cells[1].clone(), i + 1));
            }
            continue;
        }
        if i == header {
            continue;
        }
        for (k, ch) in channels.iter_mut().enumerate() {
            ch.cells.push(cells.get(k).cloned().unwrap_or_default());
        }
        places.push(i + 1);
    }
    Ok(RawFile {
        channels,
        places,
        single,
        place: "line",
        first_line: header + 1,
    })
}
