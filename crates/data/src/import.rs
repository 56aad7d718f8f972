//! Import of laboratory files (any delimiter, units and column names) into an experiment set.

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde_json::Map;

use crate::error::{DataError, Problem, Problems};
use crate::meta::{Control, ExperimentMeta, Interface, TestSpec};
use crate::set::{
    comment_text, load_set, meta_json_text, test_csv_text, validate_data, write_file,
    ExperimentSet, TestData, EXPERIMENT_JSON,
};

/// Cell delimiter of a lab file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Delimiter {
    /// `,`
    Comma,
    /// tab
    Tab,
    /// runs of spaces or tabs
    Whitespace,
    /// `;` (a decimal comma is then accepted)
    Semicolon,
    /// detected from the header (or first data) line: tab, then `;`, then `,`, else whitespace
    Auto,
}

impl FromStr for Delimiter {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "," | "comma" | "csv" => Ok(Delimiter::Comma),
            "\\t" | "\t" | "tab" | "tsv" => Ok(Delimiter::Tab),
            "whitespace" | "space" | "ws" | " " => Ok(Delimiter::Whitespace),
            ";" | "semicolon" => Ok(Delimiter::Semicolon),
            "auto" | "" => Ok(Delimiter::Auto),
            other => Err(format!(
                "unknown delimiter `{other}` (expected comma, tab, whitespace, semicolon or auto)"
            )),
        }
    }
}

/// A column of a lab file: by header name or by 1-based index.
///
/// ```
/// use subfric_data::ColumnRef;
/// assert_eq!("3".parse::<ColumnRef>().unwrap(), ColumnRef::Index(3));
/// assert_eq!("Shear (MPa)".parse::<ColumnRef>().unwrap(), ColumnRef::Name("Shear (MPa)".into()));
/// assert!("0".parse::<ColumnRef>().is_err());
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ColumnRef {
    /// Header name (matched ignoring case and surrounding spaces).
    Name(String),
    /// 1-based column index.
    Index(usize),
}

impl FromStr for ColumnRef {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim();
        if s.is_empty() {
            return Err(
                "empty column reference (expected a header name or a 1-based index)".into(),
            );
        }
        if s.chars().all(|c| c.is_ascii_digit()) {
            match s.parse::<usize>() {
                Ok(0) | Err(_) => Err(format!(
                    "column index `{s}` is invalid (expected 1, 2, 3, …)"
                )),
                Ok(i) => Ok(ColumnRef::Index(i)),
            }
        } else {
            Ok(ColumnRef::Name(s.to_string()))
        }
    }
}

impl fmt::Display for ColumnRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ColumnRef::Name(n) => write!(f, "{n}"),
            ColumnRef::Index(i) => write!(f, "column {i}"),
        }
    }
}

impl From<&str> for ColumnRef {
    fn from(s: &str) -> Self {
        s.parse().unwrap_or_else(|_| ColumnRef::Name(s.to_string()))
    }
}

/// Time unit of a lab file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimeUnit {
    /// seconds
    S,
    /// minutes
    Min,
    /// hours
    H,
    /// milliseconds
    Ms,
}

impl TimeUnit {
    /// Seconds per unit.
    pub fn to_s(self) -> f64 {
        match self {
            TimeUnit::S => 1.0,
            TimeUnit::Min => 60.0,
            TimeUnit::H => 3600.0,
            TimeUnit::Ms => 1e-3,
        }
    }
}

impl FromStr for TimeUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "s" | "sec" | "second" | "seconds" => Ok(TimeUnit::S),
            "min" | "minute" | "minutes" => Ok(TimeUnit::Min),
            "h" | "hr" | "hour" | "hours" => Ok(TimeUnit::H),
            "ms" | "millisecond" | "milliseconds" => Ok(TimeUnit::Ms),
            other => Err(format!(
                "unknown time unit `{other}` (expected s, min, h or ms)"
            )),
        }
    }
}

/// Length unit of a lab file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LengthUnit {
    /// millimetres
    Mm,
    /// micrometres
    Um,
    /// metres
    M,
    /// inches
    In,
}

impl LengthUnit {
    /// Millimetres per unit.
    pub fn to_mm(self) -> f64 {
        match self {
            LengthUnit::Mm => 1.0,
            LengthUnit::Um => 1e-3,
            LengthUnit::M => 1e3,
            LengthUnit::In => 25.4,
        }
    }
}

impl FromStr for LengthUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_lowercase().as_str() {
            "mm" => Ok(LengthUnit::Mm),
            "um" | "µm" | "μm" | "micron" | "microns" => Ok(LengthUnit::Um),
            "m" => Ok(LengthUnit::M),
            "in" | "inch" | "inches" => Ok(LengthUnit::In),
            other => Err(format!(
                "unknown length unit `{other}` (expected mm, um, m or in)"
            )),
        }
    }
}

/// Stress unit of a lab file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StressUnit {
    /// kilopascals
    KPa,
    /// megapascals
    MPa,
    /// pascals
    Pa,
    /// pounds per square inch
    Psi,
}

impl StressUnit {
    /// Kilopascals per unit.
    pub fn to_kpa(self) -> f64 {
        match self {
            StressUnit::KPa => 1.0,
            StressUnit::MPa => 1e3,
            StressUnit::Pa => 1e-3,
            StressUnit::Psi => 6.894_757_293_168_361,
        }
    }
}

impl FromStr for StressUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "kpa" => Ok(StressUnit::KPa),
            "mpa" => Ok(StressUnit::MPa),
            "pa" => Ok(StressUnit::Pa),
            "psi" => Ok(StressUnit::Psi),
            other => Err(format!(
                "unknown stress unit `{other}` (expected kPa, MPa, Pa or psi)"
            )),
        }
    }
}

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
    /// Which column the apparatus imposed.
    pub control: Control,
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
            control: Control::Slip,
            test_name: "test".into(),
            set_name: "imported".into(),
            title: None,
            soil: None,
            surface: None,
            source: None,
        }
    }
}

fn split_cells(line: &str, d: Delimiter) -> Vec<String> {
    let cells: Vec<&str> = match d {
        Delimiter::Comma => line.split(',').collect(),
        Delimiter::Tab => line.split('\t').collect(),
        Delimiter::Semicolon => line.split(';').collect(),
        Delimiter::Whitespace | Delimiter::Auto => line.split_whitespace().collect(),
    };
    cells
        .into_iter()
        .map(|c| {
            let c = c.trim();
            c.strip_prefix('"')
                .and_then(|x| x.strip_suffix('"'))
                .unwrap_or(c)
                .trim()
                .to_string()
        })
        .collect()
}

fn detect(line: &str) -> Delimiter {
    if line.contains('\t') {
        Delimiter::Tab
    } else if line.contains(';') {
        Delimiter::Semicolon
    } else if line.contains(',') {
        Delimiter::Comma
    } else {
        Delimiter::Whitespace
    }
}

fn decode(bytes: Vec<u8>) -> String {
    match String::from_utf8(bytes) {
        Ok(s) => s,
        // Latin-1 (common in lab exports: `µm`, `°C`)
        Err(e) => e.into_bytes().iter().map(|&b| b as char).collect(),
    }
}

/// File name for a test: the name with characters outside `[A-Za-z0-9._-]` replaced by `-`.
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
    s.push_str(".csv");
    s
}

/// Reads a lab file into a test (not yet written); problems name the lab file and its lines.
pub fn read_lab_file(
    lab_file: &Path,
    spec: &ImportSpec,
    target: &Path,
) -> Result<TestData, DataError> {
    let bytes = std::fs::read(lab_file).map_err(|e| DataError::io(lab_file, e))?;
    let text = decode(bytes);
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let mut pr = Problems::default();
    let lf = lab_file;
    if spec.test_name.trim().is_empty() {
        pr.add(
            lf,
            None,
            Some("test_name"),
            "empty test name (expected a name for the test)",
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
    if let Some(x) = spec.normal_stress_kpa {
        if !(x > 0.0 && x.is_finite()) {
            pr.add(
                lf,
                None,
                Some("normal_stress_kpa"),
                format!("normal stress {x} kPa is not positive (expected > 0)"),
            );
        }
    }
    if !pr.is_empty() {
        return Err(DataError::Problems(pr.into_vec()));
    }

    let mut comments = Vec::new();
    let mut lines: Vec<(usize, &str)> = Vec::new();
    for (i, raw) in text.split('\n').enumerate().skip(spec.skip_lines) {
        let line = raw.strip_suffix('\r').unwrap_or(raw);
        let trimmed = line.trim();
        if trimmed.is_empty() {
            continue;
        }
        if trimmed.starts_with('#') {
            comments.push(comment_text(trimmed));
            continue;
        }
        lines.push((i + 1, line));
    }
    let Some(&(first_line, first)) = lines.first() else {
        return Err(DataError::Problems(vec![Problem::new(
            lf,
            None,
            None,
            "no data in the file (expected a header line and rows of numbers)",
        )]));
    };
    let delim = match spec.delimiter {
        Delimiter::Auto => detect(first),
        d => d,
    };
    let (names, data_lines): (Vec<String>, &[(usize, &str)]) = if spec.has_header {
        (split_cells(first, delim), &lines[1..])
    } else {
        (Vec::new(), &lines[..])
    };
    let resolve = |c: &ColumnRef, what: &str, pr: &mut Problems| -> Option<(usize, String)> {
        match c {
            ColumnRef::Index(i) => {
                let label = names
                    .get(i.wrapping_sub(1))
                    .cloned()
                    .unwrap_or_else(|| format!("column {i}"));
                Some((i.saturating_sub(1), label))
            }
            ColumnRef::Name(n) => {
                if !spec.has_header {
                    pr.add(
                        lf,
                        Some(first_line),
                        Some(what),
                        format!("column `{n}` named but the file has no header (expected a 1-based column index)"),
                    );
                    return None;
                }
                match names
                    .iter()
                    .position(|h| h.trim().eq_ignore_ascii_case(n.trim()))
                {
                    Some(k) => Some((k, names[k].clone())),
                    None => {
                        pr.add(
                            lf,
                            Some(first_line),
                            Some(what),
                            format!(
                                "no column `{n}` in the header (expected one of: {})",
                                names.join(", ")
                            ),
                        );
                        None
                    }
                }
            }
        }
    };
    let time = resolve(&spec.time, "time", &mut pr);
    let slip = resolve(&spec.slip, "slip", &mut pr);
    let shear = spec
        .shear
        .as_ref()
        .map(|(c, u)| (resolve(c, "shear", &mut pr), *u));
    let friction = if spec.shear.is_none() {
        spec.friction
            .as_ref()
            .map(|c| resolve(c, "friction", &mut pr))
    } else {
        None
    };
    let normal = spec
        .normal
        .as_ref()
        .map(|(c, u)| (resolve(c, "normal", &mut pr), *u));
    if !pr.is_empty() {
        return Err(DataError::Problems(pr.into_vec()));
    }
    let (Some(time), Some(slip)) = (time, slip) else {
        return Err(DataError::Problems(pr.into_vec()));
    };
    let shear = shear.and_then(|(c, u)| c.map(|c| (c, u)));
    let friction = friction.flatten();
    let normal = normal.and_then(|(c, u)| c.map(|c| (c, u)));

    let n = data_lines.len();
    let mut t_s = Vec::with_capacity(n);
    let mut slip_mm = Vec::with_capacity(n);
    let mut shear_kpa = Vec::with_capacity(n);
    let mut normal_kpa = Vec::with_capacity(n);
    let mut line_of_row = Vec::with_capacity(n);
    let decimal_comma = delim != Delimiter::Comma;
    for &(line_no, line) in data_lines {
        let cells = split_cells(line, delim);
        let mut ok = true;
        let mut get = |col: &(usize, String), factor: f64, pr: &mut Problems| -> f64 {
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
                ok = false;
                return f64::NAN;
            };
            let mut c = cell.clone();
            if decimal_comma && c.contains(',') && !c.contains('.') {
                c = c.replace(',', ".");
            }
            match crate::set::parse_number(&c) {
                Ok(x) => x * factor,
                Err(msg) => {
                    pr.add(lf, Some(line_no), Some(&col.1), msg);
                    ok = false;
                    f64::NAN
                }
            }
        };
        let tv = get(&time, spec.time_unit.to_s(), &mut pr);
        let sv = get(&slip, spec.slip_unit.to_mm(), &mut pr);
        let nv = match &normal {
            Some((c, u)) => get(c, u.to_kpa(), &mut pr),
            None => spec.normal_stress_kpa.unwrap_or(f64::NAN),
        };
        let qv = match (&shear, &friction) {
            (Some((c, u)), _) => get(c, u.to_kpa(), &mut pr),
            (None, Some(c)) => get(c, 1.0, &mut pr) * nv,
            (None, None) => f64::NAN,
        };
        if ok {
            t_s.push(tv);
            slip_mm.push(sv);
            shear_kpa.push(qv);
            normal_kpa.push(nv);
            line_of_row.push(line_no);
        }
    }
    if n == 0 {
        pr.add(
            lf,
            Some(first_line),
            None,
            "the file has a header but no data rows (expected rows of numbers)",
        );
    }
    let spec_normal = match (&normal, spec.normal_stress_kpa) {
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
    };
    let file_name = lab_file
        .file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    comments.push(format!("imported from lab file `{file_name}`"));
    let td = TestData {
        spec: TestSpec {
            name: spec.test_name.trim().to_string(),
            file: file_name_for(&spec.test_name),
            control: spec.control,
            normal_stress_kpa: spec_normal,
            initial: None,
            extra: Map::new(),
        },
        path: lab_file.to_path_buf(),
        time_s: t_s,
        slip_mm,
        shear_kpa,
        normal_kpa,
        friction_given: shear.is_none(),
        line_of_row,
        comments,
    };
    if pr.is_empty() {
        pr.extend(validate_data(&td, normal.is_some()));
    }
    let mut td = pr.into_result(td)?;
    td.path = target.join(&td.spec.file);
    Ok(td)
}

/// Imports a lab file as a test of the experiment set in `out_dir`.
///
/// Units are converted to mm, s and kPa; shear is computed as friction × normal when only
/// friction is given. The result is validated like [`load_set`] does. If `out_dir` already
/// holds an `experiment.json`, the test is appended to that set (a duplicate test name or an
/// existing file of the same name is refused); otherwise a new set is created. Returns the set
/// as loaded back from `out_dir`.
pub fn import(
    lab_file: &Path,
    spec: &ImportSpec,
    out_dir: &Path,
) -> Result<ExperimentSet, DataError> {
    let test = read_lab_file(lab_file, spec, out_dir)?;
    let json_path = out_dir.join(EXPERIMENT_JSON);
    let csv_path: PathBuf = out_dir.join(&test.spec.file);
    let mut meta = if json_path.is_file() {
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
        if existing.meta.tests.iter().any(|t| t.file == test.spec.file) || csv_path.exists() {
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
        existing.meta
    } else {
        if csv_path.exists() {
            return Err(DataError::Problems(vec![Problem::new(
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
        ExperimentMeta {
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
            extra: Map::new(),
        }
    };
    meta.tests.push(test.spec.clone());
    std::fs::create_dir_all(out_dir).map_err(|e| DataError::io(out_dir, e))?;
    write_file(&csv_path, &test_csv_text(&test))?;
    write_file(&json_path, &meta_json_text(&meta)?)?;
    load_set(out_dir)
}
