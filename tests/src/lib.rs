//! Helpers of the end-to-end tests: running the program, copying sets, reading its output.
//!
//! The program is this package's `subfric-e2e` binary (the subfric program itself, see
//! Cargo.toml); a test gets it with [`subfric!`].

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

pub mod html;

/// The program under test, as a [`Subfric`] runner.
#[macro_export]
macro_rules! subfric {
    () => {
        $crate::Subfric::new(env!("CARGO_BIN_EXE_subfric-e2e"))
    };
}

/// Arguments as `OsStr`s, so that paths and strings mix.
#[macro_export]
macro_rules! args {
    ($($a:expr),* $(,)?) => { &[$(std::ffi::OsStr::new($a)),*] };
}

/// Runs the program with arguments, optionally in a working folder and with environment.
#[derive(Clone, Debug)]
pub struct Subfric {
    exe: PathBuf,
    cwd: Option<PathBuf>,
    env: Vec<(String, String)>,
}

/// Text of captured bytes.
pub fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).to_string()
}

impl Subfric {
    /// A runner of `exe`.
    pub fn new(exe: &str) -> Subfric {
        Subfric {
            exe: PathBuf::from(exe),
            cwd: None,
            env: Vec::new(),
        }
    }

    /// The executable.
    pub fn exe(&self) -> &Path {
        &self.exe
    }

    /// Runs in `dir`.
    pub fn cwd(mut self, dir: &Path) -> Subfric {
        self.cwd = Some(dir.to_path_buf());
        self
    }

    /// Sets an environment variable.
    pub fn env(mut self, k: &str, v: &str) -> Subfric {
        self.env.push((k.into(), v.into()));
        self
    }

    /// A command ready to run.
    pub fn command(&self, args: &[&OsStr]) -> Command {
        let mut c = Command::new(&self.exe);
        c.args(args);
        if let Some(d) = &self.cwd {
            c.current_dir(d);
        }
        for (k, v) in &self.env {
            c.env(k, v);
        }
        c
    }

    /// Runs and returns the output.
    pub fn run(&self, args: &[&OsStr]) -> Output {
        self.command(args)
            .output()
            .expect("the subfric program runs")
    }

    /// Runs and asserts success without a panic; returns stdout.
    pub fn ok(&self, args: &[&OsStr]) -> String {
        self.ok_both(args).0
    }

    /// Runs and asserts success without a panic; returns (stdout, stderr).
    pub fn ok_both(&self, args: &[&OsStr]) -> (String, String) {
        let o = self.run(args);
        let err = text(&o.stderr);
        assert!(
            o.status.success(),
            "subfric {args:?} failed ({:?}):\n{err}",
            o.status.code()
        );
        assert_no_panic(&err, args);
        (text(&o.stdout), err)
    }

    /// Runs and asserts a clean runtime error: exit code 1, no panic, a message starting with
    /// `error:`. Returns stderr.
    pub fn err(&self, args: &[&OsStr]) -> String {
        self.failure(args, 1)
    }

    /// Runs and asserts a usage error (clap's exit code 2) that starts with `error:`.
    pub fn usage_err(&self, args: &[&OsStr]) -> String {
        self.failure(args, 2)
    }

    fn failure(&self, args: &[&OsStr], code: i32) -> String {
        let o = self.run(args);
        let err = text(&o.stderr);
        assert_no_panic(&err, args);
        assert_eq!(
            o.status.code(),
            Some(code),
            "subfric {args:?}: expected exit code {code}, stderr:\n{err}"
        );
        assert!(err.starts_with("error:"), "{err}");
        err
    }
}

/// Fails if the program panicked.
pub fn assert_no_panic(stderr: &str, args: &[&OsStr]) {
    assert!(
        !stderr.contains("panicked") && !stderr.contains("RUST_BACKTRACE"),
        "subfric {args:?} panicked:\n{stderr}"
    );
}

/// Asserts that `msg` contains every one of `needles`.
pub fn assert_mentions(msg: &str, needles: &[&str]) {
    for n in needles {
        assert!(msg.contains(n), "message lacks `{n}`:\n{msg}");
    }
}

/// The repository root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ is inside the repository")
        .to_path_buf()
}

/// The bundled experiment sets.
pub fn experiments() -> PathBuf {
    repo().join("experiments")
}

/// The golden data shared by the crates' tests.
pub fn golden() -> PathBuf {
    repo().join("tests/golden")
}

/// The bundled set names (folders of `experiments/` holding an `experiment.json`).
pub fn bundled_sets() -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(experiments())
        .expect("experiments/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.join("experiment.json").is_file())
        .map(|p| p.file_name().unwrap().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

/// Copies the folder `from` to `to` (files only, made writable).
pub fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        if !p.is_file() {
            continue;
        }
        let d = to.join(p.file_name().unwrap());
        std::fs::copy(&p, &d).unwrap();
        // The bundled files may be read-only; tests edit their copies.
        let mut perm = std::fs::metadata(&d).unwrap().permissions();
        #[allow(clippy::permissions_set_readonly_false)]
        perm.set_readonly(false);
        std::fs::set_permissions(&d, perm).unwrap();
    }
}

/// Copies `experiments/<name>` to `<to>/<name>`; returns the copy.
pub fn copy_set(name: &str, to: &Path) -> PathBuf {
    let dest = to.join(name);
    copy_dir(&experiments().join(name), &dest);
    dest
}

/// A data CSV: header names and rows of numbers (comment lines skipped).
pub fn read_data_csv(p: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let t = std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let mut lines = t.lines().filter(|l| !l.starts_with('#') && !l.is_empty());
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(|s| s.to_string())
        .collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|c| {
                    c.parse()
                        .unwrap_or_else(|_| panic!("{}: `{c}` in `{l}`", p.display()))
                })
                .collect()
        })
        .collect();
    (header, rows)
}

/// Column `k` of rows.
pub fn column(rows: &[Vec<f64>], k: usize) -> Vec<f64> {
    rows.iter().map(|r| r[k]).collect()
}

/// A JSON file.
pub fn read_json(p: &Path) -> Value {
    let t = std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    serde_json::from_str(&t).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// RMS difference of two columns relative to the largest magnitude of the first.
pub fn relative_rms(measured: &[f64], other: &[f64]) -> f64 {
    assert_eq!(measured.len(), other.len());
    let scale = measured.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let ss: f64 = measured
        .iter()
        .zip(other)
        .map(|(a, b)| (a - b).powi(2))
        .sum();
    (ss / measured.len() as f64).sqrt() / scale
}

/// The 1-based line of `file` holding `needle` first.
pub fn line_of(file: &Path, needle: &str) -> usize {
    std::fs::read_to_string(file)
        .unwrap()
        .lines()
        .position(|l| l.contains(needle))
        .unwrap_or_else(|| panic!("{} has no `{needle}`", file.display()))
        + 1
}

/// Replaces line `line` (1-based) of a text file.
pub fn replace_line(file: &Path, line: usize, with: &str) {
    let t = std::fs::read_to_string(file).unwrap();
    let mut lines: Vec<String> = t.lines().map(String::from).collect();
    lines[line - 1] = with.to_string();
    std::fs::write(file, lines.join("\n") + "\n").unwrap();
}

/// Every file under `dir` (recursively), relative, sorted, with its bytes.
pub fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    fn walk(root: &Path, d: &Path, out: &mut Vec<(PathBuf, Vec<u8>)>) {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                let rel = p.strip_prefix(root).unwrap().to_path_buf();
                out.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Writes a small set from columns: `tests` are (name, control, normal kPa, rows of
/// time, slip, shear).
pub fn write_small_set(dir: &Path, name: &str, tests: &[(&str, &str, f64, Vec<[f64; 3]>)]) {
    std::fs::create_dir_all(dir).unwrap();
    let specs: Vec<Value> = tests
        .iter()
        .map(|(n, c, p, _)| {
            serde_json::json!({"name": n, "file": format!("{n}.csv"), "control": c, "normal_stress_kpa": p})
        })
        .collect();
    let meta = serde_json::json!({"name": name, "title": name, "source": "written by a test", "tests": specs});
    std::fs::write(
        dir.join("experiment.json"),
        serde_json::to_string_pretty(&meta).unwrap(),
    )
    .unwrap();
    for (n, _, _, rows) in tests {
        let mut csv = String::from("time_s,slip_mm,shear_kpa\n");
        for r in rows {
            csv.push_str(&format!("{},{},{}\n", r[0], r[1], r[2]));
        }
        std::fs::write(dir.join(format!("{n}.csv")), csv).unwrap();
    }
}
