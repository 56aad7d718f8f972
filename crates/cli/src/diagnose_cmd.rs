//! `subfric diagnose` and `subfric selfcheck`.

use crate::diagnose_report::{effects_label, report_text, truncate};
use crate::io::{write_json, write_text};
use anyhow::Result;
use std::path::{Path, PathBuf};
use subfric_data::load_set;
use subfric_diagnose::selfcheck::{score, selfcheck, Case, SelfcheckOptions};
use subfric_diagnose::{diagnose, prepare_for_diagnosis, DiagnoseOptions, Diagnosis, Effect};
use subfric_fit::PreparedTest;
use subfric_plot::{render_bars_png, BarFigure};

/// Diagnoses the set in `dir`; writes diagnosis.json and the plots under `out`.
pub fn run_diagnose(
    dir: &Path,
    out: &Path,
    opts: &DiagnoseOptions,
) -> Result<(Diagnosis, Vec<PathBuf>)> {
    let set = load_set(dir)?;
    let prepared = prepare_for_diagnosis(&set);
    let d = diagnose(&prepared, opts)?;
    write_json(
        &out.join("diagnosis.json"),
        &crate::api::diagnosis_json(&set.meta.name, &d),
    )?;
    write_text(
        &out.join("diagnosis.txt"),
        &(report_text(&set.meta.name, &d) + "\n"),
    )?;
    let mut plots = Vec::new();
    let label = effects_label(&d);
    plots.extend(crate::figures::diagnosis_figures(
        &set.meta.name,
        &prepared,
        &d.base.model,
        (!d.verdict.effects.is_empty()).then_some((&d.final_model, label.as_str())),
        &out.join("figures"),
    )?);
    let f = out.join("residual-by-segment.png");
    render_bars_png(&residual_by_segment(&set.meta.name, &d), &f)?;
    plots.push(f);
    let f = out.join("residual-by-test.png");
    render_bars_png(&residual_by_test(&set.meta.name, &d, &prepared), &f)?;
    plots.push(f);
    Ok((d, plots))
}

/// Residual by segment on all rows: the base model, and with the named effects.
fn residual_by_segment(name: &str, d: &Diagnosis) -> BarFigure {
    let segments = &d.localisation.by_segment;
    let cats: Vec<String> = segments.iter().map(|g| g.group.clone()).collect();
    let base: Vec<f64> = segments.iter().map(|g| g.rms_over_noise).collect();
    let mut fig = BarFigure::new(
        format!(
            "{name}: residual by segment (verdict: {})",
            d.verdict.effect
        ),
        "RMS residual / noise SD [-]",
        cats.clone(),
    )
    .with_group("base model (all rows)", base);
    if !d.verdict.effects.is_empty() {
        let after: Vec<f64> = cats
            .iter()
            .map(|c| {
                d.remaining_by_segment
                    .iter()
                    .find(|g| &g.group == c)
                    .map_or(f64::NAN, |g| g.rms_over_noise)
            })
            .collect();
        fig = fig.with_group(format!("with {} (all rows)", effects_label(d)), after);
    }
    fig.with_reference_line("noise level", 1.0)
}

/// Residual by test on the fitted rows: the base model, and with the named effects.
fn residual_by_test(name: &str, d: &Diagnosis, prepared: &[PreparedTest]) -> BarFigure {
    let by_test = &d.localisation.by_test;
    let tests: Vec<String> = by_test.iter().map(|g| g.group.clone()).collect();
    let mut fig = BarFigure::new(
        format!("{name}: residual by test"),
        "RMS residual / noise SD [-]",
        tests.clone(),
    )
    .with_group(
        "base model",
        by_test.iter().map(|g| g.rms_over_noise).collect(),
    );
    if !d.verdict.effects.is_empty() {
        let fitted: Vec<_> = prepared.iter().map(|p| p.fit.clone()).collect();
        let m = subfric_fit::misfits(&fitted, &d.final_model);
        let after = tests
            .iter()
            .map(|t| {
                m.iter()
                    .find(|x| &x.name == t)
                    .map_or(f64::NAN, |x| x.rms_over_noise)
            })
            .collect();
        fig = fig.with_group("with the named effects", after);
    }
    fig.with_reference_line("noise level", 1.0)
}

/// Diagnoses every set under `root` and scores against its truth.json.
pub fn score_folder(
    root: &Path,
    opts: &DiagnoseOptions,
) -> Result<(Vec<Case>, subfric_diagnose::selfcheck::Scores)> {
    let truth_path = root.join("truth.json");
    let text = std::fs::read_to_string(&truth_path).map_err(|e| {
        anyhow::anyhow!(
            "{}: cannot read ({e}); expected {{\"set\": {{\"effect\": name}}}}",
            truth_path.display()
        )
    })?;
    let truth: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
        anyhow::anyhow!("{}:{}:{}: {e}", truth_path.display(), e.line(), e.column())
    })?;
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("experiment.json").is_file())
        .collect();
    dirs.sort();
    let mut cases = Vec::new();
    for d in dirs {
        let name = d
            .file_name()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        // Either {"effect": name} or {"effects": [names]}; "none" is no effect, and a name
        // outside the library (a drift) counts as "unexplained".
        let entry = &truth[&name];
        let names: Vec<&str> = match (entry["effect"].as_str(), entry["effects"].as_array()) {
            (_, Some(list)) => list.iter().filter_map(|v| v.as_str()).collect(),
            (Some(e), None) => vec![e],
            (None, None) => {
                eprintln!("{name}: no truth in {}, skipped", truth_path.display());
                continue;
            }
        };
        let families: Vec<Effect> = names
            .iter()
            .map(|e| Effect::from_name(e).unwrap_or(Effect::Unexplained))
            .filter(|e| *e != Effect::None)
            .collect();
        let set = load_set(&d)?;
        let diag = diagnose(&prepare_for_diagnosis(&set), opts)?;
        let c = Case::new(&name, families, names.join(" + "), &diag);
        print_case(&c);
        cases.push(c);
    }
    let s = score(&cases);
    Ok((cases, s))
}

/// One line per diagnosed set.
fn print_case(c: &Case) {
    let names = |v: &[Effect]| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.iter().map(|e| e.name()).collect::<Vec<_>>().join(" + ")
        }
    };
    println!(
        "{:<22} truth {:<44} verdict {:<30} {} shrink {:>4.0}%  ({:.1} s){}",
        c.name,
        truncate(&c.truth_label, 44),
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
    );
}

/// Runs the generated self-check; with `write_to`, every generated set is written there as a
/// folder, and their truths to `truth.json` (which `selfcheck --sets` reads).
pub fn run_selfcheck(
    opts: &SelfcheckOptions,
    write_to: Option<&Path>,
) -> Result<(Vec<Case>, subfric_diagnose::selfcheck::Scores)> {
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
    let result = selfcheck(opts, &print_case, &keep);
    if let Some(e) = failed.into_inner().expect("not poisoned") {
        return Err(e);
    }
    if let Some(root) = write_to {
        let truths = truths.into_inner().expect("not poisoned");
        write_json(&root.join("truth.json"), &serde_json::Value::Object(truths))?;
    }
    Ok(result)
}
