//! Experiment sets on disk: loading, validating and writing.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::csvio::{Item, Separator};
use crate::error::{DataError, InputProblem, Problems};
use crate::fsio::set_file_problem;
use crate::meta::{file_name_problem, parse_meta, ControlColumn, ExperimentMeta, TestSpec};

/// Name of the description file inside a set's folder.
pub const EXPERIMENT_JSON: &str = "experiment.json";

/// Largest magnitude accepted in any column (s, mm, kPa): 10¹² s is 30 000 years, 10¹² mm a
/// million kilometres. Beyond it a value is no measurement, and the model's arithmetic on it
/// would overflow.
pub const MAX_MAGNITUDE: f64 = 1e12;

/// Column names accepted in a test CSV.
pub const ACCEPTED_COLUMNS: [&str; 5] =
    ["time_s", "slip_mm", "shear_kpa", "friction", "normal_kpa"];

/// Further channels an interface lab records, accepted in a test CSV and carried with the
/// test as read (written back with it, given to Python), not used by the model: the normal
/// (vertical) displacement — dilation, what constant-normal-stiffness tests are about — a
/// temperature, and the force and area a stress was computed from. A missing sample in one of
/// them is kept as a missing value, not a gap of the row.
pub const CHANNEL_COLUMNS: [&str; 5] = [
    "normal_disp_mm",
    "temperature_c",
    "shear_force_kn",
    "normal_force_kn",
    "area_mm2",
];

/// One further channel of a test ([`CHANNEL_COLUMNS`]): its name and a value per row (NaN
/// where the logger missed a sample).
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Column name, as in [`CHANNEL_COLUMNS`].
    pub name: String,
    /// One value per row of the test.
    pub values: Vec<f64>,
}

/// The data of one test, validated.
///
/// All column vectors have the same length, one entry per data row.
#[derive(Clone, Debug, PartialEq)]
pub struct TestData {
    /// The test's description from `experiment.json`.
    pub spec: TestSpec,
    /// Path of the CSV file.
    pub path: PathBuf,
    /// Time, s (strictly increasing).
    pub time_s: Vec<f64>,
    /// Slip, mm.
    pub slip_mm: Vec<f64>,
    /// Shear traction, kPa (computed as friction × normal when the CSV gave `friction`).
    pub shear_kpa: Vec<f64>,
    /// Normal stress per row, kPa (from the `normal_kpa` column, else from the spec).
    pub normal_kpa: Vec<f64>,
    /// True when the CSV had `friction` instead of `shear_kpa`.
    pub friction_given: bool,
    /// 1-based line number in the CSV of each row, for messages.
    pub line_of_row: Vec<usize>,
    /// The `#` comment lines (provenance text), without the `#` and one following space.
    pub comments: Vec<String>,
    /// What the reader made of the file as written, one note each (rows without a value
    /// left out as gaps, repeated time stamps spread over their clock tick): shown with the
    /// plausibility warnings.
    pub reading_notes: Vec<crate::Warning>,
    /// Further channels the CSV carried ([`CHANNEL_COLUMNS`]), in the order of its header.
    pub channels: Vec<Channel>,
}

impl TestData {
    /// The test from row `first` on (a leading artifact cut off); lines keep their numbers.
    pub fn rows_from(&self, first: usize) -> TestData {
        let first = first.min(self.len());
        TestData {
            spec: self.spec.clone(),
            path: self.path.clone(),
            time_s: self.time_s[first..].to_vec(),
            slip_mm: self.slip_mm[first..].to_vec(),
            shear_kpa: self.shear_kpa[first..].to_vec(),
            normal_kpa: self.normal_kpa[first..].to_vec(),
            friction_given: self.friction_given,
            line_of_row: self.line_of_row[first..].to_vec(),
            comments: self.comments.clone(),
            reading_notes: self.reading_notes.clone(),
            channels: self
                .channels
                .iter()
                .map(|c| Channel {
                    name: c.name.clone(),
                    values: c.values[first.min(c.values.len())..].to_vec(),
                })
                .collect(),
        }
    }

    /// The column the apparatus imposed: slip for slip control, shear for shear control.
    pub fn imposed(&self) -> &[f64] {
        match self.spec.control {
            ControlColumn::Slip => &self.slip_mm,
            ControlColumn::Shear => &self.shear_kpa,
        }
    }

    /// The measured column: shear for slip control, slip for shear control.
    pub fn measured(&self) -> &[f64] {
        match self.spec.control {
            ControlColumn::Slip => &self.shear_kpa,
            ControlColumn::Shear => &self.slip_mm,
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.time_s.len()
    }

    /// True when the test has no rows.
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }

    /// Friction ratio shear / normal per row.
    pub fn friction(&self) -> Vec<f64> {
        self.shear_kpa
            .iter()
            .zip(&self.normal_kpa)
            .map(|(s, n)| s / n)
            .collect()
    }

    /// True when the normal stress is not the same on every row or differs from the spec.
    pub fn normal_varies(&self) -> bool {
        self.normal_kpa
            .iter()
            .any(|&n| n != self.spec.normal_stress_kpa)
    }

    /// A fingerprint of the test's rows (time, slip, shear and normal stress, bit for bit):
    /// two tests with the same fingerprint hold the same data, whatever their names and files
    /// (a 64-bit SipHash: two different records share one by chance once in 10¹⁹).
    pub fn content_hash(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        self.len().hash(&mut h);
        for col in [
            &self.time_s,
            &self.slip_mm,
            &self.shear_kpa,
            &self.normal_kpa,
        ] {
            for x in col.iter() {
                x.to_bits().hash(&mut h);
            }
        }
        h.finish()
    }

    /// 1-based CSV line of a row (0 if unknown).
    pub fn line(&self, row: usize) -> usize {
        self.line_of_row.get(row).copied().unwrap_or(0)
    }
}

/// An experiment set: `experiment.json` and the data of all its tests.
#[derive(Clone, Debug, PartialEq)]
pub struct ExperimentSet {
    /// The folder it was loaded from (or is meant to be written to).
    pub dir: PathBuf,
    /// The description.
    pub meta: ExperimentMeta,
    /// The tests, in the order of `meta.tests`.
    pub tests: Vec<TestData>,
}

impl ExperimentSet {
    /// The test of that name.
    pub fn test(&self, name: &str) -> Option<&TestData> {
        self.tests.iter().find(|t| t.spec.name == name)
    }
}

fn read_text(path: &Path, what: &str, max: u64) -> Result<String, DataError> {
    crate::fsio::read_user_text(path, what, max)
}

/// Loads and validates an experiment set folder: `experiment.json` and every test CSV.
///
/// All problems of all files are collected before an error is returned.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// std::fs::write(dir.path().join("experiment.json"), r#"{"name": "demo", "title": "Demo", "source": "doc",
///   "tests": [{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}]}"#)?;
/// std::fs::write(dir.path().join("a.csv"), "# made up\ntime_s,slip_mm,friction\n0,0,0\n1,0.01,0.3\n")?;
/// let set = subfric_data::load_set(dir.path())?;
/// assert_eq!(set.tests[0].shear_kpa, vec![0.0, 30.0]);
/// assert!(set.tests[0].friction_given);
/// assert_eq!(set.tests[0].comments, vec!["made up".to_string()]);
/// # Ok(()) }
/// ```
pub fn load_set(dir: &Path) -> Result<ExperimentSet, DataError> {
    if let Some(p) = crate::fsio::file_not_folder(dir) {
        return Err(DataError::Problems(vec![p]));
    }
    let json_path = dir.join(EXPERIMENT_JSON);
    if dir.is_dir() {
        if let Some(msg) = set_file_problem(dir, &json_path).filter(|_| json_path.exists()) {
            return Err(DataError::Problems(vec![InputProblem::new(
                &json_path,
                None,
                None,
                format!("{EXPERIMENT_JSON} {msg}"),
            )]));
        }
    }
    let text = match read_text(
        &json_path,
        EXPERIMENT_JSON,
        crate::fsio::MAX_SETTINGS_FILE_BYTES,
    ) {
        Ok(t) => t,
        Err(DataError::Io { path, source }) if source.kind() == std::io::ErrorKind::NotFound => {
            let what = if dir.is_dir() {
                format!("no {EXPERIMENT_JSON} in folder {}", dir.display())
            } else {
                format!("folder {} does not exist", dir.display())
            };
            return Err(DataError::Problems(vec![InputProblem::new(
                path,
                None,
                None,
                format!("{what} (expected an experiment set folder holding {EXPERIMENT_JSON} and one CSV per test)"),
            )]));
        }
        Err(e) => return Err(e),
    };
    let meta = parse_meta(&text, &json_path)?;
    let positions = crate::jsonpos::value_positions(&text);
    // each file's problems are capped on their own; the set keeps them all
    let mut problems: Vec<InputProblem> = Vec::new();
    let mut tests = Vec::with_capacity(meta.tests.len());
    for (i, spec) in meta.tests.iter().enumerate() {
        let csv_path = dir.join(&spec.file);
        if let Some(msg) = set_file_problem(dir, &csv_path) {
            let field = format!("tests[{i}].file");
            let line = positions.get(&field).map(|p| p.0);
            problems.push(InputProblem::new(
                &json_path,
                line,
                Some(&field),
                format!(
                    "file `{}` of test `{}` {msg} (expected a CSV file {})",
                    spec.file,
                    spec.name,
                    csv_path.display()
                ),
            ));
            continue;
        }
        match load_test_inner(dir, spec, false) {
            Ok(t) => tests.push(t),
            Err(DataError::Problems(ps)) => problems.extend(ps),
            Err(e) => return Err(e),
        }
    }
    if problems.is_empty() {
        problems.extend(repeated_tests(&tests, &json_path, &positions));
    }
    if !problems.is_empty() {
        return Err(DataError::Problems(problems));
    }
    Ok(ExperimentSet {
        dir: dir.to_path_buf(),
        meta,
        tests,
    })
}

/// Tests of one set that hold the same rows (a CSV copied under another name, or one file
/// named by two tests): each is refused at its `file` in `experiment.json`, naming the test it
/// repeats. Its rows would count twice and every interval would be too narrow by √2.
fn repeated_tests(
    tests: &[TestData],
    json: &Path,
    positions: &HashMap<String, (usize, usize)>,
) -> Vec<InputProblem> {
    let hashes: Vec<u64> = tests.iter().map(TestData::content_hash).collect();
    let mut problems = Vec::new();
    for (j, t) in tests.iter().enumerate() {
        if let Some(i) = (0..j).find(|&i| hashes[i] == hashes[j]) {
            let field = format!("tests[{j}].file");
            problems.push(InputProblem::new(
                json,
                positions.get(&field).map(|p| p.0),
                Some(&field),
                format!(
                    "test `{}` ({}) holds the same {} rows as test `{}` ({}), value for value: its rows would count twice and every interval would be too narrow by √2 (expected each measured test once: remove the copy)",
                    t.spec.name,
                    t.spec.file,
                    t.len(),
                    tests[i].spec.name,
                    tests[i].spec.file
                ),
            ));
        }
    }
    problems
}

/// Loads and validates the CSV of one test of the set in `dir`.
///
/// All problems of the file are collected before an error is returned.
pub fn load_test(dir: &Path, spec: &TestSpec) -> Result<TestData, DataError> {
    load_test_inner(dir, spec, true)
}

fn load_test_inner(dir: &Path, spec: &TestSpec, check_spec: bool) -> Result<TestData, DataError> {
    let mut problems = Problems::default();
    if check_spec {
        let json = dir.join(EXPERIMENT_JSON);
        if let Some(msg) = file_name_problem(&spec.file) {
            problems.add(
                &json,
                None,
                Some("file"),
                format!("test `{}`: {msg}", spec.name),
            );
            return Err(DataError::Problems(problems.into_vec()));
        }
        if !(spec.normal_stress_kpa > 0.0 && spec.normal_stress_kpa <= MAX_MAGNITUDE) {
            let n = spec.normal_stress_kpa;
            problems.add(
                &json,
                None,
                Some("normal_stress_kpa"),
                format!(
                    "test `{}`: normal stress {} kPa is {} (expected a normal stress > 0 kPa, at most 1e12)",
                    spec.name,
                    crate::text::short_number(n),
                    if n > MAX_MAGNITUDE { "beyond 1e12" } else { "not positive" }
                ),
            );
        }
    }
    let path = dir.join(&spec.file);
    if let Some(msg) = set_file_problem(dir, &path) {
        problems.add(
            &path,
            None,
            Some("file"),
            format!(
                "file `{}` named in {EXPERIMENT_JSON} for test `{}` {msg} (expected a CSV file)",
                spec.file, spec.name
            ),
        );
        return Err(DataError::Problems(problems.into_vec()));
    }
    let text = read_text(&path, "the test's CSV", crate::fsio::MAX_DATA_FILE_BYTES)?;
    let result = parse_test_csv(&text, &path, spec);
    match result {
        Ok(t) => problems.into_result(t),
        Err(ps) => {
            let mut all = problems.into_vec();
            all.extend(ps);
            Err(DataError::Problems(all))
        }
    }
}

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

/// Parses and validates the text of a test CSV, as [`load_test`] does for a file; problems
/// name `path`.
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

/// Semantic checks of a test's numbers: all columns the same length, finite values, time
/// strictly increasing, positive normal stress. Used for loaded and imported tests alike.
pub(crate) fn validate_data(td: &TestData, normal_from_column: bool) -> Vec<InputProblem> {
    let mut pr = Problems::default();
    let path = td.path.as_path();
    let n = td.time_s.len();
    if n == 0 {
        pr.add(
            path,
            None,
            None,
            "the test has no data rows (expected at least one row of numbers)",
        );
        return pr.into_vec();
    }
    let lens = [
        td.slip_mm.len(),
        td.shear_kpa.len(),
        td.normal_kpa.len(),
        td.line_of_row.len(),
    ];
    if lens.iter().any(|&l| l != n) || td.channels.iter().any(|c| c.values.len() != n) {
        pr.add(
            path,
            None,
            None,
            format!("columns have different lengths {n}, {lens:?} (expected one value per row in every column)"),
        );
        return pr.into_vec();
    }
    let shear_name = if td.friction_given {
        "friction"
    } else {
        "shear_kpa"
    };
    for i in 0..n {
        let line = Some(td.line(i));
        // A constant normal stress is the description's, checked there once (not on each row).
        let columns = [
            ("time_s", td.time_s[i]),
            ("slip_mm", td.slip_mm[i]),
            (shear_name, td.shear_kpa[i]),
            ("normal_kpa", td.normal_kpa[i]),
        ];
        for (name, x) in columns
            .into_iter()
            .take(if normal_from_column { 4 } else { 3 })
        {
            if !x.is_finite() {
                pr.add(
                    path,
                    line,
                    Some(name),
                    format!(
                        "value {} is not finite (expected a finite number)",
                        crate::text::short_number(x)
                    ),
                );
            } else if x.abs() > MAX_MAGNITUDE {
                pr.add(
                    path,
                    line,
                    Some(name),
                    format!(
                        "value {x:e} is beyond ±{MAX_MAGNITUDE:e} (expected a measurement in s, mm or kPa: a corrupt cell?)"
                    ),
                );
            }
        }
        if i > 0 {
            let (a, b) = (td.time_s[i - 1], td.time_s[i]);
            if a.is_finite() && b.is_finite() && b <= a {
                pr.add(
                    path,
                    line,
                    Some("time_s"),
                    format!(
                        "time {b} is not after time {a} on line {} (expected time_s strictly increasing)",
                        td.line(i - 1)
                    ),
                );
            }
        }
        if normal_from_column {
            let x = td.normal_kpa[i];
            if x.is_finite() && x <= 0.0 {
                pr.add(
                    path,
                    line,
                    Some("normal_kpa"),
                    format!("normal stress {x} kPa is not positive (expected normal_kpa > 0)"),
                );
            }
        }
    }
    pr.into_vec()
}

// Writing sets lives in `write.rs`; its functions keep their paths here.
pub(crate) use crate::write::prepare_parent;
pub use crate::write::{meta_json_text, test_csv_text, write_set};
