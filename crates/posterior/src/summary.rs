//! What a posterior run gives back, as values: the summary per parameter, the correlations,
//! the convergence, and the thinned chain (with a CSV writer).

use crate::convergence::Convergence;
use crate::ensemble::{Run, Stop};
use crate::target::{is_log, NoiseScale};
use serde::Serialize;
use std::io::{self, Write};
use subfric_fit::{Param, Space};

/// The posterior of one free parameter (natural units).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParamSummary {
    /// Key (as in `params.json`).
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Median.
    pub median: f64,
    /// 2.5 % quantile: with `hi`, the 95 % equal-tailed credible interval.
    pub lo: f64,
    /// 97.5 % quantile.
    pub hi: f64,
    /// Mean.
    pub mean: f64,
    /// Standard deviation.
    pub sd: f64,
    /// The prior used.
    pub prior: String,
}

impl ParamSummary {
    /// Whether the 95 % credible interval holds `v`.
    pub fn covers(&self, v: f64) -> bool {
        self.lo <= v && v <= self.hi
    }
}

/// Everything a posterior run found.
#[derive(Clone, Debug, Serialize)]
pub struct Posterior {
    /// The free parameters, in the order of every per-parameter vector.
    pub parameters: Vec<Param>,
    /// Per parameter.
    pub summary: Vec<ParamSummary>,
    /// Correlation matrix of the natural parameters over the kept samples.
    pub correlation: Vec<Vec<f64>>,
    /// Convergence: τ, R̂ and ESS per parameter, and the verdict.
    pub convergence: Convergence,
    /// Why the sampler stopped.
    pub stopped: Stop,
    /// Share of proposed moves accepted.
    pub acceptance: f64,
    /// Model runs of the sampler (proposals outside the bounds or the priors' support cost
    /// none).
    pub model_runs: usize,
    /// Model runs that failed (taken as zero likelihood).
    pub failed_runs: usize,
    /// The noise scale of the likelihood.
    pub noise: NoiseScale,
    /// Natural values at the least-squares optimum the walkers started around.
    pub optimum: Vec<f64>,
    /// Steps kept in [`Posterior::chain`]: every `thin`-th after the burn-in (about τ/2).
    pub thin: usize,
    /// Wall time [s].
    pub elapsed_s: f64,
    /// The thinned chain, natural values (not serialised: see [`Posterior::write_chain_csv`]).
    #[serde(skip)]
    pub chain: Chain,
    /// The space the samples live in (to turn them into models).
    #[serde(skip)]
    pub(crate) space: Space,
}

/// Thinned samples of every walker.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Chain {
    /// Step of each sample.
    pub step: Vec<usize>,
    /// Walker of each sample.
    pub walker: Vec<usize>,
    /// Natural values of the free parameters of each sample.
    pub values: Vec<Vec<f64>>,
    /// Optimiser coordinates of each sample.
    pub coords: Vec<Vec<f64>>,
    /// Log posterior density of each sample on the optimiser coordinates (up to a constant).
    pub log_density: Vec<f64>,
}

impl Chain {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// True when there is no sample.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Parameter `k` of every sample.
    pub fn column(&self, k: usize) -> Vec<f64> {
        self.values.iter().map(|v| v[k]).collect()
    }
}

impl Posterior {
    /// Summary of a parameter by key.
    pub fn param(&self, key: &str) -> Option<&ParamSummary> {
        self.summary.iter().find(|s| s.name == key)
    }

    /// The model of sample `i` of the thinned chain.
    pub fn model_of(&self, i: usize) -> subfric_model::Model {
        self.space.model_at(&self.chain.coords[i])
    }

    /// Writes the thinned chain as CSV (through the `csv` crate's writer,
    /// [`subfric_data::csvio::writer`]): a header line `step,walker,<parameter keys>`, then
    /// one line per sample, values in natural units with full precision.
    pub fn write_chain_csv<W: Write>(&self, out: &mut W) -> io::Result<()> {
        let mut w = subfric_data::csvio::writer(out);
        let head = ["step", "walker"]
            .into_iter()
            .chain(self.parameters.iter().map(|p| p.key()));
        w.write_record(head)?;
        for i in 0..self.chain.len() {
            let ids = [
                self.chain.step[i].to_string(),
                self.chain.walker[i].to_string(),
            ];
            let values = self.chain.values[i].iter().map(|v| format!("{v:e}"));
            w.write_record(ids.into_iter().chain(values))?;
        }
        w.flush()
    }

    /// A plain-text table of the summary and the convergence (for `fit.txt`-like reports).
    pub fn table(&self) -> String {
        let mut s = format!(
            "{:<20} {:>12} {:>12} {:>12} {:>12} {:>8} {:>7} {:>9}\n",
            "parameter", "median", "2.5%", "97.5%", "sd", "tau", "R-hat", "ESS"
        );
        for (p, d) in self.summary.iter().zip(&self.convergence.quantities) {
            let name = if p.unit.is_empty() {
                p.name.clone()
            } else {
                format!("{} [{}]", p.name, p.unit)
            };
            s += &format!(
                "{:<20} {:>12.5e} {:>12.5e} {:>12.5e} {:>12.4e} {:>8.1} {:>7.3} {:>9.0}\n",
                name, p.median, p.lo, p.hi, p.sd, d.tau, d.rhat, d.ess
            );
        }
        s += &self.convergence.message();
        s.push('\n');
        s
    }
}

/// The posterior's values from a finished run.
pub(crate) struct Assembly<'a> {
    pub run: &'a Run,
    pub space: &'a Space,
    pub priors: Vec<String>,
    pub noise: NoiseScale,
    pub optimum: Vec<f64>,
    pub model_runs: usize,
    pub failed_runs: usize,
    pub elapsed_s: f64,
}

impl Assembly<'_> {
    pub fn posterior(self) -> Posterior {
        let run = self.run;
        let params = self.space.free.clone();
        let d = params.len();
        let burn = run.convergence.burn_in;
        let natural = |q: &[f64]| -> Vec<f64> {
            q.iter()
                .zip(&params)
                .map(|(v, p)| if is_log(*p) { v.exp() } else { *v })
                .collect()
        };
        // Every kept sample, per parameter.
        let mut columns: Vec<Vec<f64>> = vec![Vec::new(); d];
        for s in burn..run.steps {
            for w in 0..run.walkers {
                for (k, v) in natural(run.quantities_at(s, w)).into_iter().enumerate() {
                    columns[k].push(v);
                }
            }
        }
        let summary: Vec<ParamSummary> = params
            .iter()
            .zip(&columns)
            .zip(&self.priors)
            .map(|((p, c), prior)| summarise(*p, c, prior))
            .collect();
        let correlation = correlations(&columns);
        let thin = thinning(&run.convergence);
        let mut chain = Chain::default();
        let mut s = burn;
        while s < run.steps {
            for w in 0..run.walkers {
                chain.step.push(s);
                chain.walker.push(w);
                chain.values.push(natural(run.quantities_at(s, w)));
                chain.coords.push(run.coords_at(s, w).to_vec());
                chain.log_density.push(run.log_density_at(s, w));
            }
            s += thin;
        }
        Posterior {
            parameters: params,
            summary,
            correlation,
            convergence: run.convergence.clone(),
            stopped: run.stopped,
            acceptance: run.acceptance(),
            model_runs: self.model_runs,
            failed_runs: self.failed_runs,
            noise: self.noise,
            optimum: self.optimum,
            thin,
            elapsed_s: self.elapsed_s,
            chain,
            space: self.space.clone(),
        }
    }
}

/// Thinning of the stored chain: half the smallest finite τ of the judged parameters.
fn thinning(c: &Convergence) -> usize {
    let tau = c
        .quantities
        .iter()
        .filter(|q| q.judged && q.tau.is_finite())
        .map(|q| q.tau)
        .fold(f64::INFINITY, f64::min);
    if tau.is_finite() {
        ((tau / 2.0).floor() as usize).max(1)
    } else {
        1
    }
}

/// The `q` quantile of sorted values (linear interpolation between order statistics): the
/// one of [`subfric_reading::stats`].
pub use subfric_reading::stats::quantile;

fn summarise(p: Param, values: &[f64], prior: &str) -> ParamSummary {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = values.len().max(1) as f64;
    let mean = values.iter().sum::<f64>() / n;
    let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0)).sqrt();
    ParamSummary {
        name: p.key().into(),
        unit: p.unit().into(),
        median: quantile(&sorted, 0.5),
        lo: quantile(&sorted, 0.025),
        hi: quantile(&sorted, 0.975),
        mean,
        sd,
        prior: prior.to_string(),
    }
}

fn correlations(columns: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let stats: Vec<(f64, f64)> = columns
        .iter()
        .map(|c| {
            let n = c.len().max(1) as f64;
            let m = c.iter().sum::<f64>() / n;
            let sd = (c.iter().map(|v| (v - m).powi(2)).sum::<f64>() / n).sqrt();
            (m, sd)
        })
        .collect();
    (0..columns.len())
        .map(|i| {
            (0..columns.len())
                .map(|j| {
                    let (mi, si) = stats[i];
                    let (mj, sj) = stats[j];
                    if si > 0.0 && sj > 0.0 {
                        let n = columns[i].len().max(1) as f64;
                        let c: f64 = columns[i]
                            .iter()
                            .zip(&columns[j])
                            .map(|(a, b)| (a - mi) * (b - mj))
                            .sum();
                        (c / n / (si * sj)).clamp(-1.0, 1.0)
                    } else {
                        f64::NAN
                    }
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_interpolate_between_order_statistics() {
        let v: Vec<f64> = (0..=100).map(f64::from).collect();
        assert_eq!(quantile(&v, 0.5), 50.0);
        assert!((quantile(&v, 0.025) - 2.5).abs() < 1e-12);
        assert_eq!(quantile(&v, 1.0), 100.0);
        assert!(quantile(&[], 0.5).is_nan());
    }

    #[test]
    fn correlations_of_linearly_related_columns_are_plus_minus_one() {
        let a: Vec<f64> = (0..50).map(|i| (i as f64 * 0.37).sin()).collect();
        let b: Vec<f64> = a.iter().map(|v| 3.0 - 2.0 * v).collect();
        let c = correlations(&[a.clone(), b, vec![1.0; 50]]);
        assert!((c[0][1] + 1.0).abs() < 1e-12);
        assert!((c[0][0] - 1.0).abs() < 1e-12);
        assert!(c[2][0].is_nan(), "a constant column has no correlation");
    }
}
