//! One writer per output folder. Two commands writing the same folder at once would mix their
//! results (one `fit.json` beside the other's `.subfric-source`) or lose one silently; so a
//! command locks each folder it writes, from before it looks at what is there until its results
//! are recorded, and a second command is refused at once, told which process holds the folder.
//!
//! The lock is an advisory `flock` on a hidden file in the folder ([`LOCK_FILE`]), taken with
//! [`std::fs::File::try_lock`]: the system releases it when its holder ends, however it ends (a
//! kill included), so a stale lock never blocks a folder. The file holds the holder's process
//! id, for the message, and is removed when the lock is released. On a file system without
//! locks (some network mounts) the folder is written unlocked.
//!
//! The lock file is opened without following a symbolic link and without blocking, and only a
//! regular file with no other name (one link) is taken as a lock file: a link, a FIFO, a device
//! or a hard link to some other file planted at its name is refused, never written through
//! (it would receive a process id) nor truncated.

use anyhow::{anyhow, bail, Result};
use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

/// The lock file of an output folder.
pub const LOCK_FILE: &str = ".subfric-lock";

/// An output folder locked by this process; unlocked (and its lock file removed) on drop.
#[derive(Debug)]
pub struct FolderLock {
    file: File,
    path: PathBuf,
}

impl FolderLock {
    /// Locks the existing folder `dir`, or says which process holds it.
    pub fn acquire(dir: &Path) -> Result<FolderLock> {
        let path = dir.join(LOCK_FILE);
        // A holder removes the file when it lets go: a file opened just before that is no
        // longer the folder's lock file, and is opened again.
        for _ in 0..100 {
            let mut file = open_lock_file(&path)?;
            match file.try_lock() {
                Ok(()) => {}
                Err(TryLockError::WouldBlock) => bail!(
                    "{}: is being written by another subfric command ({}) (expected one command at a time per output folder: wait for it to end, or give another --out)",
                    dir.display(),
                    holder(&mut file)
                ),
                Err(TryLockError::Error(e)) if e.kind() == std::io::ErrorKind::Unsupported => {
                    return Ok(FolderLock { file, path });
                }
                Err(TryLockError::Error(e)) => {
                    bail!("{}: cannot lock the output folder: {e}", path.display())
                }
            }
            if is_file_at(&file, &path) {
                let _ = file.set_len(0);
                let _ = file.rewind();
                let _ = writeln!(file, "{}", std::process::id());
                let _ = file.flush();
                return Ok(FolderLock { file, path });
            }
        }
        bail!(
            "{}: cannot lock the output folder (its lock file keeps changing)",
            dir.display()
        )
    }
}

/// Opens (creating it if need be) the lock file at `path`: never through a symbolic link,
/// never blocking on a FIFO, and refusing anything but a regular file of one link.
fn open_lock_file(path: &Path) -> Result<File> {
    let refuse = |what: &str| {
        anyhow!(
            "{}: {what} where subfric keeps its lock file (expected a regular file subfric wrote, or nothing: remove it, or give another --out)",
            path.display()
        )
    };
    if let Ok(m) = std::fs::symlink_metadata(path) {
        if m.file_type().is_symlink() {
            return Err(refuse("a symbolic link"));
        }
    }
    let mut options = OpenOptions::new();
    options.read(true).write(true).create(true).truncate(false);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK);
    }
    let file = options.open(path).map_err(|e| {
        #[cfg(unix)]
        if e.raw_os_error() == Some(libc::ELOOP) {
            return refuse("a symbolic link");
        }
        anyhow!("{}: cannot create the lock file: {e}", path.display())
    })?;
    let meta = file
        .metadata()
        .map_err(|e| anyhow!("{}: cannot read the lock file: {e}", path.display()))?;
    if !meta.is_file() {
        return Err(refuse(
            "a FIFO, socket, device or folder (not a regular file)",
        ));
    }
    #[cfg(unix)]
    if std::os::unix::fs::MetadataExt::nlink(&meta) > 1 {
        return Err(refuse(
            "a file with another name too (a hard link: it may be some other file)",
        ));
    }
    Ok(file)
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        // Removed while still locked, so that no other process locks this file meanwhile.
        let _ = std::fs::remove_file(&self.path);
        let _ = self.file.unlock();
    }
}

/// Who holds a lock: "process 1234", from the lock file's content. The holder writes its id
/// just after it takes the lock, so a refusal that comes in between waits for the id a little
/// (at most a second, on a loaded machine) rather than name no one.
fn holder(file: &mut File) -> String {
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(1);
    loop {
        let mut text = String::new();
        let _ = file.rewind();
        let _ = file.read_to_string(&mut text);
        if let Ok(pid) = text.trim().parse::<u32>() {
            return format!("process {pid}");
        }
        if std::time::Instant::now() >= deadline {
            return "a process just starting".into();
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

/// Whether the open `file` is still the file at `path`.
#[cfg(unix)]
fn is_file_at(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Whether the open `file` is still the file at `path` (without inode numbers: whether there is
/// a file at `path`; a lock file is removed only by its holder).
#[cfg(not(unix))]
fn is_file_at(_file: &File, path: &Path) -> bool {
    path.is_file()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_writer_is_refused_with_the_holders_process_and_the_lock_is_released() {
        let tmp = tempfile::tempdir().unwrap();
        let first = FolderLock::acquire(tmp.path()).unwrap();
        let e = FolderLock::acquire(tmp.path()).unwrap_err().to_string();
        assert!(
            e.contains("is being written by another subfric command")
                && e.contains(&format!("process {}", std::process::id())),
            "{e}"
        );
        drop(first);
        assert!(!tmp.path().join(LOCK_FILE).exists());
        // A lock file left behind (its holder was killed) does not block the folder.
        std::fs::write(tmp.path().join(LOCK_FILE), "99999999\n").unwrap();
        let again = FolderLock::acquire(tmp.path()).unwrap();
        drop(again);
        assert!(!tmp.path().join(LOCK_FILE).exists());
    }

    #[test]
    fn a_refusal_between_the_holders_lock_and_its_id_waits_for_the_id() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join(LOCK_FILE);
        // A holder that has locked the file but not yet written its id.
        let held = File::create(&path).unwrap();
        held.try_lock().unwrap();
        let writer = {
            let path = path.clone();
            std::thread::spawn(move || {
                std::thread::sleep(std::time::Duration::from_millis(100));
                std::fs::write(&path, "4242\n").unwrap();
            })
        };
        let e = FolderLock::acquire(tmp.path()).unwrap_err().to_string();
        writer.join().unwrap();
        assert!(e.contains("(process 4242)"), "{e}");
        drop(held);
    }
}
