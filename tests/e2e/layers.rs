//! The layers below the front ends (issue 22): the Python package is built on the application
//! layer (`subfric-app`) without the command line's clap and indicatif, and the application
//! layer gives the program's results.

use std::collections::{BTreeSet, HashMap};
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
