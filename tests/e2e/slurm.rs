//! A campaign on a real Slurm cluster (issue 41): the array `campaign --emit-slurm` writes and
//! its collect step submitted with `sbatch` (the collect step depending on the array), followed
//! through `squeue` to their ends, give the local run's table byte for byte; a task killed by
//! `scancel` in the middle of its set leaves the table without that set (exit code 3 of the
//! collect step), and submitting the array again runs that set alone and completes the table.
//! `campaign --submit --wait` does the same for a user, and names what sbatch refuses.
//!
//! The cluster: the one `sinfo` answers for (a machine that is a Slurm client already), else a
//! one-node cluster started on localhost by `scripts/slurm-local.sh` in a temporary folder
//! (installing Slurm and munge from Debian's packages when they are missing) and stopped when
//! the last test using it ends. A cluster that cannot be started fails the tests: they never
//! skip. The nodes of an existing cluster must see this machine's temporary folder (TMPDIR).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, Mutex, Weak};
use std::time::{Duration, Instant};
use subfric_e2e::{args, assert_mentions, copy_dir, copy_set, golden, repo, subfric, text};

/// How long a job may take to end before the test gives up on it (the jobs here take seconds).
const DEADLINE: Duration = Duration::from_secs(20 * 60);

/// The cluster the tests submit to.
struct Cluster {
    /// `SLURM_CONF` of a cluster started here (None: the environment's cluster).
    conf: Option<PathBuf>,
    /// The folder of a cluster started here; it is stopped, then removed, on drop.
    started: Option<tempfile::TempDir>,
}

fn script() -> PathBuf {
    repo().join("scripts/slurm-local.sh")
}

impl Cluster {
    /// The cluster `sinfo` answers for, or one started through the script.
    fn find_or_start() -> Cluster {
        let answers = Command::new("sinfo")
            .args(["--noheader", "--format=%T"])
            .output()
            .is_ok_and(|o| o.status.success() && !text(&o.stdout).trim().is_empty());
        if answers {
            eprintln!("slurm: using the cluster sinfo answers for");
            return Cluster {
                conf: None,
                started: None,
            };
        }
        let dir = tempfile::Builder::new()
            .prefix("subfric-slurm-")
            .tempdir()
            .unwrap();
        let o = Command::new("bash")
            .arg(script())
            .arg("start")
            .arg(dir.path())
            .output()
            .expect("bash runs scripts/slurm-local.sh");
        assert!(
            o.status.success(),
            "no Slurm cluster answers and scripts/slurm-local.sh could not start one (these tests need one; they do not skip):\n{}\n{}",
            text(&o.stdout),
            text(&o.stderr)
        );
        eprintln!("slurm: {}", text(&o.stdout).trim());
        Cluster {
            conf: Some(dir.path().join("slurm.conf")),
            started: Some(dir),
        }
    }

    /// One of Slurm's commands, pointed at this cluster.
    fn command(&self, program: &str) -> Command {
        let mut c = Command::new(program);
        if let Some(conf) = &self.conf {
            c.env("SLURM_CONF", conf);
        }
        c
    }

    /// Runs a command of Slurm's and asserts it succeeded; its stdout.
    fn run(&self, program: &str, args: &[&str], cwd: &Path) -> String {
        let o = self
            .command(program)
            .args(args)
            .current_dir(cwd)
            .output()
            .unwrap_or_else(|e| panic!("{program}: {e}"));
        assert!(
            o.status.success(),
            "{program} {args:?}: {}",
            text(&o.stderr)
        );
        text(&o.stdout)
    }

    /// `sbatch --parsable`: the job id.
    fn sbatch(&self, args: &[&str], cwd: &Path) -> String {
        let mut a = vec!["--parsable"];
        a.extend_from_slice(args);
        let id = self.run("sbatch", &a, cwd).trim().to_string();
        assert!(
            id.chars().all(|c| c.is_ascii_digit()),
            "sbatch printed {id}"
        );
        id
    }

    /// The program under test, pointed at this cluster.
    fn subfric(&self) -> subfric_e2e::Subfric {
        match &self.conf {
            Some(conf) => subfric!().env("SLURM_CONF", &conf.display().to_string()),
            None => subfric!(),
        }
    }

    /// The jobs `ids` as squeue lists them (every state): `<array>_<task>` or `<job>` → (state,
    /// exit code).
    fn states(&self, ids: &[&str]) -> Vec<(String, String, i32)> {
        let o = self.run(
            "squeue",
            &[
                "--noheader",
                "--array",
                "--states=all",
                &format!("--jobs={}", ids.join(",")),
                "--Format=ArrayJobID:|,ArrayTaskID:|,State:|,exit_code:|",
            ],
            Path::new("/"),
        );
        let mut v: Vec<(String, String, i32)> = o
            .lines()
            .map(|l| {
                let f: Vec<&str> = l.split('|').map(str::trim).collect();
                let job = match f[1] {
                    "N/A" => f[0].to_string(),
                    task => format!("{}_{task}", f[0]),
                };
                let status: i32 = f[3].parse().unwrap_or(-1);
                (job, f[2].to_string(), status >> 8)
            })
            .collect();
        v.sort();
        v
    }

    /// Waits until every job of `ids` has ended; their states, by job.
    fn wait(&self, ids: &[&str]) -> Vec<(String, String, i32)> {
        let t0 = Instant::now();
        loop {
            let now = self.states(ids);
            let running = |s: &str| {
                matches!(
                    s,
                    "PENDING" | "RUNNING" | "CONFIGURING" | "COMPLETING" | "SUSPENDED"
                )
            };
            if !now.is_empty() && !now.iter().any(|(_, s, _)| running(s)) {
                return now;
            }
            assert!(
                t0.elapsed() < DEADLINE,
                "the jobs {ids:?} have not ended in {DEADLINE:?}: {now:?}\n{}",
                self.log_tail()
            );
            std::thread::sleep(Duration::from_millis(300));
        }
    }

    /// The last lines of the started cluster's controller and node logs.
    fn log_tail(&self) -> String {
        let Some(dir) = &self.started else {
            return String::new();
        };
        ["slurmctld.log", "slurmd.log"]
            .iter()
            .map(|f| {
                let t = std::fs::read_to_string(dir.path().join("log").join(f)).unwrap_or_default();
                let lines: Vec<&str> = t.lines().collect();
                format!(
                    "{f}:\n{}",
                    lines[lines.len().saturating_sub(15)..].join("\n")
                )
            })
            .collect::<Vec<_>>()
            .join("\n")
    }
}

impl Drop for Cluster {
    /// Stops the cluster started here (the script cancels its jobs and stops exactly the
    /// daemons it started), before its folder is removed.
    fn drop(&mut self) {
        if let Some(dir) = &self.started {
            let o = Command::new("bash")
                .arg(script())
                .arg("stop")
                .arg(dir.path())
                .output();
            match o {
                Ok(o) if o.status.success() => eprintln!("slurm: {}", text(&o.stdout).trim()),
                Ok(o) => eprintln!("slurm: stopping failed: {}", text(&o.stderr)),
                Err(e) => eprintln!("slurm: stopping failed: {e}"),
            }
        }
    }
}

/// The cluster, shared by the tests of this file that run at once.
fn cluster() -> Arc<Cluster> {
    static SHARED: Mutex<Weak<Cluster>> = Mutex::new(Weak::new());
    let mut shared = SHARED.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(c) = shared.upgrade() {
        return c;
    }
    let c = Arc::new(Cluster::find_or_start());
    *shared = Arc::downgrade(&c);
    c
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The campaign's options, the same for the local run and the cluster's (few starts: the
/// tables must agree, not be good fits).
const OPTIONS: [&str; 4] = ["--starts", "2", "--global-evals", "600"];

/// `<root>/lab`: the golden four-test pair (a fit of some seconds: the task killed) and two
/// Table 1 sets (fits of a fraction of a second).
fn lab(root: &Path) -> PathBuf {
    let lab = root.join("lab");
    copy_dir(&golden().join("pair-01"), &lab.join("pair-01"));
    copy_set("table1-rough", &lab);
    copy_set("table1-smooth", &lab);
    lab
}

/// The campaign `lab` run here, into `<root>/out`.
fn local_run(root: &Path, lab: &Path) -> PathBuf {
    let out = root.join("out");
    let mut a = args!["campaign", lab, "--out", &out, "--progress", "never"].to_vec();
    a.extend(OPTIONS.iter().map(std::ffi::OsStr::new));
    subfric!().ok(&a);
    out
}

/// The table, its figures and every set's fit.json are the same bytes in both campaign folders.
fn assert_same_results(cluster: &Path, local: &Path, sets: &[&str]) {
    let mut files: Vec<String> = [
        "campaign.csv",
        "campaign.md",
        "campaign.html",
        "figures/mu-vs-roughness.png",
        "figures/mu-vs-normal-stress.png",
    ]
    .map(String::from)
    .to_vec();
    files.extend(sets.iter().map(|s| format!("sets/{s}/fit.json")));
    for f in files {
        assert!(
            read(&cluster.join(&f)) == read(&local.join(&f)),
            "{f} differs from the local run's"
        );
    }
}

/// The process id in a results folder's lock file, once the folder is locked.
fn lock_holder(dir: &Path) -> Option<u32> {
    std::fs::read_to_string(dir.join(".subfric-lock"))
        .ok()?
        .trim()
        .parse()
        .ok()
}

fn state_of<'a>(states: &'a [(String, String, i32)], job: &str) -> (&'a str, i32) {
    states
        .iter()
        .find(|(j, _, _)| j == job)
        .map(|(_, s, c)| (s.as_str(), *c))
        .unwrap_or_else(|| panic!("squeue does not list {job}: {states:?}"))
}

#[test]
fn sbatch_runs_the_array_and_its_collect_step_into_the_local_table_and_a_cancelled_task_is_rerun() {
    let cluster = cluster();
    let tmp = tempfile::tempdir().unwrap();
    let local = local_run(&tmp.path().join("local"), &lab(&tmp.path().join("local")));
    let here = tmp.path().join("cluster");
    let lab = lab(&here);
    let mut a = args![
        "campaign",
        &lab,
        "--out",
        "out",
        "--emit-slurm",
        "--slurm-cpus",
        "1",
        "--slurm-option=--time=00:30:00"
    ]
    .to_vec();
    a.extend(OPTIONS.iter().map(std::ffi::OsStr::new));
    let stdout = subfric!().cwd(&here).ok(&a);
    assert_mentions(&stdout, &["3 sets, array tasks 0-2"]);
    let out = here.join("out");

    // The array and its collect step, as the script's comment and docs/campaign.md say.
    let array = cluster.sbatch(&["campaign.sbatch"], &out);
    let collect = cluster.sbatch(
        &[&format!("--dependency=afterany:{array}"), "collect.sbatch"],
        &out,
    );
    // Task 0 (pair-01, the longest fit) killed in the middle of its set: once it holds its
    // results folder, it is stopped (so that it cannot end first) and cancelled.
    let set0 = out.join("sets/pair-01");
    let t0 = Instant::now();
    let pid = loop {
        if let Some(pid) = lock_holder(&set0) {
            break pid;
        }
        assert!(
            t0.elapsed() < DEADLINE,
            "task 0 never began its set: {:?}\n{}",
            cluster.states(&[&array]),
            cluster.log_tail()
        );
        std::thread::sleep(Duration::from_millis(5));
    };
    let stopped = Command::new("kill")
        .args(["-STOP", &pid.to_string()])
        .status()
        .unwrap();
    assert!(
        stopped.success(),
        "task 0 (process {pid}) ended before it could be stopped"
    );
    cluster.run("scancel", &[&format!("{array}_0")], &out);
    let states = cluster.wait(&[&array, &collect]);
    eprintln!("slurm: first submission: {states:?}");
    assert_eq!(state_of(&states, &format!("{array}_0")).0, "CANCELLED");
    for task in [1, 2] {
        assert_eq!(
            state_of(&states, &format!("{array}_{task}")),
            ("COMPLETED", 0),
            "task {task}"
        );
    }
    // The collect step ran after the array, and found set 0 without results: exit code 3.
    assert_eq!(state_of(&states, &collect), ("FAILED", 3));
    let log = String::from_utf8(read(&out.join(format!("slurm/{collect}-collect.out")))).unwrap();
    assert_mentions(&log, &["1 of 3 sets have no results", "pair-01: not run"]);
    assert!(!set0.join("fit.json").exists() && !set0.join("campaign-set.json").exists());

    // Submitted again, unchanged: the cancelled set runs, the others are skipped, and the
    // table is complete: the local run's, byte for byte.
    let array2 = cluster.sbatch(&["campaign.sbatch"], &out);
    let collect2 = cluster.sbatch(
        &[&format!("--dependency=afterany:{array2}"), "collect.sbatch"],
        &out,
    );
    let states2 = cluster.wait(&[&array2, &collect2]);
    eprintln!("slurm: second submission: {states2:?}");
    for task in 0..3 {
        assert_eq!(
            state_of(&states2, &format!("{array2}_{task}")),
            ("COMPLETED", 0),
            "task {task}"
        );
    }
    assert_eq!(state_of(&states2, &collect2), ("COMPLETED", 0));
    let task_log =
        |t: usize| String::from_utf8(read(&out.join(format!("slurm/{array2}_{t}.out")))).unwrap();
    assert_mentions(&task_log(0), &["pair-01: fitted"]);
    assert_mentions(&task_log(1), &["table1-rough: skipped"]);
    assert_same_results(&out, &local, &["pair-01", "table1-rough", "table1-smooth"]);
}

#[test]
fn campaign_submit_prints_the_job_ids_waits_for_them_and_names_what_sbatch_refuses() {
    let cluster = cluster();
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path().join("lab-root");
    let lab = root.join("lab");
    copy_set("table1-rough", &lab);
    copy_set("table1-smooth", &lab);
    let local = local_run(&tmp.path().join("local"), &lab);
    let out = tmp.path().join("submitted");
    let mut a = args![
        "campaign",
        &lab,
        "--out",
        &out,
        "--submit",
        "--wait",
        "--slurm-cpus",
        "1",
        "--progress",
        "always"
    ]
    .to_vec();
    a.extend(OPTIONS.iter().map(std::ffi::OsStr::new));
    let (stdout, stderr) = cluster.subfric().ok_both(&a);
    eprintln!("slurm: campaign --submit --wait:\n{stdout}");
    let ids: Vec<&str> = stdout
        .split("submitted array job ")
        .nth(1)
        .and_then(|s| s.split_once(" (2 tasks"))
        .map(|(array, rest)| (array, rest.split("collect step ").nth(1).unwrap()))
        .map(|(array, rest)| vec![array, rest.split(' ').next().unwrap()])
        .unwrap_or_else(|| panic!("no job ids in:\n{stdout}"));
    let (array, collect) = (ids[0], ids[1]);
    assert_mentions(
        &stdout,
        &[
            &format!("array job {array}: 2 COMPLETED"),
            &format!("collect step {collect}: COMPLETED (exit code 0)"),
            "table: ",
        ],
    );
    // Followed through squeue: a line per change off a terminal (a bar on one).
    assert_mentions(
        &stderr,
        &[
            &format!("progress: Slurm: array job {array} (2 tasks), then collect step {collect}"),
            &format!("progress: Slurm: array job {array} ended (2 COMPLETED); collect step {collect}: COMPLETED"),
        ],
    );
    // Slurm agrees, and the table is the local run's.
    let states = cluster.states(&[array, collect]);
    assert_eq!(state_of(&states, collect), ("COMPLETED", 0));
    assert_same_results(&out, &local, &["table1-rough", "table1-smooth"]);

    // What sbatch refuses is named, with the script it refused.
    let e = cluster.subfric().err(args![
        "campaign",
        &lab,
        "--out",
        &tmp.path().join("refused"),
        "--submit",
        "--slurm-option=--partition=subfric-no-such-partition"
    ]);
    assert_mentions(
        &e,
        &[
            "refused/campaign.sbatch: sbatch refused it (exit code 1)",
            "invalid partition",
        ],
    );
}
