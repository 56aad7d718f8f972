//! Priors in natural units, one per free parameter: uniform within the fit's bounds unless a
//! prior file ([`crate::prior_file`]) or the caller says otherwise.

use serde::Serialize;
use std::fmt;
use std::path::{Path, PathBuf};
use subfric_data::InputProblem;
use subfric_fit::space::Scale;
use subfric_fit::{Coord, Param, Space};

/// The prior of one parameter, in its natural units (μ_k itself, κ in 1/mm, ...).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "dist", rename_all = "kebab-case")]
pub enum Prior {
    /// Constant density on [lo, hi].
    Uniform {
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
    },
    /// Constant density of ln(value) on [ln lo, ln hi] (lo > 0).
    LogUniform {
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
    },
    /// Gaussian.
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation (> 0).
        sd: f64,
    },
    /// ln(value) Gaussian with mean μ = ln(median) and standard deviation σ.
    LogNormal {
        /// Mean of ln(value).
        mu: f64,
        /// Standard deviation of ln(value) (> 0).
        sigma: f64,
    },
}

/// ½ ln 2π.
const HALF_LN_2PI: f64 = 0.918_938_533_204_672_8;

impl Prior {
    /// Log density at `v` (natural units); −∞ outside the support.
    pub fn log_density(&self, v: f64) -> f64 {
        match *self {
            Prior::Uniform { lo, hi } if (lo..=hi).contains(&v) => -(hi - lo).ln(),
            Prior::LogUniform { lo, hi } if (lo..=hi).contains(&v) => {
                -v.ln() - (hi.ln() - lo.ln()).ln()
            }
            Prior::Normal { mean, sd } if v.is_finite() => {
                -0.5 * ((v - mean) / sd).powi(2) - sd.ln() - HALF_LN_2PI
            }
            Prior::LogNormal { mu, sigma } if v > 0.0 && v.is_finite() => {
                let l = v.ln();
                -0.5 * ((l - mu) / sigma).powi(2) - l - sigma.ln() - HALF_LN_2PI
            }
            _ => f64::NEG_INFINITY,
        }
    }

    /// The interval outside which the density is zero.
    pub fn support(&self) -> (f64, f64) {
        match *self {
            Prior::Uniform { lo, hi } | Prior::LogUniform { lo, hi } => (lo, hi),
            Prior::Normal { .. } => (f64::NEG_INFINITY, f64::INFINITY),
            Prior::LogNormal { .. } => (0.0, f64::INFINITY),
        }
    }

    /// Whether the prior lives on ln(value) (and so needs a positive parameter).
    pub fn is_logarithmic(&self) -> bool {
        matches!(self, Prior::LogUniform { .. } | Prior::LogNormal { .. })
    }

    /// Why these numbers do not make a prior, if they do not.
    pub fn problem(&self) -> Option<String> {
        match *self {
            Prior::Uniform { lo, hi } | Prior::LogUniform { lo, hi } => {
                if lo >= hi {
                    return Some(format!(
                        "lo = {lo} is not below hi = {hi} (expected lo < hi)"
                    ));
                }
                if self.is_logarithmic() && lo <= 0.0 {
                    return Some(format!(
                        "lo = {lo} is not positive (expected lo > 0 for a log-uniform prior)"
                    ));
                }
                None
            }
            Prior::Normal { sd, .. } if sd <= 0.0 => {
                Some(format!("sd = {sd} is not positive (expected sd > 0)"))
            }
            Prior::LogNormal { sigma, .. } if sigma <= 0.0 => Some(format!(
                "sigma = {sigma} is not positive (expected sigma > 0)"
            )),
            _ => None,
        }
    }
}

/// `v` to six significant digits, as short as that allows (a box edge computed as
/// exp(ln 3) reads 3, not 3.0000000000000004).
fn compact(v: f64) -> String {
    if !v.is_finite() || v == 0.0 {
        return v.to_string();
    }
    let rounded: f64 = format!("{v:.5e}").parse().unwrap_or(v);
    if rounded.abs() >= 1e-4 && rounded.abs() < 1e6 {
        rounded.to_string()
    } else {
        format!("{rounded:e}")
    }
}

impl fmt::Display for Prior {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let c = compact;
        match *self {
            Prior::Uniform { lo, hi } => write!(f, "uniform({}, {})", c(lo), c(hi)),
            Prior::LogUniform { lo, hi } => write!(f, "log-uniform({}, {})", c(lo), c(hi)),
            Prior::Normal { mean, sd } => write!(f, "normal(mean {}, sd {})", c(mean), c(sd)),
            Prior::LogNormal { mu, sigma } => {
                write!(f, "log-normal(median {}, sigma {})", c(mu.exp()), c(sigma))
            }
        }
    }
}

/// Where a prior was given.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Origin {
    /// The prior file.
    pub file: PathBuf,
    /// 1-based line of the parameter's entry.
    pub line: usize,
}

/// A prior given for one parameter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PriorEntry {
    /// The parameter.
    pub param: Param,
    /// Its prior.
    pub prior: Prior,
    /// Where it was given (None when set by a program).
    pub origin: Option<Origin>,
}

/// Why a prior cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum PriorError {
    /// The file could not be read.
    #[error("cannot read the prior file {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The reason.
        #[source]
        source: std::io::Error,
    },
    /// Problems in the priors, each located (file, line, field) when it came from a file.
    #[error("{}", list(.0))]
    Invalid(Vec<InputProblem>),
}

fn list(problems: &[InputProblem]) -> String {
    problems
        .iter()
        .map(|p| p.to_string())
        .collect::<Vec<_>>()
        .join("\n")
}

/// The priors of a posterior: those given, by parameter; every free parameter without one is
/// uniform within the fit's bounds on the fit's scale (see [`Priors::resolve`]).
/// `Priors::default()` gives none: every parameter gets that default.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Priors {
    entries: Vec<PriorEntry>,
}

impl Priors {
    /// Reads a prior file (JSON or TOML, by its extension; format in docs/posterior.md).
    pub fn load(path: &Path) -> Result<Priors, PriorError> {
        crate::prior_file::load(path)
    }

    /// The same priors with `prior` for `param` (replacing a prior given before), refused with
    /// the reason when the numbers do not make a prior or a logarithmic prior is put on a
    /// parameter that can be zero or negative.
    pub fn with(mut self, param: Param, prior: Prior) -> Result<Priors, PriorError> {
        let field = param.key();
        let invalid = |m: String| {
            PriorError::Invalid(vec![InputProblem::new("(priors)", None, Some(field), m)])
        };
        if let Some(m) = numbers_problem(&prior).or_else(|| sign_problem(param, &prior)) {
            return Err(invalid(m));
        }
        self.entries.retain(|e| e.param != param);
        self.entries.push(PriorEntry {
            param,
            prior,
            origin: None,
        });
        Ok(self)
    }

    pub(crate) fn from_entries(entries: Vec<PriorEntry>) -> Priors {
        Priors { entries }
    }

    /// The priors given.
    pub fn entries(&self) -> &[PriorEntry] {
        &self.entries
    }

    /// The prior given for `param`, if any.
    pub fn get(&self, param: Param) -> Option<&PriorEntry> {
        self.entries.iter().find(|e| e.param == param)
    }

    /// The prior of every free parameter of `space`, in the order of `space.free`: the given
    /// one, or uniform within the space's bounds on the scale the fit charts the parameter in —
    /// log-uniform for those charted as logarithms (μ_s, κ, ξ, ũ, ...: bounds spanning decades,
    /// where a prior uniform in the value itself would put 99.9 % of κ's mass above 10 /mm and
    /// so decide where along a valley the posterior lies), uniform for the others, and μ_k
    /// uniform between 0 and μ_s (the share of μ_s the space allows). Refused, with the place
    /// in the file, when a prior is given for a parameter that is not free or when its support
    /// misses the parameter's bounds.
    pub fn resolve(&self, space: &Space) -> Result<Vec<ResolvedPrior>, PriorError> {
        let mut problems = Vec::new();
        for e in &self.entries {
            let at = |m: String| problem_at(e, m);
            if !space.free.contains(&e.param) {
                problems.push(at(format!(
                    "{} is not free in this fit, so a prior on it would have no effect (expected priors on the free parameters: {})",
                    e.param.key(),
                    keys(&space.free)
                )));
                continue;
            }
            let (lo, hi) = natural_box(space, e.param);
            let (a, b) = e.prior.support();
            if b < lo || a > hi {
                problems.push(at(format!(
                    "the prior {} lies outside the bounds of {} in this fit, {lo:.6e}..{hi:.6e} (expected a prior overlapping them)",
                    e.prior,
                    e.param.key()
                )));
            }
        }
        if !problems.is_empty() {
            return Err(PriorError::Invalid(problems));
        }
        Ok(space
            .free
            .iter()
            .map(|&p| match self.get(p) {
                Some(e) => ResolvedPrior::Given(e.prior),
                None if p == Param::MuK => {
                    let (lo, hi) = mu_k_share(space);
                    ResolvedPrior::ShareOfMuS { lo, hi }
                }
                None => {
                    let (lo, hi) = natural_box(space, p);
                    ResolvedPrior::Default(match p.scale() {
                        Scale::Log => Prior::LogUniform { lo, hi },
                        _ => Prior::Uniform { lo, hi },
                    })
                }
            })
            .collect())
    }
}

/// A free parameter's prior as the posterior uses it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ResolvedPrior {
    /// Given by the user.
    Given(Prior),
    /// Not given: uniform within the fit's bounds on the fit's scale (log-uniform for
    /// parameters charted as logarithms).
    Default(Prior),
    /// Not given, and the least-squares optimum lay outside the default bounds (the chart of
    /// combinations — κ + ξ/v and the recovery share ψ — reaches beyond ξ's and κ's own
    /// default bounds, so an undetermined ξ can end below 10⁻⁷ /s): the default widened on its
    /// own scale just enough to hold the optimum, so that the walkers can start there.
    Widened(Prior),
    /// Not given, μ_k: uniform on [lo·μ_s, hi·μ_s] (density 1/((hi − lo) μ_s)).
    ShareOfMuS {
        /// Lowest share.
        lo: f64,
        /// Highest share.
        hi: f64,
    },
}

impl ResolvedPrior {
    /// Log density of value `v` of the parameter, in a model whose μ_s is `mu_s`.
    pub fn log_density(&self, v: f64, mu_s: f64) -> f64 {
        match *self {
            ResolvedPrior::Given(p) | ResolvedPrior::Default(p) | ResolvedPrior::Widened(p) => {
                p.log_density(v)
            }
            ResolvedPrior::ShareOfMuS { lo, hi } => {
                let share = v / mu_s;
                if mu_s > 0.0 && (lo..=hi).contains(&share) {
                    -((hi - lo) * mu_s).ln()
                } else {
                    f64::NEG_INFINITY
                }
            }
        }
    }

    /// A default prior whose support misses `optimum` (the parameter's value at the
    /// least-squares optimum) widened to hold it ([`ResolvedPrior::Widened`]); every other
    /// prior as it is (a given prior that excludes the optimum is the user's to change).
    pub fn holding(self, optimum: f64) -> ResolvedPrior {
        let ResolvedPrior::Default(p) = self else {
            return self;
        };
        let widened = match p {
            Prior::LogUniform { lo, hi } if optimum > 0.0 && !(lo..=hi).contains(&optimum) => {
                Prior::LogUniform {
                    lo: lo.min(optimum),
                    hi: hi.max(optimum),
                }
            }
            Prior::Uniform { lo, hi } if optimum.is_finite() && !(lo..=hi).contains(&optimum) => {
                Prior::Uniform {
                    lo: lo.min(optimum),
                    hi: hi.max(optimum),
                }
            }
            _ => return self,
        };
        ResolvedPrior::Widened(widened)
    }

    /// For a report: the prior, and whether it was given or is the default (uniform within
    /// the bounds on the fit's scale).
    pub fn describe(&self) -> String {
        match self {
            ResolvedPrior::Given(p) => format!("{p} (given)"),
            ResolvedPrior::Default(p) => format!("{p} (default)"),
            ResolvedPrior::Widened(p) => format!("{p} (default, widened to hold the optimum)"),
            ResolvedPrior::ShareOfMuS { lo, hi } => format!(
                "uniform({}·mu_s, {}·mu_s) (default)",
                compact(*lo),
                compact(*hi)
            ),
        }
    }
}

fn problem_at(e: &PriorEntry, message: String) -> InputProblem {
    match &e.origin {
        Some(o) => InputProblem::new(&o.file, Some(o.line), Some(e.param.key()), message),
        None => InputProblem::new("(priors)", None, Some(e.param.key()), message),
    }
}

fn keys(params: &[Param]) -> String {
    params
        .iter()
        .map(|p| p.key())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Why the numbers of a prior are unusable (not finite, lo ≥ hi, sd ≤ 0, ...).
pub(crate) fn numbers_problem(prior: &Prior) -> Option<String> {
    let numbers: Vec<(&str, f64)> = match *prior {
        Prior::Uniform { lo, hi } | Prior::LogUniform { lo, hi } => vec![("lo", lo), ("hi", hi)],
        Prior::Normal { mean, sd } => vec![("mean", mean), ("sd", sd)],
        Prior::LogNormal { mu, sigma } => vec![("mu", mu), ("sigma", sigma)],
    };
    numbers
        .iter()
        .find(|(_, v)| !v.is_finite())
        .map(|(n, v)| format!("{n} = {v} is not finite (expected a finite number)"))
        .or_else(|| prior.problem())
}

/// Why a logarithmic prior cannot be put on `param`: it can be zero or negative.
pub(crate) fn sign_problem(param: Param, prior: &Prior) -> Option<String> {
    let (lo, hi) = param.default_bounds();
    let can_be_non_positive = param.scale() == Scale::Linear && lo <= 0.0;
    (prior.is_logarithmic() && can_be_non_positive).then(|| {
        format!(
            "a {} prior needs a positive parameter, but {} can be zero or negative (bounds {lo}..{hi}) (expected a uniform or normal prior)",
            if matches!(prior, Prior::LogUniform { .. }) { "log-uniform" } else { "log-normal" },
            param.key()
        )
    })
}

/// The natural range of `p` in `space`: its coordinate's box mapped back (for a parameter
/// charted in combinations, its default bounds; for μ_k, the share of the largest μ_s).
pub fn natural_box(space: &Space, p: Param) -> (f64, f64) {
    if p == Param::MuK {
        let (lo, hi) = mu_k_share(space);
        let mu_s = match space
            .coords
            .iter()
            .position(|c| *c == Coord::Natural(Param::MuS))
        {
            Some(i) => space.hi[i].exp(),
            None => space.base.params.mu_s,
        };
        return (lo * mu_s, hi * mu_s);
    }
    match space.coords.iter().position(|c| *c == Coord::Natural(p)) {
        Some(i) => match p.scale() {
            Scale::Log => (space.lo[i].exp(), space.hi[i].exp()),
            _ => (space.lo[i], space.hi[i]),
        },
        None => p.default_bounds(),
    }
}

/// The range of μ_k/μ_s the space allows: its logit box when μ_k is charted on its own, else
/// all of 0..1 (the combined chart keeps μ_k between 0 and μ_s).
fn mu_k_share(space: &Space) -> (f64, f64) {
    let sigmoid = |x: f64| 1.0 / (1.0 + (-x).exp());
    match space
        .coords
        .iter()
        .position(|c| *c == Coord::Natural(Param::MuK))
    {
        Some(i) => (sigmoid(space.lo[i]), sigmoid(space.hi[i])),
        None => (0.0, 1.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfric_model::{Model, Params};

    #[test]
    fn a_default_prior_is_widened_to_hold_the_optimum_and_no_other_is() {
        let d = ResolvedPrior::Default(Prior::LogUniform { lo: 1e-7, hi: 10.0 });
        assert_eq!(d.holding(1e-3), d, "an optimum inside leaves it as it is");
        let w = d.holding(4.7e-8);
        assert_eq!(
            w,
            ResolvedPrior::Widened(Prior::LogUniform {
                lo: 4.7e-8,
                hi: 10.0
            })
        );
        assert!(w.log_density(4.7e-8, 1.0).is_finite());
        assert_eq!(w.log_density(4.0e-8, 1.0), f64::NEG_INFINITY);
        assert!(w
            .describe()
            .ends_with("(default, widened to hold the optimum)"));
        let u = ResolvedPrior::Default(Prior::Uniform { lo: -0.2, hi: 0.2 });
        assert_eq!(
            u.holding(0.3),
            ResolvedPrior::Widened(Prior::Uniform { lo: -0.2, hi: 0.3 })
        );
        let given = ResolvedPrior::Given(Prior::LogUniform { lo: 1e-7, hi: 10.0 });
        assert_eq!(given.holding(1e-9), given, "a given prior is the user's");
        let share = ResolvedPrior::ShareOfMuS { lo: 0.0, hi: 1.0 };
        assert_eq!(share.holding(5.0), share);
    }

    #[test]
    fn priors_print_their_numbers_to_six_digits_without_rounding_noise() {
        let p = Prior::LogUniform {
            lo: 0.10000000000000002,
            hi: 3.0f64.ln().exp(),
        };
        assert_eq!(p.to_string(), "log-uniform(0.1, 3)");
        let n = Prior::LogNormal {
            mu: 0.002f64.ln(),
            sigma: 1.0,
        };
        assert_eq!(n.to_string(), "log-normal(median 0.002, sigma 1)");
        assert_eq!(compact(1e-7), "1e-7");
        assert_eq!(compact(100000.00000000001), "100000");
        assert_eq!(compact(1.234567e8), "1.23457e8");
        assert_eq!(compact(-0.5), "-0.5");
    }

    fn integral(p: &Prior, a: f64, b: f64) -> f64 {
        let n = 200_000;
        let h = (b - a) / n as f64;
        (0..n)
            .map(|i| p.log_density(a + (i as f64 + 0.5) * h).exp() * h)
            .sum()
    }

    #[test]
    fn densities_are_normalised() {
        for (p, a, b) in [
            (Prior::Uniform { lo: 1.0, hi: 3.0 }, 0.0, 4.0),
            (Prior::LogUniform { lo: 0.01, hi: 10.0 }, 0.0, 11.0),
            (Prior::Normal { mean: 2.0, sd: 0.5 }, -2.0, 6.0),
            (
                Prior::LogNormal {
                    mu: 0.0,
                    sigma: 0.5,
                },
                1e-9,
                30.0,
            ),
        ] {
            let total = integral(&p, a, b);
            assert!((total - 1.0).abs() < 2e-3, "{p}: {total}");
        }
        assert_eq!(
            Prior::LogNormal {
                mu: 0.0,
                sigma: 1.0
            }
            .log_density(-1.0),
            f64::NEG_INFINITY
        );
    }

    #[test]
    fn programmatic_priors_are_checked_too() {
        let bad = Priors::default().with(
            Param::Kappa,
            Prior::Normal {
                mean: 1.0,
                sd: -2.0,
            },
        );
        assert!(bad
            .unwrap_err()
            .to_string()
            .contains("sd = -2 is not positive"));
        let bad = Priors::default().with(
            Param::from_key("rate.a").unwrap(),
            Prior::LogUniform { lo: 0.1, hi: 1.0 },
        );
        assert!(bad
            .unwrap_err()
            .to_string()
            .contains("can be zero or negative"));
        let ok = Priors::default()
            .with(Param::Kappa, Prior::Normal { mean: 1.0, sd: 2.0 })
            .unwrap()
            .with(Param::Kappa, Prior::Normal { mean: 3.0, sd: 2.0 })
            .unwrap();
        assert_eq!(ok.entries().len(), 1, "the second prior replaces the first");
    }

    #[test]
    fn resolution_gives_defaults_and_refuses_priors_on_fixed_or_unreachable_parameters() {
        let m = Model::base(Params::sample()).unwrap();
        let space = Space::with_rate(m, &Param::BASE, &[], 0.01);
        let r = Priors::default().resolve(&space).unwrap();
        assert_eq!(r.len(), 5);
        // κ (combined chart, charted as a logarithm): log-uniform on its default bounds.
        let k = space.free.iter().position(|p| *p == Param::Kappa).unwrap();
        assert_eq!(
            r[k],
            ResolvedPrior::Default(Prior::LogUniform { lo: 1e-3, hi: 1e4 })
        );
        // μ_s, charted as a logarithm on its own: log-uniform on its box.
        let s = space.free.iter().position(|p| *p == Param::MuS).unwrap();
        match r[s] {
            ResolvedPrior::Default(Prior::LogUniform { lo, hi }) => {
                assert!(
                    (lo - 0.02).abs() < 1e-12 && (hi - 3.0).abs() < 1e-12,
                    "{lo}..{hi}"
                );
            }
            other => panic!("{other:?}"),
        }
        // A parameter charted linearly: uniform on its box.
        let linear = Space::new(m, &[Param::from_key("rate.a").unwrap()], &[]);
        assert_eq!(
            Priors::default().resolve(&linear).unwrap()[0],
            ResolvedPrior::Default(Prior::Uniform { lo: -0.2, hi: 0.2 })
        );
        // μ_k: uniform between 0 and μ_s, whatever μ_s is.
        let mk = space.free.iter().position(|p| *p == Param::MuK).unwrap();
        assert!((r[mk].log_density(0.3, 0.6) - (-(0.6f64).ln())).abs() < 1e-12);
        assert_eq!(r[mk].log_density(0.7, 0.6), f64::NEG_INFINITY);
        let fixed = Priors::default()
            .with(Param::AlphaT, Prior::Uniform { lo: 1.0, hi: 2.0 })
            .unwrap();
        let e = fixed.resolve(&space).unwrap_err().to_string();
        assert!(
            e.contains("alpha_t is not free") && e.contains("mu_s, mu_k"),
            "{e}"
        );
        let outside = Priors::default()
            .with(Param::MuS, Prior::Uniform { lo: 5.0, hi: 6.0 })
            .unwrap();
        let e = outside.resolve(&space).unwrap_err().to_string();
        assert!(e.contains("lies outside the bounds of mu_s"), "{e}");
    }
}
