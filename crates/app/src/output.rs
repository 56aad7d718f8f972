//! Where results go, and what may be replaced there.
//!
//! - Default output folders are `fits/<name>`, with the set's `name` made a plain folder name
//!   ([`safe_name`]): a name such as `../../x` or `/etc` cannot lead out of `fits/`.
//! - A results folder records the set folders its results come from in [`SOURCE_FILE`]
//!   (paths relative to the folder, so the record is the same on every checkout). Results are
//!   replaced only for the same sets; results of other sets, or files subfric did not write,
//!   are replaced only with `--force`.
//! - A folder receiving a simulated set must not be the set simulated (not even with
//!   `--force`), and an existing set in it is replaced only with `--force` (its old CSVs are
//!   then removed, so none is left orphaned).
//! - Every output folder is created and test-written before the long work starts, and a folder
//!   created for a job that then fails is removed again (when still empty).

use anyhow::{anyhow, bail, Result};
use std::path::{Component, Path, PathBuf};
use subfric_data::fsio::{set_file_problem, stage_file};
use subfric_data::{parse_meta, PathKind, EXPERIMENT_JSON};

/// The record of the sets a results folder holds the results of.
pub const SOURCE_FILE: &str = ".subfric-source";

/// Where a command writes its results: a folder (`None`: the command's default under `fits/`)
/// and whether results there that came from other sets may be replaced.
#[derive(Clone, Debug, Default)]
pub struct Destination {
    /// The results folder; `None`: the command's default, `fits/<set name>[/...]`.
    pub dir: Option<PathBuf>,
    /// Replace results of other sets, or files subfric did not write (`--force`).
    pub force: bool,
}

/// A plain folder or file name for a set or test name: characters outside
/// `[A-Za-z0-9._+-]` become `-`, leading dots and dashes are dropped (no `..`, no hidden
/// file), an empty result becomes `set`.
///
/// ```
/// # use subfric_app::output::safe_name;
/// assert_eq!(safe_name("table1-medium"), "table1-medium");
/// assert_eq!(safe_name("../../victim"), "victim");
/// assert_eq!(safe_name("/etc/passwd"), "etc-passwd");
/// assert_eq!(safe_name(".."), "set");
/// ```
pub fn safe_name(name: &str) -> String {
    let mapped: String = name
        .trim()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-' | '+') {
                c
            } else {
                '-'
            }
        })
        .collect();
    let trimmed = mapped.trim_start_matches(['.', '-']).trim_end_matches('-');
    if trimmed.is_empty() {
        "set".into()
    } else {
        trimmed.to_string()
    }
}

/// The default results folder of a set: `fits/<safe name>`.
pub fn default_results_dir(set_name: &str) -> PathBuf {
    Path::new("fits").join(safe_name(set_name))
}

/// `to` relative to the folder `from` (both absolute and canonical).
fn relative(from: &Path, to: &Path) -> PathBuf {
    let a: Vec<Component> = from.components().collect();
    let b: Vec<Component> = to.components().collect();
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut rel = PathBuf::new();
    for _ in common..a.len() {
        rel.push("..");
    }
    for c in &b[common..] {
        rel.push(c.as_os_str());
    }
    if rel.as_os_str().is_empty() {
        rel.push(".");
    }
    rel
}

fn canonical(p: &Path) -> Result<PathBuf> {
    std::fs::canonicalize(p).map_err(|e| anyhow!("{}: {e}", p.display()))
}

/// The topmost folder `create_dir_all(dir)` will create, if any.
fn first_missing(dir: &Path) -> Option<PathBuf> {
    let mut missing = None;
    let mut p = Some(dir);
    while let Some(d) = p {
        if d.as_os_str().is_empty() || PathKind::of(d) != PathKind::Absent {
            break;
        }
        missing = Some(d.to_path_buf());
        p = d.parent();
    }
    missing
}

/// Creates `dir` and proves it writable by writing and removing a probe file; returns the
/// topmost folder created.
fn create_writable(dir: &Path) -> Result<Option<PathBuf>> {
    match PathKind::of(dir) {
        PathKind::Absent | PathKind::Folder => {}
        kind => bail!(
            "{}: the output folder {} (expected a folder, or nothing)",
            dir.display(),
            kind.describe()
        ),
    }
    let created = first_missing(dir);
    std::fs::create_dir_all(dir)
        .map_err(|e| anyhow!("{}: cannot create the output folder: {e}", dir.display()))?;
    let probe = stage_file(&dir.join(".subfric-write-probe"), b"").map_err(|e| {
        remove_created(created.as_deref(), dir);
        anyhow!("cannot write in the output folder: {e}")
    })?;
    let _ = std::fs::remove_file(probe);
    Ok(created)
}

/// Removes the folders from `dir` up to `top` that `create_writable` created, if empty.
fn remove_created(top: Option<&Path>, dir: &Path) {
    let Some(top) = top else { return };
    let mut p = Some(dir);
    while let Some(d) = p {
        if std::fs::remove_dir(d).is_err() || d == top {
            break;
        }
        p = d.parent();
    }
}

/// A results folder claimed for the results of some sets.
pub struct ResultsDir {
    dir: PathBuf,
    sources: Vec<PathBuf>,
    created: Option<PathBuf>,
    committed: bool,
}

impl ResultsDir {
    /// Claims `dir` for the results of the set folders `sources`, to be written as `files`
    /// (names inside `dir`). Refuses, unless `force`: a folder recorded as holding the results
    /// of other sets, or (without a record) one where any of `files` exists. Creates the
    /// folder and checks it can be written.
    pub fn claim(dir: &Path, sources: &[PathBuf], files: &[String], force: bool) -> Result<Self> {
        let mut ours: Vec<PathBuf> = sources
            .iter()
            .map(|s| canonical(s))
            .collect::<Result<_>>()?;
        ours.sort();
        ours.dedup();
        if PathKind::of(dir) == PathKind::Folder && !force {
            check_replaceable(dir, &ours, files)?;
        }
        let created = create_writable(dir)?;
        Ok(ResultsDir {
            dir: dir.to_path_buf(),
            sources: ours,
            created,
            committed: false,
        })
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Records the sources once the results are written.
    pub fn commit(mut self) -> Result<()> {
        let here = canonical(&self.dir)?;
        let mut text = String::from(
            "# Written by subfric: the set folders the results here come from, relative to this folder.\n\
             # subfric replaces these results only for the same sets, or with --force.\n",
        );
        for s in &self.sources {
            text.push_str(&relative(&here, s).to_string_lossy());
            text.push('\n');
        }
        crate::io::write_text(&self.dir.join(SOURCE_FILE), &text)?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for ResultsDir {
    fn drop(&mut self) {
        if !self.committed {
            remove_created(self.created.as_deref(), &self.dir);
        }
    }
}

/// The sets recorded in a results folder's [`SOURCE_FILE`] (canonical; `Err` keeps a record
/// that no longer resolves, as written).
fn recorded_sources(dir: &Path) -> Option<Vec<std::result::Result<PathBuf, String>>> {
    let text = std::fs::read_to_string(dir.join(SOURCE_FILE)).ok()?;
    Some(
        text.lines()
            .map(str::trim)
            .filter(|l| !l.is_empty() && !l.starts_with('#'))
            .map(|l| std::fs::canonicalize(dir.join(l)).map_err(|_| l.to_string()))
            .collect(),
    )
}

/// Whether the results folder `dir` records exactly the set folder `set` as its source: its
/// results are of that set (not of another set of the same name).
pub(crate) fn holds_results_of(dir: &Path, set: &Path) -> bool {
    let ours = std::fs::canonicalize(set).ok();
    let recorded = recorded_sources(dir).unwrap_or_default();
    recorded.len() == 1 && ours.is_some() && recorded[0].as_ref().ok() == ours.as_ref()
}

fn check_replaceable(dir: &Path, ours: &[PathBuf], files: &[String]) -> Result<()> {
    if let Some(recorded) = recorded_sources(dir) {
        let mut theirs: Vec<PathBuf> = recorded.iter().filter_map(|r| r.clone().ok()).collect();
        theirs.sort();
        theirs.dedup();
        if recorded.iter().all(|r| r.is_ok()) && theirs == ours {
            return Ok(());
        }
        let names: Vec<String> = recorded
            .iter()
            .map(|r| match r {
                Ok(p) => p.display().to_string(),
                Err(l) => format!("{l} (no longer there)"),
            })
            .collect();
        let mine: Vec<String> = ours.iter().map(|p| p.display().to_string()).collect();
        bail!(
            "{}: holds the results of {} (recorded in {}), not of {} (expected another --out folder, or --force to replace them)",
            dir.display(),
            names.join(", "),
            SOURCE_FILE,
            mine.join(", ")
        );
    }
    for f in files {
        let p = dir.join(f);
        if PathKind::of(&p) != PathKind::Absent {
            bail!(
                "{}: exists and was not written by subfric for this set (expected a new or empty folder, or --force to replace it)",
                p.display()
            );
        }
    }
    Ok(())
}

/// A folder claimed for a new set (simulate).
pub struct SetDir {
    dir: PathBuf,
    stale: Vec<PathBuf>,
    created: Option<PathBuf>,
    committed: bool,
}

impl SetDir {
    /// Claims `out` for a set of `files` (`experiment.json` and the CSV names) made from the
    /// set folder `input` (if any). Never the input set itself; an existing set, or an
    /// existing file of `files`, only with `force` (the old set's CSVs that the new set does
    /// not replace are removed on [`SetDir::commit`]).
    pub fn claim(out: &Path, input: Option<&Path>, files: &[String], force: bool) -> Result<Self> {
        if let (Some(input), PathKind::Folder) = (input, PathKind::of(out)) {
            if canonical(out)? == canonical(input)? {
                bail!(
                    "--out {}: is the set being simulated; writing there would replace its measured data with the model's (expected another folder)",
                    out.display()
                );
            }
        }
        let mut stale = Vec::new();
        if PathKind::of(out) == PathKind::Folder {
            let json = out.join(EXPERIMENT_JSON);
            if PathKind::of(&json) != PathKind::Absent {
                if !force {
                    bail!(
                        "--out {}: already holds a set ({}) (expected a new or empty folder, or --force to replace that set)",
                        out.display(),
                        json.display()
                    );
                }
                stale = old_csvs(out, files);
            } else if let Some(f) = files
                .iter()
                .map(|f| out.join(f))
                .find(|p| PathKind::of(p) != PathKind::Absent)
            {
                if !force {
                    bail!(
                        "{}: exists (expected a new or empty folder, or --force to replace it)",
                        f.display()
                    );
                }
            }
        }
        let created = create_writable(out)?;
        Ok(SetDir {
            dir: out.to_path_buf(),
            stale,
            created,
            committed: false,
        })
    }

    /// Once the new set is written: removes the old set's CSVs it did not replace; returns them.
    pub fn commit(mut self) -> Vec<PathBuf> {
        self.committed = true;
        std::mem::take(&mut self.stale)
            .into_iter()
            .filter(|p| std::fs::remove_file(p).is_ok())
            .collect()
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.dir
    }
}

impl Drop for SetDir {
    fn drop(&mut self) {
        if !self.committed {
            remove_created(self.created.as_deref(), &self.dir);
        }
    }
}

/// CSV files of the set in `dir` (regular files inside it) that are not among `files`.
fn old_csvs(dir: &Path, files: &[String]) -> Vec<PathBuf> {
    let json = dir.join(EXPERIMENT_JSON);
    let Ok(text) = std::fs::read_to_string(&json) else {
        return Vec::new();
    };
    let Ok(meta) = parse_meta(&text, &json) else {
        return Vec::new();
    };
    meta.tests
        .iter()
        .filter(|t| !files.iter().any(|f| f == &t.file))
        .map(|t| dir.join(&t.file))
        .filter(|p| set_file_problem(dir, p).is_none())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_between_folders() {
        let r = relative(Path::new("/a/fits/s"), Path::new("/a/experiments/s"));
        assert_eq!(r, Path::new("../../experiments/s"));
        assert_eq!(relative(Path::new("/a"), Path::new("/a")), Path::new("."));
    }

    #[test]
    fn a_results_folder_is_replaced_only_for_the_same_set() {
        let tmp = tempfile::tempdir().unwrap();
        let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
        std::fs::create_dir_all(&a).unwrap();
        std::fs::create_dir_all(&b).unwrap();
        let out = tmp.path().join("fits/x");
        let files = vec!["fit.json".to_string()];
        let d = ResultsDir::claim(&out, std::slice::from_ref(&a), &files, false).unwrap();
        std::fs::write(out.join("fit.json"), "{}").unwrap();
        d.commit().unwrap();
        assert!(ResultsDir::claim(&out, std::slice::from_ref(&a), &files, false).is_ok());
        let e = ResultsDir::claim(&out, std::slice::from_ref(&b), &files, false)
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("holds the results of") && e.contains("--force"),
            "{e}"
        );
        assert!(ResultsDir::claim(&out, &[b], &files, true).is_ok());
        // A folder created for a job that fails is removed again.
        let fresh = tmp.path().join("new/deeper");
        drop(ResultsDir::claim(&fresh, &[a], &files, false).unwrap());
        assert!(!tmp.path().join("new").exists());
    }
}
