//! Bad input gives an error naming the file, the line and the field and what was expected —
//! never a panic, never output written: missing folders and files, broken CSV cells, invalid
//! parameter files, malformed options, lab files without the named columns.

use std::ffi::OsStr;

use subfric_e2e::{args, assert_mentions, copy_set, experiments, line_of, replace_line, subfric};

fn run_err(a: &[&OsStr]) -> String {
    subfric!().err(a)
}

#[test]
fn a_missing_set_folder_is_named_by_every_command() {
    let tmp = tempfile::tempdir().unwrap();
    let missing = tmp.path().join("no-such-set");
    let params = experiments().join("table1-medium/experiment.json");
    let out = tmp.path().join("out");
    for a in [
        args!["check", &missing].to_vec(),
        args!["fit", &missing, "--no-profiles", "--out", &out].to_vec(),
        args!["simulate", &missing, "--params", &params, "--out", &out].to_vec(),
        args!["plot", &missing, "--out", &out].to_vec(),
        args!["diagnose", &missing, "--out", &out].to_vec(),
    ] {
        let err = run_err(&a);
        assert_mentions(&err, &["no-such-set", "does not exist", "expected"]);
    }
    let err = run_err(args!["reproduce", "--experiments", &missing, "--out", &out]);
    assert_mentions(&err, &["no-such-set"]);
    // An experiments folder without any set.
    let empty = tmp.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let err = run_err(args!["reproduce", "--experiments", &empty, "--out", &out]);
    assert_mentions(&err, &["empty", "experiment.json"]);
    assert!(!out.exists(), "nothing is written on error");
}

#[test]
fn an_absent_csv_is_reported_at_its_line_of_experiment_json() {
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-medium", tmp.path());
    std::fs::remove_file(set.join("monotonic.csv")).unwrap();
    let line = line_of(&set.join("experiment.json"), "\"file\"");
    let err = run_err(args!["check", &set]);
    assert_mentions(
        &err,
        &[
            &format!("experiment.json:{line}"),
            "tests[0].file",
            "monotonic.csv",
            "absent",
            "expected",
        ],
    );
    // fit goes through the same loader.
    let out = tmp.path().join("out");
    let err = run_err(args!["fit", &set, "--no-profiles", "--out", &out]);
    assert_mentions(&err, &[&format!("experiment.json:{line}"), "monotonic.csv"]);
    assert!(!out.exists());
}

#[test]
fn csv_errors_name_file_line_and_field() {
    let tmp = tempfile::tempdir().unwrap();
    // (what, line to edit, its time cell before, new text, words the message must hold)
    let header_line = 2;
    let cases: [(&str, usize, &str, &str, &[&str]); 5] = [
        (
            "wrong column name",
            header_line,
            "time_s",
            "time_s,slip_mm,shear_kPa_x",
            &[":2", "shear_kPa_x", "unknown column", "shear_kpa"],
        ),
        (
            "an overflow in a cell",
            7,
            "0.240",
            "0.240,0.00400,inf",
            &[":7", "shear_kpa", "inf", "finite"],
        ),
        (
            "non-increasing time",
            7,
            "0.240",
            "0.120,0.00400,28.4797",
            &[":7", "time_s", "increasing"],
        ),
        (
            "text in a cell",
            9,
            "0.360",
            "0.360,abc,28.0",
            &[":9", "slip_mm", "abc"],
        ),
        (
            "a missing cell",
            12,
            "0.540",
            "0.540,0.00900",
            &[":12", "2 cells", "expected 3"],
        ),
    ];
    for (i, (what, line, was, new, words)) in cases.iter().enumerate() {
        let root = tmp.path().join(format!("case{i}"));
        let set = copy_set("table1-medium", &root);
        let csv = set.join("monotonic.csv");
        // The edit must land where the case expects it.
        let before = std::fs::read_to_string(&csv).unwrap();
        let old = before.lines().nth(line - 1).unwrap();
        assert_eq!(old.split(',').next(), Some(*was), "{what}: {old}");
        replace_line(&csv, *line, new);
        let err = run_err(args!["check", &set]);
        assert_mentions(&err, &["monotonic.csv", "expected"]);
        assert_mentions(&err, words);
        // The message points at monotonic.csv:<line>, not at another file or line.
        assert!(
            err.contains(&format!("monotonic.csv:{line}")),
            "{what}: {err}"
        );
        // The same problem stops a fit and a simulation before any output is written.
        let out = root.join("out");
        let err = run_err(args!["fit", &set, "--no-profiles", "--out", &out]);
        assert!(
            err.contains(&format!("monotonic.csv:{line}")),
            "{what}: {err}"
        );
        let err = run_err(args![
            "simulate",
            &set,
            "--params",
            &set.join("experiment.json"),
            "--out",
            &out
        ]);
        assert!(
            err.contains(&format!("monotonic.csv:{line}")),
            "{what}: {err}"
        );
        assert!(!out.exists(), "{what}: output written despite the error");
    }
}

#[test]
fn a_missing_sample_is_a_gap_every_command_reads_and_says() {
    // A logger's NaN is no error: the row is left out, and check and fit say which line.
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-medium", tmp.path());
    let csv = set.join("monotonic.csv");
    let before = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(
        before.lines().nth(6).unwrap().split(',').next(),
        Some("0.240")
    );
    replace_line(&csv, 7, "0.240,0.00400,NaN");
    let (out, err) = subfric!().ok_both(args!["check", &set]);
    assert_mentions(&out, &["monotonic"]);
    assert_mentions(
        &err,
        &[
            "monotonic.csv",
            "shear_kpa",
            "1 row without a value",
            "line 7",
        ],
    );
    let (_, err) = subfric!().ok_both(args![
        "fit",
        &set,
        "--no-profiles",
        "--out",
        &tmp.path().join("fit"),
        "--progress",
        "never"
    ]);
    assert_mentions(&err, &["monotonic.csv", "read as gap", "line 7"]);
}

#[test]
fn invalid_parameter_files_are_errors_naming_every_bad_field() {
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table1-medium");
    let params = tmp.path().join("params.json");
    let out = tmp.path().join("out");
    // μ_k above μ_s and a negative κ: both reported in one message.
    std::fs::write(
        &params,
        r#"{"mu_s": 0.3, "mu_k": 0.5, "kappa": -1, "xi": 0.01, "u_tilde": 10, "alpha_t": 100}"#,
    )
    .unwrap();
    for a in [
        args!["simulate", &set, "--params", &params, "--out", &out].to_vec(),
        args!["plot", &set, "--params", &params, "--out", &out].to_vec(),
    ] {
        let err = run_err(&a);
        let first = err.lines().next().unwrap();
        assert_mentions(first, &["params.json", "mu_k", "kappa", "expected"]);
    }
    assert!(!out.exists());

    // Not JSON: the line and column of the mistake.
    std::fs::write(&params, "{\"mu_s\": 0.3,\n  \"mu_k\": }").unwrap();
    let err = run_err(args!["simulate", &set, "--params", &params, "--out", &out]);
    assert_mentions(&err, &["params.json:2:11", "JSON", "expected"]);

    // A missing and a mistyped field.
    std::fs::write(
        &params,
        r#"{"mu_s": 0.3, "mu_k": 0.1, "kappa": 1, "xi": 0.01, "u_tilde": 10}"#,
    )
    .unwrap();
    let err = run_err(args!["simulate", &set, "--params", &params, "--out", &out]);
    assert_mentions(&err, &["params.json", "alpha_t", "missing", "expected"]);
    std::fs::write(
        &params,
        r#"{"mu_s": "high", "mu_k": 0.1, "kappa": 1, "xi": 0.01, "u_tilde": 10, "alpha_t": 1}"#,
    )
    .unwrap();
    let err = run_err(args!["simulate", &set, "--params", &params, "--out", &out]);
    assert_mentions(&err, &["params.json", "mu_s", "high", "expected a number"]);
    let absent = tmp.path().join("absent.json");
    let err = run_err(args!["simulate", &set, "--params", &absent, "--out", &out]);
    assert_mentions(&err, &["absent.json"]);
    assert!(!out.exists());
}

#[test]
fn bad_fit_options_are_errors_that_say_what_is_expected() {
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table1-medium");
    let out = tmp.path().join("out");
    let fit = |extra: &[&str]| {
        let mut a: Vec<std::ffi::OsString> = vec!["fit".into(), set.clone().into()];
        a.extend(extra.iter().map(|s| s.into()));
        a.extend(["--no-profiles".into(), "--out".into(), out.clone().into()]);
        a
    };
    // Malformed option values: usage errors (exit code 2) naming the flag, before anything runs.
    let usage: [(&[&str], &[&str]); 6] = [
        (
            &["--free", "nonsense"],
            &["--free", "nonsense", "expected one of", "mu_s", "u_tilde"],
        ),
        (&["--free", "mu_s,bogus"], &["--free", "bogus", "mu_s"]),
        (
            &["--fix", "kappa=abc"],
            &["--fix", "kappa", "abc", "not a number"],
        ),
        (&["--fix", "kappa"], &["--fix", "kappa", "key=value"]),
        (
            &["--bounds", "mu_s=0.5:0.1"],
            &["--bounds", "mu_s", "lower bound"],
        ),
        (
            &["--weight", "monotonic=-1"],
            &["--weight", "monotonic", "> 0"],
        ),
    ];
    for (extra, words) in usage {
        let a = fit(extra);
        let err = subfric!().usage_err(&a.iter().map(|s| s.as_os_str()).collect::<Vec<_>>());
        assert_mentions(&err, words);
    }
    // Values that parse but do not fit the set or the model: errors (exit code 1).
    let cases: [(&[&str], &[&str]); 4] = [
        (
            &["--fix", "mu_k=0.9"],
            &["--fix", "mu_k", "0.9", "expected"],
        ),
        (&["--tests", "nope"], &["--tests", "nope", "monotonic"]),
        (&["--weight", "nope=2"], &["--weight", "nope", "monotonic"]),
        (&["--fix", "alpha_t=1e15"], &["alpha_t", "1e15", "expected"]),
    ];
    for (extra, words) in cases {
        let a = fit(extra);
        let err = run_err(&a.iter().map(|s| s.as_os_str()).collect::<Vec<_>>());
        assert_mentions(&err, words);
    }
    assert!(!out.exists(), "a rejected fit wrote output");
}

#[test]
fn import_keeps_the_stretch_asked_and_refuses_a_keep_it_cannot_read() {
    let tmp = tempfile::tempdir().unwrap();
    let lab = tmp.path().join("box.csv");
    // An aborted first stage before 10 s, then the real one.
    std::fs::write(
        &lab,
        "t,u,tau\n0,0,0\n5,0.02,8\n10,0,0\n20,0.4,30\n30,0.8,32\n",
    )
    .unwrap();
    let import = |set: &str, keep: &str| {
        args![
            "import",
            &lab,
            "--out",
            &tmp.path().join(set),
            "--time",
            "t",
            "--slip",
            "u",
            "--shear",
            "tau",
            "--normal-stress",
            "100",
            "--keep",
            keep
        ]
        .iter()
        .map(|a| a.to_os_string())
        .collect::<Vec<_>>()
    };
    fn as_args(v: &[std::ffi::OsString]) -> Vec<&OsStr> {
        v.iter().map(|a| a.as_os_str()).collect()
    }
    subfric!().ok(&as_args(&import("kept", "time=10:")));
    let csv = std::fs::read_to_string(tmp.path().join("kept/test.csv")).unwrap();
    assert_mentions(
        &csv,
        &[
            "trimmed as asked (--keep time=10:): 3 of 5 rows kept",
            "lines 2–3",
        ],
    );
    // A form the flag cannot read is a usage error saying the form; nothing is written.
    let err = subfric!().usage_err(&as_args(&import("bad", "force=1:2")));
    assert_mentions(&err, &["--keep", "unknown column `force`", "time=FROM:TO"]);
    assert!(!tmp.path().join("bad").exists());
    // A stretch the record never reaches is an error naming the column; nothing is written.
    let err = run_err(&as_args(&import("never", "time=100:")));
    assert_mentions(&err, &["box.csv", "time_s", "keeps no row"]);
    assert!(!tmp.path().join("never").exists());
}

#[test]
fn import_with_a_missing_column_names_file_line_and_column() {
    let tmp = tempfile::tempdir().unwrap();
    let lab = tmp.path().join("lab.tsv");
    std::fs::write(
        &lab,
        "t_min\tslip_um\tshear_MPa\n0\t0\t0.001\n1\t10\t0.002\n2\t20\t0.003\n",
    )
    .unwrap();
    let out = tmp.path().join("set");
    let err = run_err(args![
        "import",
        &lab,
        "--out",
        &out,
        "--time",
        "t_min",
        "--time-unit",
        "min",
        "--slip",
        "displacement",
        "--shear",
        "shear_MPa",
        "--shear-unit",
        "MPa",
        "--normal-stress",
        "100"
    ]);
    assert_mentions(
        &err,
        &["lab.tsv:1", "slip", "displacement", "expected", "slip_um"],
    );
    // Without --shear the default column shear_kpa is looked for and reported missing.
    let err = run_err(args![
        "import",
        &lab,
        "--out",
        &out,
        "--time",
        "t_min",
        "--slip",
        "slip_um",
        "--normal-stress",
        "100"
    ]);
    assert_mentions(&err, &["lab.tsv:1", "shear", "shear_kpa", "expected"]);
    // No normal stress at all.
    let err = run_err(args![
        "import",
        &lab,
        "--out",
        &out,
        "--time",
        "t_min",
        "--slip",
        "slip_um",
        "--shear",
        "shear_MPa"
    ]);
    assert_mentions(&err, &["lab.tsv", "normal", "expected"]);
    // An unknown unit: a usage error listing the units.
    let err = subfric!().usage_err(args![
        "import",
        &lab,
        "--out",
        &out,
        "--time",
        "t_min",
        "--time-unit",
        "fortnight",
        "--slip",
        "slip_um",
        "--shear",
        "shear_MPa",
        "--normal-stress",
        "100"
    ]);
    assert_mentions(
        &err,
        &["--time-unit", "fortnight", "possible values", "min"],
    );
    assert!(!out.exists(), "a failed import wrote a set");
}

#[test]
fn import_reads_quoted_cells_with_the_delimiter_given_and_refuses_an_unknown_one() {
    let tmp = tempfile::tempdir().unwrap();
    let lab = tmp.path().join("lab.csv");
    // A spreadsheet's export: BOM, CRLF, `;` between cells, quoted names holding `;` and `,`,
    // decimal commas.
    std::fs::write(
        &lab,
        "\u{feff}\"time; s\";\"slip, mm\";\"shear, kPa\"\r\n0;0;0\r\n1;0,05;12,5\r\n2;0,1;\"20,25\"\r\n",
    )
    .unwrap();
    let out = tmp.path().join("set");
    let import = |delimiter: &str| {
        subfric!().run(args![
            "import",
            &lab,
            "--out",
            &out,
            "--delimiter",
            delimiter,
            "--time",
            "time; s",
            "--slip",
            "slip, mm",
            "--shear",
            "shear, kPa",
            "--normal-stress",
            "100"
        ])
    };
    // An unknown delimiter is a usage error naming the flag and the values it takes.
    let o = import("pipe");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_mentions(&err, &["--delimiter", "pipe", "semicolon", "tab"]);
    assert!(!out.exists(), "a refused import wrote a set");
    let o = import(";");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("test.csv")).unwrap();
    assert!(
        csv.ends_with("time_s,slip_mm,shear_kpa\n0,0,0\n1,0.05,12.5\n2,0.1,20.25\n"),
        "{csv}"
    );
}

#[test]
fn unknown_candidate_forms_and_unlisted_with_sets_are_usage_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table1-medium");
    let out = tmp.path().join("out");
    let err = subfric!().usage_err(args![
        "diagnose",
        &set,
        "--without-form",
        "log time",
        "--out",
        &out
    ]);
    // The message lists the names the flag takes, so the user can copy one.
    assert_mentions(
        &err,
        &[
            "--without-form",
            "log time",
            "no candidate form",
            "log time, b ln(1 + t/t_c) at rest",
            "rate and state, slip law",
        ],
    );
    let err = subfric!().usage_err(args!["selfcheck", "--unlisted", "--sets", &set]);
    assert_mentions(&err, &["--unlisted", "--sets"]);
    // An unknown registered family: the names the flag takes.
    let err = subfric!().usage_err(args![
        "diagnose",
        &set,
        "--with-family",
        "wear",
        "--out",
        &out
    ]);
    assert_mentions(
        &err,
        &["--with-family", "unknown family `wear`", "time-trend"],
    );
    // No diagnosis at all, or more than the cap: the range the flag takes.
    for n in ["0", "65", "two"] {
        let err = subfric!().usage_err(args!["diagnose", &set, "--replicates", n, "--out", &out]);
        assert_mentions(
            &err,
            &["--replicates", "from 1", "to 64", &format!("`{n}`")],
        );
    }
    assert!(!out.exists(), "a rejected diagnosis wrote output");
}

#[test]
fn a_registered_family_in_a_parameter_file_is_checked_like_every_extension() {
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table1-medium");
    let params = tmp.path().join("params.json");
    let out = tmp.path().join("out");
    let model = |term: &str| {
        format!(
            r#"{{"params": {{"mu_s": 0.45, "mu_k": 0.3, "kappa": 1.2, "xi": 0.003,
            "u_tilde": 15, "alpha_t": 1000}}, "ext": {{"term": {term}}}}}"#
        )
    };
    for (term, says) in [
        (
            r#"{"family": "wear", "c": 1}"#,
            &["unknown family `wear`", "time-trend"][..],
        ),
        (
            r#"{"family": "time-trend", "form": "cubic"}"#,
            &["unknown form", "linear", "saturating"][..],
        ),
        (
            r#"{"family": "time-trend", "form": "saturating", "delta": 0.1, "t_s": -5}"#,
            &["time_trend.t_s", "-5", "expected a finite time > 0"][..],
        ),
        (
            r#"{"family": "time-trend", "form": "linear", "c": 1e-5, "t_s": 10}"#,
            &["t_s"][..],
        ),
    ] {
        std::fs::write(&params, model(term)).unwrap();
        let err = run_err(args!["simulate", &set, "--params", &params, "--out", &out]);
        let mut want = vec!["params.json"];
        want.extend_from_slice(says);
        assert_mentions(&err, &want);
        assert!(!out.exists(), "{term}: a refused model wrote output");
    }
    // A valid one simulates.
    std::fs::write(
        &params,
        model(r#"{"family": "time-trend", "form": "linear", "c": 1e-5}"#),
    )
    .unwrap();
    subfric!().ok(args!["simulate", &set, "--params", &params, "--out", &out]);
    assert!(out.join("experiment.json").exists());
}
