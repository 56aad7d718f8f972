//! `subfric`: calibrate the subloading-friction model of sand–metal interfaces and tell where
//! the model and the laboratory disagree, and why.

mod bench;
mod diagnose_cmd;
mod figures;
mod fit_cmd;
mod io;
mod plan_cmd;
mod reproduce;
mod simulate_cmd;

use anyhow::{anyhow, bail, Result};
use clap::{Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use subfric_data::{
    import, load_set, summary, ColumnRef, Delimiter, ImportSpec, LengthUnit, StressUnit, TimeUnit,
};
use subfric_diagnose::selfcheck::SelfcheckOptions;
use subfric_diagnose::{DiagnoseOptions, Effect};
use subfric_fit::{FitOptions, Param};

#[derive(Parser)]
#[command(
    name = "subfric",
    version,
    about = "Calibrate the subloading-friction model of sand–metal interfaces and diagnose the sim-to-real gap"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, ValueEnum)]
enum ControlArg {
    Slip,
    Shear,
}

// Parsed once per run: the size of the import variant does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
enum Command {
    /// Fit every set of experiments/ and write Tables 1–4, plots and a summary under fits/.
    Reproduce {
        /// Folder of experiment sets.
        #[arg(long, default_value = "experiments")]
        experiments: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "fits")]
        out: PathBuf,
        /// Seed of the optimiser.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Simulate every test of a set (or a scenario) with given parameters.
    Simulate {
        /// Set folder (omit with --scenario).
        set: Option<PathBuf>,
        /// Parameters: params.json, a fit.json, or an experiment.json with reference_parameters.
        #[arg(long)]
        params: PathBuf,
        /// Declarative scenario JSON instead of a set.
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// Output folder (a set in the same format).
        #[arg(long)]
        out: PathBuf,
    },
    /// Validate a set and print a summary of its tests.
    Check {
        /// Set folder.
        set: PathBuf,
    },
    /// Turn a laboratory export into a test of a set in the data format.
    Import {
        /// Lab file.
        file: PathBuf,
        /// Output set folder (created, or the test is added to it).
        #[arg(long)]
        out: PathBuf,
        /// Time column (header name or 1-based index).
        #[arg(long, default_value = "time_s")]
        time: String,
        /// Unit of time: s, min, h, ms.
        #[arg(long, default_value = "s")]
        time_unit: String,
        /// Slip column.
        #[arg(long, default_value = "slip_mm")]
        slip: String,
        /// Unit of slip: mm, um, m, in.
        #[arg(long, default_value = "mm")]
        slip_unit: String,
        /// Shear column (or give --friction).
        #[arg(long)]
        shear: Option<String>,
        /// Unit of shear: kPa, MPa, Pa, psi.
        #[arg(long, default_value = "kPa")]
        shear_unit: String,
        /// Friction (shear/normal) column.
        #[arg(long)]
        friction: Option<String>,
        /// Normal stress column.
        #[arg(long)]
        normal: Option<String>,
        /// Unit of the normal column.
        #[arg(long, default_value = "kPa")]
        normal_unit: String,
        /// Constant normal stress [kPa] when there is no normal column.
        #[arg(long)]
        normal_stress: Option<f64>,
        /// Which column the apparatus imposed.
        #[arg(long, value_enum, default_value = "slip")]
        control: ControlArg,
        /// Delimiter: comma, tab, whitespace, semicolon, auto.
        #[arg(long, default_value = "auto")]
        delimiter: String,
        /// Lines to skip before the header.
        #[arg(long, default_value_t = 0)]
        skip: usize,
        /// The file has no header line (columns by index).
        #[arg(long)]
        no_header: bool,
        /// Test name.
        #[arg(long, default_value = "test")]
        test_name: String,
        /// Set name (for a new set).
        #[arg(long)]
        set_name: Option<String>,
        /// Soil.
        #[arg(long)]
        soil: Option<String>,
        /// Surface.
        #[arg(long)]
        surface: Option<String>,
        /// Title.
        #[arg(long)]
        title: Option<String>,
    },
    /// Calibrate μ_s, μ_k, κ, ξ, ũ (or chosen parameters) against one or several sets.
    Fit {
        /// Set folders (several: a joint fit sharing parameters).
        #[arg(required = true)]
        sets: Vec<PathBuf>,
        /// Only these tests (comma separated).
        #[arg(long, value_delimiter = ',')]
        tests: Vec<String>,
        /// Free parameters (comma separated; default mu_s,mu_k,kappa,xi,u_tilde; alpha_t may be added).
        #[arg(long, value_delimiter = ',')]
        free: Vec<String>,
        /// Fixed values, key=value (comma separated).
        #[arg(long, value_delimiter = ',')]
        fix: Vec<String>,
        /// Bounds, key=lo:hi (comma separated).
        #[arg(long, value_delimiter = ',')]
        bounds: Vec<String>,
        /// Test weights, name=w (comma separated).
        #[arg(long, value_delimiter = ',')]
        weight: Vec<String>,
        /// Local method: lsq (Levenberg–Marquardt) or nm (Nelder–Mead).
        #[arg(long, default_value = "lsq")]
        method: String,
        /// Local starts.
        #[arg(long, default_value_t = 8)]
        starts: usize,
        /// Seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Model runs of the global stage.
        #[arg(long, default_value_t = 3000)]
        global_evals: usize,
        /// Skip profile intervals.
        #[arg(long)]
        no_profiles: bool,
        /// Output folder (default fits/<set>).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Overlay plots of a set: measured, published, and a fit.
    Plot {
        /// Set folder.
        set: PathBuf,
        /// Fitted parameters (fit.json or params.json).
        #[arg(long)]
        params: Option<PathBuf>,
        /// Output folder (default fits/<set>/plots).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Where the calibrated model misses, which unmodelled effect explains it, how far it shrinks.
    Diagnose {
        /// Set folder.
        set: PathBuf,
        /// Output folder for diagnosis.json and plots (default fits/<set>/diagnosis).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Check the diagnosis on generated sets with withheld effects (or on a folder with truth.json).
    Selfcheck {
        /// Sets per class.
        #[arg(long, default_value_t = 2)]
        per_class: usize,
        /// Seed.
        #[arg(long, default_value_t = 7)]
        seed: u64,
        /// Score the sets of this folder against its truth.json instead of generating sets.
        #[arg(long)]
        sets: Option<PathBuf>,
        /// Write the scores as JSON here.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Which test to run next: proposals ranked by how far they determine what the data do not.
    Plan(plan_cmd::PlanArgs),
    /// Speed of the model step, of each paper fit, and of multi-start scaling.
    Bench {
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Folder of experiment sets.
        #[arg(long, default_value = "experiments")]
        experiments: PathBuf,
    },
}

fn parse_kv(s: &str, what: &str) -> Result<(String, String)> {
    let (k, v) = s
        .split_once('=')
        .ok_or_else(|| anyhow!("{what} `{s}`: expected key=value"))?;
    Ok((k.trim().to_string(), v.trim().to_string()))
}

fn num(s: &str, what: &str) -> Result<f64> {
    let v: f64 = s
        .parse()
        .map_err(|_| anyhow!("{what}: `{s}` is not a number"))?;
    if !v.is_finite() {
        bail!("{what}: `{s}` is not a finite number");
    }
    Ok(v)
}

fn parse_unit<T: std::str::FromStr<Err = String>>(s: &str, what: &str) -> Result<T> {
    s.parse::<T>().map_err(|e| anyhow!("--{what}: {e}"))
}

fn main() {
    let cli = Cli::parse();
    if let Err(e) = run(cli) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Reproduce {
            experiments,
            out,
            seed,
        } => {
            let t0 = std::time::Instant::now();
            let res = reproduce::reproduce(
                &experiments,
                &out,
                FitOptions {
                    seed,
                    ..FitOptions::default()
                },
            )?;
            for r in &res {
                println!("{}\n", fit_cmd::report_table(&r.name, &r.outcome.report));
            }
            println!(
                "wrote {} sets to {} in {:.1} s: {}/README.md",
                res.len(),
                out.display(),
                t0.elapsed().as_secs_f64(),
                out.display()
            );
        }
        Command::Simulate {
            set,
            params,
            scenario,
            out,
        } => {
            let model = io::load_model(&params)?;
            match (set, scenario) {
                (Some(dir), None) => {
                    for f in simulate_cmd::simulate_set(&dir, &model, &out)? {
                        println!("wrote {f}");
                    }
                }
                (None, Some(sc)) => println!(
                    "wrote {}",
                    simulate_cmd::simulate_scenario(&sc, &model, &out)?
                ),
                (Some(_), Some(_)) => bail!("give either a set folder or --scenario, not both"),
                (None, None) => bail!("give a set folder or --scenario <file>"),
            }
        }
        Command::Check { set } => {
            let s = load_set(&set)?;
            println!("{}", summary(&s));
        }
        Command::Import {
            file,
            out,
            time,
            time_unit,
            slip,
            slip_unit,
            shear,
            shear_unit,
            friction,
            normal,
            normal_unit,
            normal_stress,
            control,
            delimiter,
            skip,
            no_header,
            test_name,
            set_name,
            soil,
            surface,
            title,
        } => {
            let col = |s: &str, what: &str| -> Result<ColumnRef> {
                s.parse::<ColumnRef>().map_err(|e| anyhow!("--{what}: {e}"))
            };
            let shear = match (&shear, &friction) {
                (Some(c), _) => Some((
                    col(c, "shear")?,
                    parse_unit::<StressUnit>(&shear_unit, "shear-unit")?,
                )),
                (None, Some(_)) => None,
                (None, None) => Some((
                    ColumnRef::Name("shear_kpa".into()),
                    parse_unit::<StressUnit>(&shear_unit, "shear-unit")?,
                )),
            };
            let spec = ImportSpec {
                delimiter: parse_unit::<Delimiter>(&delimiter, "delimiter")?,
                skip_lines: skip,
                has_header: !no_header,
                time: col(&time, "time")?,
                time_unit: parse_unit::<TimeUnit>(&time_unit, "time-unit")?,
                slip: col(&slip, "slip")?,
                slip_unit: parse_unit::<LengthUnit>(&slip_unit, "slip-unit")?,
                shear,
                friction: friction
                    .as_deref()
                    .map(|f| col(f, "friction"))
                    .transpose()?,
                normal: match &normal {
                    Some(c) => Some((
                        col(c, "normal")?,
                        parse_unit::<StressUnit>(&normal_unit, "normal-unit")?,
                    )),
                    None => None,
                },
                normal_stress_kpa: normal_stress,
                control: match control {
                    ControlArg::Slip => subfric_data::Control::Slip,
                    ControlArg::Shear => subfric_data::Control::Shear,
                },
                test_name,
                set_name: set_name.unwrap_or_else(|| {
                    out.file_name()
                        .map(|s| s.to_string_lossy().to_string())
                        .unwrap_or_else(|| "imported".into())
                }),
                title,
                soil,
                surface,
                source: Some(file.display().to_string()),
            };
            let set = import(&file, &spec, &out)?;
            println!("{}", summary(&set));
        }
        Command::Fit {
            sets,
            tests,
            free,
            fix,
            bounds,
            weight,
            method,
            starts,
            seed,
            global_evals,
            no_profiles,
            out,
        } => {
            let free: Vec<Param> = if free.is_empty() {
                Param::BASE.to_vec()
            } else {
                free.iter()
                    .map(|s| fit_cmd::parse_param(s))
                    .collect::<Result<_>>()?
            };
            let fix = fix
                .iter()
                .map(|s| {
                    let (k, v) = parse_kv(s, "--fix")?;
                    Ok((fit_cmd::parse_param(&k)?, num(&v, &format!("--fix {k}"))?))
                })
                .collect::<Result<Vec<_>>>()?;
            let bounds = bounds
                .iter()
                .map(|s| {
                    let (k, v) = parse_kv(s, "--bounds")?;
                    let (a, b) = v
                        .split_once(':')
                        .ok_or_else(|| anyhow!("--bounds {s}: expected key=lo:hi"))?;
                    let (a, b) = (num(a, "--bounds lower")?, num(b, "--bounds upper")?);
                    if a >= b {
                        bail!("--bounds {s}: lower bound must be below the upper bound");
                    }
                    Ok((fit_cmd::parse_param(&k)?, a, b))
                })
                .collect::<Result<Vec<_>>>()?;
            let weights = weight
                .iter()
                .map(|s| {
                    let (k, v) = parse_kv(s, "--weight")?;
                    Ok((k, num(&v, "--weight")?))
                })
                .collect::<Result<Vec<_>>>()?;
            let req = fit_cmd::FitRequest {
                dirs: sets,
                tests,
                free,
                fix,
                bounds,
                weights,
                options: FitOptions {
                    method: fit_cmd::method_of(&method)?,
                    starts,
                    seed,
                    global_evaluations: global_evals,
                    profiles: !no_profiles,
                    ..FitOptions::default()
                },
                progress: true,
            };
            let outcome = fit_cmd::run_fit(&req)?;
            println!("{}", fit_cmd::report_table(&outcome.name, &outcome.report));
            let dir = out.unwrap_or_else(|| PathBuf::from("fits").join(&outcome.name));
            let f = fit_cmd::write_fit(&dir, &outcome)?;
            println!("wrote {}", f.display());
        }
        Command::Plot { set, params, out } => {
            let s = load_set(&set)?;
            let prepared = subfric_fit::prepare_set(&s, false);
            let published = subfric_fit::reference_model(&s);
            let fitted = params.as_deref().map(io::load_model).transpose()?;
            let dir = out.unwrap_or_else(|| PathBuf::from("fits").join(&s.meta.name).join("plots"));
            for f in figures::plot_set(
                &s.meta.name,
                &prepared,
                published.as_ref(),
                fitted.as_ref(),
                &dir,
            )? {
                println!("wrote {}", f.display());
            }
        }
        Command::Diagnose { set, out, seed } => {
            let name = set
                .file_name()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_else(|| "set".into());
            let dir = out.unwrap_or_else(|| PathBuf::from("fits").join(&name).join("diagnosis"));
            let opts = DiagnoseOptions {
                seed,
                ..DiagnoseOptions::default()
            };
            let (d, plots) = diagnose_cmd::run_diagnose(&set, &dir, &opts)?;
            println!("{}", diagnose_cmd::report_text(&name, &d));
            println!("wrote {}", dir.join("diagnosis.json").display());
            for p in plots {
                println!("wrote {}", p.display());
            }
        }
        Command::Selfcheck {
            per_class,
            seed,
            sets,
            json,
        } => {
            let (cases, scores) = match sets {
                Some(root) => diagnose_cmd::score_folder(&root, &DiagnoseOptions::default())?,
                None => diagnose_cmd::run_selfcheck(&SelfcheckOptions {
                    classes: Effect::ALL.to_vec(),
                    per_class,
                    seed,
                    ..SelfcheckOptions::default()
                }),
            };
            println!("\n{scores}");
            if let Some(j) = json {
                io::write_json(&j, &serde_json::json!({"cases": cases, "scores": scores}))?;
            }
        }
        Command::Plan(args) => plan_cmd::run(args)?,
        Command::Bench { json, experiments } => {
            let r = bench::run(&experiments)?;
            if json {
                println!("{}", serde_json::to_string_pretty(&r)?);
            } else {
                println!(
                    "model step: {:.2} million steps/s on one core ({})",
                    r.steps_per_second / 1e6,
                    r.step_case
                );
                println!(
                    "  identical to the general simulate path: {}",
                    r.identical_to_simulate
                );
                println!("one full fit of each paper set:");
                for (s, t) in &r.fit_seconds {
                    println!("  {s:<24} {t:6.2} s");
                }
                let m = &r.multistart;
                println!(
                    "multi-start fit of {}: {:.2} s on 1 thread, {:.2} s on {} threads: speed-up {:.2}×",
                    m.set, m.one_thread_s, m.all_threads_s, m.threads, m.speedup
                );
            }
        }
    }
    Ok(())
}
