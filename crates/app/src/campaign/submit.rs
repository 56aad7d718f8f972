//! `subfric campaign --submit`: the scripts [`super::emit_slurm`] writes handed to Slurm with
//! `sbatch` (the array, then the collect step with a dependency on it), and, with `--wait`,
//! followed through `squeue` until the collect step has ended. Slurm's own commands do the
//! work, found on `PATH` as a user runs them; what they say when they refuse is passed on,
//! located at the script they refused.

use super::slurm::{ARRAY_SCRIPT, COLLECT_SCRIPT, LOG_DIR};
use crate::progress::Progress;
use anyhow::{anyhow, bail, Result};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// The jobs a campaign was submitted as.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Submitted {
    /// The job array's id: task N is `<array>_N`, set N of the plan.
    pub array: String,
    /// The collect step's job id (it runs once every task of the array has ended).
    pub collect: String,
    /// Tasks of the array (sets of the plan).
    pub tasks: usize,
}

/// Runs one of Slurm's commands, or says plainly that it is not there.
fn slurm_command(program: &str, args: &[&str], cwd: &Path, what: &str) -> Result<Output> {
    Command::new(program)
        .args(args)
        .current_dir(cwd)
        .output()
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => anyhow!(
                "{what}: `{program}` is not on PATH (expected Slurm's client commands on this machine: submit from a Slurm login node, or use --emit-slurm and submit the scripts where Slurm is)"
            ),
            _ => anyhow!("{what}: cannot run `{program}`: {e}"),
        })
}

/// The last lines of what a command wrote, for an error message.
fn said(o: &Output) -> String {
    let text = String::from_utf8_lossy(&o.stderr);
    let text = if text.trim().is_empty() {
        String::from_utf8_lossy(&o.stdout)
    } else {
        text
    };
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    let tail = &lines[lines.len().saturating_sub(4)..];
    if tail.is_empty() {
        "nothing said".into()
    } else {
        tail.join(" / ")
    }
}

fn exit_code(o: &Output) -> String {
    o.status
        .code()
        .map_or_else(|| "killed by a signal".into(), |c| format!("exit code {c}"))
}

/// The job id `sbatch --parsable` prints (`<id>` or `<id>;<cluster>`).
fn parsable_id(stdout: &[u8]) -> Option<String> {
    let text = String::from_utf8_lossy(stdout);
    let id = text.lines().next()?.split(';').next()?.trim();
    (!id.is_empty() && id.chars().all(|c| c.is_ascii_digit())).then(|| id.to_string())
}

/// `sbatch --parsable <extra> <script>` in the campaign folder: the job id.
fn sbatch(out: &Path, script: &str, extra: &[&str]) -> Result<String> {
    let file = out.join(script);
    let what = format!("{}: cannot submit it", file.display());
    let mut args = vec!["--parsable"];
    args.extend_from_slice(extra);
    args.push(script);
    let o = slurm_command("sbatch", &args, out, &what)?;
    if !o.status.success() {
        bail!(
            "{}: sbatch refused it ({}): {} (expected a script Slurm accepts: fix what sbatch names, e.g. a --slurm-option, and submit again)",
            file.display(),
            exit_code(&o),
            said(&o)
        );
    }
    parsable_id(&o.stdout).ok_or_else(|| {
        anyhow!(
            "{}: sbatch printed `{}` (expected a job id, as `sbatch --parsable` prints)",
            file.display(),
            String::from_utf8_lossy(&o.stdout).trim()
        )
    })
}

/// Submits the array of the campaign folder `out` (written by `--emit-slurm`, `tasks` tasks),
/// then its collect step with a dependency on the array (`afterany`: it runs once every task
/// has ended, however each ended).
pub fn submit(out: &Path, tasks: usize) -> Result<Submitted> {
    let array = sbatch(out, ARRAY_SCRIPT, &[])?;
    let dependency = format!("--dependency=afterany:{array}");
    let collect = sbatch(out, COLLECT_SCRIPT, &[&dependency]).map_err(|e| {
        anyhow!(
            "{e}; the array is submitted as job {array} (cancel it with `scancel {array}`, or submit the collect step by hand: sbatch {dependency} {COLLECT_SCRIPT})"
        )
    })?;
    Ok(Submitted {
        array,
        collect,
        tasks,
    })
}

/// Where a job stands, as `squeue` (or `sacct`) names it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct JobState {
    /// `<array>_<task>` or the job id.
    pub job: String,
    /// Slurm's state: `PENDING`, `RUNNING`, `COMPLETED`, `FAILED`, `CANCELLED`, ...; `ENDED`
    /// when the job left the queue and no accounting tells how it ended.
    pub state: String,
    /// The exit code of its script, once ended, when Slurm tells it.
    pub exit_code: Option<i32>,
    /// The signal that killed its script (15 for a cancelled job), when one did.
    pub signal: Option<i32>,
}

impl JobState {
    /// Whether it has ended.
    pub fn ended(&self) -> bool {
        ended(&self.state)
    }

    /// How its script ended, when Slurm tells it: ` (exit code 3)`, ` (killed by signal 15)`.
    pub fn how(&self) -> String {
        match (self.exit_code, self.signal) {
            (_, Some(s)) => format!(" (killed by signal {s})"),
            (Some(c), None) => format!(" (exit code {c})"),
            (None, None) => String::new(),
        }
    }
}

/// Whether a Slurm state is an end: the job will not run again by itself.
fn ended(state: &str) -> bool {
    matches!(
        state,
        "COMPLETED"
            | "FAILED"
            | "CANCELLED"
            | "TIMEOUT"
            | "NODE_FAIL"
            | "PREEMPTED"
            | "OUT_OF_MEMORY"
            | "BOOT_FAIL"
            | "DEADLINE"
            | "ENDED"
    )
}

/// The jobs of a submission as Slurm sees them now.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Followed {
    /// Task N of the array at N.
    pub tasks: Vec<JobState>,
    /// The collect step.
    pub collect: JobState,
}

impl Followed {
    /// Tasks ended, running, pending (or otherwise waiting).
    pub fn counts(&self) -> (usize, usize, usize) {
        let ended = self.tasks.iter().filter(|t| t.ended()).count();
        let running = self
            .tasks
            .iter()
            .filter(|t| matches!(t.state.as_str(), "RUNNING" | "COMPLETING" | "CONFIGURING"))
            .count();
        (ended, running, self.tasks.len() - ended - running)
    }

    /// The tasks' ends, counted by state: `3 COMPLETED, 1 CANCELLED`.
    pub fn task_summary(&self) -> String {
        let mut by: BTreeMap<&str, usize> = BTreeMap::new();
        for t in &self.tasks {
            *by.entry(t.state.as_str()).or_default() += 1;
        }
        by.iter()
            .map(|(s, n)| format!("{n} {s}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// A job's exit code and killing signal from the wait status `squeue -O exit_code` prints
/// (code × 256 + signal).
fn squeue_exit(field: &str) -> (Option<i32>, Option<i32>) {
    match field.trim().parse::<i32>() {
        Ok(status) if status & 0x7f != 0 => (None, Some(status & 0x7f)),
        Ok(status) => (Some(status >> 8), None),
        Err(_) => (None, None),
    }
}

/// A job's exit code and killing signal from `sacct`'s `ExitCode` (`code:signal`).
fn sacct_exit(field: &str) -> (Option<i32>, Option<i32>) {
    let mut f = field.split(':').map(|v| v.trim().parse::<i32>().ok());
    match (f.next().flatten(), f.next().flatten()) {
        (_, Some(signal)) if signal != 0 => (None, Some(signal)),
        (code, _) => (code, None),
    }
}

/// A state as `squeue` or `sacct` write it, without sacct's `CANCELLED by 0`.
fn plain_state(s: &str) -> String {
    s.split_whitespace().next().unwrap_or("").to_string()
}

/// The jobs as squeue lists them (those it no longer lists are absent), or what squeue said
/// when it failed (the controller busy: asked again later).
type Listing = std::result::Result<BTreeMap<String, JobState>, String>;

/// What `squeue` says of the submission's jobs (every state, the array's tasks one per line).
fn squeue(s: &Submitted, out: &Path) -> Result<Listing> {
    let what = format!(
        "following the campaign's jobs {} and {}",
        s.array, s.collect
    );
    let o = slurm_command(
        "squeue",
        &[
            "--noheader",
            "--array",
            "--states=all",
            "--me",
            "--Format=ArrayJobID:|,ArrayTaskID:|,JobID:|,State:|,exit_code:|",
        ],
        out,
        &what,
    )?;
    if !o.status.success() {
        return Ok(Err(format!(
            "{what}: squeue failed ({}): {}",
            exit_code(&o),
            said(&o)
        )));
    }
    let mut jobs = BTreeMap::new();
    for line in String::from_utf8_lossy(&o.stdout).lines() {
        let f: Vec<&str> = line.split('|').map(str::trim).collect();
        if f.len() < 5 {
            continue;
        }
        let (array_id, task, job) = (f[0], f[1], f[2]);
        let key = if array_id == s.array && task.chars().all(|c| c.is_ascii_digit()) {
            format!("{}_{task}", s.array)
        } else if job == s.collect {
            s.collect.clone()
        } else {
            continue;
        };
        let state = plain_state(f[3]);
        let (exit_code, signal) = if ended(&state) {
            squeue_exit(f[4])
        } else {
            (None, None)
        };
        jobs.insert(
            key.clone(),
            JobState {
                job: key,
                state,
                exit_code,
                signal,
            },
        );
    }
    Ok(Ok(jobs))
}

/// How the jobs `squeue` no longer lists ended, from Slurm's accounting when it keeps one
/// (`sacct`); nothing when it does not.
fn sacct(s: &Submitted, out: &Path) -> BTreeMap<String, JobState> {
    let ids = format!("{},{}", s.array, s.collect);
    let args = [
        "--noheader",
        "--parsable2",
        "--allocations",
        "--jobs",
        &ids,
        "--format=JobID,State,ExitCode",
    ];
    let Ok(o) = slurm_command("sacct", &args, out, "sacct") else {
        return BTreeMap::new();
    };
    if !o.status.success() {
        return BTreeMap::new();
    }
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .filter_map(|line| {
            let f: Vec<&str> = line.split('|').collect();
            let (job, state) = (f.first()?.to_string(), plain_state(f.get(1)?));
            let (exit_code, signal) = sacct_exit(f.get(2)?);
            Some((
                job.clone(),
                JobState {
                    job,
                    state,
                    exit_code,
                    signal,
                },
            ))
        })
        .collect()
}

/// What a look at the queue found.
enum Look {
    /// Every job of the submission, where it stands.
    Jobs(Followed),
    /// Jobs of the submission that squeue never listed (not yet, or not at all).
    Unlisted,
    /// squeue failed, saying this.
    Failed(String),
}

/// The submission as Slurm sees it now: squeue's view, and for jobs it no longer lists,
/// accounting's (or `ENDED` when none). `seen`: the jobs as squeue listed them before.
fn look(s: &Submitted, out: &Path, seen: &mut BTreeMap<String, JobState>) -> Result<Look> {
    let now = match squeue(s, out)? {
        Ok(now) => now,
        Err(said) => return Ok(Look::Failed(said)),
    };
    let keys: Vec<String> = (0..s.tasks)
        .map(|i| format!("{}_{i}", s.array))
        .chain([s.collect.clone()])
        .collect();
    let gone: Vec<&String> = keys.iter().filter(|k| !now.contains_key(*k)).collect();
    let accounting = if gone.is_empty() {
        BTreeMap::new()
    } else {
        sacct(s, out)
    };
    let mut states = Vec::with_capacity(keys.len());
    for k in &keys {
        let state = match (now.get(k), accounting.get(k), seen.get(k)) {
            (Some(j), _, _) => j.clone(),
            (None, Some(j), _) => j.clone(),
            // Listed before, gone now, no accounting: it ended, how is not known.
            (None, None, Some(j)) if j.ended() => j.clone(),
            (None, None, Some(_)) => JobState {
                job: k.clone(),
                state: "ENDED".into(),
                exit_code: None,
                signal: None,
            },
            // Never listed: an array's tasks are listed one per line from the start, so a job
            // missing from the start is one the queue forgot (or never had).
            (None, None, None) => return Ok(Look::Unlisted),
        };
        seen.insert(k.clone(), state.clone());
        states.push(state);
    }
    let collect = states.pop().expect("the collect step is in the keys");
    Ok(Look::Jobs(Followed {
        tasks: states,
        collect,
    }))
}

/// Follows a submission until its collect step has ended, reporting the array's tasks as they
/// end (`progress.count`: tasks ended of the array's). Looks every second at first, then less
/// often while nothing changes (at most every `max_poll`).
pub fn follow(
    s: &Submitted,
    out: &Path,
    max_poll: Duration,
    progress: &dyn Progress,
) -> Result<Followed> {
    let mut seen = BTreeMap::new();
    let mut poll = Duration::from_secs(1).min(max_poll);
    let mut last: Option<Followed> = None;
    let mut unseen_since = None::<Instant>;
    let mut failures = 0;
    progress.stage(
        &format!(
            "Slurm: array job {} ({} tasks), then collect step {}",
            s.array, s.tasks, s.collect
        ),
        None,
    );
    loop {
        let now = match look(s, out, &mut seen)? {
            Look::Jobs(now) => {
                failures = 0;
                now
            }
            // squeue fails while the controller is busy or restarting: asked again, a while.
            Look::Failed(said) => {
                failures += 1;
                if failures > 20 {
                    bail!("{said} (20 times in a row)");
                }
                std::thread::sleep(poll);
                continue;
            }
            // Jobs just submitted are listed at once; a minute without them is an answer.
            Look::Unlisted => {
                let t0 = *unseen_since.get_or_insert_with(Instant::now);
                if t0.elapsed() > Duration::from_secs(60) {
                    bail!(
                        "squeue does not list the campaign's jobs {} and {} (expected the jobs just submitted, as this user's; purged already?)",
                        s.array,
                        s.collect
                    );
                }
                std::thread::sleep(poll);
                continue;
            }
        };
        let (ended, running, waiting) = now.counts();
        progress.count(ended, s.tasks);
        if ended < s.tasks {
            progress.stage(
                &format!(
                    "Slurm: array job {}: {ended} of {} tasks ended, {running} running, {waiting} waiting",
                    s.array, s.tasks
                ),
                None,
            );
        } else {
            progress.stage(
                &format!(
                    "Slurm: array job {} ended ({}); collect step {}: {}",
                    s.array,
                    now.task_summary(),
                    s.collect,
                    now.collect.state
                ),
                None,
            );
        }
        if now.collect.ended() {
            return Ok(now);
        }
        let changed = last.as_ref() != Some(&now);
        poll = if changed {
            Duration::from_secs(1).min(max_poll)
        } else {
            (poll * 3 / 2).min(max_poll)
        };
        last = Some(now);
        std::thread::sleep(poll);
    }
}

/// Where a task's log is: `slurm/<array>_<task>.out` (the array script's `--output`).
pub fn task_log(out: &Path, array: &str, task: usize) -> std::path::PathBuf {
    out.join(LOG_DIR).join(format!("{array}_{task}.out"))
}

/// Where the collect step's log is.
pub fn collect_log(out: &Path, collect: &str) -> std::path::PathBuf {
    out.join(LOG_DIR).join(format!("{collect}-collect.out"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn job_ids_and_exit_codes_are_read_as_slurm_writes_them() {
        assert_eq!(parsable_id(b"4711\n").as_deref(), Some("4711"));
        assert_eq!(parsable_id(b"4711;cluster\n").as_deref(), Some("4711"));
        assert_eq!(parsable_id(b"Submitted batch job 4711\n"), None);
        assert_eq!(parsable_id(b""), None);
        assert_eq!(squeue_exit("768"), (Some(3), None));
        assert_eq!(squeue_exit("0"), (Some(0), None));
        assert_eq!(squeue_exit("15"), (None, Some(15)));
        assert_eq!(sacct_exit("3:0"), (Some(3), None));
        assert_eq!(sacct_exit("0:15"), (None, Some(15)));
        assert_eq!(plain_state("CANCELLED by 0"), "CANCELLED");
        assert!(ended("CANCELLED") && ended("COMPLETED") && !ended("RUNNING"));
    }

    #[test]
    fn the_tasks_are_counted_by_where_they_stand() {
        let j = |state: &str| JobState {
            job: "1_0".into(),
            state: state.into(),
            exit_code: None,
            signal: None,
        };
        let f = Followed {
            tasks: vec![j("COMPLETED"), j("CANCELLED"), j("RUNNING"), j("PENDING")],
            collect: j("PENDING"),
        };
        assert_eq!(f.counts(), (2, 1, 1));
        assert_eq!(
            f.task_summary(),
            "1 CANCELLED, 1 COMPLETED, 1 PENDING, 1 RUNNING"
        );
    }

    #[test]
    fn a_missing_sbatch_is_named_with_the_script() {
        let dir = tempfile::tempdir().unwrap();
        let e = slurm_command(
            "subfric-no-such-sbatch",
            &[],
            dir.path(),
            "campaign.sbatch: cannot submit it",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with(
                "campaign.sbatch: cannot submit it: `subfric-no-such-sbatch` is not on PATH"
            ),
            "{e}"
        );
    }
}
