//! The diagnosis scored on sets whose truth is known: sets generated with withheld effects, or
//! a folder of sets with a `truth.json` (`subfric selfcheck`).

use crate::diagnose_report::truncate;
use crate::io::write_json;
use crate::progress::{Progress, Silent};
use anyhow::{anyhow, bail, Result};
use std::path::{Path, PathBuf};
use subfric_data::PathKind;
use subfric_diagnose::selfcheck::{all_classes, score, selfcheck, Case, Scores, SelfcheckOptions};
use subfric_diagnose::{DiagnoseOptions, Effect};

/// What to score.
#[derive(Clone, Debug)]
pub enum SelfcheckSource {
    /// Sets generated here: classes by their 1-based numbers (all when empty), sets per
    /// class, seed, and whether each set is diagnosed without the forms that made it.
    Generated {
        /// Class numbers, from 1 (all when empty).
        classes: Vec<usize>,
        /// Sets per class.
        per_class: usize,
        /// Seed.
        seed: u64,
        /// Diagnose each set without the candidate forms that generated it.
        unlisted: bool,
        /// Also write every generated set and a `truth.json` to this new folder.
        write_sets: Option<PathBuf>,
    },
    /// The sets of a folder, scored against its `truth.json`.
    Folder(PathBuf),
}

/// A self-check: what to score, and where to write the scores as JSON.
#[derive(Clone, Debug)]
pub struct SelfcheckRequest {
    /// The sets.
    pub source: SelfcheckSource,
    /// Write the cases and scores as JSON to this file.
    pub json: Option<PathBuf>,
    /// Replace an existing `json` file.
    pub force: bool,
}

/// Runs a self-check; `on_case` sees each case as soon as it is diagnosed, `progress` the
/// sets skipped. Every output path is checked before the first diagnosis.
pub fn run(
    req: &SelfcheckRequest,
    on_case: &dyn Fn(&Case),
    progress: &dyn Progress,
) -> Result<(Vec<Case>, Scores)> {
    if let Some(j) = &req.json {
        if PathKind::of(j) != PathKind::Absent && !req.force {
            bail!(
                "--json {}: exists (expected a new file, or --force to replace it)",
                j.display()
            );
        }
    }
    let (cases, scores) = match &req.source {
        SelfcheckSource::Folder(root) => {
            score_folder(root, &DiagnoseOptions::default(), on_case, progress)?
        }
        SelfcheckSource::Generated {
            classes,
            per_class,
            seed,
            unlisted,
            write_sets,
        } => {
            if let Some(w) = write_sets {
                if PathKind::of(w) != PathKind::Absent {
                    bail!(
                        "--write-sets {}: exists (expected a new folder)",
                        w.display()
                    );
                }
            }
            let opts = SelfcheckOptions {
                classes: chosen_classes(classes)?,
                per_class: *per_class,
                seed: *seed,
                unlisted: *unlisted,
                ..SelfcheckOptions::default()
            };
            run_generated(&opts, write_sets.as_deref(), on_case)?
        }
    };
    if let Some(j) = &req.json {
        write_json(j, &serde_json::json!({"cases": cases, "scores": scores}))?;
    }
    Ok((cases, scores))
}

/// The classes numbered `numbers` (from 1; all when empty).
fn chosen_classes(numbers: &[usize]) -> Result<Vec<subfric_diagnose::selfcheck::Class>> {
    let all = all_classes();
    if numbers.is_empty() {
        return Ok(all);
    }
    numbers
        .iter()
        .map(|&k| match all.get(k.wrapping_sub(1)) {
            Some(c) => Ok(c.clone()),
            None => bail!(
                "--classes {k}: no such class (expected numbers from 1 to {})",
                all.len()
            ),
        })
        .collect()
}

/// Diagnoses every set under `root` as `subfric diagnose` does ([`crate::diagnose()`]: a
/// diagnosis that ends non-finite is an error naming the set) and scores it against the
/// folder's truth.json (a set without a truth there is skipped, with a warning to `progress`).
pub fn score_folder(
    root: &Path,
    opts: &DiagnoseOptions,
    on_case: &dyn Fn(&Case),
    progress: &dyn Progress,
) -> Result<(Vec<Case>, Scores)> {
    let truth_path = root.join("truth.json");
    let text = std::fs::read_to_string(&truth_path).map_err(|e| {
        anyhow!(
            "{}: cannot read ({e}); expected {{\"set\": {{\"effect\": name}}}}",
            truth_path.display()
        )
    })?;
    let truth: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| anyhow!("{}:{}:{}: {e}", truth_path.display(), e.line(), e.column()))?;
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("experiment.json").is_file())
        .collect();
    dirs.sort();
    // Every truth is read before the first diagnosis: a label that is not an effect is an
    // error naming the set, not a case scored as something else.
    let mut jobs = Vec::new();
    for d in dirs {
        let name = d
            .file_name()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        match truth_of(&truth, &name, &truth_path)? {
            Some((families, label)) => jobs.push((d, name, families, label)),
            None => progress.warning(&format!(
                "{}: no truth in {}, skipped",
                crate::visible(&name),
                truth_path.display()
            )),
        }
    }
    if jobs.is_empty() {
        bail!(
            "{}: no set of {} has a truth there (expected {{\"<set folder>\": {{\"effect\": name}}}} for the sets to score)",
            truth_path.display(),
            root.display()
        );
    }
    let mut cases = Vec::new();
    for (d, name, families, label) in jobs {
        let diag = crate::diagnose::diagnose(&d, opts, &Silent)?.diagnosis;
        let c = Case::new(&name, families, label, &diag);
        on_case(&c);
        cases.push(c);
    }
    let s = score(&cases);
    Ok((cases, s))
}

/// The truth of the set `name` in `truth.json` (`truth`, read from `path`): either
/// `{"effect": name}` or `{"effects": [names]}`, each an effect's name as in diagnosis.json
/// (`none`: no effect; `drift` or `unexplained`: a gap outside the library). `None`: no entry.
fn truth_of(
    truth: &serde_json::Value,
    name: &str,
    path: &Path,
) -> Result<Option<(Vec<Effect>, String)>> {
    let entry = &truth[name];
    let labels: Vec<&serde_json::Value> = match (&entry["effect"], entry["effects"].as_array()) {
        (_, Some(list)) => list.iter().collect(),
        (serde_json::Value::Null, None) => return Ok(None),
        (e, None) => vec![e],
    };
    let known = || {
        Effect::ALL
            .iter()
            .map(|e| e.name())
            .chain(["drift"])
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut names = Vec::new();
    let mut families = Vec::new();
    for v in labels {
        let effect = v.as_str().and_then(Effect::from_name).ok_or_else(|| {
            anyhow!(
                "{}: set `{}`: truth {} is not an effect subfric knows (expected one of {})",
                path.display(),
                crate::visible(name),
                crate::visible(&v.to_string()),
                known()
            )
        })?;
        names.push(v.as_str().unwrap_or_default());
        if effect != Effect::None {
            families.push(effect);
        }
    }
    Ok(Some((families, names.join(" + "))))
}

/// One line per diagnosed set: its truth, the verdict, right or wrong, the held-out shrink.
pub fn case_line(c: &Case) -> String {
    let names = |v: &[Effect]| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.iter().map(|e| e.name()).collect::<Vec<_>>().join(" + ")
        }
    };
    format!(
        "{:<22} truth {:<44} verdict {:<30} {} shrink {:>4.0}%  ({:.1} s){}",
        crate::visible(&c.name),
        truncate(&crate::visible(&c.truth_label), 44),
        names(&c.verdict),
        if c.right() { "right" } else { "WRONG" },
        100.0 * c.shrink,
        c.elapsed_s,
        match (c.lab_like, c.mid_run) {
            (true, true) => "  [lab-like, mid-run]",
            (true, false) => "  [lab-like]",
            (false, true) => "  [mid-run]",
            _ => "",
        }
    )
}

/// Runs the generated self-check; with `write_to`, every generated set is written there as a
/// folder, and their truths to `truth.json` (which `selfcheck --sets` reads).
fn run_generated(
    opts: &SelfcheckOptions,
    write_to: Option<&Path>,
    on_case: &dyn Fn(&Case),
) -> Result<(Vec<Case>, Scores)> {
    let truths = std::sync::Mutex::new(serde_json::Map::new());
    let failed = std::sync::Mutex::new(None::<anyhow::Error>);
    let keep = |set: &subfric_data::ExperimentSet, truth: &subfric_diagnose::synth::Truth| {
        let Some(root) = write_to else { return };
        let dir = root.join(&set.meta.name);
        if let Err(e) = subfric_data::write_set(set, &dir) {
            failed.lock().expect("not poisoned").get_or_insert(e.into());
        }
        let names: Vec<&str> = if truth.effects.is_empty() {
            vec!["none"]
        } else {
            truth
                .effects
                .iter()
                .map(|b| match b.effect {
                    Effect::Unexplained => "drift",
                    e => e.name(),
                })
                .collect()
        };
        truths.lock().expect("not poisoned").insert(
            set.meta.name.clone(),
            serde_json::json!({"effects": names, "label": truth.label(), "model": truth.model}),
        );
    };
    let result = selfcheck(opts, on_case, &keep);
    if let Some(e) = failed.into_inner().expect("not poisoned") {
        return Err(e);
    }
    if let Some(root) = write_to {
        let truths = truths.into_inner().expect("not poisoned");
        write_json(&root.join("truth.json"), &serde_json::Value::Object(truths))?;
    }
    Ok(result)
}
