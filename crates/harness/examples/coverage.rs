//! Coverage of the reported 95 % intervals on generated multi-test campaigns with random
//! sand–steel parameters and white + slowly correlated noise (see `subfric_harness::coverage`).
//!
//! `cargo run --release -p subfric-harness --example coverage -- --campaigns 40 --seed 1 [--json FILE]
//! [--white-only] [--slip-noise-mm SD]` (`--white-only`: no correlated part; `--slip-noise-mm`:
//! the noise of the imposed slip, 0.0002 by default)

use subfric_fit::FitOptions;
use subfric_harness::coverage::{measure_coverage, CampaignRanges};

fn main() {
    let mut campaigns = 40usize;
    let mut seed = 1u64;
    let mut json: Option<String> = None;
    let mut ranges = CampaignRanges::default();
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
            "--json" => json = Some(value("--json")),
            "--white-only" => ranges.correlated_ratio = (0.0, 0.0),
            "--slip-noise-mm" => {
                ranges.slip_noise_mm = parse(&value("--slip-noise-mm"), "--slip-noise-mm")
            }
            other => {
                eprintln!(
                    "unknown argument `{other}` (expected --campaigns N, --seed S, --json FILE)"
                );
                std::process::exit(2)
            }
        }
    }
    let report = measure_coverage(campaigns, seed, &ranges, &FitOptions::default(), &|o| {
        let missed: Vec<&str> = o
            .parameters
            .iter()
            .filter(|p| !p.covered)
            .map(|p| p.name.as_str())
            .collect();
        eprintln!(
            "campaign {:>3}: misfit {:.2}, correlation factor {:5.1}, white {:.2} kPa, correlated {:.2} kPa over {:.0} s, {:.1} s{}",
            o.index,
            o.reduced_chi2,
            o.noise_correlation,
            o.noise.white_kpa,
            o.noise.correlated_kpa,
            o.noise.correlation_time_s,
            o.elapsed_s,
            if missed.is_empty() {
                String::new()
            } else {
                format!("  MISSED {}", missed.join(", "))
            }
        );
    });
    println!(
        "coverage of the 95 % intervals on {campaigns} campaigns (seed {seed}), {:.0} s:",
        report.elapsed_s
    );
    println!(
        "{:<10} {:>9} {:>8} {:>12} {:>22}",
        "parameter", "covered", "share", "determined", "median half-width [%]"
    );
    for r in &report.rows {
        println!(
            "{:<10} {:>4} / {:<3} {:>7.1}% {:>12} {:>22.2}",
            r.name,
            r.covered,
            r.total,
            100.0 * r.fraction(),
            r.determined,
            r.median_half_width_percent
        );
    }
    let all: usize = report.rows.iter().map(|r| r.covered).sum();
    let total: usize = report.rows.iter().map(|r| r.total).sum();
    println!(
        "all parameters: {all} / {total} ({:.1}%)",
        100.0 * all as f64 / total.max(1) as f64
    );
    if let Some(f) = json {
        let text = serde_json::to_string_pretty(&report).expect("the report serialises");
        if let Err(e) = std::fs::write(&f, text + "\n") {
            eprintln!("{f}: cannot write: {e}");
            std::process::exit(1);
        }
    }
}

fn parse<T: std::str::FromStr>(s: &str, what: &str) -> T {
    s.parse().unwrap_or_else(|_| {
        eprintln!("{what}: `{s}` is not a valid number");
        std::process::exit(2)
    })
}
