//! A lab user's first hour (issue 21), end to end: every command that fits says first whether
//! the model describes the data and what to do next; undetermined parameters are shown as the
//! bound the data set, never as a fake estimate; `plan` warns on a model that misses, plans on
//! the model the diagnosis chose, and never proposes a test the set holds; `import` takes
//! forces with a contact area and hints at `--skip`; a file given for a set is named as such;
//! each report is one self-contained HTML page holding every figure the job wrote.

use std::path::Path;
use subfric_e2e::html::check_report;
use subfric_e2e::{
    args, assert_mentions, copy_dir, copy_set, golden, read_json, repo, subfric, text,
};

/// The golden lab-style set (four tests, a rate effect the base model lacks), copied.
fn pair_01(tmp: &Path) -> std::path::PathBuf {
    let dest = tmp.join("pair-01");
    copy_dir(&golden().join("pair-01"), &dest);
    dest
}

/// The rows of the parameter table of a fit's terminal report: (name, the rest of the line).
fn parameter_line<'a>(stdout: &'a str, name: &str) -> &'a str {
    stdout
        .lines()
        .find(|l| l.starts_with(name))
        .unwrap_or_else(|| panic!("no row `{name}` in:\n{stdout}"))
}

#[test]
fn fit_says_the_model_describes_the_data_shows_bounds_not_fake_values_and_writes_a_report() {
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-smooth", tmp.path());
    let out = tmp.path().join("fit");
    let stdout = subfric!().ok(args!["fit", &set, "--out", &out]);
    let first: Vec<&str> = stdout.lines().take(2).collect();
    assert!(
        first[0].starts_with("verdict: the model describes these data: misfit 0.9")
            && first[0].contains("× the noise variance"),
        "{stdout}"
    );
    assert!(
        first[1].starts_with("next: `subfric plan ") && first[1].contains("xi"),
        "{stdout}"
    );
    // ξ has an upper bound only: the bound, no value, no difference from the published one.
    let xi = parameter_line(&stdout, "xi [1/s]");
    assert!(xi.contains("not determined (≤ 0.8"), "{xi}");
    assert!(
        !xi.contains('%'),
        "a difference for an undetermined parameter: {xi}"
    );
    let mu_s = parameter_line(&stdout, "mu_s");
    assert!(mu_s.contains("determined") && mu_s.contains('%'), "{mu_s}");
    // "combinations the data determine" lists determined ones only.
    let combos: Vec<&str> = stdout
        .lines()
        .skip_while(|l| !l.starts_with("combinations the data determine"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .collect();
    assert!(!combos.is_empty(), "{stdout}");
    assert!(
        combos.iter().all(|l| !l.contains("not determined")),
        "{combos:?}"
    );
    // One meaning of "× noise": every misfit is a variance ratio, and the legend says so.
    assert!(
        stdout.contains("misfit: the mean square of the residual divided by the noise variance"),
        "{stdout}"
    );
    assert!(!stdout.contains("× noise)"), "{stdout}");
    assert!(stdout.contains("95 % interval [a, b]"), "{stdout}");
    // fit.json says it too, for scripts and the Python package.
    let fit = read_json(&out.join("fit.json"));
    assert_eq!(
        fit["verdict"]["describes_the_data"], true,
        "{}",
        fit["verdict"]
    );
    let xi = fit["report"]["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "xi")
        .unwrap()
        .clone();
    assert_eq!(xi["status"], "not determined (upper bound only)");
    // The report: one page with the verdict first, the tables, every figure written.
    let page = check_report(&out.join("report.html"), &out);
    assert_eq!(page.images.len(), 1);
    let t = &page.text;
    let verdict = t
        .find("the model describes these data")
        .expect("the verdict");
    let table = t.find("identifiability").expect("the parameter table");
    assert!(verdict < table, "the verdict is not first");
    assert!(t.contains("not determined (≤ "), "bounds in the page");
}

#[test]
fn a_model_that_misses_is_called_so_and_diagnose_is_named_as_the_next_step() {
    let tmp = tempfile::tempdir().unwrap();
    let set = pair_01(tmp.path());
    let out = tmp.path().join("fit");
    let stdout = subfric!().ok(args![
        "fit",
        &set,
        "--out",
        &out,
        "--global-evals",
        "500",
        "--no-profiles"
    ]);
    let first = stdout.lines().next().unwrap();
    assert!(
        first.starts_with("verdict: the model does NOT describe these data: misfit ")
            && first.contains("it misses most in slide-hold-slide / hold"),
        "{stdout}"
    );
    assert!(
        stdout.contains(&format!("next: `subfric diagnose {}`", set.display())),
        "{stdout}"
    );
    let fit = read_json(&out.join("fit.json"));
    assert_eq!(fit["verdict"]["level"], "fails");
    check_report(&out.join("report.html"), &out);
}

#[test]
fn plan_warns_on_a_model_that_misses_and_never_proposes_a_test_the_set_holds() {
    let tmp = tempfile::tempdir().unwrap();
    let set = pair_01(tmp.path());
    let out = tmp.path().join("plan");
    let (stdout, stderr) = subfric!().ok_both(args!["plan", &set, "--out", &out, "--check", "0"]);
    assert!(
        stderr.contains("warning: the base model misses these data by")
            && stderr.contains("subfric diagnose"),
        "{stderr}"
    );
    assert!(
        stdout.starts_with("verdict: the base model does NOT describe these data"),
        "{stdout}"
    );
    assert!(stdout.contains("next: `subfric diagnose"), "{stdout}");
    // The set has a monotonic test at 400 kPa: the monotonic test at twice the rig's 200 kPa
    // is that test again.
    let v = read_json(&out.join("plan.json"));
    let proposed: Vec<&str> = v["plan"]["proposals"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert!(!proposed.contains(&"normal-stress-x2"), "{proposed:?}");
    let rejected = v["plan"]["rejected"].to_string();
    assert!(
        rejected.contains("normal-stress-x2") && rejected.contains("monotonic-400kPa"),
        "{rejected}"
    );
    assert_eq!(v["model"]["verdict"]["describes_the_data"], false);
    // Proposals that narrow nothing come last and are not ranked.
    let narrows: Vec<bool> = v["plan"]["proposals"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["narrows"].as_bool().unwrap())
        .collect();
    assert!(narrows.windows(2).all(|w| w[0] || !w[1]), "{narrows:?}");
    for line in stdout.lines().filter(|l| l.starts_with("—    ")) {
        let name = line.split_whitespace().nth(1).unwrap_or_default();
        let p = v["plan"]["proposals"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == name);
        assert_eq!(
            p.map(|p| p["narrows"].clone()),
            Some(false.into()),
            "{line}"
        );
    }
    check_report(&out.join("report.html"), &out);

    // With a diagnosis that found no effect to close the gap, the plan says the model must
    // change first, what the diagnosis found and the tests that would tell its explanations
    // apart, and names that test as the next step, not a proposal for the base model.
    let diagnosis = tmp.path().join("diagnosis.json");
    let name = read_json(&set.join("experiment.json"))["name"].clone();
    std::fs::write(
        &diagnosis,
        serde_json::json!({
            "set": name,
            "verdict": {
                "effect": "unexplained",
                "effects": ["unexplained"],
                "confidence": 0.41,
                "alternatives": [{
                    "effects": ["log-healing"],
                    "label": "log-healing",
                    "probability": 0.35,
                    "tell_apart": "holds of 10, 100 and 1000 s between slides would tell them apart"
                }]
            },
            "diagnosis": {"verdict": {"effects": []}}
        })
        .to_string(),
    )
    .unwrap();
    let out2 = tmp.path().join("plan2");
    let stdout = subfric!().ok(args![
        "plan",
        &set,
        "--diagnosis",
        &diagnosis,
        "--out",
        &out2,
        "--check",
        "0"
    ]);
    assert_mentions(
        &stdout,
        &[
            "the model must change first",
            "found no effect that explains the gap (how sure: 41 %)",
            "or log-healing (35 %): holds of 10, 100 and 1000 s",
            "next: the test that tells these explanations apart",
        ],
    );
    assert!(!stdout.contains("next: run "), "{stdout}");
}

#[test]
fn diagnose_counts_its_progress_and_plan_then_plans_on_the_model_it_chose() {
    let tmp = tempfile::tempdir().unwrap();
    pair_01(tmp.path());
    let run = subfric!().cwd(tmp.path());
    let (stdout, stderr) = run.ok_both(args!["diagnose", "pair-01", "--progress", "always"]);
    assert!(
        stderr.contains("diagnosis 2/5: screening every candidate form (")
            && stderr.contains("forms fitted)")
            && stderr.contains("diagnosis 5/5"),
        "{stderr}"
    );
    let lines: Vec<&str> = stdout.lines().collect();
    assert!(
        lines[0].starts_with("verdict: the base model does NOT describe these data"),
        "{stdout}"
    );
    assert!(
        lines[1].starts_with("verdict: missing effect: rate"),
        "{stdout}"
    );
    // How sure the verdict is, with a probability, before the next step.
    assert!(
        lines[2].starts_with("how sure: ") && lines[2].contains(" %"),
        "{stdout}"
    );
    assert!(
        lines[3].starts_with("next: `subfric plan pair-01`"),
        "{stdout}"
    );
    let diagnosis = tmp.path().join("fits/pair-01/diagnosis");
    let page = check_report(&diagnosis.join("report.html"), &diagnosis);
    assert!(page.images.len() >= 8, "{} figures", page.images.len());
    // Each stage of the selection ends with its decision, as in the terminal's report.
    let json = read_json(&diagnosis.join("diagnosis.json"));
    let stages = json["diagnosis"]["selection"]
        .as_array()
        .map_or(0, Vec::len);
    assert!(stages > 0);
    let html = std::fs::read_to_string(diagnosis.join("report.html")).unwrap();
    assert_eq!(html.matches("<p>→ ").count(), stages, "{html}");
    // The fit's report draws each test against the same axis as the diagnosis's: time where
    // the test holds, slip elsewhere.
    let fit = tmp.path().join("fit");
    run.ok(args!["fit", "pair-01", "--no-profiles", "--out", &fit]);
    let axis = |svg: &Path| {
        let text = std::fs::read_to_string(svg).unwrap();
        ["time t [s]", "slip u [mm]"]
            .into_iter()
            .filter(|label| text.contains(label))
            .collect::<Vec<_>>()
    };
    for (test, expected) in [
        ("slide-hold-slide", "time t [s]"),
        ("velocity-steps", "slip u [mm]"),
        ("two-way-cyclic", "slip u [mm]"),
        ("monotonic-400kPa", "slip u [mm]"),
    ] {
        let in_fit = axis(&fit.join(format!("{test}.svg")));
        let in_diagnosis = axis(&diagnosis.join("figures").join(format!("{test}.svg")));
        assert_eq!(in_fit, [expected], "{test} in the fit's report");
        assert_eq!(in_diagnosis, [expected], "{test} in the diagnosis's report");
    }

    // plan reads fits/pair-01/diagnosis/diagnosis.json and fits the model with the effect.
    let stdout = run.ok(args!["plan", "pair-01", "--check", "0"]);
    assert!(
        stdout.starts_with("verdict: the model with rate (")
            && stdout.contains("describes these data"),
        "{stdout}"
    );
    assert!(
        stdout.contains("planned on the model with rate"),
        "{stdout}"
    );
    let v = read_json(&tmp.path().join("fits/pair-01/plan/plan.json"));
    let free: Vec<&str> = v["plan"]["free"]
        .as_array()
        .unwrap()
        .iter()
        .map(|k| k.as_str().unwrap())
        .collect();
    assert!(free.iter().any(|k| k.starts_with("rate.")), "{free:?}");
    assert_eq!(v["model"]["verdict"]["describes_the_data"], true);
}

/// A lab export: a header block, then time in minutes, displacement in µm, and the shear force
/// in N on a 60 mm box (3600 mm²) under 400 kPa.
fn lab_export(dir: &Path) -> std::path::PathBuf {
    let mut s = String::from("Specimen: A\nDate: 2024-05-01\nOperator: JK\n");
    s.push_str("Time (min)\tDisp (um)\tShear force (N)\n");
    for i in 0..120 {
        let t = f64::from(i) * 0.05;
        let u = 600.0 * t;
        let tau = 400.0 * 0.6 * (1.0 - (-u / 50.0).exp());
        s.push_str(&format!("{t:.2}\t{u:.2}\t{:.1}\n", tau * 3.6));
    }
    s.push_str("6.00\t4.93\t0.0\n");
    let f = dir.join("export.txt");
    std::fs::write(&f, s).unwrap();
    f
}

#[test]
fn import_takes_forces_with_an_area_hints_at_skip_and_keeps_the_input_precision() {
    let tmp = tempfile::tempdir().unwrap();
    let lab = lab_export(tmp.path());
    let cols = [
        "--time",
        "1",
        "--time-unit",
        "min",
        "--slip",
        "2",
        "--slip-unit",
        "um",
        "--shear",
        "3",
        "--normal-stress",
        "400",
    ];
    let with = |extra: &[&str]| -> Vec<String> {
        let mut v = vec!["import".to_string(), lab.display().to_string()];
        v.extend(cols.iter().map(|s| s.to_string()));
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let os = |v: &[String]| v.iter().map(std::ffi::OsString::from).collect::<Vec<_>>();
    let run = |v: &[String]| {
        let o = os(v);
        let r: Vec<&std::ffi::OsStr> = o.iter().map(|s| s.as_os_str()).collect();
        subfric!().run(&r)
    };
    // The header block: a hint at --skip, first.
    let o = run(&with(&[
        "--out",
        &tmp.path().join("a").display().to_string(),
    ]));
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let hint = err.lines().nth(1).unwrap_or_default();
    assert!(
        hint.contains("line 1 `Specimen: A` is not a number; is it a header block? try --skip 3"),
        "{err}"
    );
    // A force unit needs the area.
    let o = run(&with(&[
        "--skip",
        "3",
        "--shear-unit",
        "N",
        "--out",
        &tmp.path().join("b").display().to_string(),
    ]));
    let err = text(&o.stderr);
    assert!(
        err.contains("force in N") && err.contains("--area"),
        "{err}"
    );
    // Read as kPa, a force in N is implausible beside 400 kPa: a warning says what it may be.
    let o = run(&with(&[
        "--skip",
        "3",
        "--out",
        &tmp.path().join("c").display().to_string(),
    ]));
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("warning:") && err.contains("--shear-unit N --area"),
        "{err}"
    );
    // In N over 3600 mm²: kPa, written with the digits the lab recorded.
    let d = tmp.path().join("d");
    let o = run(&with(&[
        "--skip",
        "3",
        "--shear-unit",
        "N",
        "--area",
        "3600",
        "--out",
        &d.display().to_string(),
    ]));
    let err = text(&o.stderr);
    assert!(o.status.success() && !err.contains("warning"), "{err}");
    let csv = std::fs::read_to_string(d.join("test.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    // 0.05 min = 3 s; 30.00 µm = 0.03 mm; 389.8 N / 3600 mm² = 108.278 kPa.
    assert_eq!(rows[1], vec!["3", "0.03", "108.278"]);
    // 4.93 µm is 0.00493 mm, not 0.0049299999999999995.
    assert_eq!(rows.last().unwrap()[1], "0.00493");
    for r in &rows {
        for c in r {
            assert!(
                c.len() <= 10,
                "a number with more digits than the input: {c}"
            );
        }
    }
}

#[test]
fn check_of_a_file_says_a_set_folder_was_expected_and_progress_is_accepted_everywhere() {
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-medium", tmp.path());
    let err = subfric!().err(args!["check", &set.join("monotonic.csv")]);
    assert!(
        err.contains("this is a file, and a set folder was expected")
            && err.contains("experiment.json and one CSV per test")
            && err.contains(&format!("the set folder {}", set.display())),
        "{err}"
    );
    assert!(!err.contains("Not a directory"), "{err}");
    // --progress is accepted (and harmless) by check, plot and simulate too.
    let stdout = subfric!().ok(args!["check", &set, "--progress", "never"]);
    assert!(
        stdout.contains("mm/s"),
        "the rates say their unit:\n{stdout}"
    );
    subfric!().ok(args![
        "plot",
        &set,
        "--out",
        &tmp.path().join("plots"),
        "--progress",
        "always"
    ]);
    subfric!().ok(args![
        "simulate",
        &set,
        "--params",
        &set.join("experiment.json"),
        "--out",
        &tmp.path().join("sim"),
        "--progress",
        "never"
    ]);
}

#[test]
fn plot_draws_the_fit_of_the_set_when_no_parameters_are_given() {
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-medium", tmp.path());
    let run = subfric!().cwd(tmp.path());
    run.ok(args![
        "fit",
        "table1-medium",
        "--no-profiles",
        "--global-evals",
        "300"
    ]);
    let (_, stderr) = run.ok_both(args!["plot", "table1-medium"]);
    assert!(
        stderr.contains("note: drawing the fit in fits/table1-medium/fit.json"),
        "{stderr}"
    );
    // The fitted curve is in the figure: the residual panel exists only with a model.
    let png = tmp.path().join("fits/table1-medium/plots/monotonic.png");
    assert!(png.is_file());
    let img = subfric_plot::read_rgb(&png).unwrap();
    let red = img
        .pixels()
        .filter(|&(_, _, c)| c == subfric_plot::FITTED_RGB)
        .count();
    assert!(red > 500, "{red} red pixels: the fit is not drawn");
    let _ = set;
}

#[test]
fn the_readme_is_short_and_starts_with_the_two_commands() {
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(lines <= 250, "README.md has {lines} lines");
    let first_block: Vec<&str> = readme
        .split("```")
        .nth(1)
        .expect("a code block")
        .lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .collect();
    assert_eq!(first_block.len(), 2, "{first_block:?}");
    assert!(first_block[0].starts_with("cargo run --release -- reproduce"));
    assert!(first_block[1].starts_with("cargo test --workspace --release"));
    // Every document it links exists.
    for part in readme.split("](").skip(1) {
        let target = part.split(')').next().unwrap();
        if target.starts_with("http") || target.starts_with('#') {
            continue;
        }
        let path = target.split('#').next().unwrap();
        assert!(
            repo().join(path).exists(),
            "README links {target}, which is absent"
        );
    }
    assert!(repo().join("docs/data-format.md").is_file());
}

/// `simulate` on records with a seating toe: the model does not simulate the toe (the test
/// starts at rest after it), so the simulated set leaves those rows out and says so in each
/// file's comment, every column keeping one value per row; the set it writes loads again.
#[test]
fn simulate_leaves_out_a_seating_toe_and_writes_a_set_that_loads() {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let sets = tmp.path().join("generated");
    // Sets of the independent generator with no effect, on each rig and logger profile.
    s.ok(args![
        "selfcheck",
        "--write",
        &sets,
        "--classes",
        "1",
        "--per-class",
        "4",
        "--seed",
        "3"
    ]);
    let params = tmp.path().join("params.json");
    std::fs::write(
        &params,
        r#"{"mu_s": 0.4, "mu_k": 0.3, "kappa": 2.0, "xi": 0.001, "u_tilde": 20.0, "alpha_t": 0.005, "alpha_n": 0.005}"#,
    )
    .unwrap();
    let mut toes = 0;
    for entry in std::fs::read_dir(&sets).unwrap() {
        let set = entry.unwrap().path();
        if !set.is_dir() {
            continue;
        }
        let out = tmp.path().join("simulated").join(set.file_name().unwrap());
        s.ok(args!["simulate", &set, "--params", &params, "--out", &out]);
        s.ok(args!["check", &out]);
        for csv in std::fs::read_dir(&out).unwrap() {
            let csv = csv.unwrap().path();
            if csv.extension().is_none_or(|e| e != "csv") {
                continue;
            }
            let simulated = std::fs::read_to_string(&csv).unwrap();
            let measured = std::fs::read_to_string(set.join(csv.file_name().unwrap())).unwrap();
            let data_rows = |t: &str| {
                t.lines()
                    .filter(|l| l.starts_with(|c: char| c.is_ascii_digit() || c == '-'))
                    .count()
            };
            let comment = simulated.lines().next().unwrap();
            match comment.split("the record's first ").nth(1) {
                Some(rest) => {
                    toes += 1;
                    let cut: usize = rest.split(' ').next().unwrap().parse().unwrap();
                    assert!(comment.contains("seating toe"), "{comment}");
                    assert_eq!(
                        data_rows(&simulated) + cut,
                        data_rows(&measured),
                        "{}: {comment}",
                        csv.display()
                    );
                }
                None => assert_eq!(
                    data_rows(&simulated),
                    data_rows(&measured),
                    "{}",
                    csv.display()
                ),
            }
        }
    }
    assert!(
        toes > 0,
        "the rig and lab profiles put a seating toe on tests loaded from rest"
    );
}

/// A GDS `.ini` export as the apparatus writes it: one `Key="v1,v2,…"` line per channel, the
/// box's area and the rate as single values, stages as a channel (a 7-row aborted shear
/// stage before the real one), no time column.
fn gds_ini(dir: &Path) -> std::path::PathBuf {
    gds_ini_at(dir, "DS-04.ini", 100.0)
}

/// [`gds_ini`] under normal stress `normal_kpa` (the shear force in proportion), as `name`.
fn gds_ini_at(dir: &Path, name: &str, normal_kpa: f64) -> std::path::PathBuf {
    let (mut stage, mut h, mut v, mut f) = (vec![], vec![], vec![], vec![]);
    for i in 0..7 {
        stage.push("1".to_string());
        h.push(format!("{:.3}", 0.01 * f64::from(i)));
        v.push(format!("{:.4}", -0.001 * f64::from(i)));
        f.push(format!("{:.4}", 0.05 * f64::from(i)));
    }
    for i in 0..150 {
        let x = 0.05 * f64::from(i);
        let q_kn = 0.6 * normal_kpa / 1000.0 * 3.6 * (1.0 - (-x / 0.4).exp());
        stage.push("2".to_string());
        h.push(format!("{x:.3}"));
        v.push(format!("{:.4}", 0.3 * (1.0 - (-x / 2.0).exp())));
        f.push(format!("{q_kn:.4}"));
    }
    let n = stage.len();
    let text = format!(
        "[Test Data]\nSpecimen=\"dense sand, mild steel\"\nArea=\"3600\"\nRate of shear displacement=\"0.5\"\nStage Number=\"{}\"\nHorizontal Displacement=\"{}\"\nVertical Displacement=\"{}\"\nShear Force=\"{}\"\nNormal Stress=\"{}\"\n",
        stage.join(","),
        h.join(","),
        v.join(","),
        f.join(","),
        vec![format!("{normal_kpa:.1}"); n].join(",")
    );
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_gds_ini_export_imports_in_one_command_and_says_every_choice() {
    let tmp = tempfile::tempdir().unwrap();
    let lab = gds_ini(tmp.path());
    let set = tmp.path().join("ds");
    // Without a time and with a rate that states no unit, the unit is asked for.
    let err = subfric!().err(args!["import", &lab, "--out", &set]);
    assert_mentions(
        &err,
        &["DS-04.ini:4", "Rate of shear displacement", "--rate-unit"],
    );
    assert!(!set.exists(), "nothing written on refusal");
    let o = subfric!().run(args![
        "import",
        &lab,
        "--out",
        &set,
        "--rate-unit",
        "mm/min",
        "--test-name",
        "ds04"
    ]);
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert_mentions(
        &err,
        &[
            "stage 2 is kept, the one with the longest shear travel",
            "values 1–7",
            "over the stated rate 0.5 mm/min",
            "`Shear Force` in kN",
        ],
    );
    let csv = std::fs::read_to_string(set.join("ds04.csv")).unwrap();
    let header = csv
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap_or_default();
    assert_eq!(
        header,
        "time_s,slip_mm,shear_kpa,normal_disp_mm,shear_force_kn"
    );
    // The set checks and fits like any other.
    subfric!().ok(args!["check", &set]);
    let out = tmp.path().join("fit");
    let o = subfric!().run(args!["fit", &set, "--no-profiles", "--out", &out]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(out.join("fit.json").exists());
    // ... and is diagnosed like any other once a second test, at twice the normal stress, is
    // imported beside it: two tests give pieces to hold out, so the diagnosis decides, and it
    // names nothing whose variable the two tests do not vary (one rate, no holds, no
    // reversals).
    let second = gds_ini_at(tmp.path(), "DS-05.ini", 200.0);
    subfric!().ok(args![
        "import",
        &second,
        "--out",
        &set,
        "--rate-unit",
        "mm/min",
        "--test-name",
        "ds05"
    ]);
    let dout = tmp.path().join("diagnosis");
    let o = subfric!().run(args!["diagnose", &set, "--out", &dout]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let d: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dout.join("diagnosis.json")).unwrap())
            .unwrap();
    let effect = d["verdict"]["effect"].as_str().unwrap_or_default();
    assert_ne!(effect, "cannot-judge", "{}", d["verdict"]);
    let effects: Vec<&str> = d["verdict"]["effects"]
        .as_array()
        .expect("the verdict lists its effects")
        .iter()
        .filter_map(|e| e.as_str())
        .collect();
    for absent in ["rate", "log-healing", "direction"] {
        assert!(
            !effects.contains(&absent),
            "{absent} named: {}",
            d["verdict"]
        );
    }
    assert!(dout.join("report.html").exists());
}

/// `table1-medium` copied with a `normal_kpa` column around its 78.4 kPa: a reading's scatter
/// (±0.4 kPa, deterministic) that the shear does not follow, or, with `followed`, a load that
/// really moves by as much and the shear with it at the row's stress ratio.
fn with_noisy_normal(tmp: &Path, followed: bool) -> std::path::PathBuf {
    let name = if followed { "followed" } else { "scatter" };
    let set = copy_set("table1-medium", &tmp.join(name));
    let csv = set.join("monotonic.csv");
    let (header, rows) = subfric_e2e::read_data_csv(&csv);
    assert_eq!(header, ["time_s", "slip_mm", "shear_kpa"]);
    let mut out = String::from("time_s,slip_mm,shear_kpa,normal_kpa\n");
    for (i, r) in rows.iter().enumerate() {
        let wiggle = [0.4, -0.3, 0.1, -0.4, 0.3, -0.1][i % 6];
        let normal = 78.4 + wiggle;
        let shear = if followed { r[2] * normal / 78.4 } else { r[2] };
        out.push_str(&format!("{},{},{shear:.4},{normal:.2}\n", r[0], r[1]));
    }
    std::fs::write(&csv, out).unwrap();
    set
}

#[test]
fn check_says_when_the_normal_column_is_held_at_its_level_and_why() {
    let tmp = tempfile::tempdir().unwrap();
    let said = "the shear does not follow it while sliding";
    let scatter = subfric!().ok(args!["check", &with_noisy_normal(tmp.path(), false)]);
    assert!(
        scatter.contains("rig artifact, monotonic: the normal stress column scatters by")
            && scatter.contains(said)
            && scatter.contains("held at its level"),
        "{scatter}"
    );
    let followed = subfric!().ok(args!["check", &with_noisy_normal(tmp.path(), true)]);
    assert!(!followed.contains(said), "{followed}");
}
