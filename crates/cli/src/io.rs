//! Reading parameter files and writing results.

use anyhow::{anyhow, bail, Context, Result};
use serde::Serialize;
use std::path::Path;
use subfric_data::{write_atomic, PathKind};
use subfric_model::{Extensions, Model, Params};

/// Reads a model from `params.json` (keys of `reference_parameters`), a `fit.json` written by
/// `subfric fit` (its `model`), or an `experiment.json` (its `reference_parameters`).
pub fn load_model(path: &Path) -> Result<Model> {
    let kind = PathKind::of(path);
    if kind != PathKind::File {
        bail!(
            "{}: the parameter file {} (expected a JSON file)",
            path.display(),
            kind.describe()
        );
    }
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read the parameter file", path.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
        anyhow!(
            "{}:{}:{}: not valid JSON: {} (expected an object with mu_s, mu_k, kappa, xi, u_tilde, alpha_t)",
            path.display(),
            e.line(),
            e.column(),
            e
        )
    })?;
    model_from_json(&v, &path.display().to_string())
}

/// A model from the JSON value of a `params.json` (keys of `reference_parameters`), a
/// `fit.json` (its `model`: parameters and extensions) or an `experiment.json` (its
/// `reference_parameters`); `origin` names where the value came from in messages (a file).
pub fn model_from_json(v: &serde_json::Value, origin: &str) -> Result<Model> {
    let (obj, ext) = if let Some(m) = v.get("model") {
        (
            m.get("params").cloned().unwrap_or_default(),
            m.get("ext").cloned(),
        )
    } else if let Some(r) = v.get("reference_parameters") {
        (r.clone(), None)
    } else {
        (v.clone(), None)
    };
    if !obj.is_object() {
        bail!("{origin}: expected a JSON object of parameters (mu_s, mu_k, kappa, xi, u_tilde, alpha_t, ...)");
    }
    for key in ["mu_s", "mu_k", "kappa", "xi", "u_tilde", "alpha_t"] {
        match obj.get(key) {
            None => bail!("{origin}: field `{key}` is missing (expected a number)"),
            Some(x) if !x.is_number() => {
                bail!("{origin}: field `{key}` is {x} (expected a number)")
            }
            _ => {}
        }
    }
    let params: Params = serde_json::from_value(obj).map_err(|e| anyhow!("{origin}: {e}"))?;
    let ext: Extensions = match ext {
        Some(e) => {
            serde_json::from_value(e).map_err(|e| anyhow!("{origin}: field `model.ext`: {e}"))?
        }
        None => Extensions::default(),
    };
    Model::new(params, ext).map_err(|e| anyhow!("{origin}: {e}"))
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
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow!("{}: cannot create the folder: {e}", dir.display()))?;
    }
    write_atomic(path, text.as_bytes()).map_err(|e| anyhow!("cannot write {e}"))
}
