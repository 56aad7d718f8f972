//! `subfric fit`: calibrate one or several sets, print a table, write fit.json.

use crate::progress::{Progress, ProgressMode};
use anyhow::{anyhow, bail, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use subfric_data::{load_set, plausibility, Warning};
use subfric_fit::interval::short_number as fmt_num;
use subfric_fit::{
    calibrate, compare_with_published, prepare_set, reference_model, typical_rate, FitOptions,
    FitReport, FitTest, Param, PreparedTest, Space, Status,
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
    /// Bounds in natural units, each honoured or refused.
    pub bounds: Vec<(Param, f64, f64)>,
    /// Per-test weights.
    pub weights: Vec<(String, f64)>,
    /// Optimiser options.
    pub options: FitOptions,
    /// Progress display.
    pub progress: ProgressMode,
}

impl FitRequest {
    /// The default calibration of one set (as `reproduce` and `bench` run it), without progress.
    pub fn of_set(dir: PathBuf, options: FitOptions) -> FitRequest {
        FitRequest {
            dirs: vec![dir],
            tests: vec![],
            free: Param::BASE.to_vec(),
            fix: vec![],
            bounds: vec![],
            weights: vec![],
            options,
            progress: ProgressMode::Never,
        }
    }
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

/// Sets loaded, checked and charted, ready for the long work.
pub struct FitSetup {
    tests: Vec<PreparedTest>,
    /// The CSV file of each test, by test name (for messages).
    files: Vec<(String, PathBuf)>,
    fits: Vec<FitTest>,
    space: Space,
    published: Option<Model>,
    names: Vec<String>,
    /// Plausibility warnings of the sets.
    pub warnings: Vec<Warning>,
}

impl FitSetup {
    /// Name of the fit (set names joined by `+`).
    pub fn name(&self) -> String {
        self.names.join("+")
    }
}

/// Loads the sets, selects and weights the tests, and checks fixed values and bounds: every
/// mistake in the request is found here, before any output is prepared or any fitting done.
pub fn setup_fit(req: &FitRequest, progress: &Progress) -> Result<FitSetup> {
    if req.dirs.is_empty() {
        bail!("no set folder given");
    }
    let joint = req.dirs.len() > 1;
    let mut tests = Vec::new();
    let mut published = None;
    let mut names = Vec::new();
    let mut warnings = Vec::new();
    let mut files = Vec::new();
    for d in &req.dirs {
        progress.stage(format!("reading {}", d.display()), None);
        let set = load_set(d)?;
        if !joint {
            published = reference_model(&set);
        }
        warnings.extend(plausibility(&set));
        names.push(set.meta.name.clone());
        for t in &set.tests {
            let name = if joint {
                format!("{}/{}", set.meta.name, t.spec.name)
            } else {
                t.spec.name.clone()
            };
            files.push((name, t.path.clone()));
        }
        let rows: usize = set.tests.iter().map(|t| t.len()).sum();
        progress.stage(
            format!("segmenting {} tests ({rows} rows)", set.tests.len()),
            None,
        );
        tests.extend(prepare_set(&set, joint));
    }
    select_tests(&mut tests, &req.tests)?;
    for (name, w) in &req.weights {
        let Some(t) = tests.iter_mut().find(|t| &t.fit.name == name) else {
            bail!(
                "--weight {name}={w}: test `{name}` not found (the sets have: {})",
                test_names(&tests)
            );
        };
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
    let fits: Vec<FitTest> = tests.iter().map(|t| t.fit.clone()).collect();
    let space = Space::try_with_rate(template, &free, &req.bounds, typical_rate(&fits))
        .map_err(|e| anyhow!("--bounds {e}"))?;
    if space.v_ref == 0.0 && !req.bounds.is_empty() && free_triple(&free) {
        progress.println(
            "note: with bounds on mu_k, kappa or xi the optimiser works in those parameters themselves, not in the combinations a single rate determines",
        );
    }
    Ok(FitSetup {
        tests,
        files,
        fits,
        space,
        published,
        names,
        warnings,
    })
}

fn free_triple(free: &[Param]) -> bool {
    [Param::MuK, Param::Kappa, Param::Xi]
        .iter()
        .all(|p| free.contains(p))
}

fn test_names(tests: &[PreparedTest]) -> String {
    tests
        .iter()
        .map(|t| t.fit.name.clone())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Keeps only the tests named in `want` (all when empty); an unknown name is an error.
fn select_tests(tests: &mut Vec<PreparedTest>, want: &[String]) -> Result<()> {
    if want.is_empty() {
        return Ok(());
    }
    for w in want {
        if !tests.iter().any(|t| &t.fit.name == w) {
            bail!(
                "--tests: test `{w}` not found (the sets have: {})",
                test_names(tests)
            );
        }
    }
    tests.retain(|t| want.contains(&t.fit.name));
    Ok(())
}

/// Runs the calibration of a checked setup.
pub fn fit_setup(req: &FitRequest, setup: FitSetup, progress: &Progress) -> Result<FitOutcome> {
    let budget = req.options.global_evaluations;
    let stage = |s| progress.fit_stage(s, budget);
    let name = setup.name();
    let mut report = calibrate(&setup.fits, setup.space.clone(), &req.options, &stage)?;
    // Fitted on bins of a long record: the misfit is reported on every row.
    let fulls: Vec<FitTest> = setup.tests.iter().map(|t| t.full.clone()).collect();
    report.tests = subfric_fit::misfits(&fulls, &report.model);
    for &(p, lo, hi) in &req.bounds {
        let v = p.get(&report.model).unwrap_or(f64::NAN);
        let slack = 1e-9 * lo.abs().max(hi.abs());
        if !(v >= lo - slack && v <= hi + slack) {
            bail!(
                "--bounds {}={lo}:{hi}: the fit ended at {} = {v}, outside the bounds (expected the optimiser to keep them; the result is withheld)",
                p.key(),
                p.key()
            );
        }
    }
    check_finite(&report, &setup, &fulls)?;
    if let Some(p) = &setup.published {
        compare_with_published(&mut report, p);
    }
    Ok(FitOutcome {
        report,
        name,
        tests: setup.tests,
        published: setup.published,
    })
}

/// A result with a number that is not finite is withheld: the error names the test's file and
/// why the fitted model cannot follow it.
fn check_finite(report: &FitReport, setup: &FitSetup, fulls: &[FitTest]) -> Result<()> {
    let file_of = |name: &str| {
        setup
            .files
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, p)| p.display().to_string())
            .unwrap_or_else(|| name.to_string())
    };
    for (t, m) in fulls.iter().zip(&report.tests) {
        if m.rms.is_finite() {
            continue;
        }
        let why = match t.predict(&report.model) {
            Err(e) => format!("{e} (row numbers count data rows from 0)"),
            Ok(_) => "its misfit is not a finite number".into(),
        };
        bail!(
            "{}: test `{}`: the best fit found cannot follow this test: {why} (expected data the model can simulate; check the units and the control column; the result is withheld)",
            file_of(&t.name),
            t.name
        );
    }
    let params = &report.model.params;
    if !(report.ssr.is_finite()
        && report.reduced_chi2.is_finite()
        && [
            params.mu_s,
            params.mu_k,
            params.kappa,
            params.xi,
            params.u_tilde,
            params.alpha_t,
        ]
        .iter()
        .all(|v| v.is_finite()))
    {
        let files: Vec<String> = setup.files.iter().map(|(n, _)| file_of(n)).collect();
        bail!(
            "{}: the fit ended with a number that is not finite (misfit {}, parameters {params:?}); the result is withheld",
            files.join(", "),
            report.ssr
        );
    }
    Ok(())
}

/// Loads, checks and calibrates in one go.
pub fn run_fit(req: &FitRequest) -> Result<FitOutcome> {
    let progress = Progress::new(req.progress);
    let setup = setup_fit(req, &progress)?;
    let out = fit_setup(req, setup, &progress);
    progress.finish();
    out
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
    write_parameter_rows(&mut s, r);
    write_combinations(&mut s, r);
    write_undetermined_note(&mut s, r);
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
        "optimiser: {:?}, {} starts of which {} reached the best, {} informed guesses, {} global + {} total model runs",
        o.method, o.starts, o.starts_at_best, o.informed_guesses, o.global_evaluations, o.evaluations
    );
    if o.repolished_from_profile {
        let _ = write!(s, " (profiling found a better optimum; re-polished)");
    }
    s
}

/// One line per parameter: value, standard error (∞: unbounded), interval, verdict, and the
/// published value with the difference from it.
fn write_parameter_rows(s: &mut String, r: &FitReport) {
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
}

/// The combinations of parameters the data determine (when the fit charted any).
fn write_combinations(s: &mut String, r: &FitReport) {
    if r.combinations.is_empty() {
        return;
    }
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

/// A warning that the values of undetermined parameters are not estimates.
fn write_undetermined_note(s: &mut String, r: &FitReport) {
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
}

/// The table with the wall time, for the terminal (files get [`report_table`]: no timings, so
/// that they depend on the data, the code and the seed only).
pub fn report_table_timed(name: &str, r: &FitReport) -> String {
    format!(
        "{}; {:.1} s wall time",
        report_table(name, r),
        r.optimizer.elapsed_s
    )
}

/// Writes `fit.json` under `dir` (atomically), without the wall time: a fit.json depends on the
/// data, the code and the seed only.
pub fn write_fit(dir: &Path, out: &FitOutcome) -> Result<PathBuf> {
    let file = dir.join("fit.json");
    crate::io::write_json(&file, &fit_json(out)?)?;
    Ok(file)
}

/// The content of `fit.json`: the set, the tests, the fitted parameters and model, and the
/// report without the wall time (what `subfric fit` writes and the Python package returns).
pub fn fit_json(out: &FitOutcome) -> Result<serde_json::Value> {
    let mut report = serde_json::to_value(&out.report)?;
    if let Some(o) = report
        .get_mut("optimizer")
        .and_then(serde_json::Value::as_object_mut)
    {
        o.remove("elapsed_s");
    }
    Ok(serde_json::json!({
        "set": out.name,
        "tests": out.tests.iter().map(|t| t.fit.name.clone()).collect::<Vec<_>>(),
        "params": out.report.model.params,
        "model": out.report.model,
        "report": report,
    }))
}
