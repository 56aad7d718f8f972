//! `subfric reproduce`: fit every set of `experiments/`, write Tables 1–4 beside the published
//! values, the overlay plots and a summary README under `fits/`.

use crate::figures::plot_set;
use crate::fit_cmd::{interval_text, report_table, run_fit, write_fit, FitOutcome, FitRequest};
use crate::io::write_text;
use anyhow::{bail, Result};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;
use subfric_fit::{FitOptions, Param, Status};

/// One set's result.
pub struct SetResult {
    /// Set folder name.
    pub name: String,
    /// Paper table it belongs to ("Table 1", ...), from `reference_parameters.source`.
    pub table: String,
    /// Fit.
    pub outcome: FitOutcome,
    /// PNG files.
    pub plots: Vec<PathBuf>,
    /// The next test `subfric plan` proposes (when some parameter is not determined).
    pub next: Option<crate::plan_cmd::NextTest>,
}

fn table_of(dir: &Path) -> String {
    std::fs::read_to_string(dir.join("experiment.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| {
            v["reference_parameters"]["source"]
                .as_str()
                .map(String::from)
        })
        .unwrap_or_else(|| "other sets".into())
}

/// Runs the whole job.
pub fn reproduce(experiments: &Path, out: &Path, options: FitOptions) -> Result<Vec<SetResult>> {
    let t0 = Instant::now();
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(experiments)
        .map_err(|e| {
            anyhow::anyhow!(
                "{}: cannot read the experiments folder: {e}",
                experiments.display()
            )
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("experiment.json").is_file())
        .collect();
    dirs.sort();
    if dirs.is_empty() {
        bail!(
            "{}: no experiment set (a folder with experiment.json) found",
            experiments.display()
        );
    }
    let results: Vec<Result<SetResult>> = dirs
        .par_iter()
        .map(|d| {
            let name = d
                .file_name()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_default();
            let outcome = run_fit(&FitRequest {
                dirs: vec![d.clone()],
                tests: vec![],
                free: Param::BASE.to_vec(),
                fix: vec![],
                bounds: vec![],
                weights: vec![],
                options,
                progress: false,
            })?;
            let set_out = out.join(&name);
            write_fit(&set_out, &outcome)?;
            write_text(
                &set_out.join("fit.txt"),
                &(report_table(&name, &outcome.report) + "\n"),
            )?;
            let plots = plot_set(
                &name,
                &outcome.tests,
                outcome.published.as_ref(),
                Some(&outcome.report.model),
                &set_out,
            )?;
            let next = crate::plan_cmd::next_test(&outcome, &set_out.join("plan"))?;
            Ok(SetResult {
                table: table_of(d),
                name,
                outcome,
                plots,
                next,
            })
        })
        .collect();
    let mut ok = Vec::new();
    for r in results {
        ok.push(r?);
    }
    let mut by_table: BTreeMap<String, Vec<&SetResult>> = BTreeMap::new();
    for r in &ok {
        by_table.entry(r.table.clone()).or_default().push(r);
    }
    let mut readme = String::new();
    let _ = writeln!(readme, "# Fitted parameters beside the published values\n");
    let _ = writeln!(
        readme,
        "Written by `subfric reproduce` in {:.1} s. Each set of `experiments/` is fitted from informed first guesses, a global search and least-squares polish; intervals are 95 % profile intervals. \"not determined\" means the data bound the parameter on at most one side (e.g. κ and ξ from a single sliding rate): the value shown is one point of a flat valley.\n",
        t0.elapsed().as_secs_f64()
    );
    for (table, sets) in &by_table {
        let slug = table.to_lowercase().replace(' ', "");
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
                "- **{}** (misfit {:.2}× noise variance): [fit.json]({}/fit.json), [report]({}/fit.txt)",
                s.name, s.outcome.report.reduced_chi2, s.name, s.name
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
    write_text(&out.join("README.md"), &readme)?;
    Ok(ok)
}

fn table_files(table: &str, sets: &[&SetResult]) -> (String, String) {
    let mut md = String::new();
    let mut csv = String::from(
        "table,set,parameter,unit,value,std_error,lower,upper,lower_open,upper_open,status,published,difference_percent\n",
    );
    let _ = writeln!(md, "# {table}: fitted beside published\n");
    for s in sets {
        let r = &s.outcome.report;
        let _ = writeln!(
            md,
            "## {}\n\nmisfit {:.3}× the noise variance over {} rows; {} of {} starts reached the best optimum.\n",
            s.name, r.reduced_chi2, r.rows, r.optimizer.starts_at_best, r.optimizer.starts
        );
        let _ = writeln!(md, "| parameter | fitted | ± s.e. | 95% interval | identifiability | published | difference |");
        let _ = writeln!(md, "|---|---:|---:|---|---|---:|---:|");
        for p in &r.parameters {
            let _ = writeln!(
                md,
                "| {}{} | {:.4} | {} | {} | {} | {} | {} |",
                p.name,
                if p.unit.is_empty() {
                    String::new()
                } else {
                    format!(" [{}]", p.unit)
                },
                p.value,
                p.std_error.map(|v| format!("{v:.3e}")).unwrap_or_else(|| {
                    if p.status == Status::Fixed {
                        "".into()
                    } else {
                        "∞".into()
                    }
                }),
                interval_text(p),
                p.status.describe(),
                p.published.map(|v| format!("{v}")).unwrap_or_default(),
                p.difference_percent
                    .map(|d| format!("{d:+.1}%"))
                    .unwrap_or_default()
            );
            let (lo, hi, lo_o, hi_o) = p.interval.map_or((f64::NAN, f64::NAN, false, false), |i| {
                (i.lo, i.hi, i.lo_open, i.hi_open)
            });
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{},{},{},{},{}",
                table,
                s.name,
                p.name,
                p.unit,
                p.value,
                p.std_error.map(|v| v.to_string()).unwrap_or_default(),
                if lo.is_nan() {
                    String::new()
                } else {
                    lo.to_string()
                },
                if hi.is_nan() {
                    String::new()
                } else {
                    hi.to_string()
                },
                lo_o,
                hi_o,
                p.status.describe(),
                p.published.map(|v| v.to_string()).unwrap_or_default(),
                p.difference_percent
                    .map(|v| format!("{v:.3}"))
                    .unwrap_or_default()
            );
        }
        if !r.combinations.is_empty() {
            let _ = writeln!(md, "\nCombinations the data determine:\n");
            for c in &r.combinations {
                let _ = writeln!(
                    md,
                    "- {}: {:.4} {} ({})",
                    c.name,
                    c.value,
                    c.interval.map(|i| i.to_string()).unwrap_or_default(),
                    if c.determined {
                        "determined"
                    } else {
                        "not determined"
                    }
                );
            }
        }
        if let Some(n) = &s.next {
            let _ = writeln!(md, "\n{}", n.markdown(&s.name));
        }
        let _ = writeln!(md);
    }
    (md, csv)
}
