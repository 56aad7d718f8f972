//! The posterior of the real model on small generated problems: credible intervals that hold
//! the truth and agree with the linearised errors, priors carried correctly through the
//! combined chart, failed runs as zero likelihood, predictive bands that cover new data at
//! their nominal rate, and the outputs (chain CSV, figures).

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use subfric_fit::{calibrate, FitOptions, Param, Space};
use subfric_model::{simulate, Control, Model, Params, Protocol};
use subfric_posterior::ensemble::{run_ensemble, LogDensity, RunOptions};
use subfric_posterior::target::Target;
use subfric_posterior::{
    figures, sample, BandOptions, Posterior, PosteriorError, PosteriorOptions, Prior, Priors,
    Verdict,
};
use subfric_reading::FitTest;

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.random::<f64>().max(1e-300);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// A monotonic slip-controlled test (3 mm at 0.01 mm/s, 100 kPa) from `truth`, with white
/// noise of `sd` kPa; also returns the noise-free curve.
fn monotonic(truth: &Model, sd: f64, seed: u64) -> (FitTest, Vec<f64>) {
    let time: Vec<f64> = (0..=300).map(f64::from).collect();
    let slip: Vec<f64> = time.iter().map(|t| 0.01 * t).collect();
    let normal_kpa = vec![100.0; time.len()];
    let proto = Protocol {
        control: Control::Slip,
        time: &time,
        imposed: &slip,
        normal: &normal_kpa,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    let clean = simulate(truth, &proto).unwrap().shear;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let noisy = clean.iter().map(|v| v + sd * normal(&mut rng)).collect();
    (
        FitTest::new("mono", Control::Slip, time, slip, noisy, normal_kpa),
        clean,
    )
}

/// The problem of the tests below: μ_s and ũ free, from a start away from the truth.
struct Fixture {
    truth: Model,
    tests: Vec<FitTest>,
    clean: Vec<f64>,
    space: Space,
    fit: subfric_fit::FitReport,
}

fn fixture() -> Fixture {
    let truth = Model::base(Params::sample()).unwrap();
    let (test, clean) = monotonic(&truth, 0.4, 7);
    let mut start = truth;
    start.params.mu_s = 0.6;
    start.params.u_tilde = 40.0;
    let space = Space::new(start, &[Param::MuS, Param::UTilde], &[]);
    let tests = vec![test];
    let opts = FitOptions {
        global_evaluations: 200,
        starts: 2,
        profiles: false,
        ..FitOptions::default()
    };
    let fit = calibrate(&tests, space.clone(), &opts, &|_| {}).unwrap();
    Fixture {
        truth,
        tests,
        clean,
        space,
        fit,
    }
}

impl Fixture {
    /// The posterior of the fixture's fit under the default priors.
    fn sampled(&self, opts: &PosteriorOptions) -> Posterior {
        sample(
            &self.tests,
            &self.space,
            &self.fit.model,
            &Priors::default(),
            opts,
            &|_, _| {},
        )
        .unwrap()
    }
}

fn options() -> PosteriorOptions {
    PosteriorOptions {
        walkers: 16,
        max_evals: 100_000,
        seed: 3,
        ..PosteriorOptions::default()
    }
}

#[test]
fn the_credible_intervals_hold_the_truth_and_match_the_linearised_errors() {
    let f = fixture();
    let post = f.sampled(&options());
    assert!(
        post.convergence.converged(),
        "{}",
        post.convergence.message()
    );
    assert_eq!(post.failed_runs, 0);
    for (key, truth) in [
        ("mu_s", f.truth.params.mu_s),
        ("u_tilde", f.truth.params.u_tilde),
    ] {
        let p = post.param(key).unwrap();
        let lsq = f.fit.param(key).unwrap();
        assert!(
            p.covers(truth),
            "{key}: truth {truth} outside [{}, {}]",
            p.lo,
            p.hi
        );
        // A nearly linear problem with flat priors: the posterior is the likelihood, whose
        // width is the linearised standard error and whose centre is the optimum.
        let se = lsq.std_error.unwrap();
        assert!(
            (p.sd / se - 1.0).abs() < 0.15,
            "{key}: sd {} vs se {se}",
            p.sd
        );
        assert!(
            (p.median - lsq.value).abs() < 0.3 * se,
            "{key}: median {} vs {}",
            p.median,
            lsq.value
        );
        // The equal-tailed interval is about ±1.96 sd.
        let half = 0.5 * (p.hi - p.lo);
        assert!(
            (half / (1.96 * p.sd) - 1.0).abs() < 0.1,
            "{key}: half-width {half}"
        );
    }
    // μ_s and ũ of a monotonic test trade against each other a little: the correlation the
    // linearisation reports, within Monte-Carlo error.
    let want = f.fit.correlation[0][1];
    assert!(
        (post.correlation[0][1] - want).abs() < 0.1,
        "{} vs {want}",
        post.correlation[0][1]
    );
}

#[test]
fn the_same_seed_gives_the_same_posterior() {
    let f = fixture();
    let opts = PosteriorOptions {
        max_evals: 16 * 301,
        stop_when_converged: false,
        ..options()
    };
    let a = f.sampled(&opts);
    let b = f.sampled(&opts);
    assert_eq!(a.chain.values, b.chain.values);
    assert_eq!(a.summary, b.summary);
}

#[test]
fn a_tiny_budget_on_the_real_model_is_reported_as_not_converged() {
    let f = fixture();
    let opts = PosteriorOptions {
        max_evals: 16 * 41,
        ..options()
    };
    let post = f.sampled(&opts);
    assert_eq!(post.convergence.steps, 40);
    match post.convergence.verdict {
        Verdict::NotConverged {
            more_steps,
            more_evaluations,
        } => {
            assert!(more_steps > 0 && more_evaluations == 16 * more_steps);
        }
        Verdict::Converged => panic!("40 steps cannot converge"),
    }
    assert!(
        post.table().contains("NOT converged after 40 steps"),
        "{}",
        post.table()
    );
}

#[test]
fn the_noisy_predictive_band_covers_the_measurements_at_its_nominal_rate() {
    let f = fixture();
    let post = f.sampled(&options());
    let noisy = post.predictive_bands(
        &f.tests,
        &BandOptions {
            noise: true,
            ..BandOptions::default()
        },
    );
    let t = &f.tests[0];
    let b = &noisy[0];
    assert_eq!(b.draws, 200);
    assert_eq!(b.failed_draws, 0);
    let inside = (0..t.len())
        .filter(|&i| b.lo[i] <= t.measured[i] && t.measured[i] <= b.hi[i])
        .count() as f64
        / t.len() as f64;
    assert!(
        (0.88..=0.995).contains(&inside),
        "{inside} of the measured rows inside"
    );
    // The band of the model curve alone is narrower and holds the noise-free curve at most rows.
    let curve = &post.predictive_bands(&f.tests, &BandOptions::default())[0];
    let width = |b: &subfric_posterior::TestBand| -> f64 {
        (0..t.len()).map(|i| b.hi[i] - b.lo[i]).sum::<f64>()
    };
    assert!(width(curve) < 0.5 * width(b));
    let holds = (1..t.len())
        .filter(|&i| curve.lo[i] <= f.clean[i] && f.clean[i] <= curve.hi[i])
        .count() as f64
        / (t.len() - 1) as f64;
    assert!(holds > 0.8, "{holds} of the rows hold the noise-free curve");
}

#[test]
fn the_predictive_draws_are_the_models_of_their_samples_with_the_noise_asked_for() {
    let f = fixture();
    let post = f.sampled(&options());
    let opts = BandOptions {
        draws: 40,
        ..BandOptions::default()
    };
    let clean = post.predictive_draws(&f.tests, &opts);
    assert_eq!(clean.samples.len(), 40);
    assert!(clean.samples.windows(2).all(|w| w[0] < w[1]));
    assert!(*clean.samples.last().unwrap() < post.chain.len());
    // Each draw is its sample's model curve, and every sample's density is on the chain.
    for (d, &i) in clean.samples.iter().enumerate() {
        let expected = f.tests[0].predict(&post.model_of(i)).unwrap();
        assert_eq!(
            clean.curves[d][0].as_deref(),
            Some(&expected[..]),
            "draw {d}"
        );
        assert!(post.chain.log_density[i].is_finite());
    }
    assert_eq!(post.chain.log_density.len(), post.chain.len());
    // With the noise: the same curves plus deviations of the test's noise SD (the fit's
    // variance scale, here near one) — no bias, and neither the curve nor a noise ten times off.
    let noisy = post.predictive_draws(
        &f.tests,
        &BandOptions {
            noise: true,
            ..opts
        },
    );
    let t = &f.tests[0];
    let dev: Vec<f64> = (0..40)
        .flat_map(|d| {
            let (a, b) = (
                noisy.curves[d][0].as_ref().unwrap(),
                clean.curves[d][0].as_ref().unwrap(),
            );
            (0..t.len()).map(move |r| a[r] - b[r])
        })
        .collect();
    let n = dev.len() as f64;
    let mean = dev.iter().sum::<f64>() / n;
    let sd = (dev.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
    let expected_sd = post.noise.variance_scale.sqrt() * t.noise_sd;
    assert!(mean.abs() < 4.0 * expected_sd / n.sqrt(), "mean {mean}");
    assert!(
        (sd / expected_sd - 1.0).abs() < 0.1,
        "sd {sd} against {expected_sd}"
    );
}

#[test]
fn the_chain_csv_has_a_header_and_one_line_per_thinned_sample() {
    let f = fixture();
    let post = f.sampled(&options());
    let mut out = Vec::new();
    post.write_chain_csv(&mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("step,walker,mu_s,u_tilde"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), post.chain.len());
    assert!(rows.len() >= 16 * 20, "{} samples", rows.len());
    assert!(rows.iter().all(|r| r.len() == 4 && r[1] < 16.0));
    assert!(rows.iter().all(|r| r[0] >= post.convergence.burn_in as f64));
    // Written with full precision: the values read back are the chain's.
    assert_eq!(rows[5][2], post.chain.values[5][0]);
    // The values for fit.json: everything but the chain.
    let json = serde_json::to_value(&post).unwrap();
    assert_eq!(json["summary"][1]["name"], "u_tilde");
    assert!(
        json["summary"][0]["hi"].as_f64().unwrap() > json["summary"][0]["lo"].as_f64().unwrap()
    );
    assert_eq!(json["convergence"]["verdict"]["status"], "converged");
    assert!(
        json["convergence"]["quantities"][0]["rhat"]
            .as_f64()
            .unwrap()
            <= 1.01
    );
    assert!(json.get("chain").is_none() && json.get("space").is_none());
    // The figures render.
    let dir = tempfile::tempdir().unwrap();
    let corner = dir.path().join("corner.png");
    subfric_plot::write_figure(
        &figures::corner_figure(
            &post,
            "test",
            Some(&[f.truth.params.mu_s, f.truth.params.u_tilde]),
        ),
        &corner,
    )
    .unwrap();
    let band = &post.predictive_bands(&f.tests, &BandOptions::default())[0];
    let overlay = dir.path().join("band.png");
    subfric_plot::write_figure(
        &figures::band_figure(&f.tests[0], band, Some(&f.fit.model), "test"),
        &overlay,
    )
    .unwrap();
    for p in [corner, overlay] {
        let check = subfric_plot::inspect_png(&p).unwrap();
        assert!(check.inked_fraction > 0.02, "{}: {check:?}", p.display());
    }
}

#[test]
fn priors_in_natural_units_survive_the_combined_chart() {
    // μ_k, κ and ξ all free: the optimiser charts them as μ_ss/μ_s, κ + ξ/v and the recovery
    // share ψ. Sampled with the prior alone, the natural parameters must come out with the
    // stated priors: that holds only if the chart's Jacobian is right.
    let base = Model::base(Params::sample()).unwrap();
    let free = [Param::MuS, Param::MuK, Param::Kappa, Param::Xi];
    let space = Space::with_rate(base, &free, &[], 0.01);
    assert_eq!(space.v_ref, 0.01, "the combined chart is in use");
    let priors = Priors::default()
        .with(
            Param::MuS,
            Prior::Normal {
                mean: 0.6,
                sd: 0.03,
            },
        )
        .unwrap()
        .with(Param::MuK, Prior::Uniform { lo: 0.2, hi: 0.4 })
        .unwrap()
        .with(
            Param::Kappa,
            Prior::LogNormal {
                mu: 2f64.ln(),
                sigma: 0.3,
            },
        )
        .unwrap()
        .with(
            Param::Xi,
            Prior::LogNormal {
                mu: 0.002f64.ln(),
                sigma: 0.3,
            },
        )
        .unwrap();
    let resolved = priors.resolve(&space).unwrap();
    let target = Target::prior_only(&space, resolved);
    let mut centre = base;
    centre.params.mu_s = 0.6;
    centre.params.mu_k = 0.3;
    centre.params.kappa = 2.0;
    centre.params.xi = 0.002;
    let x0 = space.point_of(&centre);
    assert!(target.log_density(&x0).is_finite());
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let start: Vec<Vec<f64>> = (0..32)
        .map(|_| x0.iter().map(|c| c + 0.01 * normal(&mut rng)).collect())
        .collect();
    let opts = RunOptions {
        seed: 4,
        max_evals: 32 * 8001,
        stop_when_converged: false,
        ..RunOptions::default()
    };
    let run = run_ensemble(&target, start, &opts, &|_, _| {}).unwrap();
    assert!(run.convergence.converged(), "{}", run.convergence.message());
    // Quantities: ln μ_s, μ_k, ln κ, ln ξ (the log-scale parameters on their logarithm).
    let burn = run.convergence.burn_in;
    let stats = |q: usize, f: &dyn Fn(f64) -> f64| {
        let v: Vec<f64> = (burn..run.steps)
            .flat_map(|s| (0..run.walkers).map(move |w| (s, w)))
            .map(|(s, w)| f(run.quantities_at(s, w)[q]))
            .collect();
        let n = v.len() as f64;
        let m = v.iter().sum::<f64>() / n;
        (
            m,
            (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n).sqrt(),
        )
    };
    let id = |v: f64| v;
    let (m, s) = stats(0, &|v: f64| v.exp());
    assert!(
        (m - 0.6).abs() < 0.003 && (s / 0.03 - 1.0).abs() < 0.08,
        "mu_s {m} ± {s}"
    );
    let (m, s) = stats(1, &id);
    assert!(
        (m - 0.3).abs() < 0.006 && (s / (0.2 / 12f64.sqrt()) - 1.0).abs() < 0.08,
        "mu_k {m} ± {s}"
    );
    let (m, s) = stats(2, &id);
    assert!(
        (m - 2f64.ln()).abs() < 0.03 && (s / 0.3 - 1.0).abs() < 0.08,
        "ln kappa {m} ± {s}"
    );
    let (m, s) = stats(3, &id);
    assert!(
        (m - 0.002f64.ln()).abs() < 0.03 && (s / 0.3 - 1.0).abs() < 0.08,
        "ln xi {m} ± {s}"
    );
}

#[test]
fn failed_model_runs_are_zero_likelihood_never_nan() {
    // Traction control up to 60 kPa at 100 kPa normal stress: any μ_s below 0.6 runs away.
    let time: Vec<f64> = (0..=100).map(f64::from).collect();
    let shear: Vec<f64> = time.iter().map(|t| 0.6 * t).collect();
    let slip: Vec<f64> = time.iter().map(|t| 1e-4 * t).collect();
    let normal_kpa = vec![100.0; time.len()];
    let test = FitTest::new("creep", Control::Shear, time, shear, slip, normal_kpa);
    let base = Model::base(Params::sample()).unwrap();
    let space = Space::new(base, &[Param::MuS], &[]);
    let resolved = Priors::default().resolve(&space).unwrap();
    let noise = subfric_posterior::NoiseScale {
        reduced_chi2: 1.0,
        variance_scale: 1.0,
        correlation_time: 1.0,
        model: subfric_posterior::ResidualModel::Independent,
    };
    let tests = [test];
    let target = Target::new(&tests, &space, resolved, &noise);
    let mut m = base;
    m.params.mu_s = 0.3;
    m.params.mu_k = 0.2;
    assert_eq!(target.log_density(&space.point_of(&m)), f64::NEG_INFINITY);
    assert_eq!(target.failed_runs(), 1);
    m.params.mu_s = 0.9;
    assert!(target.log_density(&space.point_of(&m)).is_finite());
    // Outside the box: −∞ without a model run.
    let runs = target.model_runs();
    assert_eq!(target.log_density(&[10.0]), f64::NEG_INFINITY);
    assert_eq!(target.model_runs(), runs);
}

#[test]
fn an_optimum_outside_the_prior_is_refused_with_the_reason() {
    let f = fixture();
    let priors = Priors::default()
        .with(Param::MuS, Prior::Uniform { lo: 0.5, hi: 0.6 })
        .unwrap();
    let e = sample(
        &f.tests,
        &f.space,
        &f.fit.model,
        &priors,
        &options(),
        &|_, _| {},
    )
    .unwrap_err();
    assert!(matches!(e, PosteriorError::Start(_)));
    let text = e.to_string();
    assert!(
        text.contains("mu_s = 4.5") && text.contains("uniform(0.5, 0.6)"),
        "{text}"
    );
    // Convergence judged on a parameter that is not free.
    let opts = PosteriorOptions {
        converge_on: Some(vec![Param::Kappa]),
        ..options()
    };
    let e = sample(
        &f.tests,
        &f.space,
        &f.fit.model,
        &Priors::default(),
        &opts,
        &|_, _| {},
    )
    .unwrap_err();
    assert!(e.to_string().contains("kappa, which is not free"), "{e}");
}
