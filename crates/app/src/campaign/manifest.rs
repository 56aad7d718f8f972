//! The campaign manifest: a small JSON or TOML file (by its extension) listing set folders,
//! each with optional options of its own, and options for every set:
//!
//! ```toml
//! [options]                     # every set (the command line's flags stand in for the rest)
//! diagnose = true
//!
//! [[sets]]
//! path = "lab/pair-41"          # relative to the manifest
//!
//! [[sets]]
//! path = "lab/pair-42"
//! id = "pair-42-alpha"          # its results folder, sets/<id> (default: the folder's name)
//! free = ["mu_s", "mu_k", "kappa", "xi", "u_tilde", "alpha_t"]
//! fix = { mu_k = 0.3 }
//! bounds = { kappa = [0.1, 100.0] }
//! tests = ["mono-200kPa", "mono-400kPa"]
//! seed = 3
//! starts = 12
//! global_evals = 5000
//! profiles = false
//! ```
//!
//! The JSON form is the same object: `{"options": {...}, "sets": [{"path": "lab/pair-41"}]}`.
//! Every problem of the file is reported at once, each with the file, the line and the field
//! and what was expected (docs/campaign.md lists the fields).

use subfric_data::located::{self, Expected, Node, Val};

/// What a manifest holds, in the words of its messages.
const EXPECTED: Expected = Expected {
    file: "manifest",
    json: "an object with `sets` and optionally `options`",
    toml: "`[[sets]]` tables with a `path`, and optionally `[options]`",
    content: "a manifest of sets and options",
};
use super::SetOptions;
use crate::flags::{parse_bound, parse_fix, parse_param};
use crate::folders::output::safe_name;
use anyhow::{anyhow, Result};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use subfric_data::{InputProblem, PathKind, EXPERIMENT_JSON};

/// Option values given in a manifest (`None`: not given there).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PartialOptions {
    /// Only these tests.
    pub tests: Option<Vec<String>>,
    /// Free parameters.
    pub free: Option<Vec<String>>,
    /// Fixed values.
    pub fix: Option<BTreeMap<String, f64>>,
    /// Bounds.
    pub bounds: Option<BTreeMap<String, [f64; 2]>>,
    /// Seed of the fit and of the diagnosis.
    pub seed: Option<u64>,
    /// Local starts.
    pub starts: Option<usize>,
    /// Model runs of the global stage.
    pub global_evals: Option<usize>,
    /// Profile intervals.
    pub profiles: Option<bool>,
    /// Diagnose too.
    pub diagnose: Option<bool>,
}

impl PartialOptions {
    /// `base` with the values given here.
    pub fn over(&self, base: &SetOptions) -> SetOptions {
        SetOptions {
            tests: self.tests.clone().unwrap_or_else(|| base.tests.clone()),
            free: self.free.clone().or_else(|| base.free.clone()),
            fix: self.fix.clone().unwrap_or_else(|| base.fix.clone()),
            bounds: self.bounds.clone().unwrap_or_else(|| base.bounds.clone()),
            seed: self.seed.unwrap_or(base.seed),
            starts: self.starts.unwrap_or(base.starts),
            global_evals: self.global_evals.unwrap_or(base.global_evals),
            profiles: self.profiles.unwrap_or(base.profiles),
            diagnose: self.diagnose.unwrap_or(base.diagnose),
        }
    }
}

/// One set of a manifest.
#[derive(Clone, Debug, PartialEq)]
pub struct ManifestSet {
    /// The folder as written.
    pub written: String,
    /// The folder, relative to the manifest's folder when written relative.
    pub path: PathBuf,
    /// Its results folder's name, when given.
    pub id: Option<String>,
    /// Its own options.
    pub options: PartialOptions,
    /// The line of its entry.
    pub line: usize,
    /// Its index in the manifest's list.
    pub index: usize,
}

/// A manifest read and checked.
#[derive(Clone, Debug, PartialEq)]
pub struct Manifest {
    /// Options of every set.
    pub options: PartialOptions,
    /// The sets, in file order.
    pub sets: Vec<ManifestSet>,
}

const OPTION_KEYS: [&str; 9] = [
    "tests",
    "free",
    "fix",
    "bounds",
    "seed",
    "starts",
    "global_evals",
    "profiles",
    "diagnose",
];

/// Reads and checks the manifest at `path`, its options laid over `defaults` to check each
/// set's (a `fix` in one place and a `free` of the same parameter in another are found too).
pub fn load(path: &Path, defaults: &SetOptions) -> Result<Manifest> {
    let text = crate::folders::io::read_settings_text(path, "the manifest")?;
    parse(&text, path, defaults)
}

/// Parses and checks the text of a manifest; `path` names it in messages, its extension
/// (`.json` or `.toml`) selects the format and its folder is where relative set paths start.
pub fn parse(text: &str, path: &Path, defaults: &SetOptions) -> Result<Manifest> {
    let root = located::parse(text, path, &EXPECTED).map_err(|p| problems_error(path, vec![p]))?;
    let mut cx = Cx {
        path,
        problems: Vec::new(),
    };
    let manifest = cx.manifest(&root, defaults);
    if cx.problems.is_empty() {
        Ok(manifest)
    } else {
        cx.problems.sort_by_key(|p| p.line);
        Err(problems_error(path, cx.problems))
    }
}

fn problems_error(path: &Path, problems: Vec<InputProblem>) -> anyhow::Error {
    if let [one] = &problems[..] {
        return anyhow!("{one}");
    }
    let mut s = format!(
        "{} problems in the manifest {}:",
        problems.len(),
        path.display()
    );
    for p in problems {
        s.push_str("\n  ");
        s.push_str(&p.to_string());
    }
    anyhow!(s)
}

struct Cx<'a> {
    path: &'a Path,
    problems: Vec<InputProblem>,
}

impl Cx<'_> {
    fn problem(&mut self, line: usize, field: &str, message: impl Into<String>) {
        self.problems.push(InputProblem::new(
            self.path,
            Some(line),
            (!field.is_empty()).then_some(field),
            message,
        ));
    }

    fn manifest(&mut self, root: &Node, defaults: &SetOptions) -> Manifest {
        let mut manifest = Manifest {
            options: PartialOptions::default(),
            sets: Vec::new(),
        };
        let Val::Table(items) = &root.value else {
            self.problem(
                root.line,
                "",
                format!(
                    "found {} (expected a table with `sets` and optionally `options`)",
                    root.value.kind()
                ),
            );
            return manifest;
        };
        let mut sets = None;
        for (key, node) in self.unique(items, "") {
            match key.as_str() {
                "options" => manifest.options = self.options(node, "options"),
                "sets" => sets = Some(node),
                _ => self.problem(
                    node.line,
                    key,
                    "unknown field (expected `sets`, the list of set folders, and optionally `options`)",
                ),
            }
        }
        let base = manifest.options.over(defaults);
        self.check_options(&base, "options", root.line);
        match sets.map(|n| (n.line, &n.value)) {
            None => self.problem(
                root.line,
                "sets",
                "missing required field `sets` (expected a list of set folders)",
            ),
            Some((line, Val::Array(items))) if items.is_empty() => {
                self.problem(line, "sets", "no sets (expected at least one set folder)")
            }
            Some((_, Val::Array(items))) => {
                for (i, item) in items.iter().enumerate() {
                    if let Some(s) = self.set(item, i, &base) {
                        manifest.sets.push(s);
                    }
                }
                self.check_ids(&manifest.sets);
            }
            Some((line, v)) => self.problem(
                line,
                "sets",
                format!("found {} (expected a list of set folders)", v.kind()),
            ),
        }
        manifest
    }

    /// The entries of a table, each key once (a second one is a problem).
    fn unique<'n>(&mut self, items: &'n [(String, Node)], prefix: &str) -> Vec<&'n (String, Node)> {
        let mut seen: Vec<&(String, Node)> = Vec::new();
        for item in items {
            if let Some(first) = seen.iter().find(|s| s.0 == item.0) {
                let line = first.1.line;
                self.problem(
                    item.1.line,
                    &join(prefix, &item.0),
                    format!("given twice (first on line {line}; expected each field once)"),
                );
            } else {
                seen.push(item);
            }
        }
        seen
    }

    fn set(&mut self, node: &Node, i: usize, base: &SetOptions) -> Option<ManifestSet> {
        let prefix = format!("sets[{i}]");
        let Val::Table(items) = &node.value else {
            self.problem(
                node.line,
                &prefix,
                format!(
                    "found {} (expected a table with the set's `path`)",
                    node.value.kind()
                ),
            );
            return None;
        };
        let items = self.unique(items, &prefix);
        let mut path = None;
        let mut path_line = node.line;
        let mut path_given = false;
        let mut id = None;
        let mut rest = Vec::new();
        for item in items {
            match item.0.as_str() {
                "path" => {
                    path_given = true;
                    path_line = item.1.line;
                    path = self.text(&item.1, &join(&prefix, "path"));
                }
                "id" => id = self.id(&item.1, &join(&prefix, "id")),
                _ => rest.push(item),
            }
        }
        let options = self.option_items(&rest, &prefix);
        self.check_options(&options.over(base), &prefix, node.line);
        let Some(written) = path else {
            if !path_given {
                self.problem(
                    node.line,
                    &join(&prefix, "path"),
                    "missing required field `path` (expected the set's folder, relative to the manifest)",
                );
            }
            return None;
        };
        let resolved = self
            .path
            .parent()
            .map_or_else(|| PathBuf::from(&written), |d| d.join(&written));
        let json = resolved.join(EXPERIMENT_JSON);
        match (PathKind::of(&resolved), PathKind::of(&json)) {
            (PathKind::Folder, PathKind::File) => {}
            (PathKind::Folder, _) => self.problem(
                path_line,
                &join(&prefix, "path"),
                format!(
                    "{}: holds no {EXPERIMENT_JSON} (expected a set folder)",
                    resolved.display()
                ),
            ),
            (kind, _) => self.problem(
                path_line,
                &join(&prefix, "path"),
                format!(
                    "{}: {} (expected a set folder, relative to the manifest)",
                    resolved.display(),
                    kind.describe()
                ),
            ),
        }
        Some(ManifestSet {
            written,
            path: resolved,
            id,
            options,
            line: node.line,
            index: i,
        })
    }

    /// Two sets with one results folder.
    fn check_ids(&mut self, sets: &[ManifestSet]) {
        for (k, s) in sets.iter().enumerate() {
            let id = set_id(s);
            if let Some(first) = sets[..k].iter().find(|o| set_id(o) == id) {
                let line = first.line;
                self.problem(
                    s.line,
                    &format!("sets[{}]", s.index),
                    format!(
                        "results folder sets/{id} is already that of the set on line {line} (expected an `id` that tells them apart)"
                    ),
                );
            }
        }
    }

    fn id(&mut self, node: &Node, field: &str) -> Option<String> {
        let id = self.text(node, field)?;
        if safe_name(&id) != id {
            self.problem(
                node.line,
                field,
                format!(
                    "`{id}` cannot be a folder name (expected letters, digits, `.`, `_`, `+` and `-`, not starting with `.` or `-`)"
                ),
            );
            return None;
        }
        Some(id)
    }

    fn text(&mut self, node: &Node, field: &str) -> Option<String> {
        match &node.value {
            Val::Text(s) if !s.trim().is_empty() => Some(s.clone()),
            Val::Text(_) => {
                self.problem(node.line, field, "empty (expected a text)");
                None
            }
            v => {
                self.problem(
                    node.line,
                    field,
                    format!("found {} (expected a text)", v.kind()),
                );
                None
            }
        }
    }

    fn options(&mut self, node: &Node, prefix: &str) -> PartialOptions {
        match &node.value {
            Val::Table(items) => {
                let items = self.unique(items, prefix);
                self.option_items(&items, prefix)
            }
            v => {
                self.problem(
                    node.line,
                    prefix,
                    format!("found {} (expected a table of options)", v.kind()),
                );
                PartialOptions::default()
            }
        }
    }

    fn option_items(&mut self, items: &[&(String, Node)], prefix: &str) -> PartialOptions {
        let mut o = PartialOptions::default();
        for (key, node) in items.iter().map(|i| (&i.0, &i.1)) {
            let field = join(prefix, key);
            match key.as_str() {
                "tests" => o.tests = self.texts(node, &field),
                "free" => {
                    o.free = self.texts(node, &field).and_then(|keys| {
                        let bad: Vec<String> =
                            keys.iter().filter_map(|k| parse_param(k).err()).collect();
                        if let Some(e) = bad.first() {
                            self.problem(node.line, &field, e.clone());
                            return None;
                        }
                        Some(keys)
                    })
                }
                "fix" => o.fix = self.fix(node, &field),
                "bounds" => o.bounds = self.bounds(node, &field),
                "seed" => o.seed = self.integer(node, &field, 0),
                "starts" => o.starts = self.integer(node, &field, 1).map(|v| v as usize),
                "global_evals" => {
                    o.global_evals = self.integer(node, &field, 0).map(|v| v as usize)
                }
                "profiles" => o.profiles = self.boolean(node, &field),
                "diagnose" => o.diagnose = self.boolean(node, &field),
                _ => self.problem(
                    node.line,
                    &field,
                    format!(
                        "unknown field (expected one of path, id, {})",
                        OPTION_KEYS.join(", ")
                    ),
                ),
            }
        }
        o
    }

    /// The options a set ends up with contradict each other (as `fit` refuses them).
    fn check_options(&mut self, o: &SetOptions, field: &str, line: usize) {
        if let Err(e) = o.check() {
            self.problem(line, field, e);
        }
    }

    fn texts(&mut self, node: &Node, field: &str) -> Option<Vec<String>> {
        let Val::Array(items) = &node.value else {
            self.problem(
                node.line,
                field,
                format!("found {} (expected a list of names)", node.value.kind()),
            );
            return None;
        };
        let mut out = Vec::new();
        for (i, item) in items.iter().enumerate() {
            out.push(self.text(item, &format!("{field}[{i}]"))?);
        }
        Some(out)
    }

    fn number(&mut self, node: &Node, field: &str) -> Option<f64> {
        match &node.value {
            Val::Number { value, .. } if value.is_finite() => Some(*value),
            v => {
                self.problem(
                    node.line,
                    field,
                    format!("found {} (expected a finite number)", v.kind()),
                );
                None
            }
        }
    }

    fn integer(&mut self, node: &Node, field: &str, min: u64) -> Option<u64> {
        match &node.value {
            Val::Number {
                integer: Some(i), ..
            } if *i >= i128::from(min) && *i <= i128::from(u64::MAX) => Some(*i as u64),
            v => {
                self.problem(
                    node.line,
                    field,
                    format!("found {} (expected a whole number ≥ {min})", v.describe()),
                );
                None
            }
        }
    }

    fn boolean(&mut self, node: &Node, field: &str) -> Option<bool> {
        match &node.value {
            Val::Bool(b) => Some(*b),
            v => {
                self.problem(
                    node.line,
                    field,
                    format!("found {} (expected true or false)", v.kind()),
                );
                None
            }
        }
    }

    fn fix(&mut self, node: &Node, field: &str) -> Option<BTreeMap<String, f64>> {
        let items = self.table(node, field, "parameter = value")?;
        let mut out = BTreeMap::new();
        let mut ok = true;
        for (key, n) in items {
            let f = join(field, key);
            let Some(v) = self.number(n, &f) else {
                ok = false;
                continue;
            };
            match parse_fix(&format!("{key}={v}")) {
                Ok(_) => {
                    out.insert(key.clone(), v);
                }
                Err(e) => {
                    self.problem(n.line, &f, e);
                    ok = false;
                }
            }
        }
        ok.then_some(out)
    }

    fn bounds(&mut self, node: &Node, field: &str) -> Option<BTreeMap<String, [f64; 2]>> {
        let items = self.table(node, field, "parameter = [lo, hi]")?;
        let mut out = BTreeMap::new();
        let mut ok = true;
        for (key, n) in items {
            let f = join(field, key);
            let pair = match &n.value {
                Val::Array(v) if v.len() == 2 => self
                    .number(&v[0], &format!("{f}[0]"))
                    .zip(self.number(&v[1], &format!("{f}[1]"))),
                v => {
                    self.problem(
                        n.line,
                        &f,
                        format!("found {} (expected [lo, hi])", v.describe()),
                    );
                    None
                }
            };
            let Some((lo, hi)) = pair else {
                ok = false;
                continue;
            };
            match parse_bound(&format!("{key}={lo}:{hi}")) {
                Ok(_) => {
                    out.insert(key.clone(), [lo, hi]);
                }
                Err(e) => {
                    self.problem(n.line, &f, e);
                    ok = false;
                }
            }
        }
        ok.then_some(out)
    }

    fn table<'n>(
        &mut self,
        node: &'n Node,
        field: &str,
        form: &str,
    ) -> Option<Vec<&'n (String, Node)>> {
        match &node.value {
            Val::Table(items) => Some(self.unique(items, field)),
            v => {
                self.problem(
                    node.line,
                    field,
                    format!("found {} (expected a table of {form})", v.kind()),
                );
                None
            }
        }
    }
}

/// A set's results folder name: its `id`, else its folder's name.
pub fn set_id(s: &ManifestSet) -> String {
    s.id.clone().unwrap_or_else(|| folder_id(&s.path))
}

/// The results folder name of a set folder: its last component made a plain name.
pub fn folder_id(dir: &Path) -> String {
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .or_else(|| {
            std::fs::canonicalize(dir)
                .ok()
                .and_then(|c| c.file_name().map(|n| n.to_string_lossy().to_string()))
        })
        .unwrap_or_default();
    safe_name(&name)
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

#[cfg(test)]
#[path = "manifest_tests.rs"]
mod tests;
