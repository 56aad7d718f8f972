//! What a set's results folder says about itself, so that a campaign run again skips what is
//! still current: `campaign-set.json` holds the SHA-256 of each input file (experiment.json and
//! every CSV it names, as `sha256sum` prints them), and for the fit and the diagnosis the options
//! they ran with, a key (the SHA-256 of subfric's version, the inputs' hashes and those options)
//! and whether they succeeded, with the error when not. The record is written last, after the
//! results it describes: a folder whose record matches the inputs and options of today holds
//! their results.

use crate::folders::io::write_json;
use anyhow::{anyhow, Result};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use sha2::{Digest, Sha256};
use std::path::Path;
use subfric_data::fsio::{read_user_file, MAX_DATA_FILE_BYTES, MAX_SETTINGS_FILE_BYTES};
use subfric_data::{load_set, parse_meta, ExperimentMeta, EXPERIMENT_JSON};

/// The record of a set's results folder.
pub const RECORD_FILE: &str = "campaign-set.json";

/// One input file and the SHA-256 of its bytes.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct InputFile {
    /// Name inside the set folder.
    pub file: String,
    /// SHA-256, lowercase hexadecimal.
    pub sha256: String,
}

/// Whether a part of a set's work succeeded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PartStatus {
    /// Its results are in the folder.
    Done,
    /// It failed; the error is recorded.
    Failed,
}

/// The fit or the diagnosis of a set, as recorded.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartRecord {
    /// SHA-256 of subfric's version, the inputs' hashes and the options.
    pub key: String,
    /// The options it ran with.
    pub options: Value,
    /// Whether it succeeded.
    pub status: PartStatus,
    /// The error, when it failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// `campaign-set.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SetRecord {
    /// The set's results folder name.
    pub set: String,
    /// The version of subfric that wrote it.
    pub subfric: String,
    /// The input files and their hashes.
    pub inputs: Vec<InputFile>,
    /// The fit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit: Option<PartRecord>,
    /// The diagnosis, when one was asked for.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diagnosis: Option<PartRecord>,
}

impl SetRecord {
    /// The record in `dir`, if there is a readable one (an unreadable one is as none: the set
    /// runs again).
    pub fn read(dir: &Path) -> Option<SetRecord> {
        let text =
            crate::folders::io::read_settings_text(&dir.join(RECORD_FILE), "the record").ok()?;
        serde_json::from_str(&text).ok()
    }

    /// Writes it to `dir` (atomically).
    pub fn write(&self, dir: &Path) -> Result<()> {
        write_json(&dir.join(RECORD_FILE), self)
    }
}

/// The inputs of the set in `dir`: its description (its errors named as `load_set` names them)
/// and every file it is read from, hashed.
pub fn read_inputs(dir: &Path) -> Result<(ExperimentMeta, Vec<InputFile>)> {
    let json = dir.join(EXPERIMENT_JSON);
    let bytes = match read_user_file(&json, EXPERIMENT_JSON, MAX_SETTINGS_FILE_BYTES) {
        Ok(b) => b,
        Err(e) => return Err(load_error(dir).unwrap_or_else(|| anyhow!("{e}"))),
    };
    let text = String::from_utf8_lossy(&bytes);
    let meta = parse_meta(&text, &json)?;
    let mut inputs = vec![InputFile {
        file: EXPERIMENT_JSON.to_string(),
        sha256: sha256_hex(&bytes),
    }];
    for t in &meta.tests {
        let path = dir.join(&t.file);
        let bytes = read_user_file(&path, "the test's CSV", MAX_DATA_FILE_BYTES)
            .map_err(|e| load_error(dir).unwrap_or_else(|| anyhow!("{e}")))?;
        inputs.push(InputFile {
            file: t.file.clone(),
            sha256: sha256_hex(&bytes),
        });
    }
    Ok((meta, inputs))
}

/// The error loading the set gives, when it gives one (a missing test file is located at its
/// line of experiment.json there).
fn load_error(dir: &Path) -> Option<anyhow::Error> {
    load_set(dir).err().map(anyhow::Error::from)
}

/// SHA-256 of `bytes`, lowercase hexadecimal.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The key of a part (`"fit"` or `"diagnosis"`) run with `options` on `inputs`.
pub fn part_key(part: &str, inputs: &[InputFile], options: &Value) -> String {
    let what = serde_json::json!({
        "subfric": env!("CARGO_PKG_VERSION"),
        "part": part,
        "inputs": inputs,
        "options": options,
    });
    sha256_hex(what.to_string().as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hashes_are_those_sha256sum_prints() {
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn keys_change_with_any_input_or_option() {
        let a = vec![InputFile {
            file: "a.csv".into(),
            sha256: sha256_hex(b"1"),
        }];
        let b = vec![InputFile {
            file: "a.csv".into(),
            sha256: sha256_hex(b"2"),
        }];
        let o1 = serde_json::json!({"seed": 1});
        let o2 = serde_json::json!({"seed": 2});
        let k = part_key("fit", &a, &o1);
        assert_eq!(k, part_key("fit", &a, &o1));
        assert_ne!(k, part_key("fit", &b, &o1));
        assert_ne!(k, part_key("fit", &a, &o2));
        assert_ne!(k, part_key("diagnosis", &a, &o1));
    }
}
