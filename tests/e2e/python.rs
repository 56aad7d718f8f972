//! The Python package (`python/`), installed as a user installs it and tested against this
//! subfric program: a fresh virtual environment under `target/python/`, `pip install
//! ./python[test]` from the repository's files (pip builds the wheel with maturin, which
//! compiles the extension with cargo into the same `target/`), the README's Python example
//! (without matplotlib), the `arviz` extra, then the pytest suite of `python/tests`, which
//! compares the package with the program whose path Cargo hands this test
//! (`CARGO_BIN_EXE_subfric-e2e`).
//!
//! Needs CPython ≥ 3.9 with `venv` (`python3`, or the interpreter named by `SUBFRIC_PYTHON`) and
//! PyPI (maturin, numpy, pytest, dask, arviz). Without them the test fails, it does not skip. pip's
//! downloads are cached in `target/python/pip-cache`; nothing is written outside `target/`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Runs `cmd`; panics with its output unless it succeeds.
fn run(what: &str, cmd: &mut Command) -> Output {
    let t0 = Instant::now();
    let o = cmd
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot run {cmd:?}: {e}"));
    eprintln!("{what}: {:.1} s", t0.elapsed().as_secs_f64());
    assert!(
        o.status.success(),
        "{what} failed ({}): {cmd:?}\n{}",
        o.status,
        text(&o)
    );
    o
}

#[test]
fn the_python_package_installs_from_the_repository_and_its_tests_pass() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ is inside the repository")
        .to_path_buf();
    let program = PathBuf::from(env!("CARGO_BIN_EXE_subfric-e2e"));
    // target/<profile>/subfric-e2e: the work folder is target/python.
    let target = program
        .parent()
        .and_then(Path::parent)
        .expect("the program lies in target/<profile>/");
    let work = target.join("python");
    let venv = work.join("venv");
    if venv.exists() {
        std::fs::remove_dir_all(&venv).expect("remove the previous virtual environment");
    }
    std::fs::create_dir_all(&work).unwrap();
    let interpreter = std::env::var("SUBFRIC_PYTHON").unwrap_or_else(|_| "python3".into());
    let version = Command::new(&interpreter)
        .args(["-c", "import sys; print(sys.version_info >= (3, 9))"])
        .output()
        .unwrap_or_else(|e| {
            panic!("{interpreter}: {e} (the Python package's tests need CPython 3.9 or later with venv; SUBFRIC_PYTHON names another interpreter)")
        });
    assert_eq!(
        String::from_utf8_lossy(&version.stdout).trim(),
        "True",
        "{interpreter}: expected Python 3.9 or later\n{}",
        text(&version)
    );
    run(
        "python -m venv",
        Command::new(&interpreter).arg("-m").arg("venv").arg(&venv),
    );
    let python = if cfg!(windows) {
        venv.join("Scripts").join("python.exe")
    } else {
        venv.join("bin").join("python")
    };
    let pip_env = |c: &mut Command| {
        c.env("PIP_CACHE_DIR", work.join("pip-cache"))
            .env("PIP_DISABLE_PIP_VERSION_CHECK", "1")
            .env("PIP_NO_INPUT", "1")
            .env("PYTHONDONTWRITEBYTECODE", "1")
            .current_dir(&repo);
    };
    // What the README tells a user to run: build and install from the repository's files.
    let mut install = Command::new(&python);
    install.args(["-m", "pip", "install", "./python[test]"]);
    pip_env(&mut install);
    // maturin compiles the extension with cargo into this run's own target folder, with the
    // release profile the test run used: the workspace's crates and their dependencies are
    // already built there (cargo releases its lock on target/ once the test programs are
    // built), so a clean clone compiles the dependency tree once, not twice.
    install.env("CARGO_TARGET_DIR", target);
    run("pip install ./python[test] (maturin build)", &mut install);
    // The README's example runs as written after the README's install line: that line is
    // `pip install ./python` (this venv has the same package, plus pytest and dask so far), and
    // nothing else, matplotlib in particular, is needed.
    let readme = std::fs::read_to_string(repo.join("README.md")).unwrap();
    assert!(
        readme.contains("pip install ./python\n") || readme.contains("pip install ./python "),
        "the README's install line is not `pip install ./python`"
    );
    let example = readme
        .split("```python\n")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .expect("a Python example in the README");
    let no_matplotlib = run(
        "matplotlib absent",
        Command::new(&python)
            .args([
                "-c",
                "import importlib.util as u; print(u.find_spec('matplotlib') is None)",
            ])
            .current_dir(&work),
    );
    assert_eq!(
        String::from_utf8_lossy(&no_matplotlib.stdout).trim(),
        "True"
    );
    let script = work.join("readme_example.py");
    std::fs::write(&script, example).unwrap();
    let o = run(
        "the README's Python example",
        Command::new(&python)
            .arg(&script)
            .env("PYTHONDONTWRITEBYTECODE", "1")
            .current_dir(&repo),
    );
    let printed = text(&o);
    assert!(
        printed.contains("describes these data") && printed.contains("determined"),
        "the README's example printed:\n{printed}"
    );

    // ArviZ for the posterior's InferenceData (the `arviz` extra): installed after the README's
    // example has run without matplotlib, which arviz brings. Its requirement is read from
    // pyproject.toml, so that the test installs what the extra names.
    let pyproject = std::fs::read_to_string(repo.join("python").join("pyproject.toml")).unwrap();
    let arviz: Vec<String> = pyproject
        .lines()
        .find(|l| l.trim_start().starts_with("arviz = ["))
        .expect("an `arviz` extra in python/pyproject.toml")
        .split('"')
        .skip(1)
        .step_by(2)
        .map(String::from)
        .collect();
    assert!(!arviz.is_empty(), "the `arviz` extra names no requirement");
    let mut extra = Command::new(&python);
    extra.args(["-m", "pip", "install"]).args(&arviz);
    pip_env(&mut extra);
    run("pip install the arviz extra", &mut extra);
    // pytest from target/python, so that `import subfric` is the installed package, not the
    // source folder python/subfric (which has no compiled module); no cache in the repository.
    let mut pytest = Command::new(&python);
    pytest
        .args(["-m", "pytest", "-p", "no:cacheprovider", "-q", "-rA"])
        .arg(repo.join("python").join("tests"))
        .env("SUBFRIC_BIN", &program)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .current_dir(&work);
    let o = run("pytest python/tests", &mut pytest);
    let out = text(&o);
    println!("{out}");
    let summary = out
        .lines()
        .rev()
        .find(|l| l.contains(" passed"))
        .unwrap_or_else(|| panic!("pytest printed no summary of passed tests:\n{out}"));
    for bad in ["failed", "error", "skipped", "xfail", "no tests ran"] {
        assert!(!summary.contains(bad), "pytest: {summary}\n{out}");
    }
    let passed: usize = summary
        .split_whitespace()
        .zip(summary.split_whitespace().skip(1))
        .find(|(_, w)| w.trim_end_matches(',') == "passed")
        .and_then(|(n, _)| n.trim_start_matches('=').parse().ok())
        .unwrap_or(0);
    assert!(passed >= 20, "expected the whole suite to run: {summary}");
    // The package is the one this repository builds: its version is the workspace's.
    let v = run(
        "import subfric",
        Command::new(&python)
            .args(["-c", "import subfric; print(subfric.__version__)"])
            .current_dir(&work),
    );
    assert_eq!(
        String::from_utf8_lossy(&v.stdout).trim(),
        env!("CARGO_PKG_VERSION")
    );
}

/// `cargo tree` of `args` (features per package, one line each, no tree drawing): package
/// "name version" → the feature lists it is built with (several where it is built twice, for
/// a build script and for the target).
fn features_of(
    args: &[&str],
) -> std::collections::BTreeMap<String, std::collections::BTreeSet<String>> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let o = run(
        "cargo tree",
        Command::new(cargo)
            .arg("tree")
            .args(args)
            .args([
                "--locked",
                "-f",
                "{p} {f}",
                "--prefix",
                "none",
                "--no-dedupe",
            ])
            .current_dir(repo),
    );
    let mut out: std::collections::BTreeMap<String, std::collections::BTreeSet<String>> =
        Default::default();
    for line in String::from_utf8_lossy(&o.stdout).lines() {
        let mut words = line.split_whitespace();
        let (Some(name), Some(version)) = (words.next(), words.next()) else {
            continue;
        };
        // A path package prints its folder in parentheses before its features.
        let features = words.find(|w| !w.starts_with('(')).unwrap_or("");
        out.entry(format!("{name} {version}"))
            .or_default()
            .insert(features.to_string());
    }
    out
}

#[test]
fn the_extension_is_built_from_the_crates_the_test_programs_built() {
    // maturin builds subfric-py alone; `cargo test --workspace` builds every member, with the
    // features all of them (dev- and bench-dependencies included) switch on. A dependency with
    // other features in the extension's build is another build of it and of every crate above
    // it: on a clean clone the pip install compiled the whole tree a second time (rayon, png,
    // tiny-skia, usvg and every subfric crate; serde's "alloc" came from criterion). The
    // feature pins in python/Cargo.toml keep the two equal.
    let workspace = features_of(&["--workspace", "-e", "normal,build,dev"]);
    let extension = features_of(&["-p", "subfric-py", "-e", "normal,build"]);
    assert!(
        extension.len() > 50,
        "cargo tree listed {} packages",
        extension.len()
    );
    let differ: Vec<String> = extension
        .iter()
        .filter(|(p, f)| workspace.get(*p).is_none_or(|w| !f.is_subset(w)))
        .map(|(p, f)| {
            format!(
                "{p}: {f:?} in the extension's build, {:?} in the workspace's",
                workspace.get(p)
            )
        })
        .collect();
    assert!(
        differ.is_empty(),
        "built with other features for the Python extension than for the test programs (add a feature pin to python/Cargo.toml):\n{}",
        differ.join("\n")
    );
}
