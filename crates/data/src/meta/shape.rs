//! The shape of `experiment.json`, checked before it is deserialised, every problem located.

use std::collections::HashMap;
use std::path::Path;

use serde_json::{Map, Value};

use super::units::{STRESS_UNITS, UNIT_FIELDS};
use super::{file_name_problem, INTERFACE_NUMBERS, NORMAL_STIFFNESS_FIELD};
use crate::error::Problems;
use crate::set::MAX_MAGNITUDE;
use crate::text::name_too_long;

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
pub(super) fn check_shape(
    v: &Value,
    path: &Path,
    pos: &HashMap<String, (usize, usize)>,
    pr: &mut Problems,
) {
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
        cx.check_normal_stiffness(t, &prefix, pr);
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

    /// A constant-normal-stiffness test's optional `normal_stiffness_kpa_per_mm`: a finite
    /// number > 0 (metadata: the model is driven by the normal stress the rows carry).
    fn check_normal_stiffness(&self, t: &Map<String, Value>, prefix: &str, pr: &mut Problems) {
        let field = format!("{prefix}.{NORMAL_STIFFNESS_FIELD}");
        let problem = match t.get(NORMAL_STIFFNESS_FIELD) {
            None => return,
            Some(Value::Number(n)) => match n.as_f64() {
                Some(x) if x > 0.0 && x.is_finite() && x <= MAX_MAGNITUDE => return,
                _ => format!(
                    "normal stiffness {} kPa/mm (expected a number > 0 and at most {MAX_MAGNITUDE:e}: the stiffness of the springs of a constant-normal-stiffness test)",
                    n.as_f64().map_or_else(|| n.to_string(), crate::text::short_number)
                ),
            },
            Some(v) => format!("found {} (expected a number, kPa/mm)", kind_of(v)),
        };
        self.problem(pr, &field, problem);
    }
}
