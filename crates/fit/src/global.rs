//! Global stage: Latin-hypercube sampling and differential evolution in the transformed box,
//! evaluated in parallel with rayon and deterministic for a given seed.

use crate::problem::Problem;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// `n` Latin-hypercube points in the problem's box.
pub fn latin_hypercube(p: &Problem, n: usize, rng: &mut ChaCha8Rng) -> Vec<Vec<f64>> {
    let m = p.space.dim();
    let mut pts = vec![vec![0.0; m]; n];
    for k in 0..m {
        let mut perm: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            let j = rng.gen_range(0..=i);
            perm.swap(i, j);
        }
        for (pt, slot) in pts.iter_mut().zip(&perm) {
            let u = (*slot as f64 + rng.gen::<f64>()) / n as f64;
            pt[k] = p.space.lo[k] + u * (p.space.hi[k] - p.space.lo[k]);
        }
    }
    pts
}

/// Evaluates the SSR of many points in parallel (order preserved).
pub fn evaluate_all(p: &Problem, pts: &[Vec<f64>]) -> Vec<f64> {
    pts.par_iter().map(|x| sanitize(p.ssr(x))).collect()
}

fn sanitize(v: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        f64::MAX
    }
}

/// Options of differential evolution (rand/1/bin).
#[derive(Clone, Copy, Debug)]
pub struct DeOptions {
    /// Population size.
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
pub fn differential_evolution(
    p: &Problem,
    seeds: &[Vec<f64>],
    opts: &DeOptions,
    seed: u64,
) -> Population {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let np = opts.population.max(5);
    let m = p.space.dim();
    let mut pop: Vec<Vec<f64>> = seeds.iter().take(np / 2).cloned().collect();
    let need = np - pop.len();
    pop.extend(latin_hypercube(p, need, &mut rng));
    for x in pop.iter_mut() {
        p.space.clamp(x);
    }
    let mut cost = evaluate_all(p, &pop);
    let mut evals = np;
    let mut generations = 0;
    while evals + np <= opts.max_evaluations {
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
                        t[k] = if v < p.space.lo[k] {
                            p.space.lo[k] + rng.gen::<f64>() * (pop[i][k] - p.space.lo[k])
                        } else if v > p.space.hi[k] {
                            p.space.hi[k] - rng.gen::<f64>() * (p.space.hi[k] - pop[i][k])
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
