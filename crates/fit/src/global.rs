//! Global stage: Latin-hypercube sampling and differential evolution in the transformed box,
//! evaluated in parallel with rayon and deterministic for a given seed.

use crate::residuals::Residuals;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// `n` Latin-hypercube points in the problem's box.
pub fn latin_hypercube<R: Residuals + ?Sized>(
    p: &R,
    n: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<Vec<f64>> {
    let m = p.dim();
    let (lo, hi) = p.bounds();
    let mut pts = vec![vec![0.0; m]; n];
    for k in 0..m {
        let mut perm: Vec<usize> = (0..n).collect();
        // Fisher–Yates drawing usize indices. rand's `SliceRandom::shuffle` draws u32 indices,
        // so it permutes differently for the same seed and would change every seeded fit
        // (and the committed outputs of `reproduce`): kept on purpose.
        for i in (1..n).rev() {
            let j = rng.gen_range(0..=i);
            perm.swap(i, j);
        }
        for (pt, slot) in pts.iter_mut().zip(&perm) {
            let u = (*slot as f64 + rng.gen::<f64>()) / n as f64;
            pt[k] = lo[k] + u * (hi[k] - lo[k]);
        }
    }
    pts
}

/// Evaluates the SSR of many points in parallel (order preserved; a non-finite SSR counts as
/// `f64::MAX`, so such points sort last).
pub fn evaluate_all<R: Residuals + ?Sized>(p: &R, pts: &[Vec<f64>]) -> Vec<f64> {
    pts.par_iter()
        .map(|x| sanitize(p.sum_of_squares(x)))
        .collect()
}

fn sanitize(v: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        f64::MAX
    }
}

/// Smallest population differential evolution runs with: rand/1/bin needs four distinct
/// members per trial, and fewer than five loses diversity at once.
pub const MIN_POPULATION: usize = 5;

/// Options of differential evolution (rand/1/bin).
#[derive(Clone, Copy, Debug)]
pub struct DeOptions {
    /// Population size (at least [`MIN_POPULATION`]).
    pub population: usize,
    /// Budget of model runs (population × generations, roughly).
    pub max_evaluations: usize,
    /// Differential weight F.
    pub f: f64,
    /// Crossover probability.
    pub cr: f64,
    /// Stop when the relative spread of population costs falls below this.
    pub tolerance: f64,
}

/// Tunables of the global stage as a calibration uses it; the population follows the number of
/// coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlobalTuning {
    /// Differential weight F.
    pub f: f64,
    /// Crossover probability CR.
    pub cr: f64,
    /// Stop when the relative spread of population costs falls below this.
    pub tolerance: f64,
    /// Population members per coordinate ...
    pub population_per_coordinate: usize,
    /// ... within this range.
    pub population_range: (usize, usize),
}

impl Default for GlobalTuning {
    /// Within Storn and Price's recommended ranges: F in [0.5, 1] (smaller F converges
    /// prematurely), and a high CR because the parameters are correlated (μ_k with κ and ξ),
    /// where trials that change one coordinate at a time make little progress. Ten members per
    /// coordinate is their rule of thumb, capped so that the default budget of 3000 runs still
    /// allows 50 generations.
    fn default() -> Self {
        GlobalTuning {
            f: 0.7,
            cr: 0.9,
            tolerance: 1e-6,
            population_per_coordinate: 10,
            population_range: (20, 60),
        }
    }
}

impl GlobalTuning {
    /// Options of differential evolution over `dim` coordinates with a budget of
    /// `max_evaluations` model runs.
    pub fn options(&self, dim: usize, max_evaluations: usize) -> DeOptions {
        let (a, b) = self.population_range;
        DeOptions {
            population: (self.population_per_coordinate * dim).max(a).min(b.max(a)),
            max_evaluations,
            f: self.f,
            cr: self.cr,
            tolerance: self.tolerance,
        }
    }
}

/// Result of the global stage: the final population sorted by cost.
#[derive(Clone, Debug)]
pub struct Population {
    /// Members, best first.
    pub members: Vec<Vec<f64>>,
    /// Their SSR.
    pub costs: Vec<f64>,
    /// Generations run.
    pub generations: usize,
    /// Model runs spent.
    pub evaluations: usize,
}

/// Differential evolution started from `seeds` (kept as members) plus Latin-hypercube points.
///
/// Deterministic for a `seed`: every random draw is made in order on one thread; only the
/// evaluations run in parallel.
pub fn differential_evolution<R: Residuals + ?Sized>(
    p: &R,
    seeds: &[Vec<f64>],
    opts: &DeOptions,
    seed: u64,
) -> Population {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let np = opts.population.max(MIN_POPULATION);
    let m = p.dim();
    let (lo, hi) = p.bounds();
    let mut pop: Vec<Vec<f64>> = seeds.iter().take(np / 2).cloned().collect();
    let need = np - pop.len();
    pop.extend(latin_hypercube(p, need, &mut rng));
    for x in pop.iter_mut() {
        p.clamp_into_box(x);
    }
    let mut cost = evaluate_all(p, &pop);
    let mut evals = np;
    let mut generations = 0;
    while m > 0 && evals + np <= opts.max_evaluations {
        generations += 1;
        let trials: Vec<Vec<f64>> = (0..np)
            .map(|i| {
                let pick = |rng: &mut ChaCha8Rng, not: &[usize]| loop {
                    let c = rng.gen_range(0..np);
                    if !not.contains(&c) {
                        break c;
                    }
                };
                let a = pick(&mut rng, &[i]);
                let b = pick(&mut rng, &[i, a]);
                let c = pick(&mut rng, &[i, a, b]);
                let jr = rng.gen_range(0..m);
                let mut t = pop[i].clone();
                for k in 0..m {
                    if k == jr || rng.gen::<f64>() < opts.cr {
                        let v = pop[a][k] + opts.f * (pop[b][k] - pop[c][k]);
                        // Bounce back inside rather than pile up on the wall.
                        t[k] = if v < lo[k] {
                            lo[k] + rng.gen::<f64>() * (pop[i][k] - lo[k])
                        } else if v > hi[k] {
                            hi[k] - rng.gen::<f64>() * (hi[k] - pop[i][k])
                        } else {
                            v
                        };
                    }
                }
                t
            })
            .collect();
        let tc = evaluate_all(p, &trials);
        evals += np;
        for (i, (t, c)) in trials.into_iter().zip(tc).enumerate() {
            if c <= cost[i] {
                pop[i] = t;
                cost[i] = c;
            }
        }
        let best = cost.iter().cloned().fold(f64::MAX, f64::min);
        let worst = cost.iter().cloned().fold(0.0, f64::max);
        if (worst - best) <= opts.tolerance * best.max(1e-300) {
            break;
        }
    }
    let mut idx: Vec<usize> = (0..np).collect();
    idx.sort_by(|&a, &b| cost[a].total_cmp(&cost[b]));
    Population {
        members: idx.iter().map(|&i| pop[i].clone()).collect(),
        costs: idx.iter().map(|&i| cost[i]).collect(),
        generations,
        evaluations: evals,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_problems::sphere;

    /// The sphere centred at (0.3, −0.7, 2.5, 0.1) in the box [−1, 1]⁴: the minimum is on the
    /// wall x₃ = 1, at (0.3, −0.7, 1, 0.1), with cost 1.5² = 2.25.
    fn walled_sphere() -> crate::test_problems::TestProblem {
        sphere(vec![0.3, -0.7, 2.5, 0.1], vec![-1.0; 4], vec![1.0; 4])
    }

    fn opts(tolerance: f64) -> DeOptions {
        DeOptions {
            population: 30,
            max_evaluations: 6000,
            f: 0.7,
            cr: 0.9,
            tolerance,
        }
    }

    #[test]
    fn the_same_seed_gives_the_same_population() {
        let p = walled_sphere();
        let a = differential_evolution(&p, &[], &opts(0.0), 7);
        let b = differential_evolution(&p, &[], &opts(0.0), 7);
        assert_eq!(a.members, b.members);
        assert_eq!(a.costs, b.costs);
        assert_eq!(
            (a.generations, a.evaluations),
            (b.generations, b.evaluations)
        );
        let c = differential_evolution(&p, &[], &opts(0.0), 8);
        assert_ne!(a.members, c.members, "the seed should matter");
    }

    #[test]
    fn the_result_does_not_depend_on_the_number_of_threads() {
        let p = walled_sphere();
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| differential_evolution(&p, &[], &opts(0.0), 3));
        let many = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap()
            .install(|| differential_evolution(&p, &[], &opts(0.0), 3));
        assert_eq!(one.members, many.members);
        assert_eq!(one.costs, many.costs);
    }

    #[test]
    fn a_sphere_in_a_box_is_minimised_on_the_wall() {
        let p = walled_sphere();
        let pop = differential_evolution(&p, &[], &opts(0.0), 11);
        let best = &pop.members[0];
        for (k, want) in [0.3, -0.7, 1.0, 0.1].iter().enumerate() {
            assert!((best[k] - want).abs() < 1e-4, "x[{k}] = {}", best[k]);
        }
        assert!((pop.costs[0] - 2.25).abs() < 1e-7, "{}", pop.costs[0]);
        assert!(
            pop.costs.windows(2).all(|w| w[0] <= w[1]),
            "sorted, best first"
        );
        for x in &pop.members {
            assert!(
                x.iter().all(|v| (-1.0..=1.0).contains(v)),
                "left the box: {x:?}"
            );
        }
        assert_eq!(pop.evaluations, 6000);
    }

    #[test]
    fn seeds_are_members_and_the_best_cost_is_never_lost() {
        let p = walled_sphere();
        let optimum = vec![0.3, -0.7, 1.0, 0.1];
        let exact = p.sum_of_squares(&optimum);
        // No generation: the population is the seed plus Latin-hypercube points.
        let start = DeOptions {
            max_evaluations: 30,
            ..opts(0.0)
        };
        let pop = differential_evolution(&p, std::slice::from_ref(&optimum), &start, 5);
        assert_eq!(pop.generations, 0);
        assert_eq!(pop.members[0], optimum);
        // Selection only replaces a member by a trial at least as good: the exact optimum's
        // cost survives every generation (possibly held by an equal-cost neighbour).
        let pop = differential_evolution(&p, &[optimum], &opts(0.0), 5);
        assert_eq!(pop.costs[0], exact);
    }

    #[test]
    fn a_collapsed_population_stops_before_the_budget() {
        let p = walled_sphere();
        let pop = differential_evolution(&p, &[], &opts(1e-6), 2);
        assert!(pop.evaluations < 6000, "{} runs", pop.evaluations);
        let (best, worst) = (pop.costs[0], pop.costs[pop.costs.len() - 1]);
        assert!(worst - best <= 1e-6 * best, "spread {best} .. {worst}");
    }
}
