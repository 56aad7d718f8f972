//! `subfric campaign` end to end (issue 24), on copies of the three Table 1 sets (one sand at
//! three roughness levels; a fit of about a second each): the table and figures, a second run
//! that skips everything, a changed CSV that reruns its set only, a failing set reported with
//! its file, line and field while the others finish, a manifest, the Slurm script run task by
//! task and collected into the local run's table, and a diagnosed campaign's verdicts.

use std::path::{Path, PathBuf};
use subfric_e2e::{args, assert_mentions, copy_set, read_json, subfric, text};

const SETS: [&str; 3] = ["table1-smooth", "table1-medium", "table1-rough"];

/// A folder `lab` of copies of the Table 1 sets.
fn lab(tmp: &Path) -> PathBuf {
    let lab = tmp.join("lab");
    for s in SETS {
        copy_set(s, &lab);
    }
    lab
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The records of a CSV (RFC 4180: quoted cells may hold commas, quotes and line breaks).
fn parse_csv(text: &str) -> Vec<Vec<String>> {
    let (mut records, mut record, mut cell) = (Vec::new(), Vec::new(), String::new());
    let mut chars = text.chars().peekable();
    let mut quoted = false;
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                cell.push('"');
            }
            (true, '"') => quoted = false,
            (true, c) => cell.push(c),
            (false, '"') => quoted = true,
            (false, ',') => record.push(std::mem::take(&mut cell)),
            (false, '\n') => {
                record.push(std::mem::take(&mut cell));
                records.push(std::mem::take(&mut record));
            }
            (false, c) => cell.push(c),
        }
    }
    records
}

/// The table's header, and its rows as (set, cells).
fn table(out: &Path) -> (Vec<String>, Vec<(String, Vec<String>)>) {
    let mut records = parse_csv(&read(&out.join("campaign.csv")));
    let header = records.remove(0);
    for r in &records {
        assert_eq!(r.len(), header.len(), "{r:?}");
    }
    (
        header,
        records.into_iter().map(|r| (r[0].clone(), r)).collect(),
    )
}

/// The table's rows, by set.
fn csv_rows(out: &Path) -> Vec<(String, Vec<String>)> {
    table(out).1
}

/// One cell of a CSV's data line (1-based line, counting comments), by column name.
fn set_cell(csv: &Path, line: usize, column: &str, value: &str) {
    let t = read(csv);
    let mut lines: Vec<String> = t.lines().map(str::to_string).collect();
    let header: Vec<&str> = t
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .split(',')
        .collect();
    let k = header.iter().position(|h| *h == column).unwrap();
    let mut cells: Vec<String> = lines[line - 1].split(',').map(str::to_string).collect();
    cells[k] = value.to_string();
    lines[line - 1] = cells.join(",");
    std::fs::write(csv, lines.join("\n") + "\n").unwrap();
}

fn modified(p: &Path) -> std::time::SystemTime {
    std::fs::metadata(p).unwrap().modified().unwrap()
}

#[test]
fn a_campaign_writes_its_table_skips_what_is_current_and_reruns_only_a_changed_set() {
    let tmp = tempfile::tempdir().unwrap();
    let lab = lab(tmp.path());
    let out = tmp.path().join("out");
    let stdout = subfric!().ok(args![
        "campaign",
        &lab,
        "--out",
        &out,
        "--progress",
        "never"
    ]);
    assert_mentions(&stdout, &["3 sets: 3 run, 0 skipped, 0 failed"]);
    // One row per set, sorted by set, with the interface and the parameters with intervals.
    let rows = csv_rows(&out);
    let ids: Vec<&str> = rows.iter().map(|(s, _)| s.as_str()).collect();
    assert_eq!(ids, ["table1-medium", "table1-rough", "table1-smooth"]);
    let (header, _) = table(&out);
    for h in [
        "soil",
        "d50_mm",
        "surface",
        "roughness_rmax_um",
        "rmax_over_d50",
        "normal_stresses_kpa",
        "mu_s",
        "mu_s_lo",
        "mu_s_hi",
        "mu_s_status",
        "mu_k_status",
    ] {
        assert!(header.iter().any(|c| c == h), "no column {h}: {header:?}");
    }
    let col = |row: &[String], name: &str| -> String {
        let k = header.iter().position(|h| h == name).unwrap();
        row[k].clone()
    };
    let rough = &rows[1].1;
    assert_eq!(col(rough, "roughness_rmax_um"), "9.8");
    let ratio: f64 = col(rough, "rmax_over_d50").parse().unwrap();
    assert!((ratio - 9.8 / 180.0).abs() < 1e-12, "{ratio}");
    assert_eq!(col(rough, "normal_stresses_kpa"), "78.4");
    assert_eq!(col(rough, "status"), "ok");
    // μ_s is determined on Table 1 (fit.txt of reproduce says so): a closed interval around it.
    let mu_s: f64 = col(rough, "mu_s").parse().unwrap();
    let lo: f64 = col(rough, "mu_s_lo").parse().unwrap();
    let hi: f64 = col(rough, "mu_s_hi").parse().unwrap();
    assert!(lo < mu_s && mu_s < hi, "{lo} {mu_s} {hi}");
    let md = read(&out.join("campaign.md"));
    assert_mentions(&md, &["| table1-rough |", "R_max/D50", "3 sets: 3 ok"]);
    for f in ["mu-vs-roughness.png", "mu-vs-normal-stress.png"] {
        let check = subfric_plot::inspect_png(&out.join("figures").join(f)).unwrap();
        assert_eq!((check.width, check.height), (1000, 750), "{f}");
    }
    // The campaign's page: the same table, each set's fit linked, every figure shown.
    let page = subfric_e2e::html::check_report(&out.join("campaign.html"), &out.join("figures"));
    assert_mentions(
        &page.text,
        &[
            "3 sets: 3 ok",
            "table1-rough",
            "misfit (× noise variance)",
            "R_max/D50",
        ],
    );
    assert!(
        page.links.iter().any(|l| l == "sets/table1-rough/fit.txt"),
        "{:?}",
        page.links
    );
    assert!(!out.join("figures/verdicts.png").exists());
    // A set's fit.json is the one `subfric fit` writes, byte for byte.
    let alone = tmp.path().join("alone");
    subfric!().ok(args![
        "fit",
        &lab.join("table1-rough"),
        "--out",
        &alone,
        "--progress",
        "never"
    ]);
    assert_eq!(
        read(&alone.join("fit.json")),
        read(&out.join("sets/table1-rough/fit.json"))
    );

    // Again: nothing has changed, nothing is fitted, the table is the same bytes.
    let table = read(&out.join("campaign.csv"));
    let fit_json = out.join("sets/table1-medium/fit.json");
    let written = modified(&fit_json);
    let stdout = subfric!().ok(args![
        "campaign",
        &lab,
        "--out",
        &out,
        "--progress",
        "never"
    ]);
    assert_mentions(&stdout, &["3 sets: 0 run, 3 skipped, 0 failed"]);
    assert_eq!(read(&out.join("campaign.csv")), table);
    assert_eq!(modified(&fit_json), written);
    // A file touched but not changed is the same input (its content's hash is).
    let medium_csv = lab.join("table1-medium/monotonic.csv");
    std::fs::write(&medium_csv, read(&medium_csv)).unwrap();
    let stdout = subfric!().ok(args![
        "campaign",
        &lab,
        "--out",
        &out,
        "--progress",
        "never"
    ]);
    assert_mentions(&stdout, &["0 run, 3 skipped"]);

    // One CSV changed: that set alone is fitted again, and only its row changes.
    set_cell(&medium_csv, 40, "shear_kpa", "99.5");
    let (stdout, stderr) = subfric!().ok_both(args![
        "campaign",
        &lab,
        "--out",
        &out,
        "--progress",
        "never"
    ]);
    assert_mentions(&stdout, &["1 run, 2 skipped, 0 failed"]);
    assert_mentions(&stderr, &["table1-medium: fitted"]);
    let after = csv_rows(&out);
    assert_ne!(after[0], rows[0], "the changed set's row");
    assert_eq!(after[1..], rows[1..], "the other sets' rows");
    let record = read_json(&out.join("sets/table1-medium/campaign-set.json"));
    let hashes = record["inputs"].as_array().unwrap();
    assert_eq!(hashes[1]["file"], "monotonic.csv");
    assert_eq!(hashes[1]["sha256"].as_str().unwrap().len(), 64);

    // Other options: every set is fitted again with them.
    let stdout = subfric!().ok(args![
        "campaign",
        &lab,
        "--out",
        &out,
        "--starts",
        "4",
        "--progress",
        "never"
    ]);
    assert_mentions(&stdout, &["3 run, 0 skipped"]);
    // Another campaign into the same folder is refused without --force.
    let other = tmp.path().join("other");
    std::fs::create_dir_all(&other).unwrap();
    copy_set("table1-smooth", &other);
    let e = subfric!().err(args!["campaign", &other, "--out", &out]);
    assert_mentions(&e, &["holds the results of", "--force"]);
}

#[test]
fn a_failing_set_is_reported_with_its_file_line_and_field_and_the_others_finish() {
    let tmp = tempfile::tempdir().unwrap();
    let lab = lab(tmp.path());
    let out = tmp.path().join("out");
    let bad = lab.join("table1-rough/monotonic.csv");
    let good = read(&bad);
    set_cell(&bad, 5, "shear_kpa", "abc");
    let o = subfric!().run(args!["campaign", &lab, "--out", &out, "--no-profiles"]);
    let (stdout, stderr) = (text(&o.stdout), text(&o.stderr));
    assert_eq!(o.status.code(), Some(3), "{stdout}\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_mentions(&stdout, &["3 sets: 2 run, 0 skipped, 1 failed", "wrote"]);
    assert_mentions(
        &stderr,
        &[
            "table1-rough: FAILED:",
            "monotonic.csv:5: field `shear_kpa`",
            "error: 1 of 3 sets have no results",
        ],
    );
    let (header, rows) = table(&out);
    let col =
        |row: &[String], name: &str| row[header.iter().position(|h| h == name).unwrap()].clone();
    assert_eq!(col(&rows[1].1, "status"), "failed");
    assert_mentions(
        &col(&rows[1].1, "error"),
        &["monotonic.csv:5: field `shear_kpa`"],
    );
    assert_eq!(
        (col(&rows[0].1, "status"), col(&rows[2].1, "status")),
        ("ok".into(), "ok".into())
    );
    assert!(out.join("sets/table1-medium/fit.json").is_file());
    assert_mentions(
        &read(&out.join("campaign.md")),
        &["## Sets without results"],
    );
    // Mended: that set alone runs, and the campaign is whole.
    std::fs::write(&bad, good).unwrap();
    let stdout = subfric!().ok(args![
        "campaign",
        &lab,
        "--out",
        &out,
        "--no-profiles",
        "--progress",
        "never"
    ]);
    assert_mentions(&stdout, &["1 run, 2 skipped, 0 failed"]);
}

#[test]
fn the_slurm_array_runs_one_set_per_task_and_the_collect_step_gives_the_local_table() {
    let tmp = tempfile::tempdir().unwrap();
    let lab = lab(tmp.path());
    let local = tmp.path().join("local");
    subfric!().ok(args![
        "campaign",
        &lab,
        "--out",
        &local,
        "--progress",
        "never"
    ]);
    let cluster = tmp.path().join("cluster");
    let stdout = subfric!().ok(args![
        "campaign",
        &lab,
        "--out",
        &cluster,
        "--emit-slurm",
        "--slurm-option=--time=00:20:00"
    ]);
    assert_mentions(&stdout, &["3 sets, array tasks 0-2", "sbatch --parsable"]);
    let script = read(&cluster.join("campaign.sbatch"));
    let array: Vec<&str> = script
        .lines()
        .filter(|l| l.starts_with("#SBATCH --array="))
        .collect();
    assert_eq!(array, ["#SBATCH --array=0-2"], "{script}");
    assert_mentions(
        &script,
        &[
            "#SBATCH --time=00:20:00",
            "--index \"$SLURM_ARRAY_TASK_ID\"",
        ],
    );
    assert!(read(&cluster.join("collect.sbatch")).contains(" --collect "));
    assert!(
        cluster.join("slurm").is_dir(),
        "Slurm does not make the log folder"
    );
    // Tasks 0 and 1, as Slurm would run them (the script, with the task's id), then a collect
    // step that finds set 2 without results.
    for i in ["0", "1"] {
        let o = std::process::Command::new("bash")
            .arg(cluster.join("campaign.sbatch"))
            .env("SLURM_ARRAY_TASK_ID", i)
            .output()
            .unwrap();
        assert!(o.status.success(), "task {i}: {}", text(&o.stderr));
    }
    let o = subfric!().run(args!["campaign", &lab, "--out", &cluster, "--collect"]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o.stderr));
    assert_mentions(&text(&o.stderr), &["table1-smooth: not run"]);
    // Task 2 by hand, then the collect step: the local run's table, byte for byte.
    subfric!().ok(args![
        "campaign",
        &lab,
        "--out",
        &cluster,
        "--index",
        "2",
        "--progress",
        "never"
    ]);
    subfric!().ok(args!["campaign", &lab, "--out", &cluster, "--collect"]);
    for f in ["campaign.csv", "campaign.md"] {
        assert_eq!(read(&cluster.join(f)), read(&local.join(f)), "{f}");
    }
    // A task of another campaign's options, or beyond the array, is refused.
    let e = subfric!().err(args![
        "campaign", &lab, "--out", &cluster, "--index", "0", "--seed", "2"
    ]);
    assert_mentions(&e, &["campaign.json", "plan differs", "set table1-medium"]);
    let e = subfric!().err(args!["campaign", &lab, "--out", &cluster, "--index", "3"]);
    assert_mentions(
        &e,
        &["--index 3: the campaign has 3 sets (expected 0 to 2)"],
    );
}

#[test]
fn a_manifest_names_sets_and_their_options_and_its_problems_are_located() {
    let tmp = tempfile::tempdir().unwrap();
    let lab = lab(tmp.path());
    let manifest = tmp.path().join("campaign.toml");
    std::fs::write(
        &manifest,
        "[options]\ndiagnose = true\n\n[[sets]]\npath = \"lab/table1-smooth\"\n\n[[sets]]\npath = \"lab/table1-rough\"\nid = \"rough-fixed-kappa\"\nfix = { kappa = 9.0 }\nstarts = 4\n",
    )
    .unwrap();
    let out = tmp.path().join("out");
    let (stdout, _) = subfric!().ok_both(args![
        "campaign",
        &manifest,
        "--out",
        &out,
        "--progress",
        "never"
    ]);
    assert_mentions(&stdout, &["2 sets: 2 run"]);
    let rows = csv_rows(&out);
    assert_eq!(rows[0].0, "rough-fixed-kappa");
    let fit = read_json(&out.join("sets/rough-fixed-kappa/fit.json"));
    let kappa = fit["report"]["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "kappa")
        .unwrap()
        .clone();
    assert_eq!(
        (kappa["value"].as_f64(), kappa["status"].as_str()),
        (Some(9.0), Some("fixed"))
    );
    // Diagnosed, as the manifest's options say: the verdict per set, and its figure.
    let (header, rows) = table(&out);
    let verdict = header.iter().position(|h| h == "verdict").unwrap();
    assert!(rows.iter().all(|(_, r)| !r[verdict].is_empty()), "{rows:?}");
    assert_eq!(header[verdict + 1], "held_out_shrink");
    // How sure each verdict is, as the diagnosis states it: a probability, none where the
    // diagnosis could not judge.
    assert_eq!(header[verdict + 2], "confidence");
    for (_, r) in &rows {
        let c = &r[verdict + 2];
        if r[verdict] == "cannot-judge" {
            assert!(c.is_empty(), "{r:?}");
        } else {
            assert!(
                c.parse::<f64>().is_ok_and(|c| (0.0..=1.0).contains(&c)),
                "{r:?}"
            );
        }
    }
    assert!(out
        .join("sets/table1-smooth/diagnosis/diagnosis.json")
        .is_file());
    let check = subfric_plot::inspect_png(&out.join("figures/verdicts.png")).unwrap();
    assert_eq!(check.width, 1000);

    // A manifest with mistakes: every one named at its line, nothing written.
    let bad = tmp.path().join("bad.toml");
    std::fs::write(
        &bad,
        "[[sets]]\npath = \"lab/table1-smooth\"\nseeds = 3\n\n[[sets]]\npath = \"lab/nowhere\"\n",
    )
    .unwrap();
    let out2 = tmp.path().join("out2");
    let e = subfric!().err(args!["campaign", &bad, "--out", &out2]);
    assert_mentions(
        &e,
        &[
            "bad.toml:3: field `sets[0].seeds`: unknown field",
            "bad.toml:6: field `sets[1].path`",
            "nowhere: is absent",
        ],
    );
    assert!(!out2.exists());
    // A single set is not a campaign; a folder without sets neither.
    let e = subfric!().err(args!["campaign", &lab.join("table1-smooth")]);
    assert_mentions(&e, &["is one set", "subfric fit"]);
    let empty = tmp.path().join("empty");
    std::fs::create_dir_all(empty.join("notes")).unwrap();
    let e = subfric!().err(args!["campaign", &empty, "--out", &tmp.path().join("o3")]);
    assert_mentions(&e, &["no sets"]);
}

#[test]
fn submit_without_sbatch_says_so_and_wait_needs_submit() {
    let tmp = tempfile::tempdir().unwrap();
    let lab = lab(tmp.path());
    let out = tmp.path().join("out");
    // No Slurm on PATH: the scripts are written, and the error says what is missing where.
    let e = subfric!()
        .env("PATH", "/nonexistent")
        .err(args!["campaign", &lab, "--out", &out, "--submit"]);
    assert_mentions(
        &e,
        &[
            "campaign.sbatch: cannot submit it: `sbatch` is not on PATH",
            "--emit-slurm",
        ],
    );
    assert!(out.join("campaign.sbatch").is_file() && out.join("collect.sbatch").is_file());
    let e = subfric!().usage_err(args!["campaign", &lab, "--wait"]);
    assert_mentions(&e, &["--submit"]);
    let e = subfric!().usage_err(args!["campaign", &lab, "--slurm-cpus", "4"]);
    assert_mentions(&e, &["--emit-slurm", "--submit"]);
}

/// Ctrl-C during a campaign (issue 41): the set in progress finishes, no other starts, and the
/// program says how many sets are done and how to resume, exiting with a failure; the same
/// command then skips the sets done and completes the table.
#[test]
fn a_campaign_stopped_by_ctrl_c_says_so_and_resumes_where_it_stopped() {
    let tmp = tempfile::tempdir().unwrap();
    let lab = lab(tmp.path());
    let out = tmp.path().join("out");
    let runner = subfric!();
    let a = args![
        "campaign",
        &lab,
        "--out",
        &out,
        "--progress",
        "never",
        "--jobs",
        "1"
    ];
    let child = runner
        .command(a)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Interrupted once the first set is done: the second is then in progress.
    let records = |out: &Path| -> usize {
        std::fs::read_dir(out.join("sets"))
            .map(|d| {
                d.flatten()
                    .filter(|e| e.path().join("campaign-set.json").is_file())
                    .count()
            })
            .unwrap_or(0)
    };
    let start = std::time::Instant::now();
    while records(&out) == 0 {
        assert!(
            start.elapsed().as_secs() < 300,
            "no set finished in 5 minutes"
        );
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let sent = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let stopped = child.wait_with_output().unwrap();
    let err = text(&stopped.stderr);
    assert_eq!(stopped.status.code(), Some(130), "{err}");
    assert_mentions(
        &err,
        &[
            "interrupted",
            "of 3 sets done",
            "run the same command again to resume",
        ],
    );
    let done = records(&out);
    assert!(
        (1..3).contains(&done),
        "{done} sets done after the interrupt: {err}"
    );
    assert!(
        !out.join("campaign.csv").exists(),
        "a table of an unfinished campaign"
    );
    // Resumed: the sets done are skipped, the others run, the table is complete.
    let stdout = subfric!().ok(a);
    assert_mentions(
        &stdout,
        &[&format!(
            "3 sets: {} run, {done} skipped, 0 failed",
            3 - done
        )],
    );
    assert_eq!(csv_rows(&out).len(), 3);
}
