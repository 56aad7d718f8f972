//! What the data of a set can tell: how many rates, normal stresses, holds and reversals it
//! has, and the signature of its velocity steps read off the curves (the jump right after a step
//! gives the direct effect a, the decay length D_c, the new steady level a − b).

use crate::{typical_rate, FitTest, PreparedTest};
use serde::Serialize;
use subfric_model::Control;

/// Velocity-step signature, per e-fold of rate.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StepSignature {
    /// Friction jump right after the step / ln(v₂/v₁) (the direct effect a, a lower bound
    /// when the machine is compliant).
    pub direct: f64,
    /// Change of steady friction / ln(v₂/v₁) (a − b).
    pub steady: f64,
    /// Slip from the peak until the excess over the new steady level has fallen by e [mm].
    pub decay_mm: f64,
    /// Steps measured.
    pub steps: usize,
}

/// What the set's data contain.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DataFeatures {
    /// Typical slip rate [mm/s].
    pub v_ref: f64,
    /// Reference normal stress: the geometric mean of the tests' [kPa].
    pub p_ref: f64,
    /// Distinct normal-stress levels (within 5 %).
    pub pressure_levels: usize,
    /// Distinct sliding rates (a factor 1.5 apart).
    pub sliding_rates: usize,
    /// The slowest and the fastest rate the slip-controlled tests slide at over a stretch of
    /// steady driving [mm/s] (holds and the turnarounds of reversals left out), when any.
    pub sliding_rate_range: Option<(f64, f64)>,
    /// The white noise of one reading of the stress ratio: the median over the tests of each
    /// test's noise over its mean normal stress.
    pub friction_noise_sd: f64,
    /// Tests under traction control.
    pub traction_tests: usize,
    /// Holds over all tests.
    pub holds: usize,
    /// Reversals over all tests.
    pub reversals: usize,
    /// Median imposed travel of a test [mm].
    pub slip_span_mm: f64,
    /// Longest test duration [s].
    pub duration_s: f64,
    /// How much more the record scatters over its steady stretches than its white noise shows
    /// (noise correlated in time, which a model's residual shows in full but the noise estimate
    /// misses; [`crate::noise::slow_noise_ratio`], median over the slip-controlled
    /// tests, within [1, [`MAX_UNSEEN_NOISE`]]; once the base model is fitted, the larger of
    /// that and the same measure on its residual over longer windows, [`unseen_noise_about`]):
    /// the misfit below which the gap is noise grows by this factor.
    pub unseen_noise: f64,
    /// Velocity-step signature.
    pub steps: StepSignature,
    /// First guesses from the per-event reading ([`crate::events`],
    /// [`crate::events::EventAnalysis::seeds`]), when it found them.
    pub seeds: EventSeeds,
}

/// First guesses of the effects' sizes read off the events one by one.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct EventSeeds {
    /// Rate and state (a, b, D_c [mm]) from the velocity steps fitted on their own.
    pub rate_and_state: Option<(f64, f64, f64)>,
    /// Δμ per decade of hold time.
    pub healing_per_decade: Option<f64>,
    /// Backward weakening d = 1 − |μ backward| / μ forward.
    pub backward_weakening: Option<f64>,
    /// Relative change of the tests' peak and residual stress ratios per e-fold of normal
    /// stress, where it is clear of zero.
    pub stress_trend: (Option<f64>, Option<f64>),
    /// The residual stress ratio's slope with slip past the peak [1/mm], where it is clear of
    /// zero.
    pub slip_slope_per_mm: Option<f64>,
    /// The slip from the start of a first loading to its peak, the median over the tests
    /// whose peak was read [mm].
    pub slip_to_peak_mm: Option<f64>,
}

// The features read values of the record itself: the upper median, as they always have.
use crate::stats::upper_median as median;

fn mean_normal(t: &FitTest) -> f64 {
    t.normal.iter().sum::<f64>() / t.normal.len().max(1) as f64
}

/// [`DataFeatures::friction_noise_sd`] of the slip-controlled tests among `tests`, whose mean
/// normal stresses are `normals` (NaN when none has a noise).
fn friction_noise_sd(tests: &[PreparedTest], normals: &[f64]) -> f64 {
    let mut sd: Vec<f64> = tests
        .iter()
        .zip(normals)
        .filter(|(p, _)| p.full.control == Control::Slip)
        .map(|(p, n)| p.full.noise_sd / n.abs())
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    median(&mut sd).unwrap_or(f64::NAN)
}

/// The smallest and the largest of the finite positive values of `v`, when any.
fn range_of_positive(v: &[f64]) -> Option<(f64, f64)> {
    v.iter()
        .copied()
        .filter(|x| x.is_finite() && *x > 0.0)
        .fold(None, |r, x| match r {
            None => Some((x, x)),
            Some((lo, hi)) => Some((f64::min(lo, x), f64::max(hi, x))),
        })
}

/// Distinct values among `v` (sorted groups whose neighbours are within `ratio`).
/// Ratio within which two normal stresses are one level (a test logged at 101 kPa beside one at
/// 100 kPa was run at the same stress).
pub const STRESS_LEVEL_RATIO: f64 = 1.05;

fn distinct(mut v: Vec<f64>, ratio: f64) -> usize {
    v.retain(|x| x.is_finite() && *x > 0.0);
    v.sort_by(f64::total_cmp);
    let mut count = 0;
    let mut last = f64::NEG_INFINITY;
    for x in v {
        if x > last * ratio {
            count += 1;
            last = x;
        }
    }
    count
}

/// Median of friction over rows `a..b` of a test (slip control: shear / normal).
fn friction_median(t: &FitTest, a: usize, b: usize) -> Option<f64> {
    let mut v: Vec<f64> = (a..b.min(t.len()))
        .map(|i| t.measured[i] / t.normal[i])
        .collect();
    median(&mut v)
}

/// The signature of one velocity step at row `c` from rate `v1` to `v2` in a test's full rows.
fn one_step(p: &PreparedTest, c: usize, v1: f64, v2: f64) -> Option<(f64, f64, f64)> {
    let t = &p.full;
    let seg = &p.segmentation;
    let ln = (v2 / v1).ln();
    if !ln.is_finite() || ln.abs() < 0.3 {
        return None;
    }
    let before = seg.levels.iter().find(|l| l.end == c + 1)?;
    let after = seg.levels.iter().find(|l| l.start == c + 1)?;
    let len_b = before.end - before.start;
    let len_a = after.end - after.start;
    if len_b < 10 || len_a < 10 {
        return None;
    }
    let mu_before = friction_median(t, before.end - len_b / 4, before.end)?;
    let mu_after = friction_median(t, after.end - len_a / 4, after.end)?;
    // The extreme of a 7-row running median over the first half of the new level.
    let half = after.start + len_a / 2;
    let sign = ln.signum();
    let mut best = (f64::NEG_INFINITY, after.start);
    for i in after.start..half.saturating_sub(7) {
        let m = friction_median(t, i, i + 7)?;
        if sign * m > best.0 {
            best = (sign * m, i + 3);
        }
    }
    let peak = sign * best.0;
    let excess = peak - mu_after;
    let target = mu_after + excess / std::f64::consts::E;
    let mut decay = None;
    for i in best.1..after.end.saturating_sub(7) {
        let m = friction_median(t, i, i + 7)?;
        if (m - target) * excess.signum() <= 0.0 {
            decay = Some((t.imposed[i] - t.imposed[best.1]).abs());
            break;
        }
    }
    Some((
        (peak - mu_before) / ln,
        (mu_after - mu_before) / ln,
        decay.unwrap_or((t.imposed[half] - t.imposed[after.start]).abs()),
    ))
}

fn step_signature(tests: &[PreparedTest]) -> StepSignature {
    let (mut direct, mut steady, mut decay) = (Vec::new(), Vec::new(), Vec::new());
    for p in tests {
        if p.full.control != Control::Slip {
            continue;
        }
        for (&c, (v1, v2)) in p
            .segmentation
            .rate_changes
            .iter()
            .zip(p.segmentation.step_rates())
        {
            if v1 * v2 <= 0.0 {
                continue;
            }
            if let Some((d, s, l)) = one_step(p, c, v1.abs(), v2.abs()) {
                direct.push(d);
                steady.push(s);
                decay.push(l);
            }
        }
    }
    StepSignature {
        steps: direct.len(),
        direct: median(&mut direct).unwrap_or(0.01),
        steady: median(&mut steady).unwrap_or(0.0),
        decay_mm: median(&mut decay).unwrap_or(0.05),
    }
}

/// Reads the features of a set's prepared tests.
pub fn data_features(tests: &[PreparedTest]) -> DataFeatures {
    let fits: Vec<FitTest> = tests.iter().map(|p| p.fit.clone()).collect();
    let normals: Vec<f64> = fits.iter().map(mean_normal).collect();
    let p_ref = (normals.iter().map(|p| p.ln()).sum::<f64>() / normals.len().max(1) as f64).exp();
    let mut rates = Vec::new();
    let mut spans = Vec::new();
    let (mut holds, mut reversals) = (0, 0);
    for p in tests {
        let seg = &p.segmentation;
        holds += seg.holds.len();
        reversals += seg.reversals.len();
        if p.full.control == Control::Slip {
            rates.extend(
                seg.levels
                    .iter()
                    .filter(|l| l.end - l.start >= 5)
                    .map(|l| l.rate.abs()),
            );
        }
        let travel: f64 = p.full.imposed.windows(2).map(|w| (w[1] - w[0]).abs()).sum();
        spans.push(match p.full.control {
            Control::Slip => travel,
            Control::Shear => (p.full.measured.last().unwrap_or(&0.0)
                - p.full.measured.first().unwrap_or(&0.0))
            .abs(),
        });
    }
    DataFeatures {
        seeds: EventSeeds::default(),
        v_ref: typical_rate(&fits),
        p_ref: if p_ref.is_finite() && p_ref > 0.0 {
            p_ref
        } else {
            100.0
        },
        friction_noise_sd: friction_noise_sd(tests, &normals),
        pressure_levels: distinct(normals, STRESS_LEVEL_RATIO),
        sliding_rate_range: range_of_positive(&rates),
        sliding_rates: distinct(rates, 1.5),
        traction_tests: tests
            .iter()
            .filter(|p| p.full.control == Control::Shear)
            .count(),
        holds,
        reversals,
        slip_span_mm: median(&mut spans).unwrap_or(1.0),
        unseen_noise: unseen_noise(tests),
        duration_s: fits
            .iter()
            .map(|t| t.time.last().unwrap_or(&0.0) - t.time.first().unwrap_or(&0.0))
            .fold(0.0, f64::max),
        steps: step_signature(tests),
    }
}

/// The most [`DataFeatures::unseen_noise`] may be: noise unseen by the second differences is
/// credited at most as large again as the noise they see, so a misfit of more than twice the
/// white noise variance is never called noise on this ground.
pub const MAX_UNSEEN_NOISE: f64 = 2.0;

/// On every row of each test (`full`: the fitted test may hold averaged bins, whose white noise
/// is smaller).
fn unseen_noise(tests: &[PreparedTest]) -> f64 {
    let mut ratios: Vec<f64> = tests
        .iter()
        .map(|p| &p.full)
        .filter(|t| t.control == Control::Slip)
        .filter_map(|t| {
            crate::noise::slow_noise_ratio(&t.time, &t.imposed, &t.measured, t.noise_sd)
        })
        .collect();
    median(&mut ratios).map_or(1.0, |r| r.clamp(1.0, MAX_UNSEEN_NOISE))
}

/// Rows of the longest window of [`unseen_noise_about`]: four times the raw record's window, so
/// that it spans several correlation times of a wander that 60 rows of steady driving absorb.
const RESIDUAL_WINDOW: usize = 240;

/// [`DataFeatures::unseen_noise`] measured again on the residual of the model fitted to the
/// record (`residuals`: the base model's on every row of each test, in units of the test's
/// noise as `subfric_diagnose::fits::residuals` gives them), over windows of steady driving with a
/// straight line in time removed from each: the model has taken out the friction's own
/// curvature, which is what keeps the raw record's windows short (over a longer window a
/// parabola no longer follows the friction), so a window can span the wander that the raw
/// windows absorb, and a line still takes out what the model misses slowly. Each test is
/// measured over the longest windows it holds three of: [`RESIDUAL_WINDOW`] rows, else half as
/// many, down to the raw record's [`crate::noise::SLOW_WINDOW`]. The larger of the
/// median over the tests and the raw record's figure, and of the wander the residual's
/// semivariogram within stretches of steady driving shows ([`crate::noise::Variogram`],
/// for a wander slower than those windows), within [`MAX_UNSEEN_NOISE`].
pub fn unseen_noise_about(tests: &[PreparedTest], residuals: &[Vec<f64>]) -> f64 {
    let mut ratios = Vec::new();
    // A wander slower than those windows: the residual's semivariogram within each stretch of
    // steady driving, pooled over the tests (in units of each test's white noise).
    let mut variogram = crate::noise::Variogram::default();
    for (t, r) in tests.iter().map(|p| &p.full).zip(residuals) {
        if t.control != Control::Slip || !r.iter().all(|v| v.is_finite()) {
            continue;
        }
        // The residuals are scaled by the test's weight over its noise: one white SD is the
        // square root of the weight.
        let white = t.weight.sqrt();
        let longest = std::iter::successors(Some(RESIDUAL_WINDOW), |w| Some(w / 2))
            .take_while(|&w| w >= crate::noise::SLOW_WINDOW)
            .find_map(|w| crate::noise::slow_noise_ratio_over(&t.time, &t.imposed, r, white, w, 2));
        ratios.extend(longest);
        let scaled: Vec<f64> = r.iter().map(|v| v / white).collect();
        variogram.add(&t.time, &t.imposed, &scaled);
    }
    let about_model = median(&mut ratios).unwrap_or(1.0);
    let slower = variogram.wander_ratio().unwrap_or(1.0);
    unseen_noise(tests)
        .max(about_model)
        .max(slower)
        .clamp(1.0, MAX_UNSEEN_NOISE)
}

impl DataFeatures {
    /// The scales a registered family reads its first guesses from.
    pub fn scales(&self) -> subfric_model::terms::DataScales {
        subfric_model::terms::DataScales {
            v_ref: self.v_ref,
            p_ref: self.p_ref,
            slip_span_mm: self.slip_span_mm,
            duration_s: self.duration_s,
            holds: self.holds,
            reversals: self.reversals,
            pressure_levels: self.pressure_levels,
            sliding_rates: self.sliding_rates,
            traction_tests: self.traction_tests,
            healing_per_decade: self.seeds.healing_per_decade,
            steps: subfric_model::terms::StepReading {
                direct: self.steps.direct,
                steady: self.steps.steady,
                decay_mm: self.steps.decay_mm,
            },
            rate_and_state: self.seeds.rate_and_state,
            stress_trend: subfric_model::terms::StressReading {
                peak: self.seeds.stress_trend.0,
                residual: self.seeds.stress_trend.1,
            },
            slip_slope_per_mm: self.seeds.slip_slope_per_mm,
            slip_to_peak_mm: self.seeds.slip_to_peak_mm,
        }
    }
}
