//! The diagnosis of a set: where the calibrated model misses, which unmodelled effect explains
//! it and how far it shrinks. [`diagnose()`] returns it with the content of `diagnosis.json`;
//! [`diagnose_to_folder`] writes `diagnosis.json`, `diagnosis.txt` and the figures as
//! `subfric diagnose` does. A diagnosis that ends with a number that is not finite is refused,
//! and nothing of it is written.

use crate::folders::io::{write_json, write_text};
use crate::folders::output::{default_results_dir, Destination, ResultsDir};
use crate::located;
use crate::progress::Progress;
use crate::render::diagnose_report::{effects_label, report_text};
use crate::replicates::{replicate, Replicates, SeedVerdict};
use anyhow::{bail, Result};
use serde_json::Value;
use std::path::{Path, PathBuf};
use subfric_data::{load_set, plausibility, ExperimentSet, Warning};
use subfric_diagnose::{
    diagnose_reporting, prepare_for_diagnosis, DiagnoseOptions, Diagnosis, Step,
};
use subfric_fit::RunCounter;
use subfric_plot::{write_figure, BarFigure};
use subfric_reading::PreparedTest;

/// What a diagnosis folder holds; the per-test and per-event figures go to `figures/`,
/// claimed as a whole.
const DIAGNOSIS_FILES: [&str; 8] = [
    "diagnosis.json",
    "diagnosis.txt",
    crate::render::report::REPORT_FILE,
    "residual-by-segment.png",
    "residual-by-segment.svg",
    "residual-by-test.png",
    "residual-by-test.svg",
    "figures",
];

/// A diagnosis as `subfric diagnose` runs it, with the content of its `diagnosis.json`.
pub struct Diagnosed {
    /// The set's name.
    pub name: String,
    /// The diagnosis.
    pub diagnosis: Diagnosis,
    /// The tests as the diagnosis saw them.
    pub prepared: Vec<PreparedTest>,
    /// What `subfric diagnose` writes to `diagnosis.json`.
    pub json: Value,
    /// Plausibility warnings of the set (also given to the progress).
    pub warnings: Vec<Warning>,
    /// The verdict at further seeds of the fits' random start, when asked for
    /// (`diagnose --replicates`).
    pub replicates: Option<Replicates>,
}

/// `subfric diagnose` without output files: the diagnosis of the set in `dir`, refused (with
/// the set named) when it ends with a number that is not finite.
pub fn diagnose(dir: &Path, opts: &DiagnoseOptions, progress: &dyn Progress) -> Result<Diagnosed> {
    diagnose_replicated(dir, opts, 1, progress)
}

/// [`diagnose()`], and again at the seeds after `opts.seed` up to `replicates` diagnoses in all
/// (`diagnose --replicates`; 1: the diagnosis alone): whether the verdict moves with the fits'
/// random start ([`crate::replicates`]).
pub fn diagnose_replicated(
    dir: &Path,
    opts: &DiagnoseOptions,
    replicates: usize,
    progress: &dyn Progress,
) -> Result<Diagnosed> {
    let set = load_set(dir).map_err(|e| located(e.into(), dir))?;
    let warnings = warn(&set, progress);
    diagnose_set(dir, set, warnings, opts, replicates, progress)
}

/// The set's plausibility warnings, given to `progress` as well, after what was made of the
/// columns (units, further channels) as notes.
fn warn(set: &ExperimentSet, progress: &dyn Progress) -> Vec<Warning> {
    for t in &set.tests {
        for line in subfric_reading::reading_lines(t) {
            progress.note(&format!("{}: {line}", crate::visible(&t.spec.name)));
        }
    }
    let warnings = plausibility(set);
    for w in &warnings {
        progress.warning(&w.to_string());
    }
    warnings
}

/// Diagnoses the loaded `set` (read from `dir`, which errors name), and again at the seeds
/// after its own up to `replicates` runs in all (1: the diagnosis alone).
fn diagnose_set(
    dir: &Path,
    set: ExperimentSet,
    warnings: Vec<Warning>,
    opts: &DiagnoseOptions,
    replicates: usize,
    progress: &dyn Progress,
) -> Result<Diagnosed> {
    progress.stage("diagnosis: preparing the tests", None);
    let prepared = prepare_for_diagnosis(&set);
    let report = |s: Step| progress.stage(&step_text(s), None);
    let run_counter = RunCounter::new();
    progress.watch_runs(&run_counter);
    let d = diagnose_reporting(&prepared, opts, &report, &run_counter)
        .map_err(|e| located(e.into(), dir))?;
    check_diagnosis_finite(dir, &d)?;
    let replicates = if replicates > 1 {
        let own = SeedVerdict::of(opts.seed, &d);
        let finite = |r: &Diagnosis| check_diagnosis_finite(dir, r);
        let r = replicate(&prepared, opts, own, replicates, &finite, progress)
            .map_err(|e| located(e, dir))?;
        Some(r)
    } else {
        None
    };
    let mut json = diagnosis_json(&set.meta.name, &d);
    if let Some(r) = &replicates {
        json["verdict"]["replicates"] = serde_json::to_value(r)?;
    }
    // The figures draw the tests as diagnosed (any bedding taken out of the travel).
    let prepared = d.prepared.clone();
    Ok(Diagnosed {
        name: set.meta.name,
        diagnosis: d,
        prepared,
        json,
        warnings,
        replicates,
    })
}

/// A step of a diagnosis as a progress stage: "diagnosis 2/5: screening every candidate form
/// (12/25 forms fitted)".
pub fn step_text(s: Step) -> String {
    let counted = match (s.total, s.number) {
        (0, _) => String::new(),
        (_, 2) => format!(" ({}/{} forms fitted)", s.done, s.total),
        (_, 4) => format!(" ({} of at most {} stages done)", s.done, s.total),
        _ => format!(" ({}/{})", s.done, s.total),
    };
    format!(
        "diagnosis {}/{}: {}{counted}",
        s.number,
        Step::COUNT,
        s.what
    )
}

/// The content of `diagnosis.json`: the set's name, the verdict, the whole diagnosis.
pub fn diagnosis_json(set_name: &str, d: &Diagnosis) -> Value {
    serde_json::json!({
        "set": set_name,
        "verdict": {
            // Every effect named, in the order taken (empty: none); `effect` is the first.
            "effects": d.verdict.named().iter().map(|e| e.name()).collect::<Vec<_>>(),
            "effect": d.verdict.effect.name(),
            "held_out_shrink": d.verdict.held_out_shrink,
            "explanation": d.verdict.explanation,
            "extra_parameters": d.verdict.extra_parameters,
            "confidence": d.verdict.confidence,
            // confident, probable or uncertain: the word the report leads with (null when
            // nothing was judged).
            "standing": d.verdict.standing(),
            "alternatives": d.verdict.alternatives,
        },
        "diagnosis": d,
    })
}

/// A diagnosis whose base misfit or held-out shrink is not finite is not a result: the error
/// names the set's folder `dir`.
pub fn check_diagnosis_finite(dir: &Path, d: &Diagnosis) -> Result<()> {
    if !(d.base.reduced_chi2.is_finite() && d.verdict.held_out_shrink.is_finite()) {
        bail!(
            "{}: the diagnosis ended with a number that is not finite (base misfit {}, held-out shrink {}); its result is not to be trusted",
            dir.display(),
            d.base.reduced_chi2,
            d.verdict.held_out_shrink
        );
    }
    Ok(())
}

/// A diagnosis written to its results folder.
pub struct DiagnosisWritten {
    /// The diagnosis.
    pub diagnosed: Diagnosed,
    /// The readable report (also in `diagnosis.txt`).
    pub report: String,
    /// The `diagnosis.json` written.
    pub json_file: PathBuf,
    /// The figures written, then the HTML report.
    pub figures: Vec<PathBuf>,
}

/// `subfric diagnose`: the set checked and the output folder (`fits/<set name>/diagnosis`
/// unless given) claimed before the diagnosis; its files written once it is known to be
/// finite, then the folder's record of its set.
pub fn diagnose_to_folder(
    dir: &Path,
    opts: &DiagnoseOptions,
    replicates: usize,
    to: &Destination,
    progress: &dyn Progress,
) -> Result<DiagnosisWritten> {
    let set = load_set(dir)?;
    let warnings = warn(&set, progress);
    let out = to
        .dir
        .clone()
        .unwrap_or_else(|| default_results_dir(&set.meta.name).join("diagnosis"));
    let files = DIAGNOSIS_FILES.map(String::from).to_vec();
    let claim = ResultsDir::claim(&out, &[dir.to_path_buf()], &files, to.force)?;
    let diagnosed = diagnose_set(dir, set, warnings, opts, replicates, progress)?;
    let report = report_text(
        &diagnosed.name,
        dir,
        &diagnosed.diagnosis,
        diagnosed.replicates.as_ref(),
    );
    let (json_file, mut figures) = write_diagnosis(&out, &diagnosed, &report)?;
    let page = crate::render::diagnosis_page::diagnosis_page(
        &diagnosed.name,
        dir,
        &diagnosed.diagnosis,
        &report,
        &out,
        &figures,
    )?;
    let html = out.join(crate::render::report::REPORT_FILE);
    write_text(&html, &page)?;
    figures.push(html);
    claim.commit()?;
    Ok(DiagnosisWritten {
        diagnosed,
        report,
        json_file,
        figures,
    })
}

/// Writes diagnosis.json, diagnosis.txt (`report`) and the figures under `out`; returns the
/// JSON file and the figures.
fn write_diagnosis(
    out: &Path,
    diagnosed: &Diagnosed,
    report: &str,
) -> Result<(PathBuf, Vec<PathBuf>)> {
    let (name, d) = (&diagnosed.name, &diagnosed.diagnosis);
    let json_file = out.join("diagnosis.json");
    write_json(&json_file, &diagnosed.json)?;
    write_text(&out.join("diagnosis.txt"), &format!("{report}\n"))?;
    let label = effects_label(d);
    let figures = out.join("figures");
    // The figures of the tests and of the events render in parallel as one batch; the two bar
    // figures, outside `figures/`, beside them rather than after them.
    let (plots, bars) = rayon::join(
        || {
            crate::render::figures::diagnosis_figures(
                name,
                &diagnosed.prepared,
                &d.base.model,
                (!d.verdict.effects.is_empty()).then_some((&d.final_model, label.as_str())),
                crate::render::events_figures::event_figures(name, &d.events, &figures),
                &figures,
            )
        },
        || -> Result<Vec<PathBuf>> {
            let by_segment = out.join("residual-by-segment.png");
            write_figure(&residual_by_segment(name, d), &by_segment)?;
            let by_test = out.join("residual-by-test.png");
            write_figure(&residual_by_test(name, d, &diagnosed.prepared), &by_test)?;
            Ok(vec![by_segment, by_test])
        },
    );
    let mut plots = plots?;
    plots.extend(bars?);
    Ok((json_file, plots))
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
