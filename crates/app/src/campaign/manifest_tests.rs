//! Tests of the manifest: both formats read alike, options laid over each other, and every
//! problem located at its line and field.

use super::*;

/// A folder with set folders `a`, `b` (each with an experiment.json) and `c` (without).
fn folder() -> tempfile::TempDir {
    let tmp = tempfile::tempdir().unwrap();
    for s in ["sets/a", "sets/b"] {
        std::fs::create_dir_all(tmp.path().join(s)).unwrap();
        std::fs::write(tmp.path().join(s).join(EXPERIMENT_JSON), "{}").unwrap();
    }
    std::fs::create_dir_all(tmp.path().join("sets/c")).unwrap();
    tmp
}

fn problems(tmp: &tempfile::TempDir, name: &str, text: &str) -> String {
    let path = tmp.path().join(name);
    std::fs::write(&path, text).unwrap();
    match load(&path, &SetOptions::default()) {
        Ok(m) => panic!("accepted: {m:?}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn toml_and_json_manifests_read_alike_with_options_laid_over_each_other() {
    let tmp = folder();
    let toml = "[options]\nseed = 7\ndiagnose = true\n\n[[sets]]\npath = \"sets/a\"\n\n[[sets]]\npath = \"sets/b\"\nid = \"b-alpha\"\nfree = [\"mu_s\", \"kappa\", \"xi\", \"u_tilde\", \"alpha_t\"]\nfix = { mu_k = 0.3 }\nbounds = { kappa = [0.1, 100.0] }\ntests = [\"mono\"]\nseed = 3\nstarts = 12\nglobal_evals = 5000\nprofiles = false\ndiagnose = false\n";
    let json = r#"{"options": {"seed": 7, "diagnose": true},
 "sets": [{"path": "sets/a"},
  {"path": "sets/b", "id": "b-alpha", "free": ["mu_s", "kappa", "xi", "u_tilde", "alpha_t"],
   "fix": {"mu_k": 0.3}, "bounds": {"kappa": [0.1, 100]}, "tests": ["mono"], "seed": 3,
   "starts": 12, "global_evals": 5000, "profiles": false, "diagnose": false}]}"#;
    let defaults = SetOptions {
        starts: 4,
        ..SetOptions::default()
    };
    let mut read = Vec::new();
    for (name, text) in [("m.toml", toml), ("m.json", json)] {
        let path = tmp.path().join(name);
        std::fs::write(&path, text).unwrap();
        read.push(load(&path, &defaults).unwrap());
    }
    // The same, but for the lines the entries start on.
    for m in read.iter_mut() {
        for s in m.sets.iter_mut() {
            s.line = 0;
        }
    }
    assert_eq!(read[0], read[1]);
    let m = &read[0];
    assert_eq!(m.sets.len(), 2);
    assert_eq!(m.sets[0].path, tmp.path().join("sets/a"));
    assert_eq!(m.sets[0].written, "sets/a");
    assert_eq!(set_id(&m.sets[0]), "a");
    assert_eq!(set_id(&m.sets[1]), "b-alpha");
    let base = m.options.over(&defaults);
    let a = m.sets[0].options.over(&base);
    assert_eq!((a.seed, a.starts, a.diagnose), (7, 4, true));
    let b = m.sets[1].options.over(&base);
    assert_eq!((b.seed, b.starts, b.global_evals), (3, 12, 5000));
    assert!(!b.profiles && !b.diagnose);
    assert_eq!(b.fix.get("mu_k"), Some(&0.3));
    assert_eq!(b.bounds.get("kappa"), Some(&[0.1, 100.0]));
    assert_eq!(b.tests, vec!["mono".to_string()]);
    b.check().unwrap();
}

#[test]
fn every_problem_of_a_toml_manifest_is_named_with_its_line_and_field() {
    let tmp = folder();
    let text = "[options]\nseed = -1\nsped = 2\n\n[[sets]]\npath = \"sets/a\"\nfix = { mu_k = \"low\" }\n\n[[sets]]\npath = \"sets/c\"\n\n[[sets]]\nid = \"x\"\n\n[[sets]]\npath = \"sets/a\"\nbounds = { kappa = [5.0, 1.0] }\n\n[[sets]]\npath = \"sets/b\"\nfree = [\"mu_s\", \"mu_k\"]\nfix = { mu_k = 0.3 }\n";
    let e = problems(&tmp, "m.toml", text);
    let lines: Vec<&str> = e.lines().collect();
    assert!(lines[0].contains("problems in the manifest"), "{e}");
    for (line, field, what) in [
        (2, "options.seed", "expected a whole number ≥ 0"),
        (3, "options.sped", "unknown field"),
        (
            7,
            "sets[0].fix.mu_k",
            "found a text (expected a finite number)",
        ),
        (10, "sets[1].path", "holds no experiment.json"),
        (12, "sets[2].path", "missing required field `path`"),
        (
            17,
            "sets[3].bounds.kappa",
            "lower bound 5 is not below the upper bound 1",
        ),
        (
            15,
            "sets[3]",
            "results folder sets/a is already that of the set on line 5",
        ),
        (19, "sets[4]", "mu_k cannot be both free and fixed"),
    ] {
        let want = format!("m.toml:{line}: field `{field}`: ");
        assert!(
            lines.iter().any(|l| l.contains(&want) && l.contains(what)),
            "expected `{want}` … `{what}` in:\n{e}"
        );
    }
}

#[test]
fn json_manifests_locate_their_problems_too_and_syntax_errors_have_a_line() {
    let tmp = folder();
    let text = "{\n\"sets\": [\n {\"path\": \"sets/a\", \"seed\": 1.5},\n {\"path\": 3}\n],\n\"sets\": []\n}";
    let e = problems(&tmp, "m.json", text);
    assert!(
        e.contains("m.json:3: field `sets[0].seed`: found 1.5 (expected a whole number ≥ 0)"),
        "{e}"
    );
    assert!(
        e.contains("m.json:4: field `sets[1].path`: found a number (expected a text)"),
        "{e}"
    );
    assert!(
        e.contains("m.json:6: field `sets`: given twice (first on line 2"),
        "{e}"
    );
    let e = problems(&tmp, "bad.json", "{\n\"sets\": [\n");
    assert!(
        e.starts_with(&format!("{}:3:", tmp.path().join("bad.json").display())),
        "{e}"
    );
    let e = problems(&tmp, "bad.toml", "[[sets]]\npath = \n");
    assert!(e.contains("bad.toml:2:"), "{e}");
    let e = problems(&tmp, "m.yaml", "sets: []");
    assert!(
        e.contains("expected a file ending in .json or .toml"),
        "{e}"
    );
    let e = problems(&tmp, "empty.toml", "sets = []\n");
    assert!(e.contains("empty.toml:1: field `sets`: no sets"), "{e}");
}
