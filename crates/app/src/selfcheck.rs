//! The diagnosis scored on sets whose truth is known (`subfric selfcheck`): sets made by the
//! independent generator of `subfric-harness` (its own forward model of the paper, effects in
//! forms from the friction literature, rig and logger artifacts), or a folder of sets with a
//! `truth.json`. `selfcheck --write DIR` writes a generated campaign for `--sets` to score.

mod score;

use crate::diagnose::check_diagnosis_finite;
use crate::folders::io::write_json;
use crate::progress::{Progress, Silent};
use crate::truncate;
use anyhow::{anyhow, bail, Result};
use serde_json::Value;
use std::path::{Path, PathBuf};
use subfric_data::PathKind;
use subfric_diagnose::{prepare_for_diagnosis, DiagnoseOptions, Effect};
use subfric_harness::generator::{
    all_classes, campaign_set, classes_of, write_campaign, Class, Form, Generated, Options,
};

pub use score::{score, Case, Scores};

pub use subfric_harness::generator::Layout;

/// Which generated sets: classes by their 1-based numbers (all when empty), sets per class,
/// seed.
#[derive(Clone, Debug)]
pub struct Campaign {
    /// Class numbers, from 1 (all when empty); [`class_list`] numbers them.
    pub classes: Vec<usize>,
    /// Sets per class; set k of class c has the rig-and-logger profile number c + k, in turn
    /// (lab, clean, logger, rig).
    pub per_class: usize,
    /// Seed (each set has its own, derived from it, its class and its number).
    pub seed: u64,
    /// What tests each set holds (a mixed campaign, or a direct-shear programme).
    pub layout: Layout,
}

/// What to score.
#[derive(Clone, Debug)]
pub enum SelfcheckSource {
    /// Sets generated here.
    Generated {
        /// Which.
        campaign: Campaign,
        /// Diagnose each set without the library forms the generator's forms reduce to (is
        /// the family still named through its other forms?).
        unlisted: bool,
    },
    /// The sets of a folder, scored against its `truth.json`.
    Folder {
        /// The folder.
        root: PathBuf,
        /// The diagnoses' seed (as `diagnose --seed`): scored at two seeds, a folder tells
        /// which verdicts move with the fits' random start.
        seed: u64,
    },
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

/// The classes a campaign of `layout` can hold, numbered from 1 as `--classes` takes them
/// (a direct-shear programme leaves out the effects its tests cannot show; the others keep
/// their numbers).
pub fn class_list(layout: Layout) -> Vec<(usize, String)> {
    classes_of(layout)
        .iter()
        .map(|(i, c)| (i + 1, layout.class_label(c)))
        .collect()
}

/// The library forms (by name, as `diagnose --without-form` takes them) that a generator form
/// reduces to: what `selfcheck --unlisted` takes out of the library. The generator's own
/// variants (readings, targets, additive or multiplicative) all map onto their law.
pub fn library_equivalents(form: Form) -> &'static [&'static str] {
    match form {
        Form::RsfAgeing => &[
            "rate and state, ageing law",
            "rate and state, ageing law, locked at rest",
        ],
        Form::RsfSlip => &[
            "rate and state, slip law",
            "rate and state, slip law, locked at rest",
        ],
        Form::RatePower => &["power law ((v + v_c)/v_ref)^n", "power law, locked at rest"],
        Form::RateLog => &[
            "direct effect a ln(1 + v/v_c)",
            "direct effect, locked at rest",
            "steady state only, mu_k + a ln(v/v_ref)",
        ],
        Form::PressurePower => &[
            "power law on mu, (p/p_ref)^-beta",
            "power law on mu_s only",
            "power law on mu_k only",
        ],
        Form::PressureLinear => &[
            "linear on mu, 1 - beta (p/p_ref - 1)",
            "linear on mu_s only",
            "linear on mu_k only",
        ],
        Form::PressureExp => &["exponential on mu, exp(-beta (p/p_ref - 1))"],
        Form::SlipExp => &["exponential, h s_h (1 - exp(-s/s_h))"],
        Form::SlipHyperbolic => &["hyperbolic, h s / (1 + s/s_h)"],
        Form::SlipCapped => &["capped linear, h min(s, s_h)"],
        Form::HealLog => &[
            "log time, b ln(1 + t/t_c) at rest",
            "log time at rest, added to the recovery xi",
            "log time at rest, a gain of its own erased by slip over d_h",
        ],
        Form::HealPower => &[
            "power-law time, b t^n at rest",
            "power-law time at rest, added to the recovery xi",
            "general time, b ((1 + t/t_c)^n - 1)/n at rest",
            "general time at rest, a gain of its own erased by slip over d_h",
        ],
        Form::DirectionMu => &["backward mu x (1 - d)"],
        Form::DirectionMuK => &["backward mu_k x (1 - d)"],
        Form::DirectionKappa => &["backward kappa x (1 - d)"],
        Form::Drift | Form::Vibration | Form::Creep => &[],
    }
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
        SelfcheckSource::Folder { root, seed } => {
            let opts = DiagnoseOptions {
                seed: *seed,
                ..DiagnoseOptions::default()
            };
            score_folder(root, &opts, on_case, progress)?
        }
        SelfcheckSource::Generated { campaign, unlisted } => {
            score_generated(campaign, *unlisted, on_case)?
        }
    };
    if let Some(j) = &req.json {
        write_json(j, &serde_json::json!({"cases": cases, "scores": scores}))?;
    }
    Ok((cases, scores))
}

/// The classes numbered `numbers` (from 1; all that `layout` can show when empty), with their
/// numbers from 0.
fn chosen_classes(numbers: &[usize], layout: Layout) -> Result<Vec<(usize, Class)>> {
    if numbers.is_empty() {
        return Ok(classes_of(layout));
    }
    let all = all_classes();
    numbers
        .iter()
        .map(|&k| match all.get(k.wrapping_sub(1)) {
            Some(c) if c.iter().all(|f| layout.shows(*f)) => Ok((k - 1, c.clone())),
            Some(c) => bail!(
                "--classes {k}: {} cannot show in a direct-shear programme (monotonic tests at \
                 one rate, no holds or reversals; expected one of {})",
                layout.class_label(c),
                numbers_of(layout)
            ),
            None => bail!(
                "--classes {k}: no such class (expected numbers from 1 to {})",
                all.len()
            ),
        })
        .collect()
}

/// The class numbers of `layout`, from 1, as a list for a message.
fn numbers_of(layout: Layout) -> String {
    classes_of(layout)
        .iter()
        .map(|(i, _)| (i + 1).to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Every set of `campaign`, generated one at a time and handed to `each`.
fn for_each_set(campaign: &Campaign, mut each: impl FnMut(Generated) -> Result<()>) -> Result<()> {
    let opts = Options {
        layout: campaign.layout,
        ..Options::default()
    };
    for (ci, class) in chosen_classes(&campaign.classes, campaign.layout)? {
        for k in 0..campaign.per_class {
            let g = campaign_set(campaign.seed, ci, k, &class, &opts)
                .map_err(|e| anyhow!("generating set {k} of class {}: {e}", ci + 1))?;
            each(g)?;
        }
    }
    Ok(())
}

/// A line per written set: its name, profile, rows and truth.
pub struct WrittenSet {
    /// Set name (its folder).
    pub name: String,
    /// Rig-and-logger profile.
    pub profile: String,
    /// Rows over all tests.
    pub rows: usize,
    /// The truth in words.
    pub truth: String,
}

/// `selfcheck --write DIR`: generates `campaign` and writes it to the new folder `dir`, a
/// folder per set and `truth.json` (which `selfcheck --sets DIR` scores). Nothing is
/// diagnosed.
pub fn write_generated(dir: &Path, campaign: &Campaign) -> Result<Vec<WrittenSet>> {
    if PathKind::of(dir) != PathKind::Absent {
        bail!("--write {}: exists (expected a new folder)", dir.display());
    }
    let mut sets = Vec::new();
    for_each_set(campaign, |g| {
        sets.push(g);
        Ok(())
    })?;
    write_campaign(dir, &sets).map_err(|e| anyhow!("--write {}: {e}", dir.display()))?;
    Ok(sets
        .iter()
        .map(|g| WrittenSet {
            name: g.set.meta.name.clone(),
            profile: profile_name(&g.truth.json),
            rows: g.set.tests.iter().map(|t| t.len()).sum(),
            truth: g.truth.label.clone(),
        })
        .collect())
}

/// The profile a truth entry names (`artifacts.profile`), else "mid-run" for a set cut from a
/// longer run, else nothing.
fn profile_name(entry: &Value) -> String {
    match entry["artifacts"]["profile"].as_str() {
        Some(p) => p.to_string(),
        None if entry["midrun"].as_bool() == Some(true) => "mid-run".into(),
        None => String::new(),
    }
}

/// The families of a truth entry: `{"effects": [names]}` or `{"effect": name}`; "none" is no
/// effect, a name outside the library (a drift) counts as `unexplained`. `None` when it holds
/// neither key.
fn truth_families(entry: &Value) -> Option<(Vec<Effect>, String)> {
    let names: Vec<&str> = match (entry["effect"].as_str(), entry["effects"].as_array()) {
        (_, Some(list)) => list.iter().filter_map(|v| v.as_str()).collect(),
        (Some(e), None) => vec![e],
        (None, None) => return None,
    };
    let families: Vec<Effect> = names
        .iter()
        .map(|e| Effect::from_name(e).unwrap_or(Effect::Unexplained))
        .filter(|e| *e != Effect::None)
        .collect();
    // With the forms named: "rate (rsf-ageing-creep) + pressure (pressure-power-mu)".
    let label = match (entry["forms"].as_array(), entry["form"].as_str()) {
        (Some(forms), _) if !forms.is_empty() => forms
            .iter()
            .map(|f| {
                format!(
                    "{} ({})",
                    f["effect"].as_str().unwrap_or("?"),
                    f["form"].as_str().unwrap_or("?")
                )
            })
            .collect::<Vec<_>>()
            .join(" + "),
        (_, Some(form)) if names.len() == 1 && form != names[0] && form != "none" => {
            format!("{} ({form})", names[0])
        }
        _ => names.join(" + "),
    };
    Some((families, label))
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
    let text = crate::folders::io::read_settings_text(&truth_path, "the truth file")
        .map_err(|e| anyhow!("{e}; expected {{\"set\": {{\"effect\": name}}}}"))?;
    let truth: Value = serde_json::from_str(&text)
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
            Some((families, label)) => {
                let profile = profile_name(&truth[&name]);
                jobs.push((d, name, families, label, profile))
            }
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
    for (d, name, families, label, profile) in jobs {
        let diag = crate::diagnose::diagnose(&d, opts, &Silent)?.diagnosis;
        let mut c = Case::new(&name, families, label, &diag);
        c.profile = profile;
        on_case(&c);
        cases.push(c);
    }
    let s = score(&cases);
    Ok((cases, s))
}

/// Generates each set of `campaign`, diagnoses it (without the equivalents of its forms when
/// `unlisted`) and scores it. A diagnosis that fails or ends non-finite is an error naming the
/// set.
fn score_generated(
    campaign: &Campaign,
    unlisted: bool,
    on_case: &dyn Fn(&Case),
) -> Result<(Vec<Case>, Scores)> {
    let mut cases = Vec::new();
    let mut number = 0u64;
    for_each_set(campaign, |g| {
        number += 1;
        let mut opts = DiagnoseOptions {
            seed: campaign.seed.wrapping_add(number),
            ..DiagnoseOptions::default()
        };
        if unlisted {
            opts.excluded_forms = g
                .truth
                .forms
                .iter()
                .flat_map(|f| library_equivalents(*f).iter().map(|s| s.to_string()))
                .collect();
        }
        let c = diagnose_generated(&g, &opts)?;
        on_case(&c);
        cases.push(c);
        Ok(())
    })?;
    let s = score(&cases);
    Ok((cases, s))
}

/// The diagnosis of one generated set, scored.
pub fn diagnose_generated(g: &Generated, opts: &DiagnoseOptions) -> Result<Case> {
    let name = &g.set.meta.name;
    let d = subfric_diagnose::diagnose(&prepare_for_diagnosis(&g.set), opts)
        .map_err(|e| anyhow!("{name}: {e}"))?;
    check_diagnosis_finite(Path::new(name), &d)?;
    Ok(scored(g, &d))
}

/// Diagnosis `d` of generated set `g` scored against its truth (a drift counts as
/// `unexplained`).
pub fn scored(g: &Generated, d: &subfric_diagnose::Diagnosis) -> Case {
    let families = g
        .truth
        .families
        .iter()
        .map(|f| Effect::from_name(f).unwrap_or(Effect::Unexplained))
        .collect();
    let mut c = Case::new(&g.set.meta.name, families, g.truth.label.clone(), d);
    c.profile = profile_name(&g.truth.json);
    c
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
        Effect::every()
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
    // The label names the forms when the truth gives them (the dev families' schema).
    let label = truth_families(entry).map_or_else(|| names.join(" + "), |(_, label)| label);
    Ok(Some((families, label)))
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
        "{:<22} truth {:<56} verdict {:<30} {} {} shrink {:>4.0}%  ({:.1} s){}",
        crate::visible(&c.name),
        truncate(&crate::visible(&c.truth_label), 56),
        names(&c.verdict),
        if c.right() { "right" } else { "WRONG" },
        c.confidence
            .map_or("  -  ".to_string(), |p| format!("{:>3.0} %", 100.0 * p)),
        100.0 * c.shrink,
        c.elapsed_s,
        if c.profile.is_empty() {
            String::new()
        } else {
            format!("  [{}]", c.profile)
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_library_equivalent_is_a_form_of_the_library() {
        // A renamed library form would make --unlisted take out nothing, silently.
        let names = subfric_diagnose::candidates::all_form_names();
        let mut mapped = 0;
        for f in Form::ALL {
            for n in library_equivalents(f) {
                assert!(
                    names.contains(n),
                    "{f:?}: {n:?} is not in the library {names:?}"
                );
                mapped += 1;
            }
        }
        assert!(mapped >= 20);
        // Only the gaps outside every family have none.
        let without: Vec<Form> = Form::ALL
            .into_iter()
            .filter(|f| library_equivalents(*f).is_empty())
            .collect();
        assert_eq!(without, [Form::Drift, Form::Vibration, Form::Creep]);
    }

    #[test]
    fn truth_entries_of_both_schemas_are_read() {
        let old = serde_json::json!({"effect": "drift"});
        assert_eq!(
            truth_families(&old),
            Some((vec![Effect::Unexplained], "drift".into()))
        );
        let dev = serde_json::json!({"effect": "rate", "form": "rsf-slip", "effects": ["rate"]});
        assert_eq!(
            truth_families(&dev),
            Some((
                vec![Effect::from_name("rate").unwrap()],
                "rate (rsf-slip)".into()
            ))
        );
        let none = serde_json::json!({"effect": "none", "form": "none", "effects": ["none"]});
        assert_eq!(truth_families(&none), Some((vec![], "none".into())));
        let two = serde_json::json!({"effects": ["slip-hardening", "pressure"], "forms": [
            {"effect": "slip-hardening", "form": "slip-softening-exp-add"},
            {"effect": "pressure", "form": "pressure-linear-mu"}]});
        assert_eq!(
            truth_families(&two),
            Some((
                vec![
                    Effect::from_name("slip-hardening").unwrap(),
                    Effect::from_name("pressure").unwrap()
                ],
                "slip-hardening (slip-softening-exp-add) + pressure (pressure-linear-mu)".into()
            ))
        );
        assert_eq!(truth_families(&serde_json::json!({"other": 1})), None);
    }
}
