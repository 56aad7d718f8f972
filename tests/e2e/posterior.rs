//! `subfric fit --posterior` (issue 23) run as a user runs it: every promised file written in
//! the fit's claim (fit.json and fit.txt with the posterior beside the profile intervals, the
//! chain CSV, the corner plot, a band figure per test), a run that has not converged saying so
//! with the budget it needs, a prior file with an error refused at its line before anything
//! runs, the prior actually used, and the application layer giving the program's fit.json.
//! Every run is small (a quick fit and a budget of a few thousand model runs): the sampler's
//! correctness on known targets is tested in crates/posterior.

use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};

use serde_json::Value;
use subfric_app::fit::FitRequest;
use subfric_app::posterior::PosteriorRequest;
use subfric_app::Silent;
use subfric_e2e::{args, assert_mentions, experiments, read_json, subfric};
use subfric_fit::FitOptions;

/// A fit small enough for a test.
const QUICK: [&str; 5] = ["--global-evals", "100", "--starts", "2", "--no-profiles"];
/// A budget far too small to converge, large enough for some 90 steps of 32 walkers.
const BUDGET: usize = 3000;
const FREE: [&str; 5] = ["mu_s", "mu_k", "kappa", "xi", "u_tilde"];

/// `fit <set> QUICK --posterior --max-evals BUDGET --out <out> <extra>`.
fn posterior_fit(set: &Path, out: &Path, extra: &[&str]) -> Vec<OsString> {
    let mut a: Vec<OsString> = vec!["fit".into(), set.into()];
    a.extend(QUICK.iter().map(OsString::from));
    a.extend(
        ["--posterior", "--max-evals", &BUDGET.to_string(), "--out"]
            .iter()
            .map(OsString::from),
    );
    a.push(out.into());
    a.extend(extra.iter().map(OsString::from));
    a
}

fn os(v: &[OsString]) -> Vec<&OsStr> {
    v.iter().map(|s| s.as_os_str()).collect()
}

fn medium() -> PathBuf {
    experiments().join("table1-medium")
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("{v} is not a number"))
}

/// The thinned chain: header and rows.
fn read_chain(p: &Path) -> (String, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines();
    let header = lines.next().expect("a header line").to_string();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|c| {
                    c.parse::<f64>()
                        .unwrap_or_else(|_| panic!("`{c}` in `{l}`"))
                })
                .collect()
        })
        .collect();
    (header, rows)
}

/// Width and height of a PNG file (decoded in full, so a truncated file fails).
fn png_size(p: &Path) -> (u32, u32) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(p).unwrap()));
    let mut reader = decoder
        .read_info()
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let mut buf = vec![0; reader.output_buffer_size().expect("a PNG of sane size")];
    let info = reader
        .next_frame(&mut buf)
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    (info.width, info.height)
}

#[test]
fn fit_with_posterior_writes_every_promised_file_beside_the_fit() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("post");
    let a = posterior_fit(&medium(), &out, &["--progress", "always"]);
    let (stdout, stderr) = subfric!().ok_both(&os(&a));
    // The files, each said on the terminal.
    let files = [
        "fit.json",
        "fit.txt",
        "posterior-chain.csv",
        "posterior-corner.png",
        "posterior-band-monotonic.png",
    ];
    for f in files {
        assert!(out.join(f).is_file(), "{f} missing");
        assert_mentions(&stdout, &[&format!("wrote {}", out.join(f).display())]);
    }
    assert!(out.join(".subfric-source").is_file(), "the claim's record");
    // The sampler's progress, counted in model runs, in a log (`--progress always`, no terminal).
    assert_mentions(&stderr, &["progress: posterior sampling (", " %)"]);

    let fit = read_json(&out.join("fit.json"));
    let p = &fit["posterior"];
    assert_eq!(p["parameters"], serde_json::json!(FREE));
    let summary = p["summary"].as_array().unwrap();
    assert_eq!(summary.len(), 5);
    for (s, (key, fitted)) in summary.iter().zip(
        FREE.iter()
            .zip(fit["report"]["parameters"].as_array().unwrap()),
    ) {
        assert_eq!(s["name"], *key);
        let (lo, med, hi) = (num(&s["lo"]), num(&s["median"]), num(&s["hi"]));
        assert!(lo <= med && med <= hi && lo < hi, "{key}: {lo} {med} {hi}");
        // Beside the profile interval (none without profiles) and the fit's verdict.
        assert!(s["profile_interval"].is_null(), "{s}");
        assert_eq!(s["identifiability"], fitted["status"]);
        assert!(s["prior"].as_str().unwrap().contains("(default"), "{s}");
        // The walkers started at the least-squares optimum of this very fit.
        // (through the chart and back: equal to the last bits)
        let start = num(&p["optimum"][FREE.iter().position(|k| k == key).unwrap()]);
        let value = num(&fitted["value"]);
        assert!(
            (start - value).abs() <= 1e-12 * value.abs(),
            "{key}: {start} {value}"
        );
    }
    let corr = p["correlation"].as_array().unwrap();
    assert_eq!(corr.len(), 5);
    for (i, row) in corr.iter().enumerate() {
        assert!((num(&row[i]) - 1.0).abs() < 1e-9, "diagonal {row}");
        for (j, c) in row.as_array().unwrap().iter().enumerate() {
            assert_eq!(num(c), num(&corr[j][i]), "symmetric");
        }
    }
    assert!(p.get("elapsed_s").is_none(), "no wall time in fit.json");
    assert_eq!(p["options"]["max_evals"], BUDGET);
    assert_eq!(p["options"]["residuals"], "autocorrelated");

    // The chain: its header, one line per sample of the JSON's count, values within the box.
    let (header, rows) = read_chain(&out.join("posterior-chain.csv"));
    assert_eq!(header, format!("step,walker,{}", FREE.join(",")));
    assert_eq!(rows.len() as u64, p["chain_samples"].as_u64().unwrap());
    assert!(!rows.is_empty());
    let walkers = p["convergence"]["walkers"].as_u64().unwrap() as f64;
    let burn_in = p["convergence"]["burn_in"].as_u64().unwrap() as f64;
    for r in &rows {
        assert_eq!(r.len(), 7);
        assert!(r[0] >= burn_in && r[1] < walkers, "{r:?}");
        assert!(r[2..].iter().all(|v| v.is_finite()), "{r:?}");
        assert!(r[3] >= 0.0 && r[3] <= r[2], "mu_k within 0..mu_s: {r:?}");
    }
    // The chain is the posterior summarised: its median of mu_s lies in the credible interval.
    let mut mu_s: Vec<f64> = rows.iter().map(|r| r[2]).collect();
    mu_s.sort_by(f64::total_cmp);
    let m = mu_s[mu_s.len() / 2];
    assert!(
        num(&summary[0]["lo"]) <= m && m <= num(&summary[0]["hi"]),
        "{m}"
    );

    for f in ["posterior-corner.png", "posterior-band-monotonic.png"] {
        let (w, h) = png_size(&out.join(f));
        assert!(w >= 600 && h >= 400, "{f}: {w}×{h}");
    }

    // fit.txt: the fit's table, then the posterior beside the profile intervals, as printed.
    let txt = std::fs::read_to_string(out.join("fit.txt")).unwrap();
    // As printed: the verdict first, then the fit's table.
    assert!(txt.starts_with("verdict: "), "{txt}");
    assert!(txt.contains("\nfit of table1-medium:"), "{txt}");
    assert_mentions(
        &txt,
        &[
            "95% credible interval",
            "95% profile interval",
            "correlations of the posterior samples:",
            "priors (default: uniform within the bounds, on the fit's scale): mu_s log-uniform(",
            "posterior-chain.csv",
        ],
    );
    let section = &txt[txt.find("posterior (ensemble sampler").unwrap()..];
    assert!(stdout.contains(section.trim_end()), "stdout:\n{stdout}");

    // The same seed gives the same posterior, byte for byte.
    let again = tmp.path().join("again");
    subfric!().ok(&os(&posterior_fit(
        &medium(),
        &again,
        &["--progress", "never"],
    )));
    for f in ["fit.json", "fit.txt", "posterior-chain.csv"] {
        assert_eq!(
            std::fs::read(out.join(f)).unwrap(),
            std::fs::read(again.join(f)).unwrap(),
            "{f} differs between two runs of the same seed"
        );
    }
}

#[test]
fn a_budget_too_small_says_not_converged_and_how_much_more_it_needs() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("short");
    let (stdout, stderr) = subfric!().ok_both(&os(&posterior_fit(
        &medium(),
        &out,
        &["--progress", "never"],
    )));
    let fit = read_json(&out.join("fit.json"));
    let p = &fit["posterior"];
    assert_eq!(p["converged"], false);
    assert_eq!(p["convergence"]["verdict"]["status"], "not-converged");
    let more = p["convergence"]["verdict"]["more_steps"].as_u64().unwrap();
    assert!(more > 0);
    let needed = p["max_evals_needed"].as_u64().unwrap();
    assert!(needed as usize > BUDGET, "{needed}");
    // Said plainly on the terminal (the table and a warning), in fit.txt and in fit.json.
    let sentence = format!("it needs about {more} more steps");
    let advice = format!("(give --max-evals {needed} or more)");
    assert_mentions(
        &stdout,
        &[
            "posterior NOT converged after",
            &sentence,
            &advice,
            "do not quote them",
        ],
    );
    assert_mentions(
        &stderr,
        &["warning: the posterior has NOT converged after", &advice],
    );
    let txt = std::fs::read_to_string(out.join("fit.txt")).unwrap();
    assert_mentions(&txt, &["posterior NOT converged after", &sentence, &advice]);
    let message = p["message"].as_str().unwrap();
    assert!(message.starts_with("NOT converged after"), "{message}");
    assert_mentions(message, &[&sentence, &advice]);
    // Without profiles the fit determines nothing, so every free parameter is judged.
    assert_eq!(p["judged"], serde_json::json!(FREE));
    assert_mentions(p["judged_because"].as_str().unwrap(), &["--no-profiles"]);
}

#[test]
fn a_prior_file_with_errors_is_refused_at_its_lines_before_anything_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("never");
    let refused = |priors: &Path, extra: &[&str]| -> String {
        let mut a = posterior_fit(&medium(), &out, &["--priors"]);
        a.push(priors.into());
        a.extend(extra.iter().map(OsString::from));
        let e = subfric!().err(&os(&a));
        assert!(
            !out.exists(),
            "an output folder was made for a refused request"
        );
        e
    };
    // Two problems in one file, each with its line and field, at once.
    let toml = tmp.path().join("p.toml");
    std::fs::write(
        &toml,
        "[kappa]\ndist = \"log-uniform\"\nlo = 0.1\nhi = 100.0\n\n[xi]\ndist = \"log-normal\"\nmedian = 0.002\n\n[mu_k]\ndist = \"normal\"\nmean = \"a\"\nsd = 0.01\n",
    )
    .unwrap();
    let e = refused(&toml, &[]);
    assert_mentions(
        &e,
        &[
            &format!("{}:6: field `xi.sigma`: missing", toml.display()),
            &format!(
                "{}:12: field `mu_k.mean`: \"a\" is text (expected a number)",
                toml.display()
            ),
        ],
    );
    // JSON: a syntax error at its line; an unknown parameter with the valid keys.
    let json = tmp.path().join("p.json");
    std::fs::write(
        &json,
        "{\"kappa\": {\"dist\": \"uniform\",\n \"lo\": 1 \"hi\": 2}}\n",
    )
    .unwrap();
    assert_mentions(&refused(&json, &[]), &[&format!("{}:2", json.display())]);
    std::fs::write(
        &json,
        "{\"kapa\": {\"dist\": \"uniform\", \"lo\": 1, \"hi\": 2}}\n",
    )
    .unwrap();
    assert_mentions(
        &refused(&json, &[]),
        &[&format!("{}:1: field `kapa`", json.display()), "kappa"],
    );
    // A prior on a parameter the fit holds fixed, and one whose support misses the bounds.
    std::fs::write(
        &json,
        "{\"kappa\": {\"dist\": \"uniform\", \"lo\": 1, \"hi\": 2}}\n",
    )
    .unwrap();
    assert_mentions(
        &refused(&json, &["--fix", "kappa=30"]),
        &[&format!("{}:1: field `kappa`", json.display()), "not free"],
    );
    std::fs::write(
        &json,
        "{\"kappa\": {\"dist\": \"uniform\", \"lo\": 2e4, \"hi\": 3e4}}\n",
    )
    .unwrap();
    assert_mentions(
        &refused(&json, &[]),
        &[
            &format!("{}:1: field `kappa`", json.display()),
            "lies outside the bounds of kappa",
        ],
    );
    // A file that is not there.
    assert_mentions(
        &refused(&tmp.path().join("absent.toml"), &[]),
        &["cannot read the prior file", "absent.toml"],
    );
    // The posterior's options without --posterior are usage errors naming it.
    let e = subfric!().usage_err(args!["fit", &medium(), "--priors", &toml, "--out", &out]);
    assert_mentions(&e, &["--posterior"]);
    let e = subfric!().usage_err(args![
        "fit",
        &medium(),
        "--max-evals",
        "5000",
        "--out",
        &out
    ]);
    assert_mentions(&e, &["--posterior"]);
    // A budget that cannot move the walkers once is refused before the fit, with the least.
    let e = subfric!().err(args![
        "fit",
        &medium(),
        "--posterior",
        "--max-evals",
        "10",
        "--out",
        &out
    ]);
    assert_mentions(&e, &["--max-evals 10", "expected at least 64"]);
    assert!(!out.exists());
}

#[test]
fn a_given_prior_is_the_one_sampled() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("prior");
    let toml = tmp.path().join("kappa.toml");
    // Around the optimum's κ (≈ 34.7 /mm on this set), narrower than the default box.
    std::fs::write(&toml, "[kappa]\ndist = \"log-uniform\"\nlo = 20\nhi = 50\n").unwrap();
    let mut a = posterior_fit(&medium(), &out, &["--progress", "never", "--priors"]);
    a.push(toml.clone().into());
    subfric!().ok(&os(&a));
    let fit = read_json(&out.join("fit.json"));
    let p = &fit["posterior"];
    assert_eq!(p["summary"][2]["prior"], "log-uniform(20, 50) (given)");
    // xi's default (widened when the quick fit leaves xi below its default bounds).
    let xi = p["summary"][3]["prior"].as_str().unwrap();
    assert!(
        xi.starts_with("log-uniform(") && xi.contains(", 10) (default"),
        "{xi}"
    );
    assert_eq!(p["options"]["priors_file"], toml.display().to_string());
    let (_, rows) = read_chain(&out.join("posterior-chain.csv"));
    assert!(
        rows.iter().all(|r| (20.0..=50.0).contains(&r[4])),
        "a kappa outside the prior's support"
    );
    let txt = std::fs::read_to_string(out.join("fit.txt")).unwrap();
    assert_mentions(&txt, &[&format!("priors from {}", toml.display())]);
}

#[test]
fn the_application_layer_gives_the_posterior_the_program_writes() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("cli");
    let set = experiments().join("table3-pulsating");
    subfric!().ok(&os(&posterior_fit(&set, &out, &["--progress", "never"])));
    let written = std::fs::read_to_string(out.join("fit.json")).unwrap();
    let mut req = FitRequest::of_set(
        set,
        FitOptions {
            global_evaluations: 100,
            starts: 2,
            profiles: false,
            ..FitOptions::default()
        },
    );
    req.posterior = Some(PosteriorRequest {
        max_evals: BUDGET,
        ..PosteriorRequest::default()
    });
    let fitted = subfric_app::fit(&req, &Silent).expect("the set fits and samples");
    assert!(fitted.posterior.is_some());
    let text = serde_json::to_string_pretty(&fitted.json).unwrap() + "\n";
    assert!(
        text == written,
        "the application layer's fit.json with the posterior differs from the program's"
    );

    // A parameter the fit says the data do not determine gets no median in the posterior's
    // table (its posterior is its prior's within the bound), only its interval; the others
    // keep theirs.
    let sampled = fitted.posterior.as_ref().unwrap();
    let mut report = fitted.outcome.report.clone();
    let xi = report
        .parameters
        .iter_mut()
        .find(|p| p.name == "xi")
        .unwrap();
    xi.status = subfric_fit::Status::UpperBoundOnly;
    let table = sampled.text(&report);
    let row = |name: &str| {
        table
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("no row of {name}:\n{table}"))
            .to_string()
    };
    assert!(row("xi").contains("—†"), "{table}");
    assert!(!row("mu_s").contains('—'), "{table}");
    assert_mentions(&table, &["† not determined by the data"]);
    assert!(!sampled.text(&fitted.outcome.report).contains('†'));
}

#[test]
fn a_fit_without_posterior_writes_nothing_of_it() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("plain");
    let mut a: Vec<OsString> = vec!["fit".into(), medium().into()];
    a.extend(QUICK.iter().map(OsString::from));
    a.extend(["--progress", "never", "--out"].iter().map(OsString::from));
    a.push(out.clone().into());
    let stdout = subfric!().ok(&os(&a));
    assert!(!stdout.contains("posterior"), "{stdout}");
    assert!(read_json(&out.join("fit.json")).get("posterior").is_none());
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    names.sort();
    // What a plain fit writes (fit.json, fit.txt, a figure per test as PNG and SVG, the HTML
    // report) and
    // nothing of the posterior's.
    assert_eq!(
        names,
        [
            ".subfric-source",
            "fit.json",
            "fit.txt",
            "monotonic.png",
            "monotonic.svg",
            "report.html"
        ]
    );
    let txt = std::fs::read_to_string(out.join("fit.txt")).unwrap();
    assert!(!txt.contains("credible"), "{txt}");
}
