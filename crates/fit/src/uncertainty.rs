//! Uncertainty and identifiability: standard errors and correlations from the Jacobian at the
//! optimum, flat directions of JᵀJ, and profile intervals that do not assume a quadratic cost.

use crate::lm::{jacobian, levenberg_marquardt, LmOptions};
use crate::problem::Problem;
use nalgebra::{DMatrix, SymmetricEigen};
use rayon::prelude::*;
use serde::Serialize;

/// χ²₁ quantile at 95 %: the rise of the (scaled) SSR that bounds a 95 % profile interval.
pub const CHI2_1_95: f64 = 3.841;

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

/// Standard errors, correlations and flat directions at `x`.
pub fn linearise(p: &Problem, x: &[f64], ssr: f64) -> Linearised {
    let m = x.len();
    let mut r = Vec::new();
    let mut s = Vec::new();
    p.residuals(x, &mut r, &mut s);
    let j = jacobian(p, x, &r, None);
    let jtj = j.transpose() * &j;
    let s2 = variance_scale(ssr, p.rows(), m);
    // Natural = T(x): its Jacobian by differences (μ_k depends on μ_s and its ratio).
    let nat0 = p.space.natural(x);
    let mut t = DMatrix::zeros(m, m);
    for k in 0..m {
        let mut xp = x.to_vec();
        let h = 1e-7 * (1.0 + x[k].abs());
        xp[k] += h;
        let nat = p.space.natural(&xp);
        for i in 0..m {
            t[(i, k)] = (nat[i] - nat0[i]) / h;
        }
    }
    let names: Vec<String> = p.space.coords.iter().map(|c| c.name()).collect();
    let eig = SymmetricEigen::new(jtj.clone());
    let max_ev = eig.eigenvalues.iter().cloned().fold(0.0, f64::max);
    let mut flat = Vec::new();
    for (i, &ev) in eig.eigenvalues.iter().enumerate() {
        let rel = ev / max_ev.max(1e-300);
        if rel < 1e-6 {
            let v = eig.eigenvectors.column(i);
            let mut comps: Vec<(String, f64)> =
                names.iter().cloned().zip(v.iter().cloned()).collect();
            comps.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
            comps.retain(|c| c.1.abs() > 0.1);
            flat.push(FlatDirection {
                relative_curvature: rel,
                components: comps,
            });
        }
    }
    // Pseudo-inverse: directions with (almost) no curvature get infinite variance, and so does
    // every parameter that moves along them.
    let cutoff = 1e-10 * max_ev;
    let mut cov_x = DMatrix::zeros(m, m);
    let mut flat_vectors = Vec::new();
    for (i, &ev) in eig.eigenvalues.iter().enumerate() {
        let v = eig.eigenvectors.column(i).into_owned();
        if ev > cutoff && ev.is_finite() {
            cov_x += &v * v.transpose() * (s2 / ev);
        } else {
            flat_vectors.push(v);
        }
    }
    let loads_on_flat = |row: &[f64]| {
        let norm2: f64 = row.iter().map(|v| v * v).sum();
        let load: f64 = flat_vectors
            .iter()
            .map(|v| {
                row.iter()
                    .zip(v.iter())
                    .map(|(a, b)| a * b)
                    .sum::<f64>()
                    .powi(2)
            })
            .sum();
        load > 1e-3 * norm2.max(1e-300)
    };
    let cov = &t * &cov_x * t.transpose();
    let se: Vec<f64> = (0..m)
        .map(|k| {
            let row: Vec<f64> = (0..m).map(|j| t[(k, j)]).collect();
            if loads_on_flat(&row) {
                f64::INFINITY
            } else {
                cov[(k, k)].max(0.0).sqrt()
            }
        })
        .collect();
    let se_x: Vec<f64> = (0..m)
        .map(|k| {
            let mut e = vec![0.0; m];
            e[k] = 1.0;
            if loads_on_flat(&e) {
                f64::INFINITY
            } else {
                cov_x[(k, k)].max(0.0).sqrt()
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
        std_errors_x: se_x,
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

/// Profiles every optimiser coordinate (in parallel): each is stepped away from the optimum
/// with the others re-minimised, until the SSR has risen by χ²₁(0.95)·s² or the box wall is
/// reached (then that side is open: the data set no bound there).
pub fn profiles(p: &Problem, x: &[f64], ssr: f64, se_x: &[f64]) -> Vec<Profile> {
    let m = x.len();
    let s2 = variance_scale(ssr, p.rows(), m);
    let threshold = CHI2_1_95 * s2;
    (0..m)
        .into_par_iter()
        .map(|k| {
            let mut trace = vec![TracePoint {
                x: x.to_vec(),
                delta: 0.0,
                open_wall: false,
            }];
            let mut better: Option<(Vec<f64>, f64)> = None;
            let mut ends = Vec::new();
            let fixed: Vec<bool> = (0..m).map(|i| i == k).collect();
            let opts = LmOptions {
                max_iterations: 30,
                ..LmOptions::default()
            };
            for side in [-1.0f64, 1.0] {
                let wall = if side < 0.0 {
                    p.space.lo[k]
                } else {
                    p.space.hi[k]
                };
                let room = (wall - x[k]).abs();
                let mut delta = if se_x[k].is_finite() {
                    1.5 * se_x[k]
                } else {
                    0.05
                };
                delta = delta.clamp(1e-3, 0.5);
                let mut prev_x = x.to_vec();
                let mut prev_d = 0.0f64;
                let mut end = ProfileEnd {
                    x: with(x, k, wall),
                    open: true,
                };
                for _ in 0..16 {
                    let xk = if room <= delta {
                        wall
                    } else {
                        x[k] + side * delta
                    };
                    let res = levenberg_marquardt(p, &with(&prev_x, k, xk), Some(&fixed), &opts);
                    let d = res.ssr - ssr;
                    if d < -1e-6 * ssr.max(1.0) && better.as_ref().is_none_or(|b| res.ssr < b.1) {
                        better = Some((res.x.clone(), res.ssr));
                    }
                    if d >= threshold {
                        // Interpolate in √ΔSSR, linear in the offset for a quadratic profile.
                        let (a, b) = (prev_d.max(0.0).sqrt(), d.sqrt());
                        let w = ((threshold.sqrt() - a) / (b - a)).clamp(0.0, 1.0);
                        let xi: Vec<f64> = prev_x
                            .iter()
                            .zip(&res.x)
                            .map(|(u, v)| u + w * (v - u))
                            .collect();
                        trace.push(TracePoint {
                            x: xi.clone(),
                            delta: threshold / s2,
                            open_wall: false,
                        });
                        trace.push(TracePoint {
                            x: res.x,
                            delta: d / s2,
                            open_wall: false,
                        });
                        end = ProfileEnd { x: xi, open: false };
                        break;
                    }
                    let at_wall = xk == wall;
                    trace.push(TracePoint {
                        x: res.x.clone(),
                        delta: d.max(0.0) / s2,
                        open_wall: at_wall,
                    });
                    if at_wall {
                        end = ProfileEnd {
                            x: res.x,
                            open: true,
                        };
                        break;
                    }
                    prev_x = res.x;
                    prev_d = d;
                    delta *= 2.0;
                }
                ends.push(end);
            }
            let upper = ends.pop().unwrap_or(ProfileEnd {
                x: x.to_vec(),
                open: true,
            });
            let lower = ends.pop().unwrap_or(ProfileEnd {
                x: x.to_vec(),
                open: true,
            });
            Profile {
                lower,
                upper,
                trace,
                better,
            }
        })
        .collect()
}

/// 95 % interval of a natural parameter: the range of its value over every profile point
/// inside the threshold (the projection of the confidence region traced by the profiles), and
/// whether each end lies on a wall the data did not bound.
pub fn natural_interval(p: &Problem, profiles: &[Profile], index: usize) -> (f64, f64, bool, bool) {
    let limit = CHI2_1_95 + 1e-9;
    let mut lo = (f64::INFINITY, false);
    let mut hi = (f64::NEG_INFINITY, false);
    for tp in profiles.iter().flat_map(|pr| pr.trace.iter()) {
        if tp.delta > limit {
            continue;
        }
        let v = p.space.natural(&tp.x)[index];
        if !v.is_finite() {
            continue;
        }
        if v < lo.0 {
            lo = (v, tp.open_wall);
        }
        if v > hi.0 {
            hi = (v, tp.open_wall);
        }
    }
    (lo.0, hi.0, lo.1, hi.1)
}

fn with(x: &[f64], k: usize, v: f64) -> Vec<f64> {
    let mut y = x.to_vec();
    y[k] = v;
    y
}
