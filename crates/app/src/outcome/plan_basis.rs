//! The model a plan rests on: the one the set's diagnosis chose when there is a diagnosis,
//! else the base model of the paper. Planning tests for a model that does not describe the
//! data would determine parameters that mean nothing, so `subfric plan` reads
//! `fits/<set>/diagnosis/diagnosis.json` (or the file `--diagnosis` names) and fits the model
//! with the effects it named.
//! What a plan says when that model misses the data ([`misfit_warning`]) is here too, below
//! both the plan and its report.

use crate::folders::output::{default_results_dir, holds_results_of};
use crate::outcome::adequacy::{misfit_number, Adequacy};
use anyhow::{anyhow, bail, Result};
use std::path::{Path, PathBuf};
use subfric_fit::Param;
use subfric_model::{model_from_json, Model};

/// The model a plan rests on, and where it comes from.
#[derive(Clone, Debug, Default)]
pub struct Basis {
    /// The diagnosis read, if any.
    pub diagnosis: Option<PathBuf>,
    /// The diagnosis's verdict (`rate`, `none`, `unexplained`, …), if any.
    pub verdict: Option<String>,
    /// The effects the diagnosis named, in words ("rate (power law …)"); empty: the base model.
    pub effects: Vec<String>,
    /// The model with those effects (the start of the fit), `None` for the base model.
    pub start: Option<Model>,
    /// Parameters fitted beyond the five of the paper (the effects', α_t when the diagnosis
    /// fitted it).
    pub extra_free: Vec<Param>,
    /// A note on a diagnosis found but not used, for the user.
    pub note: Option<String>,
    /// How sure the diagnosis is of its verdict (the probability it is exactly right).
    pub confidence: Option<f64>,
    /// The diagnosis's other explanations: (label, probability, the test that would tell
    /// them apart).
    pub alternatives: Vec<(String, f64, String)>,
}

impl Basis {
    /// "the model with rate", or "the base model".
    pub fn model_words(&self) -> String {
        if self.effects.is_empty() {
            "the base model".into()
        } else {
            format!("the model with {}", self.effects.join(" + "))
        }
    }

    /// One line on what the plan rests on.
    pub fn line(&self) -> String {
        match (&self.diagnosis, &self.verdict) {
            (Some(f), Some(v)) if !self.effects.is_empty() => format!(
                "planned on {} (the diagnosis {} named {v})",
                self.model_words(),
                f.display()
            ),
            (Some(f), Some(v)) if v == "cannot-judge" => format!(
                "planned on the base model (the diagnosis {} could not judge which effect is missing: see its verdict)",
                f.display()
            ),
            (Some(f), Some(v)) => format!(
                "planned on the base model (the diagnosis {} found {})",
                f.display(),
                if v == "none" {
                    "no missing effect".to_string()
                } else {
                    format!("no effect that explains the gap: {v}")
                }
            ),
            _ => "planned on the base model of the paper (no diagnosis of this set)".into(),
        }
    }
}

impl Basis {
    /// What a plan on a model that does not describe the data says first: the model must
    /// change before its parameters mean anything, what the diagnosis found and how sure it
    /// is, and the tests that would tell its leading explanations apart.
    pub fn must_change_lines(&self) -> Vec<String> {
        let (Some(f), Some(v)) = (&self.diagnosis, &self.verdict) else {
            return Vec::new();
        };
        let sure = self
            .confidence
            .map(|c| format!(" (how sure: {:.0} %)", 100.0 * c))
            .unwrap_or_default();
        let found = match v.as_str() {
            "unexplained" => "no effect that explains the gap".to_string(),
            "cannot-judge" => "that the data cannot tell which effect is missing".to_string(),
            v => format!("{v}, and the model with it still misses the data"),
        };
        let mut lines = vec![format!(
            "the model must change first: its parameters mean nothing while it misses the data; the diagnosis {} found {found}{sure}",
            f.display()
        )];
        for (label, p, tell) in &self.alternatives {
            lines.push(format!("  or {label} ({:.0} %): {tell}", 100.0 * p));
        }
        lines
    }
}

/// The warning of a plan on a model that does not describe the data (`None` when it does).
pub fn misfit_warning(a: &Adequacy, basis: &Basis, set: &Path) -> Option<String> {
    if a.describes() {
        return None;
    }
    let model = basis.model_words();
    let what = format!(
        "{model} misses these data by {}× the noise variance: the proposals below assume a model that does not describe them",
        misfit_number(a.reduced_chi2)
    );
    Some(if basis.diagnosis.is_none() {
        format!(
            "{what}; run `subfric diagnose {}` first, and `subfric plan` then plans on the model the diagnosis chooses",
            set.display()
        )
    } else if basis.verdict.as_deref() == Some("cannot-judge") {
        format!("{what}; the diagnosis could not judge which effect is missing, see its verdict")
    } else {
        format!("{what}; the diagnosis found no effect that closes the gap, see its report")
    })
}

/// The default diagnosis of a set: `fits/<set>/diagnosis/diagnosis.json`.
pub fn default_diagnosis(set_name: &str) -> PathBuf {
    default_results_dir(set_name)
        .join("diagnosis")
        .join("diagnosis.json")
}

/// The basis of a plan for the set `set` (folder) named `name`: the diagnosis in `explicit`
/// (an error when it cannot be read or is of another set), else the default one when it
/// exists and was written for this set folder, else the base model.
pub fn basis(set: &Path, name: &str, explicit: Option<&Path>) -> Result<Basis> {
    if let Some(f) = explicit {
        return read_basis(f, name);
    }
    let f = default_diagnosis(name);
    if !f.is_file() {
        return Ok(Basis::default());
    }
    let folder = f.parent().unwrap_or(Path::new("."));
    if !holds_results_of(folder, set) {
        return Ok(Basis {
            note: Some(format!(
                "{} is not a diagnosis of {} (its folder's record names another set folder): planned on the base model; give --diagnosis to use it",
                f.display(),
                set.display()
            )),
            ..Basis::default()
        });
    }
    read_basis(&f, name)
}

/// Reads a diagnosis.json written by `subfric diagnose` for the set `name`.
fn read_basis(f: &Path, name: &str) -> Result<Basis> {
    let text = crate::folders::io::read_settings_text(f, "the diagnosis")?;
    let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
        anyhow!(
            "{}:{}:{}: not valid JSON: {e} (expected a diagnosis.json written by subfric diagnose)",
            f.display(),
            e.line(),
            e.column()
        )
    })?;
    let set = json["set"].as_str().unwrap_or_default();
    if set != name {
        bail!(
            "{}: a diagnosis of set `{set}`, not of `{name}` (expected the diagnosis of the set planned for)",
            f.display()
        );
    }
    let missing = |what: &str| {
        anyhow!(
            "{}: no {what} (expected a diagnosis.json written by subfric diagnose)",
            f.display()
        )
    };
    let verdict = json["verdict"]["effect"]
        .as_str()
        .ok_or_else(|| missing("verdict.effect"))?
        .to_string();
    let d = &json["diagnosis"];
    let effects = d["verdict"]["effects"]
        .as_array()
        .ok_or_else(|| missing("diagnosis.verdict.effects"))?;
    let alternatives = json["verdict"]["alternatives"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|a| {
            Some((
                a["label"].as_str()?.to_string(),
                a["probability"].as_f64()?,
                a["tell_apart"].as_str().unwrap_or_default().to_string(),
            ))
        })
        .collect();
    let mut basis = Basis {
        diagnosis: Some(f.to_path_buf()),
        verdict: Some(verdict),
        confidence: json["verdict"]["confidence"].as_f64(),
        alternatives,
        ..Basis::default()
    };
    if effects.is_empty() {
        return Ok(basis);
    }
    for e in effects {
        let effect = e["effect"].as_str().unwrap_or("an effect");
        let form = e["form"].as_str().unwrap_or_default();
        basis.effects.push(format!("{effect} ({form})"));
        for key in e["parameters"]
            .as_object()
            .into_iter()
            .flat_map(|o| o.keys())
        {
            let q = Param::from_key(key).ok_or_else(|| {
                anyhow!(
                    "{}: effect `{effect}`: unknown parameter `{key}` (expected a diagnosis.json of this version of subfric)",
                    f.display()
                )
            })?;
            if !basis.extra_free.contains(&q) {
                basis.extra_free.push(q);
            }
        }
    }
    let fitted_alpha = d["base"]["free"]
        .as_array()
        .is_some_and(|a| a.iter().any(|k| k == "alpha_t"));
    if fitted_alpha {
        basis.extra_free.insert(0, Param::AlphaT);
    }
    let model = model_from_json(&d["final_model"].to_string())
        .map_err(|e| anyhow!("{}: diagnosis.final_model: {e}", f.display()))?;
    basis.start = Some(model);
    Ok(basis)
}
