//! `subfric campaign`: its flags, and what it prints. The campaign itself (plan, per-set runs,
//! table, figures, Slurm scripts) is `subfric_app::campaign`.

use crate::print::out;
use crate::progress::{Progress, ProgressMode};
use anyhow::{anyhow, Result};
use clap::Args;
use std::path::{Path, PathBuf};
use subfric_app::campaign::slurm::{check_directive, SlurmOptions};
use subfric_app::campaign::submit::{self, Followed, Submitted};
use subfric_app::campaign::{
    self, CampaignRequest, CampaignSource, Collected, Emitted, Row, SetOptions, SetOutcome, SetRun,
};
use subfric_app::visible;

/// `subfric campaign`.
#[derive(Args, Debug)]
#[command(group = clap::ArgGroup::new("slurm").args(["emit_slurm", "submit"]).multiple(true))]
pub struct CampaignArgs {
    /// A folder of sets (its sub-folders holding experiment.json), or a manifest (.json or
    /// .toml) listing set folders and their options (docs/campaign.md).
    pub source: PathBuf,
    /// Campaign folder [default: campaigns/<name of the folder or manifest>].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Diagnose every set too (a manifest may say otherwise per set).
    #[arg(long)]
    pub diagnose: bool,
    /// Seed of the fits and diagnoses.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Local starts of each fit.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u64).range(1..))]
    pub starts: u64,
    /// Model runs of each fit's global stage.
    #[arg(long, default_value_t = 3000)]
    pub global_evals: usize,
    /// Skip the profile intervals (the table then has no intervals).
    #[arg(long)]
    pub no_profiles: bool,
    /// Sets run at once (each fit is parallel too; see docs/campaign.md) [default: one per core].
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub jobs: Option<u64>,
    /// Replace the results of another campaign (or of other sets) in the campaign folder.
    #[arg(long)]
    pub force: bool,
    /// Write a Slurm job-array script (one task per set) and the collect step's script into the
    /// campaign folder; run nothing.
    #[arg(long, conflicts_with_all = ["index", "collect"])]
    pub emit_slurm: bool,
    /// Write the Slurm scripts (as --emit-slurm) and submit them with sbatch: the array, then
    /// the collect step once every task has ended; prints the job ids.
    #[arg(long, conflicts_with_all = ["index", "collect"])]
    pub submit: bool,
    /// With --submit: follow the jobs (squeue) until the collect step has ended, with a bar of
    /// the tasks ended; the exit code is then the campaign's (0, or 3 when sets have no
    /// results).
    #[arg(long, requires = "submit")]
    pub wait: bool,
    /// Run only set N of the campaign's plan, as Slurm's array task N does [default: every
    /// set]
    #[arg(long, value_name = "N", conflicts_with = "collect")]
    pub index: Option<usize>,
    /// Write the table and the figures from the per-set results; run nothing.
    #[arg(long)]
    pub collect: bool,
    /// CPUs of each Slurm task.
    #[arg(long, default_value_t = 2, requires = "slurm", value_parser = clap::value_parser!(u64).range(1..))]
    pub slurm_cpus: u64,
    /// A further #SBATCH option of both scripts, e.g. --slurm-option=--time=01:00:00
    /// (repeatable) [default: none].
    #[arg(long, requires = "slurm", allow_hyphen_values = true, value_parser = check_directive)]
    pub slurm_option: Vec<String>,
    /// Progress display on stderr.
    #[arg(long, value_enum, default_value_t = ProgressMode::Auto)]
    pub progress: ProgressMode,
}

/// Some sets have no results for their inputs of today (failed, not run, out of date): the
/// others' results and the table are written. Exit code 3.
#[derive(Debug)]
pub struct SomeSetsFailed(pub String);

impl std::fmt::Display for SomeSetsFailed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SomeSetsFailed {}

fn request(a: &CampaignArgs) -> Result<CampaignRequest> {
    Ok(CampaignRequest {
        source: CampaignSource::of(&a.source)?,
        out: a.out.clone(),
        defaults: SetOptions {
            seed: a.seed,
            starts: a.starts as usize,
            global_evals: a.global_evals,
            profiles: !a.no_profiles,
            diagnose: a.diagnose,
            ..SetOptions::default()
        },
        force: a.force,
    })
}

/// The line printed when a set ends.
fn set_line(r: &SetRun) -> String {
    let what = match &r.outcome {
        SetOutcome::Skipped => "skipped: its inputs and options are those of its results".into(),
        SetOutcome::Ran {
            fitted: true,
            diagnosed: true,
        } => "fitted and diagnosed".into(),
        SetOutcome::Ran {
            fitted: true,
            diagnosed: false,
        } => "fitted".into(),
        SetOutcome::Ran { fitted: false, .. } => "diagnosed (its fit is current)".into(),
        SetOutcome::Failed { error } => format!("FAILED: {error}"),
    };
    format!("{}: {what} ({:.1} s)", visible(&r.id), r.seconds)
}

fn print_collected(c: &Collected) -> Result<()> {
    for f in &c.files {
        out(format!("wrote {}", visible(&f.display().to_string())));
    }
    incomplete_error(&c.rows)
}

/// Exit code 3 with the sets without results and why, when there are some.
fn incomplete_error(rows: &[Row]) -> Result<()> {
    let incomplete: Vec<&Row> = rows
        .iter()
        .filter(|r| r.status != campaign::RowStatus::Ok)
        .collect();
    if incomplete.is_empty() {
        return Ok(());
    }
    let mut text = format!(
        "{} of {} sets have no results (the table and the others' results are written):",
        incomplete.len(),
        rows.len()
    );
    for r in incomplete {
        text.push_str(&format!(
            "\n  {}: {}{}",
            r.set,
            r.status.text(),
            r.error
                .as_deref()
                .map(|e| format!(": {e}"))
                .unwrap_or_default()
        ));
    }
    Err(SomeSetsFailed(text).into())
}

/// `subfric campaign`.
pub fn run(a: CampaignArgs) -> Result<()> {
    let req = request(&a)?;
    if a.emit_slurm || a.submit {
        let e = emit(&a, &req)?;
        return if a.submit { submit(&a, &e) } else { Ok(()) };
    }
    if a.collect {
        return print_collected(&campaign::collect(&req)?);
    }
    if let Some(index) = a.index {
        let progress = Progress::new(a.progress);
        let r = campaign::run_index(Some(&req), &req.out_dir(), index, req.force, &progress)?;
        progress.finish();
        out(set_line(&r));
        return match r.outcome {
            SetOutcome::Failed { .. } => Err(SomeSetsFailed(format!(
                "set {} of the campaign failed (its record says why; --collect puts it in the table)",
                r.id
            ))
            .into()),
            _ => Ok(()),
        };
    }
    let t0 = std::time::Instant::now();
    let progress = Progress::counted(a.progress, "sets");
    // A skipped set is in the summary line, not a line of its own: a campaign resumed after
    // hundreds of sets says so once.
    let on_set = |r: &SetRun| match r.outcome {
        SetOutcome::Skipped => progress.skipped(),
        _ => progress.println(&set_line(r)),
    };
    let f = campaign::run(&req, a.jobs.map(|j| j as usize), &on_set, &progress)?;
    progress.finish();
    let count = |p: fn(&SetOutcome) -> bool| f.runs.iter().filter(|r| p(&r.outcome)).count();
    out(format!(
        "campaign {}: {} sets: {} run, {} skipped, {} failed, in {:.1} s",
        visible(&f.collected.out.display().to_string()),
        f.runs.len(),
        count(|o| matches!(o, SetOutcome::Ran { .. })),
        count(|o| matches!(o, SetOutcome::Skipped)),
        count(|o| matches!(o, SetOutcome::Failed { .. })),
        t0.elapsed().as_secs_f64()
    ));
    print_collected(&f.collected)
}

fn absolute(p: &Path) -> Result<PathBuf> {
    std::path::absolute(p).map_err(|e| anyhow!("{}: {e}", p.display()))
}

/// `--emit-slurm`: the scripts run this program with the same source and options, every path
/// absolute.
fn emit(a: &CampaignArgs, req: &CampaignRequest) -> Result<Emitted> {
    let out_dir = absolute(&req.out_dir())?;
    let mut arguments = vec![
        "campaign".to_string(),
        absolute(&a.source)?.display().to_string(),
        "--out".into(),
        out_dir.display().to_string(),
        "--seed".into(),
        a.seed.to_string(),
        "--starts".into(),
        a.starts.to_string(),
        "--global-evals".into(),
        a.global_evals.to_string(),
    ];
    for (on, flag) in [
        (a.no_profiles, "--no-profiles"),
        (a.diagnose, "--diagnose"),
        (a.force, "--force"),
    ] {
        if on {
            arguments.push(flag.into());
        }
    }
    let o = SlurmOptions {
        program: std::env::current_exe()
            .map_err(|e| anyhow!("cannot tell where this program is: {e}"))?,
        arguments,
        workdir: std::env::current_dir()
            .map_err(|e| anyhow!("cannot tell the current folder: {e}"))?,
        cpus_per_task: a.slurm_cpus as usize,
        directives: a.slurm_option.clone(),
    };
    let e = campaign::emit_slurm(req, &o)?;
    for n in &e.notes {
        crate::print::err(format!("note: {n}"));
    }
    for f in &e.scripts {
        out(format!("wrote {}", visible(&f.display().to_string())));
    }
    let dir = visible(&e.out.display().to_string());
    if !a.submit {
        out(format!(
            "{} sets, array tasks 0-{}. Submit from {dir}:\n  jid=$(sbatch --parsable {}) && sbatch --dependency=afterany:$jid {}",
            e.plan.sets.len(),
            e.plan.sets.len().saturating_sub(1),
            campaign::slurm::ARRAY_SCRIPT,
            campaign::slurm::COLLECT_SCRIPT
        ));
    }
    Ok(e)
}

/// `--submit`: the array and the collect step handed to sbatch, their ids printed; with
/// `--wait`, followed to the end.
fn submit(a: &CampaignArgs, e: &Emitted) -> Result<()> {
    let s = submit::submit(&e.out, e.plan.sets.len())?;
    let logs = visible(&e.out.join(campaign::slurm::LOG_DIR).display().to_string());
    out(format!(
        "submitted array job {} ({} tasks, one per set: task N is set N of campaign.json) and collect step {} (runs once every task has ended)\n  follow: squeue -j {},{} · logs: {logs} · cancel: scancel {} {}",
        s.array, s.tasks, s.collect, s.array, s.collect, s.array, s.collect
    ));
    if !a.wait {
        return Ok(());
    }
    let progress = Progress::counted(a.progress, "tasks");
    let f = submit::follow(&s, &e.out, std::time::Duration::from_secs(5), &progress);
    progress.finish();
    let f = f?;
    print_ends(e, &s, &f);
    let collect = &f.collect;
    if collect.state == "COMPLETED" || collect.exit_code == Some(3) {
        let rows = campaign::rows(&e.out)?;
        out(format!(
            "table: {}",
            visible(&e.out.join(campaign::TABLE_CSV).display().to_string())
        ));
        return incomplete_error(&rows);
    }
    Err(anyhow!(
        "collect step {} ended {}{}: the table may be missing or old (its log: {})",
        s.collect,
        collect.state,
        collect.how(),
        visible(
            &submit::collect_log(&e.out, &s.collect)
                .display()
                .to_string()
        )
    ))
}

/// How the jobs ended: the array's tasks counted by state, each task that did not complete
/// with its set and log, and the collect step.
fn print_ends(e: &Emitted, s: &Submitted, f: &Followed) {
    out(format!("array job {}: {}", s.array, f.task_summary()));
    for (i, t) in f.tasks.iter().enumerate() {
        if t.state != "COMPLETED" {
            let set = e.plan.sets.get(i).map_or("?", |j| j.id.as_str());
            out(format!(
                "  task {i} (set {}): {}{}, its log: {}",
                visible(set),
                t.state,
                t.how(),
                visible(&submit::task_log(&e.out, &s.array, i).display().to_string())
            ));
        }
    }
    out(format!(
        "collect step {}: {}{}",
        s.collect,
        f.collect.state,
        f.collect.how()
    ));
}
