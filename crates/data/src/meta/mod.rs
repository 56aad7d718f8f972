//! The experiment description `experiment.json`: types and validation.

mod shape;
mod units;

pub use units::{ColumnScale, ColumnUnits};

use std::fmt;
use std::path::{Component, Path};
use std::str::FromStr;

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::error::{DataError, Problems};
use crate::jsonpos::value_positions;
use shape::check_shape;

/// Which column the apparatus imposed, as declared in `experiment.json` (the model's
/// counterpart is `subfric_model::Control`; `subfric_reading::control_of` converts).
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

/// The optional field of a constant-normal-stiffness test: the stiffness of the springs that
/// set its normal stress as the specimen dilates [kPa/mm]. Metadata: the model is driven by the
/// normal stress each row carries (`normal_kpa`), which is what such a test records.
pub const NORMAL_STIFFNESS_FIELD: &str = "normal_stiffness_kpa_per_mm";

impl TestSpec {
    /// The normal stiffness of a constant-normal-stiffness test [kPa/mm], when the test gives
    /// one ([`NORMAL_STIFFNESS_FIELD`]).
    pub fn normal_stiffness_kpa_per_mm(&self) -> Option<f64> {
        self.extra
            .get(NORMAL_STIFFNESS_FIELD)
            .and_then(Value::as_f64)
    }

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
    fn a_constant_normal_stiffness_is_a_positive_number_kept_as_metadata() {
        let ok = r#"{"name": "s", "title": "t", "source": "x", "tests": [
            {"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100, "normal_stiffness_kpa_per_mm": 500},
            {"name": "b", "file": "b.csv", "control": "slip", "normal_stress_kpa": 100}]}"#;
        let meta = parse_meta(ok, Path::new("e.json")).unwrap();
        assert_eq!(meta.tests[0].normal_stiffness_kpa_per_mm(), Some(500.0));
        assert_eq!(meta.tests[1].normal_stiffness_kpa_per_mm(), None);
        let bad = "{\"name\": \"s\", \"title\": \"t\", \"source\": \"x\", \"tests\": [\n{\"name\": \"a\", \"file\": \"a.csv\", \"control\": \"slip\", \"normal_stress_kpa\": 100, \"normal_stiffness_kpa_per_mm\": -5},\n{\"name\": \"b\", \"file\": \"b.csv\", \"control\": \"slip\", \"normal_stress_kpa\": 100, \"normal_stiffness_kpa_per_mm\": \"stiff\"}]}";
        let all = problems(bad).join("\n");
        assert!(
            all.contains(":2: field `tests[0].normal_stiffness_kpa_per_mm`: normal stiffness -5 kPa/mm (expected a number > 0"),
            "{all}"
        );
        assert!(
            all.contains(":3: field `tests[1].normal_stiffness_kpa_per_mm`: found a string (expected a number, kPa/mm)"),
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
