//! The layers below the front ends (issue 22): the Python package is built on the application
//! layer (`subfric-app`) without the command line's clap and indicatif, and the application
//! layer gives the program's results.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::process::Command;

use serde_json::Value;
use subfric_app::fit::FitRequest;
use subfric_app::Silent;
use subfric_e2e::{args, experiments, repo, subfric};
use subfric_fit::FitOptions;

/// `cargo metadata` of the workspace (the packages and the resolved dependency graph).
fn metadata() -> Value {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let o = Command::new(&cargo)
        .args(["metadata", "--format-version", "1", "--locked"])
        .current_dir(repo())
        .output()
        .unwrap_or_else(|e| panic!("{cargo} metadata: {e}"));
    assert!(
        o.status.success(),
        "cargo metadata failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).expect("cargo metadata prints JSON")
}

/// The names of the packages `package` depends on, directly or not, as `cargo tree -p` lists
/// them: normal and build dependencies all the way down, dev-dependencies of `package` itself.
fn dependency_tree(meta: &Value, package: &str) -> BTreeSet<String> {
    let name_of: HashMap<&str, &str> = meta["packages"]
        .as_array()
        .expect("packages")
        .iter()
        .map(|p| (p["id"].as_str().unwrap(), p["name"].as_str().unwrap()))
        .collect();
    let nodes: HashMap<&str, &Value> = meta["resolve"]["nodes"]
        .as_array()
        .expect("resolve.nodes")
        .iter()
        .map(|n| (n["id"].as_str().unwrap(), n))
        .collect();
    let root = nodes
        .keys()
        .find(|id| name_of[*id] == package)
        .unwrap_or_else(|| panic!("no package {package} in the workspace"));
    let mut seen = BTreeSet::new();
    let mut todo = vec![(*root, true)];
    while let Some((id, is_root)) = todo.pop() {
        for dep in nodes[id]["deps"].as_array().expect("deps") {
            let kinds: Vec<Option<&str>> = dep["dep_kinds"]
                .as_array()
                .expect("dep_kinds")
                .iter()
                .map(|k| k["kind"].as_str())
                .collect();
            let counts = kinds
                .iter()
                .any(|k| matches!(k, None | Some("build")) || (is_root && *k == Some("dev")));
            let to = dep["pkg"].as_str().unwrap();
            if counts && seen.insert(name_of[to].to_string()) {
                todo.push((to, false));
            }
        }
    }
    seen
}

#[test]
fn the_python_package_depends_on_the_application_layer_not_on_the_command_line() {
    let meta = metadata();
    let python = dependency_tree(&meta, "subfric-py");
    assert!(
        python.contains("subfric-app"),
        "subfric-py does not reach subfric-app: {python:?}"
    );
    for cli_only in ["subfric", "clap", "clap_builder", "indicatif"] {
        assert!(
            !python.contains(cli_only),
            "subfric-py depends on {cli_only} (the command line's): {python:?}"
        );
    }
    // The walk finds them where they are: the command line has both.
    let cli = dependency_tree(&meta, "subfric");
    for dep in ["subfric-app", "clap", "indicatif"] {
        assert!(
            cli.contains(dep),
            "the walk misses {dep} of subfric: {cli:?}"
        );
    }
    // And the application layer itself stays free of them.
    let app = dependency_tree(&meta, "subfric-app");
    assert!(
        !app.contains("clap") && !app.contains("indicatif"),
        "{app:?}"
    );
}

#[test]
fn the_application_layer_gives_the_fit_json_the_program_writes() {
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table3-pulsating");
    let out = tmp.path().join("fit");
    subfric!().ok(args!["fit", &set, "--out", &out, "--progress", "never"]);
    let written = std::fs::read_to_string(out.join("fit.json")).unwrap();
    let fitted = subfric_app::fit(&FitRequest::of_set(set, FitOptions::default()), &Silent)
        .expect("the set fits");
    // Compared as text, as the program writes it (serde_json's default float parser may miss
    // the last bit; its printer does not).
    let text = serde_json::to_string_pretty(&fitted.json).unwrap() + "\n";
    assert!(
        text == written,
        "the application layer's fit.json differs from the program's"
    );
}

/// Longest function, in lines from its `fn` to its closing brace, the crates' sources may hold
/// outside their tests (issue 40: a newcomer reads a function whole).
const MAX_FUNCTION_LINES: usize = 100;

/// The code of a line with its string and character literals and its comment taken out, so
/// that a brace inside them does not count.
fn code_of(line: &str) -> String {
    let mut out = String::new();
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' => {
                // A string literal: skip to its unescaped closing quote.
                while let Some(d) = chars.next() {
                    match d {
                        '\\' => {
                            chars.next();
                        }
                        '"' => break,
                        _ => {}
                    }
                }
            }
            '\'' => {
                // A character literal ('{', '\''), not a lifetime ('a): skip it whole.
                let rest: String = chars.clone().take(3).collect();
                if rest.starts_with('\\') {
                    chars.next();
                    chars.next();
                    for d in chars.by_ref() {
                        if d == '\'' {
                            break;
                        }
                    }
                } else if rest.chars().nth(1) == Some('\'') {
                    chars.next();
                    chars.next();
                }
            }
            '/' if chars.peek() == Some(&'/') => break,
            _ => out.push(c),
        }
    }
    out
}

/// (file, first line, name, lines) of every function of `text` over `max` lines, its test
/// module (from `#[cfg(test)]` at the start of a line) left out.
fn long_functions(file: &str, text: &str, max: usize) -> Vec<(String, usize, String, usize)> {
    let lines: Vec<&str> = text
        .lines()
        .take_while(|l| l.trim() != "#[cfg(test)]")
        .collect();
    let mut found = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let code = code_of(lines[i]);
        let name = code
            .split_whitespace()
            .skip_while(|w| *w != "fn")
            .nth(1)
            .map(|w| w.split(['(', '<']).next().unwrap_or("").to_string());
        let Some(name) = name.filter(|n| !n.is_empty()) else {
            i += 1;
            continue;
        };
        let (mut depth, mut opened, mut j) = (0i64, false, i);
        while j < lines.len() {
            let c = code_of(lines[j]);
            depth += c.matches('{').count() as i64 - c.matches('}').count() as i64;
            opened |= c.contains('{');
            if (opened && depth <= 0) || (!opened && c.trim_end().ends_with(';')) {
                break;
            }
            j += 1;
        }
        if opened && j + 1 - i > max {
            found.push((file.to_string(), i + 1, name, j + 1 - i));
        }
        i = if opened { j + 1 } else { i + 1 };
    }
    found
}

#[test]
fn the_length_count_finds_a_long_function_and_ignores_braces_in_literals_and_tests() {
    let body = "    let _ = \"{{{ not code\"; let _ = '{';\n".repeat(120);
    let text = format!(
        "fn short() {{\n    1;\n}}\n\npub(crate) fn long<T>(x: T) {{\n{body}}}\n#[cfg(test)]\nmod tests {{\n    fn in_tests() {{\n{body}    }}\n}}\n"
    );
    let found = long_functions("f.rs", &text, 100);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!((found[0].2.as_str(), found[0].3), ("long", 122));
}

/// The `.rs` files under `roots`, sorted, not descending into folders named in `skip`.
fn rust_files(roots: &[std::path::PathBuf], skip: &[&str]) -> Vec<std::path::PathBuf> {
    let mut files = Vec::new();
    let mut stack = roots.to_vec();
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            if path.is_dir() {
                if !skip.contains(&name.as_str()) {
                    stack.push(path);
                }
            } else if name.ends_with(".rs") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

#[test]
fn no_function_outside_tests_runs_over_a_hundred_lines() {
    let mut long = Vec::new();
    // Integration tests and benches are tests; `target` is no source.
    for path in rust_files(&[repo().join("crates")], &["tests", "benches", "target"]) {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if !name.ends_with("_tests.rs") && name != "tests.rs" {
            let text = std::fs::read_to_string(&path).unwrap();
            let shown = path.strip_prefix(repo()).unwrap().display().to_string();
            long.extend(long_functions(&shown, &text, MAX_FUNCTION_LINES));
        }
    }
    assert!(
        long.is_empty(),
        "functions over {MAX_FUNCTION_LINES} lines (split them by what each part does):\n{}",
        long.iter()
            .map(|(f, l, n, len)| format!("  {f}:{l} {n}: {len} lines"))
            .collect::<Vec<_>>()
            .join("\n")
    );
}

/// The short name `docs/architecture.md` gives a workspace package (`subfric` is the command
/// line, `subfric-py` the Python package, `subfric-<name>` the library `<name>`); `None` for
/// the test crate.
fn short_name(package: &str) -> Option<String> {
    match package {
        "subfric" => Some("cli".into()),
        "subfric-py" => Some("python".into()),
        "subfric-e2e" => None,
        p => p.strip_prefix("subfric-").map(str::to_string),
    }
}

/// Each crate's normal dependencies among the workspace's crates, by short name.
fn workspace_edges(meta: &Value) -> BTreeMap<String, BTreeSet<String>> {
    let members: BTreeSet<&str> = meta["workspace_members"]
        .as_array()
        .expect("workspace_members")
        .iter()
        .map(|m| m.as_str().unwrap())
        .collect();
    let packages: Vec<&Value> = meta["packages"]
        .as_array()
        .expect("packages")
        .iter()
        .filter(|p| members.contains(p["id"].as_str().unwrap()))
        .collect();
    let ours: BTreeSet<&str> = packages
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    let mut edges = BTreeMap::new();
    for p in packages {
        let Some(from) = short_name(p["name"].as_str().unwrap()) else {
            continue;
        };
        let to: BTreeSet<String> = p["dependencies"]
            .as_array()
            .expect("dependencies")
            .iter()
            .filter(|d| d["kind"].is_null() && ours.contains(d["name"].as_str().unwrap()))
            .filter_map(|d| short_name(d["name"].as_str().unwrap()))
            .collect();
        edges.insert(from, to);
    }
    edges
}

/// The "Exact edges" list of `docs/architecture.md`: lines `- a → b, c (remark)` or
/// `- a → nothing of ours`.
fn documented_edges(doc: &str) -> BTreeMap<String, BTreeSet<String>> {
    let list = doc
        .split_once("Exact edges")
        .expect("docs/architecture.md has its \"Exact edges\" list")
        .1;
    let mut edges = BTreeMap::new();
    for line in list.lines().skip(1).skip_while(|l| !l.starts_with("- ")) {
        let Some(item) = line.strip_prefix("- ") else {
            break;
        };
        let (from, to) = item
            .split_once('→')
            .unwrap_or_else(|| panic!("an edge reads `a → b, c`: {line:?}"));
        let to = to.split('(').next().unwrap().trim();
        let targets: BTreeSet<String> = if to == "nothing of ours" {
            BTreeSet::new()
        } else {
            to.split(',').map(|t| t.trim().to_string()).collect()
        };
        edges.insert(from.trim().to_string(), targets);
    }
    edges
}

#[test]
fn the_documented_edges_are_read_as_written() {
    let doc = "text\n\nExact edges (checked):\n\n- model → nothing of ours\n- fit → model, data\n- cli → app, fit (for types)\n\nnext paragraph\n- not → an edge\n";
    let edges = documented_edges(doc);
    assert_eq!(edges.len(), 3, "{edges:?}");
    assert!(edges["model"].is_empty());
    assert_eq!(
        edges["fit"],
        BTreeSet::from(["model".into(), "data".into()])
    );
    assert_eq!(edges["cli"], BTreeSet::from(["app".into(), "fit".into()]));
}

#[test]
fn the_architecture_doc_lists_the_crate_graph_cargo_resolves() {
    let doc = std::fs::read_to_string(repo().join("docs/architecture.md")).unwrap();
    let documented = documented_edges(&doc);
    let actual = workspace_edges(&metadata());
    let show = |m: &BTreeMap<String, BTreeSet<String>>| {
        m.iter()
            .map(|(k, v)| {
                let v: Vec<&str> = v.iter().map(String::as_str).collect();
                format!("  {k} → {}", v.join(", "))
            })
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(
        documented,
        actual,
        "docs/architecture.md's \"Exact edges\" differ from Cargo.toml's dependencies; the \
         manifests say:\n{}",
        show(&actual)
    );
}

/// No source file of ours runs over this many lines (a file that long holds more than one
/// thing: split it by what each part does).
const MAX_FILE_LINES: usize = 800;

#[test]
fn no_source_file_runs_over_eight_hundred_lines() {
    let mut long = Vec::new();
    let roots = ["crates", "python/src", "tests"].map(|r| repo().join(r));
    for path in rust_files(&roots, &["target"]) {
        let lines = std::fs::read_to_string(&path).unwrap().lines().count();
        if lines > MAX_FILE_LINES {
            let shown = path.strip_prefix(repo()).unwrap().display().to_string();
            long.push(format!("  {shown}: {lines} lines"));
        }
    }
    long.sort();
    assert!(
        long.is_empty(),
        "source files over {MAX_FILE_LINES} lines:\n{}",
        long.join("\n")
    );
}

/// The application layer's modules and where each names another: module → module it names →
/// the `file:line` of each place. The modules are the top-level ones of `crates/app/src`
/// (`fit.rs` and the files under `fit/` are `fit`).
type ModuleGraph = BTreeMap<String, BTreeMap<String, Vec<String>>>;

/// A file's text up to its test module (from the first `#[cfg(test)]` line on, left out).
fn outside_tests(text: &str) -> String {
    text.lines()
        .take_while(|l| l.trim() != "#[cfg(test)]")
        .collect::<Vec<_>>()
        .join("\n")
}

/// The offsets where the items of the braced list opening at `open` start (its top level:
/// `a` and `b` of `{a::x, b::{y, z}}`).
fn list_items(text: &str, open: usize) -> Vec<usize> {
    let (mut items, mut depth, mut expect) = (Vec::new(), 0, false);
    for (i, c) in text[open..].char_indices() {
        match c {
            '{' => {
                depth += 1;
                expect = depth == 1;
            }
            '}' => {
                depth -= 1;
                if depth == 0 {
                    break;
                }
            }
            ',' if depth == 1 => expect = true,
            c if expect && !c.is_whitespace() => {
                items.push(open + i);
                expect = false;
            }
            _ => {}
        }
    }
    items
}

/// Where `text` (of the module `own`) names another of `modules` as `crate::<module>`, also
/// in a `use crate::{a::x, b::y}` list over several lines: (module, line from 1) each.
fn crate_references(text: &str, own: &str, modules: &BTreeSet<String>) -> Vec<(String, usize)> {
    let name_at = |at: usize| {
        let rest = &text[at..];
        let end = rest
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        &rest[..end]
    };
    let mut found = Vec::new();
    for (at, prefix) in text.match_indices("crate::") {
        // `subcrate::x` names no module of ours.
        if text[..at]
            .chars()
            .next_back()
            .is_some_and(|c| c.is_alphanumeric() || c == '_')
        {
            continue;
        }
        let after = at + prefix.len();
        let heads = if text[after..].starts_with('{') {
            list_items(text, after)
        } else {
            vec![after]
        };
        for h in heads {
            let name = name_at(h);
            if name != own && modules.contains(name) {
                found.push((name.to_string(), text[..h].matches('\n').count() + 1));
            }
        }
    }
    found
}

/// The module graph of the application layer's sources under `root`, their tests left out.
fn app_module_graph(root: &std::path::Path) -> ModuleGraph {
    let files: Vec<(String, std::path::PathBuf)> = rust_files(&[root.to_path_buf()], &[])
        .into_iter()
        .map(|path| {
            let first = path
                .strip_prefix(root)
                .unwrap()
                .components()
                .next()
                .unwrap();
            let module = first
                .as_os_str()
                .to_string_lossy()
                .trim_end_matches(".rs")
                .to_string();
            (module, path)
        })
        .collect();
    let modules: BTreeSet<String> = files.iter().map(|(m, _)| m.clone()).collect();
    let mut graph: ModuleGraph = modules
        .iter()
        .map(|m| (m.clone(), BTreeMap::new()))
        .collect();
    for (module, path) in &files {
        let text = outside_tests(&std::fs::read_to_string(path).unwrap());
        let shown = path
            .strip_prefix(repo())
            .unwrap_or(path)
            .display()
            .to_string();
        for (to, line) in crate_references(&text, module, &modules) {
            let places = graph.get_mut(module).unwrap().entry(to).or_default();
            places.push(format!("{shown}:{line}"));
        }
    }
    graph
}

/// A cycle of `graph`, if it has one: modules each of which names the next, the last the first.
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    /// Depth first from `m`: a module met again while still on `path` closes a cycle.
    fn visit<'a>(
        m: &'a str,
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<&'a str>,
        seen: &mut BTreeSet<&'a str>,
    ) -> Option<Vec<String>> {
        if let Some(i) = path.iter().position(|p| *p == m) {
            return Some(path[i..].iter().map(|p| p.to_string()).collect());
        }
        if !seen.insert(m) {
            return None;
        }
        path.push(m);
        for next in graph.get(m).into_iter().flatten() {
            if let Some(cycle) = visit(next, graph, path, seen) {
                return Some(cycle);
            }
        }
        path.pop();
        None
    }
    let mut seen = BTreeSet::new();
    graph
        .keys()
        .find_map(|m| visit(m, graph, &mut Vec::new(), &mut seen))
}

#[test]
fn the_cycle_finder_finds_a_circle_and_only_a_circle() {
    let graph = |edges: &[(&str, &str)]| {
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (a, b) in edges {
            g.entry(a.to_string()).or_default().insert(b.to_string());
            g.entry(b.to_string()).or_default();
        }
        g
    };
    let circle = graph(&[("a", "b"), ("b", "c"), ("c", "a"), ("d", "a"), ("a", "e")]);
    assert_eq!(
        find_cycle(&circle),
        Some(vec!["a".into(), "b".into(), "c".into()])
    );
    let two = graph(&[("plan", "report"), ("report", "plan")]);
    assert_eq!(find_cycle(&two), Some(vec!["plan".into(), "report".into()]));
    // A diamond is no circle.
    let layers = graph(&[("a", "b"), ("a", "c"), ("b", "d"), ("c", "d"), ("e", "a")]);
    assert_eq!(find_cycle(&layers), None);
}

#[test]
fn the_references_are_read_in_use_lists_and_not_in_tests() {
    let modules: BTreeSet<String> = ["fit", "io", "report", "plan", "outcome"]
        .map(String::from)
        .into();
    let text = "use crate::{\n    fit::{a, b},\n    io::x,\n};\nuse crate::outcome::FitOutcome;\nlet _ = crate::report::X + crate::visible(subcrate::plan::y) + crate::plan_basis::z;\n#[cfg(test)]\nmod tests {\n    use crate::plan::y;\n}\n";
    let found = crate_references(&outside_tests(text), "io", &modules);
    let expected = [("fit", 2), ("outcome", 5), ("report", 6)];
    assert_eq!(
        found,
        expected.map(|(m, l)| (m.to_string(), l)).to_vec(),
        "{found:?}"
    );
}

#[test]
fn the_application_layer_has_no_import_circle() {
    let graph = app_module_graph(&repo().join("crates/app/src"));
    // The walk finds the references where they are: the fit's folder form renders a report.
    assert!(
        graph.get("fit").is_some_and(|to| to.contains_key("render")),
        "the walk misses fit → render: {graph:?}"
    );
    let edges: BTreeMap<String, BTreeSet<String>> = graph
        .iter()
        .map(|(m, to)| (m.clone(), to.keys().cloned().collect()))
        .collect();
    if let Some(cycle) = find_cycle(&edges) {
        let places: Vec<String> = cycle
            .iter()
            .zip(cycle.iter().cycle().skip(1))
            .map(|(a, b)| format!("  {a} → {b}: {}", graph[a][b][0]))
            .collect();
        panic!(
            "the application layer's modules name each other in a circle ({} → {}); outcomes go at the bottom, the reports above them, the folder forms on top (docs/architecture.md):\n{}",
            cycle.join(" → "),
            cycle[0],
            places.join("\n")
        );
    }
}

/// The module path of an application-layer source file under `root` (`fit/run.rs` →
/// `[fit, run]`, `render/mod.rs` → `[render]`, `lib.rs` → `[]`).
fn module_path(root: &std::path::Path, file: &std::path::Path) -> Vec<String> {
    let rel = file.strip_prefix(root).unwrap();
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| {
            c.as_os_str()
                .to_string_lossy()
                .trim_end_matches(".rs")
                .to_string()
        })
        .collect();
    if parts.last().is_some_and(|p| p == "mod" || p == "lib") {
        parts.pop();
    }
    parts
}

/// The source file of the longest prefix of module path `path` under `root` that is a file
/// of its own (`[render, fit_report, report_table]` → `render/fit_report.rs`).
fn file_of(root: &std::path::Path, path: &[String]) -> Option<std::path::PathBuf> {
    (1..=path.len()).rev().find_map(|k| {
        let dir = path[..k].iter().fold(root.to_path_buf(), |d, p| d.join(p));
        [dir.with_extension("rs"), dir.join("mod.rs")]
            .into_iter()
            .find(|f| f.is_file())
    })
}

/// The module paths `text` (of the module at `own`) names: `crate::a::b`, `super::c`,
/// `self::d` and `e::f` of a child module `e` it declares, also inside `use` lists over
/// several lines (`crate::{a::x, b::{y, z}}`).
fn named_paths(text: &str, own: &[String]) -> Vec<Vec<String>> {
    fn segments(text: &str, at: usize, prefix: Vec<String>, out: &mut Vec<Vec<String>>) {
        let mut path = prefix;
        let mut i = at;
        loop {
            let rest = &text[i..];
            let end = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            if end > 0 {
                path.push(rest[..end].to_string());
            }
            i += end;
            if text[i..].starts_with("::{") {
                for item in list_items(text, i + 2) {
                    segments(text, item, path.clone(), out);
                }
                return;
            }
            if text[i..].starts_with("::") {
                i += 2;
                continue;
            }
            break;
        }
        out.push(path);
    }
    let mut out = Vec::new();
    for (word, base) in [
        ("crate::", Vec::new()),
        ("super::", own[..own.len().saturating_sub(1)].to_vec()),
        ("self::", own.to_vec()),
    ] {
        for (at, _) in text.match_indices(word) {
            if text[..at]
                .chars()
                .next_back()
                .is_some_and(|c| c.is_alphanumeric() || c == '_')
            {
                continue;
            }
            if text[at + word.len()..].starts_with('{') {
                for item in list_items(text, at + word.len()) {
                    segments(text, item, base.clone(), &mut out);
                }
            } else {
                segments(text, at + word.len(), base.clone(), &mut out);
            }
        }
    }
    // A child module the file declares (`mod e;`) is named by its own name (`e::x`, `use
    // e::{..}`): declaring it is not using it.
    let children: Vec<String> = text
        .lines()
        .filter_map(|line| {
            let l = line.trim();
            let l = l.strip_prefix("pub ").unwrap_or(l);
            let l = l.strip_prefix("pub(crate) ").unwrap_or(l);
            l.strip_prefix("mod ")
                .and_then(|r| r.strip_suffix(';'))
                .map(|n| n.trim().to_string())
        })
        .collect();
    for child in &children {
        let word = format!("{child}::");
        for (at, _) in text.match_indices(&word) {
            if text[..at]
                .chars()
                .next_back()
                .is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':')
            {
                continue;
            }
            segments(text, at, own.to_vec(), &mut out);
        }
    }
    out
}

/// The application layer's source files a command's walk reaches from `start` (files under
/// `root`), following what each names outside its tests.
fn walk_files(root: &std::path::Path, start: &[&str]) -> BTreeSet<std::path::PathBuf> {
    let mut seen: BTreeSet<std::path::PathBuf> = BTreeSet::new();
    let mut todo: Vec<std::path::PathBuf> = start.iter().map(|s| root.join(s)).collect();
    while let Some(file) = todo.pop() {
        if !seen.insert(file.clone()) {
            continue;
        }
        // Comments name modules too (intra-doc links) without using them.
        let text: String = outside_tests(&std::fs::read_to_string(&file).unwrap())
            .lines()
            .map(|l| l.split("//").next().unwrap_or_default())
            .collect::<Vec<_>>()
            .join("\n");
        for path in named_paths(&text, &module_path(root, &file)) {
            if let Some(f) = file_of(root, &path) {
                if !seen.contains(&f) {
                    todo.push(f);
                }
            }
        }
    }
    seen
}

/// The files of `walk` that name the diagnosis crate.
fn naming_the_diagnosis(walk: &BTreeSet<std::path::PathBuf>) -> Vec<String> {
    walk.iter()
        .filter(|f| {
            outside_tests(&std::fs::read_to_string(f).unwrap()).contains("subfric_diagnose")
        })
        .map(|f| f.strip_prefix(repo()).unwrap_or(f).display().to_string())
        .collect()
}

#[test]
fn the_walk_of_a_fit_does_not_pass_through_the_diagnosis() {
    let root = repo().join("crates/app/src");
    let walk = walk_files(&root, &["fit.rs"]);
    // The walk follows `use` lists, `super::` and the modules a file declares: it reaches
    // the fit's folder, the adequacy it reports and the page it writes.
    for reached in [
        "fit/run.rs",
        "outcome/adequacy.rs",
        "render/fit_report.rs",
        "render/report.rs",
    ] {
        assert!(
            walk.contains(&root.join(reached)),
            "the walk from fit.rs misses {reached}: {walk:?}"
        );
    }
    let through = naming_the_diagnosis(&walk);
    assert!(
        through.is_empty(),
        "a fit's walk passes through the diagnosis (whether a model describes its data is the fitting crate's, subfric_fit::adequacy; the diagnosis's pages are render/diagnosis_page.rs): {through:?}"
    );
    // The same walk from the diagnosis command does reach it: the check can fail.
    let diagnose = walk_files(&root, &["diagnose.rs"]);
    assert!(
        !naming_the_diagnosis(&diagnose).is_empty(),
        "the walk from diagnose.rs never names the diagnosis: the walk is broken"
    );
}
