//! `subfric fit --posterior` (and `subfric.fit(..., posterior=True)`): after the least-squares
//! fit, the posterior of its free parameters sampled around the optimum (`subfric-posterior`),
//! convergence judged on the parameters the fit determined, and its results — the summary
//! beside the profile intervals, the predictive bands, the corner plot, the thinned chain —
//! as values ([`Sampled`]) and as the files the fit's results folder receives ([`files`],
//! [`Sampled::write`]). The method, the prior file and the outputs: docs/posterior.md.
//!
//! Everything a request can get wrong (a prior file with an error, a prior on a parameter
//! that is not free, a budget too small to move the walkers once) is refused by [`prepare`],
//! before any output folder is claimed or any fitting done.

use crate::outcome::FitOutcome;
use crate::progress::Progress;
use anyhow::{anyhow, bail, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use subfric_data::write_atomic;
use subfric_fit::interval::short_number as fmt_num;
use subfric_fit::{FitReport, Param, Space, Status};
use subfric_posterior::{figures, sample, PosteriorOptions, Priors, Verdict};
pub use subfric_posterior::{BandOptions, Posterior, PredictiveDraws, ResidualModel, TestBand};
use subfric_reading::{FitTest, PreparedTest};

/// The thinned chain, for notebooks: `step,walker,<parameter keys>`, one line per sample.
pub const CHAIN_FILE: &str = "posterior-chain.csv";
/// The corner plot of the posterior.
pub const CORNER_FILE: &str = "posterior-corner.png";

/// The default budget of the sampler, in model runs (Table 4 converges in about 90 000).
pub const DEFAULT_MAX_EVALS: usize = 300_000;

/// How the posterior of a fit is sampled.
#[derive(Clone, Debug, PartialEq)]
pub struct PosteriorRequest {
    /// A prior file (JSON or TOML); `None`: uniform within the bounds on the fit's scale.
    pub priors: Option<PathBuf>,
    /// Budget of model runs.
    pub max_evals: usize,
    /// How the residuals' noise enters the likelihood.
    pub residuals: ResidualModel,
    /// Seed of the sampler (the command passes the fit's `--seed`).
    pub seed: u64,
}

impl Default for PosteriorRequest {
    fn default() -> Self {
        PosteriorRequest {
            priors: None,
            max_evals: DEFAULT_MAX_EVALS,
            residuals: ResidualModel::default(),
            seed: 1,
        }
    }
}

impl PosteriorRequest {
    fn options(&self) -> PosteriorOptions {
        PosteriorOptions {
            max_evals: self.max_evals,
            seed: self.seed,
            residuals: self.residuals,
            ..PosteriorOptions::default()
        }
    }
}

/// A posterior request checked against the fit it follows, ready to sample once the fit is
/// done.
pub struct Prepared {
    request: PosteriorRequest,
    priors: Priors,
    space: Space,
    tests: Vec<FitTest>,
}

/// Reads the prior file and checks it and the budget against the fit's free parameters
/// (`space`) and tests: every error here comes before the fit, located in the prior file.
pub fn prepare(req: &PosteriorRequest, space: &Space, tests: &[FitTest]) -> Result<Prepared> {
    let priors = match &req.priors {
        Some(path) => Priors::load(path).map_err(|e| anyhow!("{e}"))?,
        None => Priors::default(),
    };
    priors.resolve(space).map_err(|e| anyhow!("{e}"))?;
    let opts = req.options();
    let least = opts.smallest_budget(space.dim());
    if req.max_evals < least {
        bail!(
            "--max-evals {}: too small to move the sampler's {} walkers even once (expected at least {least}; a converged posterior usually takes 50 000 to 150 000 model runs)",
            req.max_evals,
            opts.walkers_for(space.dim())
        );
    }
    Ok(Prepared {
        request: req.clone(),
        priors,
        space: space.clone(),
        tests: tests.to_vec(),
    })
}

/// The posterior of a fit, with what a reader needs beside it.
pub struct Sampled {
    /// The posterior (summary, correlations, convergence, thinned chain).
    pub posterior: Posterior,
    /// The 95 % band of the model curve per test (every row of the full records).
    pub bands: Vec<TestBand>,
    /// The parameters convergence was judged on.
    pub judged: Vec<Param>,
    /// Why those (the determined ones, or all when the fit determined none).
    pub judged_because: String,
    /// The request.
    pub request: PosteriorRequest,
}

impl Prepared {
    /// Samples the posterior around the fit's optimum, convergence judged on the parameters
    /// the fit determined (all free ones when it determined none), then the predictive band of
    /// every test. A run that has not converged is a result too: it says so (a warning to
    /// `progress`, and in every output) with the budget it would need.
    pub fn sample(self, outcome: &FitOutcome, progress: &dyn Progress) -> Result<Sampled> {
        let report = &outcome.report;
        let determined: Vec<Param> = report
            .parameters
            .iter()
            .filter(|p| p.status == Status::Determined)
            .filter_map(|p| Param::from_key(&p.name))
            .filter(|p| self.space.free.contains(p))
            .collect();
        let (judged, because) = if determined.is_empty() {
            let all = self.space.free.clone();
            let why = if report
                .parameters
                .iter()
                .any(|p| p.status == Status::Unprofiled)
            {
                "all free parameters: without profiles (--no-profiles) the fit does not say which it determines"
            } else {
                "all free parameters: the fit determines none of them"
            };
            (all, why.to_string())
        } else {
            (
                determined,
                "the parameters the fit determines; the others (ESS marked *) are reported, not judged: along a valley a parameter the data leave free mixes slowly".to_string(),
            )
        };
        let opts = PosteriorOptions {
            converge_on: Some(judged.clone()),
            ..self.request.options()
        };
        progress.stage("posterior sampling", Some(opts.max_evals));
        let count = |done: usize, budget: usize| progress.count(done, budget);
        let posterior = sample(
            &self.tests,
            &self.space,
            &report.model,
            &self.priors,
            &opts,
            &count,
        )
        .map_err(|e| anyhow!("the posterior cannot be sampled: {e}"))?;
        if !posterior.convergence.converged() {
            progress.warning(&format!(
                "the posterior has {}",
                not_converged_sentence(&posterior)
            ));
        }
        progress.stage("posterior predictive bands", None);
        let fulls: Vec<FitTest> = outcome.tests.iter().map(|t| t.full.clone()).collect();
        let bands = posterior.predictive_bands(&fulls, &BandOptions::default());
        Ok(Sampled {
            posterior,
            bands,
            judged,
            judged_because: because,
            request: self.request,
        })
    }
}

/// The files the posterior adds to a fit's results folder (names inside it): `fit.txt` (the
/// fit's table and the posterior's), the chain, the corner plot, one band figure per test (each
/// figure a PNG and an SVG).
pub fn files(tests: &[PreparedTest]) -> Vec<String> {
    let mut f = vec!["fit.txt".to_string(), CHAIN_FILE.to_string()];
    for png in std::iter::once(CORNER_FILE.to_string()).chain(band_files(tests)) {
        f.push(png.replace(".png", ".svg"));
        f.push(png);
    }
    f
}

/// One band figure per test: `posterior-band-<figure stem>.png`.
fn band_files(tests: &[PreparedTest]) -> Vec<String> {
    let names: Vec<&str> = tests.iter().map(|t| t.fit.name.as_str()).collect();
    crate::render::figures::figure_stems(&names)
        .into_iter()
        .map(|stem| format!("posterior-band-{stem}.png"))
        .collect()
}

/// "NOT converged after …; … (give --max-evals N)" for the terminal and the warnings.
fn not_converged_sentence(p: &Posterior) -> String {
    let c = &p.convergence;
    let message = c.message();
    let message = message.strip_prefix("NOT ").unwrap_or(&message);
    match budget_needed(p) {
        Some(n) => format!("NOT {message} (give --max-evals {n} or more)"),
        None => format!("NOT {message}"),
    }
}

/// The budget a run that has not converged would need in all, rounded up to two significant
/// digits (None when it has converged).
pub fn budget_needed(p: &Posterior) -> Option<usize> {
    let c = &p.convergence;
    match c.verdict {
        Verdict::Converged => None,
        Verdict::NotConverged { more_steps, .. } => {
            Some(round_up_2(((c.steps + more_steps + 1) * c.walkers) as f64))
        }
    }
}

fn round_up_2(v: f64) -> usize {
    if v <= 0.0 {
        return 0;
    }
    let unit = 10f64.powi((v.log10().floor() as i32 - 1).max(0));
    ((v / unit).ceil() * unit) as usize
}

impl Sampled {
    /// The posterior's block of `fit.json`: the summary per parameter beside its profile
    /// interval and identifiability, correlations, convergence with its verdict in words, the
    /// options, the noise scale, and the files. No wall time: fit.json depends on the data,
    /// the code and the seeds only.
    pub fn json(&self, report: &FitReport) -> Result<serde_json::Value> {
        let p = &self.posterior;
        let mut v = serde_json::to_value(p)?;
        let obj = v
            .as_object_mut()
            .ok_or_else(|| anyhow!("the posterior is not a JSON object"))?;
        obj.remove("elapsed_s");
        obj.insert("parameters".into(), serde_json::json!(keys(&p.parameters)));
        if let Some(rows) = obj.get_mut("summary").and_then(|s| s.as_array_mut()) {
            for row in rows.iter_mut() {
                let Some(r) = row.as_object_mut() else {
                    continue;
                };
                let name = r.get("name").and_then(|n| n.as_str()).unwrap_or_default();
                if let Some(fit) = report.parameters.iter().find(|q| q.name == name) {
                    r.insert(
                        "profile_interval".into(),
                        serde_json::to_value(fit.interval)?,
                    );
                    // As the report's own parameters write it.
                    r.insert("identifiability".into(), serde_json::to_value(fit.status)?);
                }
            }
        }
        obj.insert("converged".into(), p.convergence.converged().into());
        obj.insert(
            "message".into(),
            match p.convergence.converged() {
                true => p.convergence.message(),
                false => not_converged_sentence(p),
            }
            .into(),
        );
        obj.insert("max_evals_needed".into(), budget_needed(p).into());
        obj.insert("judged".into(), serde_json::json!(keys(&self.judged)));
        obj.insert("judged_because".into(), self.judged_because.clone().into());
        obj.insert(
            "options".into(),
            serde_json::json!({
                "priors_file": self.request.priors.as_ref().map(|f| f.display().to_string()),
                "max_evals": self.request.max_evals,
                "residuals": self.request.residuals,
                "seed": self.request.seed,
                "walkers": p.convergence.walkers,
            }),
        );
        obj.insert("chain_file".into(), CHAIN_FILE.into());
        obj.insert("chain_samples".into(), p.chain.len().into());
        obj.insert("corner_file".into(), CORNER_FILE.into());
        obj.insert(
            "bands".into(),
            serde_json::Value::Array(
                self.bands
                    .iter()
                    .map(|b| {
                        serde_json::json!({
                            "test": b.name,
                            "draws": b.draws,
                            "failed_draws": b.failed_draws,
                            "with_noise": b.with_noise,
                        })
                    })
                    .collect(),
            ),
        );
        Ok(v)
    }

    /// The posterior's section of `fit.txt` and of the terminal: per parameter the median and
    /// the 95 % credible interval beside the 95 % profile interval and the fit's verdict, τ,
    /// R̂ and ESS; the correlations; the priors; and whether the run converged — said plainly,
    /// with the budget it would need when it has not.
    pub fn text(&self, report: &FitReport) -> String {
        let p = &self.posterior;
        let c = &p.convergence;
        let mut s = String::new();
        let _ = writeln!(s, "{}", sampler_line(p));
        let _ = writeln!(
            s,
            "{:<18} {:>11} {:>26} {:>26}  {:<34} {:>7} {:>6} {:>7}",
            "parameter",
            "median",
            "95% credible interval",
            "95% profile interval",
            "identifiability",
            "tau",
            "R-hat",
            "ESS"
        );
        let mut unquoted = false;
        for (k, (sum, d)) in p.summary.iter().zip(&c.quantities).enumerate() {
            let fit = report.parameters.iter().find(|q| q.name == sum.name);
            let judged = self.judged.contains(&p.parameters[k]);
            // The median of a parameter the data do not determine is where the prior puts it:
            // no number to quote (the interval still says what prior and data allow).
            let median = if fit.is_some_and(|f| f.undetermined()) {
                unquoted = true;
                "—†".to_string()
            } else {
                fmt_num(sum.median)
            };
            let _ = writeln!(
                s,
                "{:<18} {:>11} {:>26} {:>26}  {:<34} {:>7} {:>6} {:>7}",
                labelled(&sum.name, &sum.unit),
                median,
                format!("[{}, {}]", fmt_num(sum.lo), fmt_num(sum.hi)),
                fit.and_then(|f| f.interval)
                    .map(|i| i.to_string())
                    .unwrap_or_default(),
                fit.map(|f| f.status.describe()).unwrap_or_default(),
                finite_or_dash(d.tau, 1),
                finite_or_dash(d.rhat, 3),
                format!(
                    "{}{}",
                    finite_or_dash(d.ess, 0),
                    if judged { "" } else { "*" }
                ),
            );
        }
        if unquoted {
            let _ = writeln!(
                s,
                "† not determined by the data (the fit's profile): its posterior is shaped by its prior within the bound the data set, so no median is quoted (posterior.json keeps it); the credible interval says what prior and data allow together"
            );
        }
        let _ = writeln!(
            s,
            "convergence judged on {}: {}",
            keys(&self.judged).join(", "),
            self.judged_because
        );
        if p.parameters.len() > 1 {
            s.push_str(&correlation_table(p));
        }
        let priors: Vec<String> = p
            .summary
            .iter()
            .map(|sum| format!("{} {}", sum.name, sum.prior))
            .collect();
        let _ = writeln!(
            s,
            "priors{} (default: uniform within the bounds, on the fit's scale): {}",
            self.request
                .priors
                .as_ref()
                .map(|f| format!(" from {}", crate::visible(&f.display().to_string())))
                .unwrap_or_default(),
            priors.join("; ")
        );
        if c.converged() {
            let _ = writeln!(s, "posterior {}", c.message());
        } else {
            let _ = writeln!(s, "posterior {}", not_converged_sentence(p));
            let _ = writeln!(
                s,
                "the medians and intervals above are those of an unconverged chain: do not quote them"
            );
        }
        let _ = writeln!(
            s,
            "chain ({} samples, every {} steps after the burn-in) in {CHAIN_FILE}; corner plot in {CORNER_FILE}; one band figure per test in posterior-band-<test>.png",
            p.chain.len(),
            p.thin
        );
        s
    }

    /// Writes the chain, the corner plot and one band figure per test into `dir` (claimed by
    /// the caller); returns the files written.
    pub fn write(&self, outcome: &FitOutcome, dir: &Path) -> Result<Vec<PathBuf>> {
        let mut written = Vec::new();
        let chain = dir.join(CHAIN_FILE);
        let mut csv = Vec::new();
        self.posterior.write_chain_csv(&mut csv)?;
        write_atomic(&chain, &csv).map_err(|e| anyhow!("cannot write {e}"))?;
        written.push(chain);
        let corner = dir.join(CORNER_FILE);
        subfric_plot::write_figure(
            &figures::corner_figure(
                &self.posterior,
                &format!(
                    "{}: posterior{}",
                    crate::visible(&outcome.name),
                    if self.posterior.convergence.converged() {
                        String::new()
                    } else {
                        " (NOT converged)".to_string()
                    }
                ),
                None,
            ),
            &corner,
        )?;
        written.push(corner);
        for ((t, band), file) in outcome
            .tests
            .iter()
            .zip(&self.bands)
            .zip(band_files(&outcome.tests))
        {
            let path = dir.join(file);
            subfric_plot::write_figure(
                &figures::band_figure(
                    &t.full,
                    band,
                    Some(&outcome.report.model),
                    &format!("{}: {}", crate::visible(&outcome.name), t.full.name),
                ),
                &path,
            )?;
            written.push(path);
        }
        Ok(written)
    }
}

fn keys(params: &[Param]) -> Vec<&'static str> {
    params.iter().map(|p| p.key()).collect()
}

fn labelled(name: &str, unit: &str) -> String {
    if unit.is_empty() {
        name.to_string()
    } else {
        format!("{name} [{unit}]")
    }
}

fn finite_or_dash(v: f64, decimals: usize) -> String {
    if v.is_finite() {
        format!("{v:.decimals$}")
    } else {
        "—".into()
    }
}

/// The sampler's line that heads the posterior's text: walkers, model runs (and failed ones),
/// acceptance and the noise the likelihood assumed.
fn sampler_line(p: &Posterior) -> String {
    let c = &p.convergence;
    format!(
        "posterior (ensemble sampler, {} walkers, {} model runs{}, acceptance {:.2}; noise of the fit × {:.3}{}):",
        c.walkers,
        p.model_runs,
        if p.failed_runs > 0 {
            format!(" of which {} failed", p.failed_runs)
        } else {
            String::new()
        },
        p.acceptance,
        p.noise.variance_scale,
        match p.noise.model {
            ResidualModel::Autocorrelated => format!(
                ", residuals correlated over {:.2} rows",
                p.noise.correlation_time
            ),
            ResidualModel::Independent => ", residuals independent".to_string(),
        }
    )
}

/// The correlation matrix of the posterior samples, one row per parameter ("—" where a
/// correlation is not a number).
fn correlation_table(p: &Posterior) -> String {
    let mut s = String::from("correlations of the posterior samples:\n");
    let names = keys(&p.parameters);
    let width = names.iter().map(|n| n.len()).max().unwrap_or(0).max(6);
    let _ = write!(s, "  {:<width$}", "");
    for n in &names {
        let _ = write!(s, " {n:>width$}");
    }
    s.push('\n');
    for (n, row) in names.iter().zip(&p.correlation) {
        let _ = write!(s, "  {n:<width$}");
        for r in row {
            let cell = if r.is_finite() {
                format!("{r:+.2}")
            } else {
                "—".into()
            };
            let _ = write!(s, " {cell:>width$}");
        }
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budgets_round_up_to_two_significant_digits() {
        assert_eq!(round_up_2(9360.0), 9400);
        assert_eq!(round_up_2(88_436.0), 89_000);
        assert_eq!(round_up_2(64.0), 64);
        assert_eq!(round_up_2(7.0), 7);
        assert_eq!(round_up_2(100_000.0), 100_000);
    }
}
