//! Trust, round two: two commands writing one folder, interrupted writes, figures that never
//! overwrite each other, a set given twice.

use super::*;

// 2. two commands writing one folder -----------------------------------------------------------

#[test]
fn two_fits_into_one_new_folder_never_both_succeed_nor_mix_their_results() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let a = named_copy(&tmp.path().join("a"), "set-a");
    let b = named_copy(&tmp.path().join("b"), "set-b");
    for round in 0..6 {
        let out = tmp.path().join(format!("out{round}"));
        let spawn = |set: &Path| {
            let mut args = quick_fit(&[set], &[OsStr::new("--out")]);
            args.push(out.clone().into());
            s.command(&os(&args))
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        };
        let (ca, cb) = (spawn(&a), spawn(&b));
        let (oa, ob) = (
            ca.wait_with_output().unwrap(),
            cb.wait_with_output().unwrap(),
        );
        let ok: Vec<&Output> = [&oa, &ob]
            .into_iter()
            .filter(|o| o.status.success())
            .collect();
        assert_eq!(
            ok.len(),
            1,
            "round {round}: {} of the two fits succeeded\n{}\n{}",
            ok.len(),
            text(&oa.stderr),
            text(&ob.stderr)
        );
        let refused = if oa.status.success() { &ob } else { &oa };
        let err = text(&refused.stderr);
        assert_eq!(refused.status.code(), Some(1), "{err}");
        assert!(
            err.contains(&out.display().to_string())
                && (err.contains("is being written by another subfric command (process ")
                    || err.contains(
                        "is being written by another subfric command (a process just starting)"
                    )
                    || err.contains("holds the results of")),
            "{err}"
        );
        // The result and the record are of the same set.
        let set = read_json(&out.join("fit.json"))["set"]
            .as_str()
            .unwrap()
            .to_string();
        let record = std::fs::read_to_string(out.join(".subfric-source")).unwrap();
        let folder = if set == "set-a" {
            "a/table1-medium"
        } else {
            "b/table1-medium"
        };
        assert!(
            record.contains(folder),
            "fit.json of {set}, record:\n{record}"
        );
        assert!(!out.join(".subfric-lock").exists());
    }
}

#[test]
fn a_folder_being_written_is_refused_naming_the_process_that_writes_it() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let a = named_copy(&tmp.path().join("a"), "set-a");
    let out = tmp.path().join("out");
    let mut long = quick_fit(&[&a], &[OsStr::new("--out"), out.as_os_str()]);
    long[3] = "20000".into(); // --global-evals: a second or more of work
    let first = s
        .command(&os(&long))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !out.join(".subfric-lock").exists() {
        assert!(t0.elapsed() < Duration::from_secs(20), "no lock taken");
        std::thread::sleep(Duration::from_millis(5));
    }
    let mut second = quick_fit(&[&a], &[OsStr::new("--out")]);
    second.push(out.clone().into());
    let err = s.err(&os(&second));
    assert_mentions(
        &err,
        &[
            &out.display().to_string(),
            &format!(
                "is being written by another subfric command (process {})",
                first.id()
            ),
        ],
    );
    let o = first.wait_with_output().unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(!out.join(".subfric-lock").exists());
}

// 3. interrupted writes ---------------------------------------------------------------------------

/// Runs the program under a file-size limit of `blocks` × 512 bytes: writing a larger file
/// kills it (SIGXFSZ), or (`ignore_signal`) fails with EFBIG as on a full disk.
fn run_with_file_limit(exe: &Path, a: &[&OsStr], blocks: u32, ignore_signal: bool) -> Output {
    let script = format!(
        "{}ulimit -f {blocks} && exec \"$0\" \"$@\"",
        if ignore_signal { "trap '' XFSZ; " } else { "" }
    );
    Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(exe)
        .args(a)
        .output()
        .expect("sh runs")
}

#[cfg(unix)]
#[test]
fn a_diagnosis_stopped_while_writing_is_finished_by_the_same_command() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-medium", tmp.path());
    // A limit just above the size diagnosis.json takes on this set: it is written, a larger
    // file after it (the HTML report, about 60 kB) is not. Read off an uninterrupted run, as
    // the file grows with the candidate forms the diagnosis lists.
    let reference = tmp.path().join("reference");
    s.ok(args!["diagnose", &set, "--out", &reference]);
    let json_bytes = std::fs::metadata(reference.join("diagnosis.json"))
        .unwrap()
        .len();
    let blocks = json_bytes / 512 + 2;
    let largest = std::fs::metadata(reference.join("report.html"))
        .unwrap()
        .len();
    assert!(
        largest > 2 * blocks * 512,
        "the report ({largest} bytes) must outgrow the limit ({blocks} blocks)"
    );
    for (k, ignore_signal) in [(0, false), (1, true)] {
        let out = tmp.path().join(format!("diag{k}"));
        let a = args!["diagnose", &set, "--out", &out];
        let o = run_with_file_limit(s.exe(), a, blocks as u32, ignore_signal);
        assert_no_panic(&text(&o.stderr), a);
        assert!(!o.status.success(), "the limit did not stop the write");
        assert!(out.join("diagnosis.json").is_file(), "{}", text(&o.stderr));
        // The same command finishes the job, without --force, and leaves no temporary file.
        let (stdout, _) = s.ok_both(a);
        assert!(stdout.contains("wrote"), "{stdout}");
        for dir in [out.clone(), out.join("figures")] {
            let left: Vec<String> = names_in(&dir)
                .into_iter()
                .filter(|n| n.contains("subfric-tmp") || n == ".subfric-lock")
                .collect();
            assert!(left.is_empty(), "{}: {left:?}", dir.display());
        }
    }
}

#[test]
fn a_name_no_file_system_takes_is_refused_by_check_at_its_line() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-medium", tmp.path());
    let long = "t".repeat(300);
    edit_meta(&set, |m| m["tests"][0]["name"] = long.clone().into());
    let err = s.err(args!["check", &set]);
    let json = set.join("experiment.json");
    let line = line_of(&json, &long);
    assert_mentions(
        &err,
        &[
            &format!("experiment.json:{line}: field `tests[0].name`"),
            "300 bytes",
            "255",
        ],
    );
    let err = s.err(args!["diagnose", &set, "--out", &tmp.path().join("d")]);
    assert_mentions(&err, &["tests[0].name", "255"]);
    assert!(!tmp.path().join("d").exists());
    // The set's name likewise.
    edit_meta(&set, |m| {
        m["tests"][0]["name"] = "monotonic".into();
        m["name"] = "s".repeat(256).into();
    });
    let err = s.err(args!["check", &set]);
    assert_mentions(&err, &["field `name`", "256 bytes"]);
}

// 4. figures ---------------------------------------------------------------------------------------

#[test]
fn figures_of_names_a_file_name_cannot_tell_apart_never_overwrite_each_other() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-medium", tmp.path());
    let names = ["x y", "x_y", "a/b", "a_b", "é", "_", "M", "m"];
    let csv = std::fs::read_to_string(set.join("monotonic.csv")).unwrap();
    std::fs::remove_file(set.join("monotonic.csv")).unwrap();
    let mut tests = Vec::new();
    for (i, n) in names.iter().enumerate() {
        // Each test its own record (the same rows twice are refused): a last row of its own.
        let csv = format!("{csv}{},3.01,{}\n", 181 + i, 20.0 + i as f64);
        std::fs::write(set.join(format!("t{i}.csv")), &csv).unwrap();
        tests.push(serde_json::json!({"name": n, "file": format!("t{i}.csv"), "control": "slip", "normal_stress_kpa": 78.4}));
    }
    edit_meta(&set, |m| m["tests"] = tests.into());
    let out = tmp.path().join("plots");
    let stdout = s.ok(args!["plot", &set, "--out", &out]);
    let wrote: Vec<&str> = stdout.lines().filter(|l| l.starts_with("wrote")).collect();
    let mut unique = wrote.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), names.len(), "{stdout}");
    let pngs = names_in(&out)
        .into_iter()
        .filter(|n| n.ends_with(".png"))
        .count();
    assert_eq!(pngs, names.len(), "{:?}", names_in(&out));
    // Readable where the name is a file name already.
    assert!(out.join("x_y.png").is_file() && out.join("_.png").is_file());
    // The diagnosis draws one figure per test too.
    let out = tmp.path().join("diagnosis");
    let stdout = s.ok(args!["diagnose", &set, "--out", &out]);
    let wrote: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("wrote") && l.contains("figures"))
        .collect();
    let mut unique = wrote.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), wrote.len(), "{stdout}");
    // A PNG per test, each with its SVG beside it.
    let figures = names_in(&out.join("figures"));
    for ext in [".png", ".svg"] {
        let n = figures.iter().filter(|f| f.ends_with(ext)).count();
        assert_eq!(n, names.len(), "{ext}: {figures:?}");
    }
}

// 5. a set given twice --------------------------------------------------------------------------

#[test]
fn a_set_given_twice_is_refused_however_it_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    let s = subfric!().cwd(tmp.path());
    copy_set("table1-medium", tmp.path());
    #[cfg(unix)]
    std::os::unix::fs::symlink(tmp.path().join("table1-medium"), tmp.path().join("alias")).unwrap();
    let mut pairs = vec![
        ("table1-medium", "table1-medium"),
        ("./table1-medium", "table1-medium/"),
    ];
    if cfg!(unix) {
        pairs.push(("table1-medium", "alias"));
    }
    for (x, y) in pairs {
        let mut a = quick_fit(&[Path::new(x), Path::new(y)], &[OsStr::new("--out")]);
        a.push("out".into());
        let err = s.err(&os(&a));
        assert_mentions(&err, &[x, y, "given twice", "√2"]);
        assert!(!tmp.path().join("out").exists());
    }
}
