//! The GDS `.ini` channel file: `[sections]`, `Key="v1,v2,…"` channels and `Key=v` single values.

use std::path::Path;

use super::names::{role_of, Role};
use super::{RawChannel, RawFile};
use crate::error::{DataError, Problems};

/// The lines of an `.ini` file with their 1-based numbers, without blanks and comments.
pub(super) fn ini_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    crate::text::lines(text)
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with(';') && !l.starts_with('#'))
}

/// One `[section]` of an `.ini` file: its name, its channels and its single values.
#[derive(Default)]
struct Section {
    name: String,
    channels: Vec<RawChannel>,
    single: Vec<(String, String, usize)>,
}

/// Whether a `Key=` value is a channel: a list of several values that are mostly numbers, or
/// any list under a stage's or a time's name (stage labels and clock times are words too; a
/// clock time is then refused at its place, not taken for a single value). A text with a comma
/// in it (`"sand, dense"`) is not one.
fn is_channel(key: &str, cells: &[String]) -> bool {
    let numbers = cells
        .iter()
        .filter(|c| crate::set::parse_number(c).is_ok())
        .count();
    cells.len() > 1
        && (2 * numbers >= cells.len() || matches!(role_of(key), Some(Role::Stage | Role::Time(_))))
}

/// The sections of an `.ini` channel file (the first one unnamed: the lines before any
/// `[section]`), each with its channels (`Key="a,b,c"`) and single values (`Key=v`); a line that
/// is neither, or a channel given twice in a section, is a problem added to `pr`.
fn ini_sections(lf: &Path, text: &str, pr: &mut Problems) -> Vec<Section> {
    let mut sections: Vec<Section> = vec![Section::default()];
    for (line, l) in ini_lines(text) {
        if l.starts_with('[') && l.ends_with(']') {
            sections.push(Section {
                name: l[1..l.len() - 1].trim().to_string(),
                ..Section::default()
            });
            continue;
        }
        let Some((key, value)) = l.split_once('=') else {
            pr.add(
                lf,
                Some(line),
                None,
                format!(
                    "`{}` is neither a `[section]` nor a `Key=value` line (expected a GDS .ini channel file)",
                    l.chars().take(60).collect::<String>()
                ),
            );
            continue;
        };
        let key = key.trim().trim_matches('"').to_string();
        let value = value.trim();
        let value = value
            .strip_prefix('"')
            .and_then(|v| v.strip_suffix('"'))
            .unwrap_or(value);
        let cells: Vec<String> = value.split(',').map(|c| c.trim().to_string()).collect();
        let sec = sections.last_mut().expect("one section at least");
        if is_channel(&key, &cells) {
            if let Some(prev) = sec
                .channels
                .iter()
                .find(|c| c.name.eq_ignore_ascii_case(&key))
            {
                pr.add(
                    lf,
                    Some(line),
                    Some(&key),
                    format!(
                        "channel `{key}` given again (first on line {}) (expected one line per channel in a section)",
                        prev.line
                    ),
                );
                continue;
            }
            let origin = (1..=cells.len()).map(|k| (line, k)).collect();
            sec.channels.push(RawChannel {
                name: key,
                line,
                cells,
                origin,
            });
        } else {
            sec.single.push((key, value.to_string(), line));
        }
    }
    sections
}

/// Adds to `pr` every channel of a data section whose count of values differs from its first
/// channel's: every channel has one value per row of its section.
fn check_section_lengths(lf: &Path, data: &[Section], pr: &mut Problems) {
    for sec in data {
        let first = &sec.channels[0];
        for c in &sec.channels[1..] {
            if c.cells.len() != first.cells.len() {
                pr.add(
                    lf,
                    Some(c.line),
                    Some(&c.name),
                    format!(
                        "{} values (expected {}, as many as channel `{}` on line {} has)",
                        c.cells.len(),
                        first.cells.len(),
                        first.name,
                        first.line
                    ),
                );
            }
        }
    }
}

/// The single values of the file (`file_level`: those outside the data's sections) and of the
/// data's sections: a section's value is kept single where every section says the same (or only
/// one says it), else its key is returned among the channels of per-row values (each row takes
/// its section's value).
fn singles_and_per_row(
    data: &[Section],
    file_level: &[(String, String, usize)],
) -> (Vec<(String, String, usize)>, Vec<String>) {
    let mut single = file_level.to_vec();
    let mut per_row: Vec<String> = Vec::new();
    for sec in data {
        for (key, value, line) in &sec.single {
            let same_key = |k: &String| k.eq_ignore_ascii_case(key);
            let values: Vec<&str> = data
                .iter()
                .filter_map(|d| {
                    d.single
                        .iter()
                        .find(|x| same_key(&x.0))
                        .map(|x| x.1.as_str())
                })
                .collect();
            let differ = values.iter().any(|v| v != &values[0]);
            if differ {
                if !per_row.iter().any(same_key) {
                    per_row.push(key.clone());
                }
            } else if !single.iter().any(|x| same_key(&x.0)) {
                single.push((key.clone(), value.clone(), *line));
            }
        }
    }
    (single, per_row)
}

/// Reads an `.ini` channel file: `[sections]` with data become stages (a stage channel
/// otherwise says them), `Key="a,b,c"` lines channels, `Key=v` lines single values. A single
/// value given in the sections of the data with different values there (each stage's own rate
/// or area) becomes a channel, each row taking its section's value.
pub(super) fn read_ini(lf: &Path, text: &str) -> Result<RawFile, DataError> {
    let mut pr = Problems::default();
    let sections = ini_sections(lf, text, &mut pr);
    let mut first_line = 1;
    let (data, rest): (Vec<Section>, Vec<Section>) =
        sections.into_iter().partition(|s| !s.channels.is_empty());
    check_section_lengths(lf, &data, &mut pr);
    if data.is_empty() {
        pr.add(
            lf,
            None,
            None,
            "no channel in the file (expected `Key=\"v1,v2,…\"` lines, one per channel)",
        );
    }
    pr.into_result(())?;
    if let Some(sec) = data.first() {
        first_line = sec.channels[0].line;
    }
    let file_level: Vec<(String, String, usize)> =
        rest.into_iter().flat_map(|s| s.single).collect();
    let (single, per_row) = singles_and_per_row(&data, &file_level);
    // Channels over the sections: a section lacking a channel others have leaves its rows
    // without a value there (a gap where the test reads it).
    let mut names: Vec<String> = Vec::new();
    for sec in &data {
        for c in &sec.channels {
            if !names.iter().any(|n| n.eq_ignore_ascii_case(&c.name)) {
                names.push(c.name.clone());
            }
        }
    }
    let mut channels: Vec<RawChannel> = names
        .iter()
        .chain(&per_row)
        .map(|n| RawChannel {
            name: n.clone(),
            line: 0,
            cells: Vec::new(),
            origin: Vec::new(),
        })
        .collect();
    let mut stage_cells = Vec::new();
    for (k, sec) in data.iter().enumerate() {
        let rows = sec.channels[0].cells.len();
        for ch in &mut channels {
            let same = |n: &String| n.eq_ignore_ascii_case(&ch.name);
            if let Some(c) = sec.channels.iter().find(|c| same(&c.name)) {
                if ch.line == 0 {
                    ch.line = c.line;
                }
                ch.cells.extend(c.cells.iter().cloned());
                ch.origin.extend(c.origin.iter().copied());
                continue;
            }
            // A single value of this section (or the file's) for each of its rows.
            let given = sec
                .single
                .iter()
                .chain(&file_level)
                .find(|x| same(&x.0))
                .filter(|_| per_row.iter().any(same));
            if let (Some((_, _, line)), 0) = (given, ch.line) {
                ch.line = *line;
            }
            let cell = given.map(|x| x.1.clone()).unwrap_or_default();
            let at = given.map_or(0, |x| x.2);
            ch.cells.extend(std::iter::repeat_n(cell, rows));
            ch.origin.extend(std::iter::repeat_n((at, 1), rows));
        }
        let label = if sec.name.is_empty() {
            (k + 1).to_string()
        } else {
            sec.name.clone()
        };
        stage_cells.extend(std::iter::repeat_n(label, rows));
    }
    if data.len() > 1 {
        let n = stage_cells.len();
        channels.push(RawChannel {
            name: "Stage".into(),
            line: 0,
            cells: stage_cells,
            origin: vec![(0, 0); n],
        });
    }
    let n = channels[0].cells.len();
    Ok(RawFile {
        channels,
        places: (1..=n).collect(),
        single,
        place: "value",
        first_line,
    })
}
