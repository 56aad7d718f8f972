//! Global stage: Latin-hypercube sampling and differential evolution in the transformed box,
//! evaluated in parallel with rayon and deterministic for a given seed. Differential evolution
//! is an argmin `Solver` run by its `Executor`, as the local methods are.

use crate::residuals::Residuals;
use argmin::core::{
    Error as ArgminError, Executor, IterState, Problem, Solver, State, TerminationReason,
    TerminationStatus, KV,
};
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

/// The SSRs of differential evolution's trials, each against the cost of the member it
/// challenges (`ceilings`, order preserved): a trial sure to end above that cost is stopped
/// there and counts as `f64::MAX`, like a trial that cannot be simulated. A trial replaces its
/// member when its cost is not above the member's, so the population evolves exactly as with
/// every trial run to its end.
fn evaluate_trials<R: Residuals + ?Sized>(
    p: &R,
    trials: &[Vec<f64>],
    ceilings: &[f64],
) -> Vec<f64> {
    trials
        .par_iter()
        .zip(ceilings)
        .map(|(x, &ceiling)| {
            p.sum_of_squares_unless_above(x, ceiling)
                .map_or(f64::MAX, sanitize)
        })
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
/// evaluations run in parallel. The generations are [`DifferentialEvolution`]'s, run by
/// argmin's `Executor`.
pub fn differential_evolution<R: Residuals + ?Sized>(
    p: &R,
    seeds: &[Vec<f64>],
    opts: &DeOptions,
    seed: u64,
) -> Population {
    let solver = DifferentialEvolution::new(*opts, seeds, seed);
    let run = Executor::new(p, solver)
        .configure(|s| s.max_iters(u64::MAX))
        .timer(false)
        .run();
    let (de, generations) = match run {
        Ok(mut res) => {
            let generations = res.state().get_iter() as usize;
            (std::mem::take(&mut res.solver), generations)
        }
        // Its steps fail only without a problem, which the executor always gives: should one
        // fail all the same, the seeds are the population (evaluated), never a panic.
        Err(_) => {
            let mut pop = seeds.to_vec();
            for x in pop.iter_mut() {
                p.clamp_into_box(x);
            }
            let cost = evaluate_all(p, &pop);
            let evaluations = pop.len();
            let de = DifferentialEvolution {
                pop,
                cost,
                evaluations,
                ..DifferentialEvolution::default()
            };
            (de, 0)
        }
    };
    let mut idx: Vec<usize> = (0..de.pop.len()).collect();
    idx.sort_by(|&a, &b| de.cost[a].total_cmp(&de.cost[b]));
    Population {
        members: idx.iter().map(|&i| de.pop[i].clone()).collect(),
        costs: idx.iter().map(|&i| de.cost[i]).collect(),
        generations,
        evaluations: de.evaluations,
    }
}

/// The state argmin keeps for [`DifferentialEvolution`]: the best member and its SSR.
pub type DeState = IterState<Vec<f64>, (), (), (), (), f64>;

/// Differential evolution (rand/1/bin) as an argmin [`Solver`]: `init` draws and evaluates the
/// population, each `next_iter` is one generation. It stops when the next generation would
/// exceed the budget of model runs, or when the population's costs agree within the
/// tolerance (argmin's `SolverExit` with the reason).
#[derive(Clone, Debug, Default)]
pub struct DifferentialEvolution {
    opts: Option<DeOptions>,
    seeds: Vec<Vec<f64>>,
    rng: Option<ChaCha8Rng>,
    /// The population and the SSR of each member.
    pub pop: Vec<Vec<f64>>,
    /// SSR of each member.
    pub cost: Vec<f64>,
    /// Model runs spent.
    pub evaluations: usize,
}

impl DifferentialEvolution {
    /// A solver with `opts`, keeping up to half the population from `seeds`, seeded by `seed`.
    pub fn new(opts: DeOptions, seeds: &[Vec<f64>], seed: u64) -> DifferentialEvolution {
        DifferentialEvolution {
            opts: Some(opts),
            seeds: seeds.to_vec(),
            rng: Some(ChaCha8Rng::seed_from_u64(seed)),
            ..DifferentialEvolution::default()
        }
    }

    fn best(&self) -> (Vec<f64>, f64) {
        let mut b = 0;
        for i in 1..self.cost.len() {
            if self.cost[i] < self.cost[b] {
                b = i;
            }
        }
        (self.pop[b].clone(), self.cost[b])
    }

    /// The options and the generator, taken out for a step (given back by the step).
    fn take_parts(&mut self) -> Result<(DeOptions, ChaCha8Rng), ArgminError> {
        match (self.opts, self.rng.take()) {
            (Some(o), Some(r)) => Ok((o, r)),
            _ => Err(argmin::core::ArgminError::NotInitialized {
                text: "differential evolution built without options".into(),
            }
            .into()),
        }
    }
}

impl<R: Residuals + ?Sized> Solver<&R, DeState> for DifferentialEvolution {
    const NAME: &'static str = "differential evolution (rand/1/bin)";

    fn init(
        &mut self,
        problem: &mut Problem<&R>,
        state: DeState,
    ) -> Result<(DeState, Option<KV>), ArgminError> {
        let p = *crate::residuals::given(problem)?;
        let (opts, mut rng) = self.take_parts()?;
        let np = opts.population.max(MIN_POPULATION);
        let mut pop: Vec<Vec<f64>> = self.seeds.iter().take(np / 2).cloned().collect();
        let need = np - pop.len();
        pop.extend(latin_hypercube(p, need, &mut rng));
        self.rng = Some(rng);
        for x in pop.iter_mut() {
            p.clamp_into_box(x);
        }
        self.cost = evaluate_all(p, &pop);
        self.pop = pop;
        self.evaluations = np;
        let (x, c) = self.best();
        Ok((state.param(x).cost(c), None))
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<&R>,
        state: DeState,
    ) -> Result<(DeState, Option<KV>), ArgminError> {
        let p = *crate::residuals::given(problem)?;
        let (lo, hi) = p.bounds();
        let m = p.dim();
        let (opts, mut generator) = self.take_parts()?;
        let rng = &mut generator;
        let pop = &self.pop;
        let np = pop.len();
        let trials: Vec<Vec<f64>> = (0..np)
            .map(|i| {
                let pick = |rng: &mut ChaCha8Rng, not: &[usize]| loop {
                    let c = rng.gen_range(0..np);
                    if !not.contains(&c) {
                        break c;
                    }
                };
                let a = pick(rng, &[i]);
                let b = pick(rng, &[i, a]);
                let c = pick(rng, &[i, a, b]);
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
        self.rng = Some(generator);
        let tc = evaluate_trials(p, &trials, &self.cost);
        self.evaluations += np;
        for (i, (t, c)) in trials.into_iter().zip(tc).enumerate() {
            if c <= self.cost[i] {
                self.pop[i] = t;
                self.cost[i] = c;
            }
        }
        let (x, best) = self.best();
        let worst = self.cost.iter().cloned().fold(0.0, f64::max);
        let state = state.param(x).cost(best);
        if (worst - best) <= opts.tolerance * best.max(1e-300) {
            let why = TerminationReason::SolverExit("the population's costs agree".into());
            return Ok((state.terminate_with(why), None));
        }
        Ok((state, None))
    }

    fn terminate(&mut self, _state: &DeState) -> TerminationStatus {
        let Some(opts) = self.opts else {
            return TerminationStatus::NotTerminated;
        };
        let np = self.pop.len();
        let dim = self.pop.first().map_or(0, Vec::len);
        if dim == 0 || self.evaluations + np > opts.max_evaluations {
            TerminationStatus::Terminated(TerminationReason::SolverExit(
                "the budget of model runs is spent".into(),
            ))
        } else {
            TerminationStatus::NotTerminated
        }
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
    fn evolution_runs_under_argmins_executor_generation_by_generation_within_its_budget() {
        use argmin::core::observers::{Observe, ObserverMode};
        use std::sync::{Arc, Mutex};
        // An observer keeping the best cost of each generation: it never rises.
        struct Best(Arc<Mutex<Vec<f64>>>);
        impl Observe<DeState> for Best {
            fn observe_iter(&mut self, state: &DeState, _kv: &KV) -> Result<(), ArgminError> {
                self.0.lock().unwrap().push(state.get_cost());
                Ok(())
            }
        }
        let p = walled_sphere();
        let seen = Arc::new(Mutex::new(Vec::new()));
        let o = opts(0.0);
        let res = Executor::new(&p, DifferentialEvolution::new(o, &[], 7))
            .configure(|s| s.max_iters(u64::MAX))
            .add_observer(Best(seen.clone()), ObserverMode::Always)
            .run()
            .unwrap();
        let costs = seen.lock().unwrap().clone();
        assert!(costs.windows(2).all(|w| w[1] <= w[0]), "{costs:?}");
        // The function's result is this run's: as many generations, the same best member.
        let pop = differential_evolution(&p, &[], &o, 7);
        assert_eq!(costs.len(), pop.generations);
        assert_eq!(res.state().get_param().unwrap(), &pop.members[0]);
        assert_eq!(*costs.last().unwrap(), pop.costs[0]);
        // The budget: one population to start, one per generation, never beyond it.
        assert_eq!(pop.evaluations, 30 * (1 + pop.generations));
        assert!(pop.evaluations <= o.max_evaluations && pop.evaluations + 30 > o.max_evaluations);
        assert_eq!(
            res.state().get_termination_reason(),
            Some(&TerminationReason::SolverExit(
                "the budget of model runs is spent".into()
            ))
        );
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
