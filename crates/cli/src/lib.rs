//! The `subfric` command line: parsed with clap ([`args`]), then dispatched to one function
//! per subcommand. Errors are printed once, each cause once, with exit code 1 (usage errors:
//! clap's exit code 2); no input makes it panic.

pub mod api;
pub mod args;
mod bench;
mod diagnose_cmd;
mod diagnose_report;
mod figures;
mod fit_cmd;
mod import_cmd;
mod io;
pub mod output;
mod plan_cmd;
mod progress;
mod reproduce;
mod simulate_cmd;

use anyhow::{bail, Result};
use args::{CheckArgs, Cli, Command, DiagnoseArgs, FitArgs, PlotArgs, SelfcheckArgs};
use clap::Parser;
use output::{default_results_dir, ResultsDir};
use progress::Progress;
use std::process::ExitCode;
use subfric_data::{load_set, plausibility, summary, PathKind, Warning};
use subfric_diagnose::selfcheck::SelfcheckOptions;
use subfric_diagnose::DiagnoseOptions;
use subfric_fit::{prepare_set, reference_model, FitOptions};

/// Parses the command line, runs it, prints an error if any; the process's exit code.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_text(&e));
            ExitCode::from(1)
        }
    }
}

/// Runs one subcommand.
pub fn run(command: Command) -> Result<()> {
    match command {
        Command::Reproduce(a) => reproduce::run(a),
        Command::Simulate(a) => simulate_cmd::run(a),
        Command::Check(a) => check(a),
        Command::Import(a) => import_cmd::run(a),
        Command::Fit(a) => fit(a),
        Command::Plot(a) => plot(a),
        Command::Diagnose(a) => diagnose(a),
        Command::Selfcheck(a) => selfcheck(a),
        Command::Plan(a) => plan_cmd::run(a),
        Command::Bench(a) => bench::run(a),
    }
}

/// An error and its causes, each cause once: a cause whose text the message already holds
/// (such as an OS error that a file error quotes) is not repeated.
pub fn error_text(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !text.contains(&c) {
            text.push_str(": ");
            text.push_str(&c);
        }
    }
    text
}

/// An error that names `place` (a set folder): as it is when its text already does, else with
/// `place` in front.
pub(crate) fn located(e: anyhow::Error, place: &std::path::Path) -> anyhow::Error {
    let p = place.display().to_string();
    if error_text(&e).contains(&p) {
        e
    } else {
        anyhow::anyhow!("{p}: {}", error_text(&e))
    }
}

/// Prints plausibility warnings on stderr.
pub(crate) fn print_warnings(warnings: &[Warning]) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
}

/// `subfric check`: validation, summary, plausibility warnings.
fn check(a: CheckArgs) -> Result<()> {
    let set = load_set(&a.set)?;
    println!("{}", summary(&set));
    print_warnings(&plausibility(&set));
    Ok(())
}

/// `subfric fit`: everything is checked and the output folder claimed before the fit runs.
fn fit(a: FitArgs) -> Result<()> {
    let req = fit_cmd::FitRequest {
        dirs: a.sets,
        tests: a.tests,
        free: a.free,
        fix: a.fix,
        bounds: a.bounds,
        weights: a.weight,
        options: FitOptions {
            method: a.method.into(),
            starts: a.starts,
            seed: a.seed,
            global_evaluations: a.global_evals,
            profiles: !a.no_profiles,
            ..FitOptions::default()
        },
        progress: a.progress,
    };
    let progress = Progress::new(req.progress);
    let setup = fit_cmd::setup_fit(&req, &progress)?;
    for w in &setup.warnings {
        progress.println(&format!("warning: {w}"));
    }
    let dir = a.out.unwrap_or_else(|| default_results_dir(&setup.name()));
    let claim = ResultsDir::claim(&dir, &req.dirs, &["fit.json".into()], a.force)?;
    let outcome = fit_cmd::fit_setup(&req, setup, &progress).map_err(|e| match &req.dirs[..] {
        [one] => located(e, one),
        _ => e,
    })?;
    progress.finish();
    println!(
        "{}",
        fit_cmd::report_table_timed(&outcome.name, &outcome.report)
    );
    let f = fit_cmd::write_fit(claim.path(), &outcome)?;
    claim.commit()?;
    println!("wrote {}", f.display());
    Ok(())
}

/// `subfric plot`: a curve that cannot be drawn is reported, not dropped silently.
fn plot(a: PlotArgs) -> Result<()> {
    let set = load_set(&a.set)?;
    let fitted = a.params.as_deref().map(io::load_model).transpose()?;
    let prepared = prepare_set(&set, false);
    let published = reference_model(&set);
    let dir = a
        .out
        .unwrap_or_else(|| default_results_dir(&set.meta.name).join("plots"));
    let files = figures::figure_files(&prepared);
    let claim = ResultsDir::claim(&dir, std::slice::from_ref(&a.set), &files, a.force)?;
    let (written, notes) = figures::plot_set(
        &set.meta.name,
        &prepared,
        published.as_ref(),
        fitted.as_ref(),
        claim.path(),
    )?;
    for n in notes {
        eprintln!("warning: {n}");
    }
    claim.commit()?;
    for f in written {
        println!("wrote {}", f.display());
    }
    Ok(())
}

/// `subfric diagnose`: the set is checked and the output folder claimed before the diagnosis.
fn diagnose(a: DiagnoseArgs) -> Result<()> {
    let set = load_set(&a.set)?;
    print_warnings(&plausibility(&set));
    let name = set.meta.name.clone();
    drop(set);
    let dir = a
        .out
        .unwrap_or_else(|| default_results_dir(&name).join("diagnosis"));
    // The per-test and per-event figures go to `figures/`, claimed as a whole.
    let files: Vec<String> = [
        "diagnosis.json",
        "diagnosis.txt",
        "residual-by-segment.png",
        "residual-by-test.png",
        "figures",
    ]
    .map(String::from)
    .to_vec();
    let claim = ResultsDir::claim(&dir, std::slice::from_ref(&a.set), &files, a.force)?;
    let opts = DiagnoseOptions {
        seed: a.seed,
        excluded_forms: a.without_form.clone(),
        ..DiagnoseOptions::default()
    };
    let progress = Progress::new(a.progress);
    progress.stage(
        "diagnosing: base fit, candidate effects, held-out folds",
        None,
    );
    let (d, plots) =
        diagnose_cmd::run_diagnose(&a.set, claim.path(), &opts).map_err(|e| located(e, &a.set))?;
    progress.finish();
    if let Err(e) = api::check_diagnosis_finite(&a.set, &d) {
        // Not left for a script to read as a result.
        let _ = std::fs::remove_file(claim.path().join("diagnosis.json"));
        return Err(e);
    }
    println!("{}", diagnose_report::report_text(&name, &d));
    claim.commit()?;
    println!("wrote {}", dir.join("diagnosis.json").display());
    for p in plots {
        println!("wrote {}", p.display());
    }
    Ok(())
}

/// `subfric selfcheck`.
fn selfcheck(a: SelfcheckArgs) -> Result<()> {
    if let Some(j) = &a.json {
        if PathKind::of(j) != PathKind::Absent && !a.force {
            bail!(
                "--json {}: exists (expected a new file, or --force to replace it)",
                j.display()
            );
        }
    }
    if let Some(w) = &a.write_sets {
        if PathKind::of(w) != PathKind::Absent {
            bail!(
                "--write-sets {}: exists (expected a new folder)",
                w.display()
            );
        }
    }
    let (cases, scores) = match &a.sets {
        Some(root) => diagnose_cmd::score_folder(root, &DiagnoseOptions::default())?,
        None => {
            let all = subfric_diagnose::selfcheck::all_classes();
            let classes = if a.classes.is_empty() {
                all
            } else {
                let mut v = Vec::new();
                for &k in &a.classes {
                    match all.get(k.wrapping_sub(1)) {
                        Some(c) => v.push(c.clone()),
                        None => bail!(
                            "--classes {k}: no such class (expected numbers from 1 to {})",
                            all.len()
                        ),
                    }
                }
                v
            };
            diagnose_cmd::run_selfcheck(
                &SelfcheckOptions {
                    classes,
                    per_class: a.per_class,
                    seed: a.seed,
                    unlisted: a.unlisted,
                    ..SelfcheckOptions::default()
                },
                a.write_sets.as_deref(),
            )?
        }
    };
    println!("\n{scores}");
    if let Some(j) = &a.json {
        io::write_json(j, &serde_json::json!({"cases": cases, "scores": scores}))?;
    }
    Ok(())
}
