//! `subfric fit`: calibrate one or several sets, print a table, write fit.json.

use anyhow::{anyhow, bail, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use subfric_data::load_set;
use subfric_fit::interval::short_number as fmt_num;
use subfric_fit::{
    calibrate, compare_with_published, prepare_set, reference_model, typical_rate, FitOptions,
    FitReport, Method, Param, PreparedTest, Space, Stage, Status,
};
use subfric_model::{Model, Params};

/// What to fit and how.
#[derive(Clone, Debug)]
pub struct FitRequest {
    /// Set folders (joint fit when several).
    pub dirs: Vec<PathBuf>,
    /// Only these tests (by name), all when empty.
    pub tests: Vec<String>,
    /// Free parameters (the five of the paper by default).
    pub free: Vec<Param>,
    /// Fixed values.
    pub fix: Vec<(Param, f64)>,
    /// Natural bounds.
    pub bounds: Vec<(Param, f64, f64)>,
    /// Per-test weights.
    pub weights: Vec<(String, f64)>,
    /// Optimiser options.
    pub options: FitOptions,
    /// Show a progress bar.
    pub progress: bool,
}

/// A finished calibration with what produced it.
pub struct FitOutcome {
    /// The report.
    pub report: FitReport,
    /// Tests fitted.
    pub tests: Vec<PreparedTest>,
    /// Published model (single set with reference parameters).
    pub published: Option<Model>,
    /// Name used for output.
    pub name: String,
}

/// Parses `key=value` pairs of a parameter list.
pub fn parse_param(s: &str) -> Result<Param> {
    Param::from_key(s.trim()).ok_or_else(|| {
        anyhow!(
            "unknown parameter `{s}` (expected one of {})",
            Param::ALL
                .iter()
                .map(|p| p.key())
                .collect::<Vec<_>>()
                .join(", ")
        )
    })
}

/// Runs a calibration.
pub fn run_fit(req: &FitRequest) -> Result<FitOutcome> {
    if req.dirs.is_empty() {
        bail!("no set folder given");
    }
    let joint = req.dirs.len() > 1;
    let mut tests = Vec::new();
    let mut published = None;
    let mut names = Vec::new();
    for d in &req.dirs {
        let set = load_set(d)?;
        if !joint {
            published = reference_model(&set);
        }
        names.push(set.meta.name.clone());
        tests.extend(prepare_set(&set, joint));
    }
    if !req.tests.is_empty() {
        for want in &req.tests {
            if !tests.iter().any(|t| &t.fit.name == want) {
                bail!(
                    "test `{want}` not found (the sets have: {})",
                    tests
                        .iter()
                        .map(|t| t.fit.name.clone())
                        .collect::<Vec<_>>()
                        .join(", ")
                );
            }
        }
        tests.retain(|t| req.tests.contains(&t.fit.name));
    }
    for (name, w) in &req.weights {
        let Some(t) = tests.iter_mut().find(|t| &t.fit.name == name) else {
            bail!("--weight: test `{name}` not found");
        };
        if !(*w > 0.0 && w.is_finite()) {
            bail!("--weight {name}={w}: expected a finite weight > 0");
        }
        t.fit.weight = *w;
        t.full.weight = *w;
    }
    // Template: the published α (which lab data rarely determine), else the sample values.
    let mut template = Model::base(Params::sample())?;
    if let Some(p) = &published {
        template.params.alpha_t = p.params.alpha_t;
        template.params.alpha_n = p.params.alpha_n;
    }
    for (p, v) in &req.fix {
        p.set(&mut template, *v);
    }
    Model::new(template.params, template.ext).map_err(|e| anyhow!("--fix: {e}"))?;
    let free: Vec<Param> = req
        .free
        .iter()
        .copied()
        .filter(|p| !req.fix.iter().any(|(q, _)| q == p))
        .collect();
    let fits: Vec<_> = tests.iter().map(|t| t.fit.clone()).collect();
    let space = Space::with_rate(template, &free, &req.bounds, typical_rate(&fits));
    let bar = req.progress.then(|| {
        let b = indicatif::ProgressBar::new_spinner();
        b.enable_steady_tick(std::time::Duration::from_millis(120));
        b
    });
    let progress = |s: Stage| {
        if let Some(b) = &bar {
            b.set_message(match s {
                Stage::Global => "global search (differential evolution)".to_string(),
                Stage::Local(k, n) => format!("least-squares polish {k}/{n}"),
                Stage::Profiles => "profile intervals".to_string(),
                Stage::Done => "done".to_string(),
            });
        }
    };
    let mut report = calibrate(&fits, space, &req.options, &progress)?;
    // Fitted on bins of a long record: the misfit is reported on every row.
    let fulls: Vec<_> = tests.iter().map(|t| t.full.clone()).collect();
    report.tests = subfric_fit::misfits(&fulls, &report.model);
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if let Some(p) = &published {
        compare_with_published(&mut report, p);
    }
    Ok(FitOutcome {
        report,
        tests,
        published,
        name: names.join("+"),
    })
}

/// Interval text with open ends marked (empty for a fixed or unprofiled parameter).
pub fn interval_text(p: &subfric_fit::ParamReport) -> String {
    p.interval.map(|i| i.to_string()).unwrap_or_default()
}

/// The readable table printed by `subfric fit`.
pub fn report_table(name: &str, r: &FitReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "fit of {name}: {} rows, misfit {:.3}× the noise variance (reduced χ²)",
        r.rows, r.reduced_chi2
    );
    let _ = writeln!(
        s,
        "{:<18} {:>11} {:>10} {:>26}  {:<34} {:>10} {:>8}",
        "parameter",
        "value",
        "std.err",
        "95% profile interval",
        "identifiability",
        "published",
        "diff"
    );
    for p in &r.parameters {
        let _ = writeln!(
            s,
            "{:<18} {:>11} {:>10} {:>26}  {:<34} {:>10} {:>8}",
            format!(
                "{} {}",
                p.name,
                if p.unit.is_empty() {
                    String::new()
                } else {
                    format!("[{}]", p.unit)
                }
            ),
            fmt_num(p.value),
            p.std_error
                .map(fmt_num)
                .unwrap_or_else(|| if p.status == Status::Fixed {
                    "".into()
                } else {
                    "∞".into()
                }),
            interval_text(p),
            p.status.describe(),
            p.published.map(fmt_num).unwrap_or_default(),
            p.difference_percent
                .map(|d| format!("{d:+.1}%"))
                .unwrap_or_default(),
        );
    }
    if !r.combinations.is_empty() {
        let _ = writeln!(s, "combinations the data determine:");
        for c in &r.combinations {
            let iv = c.interval.map(|i| i.to_string()).unwrap_or_default();
            let _ = writeln!(
                s,
                "  {:<58} {:>11} {:>26}  {}",
                c.name,
                fmt_num(c.value),
                iv,
                if c.determined {
                    "determined"
                } else {
                    "not determined"
                }
            );
        }
    }
    let undetermined: Vec<&str> = r
        .parameters
        .iter()
        .filter(|p| {
            matches!(
                p.status,
                Status::NotDetermined | Status::LowerBoundOnly | Status::UpperBoundOnly
            )
        })
        .map(|p| p.name.as_str())
        .collect();
    if !undetermined.is_empty() {
        let _ = writeln!(
            s,
            "the data do not determine {}: their values above are one point of a flat valley, not estimates",
            undetermined.join(", ")
        );
    }
    let _ = writeln!(s, "per test:");
    for t in &r.tests {
        let _ = writeln!(
            s,
            "  {:<30} {:>6} rows  RMS {:>9} {:<3} ({:.2}% of scale, {:.2}× noise)",
            t.name,
            t.rows,
            fmt_num(t.rms),
            t.unit,
            t.rms_percent,
            t.rms_over_noise
        );
    }
    let o = &r.optimizer;
    let _ = write!(
        s,
        "optimiser: {:?}, {} starts of which {} reached the best, {} informed guesses, {} global + {} total model runs, {:.1} s",
        o.method, o.starts, o.starts_at_best, o.informed_guesses, o.global_evaluations, o.evaluations, o.elapsed_s
    );
    if o.repolished_from_profile {
        let _ = write!(s, " (profiling found a better optimum; re-polished)");
    }
    s
}

/// Writes `fit.json` under `dir`.
pub fn write_fit(dir: &Path, out: &FitOutcome) -> Result<PathBuf> {
    let file = dir.join("fit.json");
    let v = serde_json::json!({
        "set": out.name,
        "tests": out.tests.iter().map(|t| t.fit.name.clone()).collect::<Vec<_>>(),
        "params": out.report.model.params,
        "model": out.report.model,
        "report": out.report,
    });
    crate::io::write_json(&file, &v)?;
    Ok(file)
}

/// Default method of a string.
pub fn method_of(s: &str) -> Result<Method> {
    match s {
        "lsq" | "lm" => Ok(Method::Lsq),
        "nm" | "nelder-mead" => Ok(Method::NelderMead),
        other => bail!("--method {other}: expected lsq or nm"),
    }
}
