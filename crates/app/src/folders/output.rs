//! Where results go, and what may be replaced there.
//!
//! - Default output folders are `fits/<name>`, with the set's `name` made a plain folder name
//!   ([`safe_name`]): a name such as `../../x` or `/etc` cannot lead out of `fits/`.
//! - A results folder records the set folders its results come from in [`SOURCE_FILE`]
//!   (paths relative to the folder, so the record is the same on every checkout). Results are
//!   replaced only for the same sets; results of other sets, or files subfric did not write,
//!   are replaced only with `--force`. A folder holding a set never receives results.
//! - One command at a time writes a folder ([`crate::folders::lock`]); the record is written before the
//!   results ([`ResultsDir`]), so a job killed while writing leaves a folder the same command
//!   writes again, and temporary files of killed writes are removed by the next claim.
//! - A folder receiving a simulated set must not be the set simulated (not even with
//!   `--force`), and an existing set in it is replaced only with `--force` (its old CSVs are
//!   then removed, so none is left orphaned).
//! - Every output folder is created and test-written before the long work starts, and a folder
//!   created for a job that then fails is removed again (when still empty).

use crate::folders::lock::FolderLock;
use anyhow::{anyhow, bail, Result};
use std::path::{Component, Path, PathBuf};
use subfric_data::fsio::{set_file_problem, stage_file, temp_file_writer};
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
/// # use subfric_app::folders::output::safe_name;
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
    crate::folders::io::refuse_link(dir, "the output folder")?;
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

/// Whether the process `pid`, which wrote a temporary file, may still be writing it (`None`:
/// this system cannot tell).
fn writer_alive(pid: u32) -> Option<bool> {
    if pid == std::process::id() {
        return Some(true);
    }
    Path::new("/proc/self")
        .exists()
        .then(|| Path::new("/proc").join(pid.to_string()).exists())
}

/// Removes the temporary files of atomic writes that were never renamed (their writer was
/// killed, or hit a file-size limit) from `dir`, which this process has locked, and from its
/// sub-folders `files`: those of a writer that has ended (in `dir` itself, where only the
/// lock's holder writes, every one when the system cannot tell).
fn remove_stale_temp_files(dir: &Path, files: &[String]) {
    let clean = |d: &Path, locked_here: bool| {
        let Ok(entries) = std::fs::read_dir(d) else {
            return;
        };
        for e in entries.flatten() {
            let name = e.file_name();
            let Some(pid) = temp_file_writer(&name.to_string_lossy()) else {
                continue;
            };
            let stale = match writer_alive(pid) {
                Some(alive) => !alive,
                None => locked_here,
            };
            if stale && e.file_type().is_ok_and(|t| t.is_file()) {
                let _ = std::fs::remove_file(e.path());
            }
        }
    };
    clean(dir, true);
    for f in files {
        let sub = dir.join(f);
        if PathKind::of(&sub) == PathKind::Folder {
            clean(&sub, false);
        }
    }
}

/// An output folder created if need be, proved writable and locked against other commands
/// ([`FolderLock`]), with the temporary files of killed writes removed. Unless kept
/// ([`LockedFolder::keep`]), folders it created are removed again on drop when empty.
pub struct LockedFolder {
    dir: PathBuf,
    created: Option<PathBuf>,
    lock: Option<FolderLock>,
    keep: bool,
}

impl LockedFolder {
    /// Creates (if need be) and locks `dir`; `files`: its sub-folders whose stale temporary
    /// files are removed too.
    pub fn new(dir: &Path, files: &[String]) -> Result<LockedFolder> {
        let created = create_writable(dir)?;
        let lock =
            FolderLock::acquire(dir).inspect_err(|_| remove_created(created.as_deref(), dir))?;
        remove_stale_temp_files(dir, files);
        Ok(LockedFolder {
            dir: dir.to_path_buf(),
            created,
            lock: Some(lock),
            keep: false,
        })
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Unlocks the folder and keeps it (it holds results).
    pub fn keep(mut self) {
        self.keep = true;
    }
}

impl Drop for LockedFolder {
    fn drop(&mut self) {
        drop(self.lock.take());
        if !self.keep {
            remove_created(self.created.as_deref(), &self.dir);
        }
    }
}

/// What becomes of the folder's record of its sets if the job fails before writing anything.
enum Undo {
    /// The record was already this job's: it stays.
    Nothing,
    /// There was none; the job's, written at the claim, is removed.
    Remove,
    /// Another set's (replaced with `--force`), removed at the claim, is written back.
    Restore(String),
}

/// What `files` are on disk (modification time, size, inode), to tell whether a failed job
/// wrote any of them.
type Fingerprint = Vec<Option<(Option<std::time::SystemTime>, u64, u64)>>;

fn fingerprint(dir: &Path, files: &[String]) -> Fingerprint {
    files
        .iter()
        .map(|f| {
            let m = std::fs::symlink_metadata(dir.join(f)).ok()?;
            #[cfg(unix)]
            let ino = std::os::unix::fs::MetadataExt::ino(&m);
            #[cfg(not(unix))]
            let ino = 0;
            Some((m.modified().ok(), m.len(), ino))
        })
        .collect()
}

/// A results folder claimed for the results of some sets: locked until it is committed or
/// dropped, and recorded as theirs from the claim on.
///
/// The record ([`SOURCE_FILE`]) is what lets the same command replace the results later, so
/// it is there before any result is written: a job killed, or stopped by a full disk, while
/// writing leaves a folder that the same command writes again without `--force`. With
/// `--force` over another set's results their record is removed at the claim and this job's
/// written at the commit: the folder never holds one set's results beside another's record. A
/// job that fails before writing anything leaves the record as it found it.
pub struct ResultsDir {
    folder: LockedFolder,
    sources: Vec<PathBuf>,
    files: Vec<String>,
    undo: Undo,
    before: Fingerprint,
    committed: bool,
}

impl ResultsDir {
    /// Claims `dir` for the results of the set folders `sources`, to be written as `files`
    /// (names inside `dir`). Refuses a folder that holds a set (even with `force`: results
    /// never go among measured data) and, unless `force`, a folder recorded as holding the
    /// results of other sets or, without a record, one holding anything but subfric's results
    /// folders. Creates and locks the folder and checks it can be written.
    pub fn claim(dir: &Path, sources: &[PathBuf], files: &[String], force: bool) -> Result<Self> {
        let mut ours: Vec<PathBuf> = sources
            .iter()
            .map(|s| canonical(s))
            .collect::<Result<_>>()?;
        ours.sort();
        ours.dedup();
        refuse_set_folder(dir)?;
        let folder = LockedFolder::new(dir, files)?;
        // Looked at only now, under the lock: another command may have written it meanwhile.
        let recorded = recorded_text(dir);
        if !force {
            check_replaceable(dir, &ours, files)?;
        }
        let mut claim = ResultsDir {
            folder,
            sources: ours,
            files: files.to_vec(),
            undo: Undo::Nothing,
            before: fingerprint(dir, files),
            committed: false,
        };
        let marker = dir.join(SOURCE_FILE);
        match recorded {
            Some(text) if records_these(dir, &claim.sources) => {
                if text != claim.record() {
                    crate::folders::io::write_text(&marker, &claim.record())?;
                    claim.undo = Undo::Restore(text);
                }
            }
            Some(text) => {
                std::fs::remove_file(&marker)
                    .map_err(|e| anyhow!("{}: cannot replace: {e}", marker.display()))?;
                claim.undo = Undo::Restore(text);
            }
            None => {
                claim.undo = Undo::Remove;
                crate::folders::io::write_text(&marker, &claim.record())?;
            }
        }
        Ok(claim)
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        self.folder.path()
    }

    /// The text of [`SOURCE_FILE`] for this claim's sets.
    fn record(&self) -> String {
        let here = canonical(self.path()).unwrap_or_else(|_| self.path().to_path_buf());
        let mut text = String::from(
            "# Written by subfric: the set folders the results here come from, relative to this folder.\n\
             # subfric replaces these results only for the same sets, or with --force.\n",
        );
        for s in &self.sources {
            text.push_str(&relative(&here, s).to_string_lossy());
            text.push('\n');
        }
        text
    }

    /// Records the sources once the results are written, and unlocks the folder.
    pub fn commit(mut self) -> Result<()> {
        crate::folders::io::write_text(&self.path().join(SOURCE_FILE), &self.record())?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for ResultsDir {
    fn drop(&mut self) {
        if self.committed {
            self.folder.keep = true;
            return;
        }
        // Nothing written: the record as it was. Something written: the record stays this
        // job's (or absent after --force), so that the same command can write the folder again.
        if fingerprint(self.path(), &self.files) == self.before {
            let marker = self.path().join(SOURCE_FILE);
            match std::mem::replace(&mut self.undo, Undo::Nothing) {
                Undo::Nothing => {}
                Undo::Remove => {
                    let _ = std::fs::remove_file(&marker);
                }
                Undo::Restore(text) => {
                    let _ = crate::folders::io::write_text(&marker, &text);
                }
            }
        }
    }
}

/// Refuses a results folder that holds an experiment set: results never go among measured data
/// (not even with `--force`, which is about replacing results).
fn refuse_set_folder(dir: &Path) -> Result<()> {
    let json = dir.join(EXPERIMENT_JSON);
    if PathKind::of(&json) != PathKind::Absent {
        bail!(
            "{}: holds an experiment set ({}); results never go into a folder of measured data, not even with --force (expected another --out folder)",
            dir.display(),
            EXPERIMENT_JSON
        );
    }
    Ok(())
}

/// The text of a results folder's [`SOURCE_FILE`], if it has one.
fn recorded_text(dir: &Path) -> Option<String> {
    crate::folders::io::read_settings_text(&dir.join(SOURCE_FILE), "the record").ok()
}

/// The sets recorded in a results folder's [`SOURCE_FILE`] (canonical; `Err` keeps a record
/// that no longer resolves, as written).
fn recorded_sources(dir: &Path) -> Option<Vec<std::result::Result<PathBuf, String>>> {
    let text = recorded_text(dir)?;
    Some(
        text.lines()
            .map(str::trim)
            .filter(|l| !l.is_empty() && !l.starts_with('#'))
            .map(|l| std::fs::canonicalize(dir.join(l)).map_err(|_| l.to_string()))
            .collect(),
    )
}

/// Whether the folder's record names exactly the sets `ours` (canonical, sorted).
fn records_these(dir: &Path, ours: &[PathBuf]) -> bool {
    let Some(recorded) = recorded_sources(dir) else {
        return false;
    };
    let mut theirs: Vec<PathBuf> = recorded.iter().filter_map(|r| r.clone().ok()).collect();
    theirs.sort();
    theirs.dedup();
    recorded.iter().all(|r| r.is_ok()) && theirs == ours
}

/// Whether the results folder `dir` records exactly the set folder `set` as its source: its
/// results are of that set (not of another set of the same name).
pub(crate) fn holds_results_of(dir: &Path, set: &Path) -> bool {
    match std::fs::canonicalize(set) {
        Ok(ours) => records_these(dir, &[ours]),
        Err(_) => false,
    }
}

fn check_replaceable(dir: &Path, ours: &[PathBuf], files: &[String]) -> Result<()> {
    if records_these(dir, ours) {
        return Ok(());
    }
    if let Some(recorded) = recorded_sources(dir) {
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
    let foreign = foreign_entries(dir);
    if !foreign.is_empty() {
        let shown: Vec<&str> = foreign.iter().take(3).map(String::as_str).collect();
        let more = foreign.len().saturating_sub(shown.len());
        bail!(
            "{}: holds files subfric did not write ({}{}) (expected a new or empty folder, a folder of subfric's results, or --force to write beside them)",
            dir.display(),
            shown.join(", "),
            if more > 0 {
                format!(" and {more} more")
            } else {
                String::new()
            }
        );
    }
    Ok(())
}

/// What a folder without a record of its sets holds besides hidden files and subfric's own
/// results folders (each with its record): files a user put there.
fn foreign_entries(dir: &Path) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<String> = entries
        .flatten()
        .filter(|e| !e.file_name().to_string_lossy().starts_with('.'))
        .filter(|e| PathKind::of(&e.path().join(SOURCE_FILE)) != PathKind::File)
        .map(|e| crate::visible(&e.file_name().to_string_lossy()))
        .collect();
    v.sort();
    v
}

/// A folder claimed for a new set (simulate).
pub struct SetDir {
    folder: LockedFolder,
    stale: Vec<PathBuf>,
}

impl SetDir {
    /// Claims `out` for a set of `files` (`experiment.json` and the CSV names) made from the
    /// set folder `input` (if any). Never the input set itself; an existing set, or an
    /// existing file of `files`, only with `force` (the old set's CSVs that the new set does
    /// not replace are removed on [`SetDir::commit`]). The folder is locked until then.
    pub fn claim(out: &Path, input: Option<&Path>, files: &[String], force: bool) -> Result<Self> {
        if let (Some(input), PathKind::Folder) = (input, PathKind::of(out)) {
            if canonical(out)? == canonical(input)? {
                bail!(
                    "--out {}: is the set being simulated; writing there would replace its measured data with the model's (expected another folder)",
                    out.display()
                );
            }
        }
        let folder = LockedFolder::new(out, &[])?;
        let mut stale = Vec::new();
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
        Ok(SetDir { folder, stale })
    }

    /// Once the new set is written: removes the old set's CSVs it did not replace; returns them.
    pub fn commit(mut self) -> Vec<PathBuf> {
        let removed = std::mem::take(&mut self.stale)
            .into_iter()
            .filter(|p| std::fs::remove_file(p).is_ok())
            .collect();
        self.folder.keep = true;
        removed
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        self.folder.path()
    }
}

/// CSV files of the set in `dir` (regular files inside it) that are not among `files`.
fn old_csvs(dir: &Path, files: &[String]) -> Vec<PathBuf> {
    let json = dir.join(EXPERIMENT_JSON);
    let Ok(text) = crate::folders::io::read_settings_text(&json, EXPERIMENT_JSON) else {
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

    #[test]
    fn the_record_comes_first_and_a_failed_job_leaves_the_folder_resumable() {
        let tmp = tempfile::tempdir().unwrap();
        let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
        std::fs::create_dir_all(&a).unwrap();
        std::fs::create_dir_all(&b).unwrap();
        let out = tmp.path().join("out");
        let files = vec!["fit.json".to_string()];
        let record = out.join(SOURCE_FILE);
        // The record is there from the claim on; a job that wrote nothing takes it back.
        let d = ResultsDir::claim(&out, std::slice::from_ref(&a), &files, false).unwrap();
        assert!(record.is_file());
        drop(d);
        assert!(!out.exists());
        // A job stopped after writing a result leaves its record: the same claim succeeds.
        let d = ResultsDir::claim(&out, std::slice::from_ref(&a), &files, false).unwrap();
        std::fs::write(out.join("fit.json"), "{\"set\": \"a\"}").unwrap();
        drop(d);
        assert!(record.is_file());
        let d = ResultsDir::claim(&out, std::slice::from_ref(&a), &files, false).unwrap();
        d.commit().unwrap();
        let a_record = std::fs::read_to_string(&record).unwrap();
        // --force over a's results: a's record goes at the claim and comes back if nothing was
        // written; once b's results are written, no record of a stays beside them.
        let d = ResultsDir::claim(&out, std::slice::from_ref(&b), &files, true).unwrap();
        assert!(!record.exists());
        drop(d);
        assert_eq!(std::fs::read_to_string(&record).unwrap(), a_record);
        let d = ResultsDir::claim(&out, std::slice::from_ref(&b), &files, true).unwrap();
        std::thread::sleep(std::time::Duration::from_millis(20));
        crate::folders::io::write_text(&out.join("fit.json"), "{\"set\": \"b\"}").unwrap();
        drop(d);
        assert!(!record.exists());
        // The folder is locked while claimed, and unlocked after.
        let d = ResultsDir::claim(&out, std::slice::from_ref(&b), &files, true).unwrap();
        let e = ResultsDir::claim(&out, std::slice::from_ref(&b), &files, true)
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("is being written by another subfric command"),
            "{e}"
        );
        d.commit().unwrap();
        assert!(!out.join(crate::folders::lock::LOCK_FILE).exists());
    }

    #[test]
    fn temporary_files_of_killed_writes_are_removed_by_the_next_claim() {
        let tmp = tempfile::tempdir().unwrap();
        let set = tmp.path().join("set");
        std::fs::create_dir_all(&set).unwrap();
        let out = tmp.path().join("out");
        std::fs::create_dir_all(out.join("figures")).unwrap();
        // Process ids beyond any system's limit: writers that are gone.
        let dead = ".fit.json.subfric-tmp-4294967295-0";
        let dead_in_sub = ".a.png.subfric-tmp-4294967294-3";
        let alive_in_sub = format!(".b.png.subfric-tmp-{}-0", std::process::id());
        std::fs::write(out.join(dead), "half").unwrap();
        std::fs::write(out.join("figures").join(dead_in_sub), "half").unwrap();
        std::fs::write(out.join("figures").join(&alive_in_sub), "half").unwrap();
        let files = vec!["fit.json".to_string(), "figures".to_string()];
        let d = ResultsDir::claim(&out, &[set], &files, true).unwrap();
        assert!(!out.join(dead).exists());
        assert!(!out.join("figures").join(dead_in_sub).exists());
        assert!(out.join("figures").join(&alive_in_sub).exists());
        d.commit().unwrap();
    }

    #[test]
    fn results_never_go_into_a_set_folder_nor_beside_foreign_files_without_force() {
        let tmp = tempfile::tempdir().unwrap();
        let set = tmp.path().join("set");
        std::fs::create_dir_all(&set).unwrap();
        std::fs::write(set.join(EXPERIMENT_JSON), "{}").unwrap();
        let files = vec!["fit.json".to_string()];
        for force in [false, true] {
            let e = ResultsDir::claim(&set, std::slice::from_ref(&set), &files, force)
                .err()
                .unwrap()
                .to_string();
            assert!(e.contains("holds an experiment set"), "{e}");
        }
        assert_eq!(std::fs::read_dir(&set).unwrap().count(), 1);
        let mine = tmp.path().join("mine");
        std::fs::create_dir_all(mine.join("sub")).unwrap();
        std::fs::write(mine.join("notes.txt"), "").unwrap();
        std::fs::write(mine.join(".hidden"), "").unwrap();
        let e = ResultsDir::claim(&mine, std::slice::from_ref(&set), &files, false)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("did not write (notes.txt, sub)"), "{e}");
        // subfric's own results folders inside are no foreign files.
        std::fs::remove_file(mine.join("notes.txt")).unwrap();
        std::fs::write(mine.join("sub").join(SOURCE_FILE), "x\n").unwrap();
        ResultsDir::claim(&mine, std::slice::from_ref(&set), &files, false)
            .unwrap()
            .commit()
            .unwrap();
    }
}
