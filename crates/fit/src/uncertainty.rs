//! Uncertainty and identifiability: standard errors and correlations from the Jacobian at the
//! optimum, flat directions of JᵀJ, and profile intervals that do not assume a quadratic cost.

use crate::interval::Interval;
use crate::lm::{jacobian, levenberg_marquardt, LmOptions};
use crate::problem::Problem;
use crate::residuals::Residuals;
use crate::space::Space;
use argmin::core::{
    Error as ArgminError, Executor, IterState, Solver, State, TerminationReason, KV,
};
use nalgebra::{DMatrix, DVector, SymmetricEigen};
use rayon::prelude::*;
use serde::Serialize;
use subfric_reading::stats::correlation_time;

/// χ²₁ quantile at 95 %: the rise of the (scaled) SSR that bounds a 95 % profile interval.
pub const CHI2_1_95: f64 = 3.841;

/// Relative difference step of the chart's Jacobian T (exact arithmetic, no solver noise, so
/// smaller than the residuals' [`crate::lm::JACOBIAN_STEP`]).
const CHART_STEP: f64 = 1e-7;

/// Components of a flat direction smaller than this are left out of the report.
const FLAT_COMPONENT: f64 = 0.1;

/// Linearised statistics at the optimum.
#[derive(Clone, Debug)]
pub struct Linearised {
    /// Covariance of the natural parameters (None where JᵀJ is singular).
    pub covariance: Option<DMatrix<f64>>,
    /// Standard errors (natural units); infinite when not estimable.
    pub std_errors: Vec<f64>,
    /// Standard errors in the transformed coordinates.
    pub std_errors_x: Vec<f64>,
    /// Correlation matrix of the natural parameters.
    pub correlation: Vec<Vec<f64>>,
    /// Directions of JᵀJ along which the cost hardly changes.
    pub flat_directions: Vec<FlatDirection>,
}

impl Linearised {
    /// Nothing estimated (a fit that did not ask for statistics): every standard error is
    /// infinite, no correlation or flat direction is known.
    pub fn unknown(m: usize) -> Linearised {
        Linearised {
            covariance: None,
            std_errors: vec![f64::INFINITY; m],
            std_errors_x: vec![f64::INFINITY; m],
            correlation: Vec::new(),
            flat_directions: Vec::new(),
        }
    }
}

/// A direction in parameter space the data hardly constrain.
#[derive(Clone, Debug, Serialize)]
pub struct FlatDirection {
    /// Ratio of its curvature to the stiffest direction's.
    pub relative_curvature: f64,
    /// Components along the optimiser's coordinates, largest first.
    pub components: Vec<(String, f64)>,
}

/// The variance scale s² = max(1, SSR/(n − m)): residuals are in noise units, and a misfit
/// above the noise widens every interval accordingly.
pub fn variance_scale(ssr: f64, rows: usize, m: usize) -> f64 {
    (ssr / (rows.saturating_sub(m)).max(1) as f64).max(1.0)
}

/// The variance inflation for correlated residuals of a joint fit: each test's
/// [`correlation_time`] (`subfric_reading::stats`) of its counted residuals (thinned tests: of their bins), averaged with
/// the test's share of the sum of squares as weight (a test whose residuals carry more of the
/// misfit matters more); at least 1. Multiplying s² by it widens every interval as if the fit
/// had n/τ independent rows instead of n.
pub fn noise_correlation(tests: &[subfric_reading::FitTest], residuals: &[f64]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    let mut start = 0;
    for t in tests {
        let rows = t.counted_rows();
        let end = start + t.len();
        if end > residuals.len() {
            break;
        }
        let r = &residuals[start + rows.start..start + rows.end];
        let ssr: f64 = r.iter().filter(|v| v.is_finite()).map(|v| v * v).sum();
        if ssr > 0.0 {
            num += ssr * correlation_time(r);
            den += ssr;
        }
        start = end;
    }
    if den > 0.0 {
        (num / den).max(1.0)
    } else {
        1.0
    }
}

/// Relative curvature (eigenvalue of JᵀJ over the largest) below which a direction is reported
/// as flat.
pub const FLAT_CURVATURE: f64 = 1e-6;

/// Relative curvature below which a direction counts as having none at all: it is left out of
/// the pseudo-inverse, and every quantity that moves along it gets an infinite standard error.
pub const NO_CURVATURE: f64 = 1e-10;

/// Share of a quantity's squared gradient lying along curvature-free directions above which its
/// variance is infinite rather than whatever the truncated pseudo-inverse gives.
const FLAT_LOAD: f64 = 1e-3;

/// Linearised statistics in the optimiser's own coordinates (no chart, no names): what the
/// Jacobian alone says, for any [`Residuals`] problem.
#[derive(Clone, Debug)]
pub struct CoordinateStats {
    /// Covariance of the coordinates s²(JᵀJ)⁺ (pseudo-inverse over the curved directions).
    pub covariance: DMatrix<f64>,
    /// Standard errors of the coordinates; infinite along curvature-free directions.
    pub std_errors: Vec<f64>,
    /// Eigen-directions of JᵀJ with relative curvature below [`FLAT_CURVATURE`]:
    /// (relative curvature, unit vector).
    pub flat: Vec<(f64, DVector<f64>)>,
    /// Directions without curvature (below [`NO_CURVATURE`]).
    pub curvature_free: Vec<DVector<f64>>,
}

impl CoordinateStats {
    /// Whether a quantity with gradient `row` (in the coordinates) moves along a direction
    /// without curvature, i.e. has an infinite standard error.
    pub fn loads_on_flat(&self, row: &[f64]) -> bool {
        let norm2: f64 = row.iter().map(|v| v * v).sum();
        let load: f64 = self
            .curvature_free
            .iter()
            .map(|v| {
                row.iter()
                    .zip(v.iter())
                    .map(|(a, b)| a * b)
                    .sum::<f64>()
                    .powi(2)
            })
            .sum();
        load > FLAT_LOAD * norm2.max(f64::MIN_POSITIVE)
    }
}

/// Covariance, standard errors and flat directions of the coordinates at `x` (an optimum with
/// sum of squares `ssr`).
pub fn coordinate_stats<R: Residuals + ?Sized>(p: &R, x: &[f64], ssr: f64) -> CoordinateStats {
    let s2 = variance_scale(ssr, p.observations(), x.len());
    coordinate_stats_scaled(p, x, s2)
}

/// As [`coordinate_stats`], with the variance scale s² given (e.g. widened for correlated
/// residuals, [`noise_correlation`]).
pub fn coordinate_stats_scaled<R: Residuals + ?Sized>(
    p: &R,
    x: &[f64],
    s2: f64,
) -> CoordinateStats {
    let mut r = Vec::new();
    p.residuals_at(x, &mut r);
    let j = jacobian(p, x, &r, None);
    stats_of_information(&(j.transpose() * &j), s2)
}

/// Covariance s²(JᵀJ)⁺, standard errors and flat directions from the information matrix JᵀJ
/// of the coordinates (noise-normalised residuals).
pub fn stats_of_information(jtj: &DMatrix<f64>, s2: f64) -> CoordinateStats {
    let m = jtj.nrows();
    let eig = SymmetricEigen::new(jtj.clone());
    let max_ev = eig.eigenvalues.iter().cloned().fold(0.0, f64::max);
    let mut flat = Vec::new();
    let mut curvature_free = Vec::new();
    let mut covariance = DMatrix::zeros(m, m);
    for (i, &ev) in eig.eigenvalues.iter().enumerate() {
        let v = eig.eigenvectors.column(i).into_owned();
        let rel = ev / max_ev.max(f64::MIN_POSITIVE);
        if rel < FLAT_CURVATURE {
            flat.push((rel, v.clone()));
        }
        if ev > NO_CURVATURE * max_ev && ev.is_finite() {
            covariance += &v * v.transpose() * (s2 / ev);
        } else {
            curvature_free.push(v);
        }
    }
    let mut stats = CoordinateStats {
        covariance,
        std_errors: Vec::new(),
        flat,
        curvature_free,
    };
    stats.std_errors = (0..m)
        .map(|k| {
            let mut e = vec![0.0; m];
            e[k] = 1.0;
            if stats.loads_on_flat(&e) {
                f64::INFINITY
            } else {
                stats.covariance[(k, k)].max(0.0).sqrt()
            }
        })
        .collect();
    stats
}

/// Standard errors, correlations and flat directions of the natural parameters at `x`: the
/// coordinates' statistics carried through the chart by its Jacobian T = ∂natural/∂x.
pub fn linearise(p: &Problem, x: &[f64], ssr: f64) -> Linearised {
    linearise_scaled(p, x, variance_scale(ssr, p.observations(), x.len()))
}

/// As [`linearise`], with the variance scale s² given.
pub fn linearise_scaled(p: &Problem, x: &[f64], s2: f64) -> Linearised {
    let stats = coordinate_stats_scaled(p, x, s2);
    linearise_stats(&p.space, x, &stats)
}

/// The chart's Jacobian T = ∂natural/∂x at `x` (by differences: μ_k depends on μ_s and its
/// ratio, ξ and κ on the combined coordinates).
pub fn chart_jacobian(space: &Space, x: &[f64]) -> DMatrix<f64> {
    let m = x.len();
    let nat0 = space.natural(x);
    let mut t = DMatrix::zeros(m, m);
    for k in 0..m {
        let mut xp = x.to_vec();
        let h = CHART_STEP * (1.0 + x[k].abs());
        xp[k] += h;
        let nat = space.natural(&xp);
        for i in 0..m {
            t[(i, k)] = (nat[i] - nat0[i]) / h;
        }
    }
    t
}

/// Standard errors, correlations and flat directions of the natural parameters from the
/// coordinates' statistics at `x`.
pub fn linearise_stats(space: &Space, x: &[f64], stats: &CoordinateStats) -> Linearised {
    let m = x.len();
    let t = chart_jacobian(space, x);
    let names: Vec<String> = space.coords.iter().map(|c| c.name()).collect();
    let flat = stats
        .flat
        .iter()
        .map(|(rel, v)| {
            let mut comps: Vec<(String, f64)> =
                names.iter().cloned().zip(v.iter().cloned()).collect();
            comps.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
            comps.retain(|c| c.1.abs() > FLAT_COMPONENT);
            FlatDirection {
                relative_curvature: *rel,
                components: comps,
            }
        })
        .collect();
    let cov = &t * &stats.covariance * t.transpose();
    let se: Vec<f64> = (0..m)
        .map(|k| {
            let row: Vec<f64> = (0..m).map(|j| t[(k, j)]).collect();
            if stats.loads_on_flat(&row) {
                f64::INFINITY
            } else {
                cov[(k, k)].max(0.0).sqrt()
            }
        })
        .collect();
    let corr = (0..m)
        .map(|i| {
            (0..m)
                .map(|k| {
                    let d = (cov[(i, i)] * cov[(k, k)]).sqrt();
                    if d > 0.0 && se[i].is_finite() && se[k].is_finite() {
                        (cov[(i, k)] / d).clamp(-1.0, 1.0)
                    } else {
                        f64::NAN
                    }
                })
                .collect()
        })
        .collect();
    Linearised {
        covariance: Some(cov),
        std_errors: se,
        std_errors_x: stats.std_errors.clone(),
        correlation: corr,
        flat_directions: flat,
    }
}

/// One side of a coordinate's profile.
#[derive(Clone, Debug)]
pub struct ProfileEnd {
    /// The point where the profile crossed the threshold, or the wall it reached.
    pub x: Vec<f64>,
    /// True when the SSR never rose enough before the box wall: no bound on this side.
    pub open: bool,
}

/// A point visited by a profile: coordinates, ΔSSR/s², and whether it lies on a box wall that
/// the profile reached without crossing the threshold.
#[derive(Clone, Debug)]
pub struct TracePoint {
    /// Optimiser coordinates.
    pub x: Vec<f64>,
    /// (SSR − SSR_min)/s².
    pub delta: f64,
    /// On an open wall.
    pub open_wall: bool,
}

/// Profile of one optimiser coordinate.
#[derive(Clone, Debug)]
pub struct Profile {
    /// Lower end.
    pub lower: ProfileEnd,
    /// Upper end.
    pub upper: ProfileEnd,
    /// Points visited, with the threshold crossings interpolated.
    pub trace: Vec<TracePoint>,
    /// A point with a lower SSR than the optimum, if profiling found one.
    pub better: Option<(Vec<f64>, f64)>,
}

/// Most steps a profile takes on one side (each doubles the offset, so 16 reach 2¹⁵ times the
/// first step: every box wall, in practice).
const PROFILE_STEPS: usize = 16;

/// The first offset of a profile, in standard errors of the coordinate: a little beyond the
/// quadratic 95 % point (1.96 s.e. would be reached on the second step), so a nearly quadratic
/// profile brackets the threshold in one or two re-fits.
const FIRST_STEP_SE: f64 = 1.5;

/// First offset when the standard error is infinite (transformed units).
const FIRST_STEP_FLAT: f64 = 0.05;

/// Range of the first offset (transformed units).
const FIRST_STEP_RANGE: (f64, f64) = (1e-3, 0.5);

/// Iteration limit of each profile re-fit: it starts next to its answer (the previous point).
const PROFILE_LM_ITERATIONS: usize = 30;

/// A profile point counts as a better optimum when its SSR is lower by this share (of
/// max(1, SSR)), not by round-off.
const BETTER_BY: f64 = 1e-6;

/// Profiles every optimiser coordinate (in parallel): each is stepped away from the optimum
/// with the others re-minimised, until the SSR has risen by χ²₁(0.95)·s² or the box wall is
/// reached (then that side is open: the data set no bound there).
pub fn profiles<R: Residuals + ?Sized>(p: &R, x: &[f64], ssr: f64, se_x: &[f64]) -> Vec<Profile> {
    let s2 = variance_scale(ssr, p.observations(), x.len());
    profiles_scaled(p, x, ssr, s2, se_x)
}

/// As [`profiles`], with the variance scale s² given: each profile ends where the SSR has risen
/// by χ²₁(0.95)·s².
pub fn profiles_scaled<R: Residuals + ?Sized>(
    p: &R,
    x: &[f64],
    ssr: f64,
    s2: f64,
    se_x: &[f64],
) -> Vec<Profile> {
    (0..x.len())
        .into_par_iter()
        .map(|k| profile_one(p, x, ssr, s2, se_x[k], k))
        .collect()
}

/// The profile of coordinate `k` alone (standard error `se` of the coordinate, may be
/// infinite).
pub fn profile_one<R: Residuals + ?Sized>(
    p: &R,
    x: &[f64],
    ssr: f64,
    s2: f64,
    se: f64,
    k: usize,
) -> Profile {
    let mut trace = vec![TracePoint {
        x: x.to_vec(),
        delta: 0.0,
        open_wall: false,
    }];
    let mut better: Option<(Vec<f64>, f64)> = None;
    let walk = ProfileWalk { x, k, ssr, s2, se };
    let lower = walk.side(p, -1.0, &mut trace, &mut better);
    let upper = walk.side(p, 1.0, &mut trace, &mut better);
    Profile {
        lower,
        upper,
        trace,
        better,
    }
}

/// One coordinate's profile: where it starts and how far the SSR may rise.
struct ProfileWalk<'a> {
    /// The optimum.
    x: &'a [f64],
    /// The profiled coordinate.
    k: usize,
    /// SSR at the optimum.
    ssr: f64,
    /// Variance scale.
    s2: f64,
    /// Standard error of the coordinate (may be infinite).
    se: f64,
}

impl ProfileWalk<'_> {
    /// Walks from the optimum towards the wall on `side` (−1 or +1), doubling the offset, until
    /// the SSR rises past the threshold (then the crossing is interpolated) or the wall is
    /// reached; records the points in `trace` and any better optimum in `better`. The steps
    /// are [`ProfileSide`]'s, run by argmin's `Executor`; a side that takes its
    /// [`PROFILE_STEPS`] without either is open.
    fn side<R: Residuals + ?Sized>(
        &self,
        p: &R,
        side: f64,
        trace: &mut Vec<TracePoint>,
        better: &mut Option<(Vec<f64>, f64)>,
    ) -> ProfileEnd {
        let (lo, hi) = p.bounds();
        let k = self.k;
        let wall = if side < 0.0 { lo[k] } else { hi[k] };
        let first = if self.se.is_finite() {
            FIRST_STEP_SE * self.se
        } else {
            FIRST_STEP_FLAT
        };
        let solver = ProfileSide {
            x: self.x.to_vec(),
            k,
            ssr: self.ssr,
            s2: self.s2,
            side,
            wall,
            delta: first.max(FIRST_STEP_RANGE.0).min(FIRST_STEP_RANGE.1),
            prev_x: self.x.to_vec(),
            prev_d: 0.0,
            trace: Vec::new(),
            better: better.take(),
            end: None,
        };
        let open = ProfileEnd {
            x: with(self.x, k, wall),
            open: true,
        };
        let run = Executor::new(p, solver)
            .configure(|s| s.param(self.x.to_vec()).max_iters(PROFILE_STEPS as u64))
            .timer(false)
            .run();
        match run {
            Ok(res) => {
                let walked = res.solver;
                trace.extend(walked.trace);
                *better = walked.better;
                walked.end.unwrap_or(open)
            }
            // Its steps fail only without a problem, which the executor always gives: should
            // one fail all the same, the side is open (no bound claimed), never a panic.
            Err(_) => open,
        }
    }
}

/// The state argmin keeps for [`ProfileSide`]: the last profile point and its SSR.
pub type ProfileState = IterState<Vec<f64>, (), (), (), (), f64>;

/// One side of a coordinate's profile as an argmin [`Solver`]: each `next_iter` sets the
/// coordinate one offset further (doubling it) and re-minimises the others with
/// Levenberg–Marquardt from the previous point; it stops where the SSR has risen by
/// χ²₁(0.95)·s² (the crossing interpolated) or at the wall (open).
#[derive(Clone, Debug)]
pub struct ProfileSide {
    x: Vec<f64>,
    k: usize,
    ssr: f64,
    s2: f64,
    side: f64,
    wall: f64,
    delta: f64,
    prev_x: Vec<f64>,
    prev_d: f64,
    /// Points visited.
    pub trace: Vec<TracePoint>,
    /// A point with a lower SSR than the optimum, if one was found.
    pub better: Option<(Vec<f64>, f64)>,
    /// Where the side ended, when it crossed the threshold or reached the wall.
    pub end: Option<ProfileEnd>,
}

impl<R: Residuals + ?Sized> Solver<&R, ProfileState> for ProfileSide {
    const NAME: &'static str = "profile walk";

    fn next_iter(
        &mut self,
        problem: &mut argmin::core::Problem<&R>,
        state: ProfileState,
    ) -> Result<(ProfileState, Option<KV>), ArgminError> {
        let p = *crate::residuals::given(problem)?;
        let (x, k, ssr, s2) = (&self.x, self.k, self.ssr, self.s2);
        let threshold = CHI2_1_95 * s2;
        let fixed: Vec<bool> = (0..x.len()).map(|i| i == k).collect();
        let opts = LmOptions {
            max_iterations: PROFILE_LM_ITERATIONS,
            ..LmOptions::default()
        };
        let room = (self.wall - x[k]).abs();
        let xk = if room <= self.delta {
            self.wall
        } else {
            x[k] + self.side * self.delta
        };
        let res = levenberg_marquardt(p, &with(&self.prev_x, k, xk), Some(&fixed), &opts);
        let d = res.ssr - ssr;
        if d < -BETTER_BY * ssr.max(1.0) && self.better.as_ref().is_none_or(|b| res.ssr < b.1) {
            self.better = Some((res.x.clone(), res.ssr));
        }
        let state = state.param(res.x.clone()).cost(res.ssr);
        if d >= threshold {
            // Interpolate in √ΔSSR, linear in the offset for a quadratic profile.
            let (a, b) = (self.prev_d.max(0.0).sqrt(), d.sqrt());
            let w = ((threshold.sqrt() - a) / (b - a)).clamp(0.0, 1.0);
            let xi: Vec<f64> = self
                .prev_x
                .iter()
                .zip(&res.x)
                .map(|(u, v)| u + w * (v - u))
                .collect();
            self.trace.push(TracePoint {
                x: xi.clone(),
                delta: threshold / s2,
                open_wall: false,
            });
            self.trace.push(TracePoint {
                x: res.x,
                delta: d / s2,
                open_wall: false,
            });
            self.end = Some(ProfileEnd { x: xi, open: false });
            let why = TerminationReason::SolverExit("the threshold is crossed".into());
            return Ok((state.terminate_with(why), None));
        }
        let at_wall = xk == self.wall;
        self.trace.push(TracePoint {
            x: res.x.clone(),
            delta: d.max(0.0) / s2,
            open_wall: at_wall,
        });
        if at_wall {
            self.end = Some(ProfileEnd {
                x: res.x,
                open: true,
            });
            let why = TerminationReason::SolverExit("the wall is reached".into());
            return Ok((state.terminate_with(why), None));
        }
        self.prev_x = res.x;
        self.prev_d = d;
        self.delta *= 2.0;
        Ok((state, None))
    }
}

/// 95 % interval of coordinate `k` itself, from its profile's ends.
pub fn coordinate_interval(profile: &Profile, k: usize) -> Interval {
    Interval {
        lo: profile.lower.x[k],
        hi: profile.upper.x[k],
        lo_open: profile.lower.open,
        hi_open: profile.upper.open,
    }
}

/// 95 % interval of a natural parameter: the range of its value over every profile point
/// inside the threshold (the projection of the confidence region traced by the profiles).
/// An end is open when the box, not the data, stopped the parameter there: see
/// [`stopped_by_open_wall`]. `None` when no profile point gives a finite value.
pub fn natural_interval(p: &Problem, profiles: &[Profile], index: usize) -> Option<Interval> {
    let limit = CHI2_1_95 + 1e-9;
    let mut lo: Option<(f64, &[f64])> = None;
    let mut hi: Option<(f64, &[f64])> = None;
    for tp in profiles.iter().flat_map(|pr| pr.trace.iter()) {
        if tp.delta > limit {
            continue;
        }
        let v = p.space.natural(&tp.x)[index];
        if !v.is_finite() {
            continue;
        }
        if lo.is_none_or(|(l, _)| v < l) {
            lo = Some((v, &tp.x));
        }
        if hi.is_none_or(|(h, _)| v > h) {
            hi = Some((v, &tp.x));
        }
    }
    let ((a, xa), (b, xb)) = (lo?, hi?);
    Some(Interval {
        lo: a,
        hi: b,
        lo_open: stopped_by_open_wall(p, profiles, xa, index, -1.0),
        hi_open: stopped_by_open_wall(p, profiles, xb, index, 1.0),
    })
}

/// How close (transformed units) a coordinate must be to a wall for the point to count as
/// stopped by it, and how far beyond the wall it is pushed to see whether the parameter would
/// go on: one e-fold for logarithmic and logit coordinates.
const WALL_PUSH: f64 = 1.0;

/// Relative change of the parameter under that push above which the wall, not the physics,
/// limits it. The logit walls of μ_k/μ_s and of the recovery share sit next to hard limits
/// (μ_k ≤ μ_s, μ_k ≥ 0): pushing through those moves a parameter by about the gap (1e-4 or
/// less), while pushing through a wall the physics would cross moves it by tens of percent.
const WALL_MOVES: f64 = 0.01;

/// Whether natural parameter `index`, at its extreme `x` (direction `sign`), was stopped by
/// the box: some coordinate lies within [`WALL_PUSH`] of a wall its profile found open (the data
/// set no bound there), and pushing that coordinate [`WALL_PUSH`] beyond the wall moves the
/// parameter further in direction `sign` by more than [`WALL_MOVES`] of its value. This reads
/// the answer off the chart rather than off which of several equal trace points (the optimum,
/// a wall point) happened to attain the extreme.
fn stopped_by_open_wall(
    p: &Problem,
    profiles: &[Profile],
    x: &[f64],
    index: usize,
    sign: f64,
) -> bool {
    let v0 = p.space.natural(x)[index];
    profiles.iter().enumerate().any(|(j, pr)| {
        [
            (pr.lower.open, p.space.lo[j], -1.0),
            (pr.upper.open, p.space.hi[j], 1.0),
        ]
        .into_iter()
        .any(|(open, wall, outward)| {
            if !open || (x[j] - wall).abs() > WALL_PUSH {
                return false;
            }
            let mut y = x.to_vec();
            y[j] = wall + outward * WALL_PUSH;
            let dv = p.space.natural(&y)[index] - v0;
            sign * dv > WALL_MOVES * v0.abs()
        })
    })
}

fn with(x: &[f64], k: usize, v: f64) -> Vec<f64> {
    let mut y = x.to_vec();
    y[k] = v;
    y
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_problems::{linear, TestProblem};

    /// A straight line a + b t through 20 points with a deterministic scatter of SD about 1
    /// (residuals in noise units), and a third coordinate c the data do not see.
    fn line_fit() -> (TestProblem, Vec<f64>, DMatrix<f64>) {
        let n = 20;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / (n - 1) as f64).collect();
        let y: Vec<f64> = t
            .iter()
            .enumerate()
            .map(|(i, ti)| 1.0 + 2.0 * ti + 1.3 * (2.7 * i as f64).sin())
            .collect();
        let a: Vec<Vec<f64>> = t.iter().map(|ti| vec![1.0, *ti, 0.0]).collect();
        let am = DMatrix::from_fn(n, 2, |i, j| a[i][j]);
        // Normal equations are fine here (cond ≈ 10): the exact answer to compare with.
        let ata_inv = (am.transpose() * &am).try_inverse().unwrap();
        let x_hat = &ata_inv * am.transpose() * DVector::from_vec(y.clone());
        let p = linear(a, y, vec![-10.0, -10.0, -1.0], vec![10.0, 10.0, 1.0]);
        (p, vec![x_hat[0], x_hat[1], 0.0], ata_inv)
    }

    #[test]
    fn standard_errors_of_a_linear_model_are_the_textbook_ones() {
        let (p, x, ata_inv) = line_fit();
        let ssr = p.sum_of_squares(&x);
        let s2 = variance_scale(ssr, p.observations(), 3);
        assert!(
            s2 > 1.0,
            "the scatter should widen the intervals: s² = {s2}"
        );
        let st = coordinate_stats(&p, &x, ssr);
        for k in 0..2 {
            let want = (s2 * ata_inv[(k, k)]).sqrt();
            assert!(
                (st.std_errors[k] - want).abs() < 1e-6 * want,
                "se[{k}] = {} vs {want}",
                st.std_errors[k]
            );
        }
        assert!(st.std_errors[2].is_infinite(), "c has no curvature");
        assert_eq!(st.flat.len(), 1);
        assert!(st.flat[0].1[2].abs() > 0.999, "the flat direction is c");
    }

    #[test]
    fn profile_intervals_of_a_linear_model_are_plus_minus_1_96_se() {
        let (p, x, _) = line_fit();
        let ssr = p.sum_of_squares(&x);
        let st = coordinate_stats(&p, &x, ssr);
        let prof = profiles(&p, &x, ssr, &st.std_errors);
        for k in 0..2 {
            let i = coordinate_interval(&prof[k], k);
            let half = 1.96 * st.std_errors[k];
            assert!(i.is_closed(), "{k}: {i:?}");
            // 1.96 vs √3.841 = 1.95985: 8e-5 relative.
            assert!(
                (i.lo - (x[k] - half)).abs() < 2e-4 * half,
                "{k}: {i:?} vs ±{half}"
            );
            assert!(
                (i.hi - (x[k] + half)).abs() < 2e-4 * half,
                "{k}: {i:?} vs ±{half}"
            );
            assert!(prof[k].better.is_none(), "already at the optimum");
        }
        // The coordinate the data do not see: both profile ends reach the walls, open.
        let c = coordinate_interval(&prof[2], 2);
        assert_eq!((c.lo, c.hi, c.lo_open, c.hi_open), (-1.0, 1.0, true, true));
    }

    #[test]
    fn a_profile_reports_a_better_optimum_it_walks_into() {
        // Start the profiles off the optimum: re-minimising the other coordinates finds SSRs
        // below the given one, which the caller must hear of.
        let (p, x, _) = line_fit();
        let off = vec![x[0] + 0.5, x[1], 0.0];
        let ssr = p.sum_of_squares(&off);
        let st = coordinate_stats(&p, &x, p.sum_of_squares(&x));
        let prof = profiles(&p, &off, ssr, &st.std_errors);
        let (_, better) = prof[1].better.clone().expect("a better point");
        assert!(better < ssr - 1.0, "{better} vs {ssr}");
    }
}
