//! Trust, round two (issue 25): no panic when the terminal's streams cannot be written, no
//! result lost or mixed by two commands writing one folder, an interrupted write that the same
//! command finishes, figures that never overwrite each other, a set never counted twice,
//! contradicting options refused, errors that point at the right place, and the smaller cases.
//! Every test builds its input in a temporary folder and runs the program as a user does.

use std::ffi::{OsStr, OsString};
use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use subfric_e2e::{
    args, assert_mentions, assert_no_panic, copy_set, experiments, line_of, read_json, subfric,
    text, Subfric,
};

/// A fit small enough for a test.
const QUICK: [&str; 5] = ["--global-evals", "100", "--starts", "2", "--no-profiles"];

fn os(v: &[OsString]) -> Vec<&OsStr> {
    v.iter().map(|s| s.as_os_str()).collect()
}

/// `fit <sets> QUICK <extra>`.
fn quick_fit(sets: &[&Path], extra: &[&OsStr]) -> Vec<OsString> {
    let mut a: Vec<OsString> = vec!["fit".into()];
    a.extend(sets.iter().map(|s| s.as_os_str().to_owned()));
    a.extend(QUICK.iter().map(OsString::from));
    a.extend(extra.iter().map(|s| s.to_os_string()));
    a
}

/// Names in `dir` (not recursive), sorted.
fn names_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

/// Rewrites a set's experiment.json through `edit`.
fn edit_meta(set: &Path, edit: impl FnOnce(&mut serde_json::Value)) {
    let json = set.join("experiment.json");
    let mut meta = read_json(&json);
    edit(&mut meta);
    std::fs::write(&json, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
}

/// A copy of table1-medium under `dir` with the set name `name`.
fn named_copy(dir: &Path, name: &str) -> PathBuf {
    let set = copy_set("table1-medium", dir);
    edit_meta(&set, |m| m["name"] = name.into());
    set
}

// 1. stdout and stderr that cannot be written --------------------------------------------------

/// Where the program's stdout or stderr goes.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Sink {
    /// stdout is a pipe whose reader has gone (`| head -1` once head has exited).
    ClosedPipe,
    /// stdout is a full device (`> /dev/full`).
    FullStdout,
    /// stderr is a full device (`2> /dev/full`).
    FullStderr,
}

/// A pipe whose reading end is closed: every write to it fails with EPIPE.
fn closed_pipe() -> Stdio {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    Stdio::from(writer)
}

fn dev_full() -> Stdio {
    Stdio::from(
        File::options()
            .write(true)
            .open("/dev/full")
            .expect("/dev/full"),
    )
}

fn spawn_into(s: &Subfric, a: &[&OsStr], sink: Sink) -> Child {
    let mut c = s.command(a);
    match sink {
        Sink::ClosedPipe => c.stdout(closed_pipe()).stderr(Stdio::piped()),
        Sink::FullStdout => c.stdout(dev_full()).stderr(Stdio::piped()),
        Sink::FullStderr => c.stdout(Stdio::piped()).stderr(dev_full()),
    };
    c.spawn().expect("the subfric program runs")
}

/// Every command, run so that it succeeds, with the file it must have written completely
/// (relative to `out`; `None`: it writes nothing).
fn every_command(work: &Path, out: &Path) -> Vec<(&'static str, Vec<OsString>, Option<PathBuf>)> {
    let set = work.join("table1-medium");
    let exp = work.join("experiments");
    let params = set.join("experiment.json");
    let o = |p: &str| out.join(p).into_os_string();
    let v = |a: &[&OsStr]| a.iter().map(|s| s.to_os_string()).collect::<Vec<_>>();
    let mut fit = quick_fit(&[&set], &[OsStr::new("--out")]);
    fit.push(o("fit"));
    vec![
        ("check", v(args!["check", &set]), None),
        ("fit", fit, Some(PathBuf::from("fit/fit.json"))),
        (
            "diagnose",
            v(args!["diagnose", &set, "--out", &o("diagnose")]),
            Some(PathBuf::from("diagnose/diagnosis.json")),
        ),
        (
            "plan",
            v(args!["plan", &set, "--out", &o("plan")]),
            Some(PathBuf::from("plan/plan.json")),
        ),
        (
            "reproduce",
            v(args![
                "reproduce",
                "--experiments",
                &exp,
                "--out",
                &o("reproduce")
            ]),
            Some(PathBuf::from("reproduce/README.md")),
        ),
        (
            "simulate",
            v(args![
                "simulate",
                &set,
                "--params",
                &params,
                "--out",
                &o("simulate")
            ]),
            Some(PathBuf::from("simulate/experiment.json")),
        ),
        (
            "import",
            v(args![
                "import",
                &work.join("lab.csv"),
                "--out",
                &o("import"),
                "--normal-stress",
                "100"
            ]),
            Some(PathBuf::from("import/experiment.json")),
        ),
        (
            "plot",
            v(args!["plot", &set, "--out", &o("plot")]),
            Some(PathBuf::from("plot/monotonic.png")),
        ),
        (
            "selfcheck",
            v(args![
                "selfcheck",
                "--sets",
                &work.join("scored"),
                "--json",
                &o("scores.json")
            ]),
            Some(PathBuf::from("scores.json")),
        ),
    ]
}

#[cfg(target_os = "linux")]
#[test]
fn no_command_panics_or_loses_its_results_when_stdout_or_stderr_cannot_be_written() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let work = tmp.path().join("work");
    let set = copy_set("table1-medium", &work);
    copy_set("table1-medium", &work.join("experiments"));
    let scored = work.join("scored");
    copy_set("table1-medium", &scored);
    std::fs::write(
        scored.join("truth.json"),
        r#"{"table1-medium": {"effect": "none"}}"#,
    )
    .unwrap();
    let mut lab = String::from("time_s,slip_mm,shear_kpa\n");
    for i in 0..40 {
        lab.push_str(&format!(
            "{i},{},{}\n",
            0.01 * i as f64,
            30.0 * (1.0 - (-0.2 * i as f64).exp())
        ));
    }
    std::fs::write(work.join("lab.csv"), lab).unwrap();
    // bench, once beside the others, with stdout gone and stderr full: its parts that read the
    // sets and print a line each (the whole benchmark takes minutes and prints the same way).
    let bench = s
        .command(args![
            "bench",
            "--experiments",
            &work.join("experiments"),
            "--only",
            "step,fits,multistart"
        ])
        .stdout(closed_pipe())
        .stderr(dev_full())
        .spawn()
        .unwrap();
    for sink in [Sink::ClosedPipe, Sink::FullStdout, Sink::FullStderr] {
        let out = tmp.path().join(format!("{sink:?}"));
        for (name, a, result) in every_command(&work, &out) {
            let o = spawn_into(&s, &os(&a), sink).wait_with_output().unwrap();
            let (code, err) = (o.status.code(), text(&o.stderr));
            assert_no_panic(&err, &os(&a));
            assert_ne!(code, Some(101), "{name} under {sink:?} panicked");
            match sink {
                // A reader that went away ends the command quietly, with its own exit code.
                Sink::ClosedPipe => assert!(
                    code == Some(0) && !err.contains("error"),
                    "{name} under {sink:?}: {code:?}\n{err}"
                ),
                // A full stdout is one line on stderr, exit code 1, the files written.
                Sink::FullStdout => {
                    assert_eq!(code, Some(1), "{name} under {sink:?}:\n{err}");
                    assert_eq!(
                        err.matches("cannot write to standard output").count(),
                        1,
                        "{name}:\n{err}"
                    );
                }
                // A full stderr changes nothing: the command prints its results on stdout.
                Sink::FullStderr => {
                    assert_eq!(code, Some(0), "{name} under {sink:?}");
                    assert!(!text(&o.stdout).is_empty(), "{name}: nothing on stdout");
                }
            }
            if let Some(r) = result {
                let file = out.join(&r);
                assert!(
                    file.is_file(),
                    "{name} under {sink:?}: {} missing",
                    r.display()
                );
                let folder = file.parent().unwrap();
                if name != "import" && name != "simulate" && name != "selfcheck" {
                    assert!(
                        folder.join(".subfric-source").is_file(),
                        "{name} under {sink:?}: results without their .subfric-source"
                    );
                }
                assert!(
                    !names_in(folder).iter().any(|n| n.contains("subfric-tmp")),
                    "{name}: half-written files"
                );
            }
        }
    }
    // The same folders again: every one is the command's own and is written again.
    let out = tmp.path().join("ClosedPipe");
    for (name, a, _) in every_command(&work, &out) {
        if name == "import" || name == "simulate" || name == "selfcheck" {
            continue;
        }
        let o = s.run(&os(&a));
        assert!(o.status.success(), "{name} again: {}", text(&o.stderr));
    }
    // `| head -1`: the reader takes one line and goes.
    let mut a = quick_fit(&[&set], &[OsStr::new("--out")]);
    a.push(tmp.path().join("head").into());
    let mut child = s
        .command(&os(&a))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = child.stdout.take().unwrap();
    let mut first = [0u8; 1];
    std::io::Read::read_exact(&mut stdout, &mut first).unwrap();
    drop(stdout);
    let o = child.wait_with_output().unwrap();
    assert_no_panic(&text(&o.stderr), &os(&a));
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(tmp.path().join("head/fit.json").is_file());
    // --progress always with stderr full: the fit is not aborted.
    let mut a = quick_fit(
        &[&set],
        &[
            OsStr::new("--progress"),
            OsStr::new("always"),
            OsStr::new("--out"),
        ],
    );
    a.push(tmp.path().join("progress").into());
    let o = spawn_into(&s, &os(&a), Sink::FullStderr)
        .wait_with_output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    assert!(tmp.path().join("progress/fit.json").is_file());
    let o = bench.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(0), "bench with stdout gone");
}

#[path = "trust2/folders.rs"]
mod folders;

// 10. options that contradict each other -------------------------------------------------------------

#[test]
fn contradicting_options_are_usage_errors_naming_both() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table1-medium");
    let out = tmp.path().join("out");
    for (flags, both) in [
        (vec!["--fix", "xi=0.1,xi=0.2"], ["xi=0.1", "xi=0.2"]),
        (
            vec!["--free", "mu_s,mu_k", "--fix", "mu_s=0.4"],
            ["--free mu_s", "--fix mu_s=0.4"],
        ),
        (
            vec!["--weight", "monotonic=2,monotonic=3"],
            ["monotonic=2", "monotonic=3"],
        ),
        (
            vec!["--bounds", "kappa=1:10,kappa=20:30"],
            ["kappa=1:10", "kappa=20:30"],
        ),
    ] {
        let mut a = quick_fit(&[&set], &[OsStr::new("--out"), out.as_os_str()]);
        a.extend(flags.iter().map(OsString::from));
        let err = s.usage_err(&os(&a));
        assert_mentions(&err, &both);
        assert!(!out.exists());
    }
    let lab = tmp.path().join("lab.csv");
    std::fs::write(&lab, "time_s,slip_mm,shear_kpa,N\n0,0,0,78\n1,0.01,20,78\n").unwrap();
    let err = s.usage_err(args![
        "import",
        &lab,
        "--out",
        &out,
        "--normal",
        "N",
        "--normal-stress",
        "78.4"
    ]);
    assert_mentions(&err, &["--normal", "--normal-stress"]);
    // Two columns of one name: which one is meant?
    std::fs::write(
        &lab,
        "time_s,slip_mm,shear_kpa,shear_kpa\n0,0,0,0\n1,0.01,20,25\n",
    )
    .unwrap();
    let err = s.err(args![
        "import",
        &lab,
        "--out",
        &out,
        "--normal-stress",
        "78.4"
    ]);
    assert_mentions(&err, &["lab.csv:1", "columns 3", "and 4", "shear_kpa"]);
    assert!(!out.exists());
    // A key given twice in a parameter file.
    let params = tmp.path().join("params.json");
    std::fs::write(
        &params,
        "{\"mu_s\": 0.37, \"mu_k\": 0.3, \"kappa\": 33, \"xi\": 0.027,\n \"u_tilde\": 3000, \"alpha_t\": 2000, \"xi\": 0.5}",
    )
    .unwrap();
    let err = s.err(args!["simulate", &set, "--params", &params, "--out", &out]);
    assert_mentions(&err, &["params.json:2:", "`xi` appears twice"]);
    assert!(!out.exists());
}

// 11. errors at the right place ----------------------------------------------------------------------

#[test]
fn errors_point_at_the_cell_line_and_flag_that_caused_them() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    // A normal stress of 1e308 in experiment.json: once, there.
    let set = copy_set("table1-medium", tmp.path());
    edit_meta(&set, |m| m["tests"][0]["normal_stress_kpa"] = 1e308.into());
    let err = s.err(args!["check", &set]);
    let line = line_of(&set.join("experiment.json"), "normal_stress_kpa");
    assert_mentions(
        &err,
        &[
            &format!("experiment.json:{line}: field `tests[0].normal_stress_kpa`"),
            "1e308",
        ],
    );
    assert!(
        err.contains("1 problem") && !err.contains("monotonic.csv"),
        "{err}"
    );
    // import quotes the cell as the file has it.
    let lab = tmp.path().join("lab.csv");
    std::fs::write(&lab, "time_s;slip_mm;shear_kpa\n0;0;0\n1;1,234,5;20\n").unwrap();
    let err = s.err(args![
        "import",
        &lab,
        "--out",
        &tmp.path().join("i"),
        "--normal-stress",
        "100"
    ]);
    assert_mentions(&err, &["lab.csv:3", "`1,234,5`"]);
    assert!(!err.contains("1.234.5"), "{err}");
    // Lines ended by a lone CR are read.
    let cr = copy_set("table1-medium", &tmp.path().join("cr"));
    let csv = std::fs::read_to_string(cr.join("monotonic.csv")).unwrap();
    std::fs::write(cr.join("monotonic.csv"), csv.replace('\n', "\r")).unwrap();
    let plain = s.ok(args!["check", &experiments().join("table1-medium")]);
    assert_eq!(s.ok(args!["check", &cr]), plain);
    std::fs::write(
        &lab,
        "time_s,slip_mm,shear_kpa\r0,0,0\r1,0.01,20\r2,0.02,30\r",
    )
    .unwrap();
    let stdout = s.ok(args![
        "import",
        &lab,
        "--out",
        &tmp.path().join("i"),
        "--normal-stress",
        "100"
    ]);
    assert_mentions(&stdout, &["test", "3"]);
    // bench names the folder it cannot read.
    let nosuch = tmp.path().join("nosuch");
    let err = s.err(args!["bench", "--experiments", &nosuch]);
    assert_mentions(&err, &[&nosuch.display().to_string(), "experiments"]);
    // --setup-hours NaN is a usage error, as --fix xi=NaN is.
    let err = s.usage_err(args!["plan", &set, "--setup-hours", "NaN"]);
    assert_mentions(&err, &["--setup-hours", "finite"]);
}

// 12. smaller -------------------------------------------------------------------------------------

#[test]
fn weights_are_relative_and_refused_beyond_a_factor_of_a_million() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table1-medium");
    let refused = tmp.path().join("refused");
    let err = s.usage_err(&os(&quick_fit(
        &[&set],
        &[
            OsStr::new("--weight"),
            OsStr::new("monotonic=1e-30"),
            OsStr::new("--out"),
            refused.as_os_str(),
        ],
    )));
    assert_mentions(&err, &["--weight", "1e-6", "1e6", "--tests"]);
    assert!(!refused.exists());
    // The only test, weighted 10⁻³: the same fit, the same misfit as without a weight.
    let fit = |extra: &[&str], out: &str| {
        let dir = tmp.path().join(out);
        let mut a = quick_fit(&[&set], &[OsStr::new("--out"), dir.as_os_str()]);
        a.extend(extra.iter().map(OsString::from));
        s.ok(&os(&a));
        read_json(&dir.join("fit.json"))
    };
    let plain = fit(&[], "plain");
    let weighted = fit(&["--weight", "monotonic=1e-3"], "weighted");
    let chi2 = |j: &serde_json::Value| j["report"]["reduced_chi2"].as_f64().unwrap();
    assert!(chi2(&plain) > 0.5, "{}", chi2(&plain));
    assert!(
        (chi2(&weighted) / chi2(&plain) - 1.0).abs() < 1e-6,
        "misfit {} weighted, {} not",
        chi2(&weighted),
        chi2(&plain)
    );
}

#[test]
fn selfcheck_refuses_a_truth_that_is_no_effect() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path().join("sets");
    copy_set("table1-medium", &root);
    std::fs::write(
        root.join("truth.json"),
        r#"{"table1-medium": {"effect": "ratee"}}"#,
    )
    .unwrap();
    let err = s.err(args!["selfcheck", "--sets", &root]);
    assert_mentions(
        &err,
        &["truth.json", "table1-medium", "ratee", "log-healing"],
    );
    // No set scored is no self-check.
    std::fs::write(root.join("truth.json"), r#"{"other": {"effect": "rate"}}"#).unwrap();
    let a = args!["selfcheck", "--sets", &root];
    let o = s.run(a);
    let err = text(&o.stderr);
    assert_no_panic(&err, a);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_mentions(&err, &["no truth", "skipped", "error:", "no set"]);
}

#[test]
fn results_never_go_among_measured_data_or_beside_foreign_files_without_force() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-medium", tmp.path());
    let before = subfric_e2e::snapshot(&set);
    for force in [false, true] {
        let mut a = quick_fit(&[&set], &[OsStr::new("--out"), set.as_os_str()]);
        if force {
            a.push("--force".into());
        }
        let err = s.err(&os(&a));
        assert_mentions(&err, &["holds an experiment set", "measured data"]);
        let mut p = vec![
            OsString::from("plan"),
            set.clone().into(),
            "--out".into(),
            set.clone().into(),
        ];
        if force {
            p.push("--force".into());
        }
        s.err(&os(&p));
    }
    assert!(subfric_e2e::snapshot(&set) == before, "the set was written");
    // reproduce --out the experiments folder.
    let exp = tmp.path().join("exp");
    copy_set("table1-medium", &exp);
    std::fs::write(exp.join("notes.txt"), "my notes\n").unwrap();
    let exp_before = subfric_e2e::snapshot(&exp);
    let err = s.err(args!["reproduce", "--experiments", &exp, "--out", &exp]);
    assert_mentions(
        &err,
        &["did not write", "notes.txt", "table1-medium", "--force"],
    );
    let err = s.err(args![
        "reproduce",
        "--experiments",
        &exp,
        "--out",
        &exp,
        "--force"
    ]);
    assert_mentions(&err, &["holds an experiment set"]);
    assert!(
        subfric_e2e::snapshot(&exp) == exp_before,
        "the experiments were written"
    );
    // A folder of someone's files: only with --force, and then beside them.
    let mine = tmp.path().join("mine");
    std::fs::create_dir_all(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "mine\n").unwrap();
    let mut a = quick_fit(&[&set], &[OsStr::new("--out"), mine.as_os_str()]);
    let err = s.err(&os(&a));
    assert_mentions(&err, &["notes.txt", "--force"]);
    a.push("--force".into());
    s.ok(&os(&a));
    assert_eq!(
        std::fs::read_to_string(mine.join("notes.txt")).unwrap(),
        "mine\n"
    );
    assert!(mine.join("fit.json").is_file());
}

#[test]
fn a_joint_fit_holds_the_stiffness_every_set_publishes_and_says_so() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let a = named_copy(&tmp.path().join("a"), "set-a");
    // Another record (one set's rows twice are refused, whatever the set's name).
    let b = copy_set("table1-rough", &tmp.path().join("b"));
    edit_meta(&b, |m| m["name"] = "set-b".into());
    let out = tmp.path().join("joint");
    let (_, err) = s.ok_both(&os(&quick_fit(
        &[&a, &b],
        &[OsStr::new("--out"), out.as_os_str()],
    )));
    let published = read_json(&a.join("experiment.json"))["reference_parameters"]["alpha_t"]
        .as_f64()
        .unwrap();
    assert_eq!(published, 2000.0);
    let fit = read_json(&out.join("fit.json"));
    assert_eq!(fit["params"]["alpha_t"].as_f64(), Some(published));
    assert_mentions(
        &err,
        &["note:", "alpha_t held at 2000", "every set publishes"],
    );
    // Sets that publish different values: a typical value, and why.
    edit_meta(&b, |m| m["reference_parameters"]["alpha_t"] = 1500.0.into());
    let out = tmp.path().join("joint2");
    let (_, err) = s.ok_both(&os(&quick_fit(
        &[&a, &b],
        &[OsStr::new("--out"), out.as_os_str()],
    )));
    assert_mentions(&err, &["alpha_t held at", "set-a 2000", "set-b 1500"]);
}

#[test]
fn names_are_shown_with_their_control_characters_made_visible() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-medium", tmp.path());
    edit_meta(&set, |m| {
        m["name"] = "red\u{1b}[31m\nforged".into();
        m["tests"][0]["name"] = "t\u{1b}]0;title\u{7}".into();
    });
    let check = s.ok_both(args!["check", &set]);
    let mut a = quick_fit(&[&set], &[OsStr::new("--out")]);
    a.push(tmp.path().join("out").into());
    let fit = s.ok_both(&os(&a));
    for (stdout, stderr) in [check, fit] {
        for t in [&stdout, &stderr] {
            assert!(
                !t.contains('\u{1b}') && !t.contains('\u{7}'),
                "raw control characters:\n{t}"
            );
        }
        assert!(stdout.contains("red\\x1b[31m\\nforged"), "{stdout}");
        assert!(stdout.contains("t\\x1b]0;title\\x07"), "{stdout}");
        assert!(!stdout.lines().any(|l| l.starts_with("forged")), "{stdout}");
    }
}
