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

mod columns;
mod ini;
mod names;
mod tabular;
mod time;

use std::path::Path;

use super::table::LabTable;
use super::text::{resolution, with_precision};
use super::{ColumnRef, ImportSpec, LengthUnit, StressUnit, TimeUnit};
use crate::error::{DataError, Problems};
use crate::plausible::Warning;
use ini::{ini_lines, read_ini};
use names::{role_of, stated_unit, Role};
use tabular::{read_table, table_header};

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

/// A channel's cell read: `Ok(None)` for a missing sample, the number and its resolution, or
/// the problem.
fn number(cell: &str) -> Result<Option<(f64, Option<f64>)>, String> {
    if crate::gaps::is_missing(cell) {
        return Ok(None);
    }
    crate::set::parse_number(cell).map(|x| Some((x, resolution(cell))))
}

/// The problem of a file without a channel of role `what` among its channels (`names`).
fn missing_role(names: &[String], what: &str) -> String {
    format!(
        "no {what} channel among the file's channels ({}) (expected a GDS export naming it; another layout imports with --format delimited and the columns named)",
        names.join(", ")
    )
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

    fn note(&self, field: &str, message: String) -> Warning {
        Warning {
            file: self.lf.to_path_buf(),
            field: field.into(),
            message,
        }
    }
}
