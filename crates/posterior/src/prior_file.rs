//! The prior file: JSON or TOML (by extension), one entry per parameter, keyed as
//! `Param::key()` prints it:
//!
//! ```toml
//! [kappa]
//! dist = "log-uniform"
//! lo = 0.1
//! hi = 100.0
//!
//! [xi]
//! dist = "log-normal"
//! median = 0.002
//! sigma = 1.0
//!
//! [rate.a]          # extension parameters by their key (TOML nests `rate.a` as a table)
//! dist = "normal"
//! mean = 0.0
//! sd = 0.01
//! ```
//!
//! The JSON form is the same object: `{"kappa": {"dist": "log-uniform", "lo": 0.1, "hi": 100}}`.
//! Every problem of the file is reported at once, each with the file, the line and the field,
//! and what was expected; nothing in a file can make this module panic.

use crate::prior::{numbers_problem, sign_problem, Origin, Prior, PriorEntry, PriorError, Priors};
use std::path::Path;
use subfric_data::located::{self, Expected, Node, Val};
use subfric_data::InputProblem;
use subfric_fit::Param;

/// What a prior file holds, in the words of its messages.
const EXPECTED: Expected = Expected {
    file: "prior file",
    json: "an object of priors keyed by parameter",
    toml: "one table of priors per parameter",
    content: "a table of priors keyed by parameter",
};

/// Reads and checks a prior file.
pub fn load(path: &Path) -> Result<Priors, PriorError> {
    let text = subfric_data::fsio::read_user_text(
        path,
        "the prior file",
        subfric_data::fsio::MAX_SETTINGS_FILE_BYTES,
    )
    .map_err(|e| match e {
        subfric_data::DataError::Io { path, source } => PriorError::Io { path, source },
        e => PriorError::Invalid(e.problems().to_vec()),
    })?;
    parse(&text, path)
}

/// Parses and checks the text of a prior file; `path` names it in messages and its extension
/// (`.json` or `.toml`) selects the format.
pub fn parse(text: &str, path: &Path) -> Result<Priors, PriorError> {
    let root = located::parse(text, path, &EXPECTED).map_err(|p| PriorError::Invalid(vec![p]))?;
    let mut problems = Vec::new();
    let mut entries: Vec<PriorEntry> = Vec::new();
    match root.value {
        Val::Table(items) => {
            for (key, node) in items {
                entry(path, &key, node, &mut entries, &mut problems);
            }
        }
        _ => problems.push(InputProblem::new(
            path,
            Some(root.line),
            None,
            "expected a table of priors keyed by parameter, e.g. {\"kappa\": {\"dist\": \"uniform\", \"lo\": 0.1, \"hi\": 10}}",
        )),
    }
    if problems.is_empty() {
        Ok(Priors::from_entries(entries))
    } else {
        problems.sort_by_key(|p| p.line);
        Err(PriorError::Invalid(problems))
    }
}

/// One top-level entry: a parameter's prior, or (TOML's `[rate.a]`) a group of them.
fn entry(
    path: &Path,
    key: &str,
    node: Node,
    entries: &mut Vec<PriorEntry>,
    problems: &mut Vec<InputProblem>,
) {
    let line = node.line;
    let at = |m: String| InputProblem::new(path, Some(line), Some(key), m);
    let Val::Table(fields) = node.value else {
        problems.push(at(format!(
            "a {} where a prior belongs (expected a table such as {{dist = \"uniform\", lo = 0.1, hi = 10}})",
            type_name(&node.value)
        )));
        return;
    };
    let is_group = !fields.iter().any(|(k, _)| k == "dist")
        && !fields.is_empty()
        && fields.iter().all(|(_, n)| matches!(n.value, Val::Table(_)));
    if is_group && Param::from_key(key).is_none() {
        for (sub, n) in fields {
            entry(path, &format!("{key}.{sub}"), n, entries, problems);
        }
        return;
    }
    let Some(param) = Param::from_key(key) else {
        problems.push(at(format!(
            "unknown parameter `{key}` (expected one of: {})",
            Param::all()
                .iter()
                .map(|p| p.key())
                .collect::<Vec<_>>()
                .join(", ")
        )));
        return;
    };
    if let Some(first) = entries.iter().find(|e| e.param == param) {
        let first_line = first.origin.as_ref().map_or(0, |o| o.line);
        problems.push(at(format!(
            "a second prior for {key} (the first is on line {first_line}; expected one prior per parameter)"
        )));
        return;
    }
    if let Some(prior) = prior_of(path, key, line, fields, problems) {
        let origin = Origin {
            file: path.to_path_buf(),
            line,
        };
        match numbers_problem(&prior).or_else(|| sign_problem(param, &prior)) {
            Some(m) => problems.push(at(m)),
            None => entries.push(PriorEntry {
                param,
                prior,
                origin: Some(origin),
            }),
        }
    }
}

/// The fields each distribution takes.
const DISTRIBUTIONS: &str =
    "uniform (lo, hi), log-uniform (lo, hi), normal (mean, sd), log-normal (median or mu, sigma)";

/// A distribution a prior file names (`dist`), with the fields it takes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Distribution {
    Uniform,
    LogUniform,
    Normal,
    LogNormal,
}

impl Distribution {
    /// The distribution named `name`, whatever its case and its `-`, `_` or spaces.
    fn from_name(name: &str) -> Option<Self> {
        let normalised: String = name
            .chars()
            .filter(|c| *c != '-' && *c != '_' && *c != ' ')
            .flat_map(|c| c.to_lowercase())
            .collect();
        match normalised.as_str() {
            "uniform" => Some(Self::Uniform),
            "loguniform" => Some(Self::LogUniform),
            "normal" => Some(Self::Normal),
            "lognormal" => Some(Self::LogNormal),
            _ => None,
        }
    }

    /// The number fields it takes.
    fn fields(self) -> &'static [&'static str] {
        match self {
            Self::Uniform | Self::LogUniform => &["lo", "hi"],
            Self::Normal => &["mean", "sd"],
            Self::LogNormal => &["median", "mu", "sigma"],
        }
    }

    /// What it needs, in words.
    fn needs(self) -> String {
        match self {
            Self::LogNormal => "median or mu, and sigma".to_string(),
            other => other.fields().join(" and "),
        }
    }
}

/// The fields of one prior's table as read: the distribution's name and line, the numbers with
/// their lines, and every field present (even with an unusable value, which is reported once,
/// never again as missing).
struct PriorFields {
    dist: Option<(String, usize)>,
    numbers: Vec<(String, f64, usize)>,
    present: Vec<String>,
}

impl PriorFields {
    /// The number given for field `name`.
    fn get(&self, name: &str) -> Option<f64> {
        self.numbers
            .iter()
            .find(|(k, _, _)| k == name)
            .map(|(_, v, _)| *v)
    }
}

/// Reads the fields of a prior's table: each given once, `dist` a name, the others finite
/// numbers; what is not is pushed to `problems` through `field_at` (field, line, message).
fn read_fields(
    fields: Vec<(String, Node)>,
    field_at: &dyn Fn(&str, usize, String) -> InputProblem,
    problems: &mut Vec<InputProblem>,
) -> PriorFields {
    let mut read = PriorFields {
        dist: None,
        numbers: Vec::new(),
        present: fields.iter().map(|(k, _)| k.clone()).collect(),
    };
    for (name, n) in fields {
        if read.numbers.iter().any(|(k, _, _)| *k == name)
            || (name == "dist" && read.dist.is_some())
        {
            problems.push(field_at(
                &name,
                n.line,
                "given twice (expected each field once)".into(),
            ));
            continue;
        }
        match (name.as_str(), n.value) {
            ("dist", Val::Text(t)) => read.dist = Some((t, n.line)),
            ("dist", other) => problems.push(field_at(
                "dist",
                n.line,
                format!("a {} (expected a name: {DISTRIBUTIONS})", type_name(&other)),
            )),
            (_, Val::Number { value: v, .. }) if !v.is_finite() => problems.push(field_at(
                &name,
                n.line,
                format!("{v} is not finite (expected a finite number)"),
            )),
            (_, Val::Number { value: v, .. }) => read.numbers.push((name, v, n.line)),
            (_, Val::Text(t)) => problems.push(field_at(
                &name,
                n.line,
                format!("\"{t}\" is text (expected a number)"),
            )),
            (_, other) => problems.push(field_at(
                &name,
                n.line,
                format!("a {} (expected a number)", type_name(&other)),
            )),
        }
    }
    read
}

/// μ of a log-normal prior: ln(median), or μ as given; one of them, never both, and a median
/// above zero. `None` (the problem pushed, at the table's `line`) otherwise.
fn log_normal_mu(
    read: &PriorFields,
    line: usize,
    field_at: &dyn Fn(&str, usize, String) -> InputProblem,
    problems: &mut Vec<InputProblem>,
) -> Option<f64> {
    let problem = match (read.get("median"), read.get("mu")) {
        (Some(m), None) if m > 0.0 => return Some(m.ln()),
        (None, Some(mu)) => return Some(mu),
        (Some(m), None) => format!("{m} is not positive (expected median > 0)"),
        (Some(_), Some(_)) => {
            "both median and mu given (expected one of them: mu = ln(median))".into()
        }
        (None, None) => "missing (a log-normal prior needs median or mu, and sigma)".into(),
    };
    problems.push(field_at("median", line, problem));
    None
}

/// A prior from the fields of its table; `None` (with problems pushed) when they do not make one.
fn prior_of(
    path: &Path,
    key: &str,
    line: usize,
    fields: Vec<(String, Node)>,
    problems: &mut Vec<InputProblem>,
) -> Option<Prior> {
    let before = problems.len();
    let field_at = |name: &str, l: usize, m: String| {
        InputProblem::new(path, Some(l), Some(&format!("{key}.{name}")), m)
    };
    let read = read_fields(fields, &field_at, problems);
    let Some((dist, dist_line)) = &read.dist else {
        problems.push(field_at(
            "dist",
            line,
            format!("missing (expected one of: {DISTRIBUTIONS})"),
        ));
        return None;
    };
    let Some(distribution) = Distribution::from_name(dist) else {
        problems.push(field_at(
            "dist",
            *dist_line,
            format!("unknown distribution \"{dist}\" (expected one of: {DISTRIBUTIONS})"),
        ));
        return None;
    };
    let wanted = distribution.fields();
    for (name, _, l) in &read.numbers {
        if !wanted.contains(&name.as_str()) {
            problems.push(field_at(
                name,
                *l,
                format!(
                    "not a field of a {dist} prior (expected only: dist, {})",
                    wanted.join(", ")
                ),
            ));
        }
    }
    let mut need = |n: &str| {
        let v = read.get(n);
        if v.is_none() && !read.present.iter().any(|p| p == n) {
            problems.push(field_at(
                n,
                line,
                format!("missing (a {dist} prior needs {})", distribution.needs()),
            ));
        }
        v
    };
    let prior = match distribution {
        Distribution::Uniform => Prior::Uniform {
            lo: need("lo")?,
            hi: need("hi")?,
        },
        Distribution::LogUniform => Prior::LogUniform {
            lo: need("lo")?,
            hi: need("hi")?,
        },
        Distribution::Normal => Prior::Normal {
            mean: need("mean")?,
            sd: need("sd")?,
        },
        Distribution::LogNormal => {
            let sigma = need("sigma")?;
            let mu = log_normal_mu(&read, line, &field_at, problems)?;
            Prior::LogNormal { mu, sigma }
        }
    };
    (problems.len() == before).then_some(prior)
}

/// What a value is, as the messages of a prior file name it.
fn type_name(v: &Val) -> &'static str {
    match v {
        Val::Table(_) => "table",
        Val::Array(_) => "list",
        Val::Number { .. } => "number",
        Val::Text(_) => "text",
        Val::Bool(_) => "true/false",
        Val::Other("a date") => "date",
        Val::Other(t) => t,
    }
}
