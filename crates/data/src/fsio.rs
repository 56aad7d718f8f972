//! Files on disk: writes that never leave a half-written file, and what kind of thing a path
//! names before it is read.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::error::{DataError, InputProblem};
use crate::set::EXPERIMENT_JSON;

static TEMP_COUNTER: AtomicUsize = AtomicUsize::new(0);

/// Marks the name of a temporary file of an atomic write (`.<name>.subfric-tmp-<pid>-<n>`).
pub const TEMP_MARK: &str = ".subfric-tmp-";

/// A temporary file beside `path` (same folder, so that a rename replaces `path` in one step),
/// hidden, and unique to this process and call. The name of `path` is cut to 100 characters in
/// it, so that a file whose name a file system just takes has a temporary name it takes too.
fn temp_path(path: &Path) -> PathBuf {
    let mut name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "file".into());
    if let Some((cut, _)) = name.char_indices().nth(100) {
        name.truncate(cut);
    }
    let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}{TEMP_MARK}{}-{n}", std::process::id()))
}

/// Writes `bytes` to a new temporary file beside `path`, flushed to disk; returns its path.
/// On failure nothing is left behind.
pub fn stage_file(path: &Path, bytes: &[u8]) -> Result<PathBuf, DataError> {
    let tmp = temp_path(path);
    // `create_new` never follows a link planted at the temporary name.
    let written = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp)
        .and_then(|mut f| {
            f.write_all(bytes)?;
            f.sync_all()
        });
    match written {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(DataError::io(path, e))
        }
    }
}

/// Moves a file written by [`stage_file`] to `path`, replacing what was there in one step (a
/// symbolic link at `path` is replaced, never written through). On failure the staged file is
/// removed.
pub fn commit_file(staged: &Path, path: &Path) -> Result<(), DataError> {
    if let Err(e) = std::fs::rename(staged, path) {
        let _ = std::fs::remove_file(staged);
        return Err(DataError::io(path, e));
    }
    // Make the rename itself durable (best effort: not every platform can sync a folder).
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        if let Ok(d) = std::fs::File::open(dir) {
            let _ = d.sync_all();
        }
    }
    Ok(())
}

/// Writes a file atomically: readers see the old content or the new one, never a mix, even
/// when the disk fills up or the process is killed while writing (the new content goes to a
/// temporary file in the same folder, flushed, then renamed over `path`).
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// let f = dir.path().join("a.txt");
/// subfric_data::write_atomic(&f, b"one")?;
/// subfric_data::write_atomic(&f, b"two")?;
/// assert_eq!(std::fs::read_to_string(&f)?, "two");
/// assert_eq!(std::fs::read_dir(dir.path())?.count(), 1); // no temporary file left
/// # Ok(()) }
/// ```
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), DataError> {
    let staged = stage_file(path, bytes)?;
    commit_file(&staged, path)
}

/// The process that wrote the temporary file named `name`, if `name` is one ([`TEMP_MARK`]).
///
/// ```
/// use subfric_data::fsio::temp_file_writer;
/// assert_eq!(temp_file_writer(".fit.json.subfric-tmp-4242-0"), Some(4242));
/// assert_eq!(temp_file_writer("fit.json"), None);
/// ```
pub fn temp_file_writer(name: &str) -> Option<u32> {
    if !name.starts_with('.') {
        return None;
    }
    let rest = &name[name.rfind(TEMP_MARK)? + TEMP_MARK.len()..];
    rest.split('-').next()?.parse().ok()
}

/// Largest description or settings file read (`experiment.json`, a parameter file, a
/// diagnosis.json, a prior file, a scenario, a campaign manifest, the records subfric keeps):
/// 64 MiB, a thousand times the largest one bundled, as the C interface's model files.
pub const MAX_SETTINGS_FILE_BYTES: u64 = 64 << 20;

/// Largest data file read (a test's CSV, a lab export): 1 GiB, some 20 million rows of five
/// columns, ten times the largest scenario `simulate` makes by default.
pub const MAX_DATA_FILE_BYTES: u64 = 1 << 30;

/// Reads a whole user file (`what` names it in messages: "the diagnosis", "the prior file"):
/// refuses what is not a regular file (a folder, a FIFO, a device such as `/dev/zero`), and a
/// file of more than `max` bytes, with an error naming the file. The file is opened without
/// blocking, so a FIFO put in its place between the look and the open is refused too, not
/// waited on; and it is read at most to `max` + 1 bytes, so a file that grows while it is read
/// is refused rather than read without end.
pub fn read_user_file(path: &Path, what: &str, max: u64) -> Result<Vec<u8>, DataError> {
    let refuse =
        |message: String| DataError::Problems(vec![InputProblem::new(path, None, None, message)]);
    let kind = PathKind::of(path);
    if !matches!(kind, PathKind::File | PathKind::Absent) {
        return Err(refuse(format!(
            "{what} {} (expected a regular file)",
            kind.describe()
        )));
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path).map_err(|e| DataError::io(path, e))?;
    let meta = file.metadata().map_err(|e| DataError::io(path, e))?;
    if !meta.is_file() {
        return Err(refuse(format!(
            "{what} {} (expected a regular file)",
            PathKind::Special.describe()
        )));
    }
    let too_big = |grew: bool, n: u64| {
        refuse(format!(
            "{what} {} {n} bytes, more than the {max} bytes a file of its kind may hold (expected {what} as subfric or a laboratory writes it: is this the right file?)",
            if grew { "grew while it was read, past" } else { "holds" }
        ))
    };
    if meta.len() > max {
        return Err(too_big(false, meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| DataError::io(path, e))?;
    if bytes.len() as u64 > max {
        return Err(too_big(true, max));
    }
    Ok(bytes)
}

/// [`read_user_file`] as UTF-8 text: a file that is not UTF-8 is refused at the line where it
/// stops being so, and a UTF-16 file (by its byte-order mark, or zero bytes between ASCII
/// ones) is named as such. A UTF-8 byte-order mark is dropped.
pub fn read_user_text(path: &Path, what: &str, max: u64) -> Result<String, DataError> {
    let bytes = read_user_file(path, what, max)?;
    utf8_text(path, what, bytes)
}

/// The text of `bytes` read from `path`, or an error naming the line where they stop being
/// UTF-8 (and UTF-16 as such). A UTF-8 byte-order mark is dropped.
pub fn utf8_text(path: &Path, what: &str, bytes: Vec<u8>) -> Result<String, DataError> {
    if let Some(encoding) = utf16_encoding(&bytes) {
        return Err(DataError::Problems(vec![InputProblem::new(
            path,
            Some(1),
            None,
            format!("{what} is {encoding} text, not UTF-8 (expected UTF-8: save it as UTF-8, e.g. `iconv -f UTF-16 -t UTF-8`)"),
        )]));
    }
    match String::from_utf8(bytes) {
        Ok(s) => Ok(match s.strip_prefix('\u{feff}') {
            Some(rest) => rest.to_string(),
            None => s,
        }),
        Err(e) => {
            let valid = e.utf8_error().valid_up_to();
            let bytes = e.into_bytes();
            let line = 1 + bytes[..valid].iter().filter(|&&b| b == b'\n').count();
            Err(DataError::Problems(vec![InputProblem::new(
                path,
                Some(line),
                None,
                format!("the file is not valid UTF-8 text from this line on (expected {what} as a UTF-8 encoded file)"),
            )]))
        }
    }
}

/// "UTF-16LE" or "UTF-16BE" when `bytes` look like UTF-16 text: a byte-order mark, or a zero
/// byte in every other place of the first ASCII characters.
pub fn utf16_encoding(bytes: &[u8]) -> Option<&'static str> {
    match bytes {
        [0xFF, 0xFE, ..] => return Some("UTF-16LE"),
        [0xFE, 0xFF, ..] => return Some("UTF-16BE"),
        _ => {}
    }
    let head = &bytes[..bytes.len().min(64) & !1];
    if head.len() < 4 {
        return None;
    }
    let pairs = head.chunks_exact(2);
    let le = pairs.clone().all(|p| p[1] == 0 && p[0] != 0);
    let be = pairs.clone().all(|p| p[0] == 0 && p[1] != 0);
    if le {
        Some("UTF-16LE")
    } else if be {
        Some("UTF-16BE")
    } else {
        None
    }
}

/// What a path names, for messages that say what is there instead of "absent".
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathKind {
    /// Nothing.
    Absent,
    /// A symbolic link whose target does not exist.
    DanglingLink,
    /// A regular file (possibly through a symbolic link).
    File,
    /// A folder.
    Folder,
    /// A FIFO, socket or device.
    Special,
}

impl PathKind {
    /// What `path` names (following symbolic links).
    pub fn of(path: &Path) -> PathKind {
        match std::fs::metadata(path) {
            Ok(m) if m.is_file() => PathKind::File,
            Ok(m) if m.is_dir() => PathKind::Folder,
            Ok(_) => PathKind::Special,
            Err(_) => match std::fs::symlink_metadata(path) {
                Ok(_) => PathKind::DanglingLink,
                Err(_) => PathKind::Absent,
            },
        }
    }

    /// A phrase for messages: "is absent", "is a folder", ...
    pub fn describe(self) -> &'static str {
        match self {
            PathKind::Absent => "is absent",
            PathKind::DanglingLink => "is a symbolic link to nothing",
            PathKind::File => "is a file",
            PathKind::Folder => "is a folder, not a file",
            PathKind::Special => "is not a regular file (a FIFO, socket or device)",
        }
    }
}

/// Why `file` (inside the set folder `dir`) cannot be read as a data file of the set, if it
/// cannot: not a regular file, or a symbolic link leading out of the set folder (whose target
/// is then never opened).
pub fn set_file_problem(dir: &Path, file: &Path) -> Option<String> {
    let kind = PathKind::of(file);
    if kind != PathKind::File {
        return Some(kind.describe().to_string());
    }
    let is_link = std::fs::symlink_metadata(file)
        .map(|m| m.file_type().is_symlink())
        .unwrap_or(false);
    let inside = match (std::fs::canonicalize(dir), std::fs::canonicalize(file)) {
        (Ok(d), Ok(f)) => f.starts_with(d),
        _ => false,
    };
    if !inside {
        return Some(format!(
            "{} outside the set folder (expected the set's own files inside {})",
            if is_link {
                "is a symbolic link that leads"
            } else {
                "lies"
            },
            dir.display()
        ));
    }
    None
}

/// A file given where a set folder is expected: a sentence that says so, what a set folder
/// holds, and which folder (or command) was probably meant.
pub(crate) fn file_not_folder(path: &Path) -> Option<InputProblem> {
    if PathKind::of(path) != PathKind::File {
        return None;
    }
    let parent = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let hint = if parent.join(EXPERIMENT_JSON).is_file() {
        format!(
            "this file is in the set folder {}: give that folder",
            parent.display()
        )
    } else {
        "a laboratory export becomes a set with `subfric import`".to_string()
    };
    Some(InputProblem::new(
        path,
        None,
        None,
        format!(
            "this is a file, and a set folder was expected: a set is a folder holding {} and one CSV per test (docs/data-format.md); {hint}",
            EXPERIMENT_JSON
        ),
    ))
}
