//! Coverage of the 95 % credible intervals (issue 23: between 90 % and 99 % for every
//! parameter): campaigns generated exactly as `subfric_harness::coverage` generates them (random
//! sand–steel parameters, four tests, white plus slowly correlated noise, the same preparation
//! as a set read from disk), each fitted with the default calibration, then sampled with the
//! default posterior options (uniform priors within the bounds, the autocorrelated residual
//! model) started at the fit; counts per parameter how often the credible interval holds the
//! truth, beside the profile intervals of the same fits.
//!
//! `cargo run --release -p subfric-posterior --example posterior_coverage -- --campaigns 40 --seed 1
//! [--first K] [--max-evals N] [--independent] [--json FILE]` (`--first K`: campaigns K to
//! K + N − 1 of the seed, to split a measurement over several processes)

use serde::Serialize;
use std::time::Instant;
use subfric_fit::{calibrate, FitOptions, Param, Space};
use subfric_harness::coverage::{generate_campaign, CampaignRanges};
use subfric_model::{Model, Params};
use subfric_posterior::{sample, PosteriorOptions, Priors, ResidualModel};
use subfric_reading::{prepare_set_with, typical_rate, FitTest, PrepareOptions};

#[derive(Serialize)]
struct Outcome {
    index: usize,
    truth: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    credible_covers: Vec<bool>,
    profile_covers: Vec<bool>,
    converged: bool,
    steps: usize,
    model_runs: usize,
    noise_correlation: f64,
    sample_s: f64,
}

fn main() {
    let mut campaigns = 40usize;
    let mut first = 0usize;
    let mut seed = 1u64;
    let mut json: Option<String> = None;
    let mut opts = PosteriorOptions {
        max_evals: 150_000,
        ..PosteriorOptions::default()
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |name: &str| {
            args.next().unwrap_or_else(|| {
                eprintln!("{name} needs a value");
                std::process::exit(2)
            })
        };
        match a.as_str() {
            "--campaigns" => campaigns = parse(&value("--campaigns"), "--campaigns"),
            "--seed" => seed = parse(&value("--seed"), "--seed"),
            "--first" => first = parse(&value("--first"), "--first"),
            "--max-evals" => opts.max_evals = parse(&value("--max-evals"), "--max-evals"),
            "--independent" => opts.residuals = ResidualModel::Independent,
            "--json" => json = Some(value("--json")),
            other => {
                eprintln!("unknown argument `{other}` (expected --campaigns N, --seed S, --first K, --max-evals N, --independent, --json FILE)");
                std::process::exit(2)
            }
        }
    }
    let t0 = Instant::now();
    let ranges = CampaignRanges::default();
    let mut outcomes = Vec::new();
    for index in first..first + campaigns {
        outcomes.push(run_campaign(seed, index, &ranges, &opts));
    }
    println!(
        "coverage of the 95 % intervals over {campaigns} generated campaigns ({first}..{}, seed {seed}), {} converged, {:.0} s:",
        first + campaigns - 1,
        outcomes.iter().filter(|o| o.converged).count(),
        t0.elapsed().as_secs_f64()
    );
    println!(
        "{:<10} {:>22} {:>22}",
        "parameter", "posterior (credible)", "profile"
    );
    for (k, p) in Param::BASE.iter().enumerate() {
        let count = |f: &dyn Fn(&Outcome) -> bool| outcomes.iter().filter(|o| f(o)).count();
        let cred = count(&|o| o.credible_covers[k]);
        let prof = count(&|o| o.profile_covers[k]);
        let n = outcomes.len().max(1);
        println!(
            "{:<10} {:>12}/{n} ({:>3.0} %) {:>12}/{n} ({:>3.0} %)",
            p.key(),
            cred,
            100.0 * cred as f64 / n as f64,
            prof,
            100.0 * prof as f64 / n as f64
        );
    }
    if let Some(path) = json {
        let text = serde_json::to_string_pretty(&outcomes).expect("outcomes serialise");
        subfric_data::write_atomic(std::path::Path::new(&path), text.as_bytes()).unwrap_or_else(
            |e| {
                eprintln!("{e}");
                std::process::exit(1)
            },
        );
    }
}

fn parse<T: std::str::FromStr>(s: &str, name: &str) -> T {
    s.parse().unwrap_or_else(|_| {
        eprintln!("{name}: `{s}` is not a valid value");
        std::process::exit(2)
    })
}

/// Campaign `index` of `seed` generated, fitted and sampled (with `opts`), its coverage said on
/// stderr.
fn run_campaign(
    seed: u64,
    index: usize,
    ranges: &CampaignRanges,
    opts: &PosteriorOptions,
) -> Outcome {
    let c = generate_campaign(seed, index, ranges);
    let tests: Vec<FitTest> = prepare_set_with(&c.set, false, &PrepareOptions::default())
        .into_iter()
        .map(|p| p.fit)
        .collect();
    let mut template = Model::base(Params::sample()).expect("sample parameters are valid");
    template.params.alpha_t = c.truth.params.alpha_t;
    template.params.alpha_n = c.truth.params.alpha_n;
    let space = Space::with_rate(template, &Param::BASE, &[], typical_rate(&tests));
    let fit_opts = FitOptions {
        seed: seed.wrapping_add(index as u64),
        ..FitOptions::default()
    };
    let fit =
        calibrate(&tests, space.clone(), &fit_opts, &|_| {}).expect("a generated campaign fits");
    let t1 = Instant::now();
    let post_opts = PosteriorOptions {
        seed: seed.wrapping_add(index as u64),
        ..opts.clone()
    };
    let post = sample(
        &tests,
        &space,
        &fit.model,
        &Priors::default(),
        &post_opts,
        &|_, _| {},
    )
    .expect("a generated campaign samples");
    let truth: Vec<f64> = space
        .free
        .iter()
        .map(|p| p.get(&c.truth).unwrap_or(f64::NAN))
        .collect();
    let credible_covers: Vec<bool> = post
        .summary
        .iter()
        .zip(&truth)
        .map(|(s, t)| s.covers(*t))
        .collect();
    let profile_covers: Vec<bool> = space
        .free
        .iter()
        .zip(&truth)
        .map(|(p, t)| {
            fit.param(p.key())
                .and_then(|r| r.interval)
                .is_some_and(|i| i.contains(*t))
        })
        .collect();
    let o = Outcome {
        index,
        lo: post.summary.iter().map(|s| s.lo).collect(),
        hi: post.summary.iter().map(|s| s.hi).collect(),
        truth,
        credible_covers,
        profile_covers,
        converged: post.convergence.converged(),
        steps: post.convergence.steps,
        model_runs: post.model_runs,
        noise_correlation: post.noise.correlation_time,
        sample_s: t1.elapsed().as_secs_f64(),
    };
    let missed = missed_keys(&space.free, &o.credible_covers);
    let profile_missed = missed_keys(&space.free, &o.profile_covers);
    eprintln!(
        "campaign {index:>3}: {} after {} steps, {} model runs, tau of the residuals {:.1}, {:.1} s; credible missed {}; profile missed {}",
        if o.converged { "converged" } else { "NOT converged" },
        o.steps,
        o.model_runs,
        o.noise_correlation,
        o.sample_s,
        missed,
        profile_missed
    );
    o
}

/// The keys of the parameters of `free` whose interval missed the truth (`covers` false),
/// comma separated; "-" when none did.
fn missed_keys(free: &[Param], covers: &[bool]) -> String {
    let missed: Vec<&str> = free
        .iter()
        .zip(covers)
        .filter(|(_, c)| !**c)
        .map(|(p, _)| p.key())
        .collect();
    if missed.is_empty() {
        "-".to_string()
    } else {
        missed.join(",")
    }
}
