//! The `subfric` command line: flags parsed with clap ([`args`]) into the requests of the
//! application layer (`subfric_app`), which runs the pipelines and writes the result files;
//! this crate shows progress ([`progress`], indicatif) and prints. Errors are printed once,
//! each cause once, with exit code 1 (usage errors: clap's exit code 2); no input makes it
//! panic.

pub mod args;
mod campaign;
mod print;
mod progress;

use anyhow::Result;
use args::{
    BenchArgs, CheckArgs, Cli, Command, DiagnoseArgs, FitArgs, ImportArgs, PlanArgs, PlotArgs,
    ReproduceArgs, SelfcheckArgs, SimulateArgs,
};
use clap::Parser;
use print::{err, out};
use progress::{Progress, ProgressMode};
use std::process::ExitCode;
use subfric_app::fit::{fit_to_folder, FitRequest};
use subfric_app::folders::output::Destination;
use subfric_app::plan::{plan_to_folder, PlanRequest};
use subfric_app::posterior::PosteriorRequest;
use subfric_app::render::figures;
use subfric_app::render::fit_report::report_table_timed;
use subfric_app::reproduce::{reproduce, ReproduceRequest, TIMINGS_FILE};
use subfric_app::selfcheck::{
    case_line, class_list, write_generated, Campaign, Case, SelfcheckRequest, SelfcheckSource,
};
use subfric_app::simulate::{SimulateRequest, SimulateSource};
use subfric_app::{diagnose, sets};
use subfric_data::{ColumnRef, ImportSpec, Warning};
use subfric_diagnose::DiagnoseOptions;
use subfric_fit::FitOptions;

pub use subfric_app::error_text;

/// Parses the command line, runs it, prints an error if any; the process's exit code.
///
/// Whatever happens to stdout and stderr, the command's work is done and its files written:
/// printing comes after, and a failed print is remembered, not raised ([`print`]). A reader of
/// stdout that went away (`| head -1`) ends the command quietly with its own exit code; any
/// other failure to write stdout (`> /dev/full`) is one line on stderr and exit code 1.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Err(e) = args::check_conflicts(&cli.command) {
        e.exit();
    }
    let mut code = match run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            err(format!("error: {}", error_text(&e)));
            // A campaign whose table is written but some sets have no results: 3; one stopped
            // by Ctrl-C: 130, as a program killed by SIGINT.
            ExitCode::from(if e.is::<campaign::SomeSetsFailed>() {
                3
            } else if e.is::<subfric_app::campaign::Interrupted>() {
                130
            } else {
                1
            })
        }
    };
    if let Some(e) = print::stdout_problem() {
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            err(format!(
                "error: cannot write to standard output: {e} (the command's files, if any, were written in full)"
            ));
            code = ExitCode::from(1);
        }
    }
    code
}

/// Runs one subcommand.
pub fn run(command: Command) -> Result<()> {
    match command {
        Command::Reproduce(a) => run_reproduce(a),
        Command::Simulate(a) => simulate(a),
        Command::Check(a) => check(a),
        Command::Import(a) => import(a),
        Command::Fit(a) => fit(a),
        Command::Plot(a) => plot(a),
        Command::Diagnose(a) => run_diagnose(a),
        Command::Selfcheck(a) => selfcheck(a),
        Command::Plan(a) => plan(a),
        Command::Bench(a) => bench(a),
        Command::Campaign(a) => campaign::run(a),
    }
}

/// Prints plausibility warnings on stderr.
fn print_warnings(warnings: &[Warning]) {
    for w in warnings {
        err(format!("warning: {w}"));
    }
}

/// Prints "wrote <file>" for each file.
fn print_written<'a>(files: impl IntoIterator<Item = &'a std::path::PathBuf>) {
    for f in files {
        out(format!(
            "wrote {}",
            subfric_app::visible(&f.display().to_string())
        ));
    }
}

/// `subfric check`: validation, summary, plausibility warnings.
fn check(a: CheckArgs) -> Result<()> {
    let c = sets::check(&a.set)?;
    out(c.summary);
    for r in &c.artifacts {
        let place = if r.test.is_empty() {
            String::new()
        } else {
            format!("{}: ", subfric_app::visible(&r.test))
        };
        out(format!("rig artifact, {place}{}", r.detail));
    }
    print_warnings(&c.warnings);
    Ok(())
}

/// `subfric import`: nothing in the output folder is overwritten, and the CSV and the set's
/// description are written all or nothing.
fn import(a: ImportArgs) -> Result<()> {
    let c = sets::import_test(&a.file, &import_spec(&a), &a.out)?;
    out(c.summary);
    print_warnings(&c.warnings);
    Ok(())
}

/// The import specification the options describe.
fn import_spec(a: &ImportArgs) -> ImportSpec {
    let shear = match (&a.shear, &a.friction) {
        (Some(c), _) => Some((c.clone(), a.shear_unit.into())),
        (None, Some(_)) => None,
        (None, None) => Some((ColumnRef::Name("shear_kpa".into()), a.shear_unit.into())),
    };
    ImportSpec {
        delimiter: a.delimiter.into(),
        skip_lines: a.skip,
        has_header: !a.no_header,
        time: a.time.clone(),
        time_unit: a.time_unit.into(),
        slip: a.slip.clone(),
        slip_unit: a.slip_unit.into(),
        shear,
        friction: a.friction.clone(),
        normal: a.normal.clone().map(|c| (c, a.normal_unit.into())),
        normal_stress_kpa: a.normal_stress,
        area_mm2: a.area,
        control: a.control.into(),
        test_name: a.test_name.clone(),
        set_name: a.set_name.clone().unwrap_or_else(|| {
            a.out
                .file_name()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_else(|| "imported".into())
        }),
        title: a.title.clone(),
        soil: a.soil.clone(),
        surface: a.surface.clone(),
        source: Some(a.file.display().to_string()),
        keep: a.keep,
        format: a.format,
        stage: a.stage.clone(),
        channels: a.channels.clone(),
        rate_unit: a.rate_unit,
    }
}

/// `subfric simulate`.
fn simulate(a: SimulateArgs) -> Result<()> {
    let source = match (a.set, a.scenario) {
        (Some(dir), None) => SimulateSource::Set(dir),
        (None, Some(file)) => SimulateSource::Scenario {
            file,
            max_rows: a.max_rows,
        },
        // clap refuses both and neither; kept for callers that build the arguments themselves.
        _ => anyhow::bail!("give either a set folder or --scenario <file> (expected exactly one)"),
    };
    let s = subfric_app::simulate::simulate(&SimulateRequest {
        params: a.params,
        source,
        out: a.out,
        force: a.force,
    })?;
    for f in &s.removed {
        err(format!(
            "note: removed {} (a test of the set replaced by --force)",
            f.display()
        ));
    }
    print_written(&s.files);
    Ok(())
}

/// `subfric fit`: everything is checked and the output folder claimed before the fit runs.
fn fit(a: FitArgs) -> Result<()> {
    let req = FitRequest {
        dirs: a.sets,
        tests: a.tests,
        free: a.free.unwrap_or_else(|| subfric_fit::Param::BASE.to_vec()),
        fix: a.fix,
        bounds: a.bounds,
        weights: a.weight,
        posterior: a.posterior.then(|| PosteriorRequest {
            priors: a.priors.clone(),
            max_evals: a.max_evals,
            residuals: a.residuals.into(),
            seed: a.seed,
        }),
        options: FitOptions {
            method: a.method.into(),
            starts: a.starts,
            seed: a.seed,
            global_evaluations: a.global_evals,
            profiles: !a.no_profiles,
            ..FitOptions::default()
        },
        start: None,
    };
    let progress = Progress::new(a.progress);
    let to = Destination {
        dir: a.out,
        force: a.force,
    };
    let w = fit_to_folder(&req, &to, &progress)?;
    progress.finish();
    let outcome = &w.fitted.outcome;
    out(report_table_timed(outcome));
    if let Some(p) = &w.fitted.posterior {
        out(format!(
            "\n{}sampled in {:.1} s wall time",
            p.text(&outcome.report),
            p.posterior.elapsed_s
        ));
    }
    print_written([&w.file]);
    print_written(&w.files);
    Ok(())
}

/// `subfric plot`: a curve that cannot be drawn is reported, not dropped silently.
fn plot(a: PlotArgs) -> Result<()> {
    let to = Destination {
        dir: a.out,
        force: a.force,
    };
    let progress = Progress::new(a.progress);
    let p = figures::plot(&a.set, a.params.as_deref(), &to, &progress)?;
    progress.finish();
    print_written(&p.files);
    Ok(())
}

/// `subfric diagnose`: the set is checked and the output folder claimed before the diagnosis.
fn run_diagnose(a: DiagnoseArgs) -> Result<()> {
    let opts = DiagnoseOptions {
        seed: a.seed,
        excluded_forms: a.without_form.clone(),
        with_families: a.with_family.clone(),
        ..DiagnoseOptions::default()
    };
    let to = Destination {
        dir: a.out,
        force: a.force,
    };
    let progress = Progress::new(a.progress);
    let w = diagnose::diagnose_to_folder(&a.set, &opts, a.replicates, &to, &progress)?;
    progress.finish();
    out(w.report);
    print_written([&w.json_file]);
    print_written(&w.figures);
    Ok(())
}

/// `subfric plan`: the set is checked and the output folder claimed before the fit.
fn plan(a: PlanArgs) -> Result<()> {
    let req = PlanRequest {
        set: a.set,
        seed: a.seed,
        check: a.check,
        setup_hours: a.setup_hours,
        diagnosis: a.diagnosis,
    };
    let to = Destination {
        dir: a.out,
        force: a.force,
    };
    let progress = Progress::new(a.progress);
    let p = plan_to_folder(&req, &to, &progress)?;
    progress.finish();
    out(p.text);
    print_written(&p.files);
    Ok(())
}

/// `subfric reproduce`: the job, the tables on the terminal, the wall times in timings.txt.
fn run_reproduce(a: ReproduceArgs) -> Result<()> {
    let progress = Progress::new(a.progress);
    let req = ReproduceRequest {
        experiments: a.experiments,
        out: a.out,
        seed: a.seed,
        force: a.force,
    };
    let r = reproduce(&req, &progress)?;
    progress.finish();
    for s in &r.sets {
        out(format!("{}\n", report_table_timed(&s.outcome)));
    }
    let dir = subfric_app::visible(&req.out.display().to_string());
    out(format!(
        "wrote {} sets to {dir} in {:.1} s: {dir}/README.md (wall times in {dir}/{TIMINGS_FILE})",
        r.sets.len(),
        r.elapsed_s,
    ));
    Ok(())
}

/// The seed of the sets `selfcheck` generates when none is given.
const GENERATED_SEED: u64 = 7;

/// `subfric selfcheck`.
fn selfcheck(a: SelfcheckArgs) -> Result<()> {
    if a.list_classes {
        for (number, label) in class_list(a.layout.into()) {
            println!("{number:>3}  {label}");
        }
        return Ok(());
    }
    let campaign = Campaign {
        classes: a.classes,
        per_class: a.per_class,
        seed: a.seed.unwrap_or(GENERATED_SEED),
        layout: a.layout.into(),
    };
    if let Some(dir) = a.write {
        let t0 = std::time::Instant::now();
        let written = write_generated(&dir, &campaign)?;
        for w in &written {
            println!(
                "{:<12} {:<7} {:>6} rows  {}",
                w.name, w.profile, w.rows, w.truth
            );
        }
        println!(
            "\nwrote {} sets and truth.json to {} in {:.1} s (score them with `subfric selfcheck --sets {}`)",
            written.len(),
            dir.display(),
            t0.elapsed().as_secs_f64(),
            dir.display()
        );
        return Ok(());
    }
    let source = match a.sets {
        Some(root) => SelfcheckSource::Folder {
            root,
            seed: a.seed.unwrap_or(DiagnoseOptions::default().seed),
        },
        None => SelfcheckSource::Generated {
            campaign,
            unlisted: a.unlisted,
        },
    };
    let req = SelfcheckRequest {
        source,
        json: a.json,
        force: a.force,
    };
    let print_case = |c: &Case| out(case_line(c));
    let (_, scores) =
        subfric_app::selfcheck::run(&req, &print_case, &Progress::new(ProgressMode::Never))?;
    out(format!("\n{scores}"));
    Ok(())
}

/// `subfric bench`: the figures, as text or JSON.
fn bench(a: BenchArgs) -> Result<()> {
    let parts: Vec<_> = a.only.iter().map(|p| p.part()).collect();
    let extras = subfric_app::bench::BenchExtras {
        peer: a.peer.clone(),
        records: a.records.clone(),
    };
    let r = subfric_app::bench::measure_with(&a.experiments, &parts, &extras)?;
    if a.json {
        out(serde_json::to_string_pretty(&r)?);
        return Ok(());
    }
    if let (Some(sps), Some(case), Some(identical)) =
        (r.steps_per_second, &r.step_case, r.identical_to_simulate)
    {
        out(format!(
            "model step: {:.2} million steps/s on one core ({case})",
            sps / 1e6
        ));
        out(format!(
            "  identical to the general simulate path: {identical}"
        ));
    }
    if let Some(fits) = &r.fit_seconds {
        out("one full fit of each paper set:");
        for (s, t) in fits {
            out(format!("  {s:<24} {t:6.2} s"));
        }
    }
    if let Some(m) = &r.multistart {
        out(format!(
            "multi-start fit of {}: {:.2} s on 1 thread, {:.2} s on {} threads: speed-up {:.2}×",
            m.set, m.one_thread_s, m.all_threads_s, m.threads, m.speedup
        ));
    }
    if let Some(f) = &r.many_tests {
        out(format!(
            "fit of {} tests of {} rows: {:.1} s ({:.1} s of processor time, {} model runs; \
             fitted mu_s, mu_k within {:.2}% of the truth)",
            f.tests,
            f.rows_per_test,
            f.seconds,
            f.cpu_seconds,
            f.model_runs,
            100.0 * f.worst_recovery
        ));
    }
    if let Some(p) = &r.peer {
        out(format!(
            "model step against the peer {} (same protocol, alternated {} rounds, best of each): {:.2} against {:.2} million steps/s: {:.2}× the peer",
            p.peer,
            p.rounds,
            p.steps_per_second / 1e6,
            p.peer_steps_per_second / 1e6,
            p.ratio
        ));
    }
    for (title, diagnoses) in [
        (
            "whole diagnoses (prepare, fit every candidate, held-out folds, verdict):",
            &r.diagnoses,
        ),
        (
            "whole diagnoses of the records asked for (load, prepare, fit, folds, verdict):",
            &r.records,
        ),
    ] {
        let Some(diagnoses) = diagnoses else { continue };
        out(title);
        for d in diagnoses {
            out(format!(
                "  {:<30} {:>7} rows in {} tests: {:6.2} s at {:.0} % CPU on {} threads, peak memory {:.0} MB (verdict: {})",
                d.case,
                d.rows,
                d.tests,
                d.seconds,
                100.0 * d.cpu_seconds / d.seconds.max(1e-9),
                d.threads,
                d.peak_memory_mb,
                d.verdict
            ));
        }
    }
    if let Some(p) = &r.sampler {
        out(format!(
            "posterior sampler on {}: {} steps of {} walkers, {} model runs in {:.2} s on {} threads: {:.0} model runs per second (load average {:.1})",
            p.set, p.steps, p.walkers, p.model_runs, p.seconds, p.threads, p.runs_per_second, p.load_average
        ));
    }
    Ok(())
}
