//! Experiment sets on disk: loading, validating and writing.

use std::collections::HashSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::error::{DataError, Problem, Problems};
use crate::meta::{file_name_problem, parse_meta, Control, ExperimentMeta, TestSpec};

/// Name of the description file inside a set's folder.
pub const EXPERIMENT_JSON: &str = "experiment.json";

/// Column names accepted in a test CSV.
pub const ACCEPTED_COLUMNS: [&str; 5] =
    ["time_s", "slip_mm", "shear_kpa", "friction", "normal_kpa"];

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
}

impl TestData {
    /// The column the apparatus imposed: slip for slip control, shear for shear control.
    pub fn imposed(&self) -> &[f64] {
        match self.spec.control {
            Control::Slip => &self.slip_mm,
            Control::Shear => &self.shear_kpa,
        }
    }

    /// The measured column: shear for slip control, slip for shear control.
    pub fn measured(&self) -> &[f64] {
        match self.spec.control {
            Control::Slip => &self.shear_kpa,
            Control::Shear => &self.slip_mm,
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

fn read_text(path: &Path) -> Result<String, DataError> {
    let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
    match String::from_utf8(bytes) {
        Ok(s) => Ok(s),
        Err(e) => {
            let valid = e.utf8_error().valid_up_to();
            let bytes = e.into_bytes();
            let line = 1 + bytes[..valid].iter().filter(|&&b| b == b'\n').count();
            Err(DataError::Problems(vec![Problem::new(
                path,
                Some(line),
                None,
                "the file is not valid UTF-8 text (expected a UTF-8 encoded file)",
            )]))
        }
    }
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
    let json_path = dir.join(EXPERIMENT_JSON);
    let text = match read_text(&json_path) {
        Ok(t) => t,
        Err(DataError::Io { path, source }) if source.kind() == std::io::ErrorKind::NotFound => {
            let what = if dir.is_dir() {
                format!("no {EXPERIMENT_JSON} in folder {}", dir.display())
            } else {
                format!("folder {} does not exist", dir.display())
            };
            return Err(DataError::Problems(vec![Problem::new(
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
    let mut problems: Vec<Problem> = Vec::new();
    let mut tests = Vec::with_capacity(meta.tests.len());
    for (i, spec) in meta.tests.iter().enumerate() {
        let csv_path = dir.join(&spec.file);
        if !csv_path.is_file() {
            let field = format!("tests[{i}].file");
            let line = positions.get(&field).map(|p| p.0);
            problems.push(Problem::new(
                &json_path,
                line,
                Some(&field),
                format!(
                    "file `{}` of test `{}` is absent (expected a CSV file {})",
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
    if !problems.is_empty() {
        return Err(DataError::Problems(problems));
    }
    Ok(ExperimentSet {
        dir: dir.to_path_buf(),
        meta,
        tests,
    })
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
        if !(spec.normal_stress_kpa > 0.0 && spec.normal_stress_kpa.is_finite()) {
            problems.add(
                &json,
                None,
                Some("normal_stress_kpa"),
                format!(
                    "test `{}`: normal stress {} kPa is not positive (expected a normal stress > 0 kPa)",
                    spec.name, spec.normal_stress_kpa
                ),
            );
        }
    }
    let path = dir.join(&spec.file);
    if !path.is_file() {
        problems.add(
            &path,
            None,
            Some("file"),
            format!(
                "file `{}` named in {EXPERIMENT_JSON} for test `{}` is absent (expected a CSV file)",
                spec.file, spec.name
            ),
        );
        return Err(DataError::Problems(problems.into_vec()));
    }
    let text = read_text(&path)?;
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
}

impl Col {
    fn from_name(s: &str) -> Option<Col> {
        match s.to_ascii_lowercase().as_str() {
            "time_s" => Some(Col::Time),
            "slip_mm" => Some(Col::Slip),
            "shear_kpa" => Some(Col::Shear),
            "friction" => Some(Col::Friction),
            "normal_kpa" => Some(Col::Normal),
            _ => None,
        }
    }
}

fn unquote(s: &str) -> &str {
    let s = s.trim();
    s.strip_prefix('"')
        .and_then(|x| x.strip_suffix('"'))
        .unwrap_or(s)
        .trim()
}

/// Parses one numeric cell; `Err` holds the message.
pub(crate) fn parse_number(cell: &str) -> Result<f64, String> {
    let c = unquote(cell);
    if c.is_empty() {
        return Err("empty cell (expected a number)".into());
    }
    match c.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(format!(
            "`{c}` is not a finite number (expected a finite decimal number)"
        )),
        Err(_) => Err(format!("`{c}` is not a number (expected a decimal number)")),
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
/// use subfric_data::{set::parse_test, Control, TestSpec};
/// let spec = TestSpec::new("a", "a.csv", Control::Slip, 50.0);
/// let t = parse_test("time_s,slip_mm,shear_kpa\n0,0,0\n1,0.5,20\n", "a.csv".as_ref(), &spec).unwrap();
/// assert_eq!(t.normal_kpa, vec![50.0, 50.0]);
/// let e = parse_test("time_s,slip_mm,shear_kpa\n1,0,0\n1,0.5,20\n", "a.csv".as_ref(), &spec).unwrap_err();
/// assert!(e.to_string().contains("a.csv:3: field `time_s`: time 1 is not after time 1 on line 2"));
/// ```
pub fn parse_test(text: &str, path: &Path, spec: &TestSpec) -> Result<TestData, DataError> {
    parse_test_csv(text, path, spec).map_err(DataError::Problems)
}

/// Parses and validates the text of a test CSV. Problems name `path`.
pub(crate) fn parse_test_csv(
    text: &str,
    path: &Path,
    spec: &TestSpec,
) -> Result<TestData, Vec<Problem>> {
    let mut pr = Problems::default();
    let mut comments = Vec::new();
    let mut header: Option<(usize, Vec<Option<Col>>, Vec<String>)> = None;
    let mut rows: Vec<(usize, Vec<f64>)> = Vec::new();
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    for (idx, raw) in text.split('\n').enumerate() {
        let line_no = idx + 1;
        let line = raw.strip_suffix('\r').unwrap_or(raw);
        let trimmed = line.trim();
        if trimmed.is_empty() {
            continue;
        }
        if trimmed.starts_with('#') {
            comments.push(comment_text(trimmed));
            continue;
        }
        match &header {
            None => {
                let names: Vec<String> =
                    trimmed.split(',').map(|c| unquote(c).to_string()).collect();
                let mut cols = Vec::with_capacity(names.len());
                let mut seen = HashSet::new();
                for name in &names {
                    let col = Col::from_name(name);
                    if name.is_empty() {
                        pr.add(
                            path,
                            Some(line_no),
                            None,
                            format!(
                                "empty column name in the header (expected one of {})",
                                ACCEPTED_COLUMNS.join(", ")
                            ),
                        );
                    } else if col.is_none() {
                        pr.add(
                            path,
                            Some(line_no),
                            Some(name),
                            format!(
                                "unknown column `{name}` (expected one of {})",
                                ACCEPTED_COLUMNS.join(", ")
                            ),
                        );
                    } else if !seen.insert(col) {
                        pr.add(
                            path,
                            Some(line_no),
                            Some(name),
                            format!("column `{name}` appears twice (expected each column once)"),
                        );
                    }
                    cols.push(col);
                }
                let has = |c: Col| cols.contains(&Some(c));
                for (c, name) in [(Col::Time, "time_s"), (Col::Slip, "slip_mm")] {
                    if !has(c) {
                        pr.add(
                            path,
                            Some(line_no),
                            Some(name),
                            format!("missing required column `{name}` (expected a header with time_s, slip_mm and shear_kpa or friction)"),
                        );
                    }
                }
                if !has(Col::Shear) && !has(Col::Friction) {
                    pr.add(
                        path,
                        Some(line_no),
                        Some("shear_kpa"),
                        "missing required column `shear_kpa` (expected a header with time_s, slip_mm and shear_kpa or friction)",
                    );
                }
                header = Some((line_no, cols, names));
            }
            Some((_, cols, names)) => {
                let cells: Vec<&str> = trimmed.split(',').collect();
                if cells.len() != cols.len() {
                    pr.add(
                        path,
                        Some(line_no),
                        None,
                        format!(
                            "row has {} cell{} (expected {}: {})",
                            cells.len(),
                            if cells.len() == 1 { "" } else { "s" },
                            cols.len(),
                            names.join(",")
                        ),
                    );
                    continue;
                }
                let mut values = vec![f64::NAN; cols.len()];
                let mut ok = true;
                for (k, cell) in cells.iter().enumerate() {
                    if cols[k].is_none() {
                        continue;
                    }
                    match parse_number(cell) {
                        Ok(x) => values[k] = x,
                        Err(msg) => {
                            ok = false;
                            pr.add(path, Some(line_no), Some(&names[k]), msg);
                        }
                    }
                }
                if ok {
                    rows.push((line_no, values));
                }
            }
        }
    }
    let Some((header_line, cols, _)) = header else {
        pr.add(
            path,
            None,
            None,
            "no header line (expected a first non-comment line such as `time_s,slip_mm,shear_kpa`)",
        );
        return Err(pr.into_vec());
    };
    let idx = |c: Col| cols.iter().position(|x| *x == Some(c));
    let (Some(it), Some(is)) = (idx(Col::Time), idx(Col::Slip)) else {
        return Err(pr.into_vec());
    };
    let shear_idx = idx(Col::Shear);
    let friction_idx = idx(Col::Friction);
    if shear_idx.is_none() && friction_idx.is_none() {
        return Err(pr.into_vec());
    }
    let normal_idx = idx(Col::Normal);
    if rows.is_empty() {
        if pr.is_empty() {
            pr.add(
                path,
                Some(header_line),
                None,
                "the test has a header but no data rows (expected at least one row of numbers)",
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
    };
    for (line, v) in &rows {
        let normal = normal_idx.map_or(spec.normal_stress_kpa, |k| v[k]);
        let shear = match shear_idx {
            Some(k) => v[k],
            None => friction_idx.map_or(f64::NAN, |k| v[k] * normal),
        };
        td.time_s.push(v[it]);
        td.slip_mm.push(v[is]);
        td.shear_kpa.push(shear);
        td.normal_kpa.push(normal);
        td.line_of_row.push(*line);
    }
    let normal_from_column = normal_idx.is_some();
    pr.extend(validate_data(&td, normal_from_column));
    pr.into_result(td).map_err(|e| match e {
        DataError::Problems(p) => p,
        other => vec![Problem::new(path, None, None, other.to_string())],
    })
}

/// Semantic checks of a test's numbers: all columns the same length, finite values, time
/// strictly increasing, positive normal stress. Used for loaded and imported tests alike.
pub(crate) fn validate_data(td: &TestData, normal_from_column: bool) -> Vec<Problem> {
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
    if lens.iter().any(|&l| l != n) {
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
        for (name, x) in [
            ("time_s", td.time_s[i]),
            ("slip_mm", td.slip_mm[i]),
            (shear_name, td.shear_kpa[i]),
            ("normal_kpa", td.normal_kpa[i]),
        ] {
            if !x.is_finite() {
                pr.add(
                    path,
                    line,
                    Some(name),
                    format!("value {x} is not finite (expected a finite number)"),
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

/// Writes the CSV text of a test: comments, header `time_s,slip_mm,shear_kpa` (plus
/// `normal_kpa` when the normal stress varies), one row per line.
pub fn test_csv_text(test: &TestData) -> String {
    let mut s = String::new();
    for c in &test.comments {
        if c.is_empty() {
            s.push_str("#\n");
        } else {
            let _ = writeln!(s, "# {c}");
        }
    }
    let with_normal = test.normal_varies();
    s.push_str("time_s,slip_mm,shear_kpa");
    if with_normal {
        s.push_str(",normal_kpa");
    }
    s.push('\n');
    for i in 0..test.len() {
        let _ = write!(
            s,
            "{},{},{}",
            test.time_s[i],
            test.slip_mm.get(i).copied().unwrap_or(f64::NAN),
            test.shear_kpa.get(i).copied().unwrap_or(f64::NAN)
        );
        if with_normal {
            let _ = write!(
                s,
                ",{}",
                test.normal_kpa.get(i).copied().unwrap_or(f64::NAN)
            );
        }
        s.push('\n');
    }
    s
}

/// Pretty JSON text of an `experiment.json`.
pub fn meta_json_text(meta: &ExperimentMeta) -> Result<String, DataError> {
    serde_json::to_string_pretty(meta)
        .map(|mut s| {
            s.push('\n');
            s
        })
        .map_err(|e| {
            DataError::Problems(vec![Problem::new(
                EXPERIMENT_JSON,
                None,
                None,
                format!("cannot serialise the description: {e}"),
            )])
        })
}

pub(crate) fn write_file(path: &Path, text: &str) -> Result<(), DataError> {
    std::fs::write(path, text).map_err(|e| DataError::io(path, e))
}

/// Writes an experiment set to `dir` (created if needed): `experiment.json` from `set.meta` and
/// one CSV per test (named by its spec's `file`), keeping the comment lines.
///
/// Friction data are written as `shear_kpa`; the `normal_kpa` column is written only when the
/// normal stress varies.
pub fn write_set(set: &ExperimentSet, dir: &Path) -> Result<(), DataError> {
    let mut pr = Problems::default();
    let json = dir.join(EXPERIMENT_JSON);
    let mut files = HashSet::new();
    for t in &set.tests {
        if let Some(msg) = file_name_problem(&t.spec.file) {
            pr.add(
                &json,
                None,
                Some("file"),
                format!("test `{}`: {msg}", t.spec.name),
            );
        } else if !files.insert(t.spec.file.clone()) {
            pr.add(
                &json,
                None,
                Some("file"),
                format!(
                    "file `{}` is used by two tests (expected one CSV per test)",
                    t.spec.file
                ),
            );
        }
    }
    for t in &set.tests {
        let target = dir.join(&t.spec.file);
        let mut copy = t.clone();
        copy.path = target;
        pr.extend(validate_data(&copy, true));
    }
    pr.into_result(())?;
    std::fs::create_dir_all(dir).map_err(|e| DataError::io(dir, e))?;
    write_file(&json, &meta_json_text(&set.meta)?)?;
    for t in &set.tests {
        write_file(&dir.join(&t.spec.file), &test_csv_text(t))?;
    }
    Ok(())
}
