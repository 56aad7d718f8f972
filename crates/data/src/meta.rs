//! The experiment description `experiment.json`: types and validation.

use std::collections::HashMap;
use std::fmt;
use std::path::{Component, Path};
use std::str::FromStr;

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::error::{DataError, Problems};
use crate::jsonpos::value_positions;
use crate::set::MAX_MAGNITUDE;
use crate::text::name_too_long;

/// Which column the apparatus imposed, as declared in `experiment.json` (the model's
/// counterpart is `subfric_model::Control`; `subfric_fit::control_of` converts).
///
/// ```
/// use subfric_data::ControlColumn;
/// let c: ControlColumn = serde_json::from_str("\"shear\"").unwrap();
/// assert_eq!(c, ControlColumn::Shear);
/// assert_eq!("slip".parse::<ControlColumn>().unwrap(), ControlColumn::Slip);
/// assert_eq!(ControlColumn::Slip.to_string(), "slip");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ControlColumn {
    /// Slip history imposed, shear measured (displacement control).
    Slip,
    /// Shear traction imposed, slip measured (stress control: pulsating loading, creep).
    Shear,
}

impl ControlColumn {
    /// `"slip"` or `"shear"`.
    pub fn name(self) -> &'static str {
        match self {
            ControlColumn::Slip => "slip",
            ControlColumn::Shear => "shear",
        }
    }
}

impl fmt::Display for ControlColumn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ControlColumn {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "slip" => Ok(ControlColumn::Slip),
            "shear" => Ok(ControlColumn::Shear),
            other => Err(format!(
                "unknown control `{other}` (expected `slip` or `shear`)"
            )),
        }
    }
}

/// The sand–metal interface tested.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Interface {
    /// Soil, e.g. "Toyoura sand".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub soil: Option<String>,
    /// Metal surface, e.g. "A36 steel".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<String>,
    /// Maximum roughness R_max of the surface, µm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roughness_rmax_um: Option<f64>,
    /// Any other fields, kept as they are (among them the optional numbers of
    /// [`INTERFACE_NUMBERS`], read with [`Interface::number`]).
    #[serde(flatten)]
    pub extra: Map<String, Value>,
}

/// The optional numeric fields of `interface` besides `roughness_rmax_um`: (key, unit, what).
/// Each is a number ≥ 0 (D50 > 0) when present; never required.
pub const INTERFACE_NUMBERS: [(&str, &str, &str); 2] = [
    ("d50_mm", "mm", "median grain size D50 of the soil"),
    ("roughness_ra_um", "µm", "mean roughness R_a of the surface"),
];

impl Interface {
    /// An optional numeric field of the interface kept in [`Interface::extra`] (`d50_mm`,
    /// `roughness_ra_um`, ...): `None` when absent or null (validation refuses other types).
    pub fn number(&self, key: &str) -> Option<f64> {
        self.extra.get(key).and_then(Value::as_f64)
    }
}

/// One test of an experiment set, as described in `experiment.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TestSpec {
    /// Test name, unique within the set.
    pub name: String,
    /// CSV file name, relative to the set's folder.
    pub file: String,
    /// Which column the apparatus imposed.
    pub control: ControlColumn,
    /// Constant normal stress, kPa (a `normal_kpa` CSV column overrides it per row).
    pub normal_stress_kpa: f64,
    /// How the test starts: from rest, or already sliding (a segment cut out of a longer run).
    /// `None`: decided from the data.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial: Option<InitialSpec>,
    /// Units of this test's CSV columns when they are not the format's own (kPa, mm, s); the
    /// set's `units` when the test gives none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<ColumnUnits>,
    /// Any other fields, kept as they are.
    #[serde(flatten)]
    pub extra: Map<String, Value>,
}

/// The units a logger wrote a test's CSV columns in (the optional `units` block of
/// `experiment.json`, for the whole set or per test): stresses (`shear_kpa`, `normal_kpa`),
/// displacements (`slip_mm`) and time (`time_s`). Each is converted to the format's own unit
/// (kPa, mm, s) as the CSV is read; a unit not given is the format's own. The fields of
/// `experiment.json` itself keep the units their names carry (`normal_stress_kpa` is kPa).
///
/// ```
/// use subfric_data::meta::ColumnUnits;
/// let u: ColumnUnits = serde_json::from_str(r#"{"stress": "MPa", "time": "min"}"#).unwrap();
/// let s = u.scale().unwrap();
/// assert_eq!((s.stress, s.displacement, s.time), (1000.0, 1.0, 60.0));
/// let bad: ColumnUnits = serde_json::from_str(r#"{"stress": "N"}"#).unwrap();
/// assert!(bad.scale().is_err()); // a force is not a stress
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnUnits {
    /// Unit of the stress columns: kPa, MPa, Pa or psi.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stress: Option<String>,
    /// Unit of the slip column: mm, um (µm), m or in.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displacement: Option<String>,
    /// Unit of the time column: s, ms, min or h.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<String>,
}

/// Factors that take a test's CSV columns to kPa, mm and s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColumnScale {
    /// kPa per unit of the stress columns.
    pub stress: f64,
    /// mm per unit of the slip column.
    pub displacement: f64,
    /// s per unit of the time column.
    pub time: f64,
}

impl ColumnScale {
    /// The format's own units: every factor 1.
    pub const OWN: ColumnScale = ColumnScale {
        stress: 1.0,
        displacement: 1.0,
        time: 1.0,
    };
}

/// The stress units a `units` block accepts (a force would need the contact area).
pub(crate) const STRESS_UNITS: &str = "kPa, MPa, Pa or psi";

/// kPa per unit of a stress unit `u` (a force is refused: it would need the contact area).
fn stress_factor(u: &str) -> Result<f64, String> {
    let unit: crate::import::StressUnit = u
        .parse()
        .map_err(|_| format!("unknown stress unit `{u}` (expected {STRESS_UNITS})"))?;
    if unit.is_force() {
        return Err(format!("`{u}` is a force, not a stress (expected {STRESS_UNITS}; `subfric import --area` divides a force column by the contact area)"));
    }
    Ok(unit.to_kpa())
}

/// mm per unit of a length unit `u`.
fn length_factor(u: &str) -> Result<f64, String> {
    u.parse::<crate::import::LengthUnit>().map(|l| l.to_mm())
}

/// s per unit of a time unit `u`.
fn time_factor(u: &str) -> Result<f64, String> {
    u.parse::<crate::import::TimeUnit>().map(|t| t.to_s())
}

/// Reads a unit: the factor to the format's own unit, or why it is not one.
type UnitReader = fn(&str) -> Result<f64, String>;

/// Each field of a `units` block with the function that reads its unit.
const UNIT_FIELDS: [(&str, UnitReader); 3] = [
    ("stress", stress_factor),
    ("displacement", length_factor),
    ("time", time_factor),
];

impl ColumnUnits {
    /// The factors to kPa, mm and s, or (field, message) for the first unit that is unknown.
    pub fn scale(&self) -> Result<ColumnScale, (&'static str, String)> {
        let factor = |field: &'static str, unit: &Option<String>, read: UnitReader| {
            unit.as_deref()
                .map_or(Ok(1.0), read)
                .map_err(|e| (field, e))
        };
        Ok(ColumnScale {
            stress: factor("stress", &self.stress, stress_factor)?,
            displacement: factor("displacement", &self.displacement, length_factor)?,
            time: factor("time", &self.time, time_factor)?,
        })
    }
}

/// The optional `initial` field of a test.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum InitialSpec {
    /// The test starts from an unloaded interface at rest.
    Rest,
    /// The file is a segment cut out of a longer run: the interface is already sliding (or
    /// loaded) at its first row.
    Sliding,
}

impl TestSpec {
    /// A test spec without extra fields.
    pub fn new(name: &str, file: &str, control: ControlColumn, normal_stress_kpa: f64) -> Self {
        TestSpec {
            name: name.to_string(),
            file: file.to_string(),
            control,
            normal_stress_kpa,
            initial: None,
            units: None,
            extra: Map::new(),
        }
    }

    /// Factors from this test's CSV columns to kPa, mm and s (1 where no unit is given), or
    /// (field, message) for a unit that is unknown.
    pub fn column_scale(&self) -> Result<ColumnScale, (&'static str, String)> {
        self.units
            .as_ref()
            .map_or(Ok(ColumnScale::OWN), ColumnUnits::scale)
    }
}

/// The contents of `experiment.json`.
///
/// Optional fields and unknown fields round-trip through serialisation.
///
/// ```
/// use subfric_data::ExperimentMeta;
/// let text = r#"{"name": "s", "title": "t", "source": "src", "custom": 1,
///   "interface": {"soil": "sand"},
///   "tests": [{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}]}"#;
/// let meta: ExperimentMeta = serde_json::from_str(text).unwrap();
/// assert_eq!(meta.tests[0].normal_stress_kpa, 100.0);
/// let back: ExperimentMeta = serde_json::from_str(&serde_json::to_string(&meta).unwrap()).unwrap();
/// assert_eq!(back, meta);
/// assert_eq!(back.extra["custom"], 1);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExperimentMeta {
    /// Short name of the set (usually the folder name).
    pub name: String,
    /// Human-readable title.
    pub title: String,
    /// Where the data come from.
    pub source: String,
    /// How the curves were obtained (measured, digitised, reconstructed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<String>,
    /// The interface tested.
    #[serde(default)]
    pub interface: Interface,
    /// The tests, one CSV each.
    pub tests: Vec<TestSpec>,
    /// Published parameter values to compare a fit against.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_parameters: Option<Value>,
    /// Units of the tests' CSV columns when they are not the format's own (a test's own
    /// `units` takes precedence); [`parse_meta`] hands them to each test that gives none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<ColumnUnits>,
    /// Any other fields, kept as they are.
    #[serde(flatten)]
    pub extra: Map<String, Value>,
}

/// What a JSON value is, for messages.
fn kind_of(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// Checks a relative file name: no absolute path, no `..`, not empty.
pub(crate) fn file_name_problem(file: &str) -> Option<String> {
    if file.trim().is_empty() {
        return Some("empty file name (expected a CSV file name such as `test.csv`)".into());
    }
    let p = Path::new(file);
    let ok = p
        .components()
        .all(|c| matches!(c, Component::Normal(_) | Component::CurDir));
    if !ok {
        return Some(format!(
            "file `{file}` is not a plain relative path (expected a file inside the set's folder, without `..` or a leading `/`)"
        ));
    }
    None
}

/// The 1-based line where the value of `field` (a JSON path: `reference_parameters`,
/// `tests[1].file`, ...) starts in the JSON `text`, for messages about a value found wrong
/// after parsing.
///
/// ```
/// let text = "{\n  \"name\": \"a\",\n  \"reference_parameters\": {\"mu_s\": -1}\n}";
/// assert_eq!(subfric_data::meta::field_line(text, "reference_parameters"), Some(3));
/// assert_eq!(subfric_data::meta::field_line(text, "nothing"), None);
/// ```
pub fn field_line(text: &str, field: &str) -> Option<usize> {
    value_positions(text).get(field).map(|p| p.0)
}

/// Parses and validates the text of an `experiment.json`; `path` is used in messages.
///
/// All shape problems are collected (missing or mistyped fields, unknown control, duplicate
/// test names, non-positive normal stress) before an error is returned.
pub fn parse_meta(text: &str, path: &Path) -> Result<ExperimentMeta, DataError> {
    let value: Value = serde_json::from_str(text).map_err(|e| DataError::Json {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message: format!("{e} (expected valid JSON)"),
    })?;
    let pos = value_positions(text);
    let mut problems = Problems::default();
    for (field, line, column) in crate::jsonpos::duplicate_keys(text) {
        problems.add(
            path,
            Some(line),
            Some(&field),
            format!("appears twice (the second at column {column}) (expected each field once: which of the two values is meant?)"),
        );
    }
    if !problems.is_empty() {
        return Err(DataError::Problems(problems.into_vec()));
    }
    check_shape(&value, path, &pos, &mut problems);
    if !problems.is_empty() {
        return Err(DataError::Problems(problems.into_vec()));
    }
    let mut meta = serde_json::from_str::<ExperimentMeta>(text).map_err(|e| DataError::Json {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    // The set's units hold for every test that states none of its own.
    if let Some(units) = &meta.units {
        for t in meta.tests.iter_mut().filter(|t| t.units.is_none()) {
            t.units = Some(units.clone());
        }
    }
    Ok(meta)
}

struct Ctx<'a> {
    path: &'a Path,
    pos: &'a HashMap<String, (usize, usize)>,
}

impl Ctx<'_> {
    fn line(&self, field: &str) -> Option<usize> {
        // the field itself, else the closest enclosing value
        let mut f = field.to_string();
        loop {
            if let Some((l, _)) = self.pos.get(&f) {
                return Some(*l);
            }
            match f.rfind(['.', '[']) {
                Some(i) => f.truncate(i),
                None => return self.pos.get("").map(|p| p.0),
            }
        }
    }

    fn problem(&self, problems: &mut Problems, field: &str, message: String) {
        problems.add(self.path, self.line(field), Some(field), message);
    }

    /// Required (or optional) string field.
    fn string<'v>(
        &self,
        obj: &'v Map<String, Value>,
        prefix: &str,
        key: &str,
        required: bool,
        problems: &mut Problems,
    ) -> Option<&'v str> {
        let field = join(prefix, key);
        match obj.get(key) {
            Some(Value::String(s)) => Some(s),
            Some(Value::Null) | None if !required => None,
            None => {
                problems.add(
                    self.path,
                    self.line(prefix),
                    Some(&field),
                    format!("missing required field `{key}` (expected a string)"),
                );
                None
            }
            Some(v) => {
                self.problem(
                    problems,
                    &field,
                    format!("found {} (expected a string)", kind_of(v)),
                );
                None
            }
        }
    }
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

/// Checks the shape of `experiment.json` before it is deserialised, so that every problem is
/// reported at once with its line and field (serde would stop at the first).
fn check_shape(v: &Value, path: &Path, pos: &HashMap<String, (usize, usize)>, pr: &mut Problems) {
    let cx = Ctx { path, pos };
    let Value::Object(root) = v else {
        pr.add(
            path,
            Some(1),
            None,
            format!(
                "found {} (expected a JSON object with name, title, source and tests)",
                kind_of(v)
            ),
        );
        return;
    };
    cx.check_header(root, pr);
    cx.check_interface(root, pr);
    cx.check_units(root, "", pr);
    let Some(tests) = cx.tests_array(root, pr) else {
        return;
    };
    // First index of each test name and file, for the duplicates' messages.
    let mut names: HashMap<String, usize> = HashMap::new();
    let mut files: HashMap<String, usize> = HashMap::new();
    for (i, t) in tests.iter().enumerate() {
        let prefix = format!("tests[{i}]");
        let Value::Object(t) = t else {
            cx.problem(
                pr,
                &prefix,
                format!(
                    "found {} (expected an object with name, file, control, normal_stress_kpa)",
                    kind_of(t)
                ),
            );
            continue;
        };
        cx.check_test_name(t, &prefix, i, &mut names, pr);
        cx.check_test_file(t, &prefix, i, &mut files, pr);
        cx.check_control(t, &prefix, pr);
        cx.check_initial(t, &prefix, pr);
        cx.check_normal_stress(t, &prefix, pr);
        cx.check_units(t, &prefix, pr);
    }
}

/// The parts of [`check_shape`].
impl Ctx<'_> {
    /// name (not empty), title, source, provenance.
    fn check_header(&self, root: &Map<String, Value>, pr: &mut Problems) {
        if let Some(name) = self.string(root, "", "name", true, pr) {
            if name.trim().is_empty() {
                self.problem(
                    pr,
                    "name",
                    "empty name (expected a short name for the set)".into(),
                );
            } else if let Some(msg) = name_too_long(name, "a set name") {
                self.problem(pr, "name", msg);
            }
        }
        self.string(root, "", "title", true, pr);
        self.string(root, "", "source", true, pr);
        self.string(root, "", "provenance", false, pr);
    }

    /// The optional `units` block (of the set, or of a test under `prefix`): an object of
    /// strings `stress`, `displacement` and `time`, each a unit the reader knows.
    fn check_units(&self, obj: &Map<String, Value>, prefix: &str, pr: &mut Problems) {
        let field = join(prefix, "units");
        let expected = format!(
            "expected an object such as {{\"stress\": \"MPa\", \"displacement\": \"mm\", \"time\": \"s\"}}: stress {STRESS_UNITS}; displacement mm, um, m or in; time s, ms, min or h"
        );
        let units = match obj.get("units") {
            None | Some(Value::Null) => return,
            Some(Value::Object(u)) => u,
            Some(v) => {
                self.problem(pr, &field, format!("found {} ({expected})", kind_of(v)));
                return;
            }
        };
        for (key, value) in units {
            let at = format!("{field}.{key}");
            let Some((_, read)) = UNIT_FIELDS.iter().find(|(name, _)| name == key) else {
                self.problem(pr, &at, format!("unknown unit field `{key}` ({expected})"));
                continue;
            };
            match value {
                Value::String(u) => {
                    if let Err(msg) = read(u) {
                        self.problem(pr, &at, msg);
                    }
                }
                v => self.problem(pr, &at, format!("found {} ({expected})", kind_of(v))),
            }
        }
    }

    /// The optional `interface` object.
    fn check_interface(&self, root: &Map<String, Value>, pr: &mut Problems) {
        match root.get("interface") {
            None | Some(Value::Null) => {}
            Some(Value::Object(iface)) => {
                self.string(iface, "interface", "soil", false, pr);
                self.string(iface, "interface", "surface", false, pr);
                let rmax = ("roughness_rmax_um", "µm", "maximum roughness R_max");
                for (key, unit, what) in std::iter::once(rmax).chain(INTERFACE_NUMBERS) {
                    self.check_size(iface, key, unit, what, pr);
                }
            }
            Some(v) => self.problem(
                pr,
                "interface",
                format!(
                    "found {} (expected an object with soil, d50_mm, surface, roughness_rmax_um, roughness_ra_um)",
                    kind_of(v)
                ),
            ),
        }
    }

    /// An optional size of the interface (`interface.<key>`): a finite number ≥ 0 (> 0 for a
    /// grain size, which normalised roughness divides by).
    fn check_size(
        &self,
        iface: &Map<String, Value>,
        key: &str,
        unit: &str,
        what: &str,
        pr: &mut Problems,
    ) {
        let field = format!("interface.{key}");
        let grain = key.starts_with("d50");
        match iface.get(key) {
            None | Some(Value::Null) => {}
            Some(Value::Number(n)) => match n.as_f64() {
                Some(x)
                    if x.is_finite() && x <= MAX_MAGNITUDE && (x > 0.0 || !grain && x == 0.0) => {}
                Some(x) if x > MAX_MAGNITUDE => self.problem(
                    pr,
                    &field,
                    format!(
                        "{} {unit} is beyond {MAX_MAGNITUDE:e} (expected the {what} in {unit}: a typing or unit mistake?)",
                        crate::text::short_number(x)
                    ),
                ),
                _ => self.problem(
                    pr,
                    &field,
                    if grain {
                        format!("{n} {unit} is not positive (expected the {what} in {unit}, > 0)")
                    } else {
                        format!("{n} {unit} is negative (expected the {what} in {unit}, ≥ 0)")
                    },
                ),
            },
            Some(v) => self.problem(
                pr,
                &field,
                format!("found {} (expected a number, {unit})", kind_of(v)),
            ),
        }
    }

    /// The `tests` array (`None`, with the problem recorded, when it is missing or not an
    /// array; an empty array is a problem too, but returned).
    fn tests_array<'v>(
        &self,
        root: &'v Map<String, Value>,
        pr: &mut Problems,
    ) -> Option<&'v Vec<Value>> {
        let tests = match root.get("tests") {
            Some(Value::Array(t)) => t,
            None => {
                pr.add(
                    self.path,
                    self.line(""),
                    Some("tests"),
                    "missing required field `tests` (expected an array of tests)",
                );
                return None;
            }
            Some(v) => {
                self.problem(
                    pr,
                    "tests",
                    format!("found {} (expected an array of tests)", kind_of(v)),
                );
                return None;
            }
        };
        if tests.is_empty() {
            self.problem(pr, "tests", "no tests (expected at least one test)".into());
        }
        Some(tests)
    }

    /// A test's name: present, not empty, not used by an earlier test (`names`: first index).
    fn check_test_name(
        &self,
        t: &Map<String, Value>,
        prefix: &str,
        i: usize,
        names: &mut HashMap<String, usize>,
        pr: &mut Problems,
    ) {
        let Some(name) = self.string(t, prefix, "name", true, pr) else {
            return;
        };
        let field = format!("{prefix}.name");
        if name.trim().is_empty() {
            self.problem(
                pr,
                &field,
                "empty test name (expected a unique name)".into(),
            );
        } else if let Some(msg) = name_too_long(name, "a test name") {
            self.problem(pr, &field, msg);
        } else if let Some(first) = names.get(name) {
            self.problem(
                pr,
                &field,
                format!("duplicate test name `{name}`, already used by tests[{first}] (expected unique test names)"),
            );
        } else {
            names.insert(name.to_string(), i);
        }
    }

    /// A test's file: present, a plain file name, not used by an earlier test (`files`: first
    /// index).
    fn check_test_file(
        &self,
        t: &Map<String, Value>,
        prefix: &str,
        i: usize,
        files: &mut HashMap<String, usize>,
        pr: &mut Problems,
    ) {
        let Some(file) = self.string(t, prefix, "file", true, pr) else {
            return;
        };
        let field = format!("{prefix}.file");
        if let Some(msg) = file_name_problem(file) {
            self.problem(pr, &field, msg);
        } else if let Some(first) = files.get(file) {
            self.problem(
                pr,
                &field,
                format!(
                    "file `{file}` is already used by tests[{first}] (expected one CSV per test)"
                ),
            );
        } else {
            files.insert(file.to_string(), i);
        }
    }

    /// A test's required `control`: "slip" or "shear".
    fn check_control(&self, t: &Map<String, Value>, prefix: &str, pr: &mut Problems) {
        let field = format!("{prefix}.control");
        match t.get("control") {
            Some(Value::String(s)) if s == "slip" || s == "shear" => {}
            Some(Value::String(s)) => self.problem(
                pr,
                &field,
                format!("unknown control `{s}` (expected \"slip\" or \"shear\")"),
            ),
            Some(v) => self.problem(
                pr,
                &field,
                format!("found {} (expected \"slip\" or \"shear\")", kind_of(v)),
            ),
            None => pr.add(
                self.path,
                self.line(prefix),
                Some(&field),
                "missing required field `control` (expected \"slip\" or \"shear\")",
            ),
        }
    }

    /// A test's optional `initial`: "rest" or "sliding".
    fn check_initial(&self, t: &Map<String, Value>, prefix: &str, pr: &mut Problems) {
        let field = format!("{prefix}.initial");
        match t.get("initial") {
            None | Some(Value::Null) => {}
            Some(Value::String(s)) if s == "rest" || s == "sliding" => {}
            Some(Value::String(s)) => self.problem(
                pr,
                &field,
                format!("unknown initial state `{s}` (expected \"rest\" or \"sliding\")"),
            ),
            Some(v) => self.problem(
                pr,
                &field,
                format!("found {} (expected \"rest\" or \"sliding\")", kind_of(v)),
            ),
        }
    }

    /// A test's required `normal_stress_kpa`: a finite number > 0.
    fn check_normal_stress(&self, t: &Map<String, Value>, prefix: &str, pr: &mut Problems) {
        let field = format!("{prefix}.normal_stress_kpa");
        match t.get("normal_stress_kpa") {
            Some(Value::Number(n)) => match n.as_f64() {
                Some(x) if x > 0.0 && x.is_finite() && x <= MAX_MAGNITUDE => {}
                Some(x) if x > 0.0 => self.problem(
                    pr,
                    &field,
                    format!(
                        "normal stress {x:e} kPa is beyond {MAX_MAGNITUDE:e} kPa (expected a measured normal stress in kPa: a typing or unit mistake?)"
                    ),
                ),
                _ => self.problem(
                    pr,
                    &field,
                    format!(
                        "normal stress {} kPa is not positive (expected a normal stress > 0 kPa)",
                        n.as_f64().map_or_else(|| n.to_string(), crate::text::short_number)
                    ),
                ),
            },
            Some(v) => self.problem(
                pr,
                &field,
                format!("found {} (expected a number, kPa)", kind_of(v)),
            ),
            None => pr.add(
                self.path,
                self.line(prefix),
                Some(&field),
                "missing required field `normal_stress_kpa` (expected a number, kPa)",
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problems(text: &str) -> Vec<String> {
        match parse_meta(text, Path::new("x/experiment.json")) {
            Err(DataError::Problems(p)) => p.iter().map(|p| p.to_string()).collect(),
            Err(e) => vec![e.to_string()],
            Ok(_) => vec![],
        }
    }

    #[test]
    fn reports_all_shape_problems_with_lines() {
        let text = "{\n\"name\": \"s\",\n\"source\": 3,\n\"tests\": [\n {\"name\": \"a\", \"file\": \"a.csv\", \"control\": \"slide\", \"normal_stress_kpa\": 100},\n {\"name\": \"a\", \"file\": \"../b.csv\", \"control\": \"slip\", \"normal_stress_kpa\": -1}\n]}";
        let p = problems(text);
        let all = p.join("\n");
        assert!(
            all.contains("x/experiment.json:1: field `title`: missing required field"),
            "{all}"
        );
        assert!(
            all.contains("x/experiment.json:3: field `source`: found a number (expected a string)"),
            "{all}"
        );
        assert!(
            all.contains(":5: field `tests[0].control`: unknown control `slide`"),
            "{all}"
        );
        assert!(
            all.contains(":6: field `tests[1].name`: duplicate test name `a`"),
            "{all}"
        );
        assert!(all.contains(":6: field `tests[1].file`"), "{all}");
        assert!(
            all.contains(":6: field `tests[1].normal_stress_kpa`: normal stress -1 kPa"),
            "{all}"
        );
        assert_eq!(p.len(), 6, "{all}");
    }

    #[test]
    fn names_too_long_for_a_file_and_normal_stresses_beyond_measurement_are_located() {
        let long = "n".repeat(256);
        let ok = "m".repeat(255);
        let text = format!(
            "{{\"name\": \"{long}\", \"title\": \"t\", \"source\": \"x\", \"tests\": [\n{{\"name\": \"a\", \"file\": \"a.csv\", \"control\": \"slip\", \"normal_stress_kpa\": 1e308}},\n{{\"name\": \"{long}\", \"file\": \"b.csv\", \"control\": \"slip\", \"normal_stress_kpa\": 100}},\n{{\"name\": \"{ok}\", \"file\": \"c.csv\", \"control\": \"slip\", \"normal_stress_kpa\": 100}}]}}"
        );
        let p = problems(&text);
        let all = p.join("\n");
        assert_eq!(p.len(), 3, "{all}");
        assert!(
            all.contains(":1: field `name`: a set name of 256 bytes is longer than 255"),
            "{all}"
        );
        assert!(
            all.contains(":2: field `tests[0].normal_stress_kpa`: normal stress 1e308 kPa is beyond 1e12 kPa"),
            "{all}"
        );
        assert!(
            all.contains(":3: field `tests[1].name`: a test name of 256 bytes"),
            "{all}"
        );
    }

    #[test]
    fn initial_field_is_rest_or_sliding() {
        let ok = r#"{"name": "s", "title": "t", "source": "x", "tests": [
            {"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100, "initial": "sliding"},
            {"name": "b", "file": "b.csv", "control": "slip", "normal_stress_kpa": 100}]}"#;
        let meta = parse_meta(ok, Path::new("e.json")).unwrap();
        assert_eq!(meta.tests[0].initial, Some(InitialSpec::Sliding));
        assert_eq!(meta.tests[1].initial, None);
        let bad = "{\"name\": \"s\", \"title\": \"t\", \"source\": \"x\", \"tests\": [\n{\"name\": \"a\", \"file\": \"a.csv\", \"control\": \"slip\", \"normal_stress_kpa\": 100, \"initial\": \"moving\"}]}";
        let all = problems(bad).join("\n");
        assert!(
            all.contains(":2: field `tests[0].initial`: unknown initial state `moving` (expected \"rest\" or \"sliding\")"),
            "{all}"
        );
    }

    #[test]
    fn interface_sizes_are_optional_numbers_located_when_wrong() {
        let head = "{\"name\": \"s\", \"title\": \"t\", \"source\": \"x\",\n";
        let tests = "\"tests\": [{\"name\": \"a\", \"file\": \"a.csv\", \"control\": \"slip\", \"normal_stress_kpa\": 100}]}";
        let ok = format!("{head}\"interface\": {{\"soil\": \"Toyoura\", \"d50_mm\": 0.18, \"roughness_rmax_um\": 0, \"roughness_ra_um\": 1.2}},\n{tests}");
        let meta = parse_meta(&ok, Path::new("e.json")).unwrap();
        assert_eq!(meta.interface.number("d50_mm"), Some(0.18));
        assert_eq!(meta.interface.number("roughness_ra_um"), Some(1.2));
        assert_eq!(meta.interface.roughness_rmax_um, Some(0.0));
        let none = format!("{head}\"interface\": {{\"soil\": \"Toyoura\"}},\n{tests}");
        let meta = parse_meta(&none, Path::new("e.json")).unwrap();
        assert_eq!(meta.interface.number("d50_mm"), None);
        let bad = format!("{head}\"interface\": {{\"d50_mm\": 0,\n\"roughness_ra_um\": \"1.2\",\n\"roughness_rmax_um\": -3}},\n{tests}");
        let all = problems(&bad).join("\n");
        assert!(
            all.contains(
                ":2: field `interface.d50_mm`: 0 mm is not positive (expected the median grain size D50 of the soil in mm, > 0)"
            ),
            "{all}"
        );
        assert!(
            all.contains(
                ":3: field `interface.roughness_ra_um`: found a string (expected a number, µm)"
            ),
            "{all}"
        );
        assert!(
            all.contains(":4: field `interface.roughness_rmax_um`: -3 µm is negative"),
            "{all}"
        );
    }

    #[test]
    fn syntax_error_has_line_and_column() {
        let e = parse_meta(
            "{\n \"name\": \"s\",\n \"title\" \"t\"\n}",
            Path::new("e.json"),
        )
        .unwrap_err();
        match e {
            DataError::Json {
                line,
                column,
                ref path,
                ..
            } => {
                assert_eq!(line, 3);
                assert!(column > 1);
                assert_eq!(path, Path::new("e.json"));
            }
            other => panic!("unexpected {other}"),
        }
        assert!(e.to_string().starts_with("e.json:3:"));
    }
}
