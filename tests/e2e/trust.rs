//! Trust under bad input (issue 13): no panic, no silent overwrite, no write outside the output
//! folder, no half-written file, no silently wrong number. One test per case of the issue; each
//! builds its own input in a temporary folder.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use subfric_e2e::{
    args, assert_mentions, assert_no_panic, copy_set, experiments, read_data_csv, read_json,
    snapshot, subfric, text, write_small_set,
};

/// A fit small enough for a test.
const QUICK: [&str; 5] = ["--global-evals", "100", "--starts", "2", "--no-profiles"];

fn quick_fit(set: &Path, extra: &[&str]) -> Vec<std::ffi::OsString> {
    let mut a: Vec<std::ffi::OsString> = vec!["fit".into(), set.into()];
    a.extend(QUICK.iter().map(|s| s.into()));
    a.extend(extra.iter().map(|s| s.into()));
    a
}

fn os(v: &[std::ffi::OsString]) -> Vec<&OsStr> {
    v.iter().map(|s| s.as_os_str()).collect()
}

/// Files directly in `dir`, sorted.
fn names_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

/// Runs the program under `sh` with a file-size limit of one block, so that writing any file
/// longer than that fails: killed by SIGXFSZ, or (`ignore_signal`) with an EFBIG error, as on a
/// full disk.
fn run_with_tiny_file_limit(exe: &Path, args: &[&OsStr], ignore_signal: bool) -> Output {
    let script = if ignore_signal {
        "trap '' XFSZ; ulimit -f 1 && exec \"$0\" \"$@\""
    } else {
        "ulimit -f 1 && exec \"$0\" \"$@\""
    };
    Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(exe)
        .args(args)
        .output()
        .expect("sh runs")
}

// 1. simulate --out -----------------------------------------------------------------------------

#[test]
fn simulate_never_replaces_the_set_it_reads_and_another_set_only_with_force() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let x = copy_set("table1-medium", tmp.path());
    let params = tmp.path().join("params.json");
    std::fs::copy(x.join("experiment.json"), &params).unwrap();
    let before = snapshot(&x);
    for force in [false, true] {
        let mut a = vec![
            OsStr::new("simulate"),
            x.as_os_str(),
            OsStr::new("--params"),
            params.as_os_str(),
            OsStr::new("--out"),
            x.as_os_str(),
        ];
        if force {
            a.push(OsStr::new("--force"));
        }
        let err = s.err(&a);
        assert_mentions(&err, &["is the set being simulated", "measured data"]);
    }
    // The same folder under another name is still the same set.
    #[cfg(unix)]
    {
        let link = tmp.path().join("link");
        std::os::unix::fs::symlink(&x, &link).unwrap();
        let err = s.err(args!["simulate", &x, "--params", &params, "--out", &link]);
        assert_mentions(&err, &["is the set being simulated"]);
    }
    assert!(snapshot(&x) == before, "the input set was modified");

    // Another set: refused without --force, replaced whole with it (no orphaned CSV).
    let other = copy_set("table4-two-way", tmp.path());
    let other_before = snapshot(&other);
    let err = s.err(args!["simulate", &x, "--params", &params, "--out", &other]);
    assert_mentions(&err, &["already holds a set", "--force"]);
    assert!(snapshot(&other) == other_before);
    let (_, stderr) = s.ok_both(args![
        "simulate", &x, "--params", &params, "--out", &other, "--force"
    ]);
    assert_mentions(&stderr, &["removed", "two-way-cyclic.csv"]);
    assert_eq!(names_in(&other), ["experiment.json", "monotonic.csv"]);
    s.ok(args!["check", &other]);
}

// 2. negative bounds ----------------------------------------------------------------------------

#[test]
fn bounds_outside_a_parameters_domain_are_refused_naming_flag_and_parameter() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table1-medium");
    let out = tmp.path().join("out");
    for (b, expected) in [
        ("kappa=-5:-1", "> 0"),
        ("u_tilde=-1:100", "> 0"),
        ("xi=-1:1", "> 0"),
        ("mu_s=-1:0.1", "> 0"),
        ("alpha_t=-3:5", "> 0"),
        ("mu_k=-0.1:0.2", ">= 0"),
        ("kappa=0:10", "> 0"),
        ("kappa=nan:10", "not a finite number"),
    ] {
        let name = b.split('=').next().unwrap();
        let a = quick_fit(
            &set,
            &[
                "--free",
                "mu_s,kappa,u_tilde,xi,alpha_t",
                "--bounds",
                b,
                "--out",
            ],
        );
        let mut a = os(&a);
        a.push(out.as_os_str());
        let err = s.usage_err(&a);
        assert_mentions(&err, &["--bounds", name, expected]);
    }
    // A bound on a parameter that is not free would do nothing: refused.
    let err = s.err(args![
        "fit",
        &set,
        "--free",
        "mu_s,u_tilde",
        "--bounds",
        "kappa=1:2",
        "--out",
        &out
    ]);
    assert_mentions(&err, &["--bounds", "kappa", "not free"]);
    assert!(!out.exists());
}

// 3. output paths from the set's name -------------------------------------------------------------

#[test]
fn set_names_never_lead_out_of_fits_and_a_copy_does_not_replace_the_originals_fit() {
    let tmp = tempfile::tempdir().unwrap();
    let work = tmp.path().join("work");
    std::fs::create_dir_all(&work).unwrap();
    let s = subfric!().cwd(&work);
    let absolute = tmp.path().join("abs-victim");
    let names = [
        "../../victim".to_string(),
        absolute.display().to_string(),
        "a/../../b".to_string(),
    ];
    for (i, name) in names.iter().enumerate() {
        let set = copy_set("table1-medium", &tmp.path().join(format!("sets{i}")));
        let json = set.join("experiment.json");
        let mut meta = read_json(&json);
        meta["name"] = name.clone().into();
        std::fs::write(&json, meta.to_string()).unwrap();
        let outside_before: Vec<PathBuf> = snapshot(tmp.path())
            .into_iter()
            .map(|(p, _)| p)
            .filter(|p| !p.starts_with("work/fits"))
            .collect();
        let stdout = s.ok(&os(&quick_fit(&set, &[])));
        assert!(stdout.contains("wrote fits/"), "{stdout}");
        let stdout = s.ok(args!["plot", &set]);
        assert!(stdout.contains("wrote fits/"), "{stdout}");
        let outside_after: Vec<PathBuf> = snapshot(tmp.path())
            .into_iter()
            .map(|(p, _)| p)
            .filter(|p| !p.starts_with("work/fits"))
            .collect();
        assert_eq!(outside_before, outside_after, "{name}: wrote outside fits/");
    }
    assert!(!absolute.exists());
    assert!(!tmp.path().join("victim").exists() && !tmp.path().join("b").exists());

    // A copy of a set keeps its name: its fit does not replace the original's.
    let original = copy_set("table1-medium", &tmp.path().join("original"));
    let copy = copy_set("table1-medium", &tmp.path().join("copy"));
    s.ok(&os(&quick_fit(&original, &[])));
    let fit_json = work.join("fits/table1-medium/fit.json");
    let before = std::fs::read(&fit_json).unwrap();
    let err = s.err(&os(&quick_fit(&copy, &["--seed", "2"])));
    assert_mentions(&err, &["holds the results of", "original", "--force"]);
    assert!(std::fs::read(&fit_json).unwrap() == before);
    // The same set may be refitted; the copy only with --force.
    s.ok(&os(&quick_fit(&original, &["--seed", "2"])));
    s.ok(&os(&quick_fit(&copy, &["--force"])));
}

// 4. atomic writes ----------------------------------------------------------------------------------

#[cfg(unix)]
#[test]
fn a_write_that_fails_or_is_killed_leaves_the_previous_fit_json_whole() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table1-medium");
    let out = tmp.path().join("out");
    let mut a = quick_fit(&set, &["--out"]);
    a.push(out.clone().into());
    s.ok(&os(&a));
    let fit_json = out.join("fit.json");
    let before = std::fs::read(&fit_json).unwrap();
    assert!(before.len() > 1024);
    a.extend(["--seed".into(), "3".into()]);
    // Killed while writing (SIGXFSZ at the file-size limit).
    let o = run_with_tiny_file_limit(s.exe(), &os(&a), false);
    assert!(!o.status.success(), "the limit did not stop the write");
    assert!(
        std::fs::read(&fit_json).unwrap() == before,
        "fit.json was damaged by a kill"
    );
    serde_json::from_slice::<serde_json::Value>(&std::fs::read(&fit_json).unwrap()).unwrap();
    // A kill leaves its temporary file (hidden, ignored by git); clear it for the next check.
    for n in names_in(&out).iter().filter(|n| n.contains("subfric-tmp")) {
        std::fs::remove_file(out.join(n)).unwrap();
    }
    // The write fails (EFBIG, as a full disk's ENOSPC): an error naming the file, nothing left.
    let o = run_with_tiny_file_limit(s.exe(), &os(&a), true);
    let err = text(&o.stderr);
    assert_no_panic(&err, &os(&a));
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_mentions(&err, &["error:", "fit.json"]);
    assert!(
        std::fs::read(&fit_json).unwrap() == before,
        "fit.json was damaged by a failed write"
    );
    let left: Vec<String> = names_in(&out)
        .into_iter()
        .filter(|n| n.contains("subfric-tmp"))
        .collect();
    assert!(
        left.is_empty(),
        "temporary files left by a failed write: {left:?}"
    );
}

// 5. scenario size ---------------------------------------------------------------------------------

#[test]
fn a_scenario_too_large_is_refused_at_once_with_its_row_count() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let params = experiments().join("table1-medium/experiment.json");
    let sc = tmp.path().join("sc.json");
    let out = tmp.path().join("out");
    let scenario = |dt: &str, stages: &str| {
        format!(
            r#"{{"name": "long", "control": "slip", "normal_stress_kpa": 100, "dt_s": {dt}, "stages": [{stages}]}}"#
        )
    };
    let t0 = Instant::now();
    std::fs::write(
        &sc,
        scenario(
            "1e-9",
            r#"{"type": "slide", "rate_mm_s": 1, "distance_mm": 1000}"#,
        ),
    )
    .unwrap();
    let err = s.err(args![
        "simulate",
        "--scenario",
        &sc,
        "--params",
        &params,
        "--out",
        &out
    ]);
    assert_mentions(
        &err,
        &["sc.json", "dt_s", "1000000000001 rows", "--max-rows"],
    );
    std::fs::write(
        &sc,
        scenario(
            "1",
            r#"{"type": "cycles", "amplitude_mm": 1, "rate_mm_s": 0.5, "count": 4294967295}"#,
        ),
    )
    .unwrap();
    let err = s.err(args![
        "simulate",
        "--scenario",
        &sc,
        "--params",
        &params,
        "--out",
        &out
    ]);
    assert_mentions(&err, &["rows", "limit"]);
    assert!(
        t0.elapsed() < Duration::from_secs(10),
        "refusing took {:?}",
        t0.elapsed()
    );
    assert!(!out.exists());
    // The limit is a flag: 1001 rows need --max-rows 1001.
    std::fs::write(
        &sc,
        scenario(
            "1",
            r#"{"type": "slide", "rate_mm_s": 0.001, "distance_mm": 1}"#,
        ),
    )
    .unwrap();
    let err = s.err(args![
        "simulate",
        "--scenario",
        &sc,
        "--params",
        &params,
        "--out",
        &out,
        "--max-rows",
        "1000"
    ]);
    assert_mentions(&err, &["1001 rows", "limit of 1000"]);
    s.ok(args![
        "simulate",
        "--scenario",
        &sc,
        "--params",
        &params,
        "--out",
        &out,
        "--max-rows",
        "1001"
    ]);
    let (_, rows) = read_data_csv(&out.join("long.csv"));
    assert_eq!(rows.len(), 1001);
}

// 6. bounds in derived coordinates ---------------------------------------------------------------

#[test]
fn bounds_on_mu_k_kappa_xi_are_honoured_or_refused_with_the_reason() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table1-medium");
    let fit = |extra: &[&str], out: &Path| {
        let mut a = quick_fit(&set, extra);
        a.extend(["--out".into(), out.into()]);
        a
    };
    // μ_k is charted as a share of μ_s: with μ_s free its own bounds cannot be kept.
    let out = tmp.path().join("refused");
    let err = s.err(&os(&fit(&["--bounds", "mu_k=0.1:0.2"], &out)));
    assert_mentions(&err, &["--bounds", "mu_k", "mu_s", "--fix mu_s"]);
    assert!(!out.exists());
    let value = |out: &Path, k: &str| {
        read_json(&out.join("fit.json"))["params"][k]
            .as_f64()
            .unwrap()
    };
    // With μ_s fixed they are kept (the published μ_k = 0.3 lies outside).
    let out = tmp.path().join("mu_k");
    s.ok(&os(&fit(
        &["--fix", "mu_s=0.37", "--bounds", "mu_k=0.1:0.2"],
        &out,
    )));
    let mu_k = value(&out, "mu_k");
    assert!(
        (0.1 * (1.0 - 1e-12)..=0.2 * (1.0 + 1e-12)).contains(&mu_k),
        "mu_k {mu_k}"
    );
    // κ and ξ bounded with the default free set (published κ = 33, ξ = 0.027 outside).
    let out = tmp.path().join("kappa");
    s.ok(&os(&fit(&["--bounds", "kappa=50:60,xi=0.001:0.002"], &out)));
    let (kappa, xi) = (value(&out, "kappa"), value(&out, "xi"));
    // Inside, up to the rounding of exp(ln(bound)).
    let within = |v: f64, lo: f64, hi: f64| v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12);
    assert!(within(kappa, 50.0, 60.0), "kappa {kappa}");
    assert!(within(xi, 0.001, 0.002), "xi {xi}");
}

// 7. silently wrong numbers --------------------------------------------------------------------

#[test]
fn a_stiffness_beyond_float_resolution_is_refused_with_the_reason() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let params = tmp.path().join("params.json");
    std::fs::write(
        &params,
        r#"{"mu_s": 0.37, "mu_k": 0.3, "kappa": 33, "xi": 0.027, "u_tilde": 3000, "alpha_t": 1e15}"#,
    )
    .unwrap();
    let out = tmp.path().join("out");
    let err = s.err(args![
        "simulate",
        &experiments().join("table4-two-way"),
        "--params",
        &params,
        "--out",
        &out
    ]);
    assert_mentions(&err, &["params.json", "alpha_t = 1e15", "floating-point"]);
    assert!(!out.exists());
}

#[test]
fn friction_and_shear_columns_that_disagree_are_an_error_at_their_line() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-medium", tmp.path());
    let csv = set.join("monotonic.csv");
    let normal = read_json(&set.join("experiment.json"))["tests"][0]["normal_stress_kpa"]
        .as_f64()
        .unwrap();
    let (_, rows) = read_data_csv(&csv);
    let mut lines = vec!["time_s,slip_mm,shear_kpa,friction".to_string()];
    for r in &rows {
        lines.push(format!("{},{},{},{:.5}", r[0], r[1], r[2], r[2] / normal));
    }
    // Agreeing within the rounding of the written digits: accepted.
    std::fs::write(&csv, lines.join("\n") + "\n").unwrap();
    s.ok(args!["check", &set]);
    // One row whose friction says something else: an error at its line.
    let r = &rows[100];
    lines[101] = format!("{},{},{},{:.5}", r[0], r[1], r[2], 1.5 * r[2] / normal);
    std::fs::write(&csv, lines.join("\n") + "\n").unwrap();
    let err = s.err(args!["check", &set]);
    assert_mentions(&err, &["monotonic.csv:102", "field `friction`", "agree"]);
}

#[test]
fn implausible_data_are_named_by_check_fit_and_diagnose() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    // The shear written in Pa.
    let pa = copy_set("table1-medium", &tmp.path().join("pa"));
    let csv = pa.join("monotonic.csv");
    let (_, rows) = read_data_csv(&csv);
    let mut t = String::from("time_s,slip_mm,shear_kpa\n");
    for r in &rows {
        t.push_str(&format!("{},{},{}\n", r[0], r[1], r[2] * 1000.0));
    }
    std::fs::write(&csv, t).unwrap();
    let (_, err) = s.ok_both(args!["check", &pa]);
    assert_mentions(
        &err,
        &[
            "warning:",
            "monotonic.csv",
            "shear_kpa",
            "Pa rather than kPa",
        ],
    );
    let out = tmp.path().join("fit");
    let mut a = quick_fit(&pa, &["--out"]);
    a.push(out.into());
    let (_, err) = s.ok_both(&os(&a));
    assert_mentions(&err, &["warning:", "Pa rather than kPa"]);
    let (_, err) = s.ok_both(args!["diagnose", &pa, "--out", &tmp.path().join("diag")]);
    assert_mentions(&err, &["warning:", "Pa rather than kPa"]);
    // A shear of 0 on every row, and a test of one row.
    let zero = tmp.path().join("zero");
    let rows: Vec<[f64; 3]> = (0..50).map(|i| [i as f64, 0.01 * i as f64, 0.0]).collect();
    write_small_set(
        &zero,
        "zero",
        &[
            ("flat", "slip", 100.0, rows),
            ("single", "slip", 100.0, vec![[0.0, 0.0, 10.0]]),
        ],
    );
    let (_, err) = s.ok_both(args!["check", &zero]);
    assert_mentions(
        &err,
        &["flat.csv", "0 on every row", "single.csv", "only 1 row"],
    );
}

// 8. smaller -------------------------------------------------------------------------------------

#[cfg(unix)]
#[test]
fn a_symbolic_link_out_of_the_set_is_refused_without_reading_it() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-medium", tmp.path());
    let secret = tmp.path().join("secret.txt");
    std::fs::write(&secret, "top-secret-first-line,a,b\n1,2,3\n").unwrap();
    std::fs::remove_file(set.join("monotonic.csv")).unwrap();
    std::os::unix::fs::symlink(&secret, set.join("monotonic.csv")).unwrap();
    let err = s.err(args!["check", &set]);
    assert_mentions(
        &err,
        &["monotonic.csv", "symbolic link", "outside the set folder"],
    );
    assert!(
        !err.contains("top-secret"),
        "the link's target was read:\n{err}"
    );
    // A link inside the set is fine.
    std::fs::remove_file(set.join("monotonic.csv")).unwrap();
    std::fs::copy(
        experiments().join("table1-medium/monotonic.csv"),
        set.join("data.csv"),
    )
    .unwrap();
    std::os::unix::fs::symlink("data.csv", set.join("monotonic.csv")).unwrap();
    s.ok(args!["check", &set]);
}

#[cfg(unix)]
#[test]
fn simulate_and_import_replace_symbolic_links_instead_of_writing_through_them() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table1-medium");
    let params = set.join("experiment.json");
    let out = tmp.path().join("out");
    s.ok(args!["simulate", &set, "--params", &params, "--out", &out]);
    let victim = tmp.path().join("victim.csv");
    std::fs::write(&victim, "precious\n").unwrap();
    std::fs::remove_file(out.join("monotonic.csv")).unwrap();
    std::os::unix::fs::symlink(&victim, out.join("monotonic.csv")).unwrap();
    s.ok(args![
        "simulate", &set, "--params", &params, "--out", &out, "--force"
    ]);
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious\n");
    let meta = std::fs::symlink_metadata(out.join("monotonic.csv")).unwrap();
    assert!(meta.file_type().is_file());
    s.ok(args!["check", &out]);

    // import: a dangling link where the new CSV would go is not written through.
    let lab = tmp.path().join("lab.csv");
    std::fs::write(
        &lab,
        "time_s,slip_mm,shear_kpa\n0,0,0\n1,0.01,20\n2,0.02,30\n",
    )
    .unwrap();
    let target = tmp.path().join("created-through-link.csv");
    std::os::unix::fs::symlink(&target, out.join("t.csv")).unwrap();
    let err = s.err(args![
        "import",
        &lab,
        "--out",
        &out,
        "--normal-stress",
        "100",
        "--test-name",
        "t"
    ]);
    assert_mentions(&err, &["t.csv", "already exists"]);
    assert!(!target.exists(), "import wrote through a symbolic link");
}

#[test]
fn plot_says_when_a_fitted_curve_runs_away_instead_of_dropping_it() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table3-pulsating");
    // A friction capacity far below the imposed shear: the model slides away.
    let params = tmp.path().join("params.json");
    std::fs::write(
        &params,
        r#"{"mu_s": 0.05, "mu_k": 0.04, "kappa": 1, "xi": 0.001, "u_tilde": 10, "alpha_t": 1000}"#,
    )
    .unwrap();
    let out = tmp.path().join("plots");
    let (stdout, stderr) = s.ok_both(args!["plot", &set, "--params", &params, "--out", &out]);
    assert!(stdout.contains("wrote"), "{stdout}");
    assert_mentions(
        &stderr,
        &[
            "warning:",
            "pulsating",
            "fitted curve is not drawn",
            "runaway",
        ],
    );
}

#[cfg(unix)]
#[test]
fn a_failed_import_leaves_no_orphan_and_can_be_retried() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let lab = tmp.path().join("lab.csv");
    std::fs::write(
        &lab,
        "time_s,slip_mm,shear_kpa\n0,0,0\n1,0.01,20\n2,0.02,30\n",
    )
    .unwrap();
    let out = tmp.path().join("set");
    // A title too long for the file-size limit: the CSV fits, experiment.json does not.
    let title = "t".repeat(3000);
    let a: Vec<&OsStr> = args![
        "import",
        &lab,
        "--out",
        &out,
        "--normal-stress",
        "100",
        "--test-name",
        "first",
        "--title",
        &title
    ]
    .to_vec();
    let o = run_with_tiny_file_limit(s.exe(), &a, true);
    let err = text(&o.stderr);
    assert_no_panic(&err, &a);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_mentions(&err, &["experiment.json"]);
    let left: Vec<String> = if out.exists() { names_in(&out) } else { vec![] };
    assert!(left.is_empty(), "a failed import left {left:?}");
    s.ok(&a);
    s.ok(args!["check", &out]);
}

#[test]
fn an_os_error_is_printed_once() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let lab = tmp.path().join("lab.csv");
    std::fs::write(&lab, "time_s,slip_mm,shear_kpa\n0,0,0\n1,0.01,20\n").unwrap();
    // The output folder is a file: it cannot be created.
    let out = tmp.path().join("a-file");
    std::fs::write(&out, "").unwrap();
    let err = s.err(args![
        "import",
        &lab,
        "--out",
        &out,
        "--normal-stress",
        "100"
    ]);
    // Said once, as what is there (issue 42: a file, not "File exists (os error 17)").
    assert!(err.matches("os error").count() <= 1, "{err}");
    assert_eq!(err.matches("--out is a file").count(), 1, "{err}");
}

#[cfg(unix)]
#[test]
fn a_folder_or_fifo_in_place_of_a_csv_is_named_for_what_it_is() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-medium", tmp.path());
    let csv = set.join("monotonic.csv");
    std::fs::remove_file(&csv).unwrap();
    std::fs::create_dir(&csv).unwrap();
    let err = s.err(args!["check", &set]);
    assert_mentions(&err, &["monotonic.csv", "is a folder"]);
    assert!(!err.contains("absent"), "{err}");
    std::fs::remove_dir(&csv).unwrap();
    let made = Command::new("mkfifo")
        .arg(&csv)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    // Reading a FIFO would block: the check must not open it.
    let mut child = s
        .command(args!["check", &set])
        .stderr(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed() > Duration::from_secs(20) {
            child.kill().unwrap();
            panic!("check blocked on a FIFO");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let o = child.wait_with_output().unwrap();
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_mentions(&err, &["monotonic.csv", "not a regular file", "FIFO"]);
}

#[test]
fn an_unwritable_output_folder_is_found_before_the_fit() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let blocker = tmp.path().join("a-file");
    std::fs::write(&blocker, "").unwrap();
    let out = blocker.join("fits");
    let o = s.run(args![
        "fit",
        &experiments().join("table1-medium"),
        "--out",
        &out
    ]);
    let err = text(&o.stderr);
    assert_no_panic(&err, &[]);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_mentions(&err, &["a-file", "output folder"]);
    assert!(
        !text(&o.stdout).contains("fit of"),
        "the fit ran before the output folder was checked"
    );
}

#[test]
fn progress_is_shown_on_request_when_stderr_is_not_a_terminal() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let mut a = quick_fit(
        &experiments().join("table1-medium"),
        &["--progress", "always", "--out"],
    );
    a.push(out.into());
    let (_, err) = s.ok_both(&os(&a));
    assert_mentions(
        &err,
        &[
            "progress: reading",
            "progress: global search",
            "least-squares polish",
            "model runs",
        ],
    );
    // By default nothing is drawn on a stderr that is not a terminal.
    let out = tmp.path().join("quiet");
    let mut a = quick_fit(&experiments().join("table1-medium"), &["--out"]);
    a.push(out.into());
    let (_, err) = s.ok_both(&os(&a));
    assert!(!err.contains("progress"), "{err}");
}
