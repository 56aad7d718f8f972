//! Posterior predictive draws and bands: for each test, the model curve of a thinned set of
//! posterior draws (optionally with the measurement noise added), and its 2.5 / 50 / 97.5 % per
//! row.

use crate::summary::{quantile, Posterior};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;
use subfric_reading::FitTest;

/// How the bands are drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BandOptions {
    /// Posterior draws (spread evenly over the thinned chain).
    pub draws: usize,
    /// Add the measurement noise (each test's noise SD times √max(1, reduced χ²)) to every
    /// draw: the band then says where new measurements would fall, not only the model curve.
    pub noise: bool,
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for BandOptions {
    fn default() -> Self {
        BandOptions {
            draws: 200,
            noise: false,
            seed: 1,
        }
    }
}

/// The band of one test, per row of the test's measured column (shear [kPa] under slip
/// control, slip [mm] under traction control).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TestBand {
    /// Test name.
    pub name: String,
    /// 2.5 % per row.
    pub lo: Vec<f64>,
    /// Median per row.
    pub median: Vec<f64>,
    /// 97.5 % per row.
    pub hi: Vec<f64>,
    /// Draws that could be simulated.
    pub draws: usize,
    /// Draws the model could not simulate on this test (left out of the band).
    pub failed_draws: usize,
    /// Whether the noise was added.
    pub with_noise: bool,
}

/// The posterior predictive draws of every test: the model curve of each draw (with the
/// measurement noise when asked), what the bands summarise and what ArviZ's
/// `posterior_predictive` group holds.
#[derive(Clone, Debug, PartialEq)]
pub struct PredictiveDraws {
    /// The thinned chain's sample of each draw (spread evenly over the chain).
    pub samples: Vec<usize>,
    /// `curves[d][t]`: draw `d`'s prediction of test `t`'s measured column, row by row; `None`
    /// where the model could not simulate the test with that draw's parameters.
    pub curves: Vec<Vec<Option<Vec<f64>>>>,
    /// Whether the noise was added.
    pub with_noise: bool,
}

impl Posterior {
    /// The posterior predictive band of every test (the tests need not be the fitted ones:
    /// give the full records to draw bands over every row). Empty bands (all NaN) for a test no
    /// draw could simulate.
    pub fn predictive_bands(&self, tests: &[FitTest], opts: &BandOptions) -> Vec<TestBand> {
        let draws = self.predictive_draws(tests, opts);
        tests
            .iter()
            .enumerate()
            .map(|(ti, t)| {
                let ok: Vec<&Vec<f64>> =
                    draws.curves.iter().filter_map(|c| c[ti].as_ref()).collect();
                let rows = t.len();
                let mut band = TestBand {
                    name: t.name.clone(),
                    lo: vec![f64::NAN; rows],
                    median: vec![f64::NAN; rows],
                    hi: vec![f64::NAN; rows],
                    draws: ok.len(),
                    failed_draws: draws.samples.len() - ok.len(),
                    with_noise: opts.noise,
                };
                let mut column = Vec::with_capacity(ok.len());
                for r in 0..rows {
                    column.clear();
                    column.extend(ok.iter().map(|c| c[r]));
                    column.sort_by(f64::total_cmp);
                    band.lo[r] = quantile(&column, 0.025);
                    band.median[r] = quantile(&column, 0.5);
                    band.hi[r] = quantile(&column, 0.975);
                }
                band
            })
            .collect()
    }

    /// The model curve of every test for `opts.draws` samples spread evenly over the thinned
    /// chain, each with the measurement noise added when `opts.noise` (each test's noise SD
    /// times √max(1, reduced χ²), per row as the row is weighted). Deterministic for a seed.
    pub fn predictive_draws(&self, tests: &[FitTest], opts: &BandOptions) -> PredictiveDraws {
        let n = self.chain.len();
        let draws = opts.draws.min(n);
        let samples: Vec<usize> = (0..draws)
            .map(|i| ((i as f64 + 0.5) * n as f64 / draws as f64) as usize)
            .collect();
        let s = self.noise.variance_scale.sqrt();
        let curves = samples
            .par_iter()
            .enumerate()
            .map(|(d, &i)| {
                let model = self.model_of(i);
                let mut rng = ChaCha8Rng::seed_from_u64(
                    opts.seed
                        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                        .wrapping_add(d as u64),
                );
                tests
                    .iter()
                    .map(|t| {
                        let mut p = t.predict(&model).ok()?;
                        if p.iter().any(|v| !v.is_finite()) {
                            return None;
                        }
                        if opts.noise {
                            for (r, v) in p.iter_mut().enumerate() {
                                let w = (t.weight * t.weight_of(r)).max(f64::MIN_POSITIVE);
                                *v += s * t.noise_sd / w.sqrt() * normal(&mut rng);
                            }
                        }
                        Some(p)
                    })
                    .collect()
            })
            .collect();
        PredictiveDraws {
            samples,
            curves,
            with_noise: opts.noise,
        }
    }
}

/// A standard normal draw (Box–Muller).
pub(crate) fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.random::<f64>().max(1e-300);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}
