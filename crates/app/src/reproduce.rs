//! `subfric reproduce`: fit every set of `experiments/`, write Tables 1–4 beside the published
//! values, the overlay plots and a summary README under `fits/`.
//!
//! Everything written under the output folder depends on the data, the code and the seed only
//! (no wall times), so that running the job on a clean checkout leaves it clean; the wall times
//! go to the terminal and to `timings.txt`, which is not tracked.

use crate::fit::{run_fit, write_fit, FitOutcome, FitRequest};
use crate::folders::io::write_text;
use crate::folders::output::{safe_name, ResultsDir};
use crate::plan::{next_test, NextTest, PLAN_DIR};
use crate::progress::{Progress, Silent};
use crate::render::figures::{figure_stems, plot_set};
use crate::render::fit_report::{
    determined_combinations, difference_text, estimate_interval_text, legend_text, report_table,
    std_error_text, undetermined, value_text,
};
use crate::render::report::{index_page, IndexEntry};
use anyhow::{anyhow, bail, Result};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;
use subfric_data::{parse_meta, ExperimentMeta, EXPERIMENT_JSON};
use subfric_fit::{FitOptions, RunCounter, Status};

/// The file of wall times written beside the results (not tracked by git).
pub const TIMINGS_FILE: &str = "timings.txt";

/// The one page of the results, figures embedded.
pub const INDEX_FILE: &str = "index.html";

/// One set's result.
pub struct SetResult {
    /// Set folder name (made a plain folder name).
    pub name: String,
    /// Paper table it belongs to ("Table 1", ...), from `reference_parameters.source`.
    pub table: String,
    /// Fit.
    pub outcome: FitOutcome,
    /// PNG files.
    pub plots: Vec<PathBuf>,
    /// The next test `subfric plan` proposes (when some parameter is not determined).
    pub next: Option<NextTest>,
}

/// A set to fit: its folder, output name, description.
struct Job {
    dir: PathBuf,
    name: String,
    table: String,
    meta: ExperimentMeta,
}

fn read_meta(dir: &Path) -> Result<ExperimentMeta> {
    let json = dir.join(EXPERIMENT_JSON);
    let text = crate::folders::io::read_settings_text(&json, EXPERIMENT_JSON)?;
    Ok(parse_meta(&text, &json)?)
}

fn table_slug(table: &str) -> String {
    table.to_lowercase().replace(' ', "")
}

/// The sets of `experiments` (folders holding experiment.json), sorted.
fn jobs(experiments: &Path) -> Result<Vec<Job>> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(experiments)
        .map_err(|e| {
            anyhow!(
                "{}: cannot read the experiments folder: {e}",
                experiments.display()
            )
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join(EXPERIMENT_JSON).is_file())
        .collect();
    dirs.sort();
    if dirs.is_empty() {
        bail!(
            "{}: no experiment set (a folder with {EXPERIMENT_JSON}) found",
            experiments.display()
        );
    }
    dirs.into_iter()
        .map(|dir| {
            let meta = read_meta(&dir)?;
            let table = meta
                .reference_parameters
                .as_ref()
                .and_then(|v| v["source"].as_str().map(String::from))
                .unwrap_or_else(|| "other sets".into());
            let name = safe_name(&dir.file_name().unwrap_or_default().to_string_lossy());
            Ok(Job {
                dir,
                name,
                table,
                meta,
            })
        })
        .collect()
}

/// Fits one set and writes its fit.json, fit.txt and figures into its claimed folder.
fn fit_one(job: &Job, claim: ResultsDir, options: &FitOptions) -> Result<(SetResult, Vec<String>)> {
    let outcome = run_fit(
        &FitRequest::of_set(job.dir.clone(), options.clone()),
        &Silent,
    )?;
    let set_out = claim.path().to_path_buf();
    write_fit(&set_out, &outcome)?;
    write_text(&set_out.join("fit.txt"), &(report_table(&outcome) + "\n"))?;
    let (plots, notes) = plot_set(
        &job.name,
        &outcome.tests,
        outcome.published.as_ref(),
        Some(&outcome.report.model),
        &set_out,
    )?;
    let next = next_test(
        &outcome,
        &set_out.join(PLAN_DIR),
        options.run_counter.as_ref(),
    )?;
    claim.commit()?;
    Ok((
        SetResult {
            name: job.name.clone(),
            table: job.table.clone(),
            outcome,
            plots,
            next,
        },
        notes,
    ))
}

/// What to reproduce.
#[derive(Clone, Debug)]
pub struct ReproduceRequest {
    /// Folder of experiment sets.
    pub experiments: PathBuf,
    /// Output folder (subfric's own: results in it are replaced when they come from the same
    /// sets).
    pub out: PathBuf,
    /// Seed of the optimiser.
    pub seed: u64,
    /// Replace results in the output folder that came from other sets.
    pub force: bool,
}

/// The job done.
pub struct Reproduced {
    /// Each set's result.
    pub sets: Vec<SetResult>,
    /// Wall time of the whole job [s].
    pub elapsed_s: f64,
    /// The file of wall times written.
    pub timings: PathBuf,
}

/// `subfric reproduce`: every set fitted and written, the tables, the README, and the wall
/// times in [`TIMINGS_FILE`].
pub fn reproduce(req: &ReproduceRequest, progress: &dyn Progress) -> Result<Reproduced> {
    let t0 = Instant::now();
    // The sets' fits are one job: the display shows their runs together (each set's own are in
    // its report).
    let run_counter = RunCounter::new();
    progress.watch_runs(&run_counter);
    let options = FitOptions {
        seed: req.seed,
        run_counter: Some(run_counter),
        ..FitOptions::default()
    };
    let sets = fit_all(&req.experiments, &req.out, options, req.force, progress)?;
    let elapsed_s = t0.elapsed().as_secs_f64();
    let timings = req.out.join(TIMINGS_FILE);
    write_text(&timings, &timings_text(&sets, elapsed_s))?;
    Ok(Reproduced {
        sets,
        elapsed_s,
        timings,
    })
}

/// The wall times of each set's fit and of the whole job.
fn timings_text(sets: &[SetResult], total: f64) -> String {
    let mut timings = String::from(
        "# Wall times of the last `subfric reproduce` (not tracked: they vary from run to run)\n",
    );
    for r in sets {
        let o = &r.outcome.report.optimizer;
        let _ = writeln!(
            timings,
            "{:<24} {:8.2} s  {:7} model runs",
            r.name, o.elapsed_s, o.evaluations
        );
    }
    let _ = writeln!(timings, "{:<24} {total:8.2} s", "total");
    timings
}

/// Fits every set, writes their results, the tables and the README.
fn fit_all(
    experiments: &Path,
    out: &Path,
    options: FitOptions,
    force: bool,
    progress: &dyn Progress,
) -> Result<Vec<SetResult>> {
    let jobs = jobs(experiments)?;
    // Every output folder is checked and claimed before the first fit.
    let mut top_files = vec![
        "README.md".to_string(),
        INDEX_FILE.to_string(),
        TIMINGS_FILE.to_string(),
    ];
    for j in &jobs {
        let slug = table_slug(&j.table);
        for f in [format!("{slug}.md"), format!("{slug}.csv")] {
            if !top_files.contains(&f) {
                top_files.push(f);
            }
        }
    }
    let top = ResultsDir::claim(out, &[experiments.to_path_buf()], &top_files, force)?;
    let claims = jobs
        .iter()
        .map(|j| {
            let mut files = vec![
                "fit.json".to_string(),
                "fit.txt".to_string(),
                PLAN_DIR.to_string(),
            ];
            let names: Vec<&str> = j.meta.tests.iter().map(|t| t.name.as_str()).collect();
            files.extend(
                figure_stems(&names)
                    .iter()
                    .flat_map(|s| [format!("{s}.png"), format!("{s}.svg")]),
            );
            ResultsDir::claim(
                &out.join(&j.name),
                std::slice::from_ref(&j.dir),
                &files,
                force,
            )
        })
        .collect::<Result<Vec<_>>>()?;
    let done = AtomicUsize::new(0);
    let total = jobs.len();
    progress.stage(&format!("fitting {total} sets: 0 done"), None);
    let results: Vec<Result<(SetResult, Vec<String>)>> = jobs
        .par_iter()
        .zip(claims)
        .map(|(j, claim)| {
            let r = fit_one(j, claim, &options);
            let k = done.fetch_add(1, Ordering::Relaxed) + 1;
            progress.stage(&format!("fitting {total} sets: {k} done"), None);
            r
        })
        .collect();
    let mut ok = Vec::new();
    for r in results {
        let (set, notes) = r?;
        for n in notes {
            progress.warning(&n);
        }
        ok.push(set);
    }
    write_tables(out, &ok)?;
    write_index(out, &ok)?;
    top.commit()?;
    Ok(ok)
}

/// Writes the tables and the README of the output folder.
fn write_tables(out: &Path, sets: &[SetResult]) -> Result<()> {
    let mut by_table: BTreeMap<String, Vec<&SetResult>> = BTreeMap::new();
    for r in sets {
        by_table.entry(r.table.clone()).or_default().push(r);
    }
    let mut readme = String::new();
    let _ = writeln!(readme, "# Fitted parameters beside the published values\n");
    let _ = writeln!(
        readme,
        "Written by `subfric reproduce` ([the same as one page](index.html)). Each set of `experiments/` is fitted from informed first guesses, a global search and least-squares polish; intervals are 95 % profile intervals.\n"
    );
    let _ = writeln!(readme, "How to read the tables:\n\n{}\n", legend_text("- "));
    for (table, sets) in &by_table {
        let slug = table_slug(table);
        let (md, csv) = table_files(table, sets);
        write_text(&out.join(format!("{slug}.md")), &md)?;
        write_text(&out.join(format!("{slug}.csv")), &csv)?;
        let _ = writeln!(
            readme,
            "## {table}\n\n[Markdown table]({slug}.md) · [CSV]({slug}.csv)\n"
        );
        for s in sets {
            let _ = writeln!(
                readme,
                "- **{}**: {}. [fit.json]({}/fit.json), [report]({}/fit.txt)",
                s.name,
                s.outcome.adequacy.sentence("the model"),
                s.name,
                s.name
            );
            if let Some(n) = &s.next {
                let _ = writeln!(readme, "\n  {}", n.markdown(&s.name));
            }
            for p in &s.plots {
                if let Some(f) = p.file_name() {
                    let f = f.to_string_lossy();
                    let _ = writeln!(readme, "\n  ![{} {}]({}/{})", s.name, f, s.name, f);
                }
            }
        }
        let _ = writeln!(readme);
    }
    write_text(&out.join("README.md"), &readme)
}

/// Writes `index.html`: every set's verdict, tables, next test and figures on one page
/// (the set's figures, then the predicted curve of its next test).
fn write_index(out: &Path, sets: &[SetResult]) -> Result<()> {
    let mut ordered: Vec<&SetResult> = sets.iter().collect();
    ordered.sort_by(|a, b| (&a.table, &a.name).cmp(&(&b.table, &b.name)));
    let entries: Vec<IndexEntry> = ordered
        .iter()
        .map(|s| {
            let mut figures = s.plots.clone();
            let band = out.join(&s.name).join(PLAN_DIR).join("top-proposal.png");
            if s.next.is_some() && band.is_file() {
                figures.push(band);
            }
            IndexEntry {
                name: &s.name,
                table: &s.table,
                outcome: &s.outcome,
                next: s.next.as_ref().map(|n| n.text()),
                figures,
            }
        })
        .collect();
    write_text(&out.join(INDEX_FILE), &index_page(out, &entries)?)
}

/// A number of a Markdown table: four decimals, or an exponent when very large or small.
fn md_number(v: f64) -> String {
    subfric_fit::interval::short_number(v)
}

fn table_files(table: &str, sets: &[&SetResult]) -> (String, String) {
    let mut md = String::new();
    let mut csv: Vec<[String; 13]> = vec![[
        "table",
        "set",
        "parameter",
        "unit",
        "value",
        "std_error",
        "lower",
        "upper",
        "lower_open",
        "upper_open",
        "status",
        "published",
        "difference_percent",
    ]
    .map(String::from)];
    let _ = writeln!(md, "# {table}: fitted beside published\n");
    let _ = writeln!(md, "How to read:\n\n{}\n", legend_text("- "));
    for s in sets {
        let r = &s.outcome.report;
        let _ = writeln!(
            md,
            "## {}\n\n**{}.**\n\n{} rows; {} of {} starts reached the best optimum.\n",
            s.name,
            upper_first(&s.outcome.adequacy.sentence("the model")),
            r.rows,
            r.optimizer.starts_at_best,
            r.optimizer.starts
        );
        let _ = writeln!(md, "| parameter | fitted | ± s.e. | 95% interval | identifiability | published | difference |");
        let _ = writeln!(md, "|---|---:|---:|---|---|---:|---:|");
        for p in &r.parameters {
            let _ = writeln!(
                md,
                "| {}{} | {} | {} | {} | {} | {} | {} |",
                p.name,
                if p.unit.is_empty() {
                    String::new()
                } else {
                    format!(" [{}]", p.unit)
                },
                value_text(p, md_number),
                std_error_text(p, |v| format!("{v:.3e}")),
                estimate_interval_text(p),
                p.status.describe(),
                p.published.map(|v| format!("{v}")).unwrap_or_default(),
                difference_text(p)
            );
            csv.push(csv_row(table, &s.name, p));
        }
        let combos = determined_combinations(r);
        if !combos.is_empty() {
            let _ = writeln!(md, "\nCombinations the data determine:\n");
            for c in combos {
                let _ = writeln!(
                    md,
                    "- {}: {} {}",
                    c.name,
                    md_number(c.value),
                    c.interval.map(|i| i.to_string()).unwrap_or_default(),
                );
            }
        }
        if let Some(n) = &s.next {
            let _ = writeln!(md, "\n{}", n.markdown(&s.name));
        }
        let _ = writeln!(md);
    }
    (md, subfric_data::csvio::text_of(csv))
}

/// One CSV row of a parameter: every number as it is (the fitted value of an undetermined
/// parameter included, its status says what it is worth), the difference from the published
/// value only for an estimate. The cells are quoted by the CSV writer where they must be (a set
/// named with a comma).
fn csv_row(table: &str, set: &str, p: &subfric_fit::ParamReport) -> [String; 13] {
    let (lo, hi, lo_o, hi_o) = p.interval.map_or((f64::NAN, f64::NAN, false, false), |i| {
        (i.lo, i.hi, i.lo_open, i.hi_open)
    });
    let finite = |v: f64| {
        if v.is_nan() {
            String::new()
        } else {
            v.to_string()
        }
    };
    let estimate = !(p.status == Status::Fixed || undetermined(p));
    [
        table.to_string(),
        set.to_string(),
        p.name.to_string(),
        p.unit.to_string(),
        p.value.to_string(),
        p.std_error.map(|v| v.to_string()).unwrap_or_default(),
        finite(lo),
        finite(hi),
        lo_o.to_string(),
        hi_o.to_string(),
        p.status.describe().to_string(),
        p.published.map(|v| v.to_string()).unwrap_or_default(),
        p.difference_percent
            .filter(|_| estimate)
            .map(|v| format!("{v:.3}"))
            .unwrap_or_default(),
    ]
}

/// `s` with its first letter in upper case.
fn upper_first(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_uppercase().chain(c).collect(),
        None => String::new(),
    }
}
