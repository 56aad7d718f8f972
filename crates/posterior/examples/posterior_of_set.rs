//! The posterior of one experiment set, as `subfric fit <set> --posterior` will give it: the
//! least-squares fit of the five parameters of the paper, then the ensemble sampler started
//! around it, convergence judged on the parameters the fit determined. Prints the summary and
//! the time to convergence; with `--out DIR` writes the corner plot, the predictive-band
//! overlays and the thinned chain there.
//!
//! `cargo run --release -p subfric-posterior --example posterior_of_set -- experiments/table4-two-way
//! [--out DIR] [--max-evals N] [--seed S] [--judge determined|all] [--priors FILE]
//! [--independent]`

use std::path::PathBuf;
use std::time::Instant;
use subfric_fit::{calibrate, FitOptions, Param, Space, Status};
use subfric_model::{Model, Params};
use subfric_plot::write_figure;
use subfric_posterior::{figures, sample, BandOptions, PosteriorOptions, Priors, ResidualModel};
use subfric_reading::{prepare_set, reference_model, typical_rate};

fn main() {
    let Args {
        dir,
        out,
        mut opts,
        judge_all,
        priors,
    } = parse_args();
    let set = subfric_data::load_set(&dir).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    let prepared = prepare_set(&set, false);
    let tests: Vec<_> = prepared.iter().map(|p| p.fit.clone()).collect();
    let mut template = Model::base(Params::sample()).expect("sample parameters are valid");
    if let Some(p) = reference_model(&set) {
        template.params.alpha_t = p.params.alpha_t;
        template.params.alpha_n = p.params.alpha_n;
    }
    let space = Space::with_rate(template, &Param::BASE, &[], typical_rate(&tests));
    let t0 = Instant::now();
    let fit =
        calibrate(&tests, space.clone(), &FitOptions::default(), &|_| {}).expect("the set fits");
    let fit_s = t0.elapsed().as_secs_f64();
    let determined: Vec<Param> = fit
        .parameters
        .iter()
        .filter(|p| p.status == Status::Determined)
        .filter_map(|p| Param::from_key(&p.name))
        .collect();
    println!(
        "{}: least-squares fit in {fit_s:.1} s; determined: {}",
        set.meta.name,
        determined
            .iter()
            .map(|p| p.key())
            .collect::<Vec<_>>()
            .join(", ")
    );
    if !judge_all {
        opts.converge_on = Some(determined);
    }
    let (t1, cpu1) = (Instant::now(), cpu_seconds());
    let post = sample(&tests, &space, &fit.model, &priors, &opts, &|_, _| {}).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    println!(
        "posterior in {:.1} s wall, {:.1} s CPU ({} model runs, {:.0} runs/s, acceptance {:.2}, {} threads), stopped: {:?}",
        t1.elapsed().as_secs_f64(),
        cpu_seconds() - cpu1,
        post.model_runs,
        post.model_runs as f64 / t1.elapsed().as_secs_f64(),
        post.acceptance,
        rayon::current_num_threads(),
        post.stopped
    );
    print!("{}", post.table());
    for (p, prof) in post.summary.iter().zip(&fit.parameters) {
        println!(
            "  {:<8} posterior 95% [{:.4e}, {:.4e}]   profile 95% {}",
            p.name,
            p.lo,
            p.hi,
            prof.interval
                .map(|i| format!(
                    "[{:.4e}, {:.4e}]{}{}",
                    i.lo,
                    i.hi,
                    if i.lo_open { " lo open" } else { "" },
                    if i.hi_open { " hi open" } else { "" }
                ))
                .unwrap_or_default()
        );
    }
    if let Some(out) = out {
        write_outputs(&out, &set.meta.name, &post, &prepared, &fit.model);
    }
}

/// CPU time of this process so far [s] (user + system, from /proc; NaN elsewhere): on a
/// machine shared with others the wall time says little, the CPU time what the work costs.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // Fields after the command name (which is in parentheses): utime and stime are the 12th
    // and 13th, in clock ticks of 1/100 s.
    let rest = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = rest
        .split_whitespace()
        .map(|v| v.parse().unwrap_or(f64::NAN))
        .collect();
    match (f.get(11), f.get(12)) {
        (Some(u), Some(s)) => (u + s) / 100.0,
        _ => f64::NAN,
    }
}

fn parse<T: std::str::FromStr>(s: &str, name: &str) -> T {
    s.parse().unwrap_or_else(|_| {
        eprintln!("{name}: `{s}` is not a valid value");
        std::process::exit(2)
    })
}

/// What the command line asks: the set, where to write, the sampler's options, whether to
/// judge convergence on every parameter, and the priors.
struct Args {
    dir: PathBuf,
    out: Option<PathBuf>,
    opts: PosteriorOptions,
    judge_all: bool,
    priors: Priors,
}

/// The command line read, or the usage printed and the process ended.
fn parse_args() -> Args {
    let mut args = std::env::args().skip(1);
    let mut dir: Option<PathBuf> = None;
    let mut out: Option<PathBuf> = None;
    let mut opts = PosteriorOptions::default();
    let mut judge_all = false;
    let mut priors = Priors::default();
    while let Some(a) = args.next() {
        let mut value = |name: &str| {
            args.next().unwrap_or_else(|| {
                eprintln!("{name} needs a value");
                std::process::exit(2)
            })
        };
        match a.as_str() {
            "--out" => out = Some(value("--out").into()),
            "--max-evals" => opts.max_evals = parse(&value("--max-evals"), "--max-evals"),
            "--seed" => opts.seed = parse(&value("--seed"), "--seed"),
            "--judge" => judge_all = value("--judge") == "all",
            "--independent" => opts.residuals = ResidualModel::Independent,
            "--priors" => {
                priors = Priors::load(&PathBuf::from(value("--priors"))).unwrap_or_else(|e| {
                    eprintln!("{e}");
                    std::process::exit(2)
                })
            }
            other if !other.starts_with('-') && dir.is_none() => dir = Some(other.into()),
            other => {
                eprintln!("unknown argument `{other}`");
                std::process::exit(2)
            }
        }
    }
    let Some(dir) = dir else {
        eprintln!("usage: posterior_of_set <set folder> [--out DIR] [--max-evals N] [--seed S] [--judge determined|all] [--priors FILE] [--independent]");
        std::process::exit(2)
    };
    Args {
        dir,
        out,
        opts,
        judge_all,
        priors,
    }
}

/// The corner plot, a band figure per test and the chain, written into `out`.
fn write_outputs(
    out: &std::path::Path,
    name: &str,
    post: &subfric_posterior::Posterior,
    prepared: &[subfric_reading::PreparedTest],
    model: &Model,
) {
    std::fs::create_dir_all(out).expect("output folder");
    write_figure(
        &figures::corner_figure(post, &format!("{name}: posterior"), None),
        &out.join("corner.png"),
    )
    .expect("corner plot");
    let full: Vec<_> = prepared.iter().map(|p| p.full.clone()).collect();
    let bands = post.predictive_bands(&full, &BandOptions::default());
    for (t, b) in full.iter().zip(&bands) {
        let path = out.join(format!("{}-band.png", t.name));
        write_figure(
            &figures::band_figure(t, b, Some(model), &format!("{name}: {}", t.name)),
            &path,
        )
        .expect("band figure");
    }
    let mut csv = Vec::new();
    post.write_chain_csv(&mut csv).expect("chain CSV");
    subfric_data::write_atomic(&out.join("chain.csv"), &csv).expect("chain CSV written");
    println!("figures and chain in {}", out.display());
}
