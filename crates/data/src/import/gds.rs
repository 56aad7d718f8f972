//! GDS direct- and interface-shear exports, read by their channels' names.
//!
//! Two layouts: the `.ini` channel file — one `Key="v1,v2,…"` line per channel, single values
//! (the box area, the rate of shear displacement) as `Key=v`, stages as `[sections]` or a
//! stage channel — and the tabular GDSLAB export — a block of `key,value` lines, then a header
//! row (`Stage Number`, `Horizontal Displacement (mm)`, …) and the rows. The channels are
//! mapped onto the test's columns by what their names say, in the units the names state; a
//! name that states none is read in GDS's own (mm, kN, kPa, mm², s) and a note says so. A file
//! without a time gets it from the displacement and the stated rate, whose unit must be known
//! (`--rate-unit` when the file does not say it). A force becomes a stress over the area of
//! its row (an area channel: an area-corrected test) or the file's area. Channels the test
//! does not carry are named in a note, never dropped unsaid.

use std::path::Path;

use super::stage::plain_name;
use super::text::{resolution, with_precision};
use super::{ColumnRef, Delimiter, ImportSpec, LabTable, LengthUnit, StressUnit, TimeUnit};
use crate::error::{DataError, Problems};
use crate::plausible::Warning;

/// What a channel holds, read off its name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Role {
    Stage,
    /// Time; the rank orders several (time since the test's start before the stage's).
    Time(u8),
    Slip,
    NormalDisp,
    ShearStress,
    ShearForce,
    NormalStress,
    NormalForce,
    Area,
    Rate,
    Temperature,
}

/// The role a channel's name says it has (`None`: a channel the test does not carry).
fn role_of(name: &str) -> Option<Role> {
    let n = plain_name(name);
    let has = |w: &str| n.contains(w);
    let any = |ws: &[&str]| ws.iter().any(|w| n.contains(w));
    if super::stage::column(&[name.to_string()]).is_some() {
        return Some(Role::Stage);
    }
    if any(&["rate", "velocity", "speed"]) {
        return any(&["displacement", "shear", "horizontal"])
            .then_some(Role::Rate)
            .or((n == "rate").then_some(Role::Rate));
    }
    if has("time") {
        return Some(Role::Time(if has("stage") {
            2
        } else if has("test") || n == "time" || has("elapsed") {
            0
        } else {
            1
        }));
    }
    if any(&[
        "horizontal displacement",
        "shear displacement",
        "horizontal disp",
    ]) {
        return Some(Role::Slip);
    }
    if any(&[
        "vertical displacement",
        "normal displacement",
        "vertical disp",
    ]) {
        return Some(Role::NormalDisp);
    }
    if any(&["shear stress", "horizontal stress"]) {
        return Some(Role::ShearStress);
    }
    if any(&[
        "shear force",
        "shear load",
        "horizontal load",
        "horizontal force",
    ]) {
        return Some(Role::ShearForce);
    }
    if any(&["normal stress", "vertical stress"]) {
        return Some(Role::NormalStress);
    }
    if any(&[
        "normal force",
        "normal load",
        "vertical load",
        "vertical force",
    ]) {
        return Some(Role::NormalForce);
    }
    if has("area") {
        return Some(Role::Area);
    }
    if has("temperature") || n == "temp" {
        return Some(Role::Temperature);
    }
    None
}

/// The unit a channel's name states: the text of its last `(…)` or `[…]`.
fn stated_unit(name: &str) -> Option<String> {
    let open = name.rfind(['(', '['])?;
    let close = name[open..].find([')', ']'])? + open;
    let u = name[open + 1..close].trim();
    (!u.is_empty()).then(|| u.to_string())
}

/// Square millimetres per unit of an area.
fn area_unit(u: &str) -> Result<f64, String> {
    match u
        .trim()
        .to_lowercase()
        .replace(['²', '^'], "2")
        .replace("22", "2")
        .as_str()
    {
        "mm2" | "sq mm" => Ok(1.0),
        "cm2" | "sq cm" => Ok(100.0),
        "m2" | "sq m" => Ok(1e6),
        other => Err(format!(
            "unknown area unit `{other}` (expected mm², cm² or m²)"
        )),
    }
}

/// One channel of a GDS file: its name, the line it is on (an `.ini` file) and a cell per
/// row.
struct RawChannel {
    name: String,
    /// The line it is first given on (0: made by the reader).
    line: usize,
    cells: Vec<String>,
    /// Where each cell stands in an `.ini` file: its line and its place in that line's list
    /// (empty for a table, whose rows have lines of their own).
    origin: Vec<(usize, usize)>,
}

/// A GDS file's content before mapping: channels (columns) with a place per row, and single
/// values (`key`, value, line).
struct RawFile {
    channels: Vec<RawChannel>,
    places: Vec<usize>,
    single: Vec<(String, String, usize)>,
    place: &'static str,
    first_line: usize,
}

/// Whether a file is a GDS export: an `.ini` file of `Key=` lines, or a table under a header
/// naming a stage number and a displacement.
pub(super) fn looks_like_gds(lf: &Path, text: &str) -> bool {
    let ini_ext = lf
        .extension()
        .is_some_and(|e| e.to_string_lossy().eq_ignore_ascii_case("ini"));
    if ini_ext && ini_lines(text).any(|(_, l)| l.contains('=')) {
        return true;
    }
    table_header(text).is_some()
}

/// The lines of an `.ini` file with their 1-based numbers, without blanks and comments.
fn ini_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    crate::text::lines(text)
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with(';') && !l.starts_with('#'))
}

/// The header line of a tabular GDSLAB export: its index among the lines, its cells and its
/// delimiter. A header names a stage number and a displacement (the key-value block above it
/// names neither in one line).
fn table_header(text: &str) -> Option<(usize, Vec<String>, Delimiter)> {
    for (i, line) in crate::text::lines(text).enumerate().take(200) {
        let delim = match super::text::detect(line) {
            Delimiter::Tab => Delimiter::Tab,
            Delimiter::Semicolon => Delimiter::Semicolon,
            _ => Delimiter::Comma,
        };
        let cells = cells_of(line, delim);
        let stage = super::stage::column(&cells).is_some();
        let disp = cells.iter().any(|c| matches!(role_of(c), Some(Role::Slip)));
        if stage && disp {
            return Some((i, cells, delim));
        }
    }
    None
}

/// The cells of one line as the CSV reader reads them (quotes removed), trimmed.
fn cells_of(line: &str, delim: Delimiter) -> Vec<String> {
    crate::csvio::cells_of_line(line, super::text::separator(delim))
        .into_iter()
        .map(|c| c.trim().to_string())
        .collect()
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

/// The problem of a file without a channel of role `what` among its channels (`names`).
fn missing_role(names: &[String], what: &str) -> String {
    format!(
        "no {what} channel among the file's channels ({}) (expected a GDS export naming it; another layout imports with --format delimited and the columns named)",
        names.join(", ")
    )
}

/// Reads an `.ini` channel file: `[sections]` with data become stages (a stage channel
/// otherwise says them), `Key="a,b,c"` lines channels, `Key=v` lines single values. A single
/// value given in the sections of the data with different values there (each stage's own rate
/// or area) becomes a channel, each row taking its section's value.
fn read_ini(lf: &Path, text: &str) -> Result<RawFile, DataError> {
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

/// Reads a tabular GDSLAB export: the `key,value` lines above the header are single values.
fn read_table(lf: &Path, text: &str) -> Result<RawFile, DataError> {
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

/// A channel's cell read: `Ok(None)` for a missing sample, the number and its resolution, or
/// the problem.
fn number(cell: &str) -> Result<Option<(f64, Option<f64>)>, String> {
    if crate::gaps::is_missing(cell) {
        return Ok(None);
    }
    crate::set::parse_number(cell).map(|x| Some((x, resolution(cell))))
}

/// Reads a GDS export into a table with the test's own columns (`time_s`, `slip_mm`,
/// `shear_kpa`, `normal_kpa`, a stage, further channels) and the specification that reads it.
pub(super) fn read(
    lf: &Path,
    text: &str,
    spec: &ImportSpec,
) -> Result<(LabTable, ImportSpec), DataError> {
    let is_ini = lf
        .extension()
        .is_some_and(|e| e.to_string_lossy().eq_ignore_ascii_case("ini"))
        || (table_header(text).is_none() && ini_lines(text).any(|(_, l)| l.contains("=\"")));
    let raw = if is_ini {
        read_ini(lf, text)?
    } else {
        read_table(lf, text)?
    };
    Mapper::new(lf, raw, spec).table()
}

/// Maps a GDS file's channels onto the test's columns.
struct Mapper<'a> {
    lf: &'a Path,
    raw: RawFile,
    spec: &'a ImportSpec,
    pr: Problems,
    /// Units read as GDS's defaults because the names state none.
    defaulted: Vec<String>,
    /// The channels read into the test.
    used: Vec<usize>,
    /// A force was read and turned into a stress over the area.
    force_read: bool,
}

impl<'a> Mapper<'a> {
    fn new(lf: &'a Path, raw: RawFile, spec: &'a ImportSpec) -> Self {
        Mapper {
            lf,
            raw,
            spec,
            pr: Problems::default(),
            defaulted: Vec::new(),
            used: Vec::new(),
            force_read: false,
        }
    }

    /// The channel of a role, the first by rank, taken as read (the others of the same role
    /// are named among the channels not carried).
    fn channel_of(&mut self, role: impl Fn(Role) -> bool) -> Option<usize> {
        let k = self.find_channel(role);
        if let Some(k) = k.filter(|k| !self.used.contains(k)) {
            self.used.push(k);
        }
        k
    }

    /// The channel of a role, the first by rank, without taking it.
    fn find_channel(&self, role: impl Fn(Role) -> bool) -> Option<usize> {
        let mut found: Vec<(u8, usize)> = self
            .raw
            .channels
            .iter()
            .enumerate()
            .filter_map(|(k, c)| {
                role_of(&c.name)
                    .filter(|r| role(*r))
                    .map(|r| (if let Role::Time(rank) = r { rank } else { 0 }, k))
            })
            .collect();
        found.sort();
        found.first().map(|&(_, k)| k)
    }

    fn single_of(&self, role: Role) -> Option<&(String, String, usize)> {
        self.raw
            .single
            .iter()
            .find(|(k, _, _)| role_of(k) == Some(role))
    }

    /// The unit of `name` by `parse`, or `default` (said in the note) when it states none.
    fn unit<U>(
        &mut self,
        name: &str,
        line: usize,
        default: U,
        default_name: &str,
        parse: impl Fn(&str) -> Result<U, String>,
    ) -> Option<U> {
        match stated_unit(name) {
            Some(u) => match parse(&u) {
                Ok(u) => Some(u),
                Err(e) => {
                    let line = (line > 0).then_some(line);
                    self.pr.add(self.lf, line, Some(name), e);
                    None
                }
            },
            None => {
                let said = format!("`{name}` in {default_name}");
                if !self.defaulted.contains(&said) {
                    self.defaulted.push(said);
                }
                Some(default)
            }
        }
    }

    /// The values of channel `k` times `factor` (per row when `factor` gives one per row),
    /// rounded to the digits read; a missing sample stays missing (`None`).
    fn values(&mut self, k: usize, factor: impl Fn(usize) -> f64) -> Vec<Option<f64>> {
        let ch = &self.raw.channels[k];
        let mut out = Vec::with_capacity(ch.cells.len());
        let mut problems = Vec::new();
        for (i, cell) in ch.cells.iter().enumerate() {
            match number(cell) {
                Ok(Some((x, q))) => out.push(Some(with_precision(x, q, factor(i)))),
                Ok(None) => out.push(None),
                Err(e) => {
                    // A table's row has its line; an `.ini` value its line and its place in
                    // that line's list.
                    let (line, msg) = match ch.origin.get(i) {
                        Some(&(line, k)) => (
                            Some(line).filter(|&l| l > 0),
                            format!("value {k} of the list: {e}"),
                        ),
                        None => (Some(self.raw.places[i]), e),
                    };
                    problems.push((line, msg));
                    out.push(None);
                }
            }
        }
        let name = ch.name.clone();
        for (line, msg) in problems.into_iter().take(20) {
            self.pr.add(self.lf, line, Some(&name), msg);
        }
        out
    }

    /// A single value of the file (`Key=v`) read as a number, or reported.
    fn single_number(&mut self, role: Role) -> Option<(f64, String, usize)> {
        let (key, value, line) = self.single_of(role)?.clone();
        match crate::set::parse_number(&value) {
            Ok(x) if x.is_finite() && x > 0.0 => Some((x, key, line)),
            Ok(x) => {
                self.pr.add(
                    self.lf,
                    Some(line),
                    Some(&key),
                    format!("{x} is not positive (expected a positive number)"),
                );
                None
            }
            Err(e) => {
                self.pr.add(self.lf, Some(line), Some(&key), e);
                None
            }
        }
    }

    fn table(mut self) -> Result<(LabTable, ImportSpec), DataError> {
        let n = self.raw.places.len();
        let names: Vec<String> = self.raw.channels.iter().map(|c| c.name.clone()).collect();
        let line_of = |m: &Self, k: usize| m.raw.channels[k].line;
        let missing_role = |what: &str| missing_role(&names, what);
        let slip = self.slip_column(&names);
        let area = self.area_column(&names);
        // Shear and normal: a stress, else a force over the area of its row.
        let stress = |m: &mut Self, stress_role: Role, force_role: Role, what: &str| {
            m.stress_column(&names, area.as_ref(), (stress_role, force_role), what)
        };
        let shear = stress(&mut self, Role::ShearStress, Role::ShearForce, "shear");
        if shear.is_none() && self.pr.is_empty() {
            self.pr.add(
                self.lf,
                None,
                Some("shear"),
                missing_role("shear stress or shear force"),
            );
        }
        let normal = stress(
            &mut self,
            Role::NormalStress,
            Role::NormalForce,
            "normal load",
        );
        if normal.is_none() && self.spec.normal_stress_kpa.is_none() && self.pr.is_empty() {
            self.pr.add(
                self.lf,
                None,
                Some("normal"),
                missing_role("normal stress or vertical load (or --normal-stress)"),
            );
        }
        if self.spec.area_mm2.is_some() && !self.force_read && self.pr.is_empty() {
            self.pr.add(
                self.lf,
                None,
                Some("area"),
                "--area was given but the file's shear and normal channels are stresses (expected --area only for a file that logs forces; a stress needs no area)",
            );
        }
        // Time: logged, else the displacement over the stated rate.
        let mut notes = Vec::new();
        let time = if let Some(k) = self.channel_of(|r| matches!(r, Role::Time(_))) {
            let name = names[k].clone();
            let u = self.unit(&name, line_of(&self, k), TimeUnit::S, "s", |u| u.parse());
            u.map(|u| self.values(k, |_| u.to_s()))
        } else {
            self.time_from_rate(slip.as_deref(), &mut notes)
        };
        let extra = self.further_channels(&names, area.as_ref());
        let stage_k = self.channel_of(|r| r == Role::Stage);
        std::mem::take(&mut self.pr).into_result(())?;
        let (slip, shear, time) = (
            slip.expect("reported above"),
            shear.expect("reported above"),
            time.expect("reported above"),
        );
        notes.extend(self.reading_notes(&names));
        // The table in the test's own columns.
        let mut cols: Vec<(&str, Vec<Option<f64>>)> =
            vec![("time_s", time), ("slip_mm", slip), ("shear_kpa", shear)];
        if let Some(nv) = normal.clone() {
            cols.push(("normal_kpa", nv));
        }
        let stage_name = stage_k.map(|k| names[k].clone());
        let mut header: Vec<String> = cols.iter().map(|c| c.0.to_string()).collect();
        header.extend(stage_name.iter().cloned());
        header.extend(extra.iter().map(|c| c.0.to_string()));
        let records = (0..n)
            .map(|i| {
                let mut cells: Vec<String> = cols
                    .iter()
                    .chain(&extra)
                    .map(|(_, v)| v[i].map_or(String::new(), |x| format!("{x}")))
                    .collect();
                if let Some(k) = stage_k {
                    cells.insert(cols.len(), self.raw.channels[k].cells[i].clone());
                }
                (self.raw.places[i], cells)
            })
            .collect();
        let read_spec = self.spec_of_table(normal.is_some(), &extra);
        let table = LabTable {
            names: header,
            first_line: self.raw.first_line,
            records,
            delim: super::Delimiter::Comma,
            comments: Vec::new(),
            notes,
            place: self.raw.place,
        };
        Ok((table, read_spec))
    }

    /// How the table the GDS file becomes is read: the test's own columns by name, in their own
    /// units (`normal_read`: whether it has a normal stress column; `extra`: the further channels
    /// it carries), with the rest of the user's import options.
    fn spec_of_table(
        &self,
        normal_read: bool,
        extra: &[(&'static str, Vec<Option<f64>>)],
    ) -> ImportSpec {
        let name = |s: &str| ColumnRef::Name(s.into());
        ImportSpec {
            delimiter: super::Delimiter::Comma,
            skip_lines: 0,
            has_header: true,
            time: name("time_s"),
            time_unit: TimeUnit::S,
            slip: name("slip_mm"),
            slip_unit: LengthUnit::Mm,
            shear: Some((name("shear_kpa"), StressUnit::KPa)),
            friction: None,
            normal: normal_read.then(|| (name("normal_kpa"), StressUnit::KPa)),
            area_mm2: None,
            channels: extra.iter().map(|c| (c.0.to_string(), name(c.0))).collect(),
            format: super::ImportFormat::Delimited,
            ..self.spec.clone()
        }
    }

    /// A stress column [kPa]: the channel of `stress_role` in its unit, else the channel of
    /// `force_role` over each row's `area`; `None` where the file has neither, or gives a force
    /// without an area (said, naming the `what`).
    fn stress_column(
        &mut self,
        names: &[String],
        area: Option<&Vec<Option<f64>>>,
        (stress_role, force_role): (Role, Role),
        what: &str,
    ) -> Option<Vec<Option<f64>>> {
        if let Some(k) = self.channel_of(|r| r == stress_role) {
            let name = names[k].clone();
            let u = self.unit(&name, self.raw.channels[k].line, StressUnit::KPa, "kPa", |u| u.parse::<StressUnit>().and_then(|s| if s.is_force() { Err(format!("`{u}` is a force but the channel is named a stress (expected kPa, MPa, Pa or psi)")) } else { Ok(s) }));
            return u.map(|u| self.values(k, |_| u.to_kpa()));
        }
        let k = self.channel_of(|r| r == force_role)?;
        self.force_read = true;
        let name = names[k].clone();
        let u = self.unit(&name, self.raw.channels[k].line, StressUnit::KN, "kN", |u| u.parse::<StressUnit>().and_then(|s| if s.is_force() { Ok(s) } else { Err(format!("`{u}` is a stress but the channel is named a force (expected N, kN or lbf)")) }))?;
        match area {
            Some(a) => {
                let a = a.clone();
                Some(self.values(k, |i| a[i].map_or(f64::NAN, |a| u.to_kpa() / a)))
            }
            None => {
                self.pr.add(self.lf, None, Some(&name), format!("the {what} is a force in {} but the file states no area (expected an area line or channel, or --area in mm²)", u.name()));
                None
            }
        }
    }

    /// The slip column [mm], from the horizontal (shear) displacement channel in its unit; `None`,
    /// with the problem said, where there is none or its unit is not a length.
    fn slip_column(&mut self, names: &[String]) -> Option<Vec<Option<f64>>> {
        match self.channel_of(|r| r == Role::Slip) {
            Some(k) => {
                let name = names[k].clone();
                let u = self.unit(
                    &name,
                    self.raw.channels[k].line,
                    LengthUnit::Mm,
                    "mm",
                    |u| u.parse(),
                );
                u.map(|u| self.values(k, |_| u.to_mm()))
            }
            None => {
                self.pr.add(
                    self.lf,
                    None,
                    Some("slip"),
                    missing_role(names, "horizontal (shear) displacement"),
                );
                None
            }
        }
    }

    /// The contact area of each row [mm²]: `--area`, else an area channel (area correction),
    /// else the file's single value; `None` where none is given (a file that logs stresses needs
    /// none). An area that is not positive is a problem, said where it was read.
    fn area_column(&mut self, names: &[String]) -> Option<Vec<Option<f64>>> {
        let n = self.raw.places.len();
        if let Some(a) = self.spec.area_mm2 {
            if !(a > 0.0 && a.is_finite()) {
                self.pr.add(
                    self.lf,
                    None,
                    Some("area"),
                    format!(
                        "--area {a} mm² (expected the contact area in mm², a finite number > 0)"
                    ),
                );
            }
            Some(vec![Some(a); n])
        } else if let Some(k) = self.channel_of(|r| r == Role::Area) {
            let name = names[k].clone();
            let values = self
                .unit(&name, self.raw.channels[k].line, 1.0, "mm²", area_unit)
                .map(|f| self.values(k, |_| f));
            // A row's area that is not positive would turn its force into a wrong stress.
            if let Some(i) = values.as_ref().and_then(|v| {
                v.iter()
                    .position(|a| a.is_some_and(|a| !(a > 0.0 && a.is_finite())))
            }) {
                let at = self.raw.channels[k].origin.get(i).copied();
                let (line, place) = match at {
                    Some((line, j)) => (line, format!("value {j} of the list: ")),
                    None => (self.raw.places[i], String::new()),
                };
                self.pr.add(
                    self.lf,
                    Some(line).filter(|&l| l > 0),
                    Some(&name),
                    format!("{place}an area that is not positive (expected the contact area, > 0)"),
                );
            }
            values
        } else if let Some((x, key, line)) = self.single_number(Role::Area) {
            self.unit(&key, line, 1.0, "mm²", area_unit)
                .map(|f| vec![Some(x * f); n])
        } else {
            None
        }
    }

    /// The further channels the test carries, in its own columns: the normal displacement, the
    /// forces read (kN per mm² of area: a force's kPa on one mm²), the area where a channel gave
    /// it (`area`: each row's) and the temperature in °C.
    fn further_channels(
        &mut self,
        names: &[String],
        area: Option<&Vec<Option<f64>>>,
    ) -> Vec<(&'static str, Vec<Option<f64>>)> {
        let mut extra: Vec<(&'static str, Vec<Option<f64>>)> = Vec::new();
        if let Some(k) = self.channel_of(|r| r == Role::NormalDisp) {
            let name = names[k].clone();
            if let Some(u) = self.unit(
                &name,
                self.raw.channels[k].line,
                LengthUnit::Mm,
                "mm",
                |u| u.parse(),
            ) {
                extra.push(("normal_disp_mm", self.values(k, |_| u.to_mm())));
            }
        }
        for (role, col) in [
            (Role::ShearForce, "shear_force_kn"),
            (Role::NormalForce, "normal_force_kn"),
        ] {
            if let Some(k) = self.channel_of(|r| r == role) {
                let name = names[k].clone();
                if let Some(u) = self.unit(
                    &name,
                    self.raw.channels[k].line,
                    StressUnit::KN,
                    "kN",
                    |u| u.parse(),
                ) {
                    // kN per unit: a force's kPa on one mm² is 1e6 per kN.
                    extra.push((col, self.values(k, |_| u.to_kpa() / 1e6)));
                }
            }
        }
        if let Some(a) = area {
            if self.spec.area_mm2.is_none() && self.find_channel(|r| r == Role::Area).is_some() {
                extra.push(("area_mm2", a.clone()));
            }
        }
        if let Some(k) = self.channel_of(|r| r == Role::Temperature) {
            let name = names[k].clone();
            if stated_unit(&name).is_none() {
                self.defaulted.push(format!("`{name}` in °C"));
            }
            let ok = stated_unit(&name).is_none_or(|u| {
                matches!(
                    u.trim().to_lowercase().replace(['°', ' '], "").as_str(),
                    "c" | "degc"
                )
            });
            if ok {
                extra.push(("temperature_c", self.values(k, |_| 1.0)));
            } else {
                self.pr.add(
                    self.lf,
                    Some(self.raw.channels[k].line).filter(|&l| l > 0),
                    Some(&name),
                    "a temperature not in °C (expected °C)",
                );
            }
        }
        extra
    }

    /// What the reading says of the file beyond its values: the channels not carried (a second
    /// channel of a role read once among them) and the units read as GDS's where the file left
    /// them unsaid.
    fn reading_notes(&self, names: &[String]) -> Vec<Warning> {
        let mut notes = Vec::new();
        // The channels not carried, said (a second channel of a role read once among them).
        let unused: Vec<String> = (0..names.len())
            .filter(|k| !self.used.contains(k))
            .map(|k| format!("`{}`", names[k]))
            .collect();
        if !unused.is_empty() {
            notes.push(self.note(
                "channels",
                format!(
                    "channel{} {} not carried (a test holds time, slip, shear, normal stress and {}; the lab file keeps them)",
                    if unused.len() == 1 { "" } else { "s" },
                    unused.join(", "),
                    crate::set::CHANNEL_COLUMNS.join(", ")
                ),
            ));
        }
        if !self.defaulted.is_empty() {
            notes.push(self.note(
                "units",
                format!(
                    "units not stated in the file, read as GDS's: {} (expected units in the channel names, e.g. `Shear Force (kN)`)",
                    self.defaulted.join(", ")
                ),
            ));
        }
        notes
    }

    /// Time from the displacement and the rate of shear displacement (a single value or a
    /// channel): each row's time is the slip travelled so far over the rate. The rate's unit
    /// is the one its name states, else `--rate-unit`, else the file is refused.
    fn time_from_rate(
        &mut self,
        slip: Option<&[Option<f64>]>,
        notes: &mut Vec<Warning>,
    ) -> Option<Vec<Option<f64>>> {
        let n = self.raw.places.len();
        let rate_channel = self.channel_of(|r| r == Role::Rate);
        let (name, line) = match (rate_channel, self.single_of(Role::Rate)) {
            (Some(k), _) => (self.raw.channels[k].name.clone(), self.raw.channels[k].line),
            (None, Some((k, _, l))) => (k.clone(), *l),
            (None, None) => {
                self.pr.add(self.lf, None, Some("time"), "no time channel and no rate of shear displacement to reckon the time from (expected a `Time` channel, or a `Rate` line with --rate-unit)");
                return None;
            }
        };
        let unit = self.rate_unit(&name, line)?;
        let per_s = unit.to_mm_per_s();
        let rates: Vec<Option<f64>> = match rate_channel {
            // Read as written and converted unrounded: the time divides by it, and rounding
            // 0.1 mm/min to the digits of mm/s would put 2 % into every time.
            Some(k) => self
                .values(k, |_| 1.0)
                .into_iter()
                .map(|r| r.map(|r| r * per_s))
                .collect(),
            None => {
                let (x, _, _) = self.single_number(Role::Rate)?;
                vec![Some(x * per_s); n]
            }
        };
        let slip = slip?;
        // The clock restarts with each stage: the travel between stages (a box set back) is
        // not shearing at the rate.
        let stage = self
            .channel_of(|r| r == Role::Stage)
            .map(|k| self.raw.channels[k].cells.clone());
        let mut t = 0.0;
        let mut prev: Option<f64> = None;
        let mut out = Vec::with_capacity(n);
        // The stage of the rows so far: a row whose stage cell is missing stays in it.
        let mut current: Option<String> = None;
        for (i, (s, r)) in slip.iter().zip(&rates).enumerate() {
            if let Some(cell) = stage.as_ref().map(|st| st[i].as_str()) {
                if !crate::gaps::is_missing(cell) {
                    let label = super::stage::label_of(cell);
                    if current.as_ref().is_some_and(|c| *c != label) {
                        t = 0.0;
                        prev = None;
                    }
                    current = Some(label);
                }
            }
            match (s, r) {
                (Some(s), Some(r)) if *r > 0.0 => {
                    if let Some(p) = prev {
                        t += (s - p).abs() / r;
                    }
                    prev = Some(*s);
                    // Rounded to a thousandth of a second: the slip's digits carry no more.
                    out.push(Some((t * 1e3).round() / 1e3));
                }
                _ => out.push(None),
            }
        }
        let rate_text = match rate_channel {
            Some(_) => format!("the rates of channel `{name}`"),
            None => format!(
                "the stated rate {} {unit}",
                crate::text::short_number(rates.first().copied().flatten().unwrap_or(0.0) / per_s)
            ),
        };
        notes.push(self.note(
            "time_s",
            format!(
                "no time in the file: each row's time is the slip travelled so far in its stage over {rate_text}{} — a record that holds or changes rate unlogged is not what this time says",
                if self.spec.rate_unit.is_some() { " (unit from --rate-unit)" } else { "" }
            ),
        ));
        Some(out)
    }

    /// The unit of the rate channel or value `name` (on line `line`): the one its name states,
    /// else `--rate-unit`; `None`, with the problem added, when they contradict, when the stated
    /// one is not a unit of rate, or when neither says.
    fn rate_unit(&mut self, name: &str, line: usize) -> Option<super::RateUnit> {
        let unit = match (stated_unit(name), self.spec.rate_unit) {
            // The file's own unit stands; --rate-unit is for a file that states none, and one
            // that contradicts the file is refused rather than chosen between.
            (Some(stated), Some(given)) => match stated.parse::<super::RateUnit>() {
                Ok(u) if u == given => u,
                Ok(u) => {
                    self.pr.add(
                        self.lf,
                        Some(line).filter(|&l| l > 0),
                        Some(name),
                        format!("the file states the rate in {u}, --rate-unit says {given} (expected --rate-unit only for a rate that states no unit, or the same unit)"),
                    );
                    return None;
                }
                Err(e) => {
                    self.pr
                        .add(self.lf, Some(line).filter(|&l| l > 0), Some(name), e);
                    return None;
                }
            },
            (None, Some(u)) => u,
            (Some(u), None) => match u.parse::<super::RateUnit>() {
                Ok(u) => u,
                Err(e) => {
                    self.pr
                        .add(self.lf, Some(line).filter(|&l| l > 0), Some(name), e);
                    return None;
                }
            },
            (None, None) => {
                self.pr.add(
                    self.lf,
                    Some(line).filter(|&l| l > 0),
                    Some(name),
                    "the rate of shear displacement states no unit, and the file has no time (expected --rate-unit, e.g. mm/min, to reckon the time from the displacement)",
                );
                return None;
            }
        };
        Some(unit)
    }

    fn note(&self, field: &str, message: String) -> Warning {
        Warning {
            file: self.lf.to_path_buf(),
            field: field.into(),
            message,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channels_are_known_by_their_names() {
        let cases = [
            ("Horizontal Displacement (mm)", Some(Role::Slip)),
            ("Vertical Displacement", Some(Role::NormalDisp)),
            ("Shear Force (kN)", Some(Role::ShearForce)),
            ("Horizontal Load (kN)", Some(Role::ShearForce)),
            ("Normal Stress (kPa)", Some(Role::NormalStress)),
            ("Vertical Load (kN)", Some(Role::NormalForce)),
            ("Box Area (mm2)", Some(Role::Area)),
            ("Rate of Shear Displacement", Some(Role::Rate)),
            ("Time since start of test (s)", Some(Role::Time(0))),
            ("Time since start of stage (s)", Some(Role::Time(2))),
            ("Stage Number", Some(Role::Stage)),
            ("Back Pressure (kPa)", None),
        ];
        for (name, role) in cases {
            assert_eq!(role_of(name), role, "{name}");
        }
    }

    #[test]
    fn units_are_read_from_the_names() {
        assert_eq!(stated_unit("Shear Force (kN)").as_deref(), Some("kN"));
        assert_eq!(stated_unit("Area [cm²]").as_deref(), Some("cm²"));
        assert_eq!(stated_unit("Rate"), None);
        assert_eq!(area_unit("cm²"), Ok(100.0));
        assert_eq!(area_unit("mm^2"), Ok(1.0));
        assert!(area_unit("acre").is_err());
    }
}
