//! Step 1 of the plan: the valley, the parameter vectors the current data allow, walked along
//! every coordinate the fit does not determine, and the planning point in its middle.

use crate::information::information;
use crate::outcome::{PlanOptions, ValleyPoint};
use rayon::prelude::*;
use subfric_fit::calibrate::report_variance_scale;
use subfric_fit::lm::{levenberg_marquardt, LmOptions};
use subfric_fit::uncertainty::{profile_one, stats_of_information, CHI2_1_95};
use subfric_fit::{Coord, FitReport, Problem, Space, Status};
use subfric_reading::FitTest;

/// Iterations of each held re-fit of a walk: it starts next to its answer (the previous
/// point), so a few suffice.
const WALK_MAX_ITERATIONS: usize = 40;

/// Round-off allowance on the χ²₁(95 %) threshold of a walk point (the walk's own end points
/// sit on it).
const WALK_CHI2_SLACK: f64 = 1e-6;

/// A point of a valley walk: optimiser coordinates and (SSR − SSR_min)/s².
type WalkPoint = (Vec<f64>, f64);

/// Walks coordinate `k` over its profile interval: `n` points evenly spread, each re-fitted
/// with `k` held, walked outward from `x0` so that each re-fit starts next to its answer.
/// `hold`: another coordinate held at its value in `x0` (the primary valley's, so that a
/// secondary walk does not slide along it).
#[allow(clippy::too_many_arguments)]
fn walk(
    p: &Problem,
    x0: &[f64],
    ssr0: f64,
    s2: f64,
    se: f64,
    k: usize,
    n: usize,
    hold: Option<usize>,
) -> Vec<WalkPoint> {
    let prof = profile_one(p, x0, ssr0, s2, se, k);
    let (a, b) = (prof.lower.x[k], prof.upper.x[k]);
    let n = n.max(2);
    let targets: Vec<f64> = (0..n)
        .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
        .collect();
    let fixed: Vec<bool> = (0..x0.len()).map(|i| i == k || Some(i) == hold).collect();
    let opts = LmOptions {
        max_iterations: WALK_MAX_ITERATIONS,
        ..LmOptions::default()
    };
    let mut out = Vec::new();
    for side in [-1.0, 1.0] {
        let mut prev = x0.to_vec();
        let mut ts: Vec<f64> = targets
            .iter()
            .copied()
            .filter(|t| if side < 0.0 { *t < x0[k] } else { *t >= x0[k] })
            .collect();
        if side < 0.0 {
            ts.reverse();
        }
        for t in ts {
            let mut start = prev.clone();
            start[k] = t;
            let r = levenberg_marquardt(p, &start, Some(&fixed), &opts);
            let delta = (r.ssr - ssr0) / s2;
            if delta <= CHI2_1_95 + WALK_CHI2_SLACK {
                out.push((r.x.clone(), delta.max(0.0)));
            }
            prev = r.x;
        }
    }
    out
}

pub(crate) struct Valley {
    /// The current fit first, then the primary walk, then the others.
    pub(crate) points: Vec<ValleyPoint>,
    /// Optimiser coordinates of each point.
    pub(crate) xs: Vec<Vec<f64>>,
    /// The planning point: the primary walk's point nearest the middle of its interval.
    pub(crate) planning_index: usize,
}

impl Valley {
    /// Appends the points of the walk along coordinate `k`.
    fn push_walk(&mut self, space: &Space, k: usize, pts: Vec<WalkPoint>) {
        for (x, d) in pts {
            self.points.push(ValleyPoint {
                model: space.model_at(&x),
                delta: d,
                walked: space.coords[k].name(),
            });
            self.xs.push(x);
        }
    }
}

/// Walks the valley (step 1 of the module documentation): the primary undetermined
/// coordinate from the current fit, the others from the planning point with the primary one
/// held.
pub(crate) fn walk_valley(
    tests: &[FitTest],
    report: &FitReport,
    space: &Space,
    opts: &PlanOptions,
) -> Valley {
    let fit = report.model;
    let run_counter = opts.fit.run_counter.as_ref();
    let problem = Problem::new(tests, space.clone()).counting(run_counter);
    let x_fit = space.point_of(&fit);
    let ssr_fit = problem.ssr(&x_fit);
    let s2 = report_variance_scale(report);
    let se_x: Vec<f64> = match information(tests, space, &x_fit, run_counter) {
        Some(a) => stats_of_information(&a, s2).std_errors,
        None => vec![f64::INFINITY; space.dim()],
    };
    let walked = walked_coords(space, report);
    // The planning point: the walked point nearest the middle of the primary walk (the
    // recovery share when the combined chart is used: the paper's κ–ξ valley). The other
    // undetermined coordinates are walked from it, not from the optimiser's point, which often
    // sits on a wall of the primary valley (ξ ≈ 0).
    let primary = walked
        .iter()
        .position(|&k| space.coords[k] == Coord::RecoveryShare)
        .unwrap_or(0);
    let mut valley = Valley {
        points: vec![ValleyPoint {
            model: fit,
            delta: 0.0,
            walked: "the current fit".into(),
        }],
        xs: vec![x_fit.clone()],
        planning_index: 0,
    };
    if let Some(&k) = walked.get(primary) {
        let pts = walk(
            &problem,
            &x_fit,
            ssr_fit,
            s2,
            se_x[k],
            k,
            opts.valley_points,
            None,
        );
        if let Some(i) = nearest_middle(&pts, k) {
            valley.planning_index = 1 + i;
        }
        valley.push_walk(space, k, pts);
    }
    let x_centre = valley.xs[valley.planning_index].clone();
    let others: Vec<(usize, Vec<WalkPoint>)> = walked
        .par_iter()
        .enumerate()
        .filter(|(i, _)| *i != primary)
        .map(|(_, &k)| {
            (
                k,
                walk(
                    &problem,
                    &x_centre,
                    ssr_fit,
                    s2,
                    se_x[k],
                    k,
                    opts.valley_points,
                    walked.get(primary).copied(),
                ),
            )
        })
        .collect();
    for (k, pts) in others {
        valley.push_walk(space, k, pts);
    }
    valley
}

/// The optimiser coordinates whose interval (or combination) the report does not call
/// determined.
fn walked_coords(space: &Space, report: &FitReport) -> Vec<usize> {
    let mut combos = report.combinations.iter();
    space
        .coords
        .iter()
        .enumerate()
        .filter(|(_, c)| match c {
            Coord::Natural(q) => report
                .param(q.key())
                .is_some_and(|p| p.status != Status::Determined),
            _ => combos.next().is_some_and(|c| !c.determined),
        })
        .map(|(k, _)| k)
        .collect()
}

/// Index of the walk point whose coordinate `k` is nearest the middle of the walk's range.
fn nearest_middle(pts: &[WalkPoint], k: usize) -> Option<usize> {
    let (lo, hi) = pts.iter().fold((f64::MAX, f64::MIN), |(a, b), (x, _)| {
        (a.min(x[k]), b.max(x[k]))
    });
    let mid = 0.5 * (lo + hi);
    (0..pts.len()).min_by(|&i, &j| {
        (pts[i].0[k] - mid)
            .abs()
            .total_cmp(&(pts[j].0[k] - mid).abs())
    })
}
