//! The ensemble sampler on targets whose moments are known exactly: correlated Gaussians in 2
//! and 5 dimensions and the Rosenbrock "banana" of Goodman & Weare; split R̂ on a converged run
//! and on walkers stuck in two modes; a tiny budget that must be reported as not converged.

use nalgebra::{DMatrix, DVector};
use subfric_posterior::convergence::Verdict;
use subfric_posterior::ensemble::{run_ensemble, LogDensity, Run, RunOptions, SamplerError, Stop};

/// A Gaussian with mean `mean` and covariance `cov`.
struct Gaussian {
    mean: Vec<f64>,
    /// Inverse of the lower Cholesky factor of the covariance.
    l_inv: DMatrix<f64>,
}

impl Gaussian {
    fn new(mean: Vec<f64>, cov: &[Vec<f64>]) -> Gaussian {
        let n = mean.len();
        let c = DMatrix::from_fn(n, n, |i, j| cov[i][j]);
        let l = c.cholesky().expect("a positive definite covariance").l();
        let l_inv = l.try_inverse().expect("an invertible factor");
        Gaussian { mean, l_inv }
    }
}

impl LogDensity for Gaussian {
    fn dim(&self) -> usize {
        self.mean.len()
    }
    fn log_density(&self, x: &[f64]) -> f64 {
        let d = DVector::from_iterator(x.len(), x.iter().zip(&self.mean).map(|(a, b)| a - b));
        -0.5 * (&self.l_inv * d).norm_squared()
    }
}

/// Goodman & Weare's Rosenbrock density: exp(−(100 (x₂ − x₁²)² + (1 − x₁)²)/20). x₁ is
/// N(1, 10) and x₂ | x₁ is N(x₁², 0.1), so E x₁ = 1, Var x₁ = 10, E x₂ = 11, Var x₂ = 240.1.
struct Banana;

impl LogDensity for Banana {
    fn dim(&self) -> usize {
        2
    }
    fn log_density(&self, x: &[f64]) -> f64 {
        -(100.0 * (x[1] - x[0] * x[0]).powi(2) + (1.0 - x[0]).powi(2)) / 20.0
    }
}

/// Two well separated Gaussian modes at ±20 on the first axis.
struct TwoModes;

impl LogDensity for TwoModes {
    fn dim(&self) -> usize {
        2
    }
    fn log_density(&self, x: &[f64]) -> f64 {
        let a = -0.5 * ((x[0] - 20.0).powi(2) + x[1] * x[1]);
        let b = -0.5 * ((x[0] + 20.0).powi(2) + x[1] * x[1]);
        a.max(b) + (1.0 + (-(a - b).abs()).exp()).ln()
    }
}

/// `walkers` start points in a small ball around `centre`, from a deterministic generator (in
/// general position: an ensemble started on a lower-dimensional set would stay on it).
fn ball(centre: &[f64], scale: f64, walkers: usize) -> Vec<Vec<f64>> {
    let mut state = 0x2545_F491_4F6C_DD1Du64 ^ (walkers as u64);
    let mut uniform = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    (0..walkers)
        .map(|_| centre.iter().map(|c| c + scale * uniform()).collect())
        .collect()
}

/// Mean, SD of quantity `q` and correlation of quantities `a`, `b` over the kept samples.
struct Moments {
    mean: Vec<f64>,
    sd: Vec<f64>,
    samples: usize,
}

fn moments(run: &Run) -> Moments {
    let burn = run.convergence.burn_in;
    let d = run.quantity_names.len();
    let mut sum = vec![0.0; d];
    let mut sum2 = vec![0.0; d];
    let mut n = 0;
    for s in burn..run.steps {
        for w in 0..run.walkers {
            let q = run.quantities_at(s, w);
            for k in 0..d {
                sum[k] += q[k];
                sum2[k] += q[k] * q[k];
            }
            n += 1;
        }
    }
    let mean: Vec<f64> = sum.iter().map(|s| s / n as f64).collect();
    let sd = sum2
        .iter()
        .zip(&mean)
        .map(|(s2, m)| (s2 / n as f64 - m * m).sqrt())
        .collect();
    Moments {
        mean,
        sd,
        samples: n,
    }
}

fn correlation(run: &Run, a: usize, b: usize, m: &Moments) -> f64 {
    let burn = run.convergence.burn_in;
    let mut c = 0.0;
    for s in burn..run.steps {
        for w in 0..run.walkers {
            let q = run.quantities_at(s, w);
            c += (q[a] - m.mean[a]) * (q[b] - m.mean[b]);
        }
    }
    c / m.samples as f64 / (m.sd[a] * m.sd[b])
}

/// Monte-Carlo standard error of the mean of quantity `k`: sd √(τ / samples).
fn mc_error(run: &Run, m: &Moments, k: usize) -> f64 {
    m.sd[k] * (run.convergence.quantities[k].tau / m.samples as f64).sqrt()
}

fn no_progress(_: usize, _: usize) {}

fn check_gaussian(mean: Vec<f64>, cov: Vec<Vec<f64>>, seed: u64) {
    let target = Gaussian::new(mean.clone(), &cov);
    let d = mean.len();
    let opts = RunOptions {
        seed,
        max_evals: 400_000,
        ..RunOptions::default()
    };
    let start = ball(&mean, 0.01, 32);
    let run = run_ensemble(&target, start, &opts, &no_progress).unwrap();
    assert_eq!(
        run.stopped,
        Stop::Converged,
        "{}",
        run.convergence.message()
    );
    let m = moments(&run);
    for k in 0..d {
        let sd = cov[k][k].sqrt();
        let err = mc_error(&run, &m, k);
        assert!(
            (m.mean[k] - mean[k]).abs() < 4.0 * err,
            "mean {k}: {} vs {} (MC error {err})",
            m.mean[k],
            mean[k]
        );
        // ≥ 1000 effective samples: the SD is within a few percent.
        assert!(
            (m.sd[k] / sd - 1.0).abs() < 0.1,
            "sd {k}: {} vs {sd}",
            m.sd[k]
        );
        assert!(run.convergence.quantities[k].rhat <= 1.01);
    }
    for a in 0..d {
        for b in 0..a {
            let want = cov[a][b] / (cov[a][a] * cov[b][b]).sqrt();
            let got = correlation(&run, a, b, &m);
            assert!(
                (got - want).abs() < 0.06,
                "correlation {a},{b}: {got} vs {want}"
            );
        }
    }
    // The stretch move accepts a fair share on a Gaussian (about 0.55 in 5-D, 0.7 in 2-D).
    assert!(
        (0.2..0.85).contains(&run.acceptance()),
        "{}",
        run.acceptance()
    );
}

#[test]
fn recovers_a_correlated_2d_gaussian() {
    // Scales four decades apart and a correlation of 0.95: the affine invariance at work.
    let cov = vec![vec![1.0, 0.95 * 100.0], vec![0.95 * 100.0, 1e4]];
    check_gaussian(vec![3.0, -200.0], cov, 11);
}

#[test]
fn recovers_a_correlated_5d_gaussian() {
    let sd = [1.0, 0.01, 100.0, 5.0, 0.3];
    let corr = [
        [1.0, 0.6, -0.3, 0.0, 0.2],
        [0.6, 1.0, -0.5, 0.1, 0.0],
        [-0.3, -0.5, 1.0, 0.3, -0.2],
        [0.0, 0.1, 0.3, 1.0, 0.6],
        [0.2, 0.0, -0.2, 0.6, 1.0],
    ];
    let cov: Vec<Vec<f64>> = (0..5)
        .map(|i| (0..5).map(|j| corr[i][j] * sd[i] * sd[j]).collect())
        .collect();
    check_gaussian(vec![0.5, 0.02, 1000.0, -3.0, 0.0], cov, 12);
}

#[test]
fn samples_the_rosenbrock_banana_with_its_known_moments() {
    let opts = RunOptions {
        seed: 5,
        max_evals: 64 * 12_000,
        stop_when_converged: false,
        ..RunOptions::default()
    };
    let run = run_ensemble(&Banana, ball(&[1.0, 1.0], 0.1, 64), &opts, &no_progress).unwrap();
    let m = moments(&run);
    let (e1, e2) = (mc_error(&run, &m, 0), mc_error(&run, &m, 1));
    assert!(
        (m.mean[0] - 1.0).abs() < 4.0 * e1,
        "E x1 {} ± {e1}",
        m.mean[0]
    );
    assert!(
        (m.mean[1] - 11.0).abs() < 4.0 * e2,
        "E x2 {} ± {e2}",
        m.mean[1]
    );
    // Variances: x₁'s is a light-tailed quantity, x₂'s rests on E x₁⁴ (heavier tails).
    let v1 = m.sd[0].powi(2);
    let v2 = m.sd[1].powi(2);
    assert!((v1 / 10.0 - 1.0).abs() < 0.12, "Var x1 {v1}");
    assert!((v2 / 240.1 - 1.0).abs() < 0.3, "Var x2 {v2}");
    assert!(run.convergence.quantities[0].rhat < 1.02);
}

#[test]
fn the_run_is_deterministic_for_a_seed() {
    let target = Gaussian::new(vec![0.0, 0.0], &[vec![1.0, 0.5], vec![0.5, 2.0]]);
    let opts = RunOptions {
        seed: 3,
        max_evals: 8 * 201,
        stop_when_converged: false,
        ..RunOptions::default()
    };
    let a = run_ensemble(&target, ball(&[0.0, 0.0], 0.1, 8), &opts, &no_progress).unwrap();
    let b = run_ensemble(&target, ball(&[0.0, 0.0], 0.1, 8), &opts, &no_progress).unwrap();
    assert_eq!(a.coords, b.coords);
    assert_eq!(a.steps, 200);
    let other = RunOptions { seed: 4, ..opts };
    let c = run_ensemble(&target, ball(&[0.0, 0.0], 0.1, 8), &other, &no_progress).unwrap();
    assert_ne!(a.coords, c.coords);
}

#[test]
fn every_sample_carries_the_log_density_it_was_accepted_with() {
    // The sampler keeps each walker's density to itself; the run records it beside the sample
    // (ArviZ's `lp`). A rejected move leaves the walker where it was: then the density is the
    // previous step's, which must be the density of the same point.
    let target = Banana;
    let opts = RunOptions {
        seed: 9,
        max_evals: 16 * 301,
        stop_when_converged: false,
        ..RunOptions::default()
    };
    let run = run_ensemble(&target, ball(&[1.0, 1.0], 0.1, 16), &opts, &no_progress).unwrap();
    assert_eq!(run.log_density.len(), run.steps * run.walkers);
    let mut stayed = 0;
    for s in 0..run.steps {
        for w in 0..run.walkers {
            let x = run.coords_at(s, w);
            let lp = run.log_density_at(s, w);
            assert_eq!(lp, target.log_density(x), "step {s} walker {w} at {x:?}");
            stayed += usize::from(s > 0 && run.coords_at(s - 1, w) == x);
        }
    }
    // Both paths were walked: moves accepted and moves rejected.
    assert!(
        stayed > 0 && stayed < (run.steps - 1) * run.walkers,
        "{stayed}"
    );
}

#[test]
fn walkers_stuck_in_two_modes_give_a_large_split_rhat_and_no_convergence() {
    let mut start = ball(&[20.0, 0.0], 0.5, 16);
    start.extend(ball(&[-20.0, 0.0], 0.5, 16));
    let opts = RunOptions {
        seed: 9,
        max_evals: 32 * 3000,
        ..RunOptions::default()
    };
    let run = run_ensemble(&TwoModes, start, &opts, &no_progress).unwrap();
    let r = run.convergence.quantities[0].rhat;
    assert!(r > 2.0, "R-hat {r}");
    assert_eq!(run.stopped, Stop::Budget);
    assert!(!run.convergence.converged());
    assert!(run.convergence.message().contains("R-hat"));
    // The second coordinate mixes within either mode: its R̂ is near 1.
    assert!(run.convergence.quantities[1].rhat < 1.05);
}

#[test]
fn a_tiny_budget_is_reported_as_not_converged_with_the_steps_still_needed() {
    let target = Gaussian::new(
        vec![0.0; 3],
        &[
            vec![1.0, 0.9, 0.0],
            vec![0.9, 1.0, 0.0],
            vec![0.0, 0.0, 1.0],
        ],
    );
    let opts = RunOptions {
        seed: 2,
        max_evals: 16 * 61,
        ..RunOptions::default()
    };
    let calls = std::sync::atomic::AtomicUsize::new(0);
    let progress = |done: usize, total: usize| {
        assert!(done <= total);
        calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    };
    let run = run_ensemble(&target, ball(&[0.0; 3], 0.01, 16), &opts, &progress).unwrap();
    assert_eq!(run.steps, 60);
    assert_eq!(run.evaluations, 16 * 61);
    assert_eq!(run.stopped, Stop::Budget);
    assert!(calls.load(std::sync::atomic::Ordering::Relaxed) >= 60);
    match run.convergence.verdict {
        Verdict::NotConverged { more_steps, .. } => assert!(more_steps > 0),
        Verdict::Converged => panic!("60 steps cannot give 1000 effective samples"),
    }
    let text = run.convergence.message();
    assert!(text.contains("NOT converged after 60 steps"), "{text}");
    assert!(text.contains("more model runs"), "{text}");
}

#[test]
fn impossible_ensembles_are_errors_not_panics() {
    let target = Gaussian::new(
        vec![0.0; 3],
        &[
            vec![1.0, 0.0, 0.0],
            vec![0.0, 1.0, 0.0],
            vec![0.0, 0.0, 1.0],
        ],
    );
    let opts = RunOptions::default();
    let e = run_ensemble(&target, ball(&[0.0; 3], 0.1, 7), &opts, &no_progress).unwrap_err();
    assert_eq!(e, SamplerError::OddWalkers { walkers: 7 });
    let e = run_ensemble(&target, ball(&[0.0; 3], 0.1, 4), &opts, &no_progress).unwrap_err();
    assert_eq!(e, SamplerError::TooFewWalkers { walkers: 4, dim: 3 });
    let mut bad = ball(&[0.0; 3], 0.1, 6);
    bad[2][1] = f64::NAN;
    let e = run_ensemble(&target, bad, &opts, &no_progress).unwrap_err();
    assert!(e.to_string().contains("walker 2"), "{e}");
    let tiny = RunOptions {
        max_evals: 10,
        ..RunOptions::default()
    };
    let e = run_ensemble(&target, ball(&[0.0; 3], 0.1, 6), &tiny, &no_progress).unwrap_err();
    assert!(e.to_string().contains("budget of 10"), "{e}");
}
