//! Reading parameter files and writing results.

use anyhow::{anyhow, bail, Context, Result};
use serde::Serialize;
use std::path::Path;
use subfric_data::{write_atomic, PathKind};
use subfric_model::{model_from_json, Model, ModelJsonError};

/// Reads a model from a parameter file with the workspace's one reader
/// ([`subfric_model::model_from_json`]): a `params.json` (keys of `reference_parameters`), a
/// `fit.json` written by `subfric fit` (its `model`), a model object `{"params", "ext"}` or an
/// `experiment.json` (its `reference_parameters`). Errors start with the file's path (and the
/// line and column of a JSON syntax error).
pub fn load_model(path: &Path) -> Result<Model> {
    let kind = PathKind::of(path);
    if kind != PathKind::File {
        bail!(
            "{}: the parameter file {} (expected a JSON file)",
            path.display(),
            kind.describe()
        );
    }
    let text = read_settings_text(path, "the parameter file")?;
    model_from_json(&text).map_err(|e| match e {
        ModelJsonError::Syntax {
            line,
            column,
            message,
        } => anyhow!(
            "{}:{line}:{column}: not valid JSON: {message} (expected an object with mu_s, mu_k, kappa, xi, u_tilde, alpha_t)",
            path.display()
        ),
        ModelJsonError::Duplicate { key, line, column } => anyhow!(
            "{}:{line}:{column}: field `{key}` appears twice (expected each field once: which of the two values is meant?)",
            path.display()
        ),
        e => anyhow!("{}: {e}", path.display()),
    })
}

/// Reads a settings or results file a user names or subfric wrote (a parameter file, a
/// diagnosis.json, a scenario, a manifest, a record) as UTF-8 text, with the one reader of
/// user files ([`subfric_data::fsio::read_user_text`]): a regular file of at most
/// [`subfric_data::fsio::MAX_SETTINGS_FILE_BYTES`], never a FIFO or a device (which would
/// block or never end). `what` names it in messages ("the diagnosis").
pub fn read_settings_text(path: &Path, what: &str) -> Result<String> {
    subfric_data::fsio::read_user_text(path, what, subfric_data::fsio::MAX_SETTINGS_FILE_BYTES)
        .map_err(|e| {
            anyhow!(
                "{}",
                e.problems()
                    .first()
                    .map_or_else(|| e.to_string(), |p| p.to_string())
            )
        })
}

/// Writes pretty JSON, creating the folder; atomically (see [`write_text`]).
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    write_text(path, &(text + "\n"))
}

/// Writes a text file, creating the folder. The text goes to a temporary file in the same
/// folder, flushed, then renamed over `path`: a full disk or a kill leaves the old file whole,
/// and a symbolic link at `path` is replaced, not written through.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        refuse_link(dir, "the folder written")?;
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow!("{}: cannot create the folder: {e}", dir.display()))?;
    }
    write_atomic(path, text.as_bytes()).map_err(|e| anyhow!("cannot write {e}"))
}

/// Removes the files ending in `.ext` directly in `dir` (none when `dir` does not exist): the
/// results of an earlier run in a folder this process has claimed, which would otherwise be
/// read as this run's (figures of other events, scenarios of other proposals).
pub fn remove_earlier_files(dir: &Path, ext: &str) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    for e in entries.flatten() {
        if e.path().extension().is_some_and(|x| x == ext) {
            std::fs::remove_file(e.path())
                .with_context(|| format!("{}: cannot remove it", e.path().display()))?;
        }
    }
    Ok(())
}

/// Refuses a symbolic link at `dir` (`what` names it): subfric writes its results into the
/// folder it is given, never through a link planted at that name (which may lead anywhere).
/// Folders above it may be links (`/tmp` on some systems, a home folder on another disk).
pub fn refuse_link(dir: &Path, what: &str) -> Result<()> {
    if std::fs::symlink_metadata(dir).is_ok_and(|m| m.file_type().is_symlink()) {
        bail!(
            "{}: {what} is a symbolic link (expected a folder: subfric never writes through a link; give the folder it leads to, {}, instead)",
            dir.display(),
            std::fs::read_link(dir).map_or_else(|_| "?".into(), |t| t.display().to_string())
        );
    }
    Ok(())
}
