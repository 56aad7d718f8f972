//! Convergence of an ensemble run, measured and reported, never assumed: the integrated
//! autocorrelation time τ of every quantity (Sokal's automatic window, as emcee computes it),
//! the split R̂ over groups of walkers, the effective sample size, and from these a verdict that
//! says either "converged" or roughly how many more steps the run needs.

use rayon::prelude::*;
use serde::Serialize;
use subfric_reading::stats::mean_var;

pub use subfric_reading::stats::{integrated_time, SOKAL_WINDOW};

/// Groups of walkers the split R̂ compares (each group split into two halves in time).
pub const RHAT_GROUPS: usize = 4;

/// Burn-in, in autocorrelation times, discarded before anything is judged or summarised.
pub const BURN_IN_TAUS: f64 = 3.0;

/// What "converged" means.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Targets {
    /// Largest accepted split R̂ (1.01).
    pub max_rhat: f64,
    /// Fewest accepted effective samples (1000).
    pub min_ess: f64,
    /// The kept chain must be at least this many τ long for τ itself to be trusted (emcee's
    /// rule of thumb: 50).
    pub tau_multiple: f64,
}

impl Default for Targets {
    fn default() -> Self {
        Targets {
            max_rhat: 1.01,
            min_ess: 1000.0,
            tau_multiple: 50.0,
        }
    }
}

/// Diagnostics of one quantity over the kept part of the chain.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnostics {
    /// Name of the quantity.
    pub name: String,
    /// Integrated autocorrelation time [steps] (infinite when the walkers did not move).
    pub tau: f64,
    /// Split R̂ over walker groups.
    pub rhat: f64,
    /// Effective sample size: kept steps × walkers / τ.
    pub ess: f64,
    /// Whether this quantity counts for the verdict.
    pub judged: bool,
    /// What it still misses, empty when it meets every target (or is not judged).
    pub shortfalls: Vec<String>,
}

/// The verdict.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "kebab-case")]
pub enum Verdict {
    /// Every judged quantity meets every target.
    Converged,
    /// Some judged quantity misses a target.
    NotConverged {
        /// About how many more steps of the whole ensemble would meet the targets.
        more_steps: usize,
        /// The same in model evaluations (steps × walkers).
        more_evaluations: usize,
    },
}

/// Convergence of a run: per quantity, and the verdict.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Convergence {
    /// Walkers of the ensemble.
    pub walkers: usize,
    /// Steps run (every walker moved once per step).
    pub steps: usize,
    /// Steps discarded as burn-in (BURN_IN_TAUS × the largest judged τ, at most half).
    pub burn_in: usize,
    /// Per quantity.
    pub quantities: Vec<Diagnostics>,
    /// Converged or not, and if not, how much more is needed.
    pub verdict: Verdict,
    /// The targets judged against.
    pub targets: Targets,
}

impl Convergence {
    /// True when every judged quantity meets every target.
    pub fn converged(&self) -> bool {
        self.verdict == Verdict::Converged
    }

    /// Steps kept after the burn-in.
    pub fn kept_steps(&self) -> usize {
        self.steps - self.burn_in
    }

    /// A sentence or two for a report.
    pub fn message(&self) -> String {
        let judged: Vec<&Diagnostics> = self.quantities.iter().filter(|d| d.judged).collect();
        let names = judged
            .iter()
            .map(|d| d.name.as_str())
            .collect::<Vec<_>>()
            .join(", ");
        let t = &self.targets;
        match &self.verdict {
            Verdict::Converged => format!(
                "converged after {} steps of {} walkers ({} kept after a burn-in of {}): split R-hat <= {} and >= {:.0} effective samples for {names}",
                self.steps,
                self.walkers,
                self.kept_steps(),
                self.burn_in,
                t.max_rhat,
                t.min_ess
            ),
            Verdict::NotConverged {
                more_steps,
                more_evaluations,
            } => {
                let misses: Vec<String> = judged
                    .iter()
                    .filter(|d| !d.shortfalls.is_empty())
                    .map(|d| format!("{}: {}", d.name, d.shortfalls.join(", ")))
                    .collect();
                format!(
                    "NOT converged after {} steps of {} walkers ({} kept after a burn-in of {}): {}; it needs about {more_steps} more steps ({more_evaluations} more model runs), i.e. a budget of about {} model runs in all",
                    self.steps,
                    self.walkers,
                    self.kept_steps(),
                    self.burn_in,
                    misses.join("; "),
                    (self.steps + more_steps + 1) * self.walkers
                )
            }
        }
    }
}

/// Judges a run. `series[q][w]` is quantity `q` of walker `w` at every step (all of the same
/// length); `judged[q]` says whether quantity `q` counts for the verdict.
pub fn judge(
    names: &[String],
    series: &[Vec<Vec<f64>>],
    judged: &[bool],
    targets: &Targets,
) -> Convergence {
    let walkers = series.first().map_or(0, |q| q.len());
    let steps = series
        .first()
        .and_then(|q| q.first())
        .map_or(0, |s| s.len());
    // τ on the second half, where the start has been forgotten, sets the burn-in.
    let half = steps / 2;
    // Quantities in parallel: the checks run while the sampler waits.
    let tau_late = series
        .par_iter()
        .zip(judged)
        .filter(|(_, j)| **j)
        .map(|(q, _)| {
            let late: Vec<&[f64]> = q.iter().map(|s| &s[half..]).collect();
            integrated_time(&late)
        })
        .reduce(|| 0.0f64, f64::max);
    let burn_in = ((BURN_IN_TAUS * tau_late).ceil() as usize).min(half);
    let kept = steps - burn_in;
    let mut quantities = Vec::with_capacity(series.len());
    let mut needed_kept = 0.0f64;
    let mut needed_burn = 0.0f64;
    let measured: Vec<(f64, f64)> = series
        .par_iter()
        .map(|q| {
            let tail: Vec<&[f64]> = q.iter().map(|s| &s[burn_in..]).collect();
            (integrated_time(&tail), split_rhat(&tail, RHAT_GROUPS))
        })
        .collect();
    for ((name, &(tau, rhat)), &is_judged) in names.iter().zip(&measured).zip(judged) {
        let ess = if tau.is_finite() && tau > 0.0 {
            (kept * walkers) as f64 / tau
        } else {
            0.0
        };
        let mut shortfalls = Vec::new();
        if is_judged {
            let (s, need) = shortfall(tau, rhat, ess, kept, walkers, targets);
            shortfalls = s;
            needed_kept = needed_kept.max(need);
            needed_burn = needed_burn.max(BURN_IN_TAUS * tau);
        }
        quantities.push(Diagnostics {
            name: name.clone(),
            tau,
            rhat,
            ess,
            judged: is_judged,
            shortfalls,
        });
    }
    let converged = quantities.iter().all(|d| d.shortfalls.is_empty()) && steps > 0;
    let verdict = if converged {
        Verdict::Converged
    } else {
        let total = if needed_kept.is_finite() && needed_burn.is_finite() {
            needed_kept + needed_burn
        } else {
            // The walkers did not move: nothing can be extrapolated; ask for as much again.
            2.0 * steps.max(1) as f64
        };
        let more_steps = ((total - steps as f64).ceil().max(1.0)) as usize;
        Verdict::NotConverged {
            more_steps,
            more_evaluations: more_steps * walkers,
        }
    };
    Convergence {
        walkers,
        steps,
        burn_in,
        quantities,
        verdict,
        targets: *targets,
    }
}

/// What a judged quantity misses, and how many kept steps would meet every target.
fn shortfall(
    tau: f64,
    rhat: f64,
    ess: f64,
    kept: usize,
    walkers: usize,
    t: &Targets,
) -> (Vec<String>, f64) {
    let mut out = Vec::new();
    if !tau.is_finite() || rhat.is_nan() {
        out.push("the walkers did not move".to_string());
        return (out, f64::INFINITY);
    }
    let kept_f = kept as f64;
    let mut need = 0.0f64;
    if kept_f < t.tau_multiple * tau {
        out.push(format!(
            "chain of {kept} steps shorter than {} tau = {:.0} steps (tau = {tau:.1} is not yet reliable)",
            t.tau_multiple,
            t.tau_multiple * tau
        ));
    }
    need = need.max(t.tau_multiple * tau);
    if rhat > t.max_rhat {
        out.push(format!("split R-hat {rhat:.3} > {}", t.max_rhat));
        // R̂² − 1 falls roughly as 1/length.
        need = need.max(kept_f * (rhat * rhat - 1.0) / (t.max_rhat * t.max_rhat - 1.0));
    }
    if ess < t.min_ess {
        out.push(format!("{ess:.0} effective samples < {:.0}", t.min_ess));
    }
    need = need.max(t.min_ess * tau / walkers.max(1) as f64);
    (out, need)
}

/// Split R̂ (Gelman et al.) with groups of walkers as the chains: the walkers are cut into
/// `groups` contiguous groups, each group's series into a first and a second half, and the
/// 2 × groups pooled chains are compared (between-chain against within-chain variance).
/// Grouping walkers, rather than treating each walker as a chain, is what makes R̂ usable on
/// an ensemble: a single walker's chain is short compared with τ, so per-walker R̂ stays above
/// 1.01 long after the ensemble has converged. NaN when nothing moved.
pub fn split_rhat(walkers: &[&[f64]], groups: usize) -> f64 {
    let w = walkers.len();
    let n = walkers.iter().map(|s| s.len()).min().unwrap_or(0);
    let groups = groups.min(w / 2).max(1);
    let half = n / 2;
    if half < 2 || w == 0 {
        return f64::NAN;
    }
    let mut means = Vec::with_capacity(2 * groups);
    let mut vars = Vec::with_capacity(2 * groups);
    let mut len = 0.0f64;
    for g in 0..groups {
        // Contiguous groups of as equal sizes as the count allows.
        let members = &walkers[g * w / groups..(g + 1) * w / groups];
        for h in 0..2 {
            let pooled: Vec<f64> = members
                .iter()
                .flat_map(|s| s[h * half..(h + 1) * half].iter().copied())
                .collect();
            let (m, v) = mean_var(&pooled);
            means.push(m);
            vars.push(v);
            len += pooled.len() as f64 / (2 * groups) as f64;
        }
    }
    let within = vars.iter().sum::<f64>() / vars.len() as f64;
    let (_, between_over_n) = mean_var(&means);
    if within <= 0.0 {
        return if between_over_n > 0.0 {
            f64::INFINITY
        } else {
            f64::NAN
        };
    }
    let pooled_var = (len - 1.0) / len * within + between_over_n;
    (pooled_var / within).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use subfric_reading::stats::autocorrelation;

    use crate::predictive::normal;

    /// AR(1) series x_t = ρ x_{t−1} + √(1−ρ²) e_t, whose τ is (1 + ρ)/(1 − ρ).
    fn ar1(rho: f64, n: usize, seed: u64) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut x = normal(&mut rng);
        (0..n)
            .map(|_| {
                x = rho * x + (1.0 - rho * rho).sqrt() * normal(&mut rng);
                x
            })
            .collect()
    }

    #[test]
    fn fft_autocorrelation_matches_the_direct_sum() {
        let x = ar1(0.7, 300, 3);
        let acf = autocorrelation(&x).unwrap();
        let mean = x.iter().sum::<f64>() / 300.0;
        let c = |k: usize| -> f64 {
            (0..300 - k)
                .map(|i| (x[i] - mean) * (x[i + k] - mean))
                .sum()
        };
        for k in [0, 1, 5, 40, 299] {
            assert!((acf[k] - c(k) / c(0)).abs() < 1e-10, "lag {k}");
        }
        assert!(autocorrelation(&[2.0; 50]).is_none());
    }

    #[test]
    fn integrated_time_of_ar1_series_is_the_known_one() {
        for (rho, seed) in [(0.5, 1), (0.9, 2), (0.95, 3)] {
            let want = (1.0 + rho) / (1.0 - rho);
            let walkers: Vec<Vec<f64>> =
                (0..32).map(|w| ar1(rho, 10_000, seed * 100 + w)).collect();
            let views: Vec<&[f64]> = walkers.iter().map(|w| w.as_slice()).collect();
            let tau = integrated_time(&views);
            // Sokal: sd(τ̂)/τ ≈ √(2(2M + 1)/N) with the window M ≈ 5τ: 3.5 % for τ = 19 over
            // 320 000 samples; the per-walker means bias τ̂ low by about 2 M τ / n (2 %).
            assert!(
                (tau - want).abs() < 0.1 * want,
                "rho {rho}: tau {tau} vs {want}"
            );
        }
    }

    #[test]
    fn a_walker_that_never_moves_counts_as_fully_correlated() {
        let mut walkers: Vec<Vec<f64>> = (0..4).map(|w| ar1(0.5, 2000, 10 + w)).collect();
        let views: Vec<&[f64]> = walkers.iter().map(|w| w.as_slice()).collect();
        let free = integrated_time(&views);
        walkers.push(vec![1.0; 2000]);
        let views: Vec<&[f64]> = walkers.iter().map(|w| w.as_slice()).collect();
        assert!(integrated_time(&views) > 3.0 * free);
        let stuck = [vec![1.0; 100], vec![2.0; 100]];
        let views: Vec<&[f64]> = stuck.iter().map(|w| w.as_slice()).collect();
        assert!(integrated_time(&views).is_infinite());
    }

    #[test]
    fn split_rhat_is_near_one_for_mixed_walkers_and_large_for_two_modes() {
        let walkers: Vec<Vec<f64>> = (0..32).map(|w| ar1(0.8, 2000, 50 + w)).collect();
        let views: Vec<&[f64]> = walkers.iter().map(|w| w.as_slice()).collect();
        let r = split_rhat(&views, RHAT_GROUPS);
        assert!((r - 1.0).abs() < 0.01, "mixed: {r}");
        // Half of the walkers in a mode at +5, half at −5, none crossing.
        let stuck: Vec<Vec<f64>> = walkers
            .iter()
            .enumerate()
            .map(|(w, s)| {
                let shift = if w < 16 { 5.0 } else { -5.0 };
                s.iter().map(|v| v + shift).collect()
            })
            .collect();
        let views: Vec<&[f64]> = stuck.iter().map(|w| w.as_slice()).collect();
        let r = split_rhat(&views, RHAT_GROUPS);
        assert!(r > 2.0, "two modes: {r}");
        // A drift in time (not yet stationary) shows up through the split halves.
        let drifting: Vec<Vec<f64>> = walkers
            .iter()
            .map(|s| {
                s.iter()
                    .enumerate()
                    .map(|(i, v)| v + 3.0 * i as f64 / 2000.0)
                    .collect()
            })
            .collect();
        let views: Vec<&[f64]> = drifting.iter().map(|w| w.as_slice()).collect();
        assert!(split_rhat(&views, RHAT_GROUPS) > 1.1);
    }

    #[test]
    fn a_short_run_is_not_converged_and_says_how_much_more_it_needs() {
        let names = vec!["a".to_string()];
        let walkers: Vec<Vec<f64>> = (0..16).map(|w| ar1(0.95, 200, 90 + w)).collect();
        let c = judge(
            &names,
            std::slice::from_ref(&walkers),
            &[true],
            &Targets::default(),
        );
        match c.verdict {
            Verdict::NotConverged {
                more_steps,
                more_evaluations,
            } => {
                // τ = 39: 50 τ ≈ 2000 kept steps against 200 run. A short chain underestimates
                // τ, so the estimate is lower, but still several times the run.
                assert!(more_steps > 400, "{more_steps}");
                assert_eq!(more_evaluations, more_steps * 16);
            }
            Verdict::Converged => panic!("200 steps of τ ≈ 39 cannot be converged"),
        }
        let text = c.message();
        assert!(
            text.contains("NOT converged") && text.contains("more steps"),
            "{text}"
        );
        // The same quantity unjudged: nothing is required of it.
        let c = judge(&names, &[walkers], &[false], &Targets::default());
        assert!(c.converged());
    }

    #[test]
    fn a_long_run_of_a_fast_mixing_series_is_converged() {
        let names = vec!["a".to_string(), "b".to_string()];
        let a: Vec<Vec<f64>> = (0..32).map(|w| ar1(0.5, 3000, 300 + w)).collect();
        let b: Vec<Vec<f64>> = (0..32).map(|w| ar1(0.3, 3000, 400 + w)).collect();
        let c = judge(&names, &[a, b], &[true, true], &Targets::default());
        assert!(c.converged(), "{}", c.message());
        assert!(c.burn_in <= 10, "burn-in {}", c.burn_in);
        assert!(c.quantities[0].ess > 20_000.0);
        assert!(c.message().starts_with("converged"));
    }
}
