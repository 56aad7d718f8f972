//! The Slurm form of a campaign: a job-array script whose task N runs set N of the plan
//! (`subfric campaign … --index N`) into the same per-set results folders a local run writes,
//! and a script of the collect step that assembles the table once every task has ended. Slurm
//! schedules, retries and accounts; subfric only says what each task runs.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The job-array script.
pub const ARRAY_SCRIPT: &str = "campaign.sbatch";
/// The collect step's script.
pub const COLLECT_SCRIPT: &str = "collect.sbatch";
/// The folder of the tasks' logs.
pub const LOG_DIR: &str = "slurm";

/// What the scripts run and ask Slurm for.
#[derive(Clone, Debug)]
pub struct SlurmOptions {
    /// The subfric program (absolute).
    pub program: PathBuf,
    /// The arguments of `subfric` that give this campaign (`campaign <source> --out <out>` and
    /// its options), absolute paths, without `--index` or `--collect`.
    pub arguments: Vec<String>,
    /// Where the tasks start (absolute).
    pub workdir: PathBuf,
    /// CPUs of each task (the fit's threads).
    pub cpus_per_task: usize,
    /// Further `#SBATCH` options, e.g. `--time=01:00:00`, `--partition=short`.
    pub directives: Vec<String>,
}

/// Checks a further `#SBATCH` option: one line, starting with `-`.
pub fn check_directive(d: &str) -> Result<String, String> {
    let d = d.trim();
    if d.is_empty() || d.contains(['\n', '\r']) || !d.starts_with('-') {
        return Err(format!(
            "`{d}` is not one sbatch option (expected e.g. --time=01:00:00 or --partition=short)"
        ));
    }
    Ok(d.to_string())
}

/// `s` quoted for a POSIX shell.
pub fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:+,@%".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

fn header(s: &mut String, o: &SlurmOptions, name: &str) {
    let _ = writeln!(s, "#SBATCH --job-name={}", shell_quote(name));
    let _ = writeln!(s, "#SBATCH --cpus-per-task={}", o.cpus_per_task.max(1));
    for d in &o.directives {
        let _ = writeln!(s, "#SBATCH {d}");
    }
    let _ = writeln!(s, "set -eu");
    let _ = writeln!(s, "cd {}", shell_quote(&o.workdir.display().to_string()));
    // The fit's threads: the CPUs Slurm gave the task.
    let _ = writeln!(
        s,
        "export RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-{}}}\"",
        o.cpus_per_task.max(1)
    );
}

fn command(o: &SlurmOptions, last: &str) -> String {
    let mut c = vec![shell_quote(&o.program.display().to_string())];
    c.extend(o.arguments.iter().map(|a| shell_quote(a)));
    c.push(last.to_string());
    c.push("--progress".into());
    c.push("never".into());
    c.join(" ")
}

/// The job-array script of `sets` sets written to `out` (absolute), and the collect step's.
pub fn scripts(o: &SlurmOptions, name: &str, out: &Path, sets: usize) -> (String, String) {
    let logs = out.join(LOG_DIR).display().to_string();
    let mut array = String::from("#!/bin/bash\n");
    let _ = writeln!(
        array,
        "# Written by `subfric campaign --emit-slurm`: one array task per set of the campaign ({sets} sets,\n\
         # listed in campaign.json beside this file). Submit it, and the collect step to run once\n\
         # every task has ended:\n\
         #\n\
         #   jid=$(sbatch --parsable {ARRAY_SCRIPT}) && sbatch --dependency=afterany:$jid {COLLECT_SCRIPT}\n\
         #\n\
         # Task N runs set N into sets/<set>/ (skipped when its results are current). The paths are\n\
         # absolute: the nodes must see this file system."
    );
    let _ = writeln!(array, "#SBATCH --array=0-{}", sets.saturating_sub(1));
    let _ = writeln!(
        array,
        "#SBATCH --output={}",
        shell_quote(&format!("{logs}/%A_%a.out"))
    );
    header(&mut array, o, name);
    let _ = writeln!(
        array,
        "exec {}",
        command(o, "--index \"$SLURM_ARRAY_TASK_ID\"")
    );
    let mut collect = String::from("#!/bin/bash\n");
    let _ = writeln!(
        collect,
        "# Written by `subfric campaign --emit-slurm`: the campaign's table and figures from the\n\
         # per-set results, once every task of {ARRAY_SCRIPT} has ended (its exit code is 3 when a\n\
         # set failed or has no results; the table then says which and why)."
    );
    let _ = writeln!(
        collect,
        "#SBATCH --output={}",
        shell_quote(&format!("{logs}/%j-collect.out"))
    );
    header(&mut collect, o, &format!("{name}-collect"));
    let _ = writeln!(collect, "exec {}", command(o, "--collect"));
    (array, collect)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_array_has_one_task_per_set_and_paths_are_quoted() {
        let o = SlurmOptions {
            program: "/opt/sub fric/subfric".into(),
            arguments: vec![
                "campaign".into(),
                "/data/it's".into(),
                "--out".into(),
                "/o".into(),
            ],
            workdir: "/work".into(),
            cpus_per_task: 4,
            directives: vec!["--time=01:00:00".into()],
        };
        let (array, collect) = scripts(&o, "lab", Path::new("/o"), 16);
        assert!(array.contains("\n#SBATCH --array=0-15\n"), "{array}");
        assert!(array.contains("#SBATCH --time=01:00:00"), "{array}");
        assert!(
            array.contains(
                "exec '/opt/sub fric/subfric' campaign '/data/it'\\''s' --out /o --index \"$SLURM_ARRAY_TASK_ID\" --progress never"
            ),
            "{array}"
        );
        assert!(collect.contains("--collect --progress never"), "{collect}");
        assert!(!collect.contains("--array"), "{collect}");
        assert!(check_directive("--partition=short").is_ok());
        assert!(check_directive("partition").is_err());
        assert!(check_directive("--a\n#SBATCH --b").is_err());
    }
}
