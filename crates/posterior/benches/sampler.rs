//! Criterion benchmark of the posterior sampler (`cargo bench -p subfric-posterior --bench
//! sampler`): model runs per second of the ensemble sampler on Table 4 (the bundled two-way
//! cyclic curve, experiments/table4-two-way, 3 150 rows), walkers moved in parallel on every
//! core rayon is given.
//!
//! Set-up (not timed): the least-squares fit of the five parameters of the paper, as `subfric
//! fit` does it. Timed: `sample` from that optimum for a fixed 100 steps of 32 walkers (about
//! 3 200 model runs), convergence checks off, so every iteration does the same work: the run
//! is deterministic for its seed, and the throughput is its exact count of model runs.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use std::path::Path;
use subfric_fit::{calibrate, FitOptions, Param, Space};
use subfric_model::{Model, Params};
use subfric_posterior::{sample, PosteriorOptions, Priors};
use subfric_reading::{prepare_set, reference_model, typical_rate, FitTest};

fn table4() -> (Vec<FitTest>, Space, Model) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../experiments/table4-two-way");
    let set = subfric_data::load_set(&dir).expect("the bundled Table 4 set loads");
    let tests: Vec<FitTest> = prepare_set(&set, false)
        .into_iter()
        .map(|p| p.fit)
        .collect();
    assert_eq!(
        tests.iter().map(|t| t.len()).sum::<usize>(),
        3151,
        "Table 4 unthinned"
    );
    let mut template = Model::base(Params::sample()).expect("sample parameters are valid");
    let published = reference_model(&set).expect("Table 4 has published parameters");
    template.params.alpha_t = published.params.alpha_t;
    template.params.alpha_n = published.params.alpha_n;
    let space = Space::with_rate(template, &Param::BASE, &[], typical_rate(&tests));
    let fit =
        calibrate(&tests, space.clone(), &FitOptions::default(), &|_| {}).expect("Table 4 fits");
    (tests, space, fit.model)
}

fn sampler(c: &mut Criterion) {
    let (tests, space, optimum) = table4();
    let walkers = 32;
    let opts = PosteriorOptions {
        walkers,
        max_evals: walkers * 101,
        stop_when_converged: false,
        ..PosteriorOptions::default()
    };
    let run = || {
        sample(
            &tests,
            &space,
            &optimum,
            &Priors::default(),
            &opts,
            &|_, _| {},
        )
        .expect("Table 4 samples")
    };
    let t0 = std::time::Instant::now();
    let first = run();
    let runs = first.model_runs;
    eprintln!(
        "sampler on Table 4: {} model runs in {:.2} s on {} threads: {:.0} model runs per second (first run, acceptance {:.2})",
        runs,
        t0.elapsed().as_secs_f64(),
        rayon::current_num_threads(),
        runs as f64 / t0.elapsed().as_secs_f64(),
        first.acceptance
    );
    let mut g = c.benchmark_group("posterior");
    g.throughput(Throughput::Elements(runs as u64));
    g.sample_size(10);
    g.bench_function(
        "table4 sampler, 100 steps of 32 walkers (model runs)",
        |b| {
            b.iter(|| {
                let post = run();
                assert_eq!(post.model_runs, runs, "the run is deterministic");
                black_box(post.summary.len())
            })
        },
    );
    g.finish();
}

criterion_group!(benches, sampler);
criterion_main!(benches);
