//! Noise of a sampled signal, estimated from the data itself so that it survives real sensors:
//! quantised values, flat stretches (a logger repeating its last reading), slow drift, and bursts
//! of denser, noisier sampling.
//!
//! Runs of exactly repeated values (a logger repeating its last reading, a still quantised
//! signal) are first collapsed to one reading each: repeats carry no information about the
//! noise. The estimate is then the scatter of each reading about the line through its two
//! neighbours (a time-aware second difference, blind to any locally linear signal, drift
//! included), measured robustly (MAD) in blocks of readings, and the median over blocks: a
//! burst of noisy rows moves it no more than its share of blocks. When the data are quantised
//! the estimate is never below the quantisation noise q/√12, and is then reported as a floor,
//! not a measurement.

use crate::stats::median;
use serde::Serialize;

/// Rows per block of the robust estimate.
const BLOCK: usize = 256;

/// What is known about the noise of one column.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct NoiseEstimate {
    /// Noise standard deviation, in the column's unit.
    pub sd: f64,
    /// Quantisation step of the column (0 when the values are not on a regular grid).
    pub quantum: f64,
    /// True when `sd` is the quantisation floor q/√12 (or zero), not a measured scatter.
    pub floor: bool,
    /// Smallest and largest block estimate: a wide range means the noise changes along the
    /// record (e.g. with the sampling rate).
    pub block_range: (f64, f64),
    /// How many second differences of the record the estimate rests on.
    pub residuals: usize,
}

/// Asymptotic efficiency of the median absolute deviation against the standard deviation for
/// Gaussian noise (2/π / (4 φ(Φ⁻¹(3/4))² · Φ⁻¹(3/4)²)… = 0.367): a MAD over k values measures
/// the noise about as well as a standard deviation over 0.367 k.
pub const MAD_EFFICIENCY: f64 = 0.367;

impl NoiseEstimate {
    /// The degrees of freedom of the noise variance this estimate measured: as many as a
    /// standard deviation over [`MAD_EFFICIENCY`] × the second differences it rests on (it is
    /// their median absolute deviation), or 0 when it measured nothing (at the floor without a
    /// quantisation step: too few rows, or a record without scatter, whose noise is then a
    /// guess). A quantisation step is read from at least 20 steps and its noise q/√12 is known,
    /// so rounding noise counts as measured by every difference.
    pub fn degrees_of_freedom(&self) -> usize {
        if !self.floor {
            (MAD_EFFICIENCY * self.residuals as f64).floor() as usize
        } else if self.quantum > 0.0 {
            self.residuals
        } else {
            0
        }
    }
}

/// Scaled residuals of each reading from the linear interpolation of its two neighbours (white
/// noise of SD σ gives residuals of SD σ), after collapsing runs of repeated values.
fn second_differences(t: &[f64], x: &[f64]) -> Vec<f64> {
    let n = t.len().min(x.len());
    let mut tt = Vec::with_capacity(n);
    let mut xx = Vec::with_capacity(n);
    for i in 0..n {
        if i > 0 && x[i] == x[i - 1] {
            continue;
        }
        tt.push(t[i]);
        xx.push(x[i]);
    }
    let mut r = Vec::with_capacity(xx.len().saturating_sub(2));
    for i in 1..xx.len().saturating_sub(1) {
        let (d1, d2) = (tt[i] - tt[i - 1], tt[i + 1] - tt[i]);
        if !(d1 > 0.0 && d2 > 0.0) {
            continue;
        }
        let a = d2 / (d1 + d2);
        let b = d1 / (d1 + d2);
        let res = (xx[i] - (a * xx[i - 1] + b * xx[i + 1])) / (1.0 + a * a + b * b).sqrt();
        if res.is_finite() {
            r.push(res);
        }
    }
    r
}

fn mad_sd(r: &[f64]) -> f64 {
    let mut v = r.to_vec();
    let med = median(&mut v).unwrap_or(0.0);
    let mut dev: Vec<f64> = r.iter().map(|v| (v - med).abs()).collect();
    1.4826 * median(&mut dev).unwrap_or(0.0)
}

/// Quantisation step of `x`: the smallest step of which most changes between consecutive rows
/// are whole multiples; 0 when the values are not on a regular grid.
///
/// ```
/// let x: Vec<f64> = (0..500).map(|i| ((i as f64 * 0.37).sin() * 40.0).round() * 0.1).collect();
/// let q = subfric_reading::noise::quantum(&x);
/// assert!((q - 0.1).abs() < 1e-9, "{q}");
/// let smooth: Vec<f64> = (0..500).map(|i| (i as f64 * 0.37).sin()).collect();
/// assert_eq!(subfric_reading::noise::quantum(&smooth), 0.0);
/// ```
pub fn quantum(x: &[f64]) -> f64 {
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    let all: Vec<f64> = x
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| d.is_finite())
        .collect();
    let mut steps: Vec<f64> = all.iter().copied().filter(|d| *d > 1e-12 * scale).collect();
    if steps.len() < 20 {
        return 0.0;
    }
    steps.sort_by(f64::total_cmp);
    // The smallest steps are one quantum; print rounding makes them differ in the last digits.
    let q = steps[steps.len() / 50];
    if q <= 1e-9 * scale {
        return 0.0;
    }
    let mut multiples: std::collections::BTreeMap<u64, usize> = Default::default();
    let mut on_grid = 0;
    for &d in &steps {
        let k = (d / q).round();
        if k >= 1.0 && (d - k * q).abs() <= 0.1 * q + 1e-9 * d {
            on_grid += 1;
            *multiples.entry(k as u64).or_default() += 1;
        }
    }
    // A grid shows as repeats or as several multiples of the step: a clean ramp whose every
    // step is equal is not quantised.
    let repeats = all.len() - steps.len();
    let mut counts: Vec<usize> = multiples.values().copied().collect();
    counts.sort_unstable_by(|a, b| b.cmp(a));
    let varied = counts.get(1).is_some_and(|&c| c * 20 >= steps.len());
    if on_grid as f64 >= 0.9 * steps.len() as f64 && (varied || repeats * 20 >= all.len()) {
        q
    } else {
        0.0
    }
}

/// Estimates the noise of `x` sampled at `t` (see the module documentation).
///
/// ```
/// use subfric_reading::noise::estimate_noise;
/// let t: Vec<f64> = (0..30_000).map(|i| i as f64 * 0.1).collect();
/// // A slowly drifting signal read by a 0.01-step converter: no scatter beyond quantisation.
/// let x: Vec<f64> = t.iter().map(|t| (0.0003 * t / 0.01).round() * 0.01).collect();
/// let e = estimate_noise(&t, &x);
/// assert!(e.floor);
/// assert!((e.sd - e.quantum / 12f64.sqrt()).abs() < 1e-12);
/// ```
pub fn estimate_noise(t: &[f64], x: &[f64]) -> NoiseEstimate {
    let r = second_differences(t, x);
    let q = quantum(x);
    let floor_sd = q / 12f64.sqrt();
    let mut blocks: Vec<f64> = r
        .chunks(BLOCK)
        .filter(|c| c.len() >= BLOCK / 4 || r.len() < BLOCK / 4)
        .map(mad_sd)
        .collect();
    if blocks.is_empty() && !r.is_empty() {
        blocks.push(mad_sd(&r));
    }
    let lo = blocks.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = blocks.iter().cloned().fold(0.0, f64::max);
    let measured = median(&mut blocks).unwrap_or(0.0);
    let (sd, floor) = if measured > floor_sd {
        (measured, false)
    } else {
        (floor_sd, true)
    };
    NoiseEstimate {
        sd: if sd.is_finite() { sd } else { 0.0 },
        quantum: q,
        floor,
        block_range: if lo.is_finite() { (lo, hi) } else { (0.0, 0.0) },
        residuals: r.len(),
    }
}

/// Rows of a window of [`slow_noise_ratio`].
pub const SLOW_WINDOW: usize = 60;

/// Fewest windows [`slow_noise_ratio`] measures on.
const SLOW_MIN_WINDOWS: usize = 3;

/// The RMS residual of `x` about the least-squares polynomial in `t` with `terms` terms (1: a
/// constant, 2: a line, 3: a parabola; for more rows than terms).
fn polynomial_rms(t: &[f64], x: &[f64], terms: usize) -> f64 {
    let terms = terms.clamp(1, 3);
    let n = t.len() as f64;
    let tm = t.iter().sum::<f64>() / n;
    let span = t
        .iter()
        .map(|v| (v - tm).abs())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    // Least squares in a scaled, centred time (well conditioned for any time unit), by
    // nalgebra's SVD; a design the rows cannot resolve (times that do not vary) has no fit.
    let design =
        nalgebra::DMatrix::from_fn(t.len(), terms, |i, j| ((t[i] - tm) / span).powi(j as i32));
    let y = nalgebra::DVector::from_column_slice(x);
    let svd = design.clone().svd(true, true);
    let largest = svd.singular_values.max();
    if !(svd.singular_values.min() > 1e-12 * largest && largest.is_finite()) {
        return f64::NAN;
    }
    let Ok(c) = svd.solve(&y, 0.0) else {
        return f64::NAN;
    };
    let ss = (design * c - y).norm_squared();
    (ss / (n - terms as f64).max(1.0)).sqrt()
}

/// How much more a measured column scatters over a slow stretch than its white noise: the
/// median, over windows of steady driving (the imposed column moving at one rate, within a
/// fifth, for [`SLOW_WINDOW`] rows), of the variance about a parabola in time, divided by the
/// variance `white_sd²` that the second differences see ([`estimate_noise`]).
///
/// Second differences see only the noise that changes from one reading to the next; a load cell
/// or amplifier also wanders over seconds (noise correlated in time), which they miss and which
/// a model's residual shows in full. This measures that part on the record itself, where the
/// friction is smooth. `None` with fewer than three such windows.
///
/// ```
/// // A steady slide whose friction rises smoothly, with white noise: nothing unseen.
/// let t: Vec<f64> = (0..2000).map(|i| i as f64 * 0.1).collect();
/// let slip: Vec<f64> = t.iter().map(|t| 0.01 * t).collect();
/// // Uniform pseudo-random noise from a linear congruential generator.
/// let mut seed = 12345u64;
/// let mut noise = || {
///     seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
///     (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
/// };
/// let x: Vec<f64> = t.iter().map(|t| 50.0 + 0.01 * t * t + noise()).collect();
/// let white = subfric_reading::estimate_noise(&t, &x).sd;
/// let ratio = subfric_reading::noise::slow_noise_ratio(&t, &slip, &x, white).unwrap();
/// assert!((0.7..1.4).contains(&ratio), "{ratio}");
/// ```
pub fn slow_noise_ratio(t: &[f64], imposed: &[f64], x: &[f64], white_sd: f64) -> Option<f64> {
    slow_noise_ratio_over(t, imposed, x, white_sd, SLOW_WINDOW, 3)
}

/// [`slow_noise_ratio`] over windows of `window` rows, about a polynomial in time of `terms`
/// terms (1: the window's mean, 2: a line, 3: a parabola) in each.
pub fn slow_noise_ratio_over(
    t: &[f64],
    imposed: &[f64],
    x: &[f64],
    white_sd: f64,
    window: usize,
    terms: usize,
) -> Option<f64> {
    let window = window.max(4);
    let n = t.len().min(imposed.len()).min(x.len());
    if white_sd.is_nan() || white_sd <= 0.0 || n < window {
        return None;
    }
    let rate = |i: usize| (imposed[i + 1] - imposed[i]) / (t[i + 1] - t[i]);
    let mut ratios = Vec::new();
    let mut i = 0;
    while i + window <= n {
        let rates: Vec<f64> = (i..i + window - 1).map(rate).collect();
        let mean = rates.iter().sum::<f64>() / rates.len() as f64;
        let steady = mean != 0.0
            && rates
                .iter()
                .all(|r| r.is_finite() && r.signum() == mean.signum())
            && rates.iter().map(|r| (r - mean).abs()).fold(0.0, f64::max) < 0.2 * mean.abs();
        if steady {
            let rms = polynomial_rms(&t[i..i + window], &x[i..i + window], terms);
            if rms.is_finite() {
                ratios.push((rms / white_sd).powi(2));
            }
            i += window;
        } else {
            i += window / 4;
        }
    }
    (ratios.len() >= SLOW_MIN_WINDOWS).then(|| median(&mut ratios).unwrap_or(0.0))
}

/// The semivariogram in time of a residual over stretches of steady driving, pooled over tests,
/// for a wander slower than any window of [`slow_noise_ratio_over`] holds: a rate-adaptive
/// logger writes a row per few µm, so sixty or even 240 rows of a fast stretch span seconds
/// while a load cell's wander runs over tens of seconds, and a line through each window takes
/// most of it out. Within one stretch the semivariogram γ(Δt) = ½ E[(r(t + Δt) − r(t))²] of
/// white noise plus a first-order wander rises from the white variance at short lags to the
/// whole variance at lags beyond its correlation time τ: γ = w + s (1 − e^(−Δt/τ)).
/// [`Variogram::wander_ratio`] fits that and returns (w + s) / w.
///
/// Pairs are taken at lags of 1, 2, 4, … rows within each stretch (n log n pairs), never
/// across a change of rate, a reversal or a hold, where the model's transients are.
#[derive(Clone, Debug, Default)]
pub struct Variogram {
    /// Per half-octave of lag (index round(2 log2 Δt)): sum of ½ (Δr)² and the pair count.
    bins: std::collections::BTreeMap<i64, (f64, usize)>,
    /// Duration of the longest stretch, s.
    longest_s: f64,
}

/// Fewest rows of a stretch of steady driving the [`Variogram`] takes.
const VARIOGRAM_MIN_ROWS: usize = 20;

/// Fewest pairs of a lag bin the [`Variogram`] fit takes.
const VARIOGRAM_MIN_PAIRS: usize = 30;

/// The longest correlation time credited, as a fraction of the longest stretch: the
/// semivariogram must have flattened at lags the stretches hold, so that a slow trend (a shape
/// the model misses, rising without a sill) is not taken for noise.
const RESOLVED_TAU_FRACTION: f64 = 1.0 / 6.0;

impl Variogram {
    /// Adds the pairs of `r` (in units of its white noise SD) within each stretch of steady
    /// driving of `imposed` (the column moving at one rate, each row's rate within a fifth of
    /// the stretch's mean so far, one sign).
    pub fn add(&mut self, t: &[f64], imposed: &[f64], r: &[f64]) {
        let n = t.len().min(imposed.len()).min(r.len());
        let rate = |i: usize| (imposed[i + 1] - imposed[i]) / (t[i + 1] - t[i]);
        let mut i = 0;
        while i + 1 < n {
            let r0 = rate(i);
            if !r0.is_finite() || r0 == 0.0 {
                i += 1;
                continue;
            }
            let (mut sum, mut j) = (0.0, i);
            while j + 1 < n {
                let rj = rate(j);
                let mean = if j > i { sum / (j - i) as f64 } else { r0 };
                if !(rj.is_finite() && rj * mean > 0.0 && (rj - mean).abs() < 0.2 * mean.abs()) {
                    break;
                }
                sum += rj;
                j += 1;
            }
            // Rows i..=j moved at one rate.
            if j + 1 - i >= VARIOGRAM_MIN_ROWS {
                self.add_stretch(&t[i..=j], &r[i..=j]);
            }
            i = j.max(i + 1);
        }
    }

    fn add_stretch(&mut self, t: &[f64], r: &[f64]) {
        let n = t.len();
        self.longest_s = self.longest_s.max(t[n - 1] - t[0]);
        let mut lag = 1;
        while lag < n {
            for i in 0..n - lag {
                let (dt, d) = (t[i + lag] - t[i], r[i + lag] - r[i]);
                if dt > 0.0 && d.is_finite() {
                    let bin = self
                        .bins
                        .entry((2.0 * dt.log2()).round() as i64)
                        .or_default();
                    bin.0 += 0.5 * d * d;
                    bin.1 += 1;
                }
            }
            lag *= 2;
        }
    }

    /// The total variance of the residual's noise over its white variance, (w + s) / w, from
    /// the least-squares fit of γ = w + s (1 − e^(−Δt/τ)) over the lag bins (each weighted by
    /// its pairs; τ on a grid up to a third of the longest stretch). `None` with fewer than
    /// four bins or when the best τ is longer than [`RESOLVED_TAU_FRACTION`] of the longest
    /// stretch (no sill seen).
    pub fn wander_ratio(&self) -> Option<f64> {
        let points: Vec<(f64, f64, f64)> = self
            .bins
            .iter()
            .filter(|(_, b)| b.1 >= VARIOGRAM_MIN_PAIRS)
            .map(|(k, b)| (2f64.powf(*k as f64 / 2.0), b.0 / b.1 as f64, b.1 as f64))
            .collect();
        if points.len() < 4 {
            return None;
        }
        let mut best: Option<(f64, f64, f64, f64)> = None; // (sse, tau, w, s)
        let mut tau = points[0].0;
        while tau <= self.longest_s / 3.0 {
            let f = |dt: f64| 1.0 - (-dt / tau).exp();
            let (mut sw, mut sf, mut sff, mut sg, mut sfg) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for &(dt, g, c) in &points {
                let fi = f(dt);
                sw += c;
                sf += c * fi;
                sff += c * fi * fi;
                sg += c * g;
                sfg += c * fi * g;
            }
            let det = sw * sff - sf * sf;
            if det > 0.0 {
                // A wander adds variance: the sill is never below the white part.
                let s = ((sw * sfg - sf * sg) / det).max(0.0);
                let w = (sg - s * sf) / sw;
                let sse: f64 = points
                    .iter()
                    .map(|&(dt, g, c)| c * (g - w - s * f(dt)).powi(2))
                    .sum();
                if best.is_none_or(|b| sse < b.0) {
                    best = Some((sse, tau, w, s));
                }
            }
            tau *= 1.25;
        }
        let (_, tau, w, s) = best?;
        (w > 0.0 && tau <= RESOLVED_TAU_FRACTION * self.longest_s).then(|| (w + s) / w)
    }
}

/// Robust noise SD of a sampled signal ([`estimate_noise`]'s `sd`).
///
/// ```
/// let t: Vec<f64> = (0..200).map(|i| i as f64 * 0.5).collect();
/// let x: Vec<f64> = t.iter().map(|t| 0.01 * t).collect();
/// assert!(subfric_reading::noise::noise_sd(&t, &x) < 1e-12);
/// ```
pub fn noise_sd(t: &[f64], x: &[f64]) -> f64 {
    estimate_noise(t, x).sd
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    fn gauss(rng: &mut rand::rngs::StdRng) -> f64 {
        StandardNormal.sample(rng)
    }

    /// White noise of SD 0.2 plus a first-order wander of SD 0.2 and correlation time `tau`
    /// s, at the instants `t` read every `dt` s.
    fn white_and_wander(rng: &mut rand::rngs::StdRng, t: &[f64], dt: f64, tau: f64) -> Vec<f64> {
        let phi = (-dt / tau).exp();
        let mut wander = 0.0;
        t.iter()
            .map(|_| {
                wander = phi * wander + 0.2 * (1.0 - phi * phi).sqrt() * gauss(rng);
                wander + 0.2 * gauss(rng)
            })
            .collect()
    }

    #[test]
    fn a_wander_slower_than_the_short_windows_is_seen_over_long_windows_about_a_line() {
        // The residual of a model that fits: white noise of SD 0.2 plus a first-order wander of
        // SD 0.2 with a correlation time of 6 s, read every 0.2 s. Sixty rows (12 s, two
        // correlation times) about a parabola absorb most of the wander; 240 rows (48 s) about
        // a line see most of it: the variance is about twice the white part's.
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let dt = 0.2;
        let t: Vec<f64> = (0..12000).map(|i| i as f64 * dt).collect();
        let slip: Vec<f64> = t.iter().map(|t| 0.01 * t).collect();
        let r = white_and_wander(&mut rng, &t, dt, 6.0);
        let white = estimate_noise(&t, &r).sd;
        let short = slow_noise_ratio(&t, &slip, &r, white).unwrap();
        let long = slow_noise_ratio_over(&t, &slip, &r, white, 240, 2).unwrap();
        assert!(short < 1.4, "white {white}, 60 rows {short}");
        assert!(long > 1.6 && long < 2.4, "white {white}, 240 rows {long}");
        // Without the wander both see the white noise alone.
        let plain: Vec<f64> = t.iter().map(|_| 0.2 * gauss(&mut rng)).collect();
        let white = estimate_noise(&t, &plain).sd;
        let long = slow_noise_ratio_over(&t, &slip, &plain, white, 240, 2).unwrap();
        assert!(
            (0.85..1.15).contains(&long),
            "white {white}, 240 rows {long}"
        );
        // A slow trend the model missed (a line over the whole stretch) is not noise: the line
        // of each window takes it out.
        let trend: Vec<f64> = t.iter().zip(&plain).map(|(t, e)| 0.01 * t + e).collect();
        let long = slow_noise_ratio_over(&t, &slip, &trend, white, 240, 2).unwrap();
        assert!(
            (0.85..1.15).contains(&long),
            "white {white}, 240 rows {long}"
        );
    }

    #[test]
    fn a_wander_slower_than_any_window_is_read_off_the_semivariogram_of_the_steady_stretches() {
        // A rate-adaptive logger: a row per 5 µm at 0.0167 mm/s (0.3 s a row), legs of 800 rows
        // (240 s) between reversals. White noise of SD 0.2 plus a wander of SD 0.2 with a
        // correlation time of 30 s: 240 rows (72 s) about a line miss most of it, the
        // semivariogram within the legs reaches its sill, twice the white variance.
        let mut rng = rand::rngs::StdRng::seed_from_u64(17);
        let dt = 0.3;
        let t: Vec<f64> = (0..16000).map(|i| i as f64 * dt).collect();
        let slip: Vec<f64> = t
            .iter()
            .map(|t| {
                let (leg, within) = ((t / 240.0).floor(), t % 240.0);
                let sign = if leg as i64 % 2 == 0 { 1.0 } else { -1.0 };
                sign * 0.0167 * (within - 120.0)
            })
            .collect();
        let r = white_and_wander(&mut rng, &t, dt, 30.0);
        let white = estimate_noise(&t, &r).sd;
        let units: Vec<f64> = r.iter().map(|v| v / white).collect();
        let windows = slow_noise_ratio_over(&t, &slip, &r, white, 240, 2).unwrap_or(1.0);
        let mut v = Variogram::default();
        v.add(&t, &slip, &units);
        let ratio = v.wander_ratio().unwrap();
        assert!(windows < 1.5, "240 rows about a line: {windows}");
        assert!((1.7..2.4).contains(&ratio), "semivariogram: {ratio}");

        // White noise alone: nothing beyond it.
        let plain: Vec<f64> = t.iter().map(|_| gauss(&mut rng)).collect();
        let mut v = Variogram::default();
        v.add(&t, &slip, &plain);
        let ratio = v.wander_ratio().unwrap_or(1.0);
        assert!((0.9..1.1).contains(&ratio), "white noise: {ratio}");

        // A shape the model misses, rising over each leg without a sill (a parabola of 1.2
        // white SDs): not credited as noise (no sill at lags the legs hold).
        let missed: Vec<f64> = t
            .iter()
            .zip(&plain)
            .map(|(t, e)| e + 1.2 * ((t % 240.0) / 240.0).powi(2))
            .collect();
        let mut v = Variogram::default();
        v.add(&t, &slip, &missed);
        let ratio = v.wander_ratio().unwrap_or(1.0);
        assert!(ratio < 1.15, "a trend within each leg: {ratio}");

        // Pairs never straddle a reversal: a jump between legs that alternate in level (a
        // direction effect the model missed) adds nothing.
        let stepped: Vec<f64> = t
            .iter()
            .zip(&plain)
            .map(|(t, e)| {
                e + if (t / 240.0).floor() as i64 % 2 == 0 {
                    1.5
                } else {
                    -1.5
                }
            })
            .collect();
        let mut v = Variogram::default();
        v.add(&t, &slip, &stepped);
        let ratio = v.wander_ratio().unwrap_or(1.0);
        assert!((0.9..1.1).contains(&ratio), "a level per leg: {ratio}");

        // No steady driving (a hold): nothing to measure on.
        let mut v = Variogram::default();
        v.add(&t, &vec![0.0; t.len()], &plain);
        assert_eq!(v.wander_ratio(), None);
    }

    #[test]
    fn slowly_wandering_noise_that_second_differences_miss_is_measured_on_steady_stretches() {
        // White noise of SD 0.2 plus a first-order wander of SD 0.2 with a correlation time of
        // 2 s, read every 0.2 s while the slip is driven steadily: the second differences see
        // about the white part, the steady stretches both.
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let dt = 0.2;
        let t: Vec<f64> = (0..6000).map(|i| i as f64 * dt).collect();
        let slip: Vec<f64> = t.iter().map(|t| 0.01 * t).collect();
        let x: Vec<f64> = white_and_wander(&mut rng, &t, dt, 2.0)
            .iter()
            .map(|v| 40.0 + v)
            .collect();
        let white = estimate_noise(&t, &x).sd;
        let ratio = slow_noise_ratio(&t, &slip, &x, white).unwrap();
        assert!(ratio > 1.3 && ratio < 2.5, "white {white}, ratio {ratio}");
        // The same record without the wander: nothing unseen.
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let plain: Vec<f64> = t.iter().map(|_| 40.0 + 0.2 * gauss(&mut rng)).collect();
        let white = estimate_noise(&t, &plain).sd;
        let ratio = slow_noise_ratio(&t, &slip, &plain, white).unwrap();
        assert!((0.8..1.2).contains(&ratio), "white {white}, ratio {ratio}");
        // No steady driving (a hold): nothing to measure on.
        let still = vec![0.0; t.len()];
        assert_eq!(slow_noise_ratio(&t, &still, &plain, white), None);
    }

    #[test]
    fn white_noise_on_a_ramp_is_measured() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let t: Vec<f64> = (0..4000).map(|i| i as f64).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|t| 0.01 * t + 0.002 * gauss(&mut rng))
            .collect();
        let e = estimate_noise(&t, &x);
        assert!((e.sd - 0.002).abs() < 0.0002, "{e:?}");
        assert!(!e.floor);
    }

    #[test]
    fn quantised_noise_with_repeated_readings_is_not_near_zero() {
        // A logger at 1 kHz repeats a 10 Hz converter's reading: 99 of 100 rows are repeats,
        // the readings are quantised at 0.5 and carry noise of SD 1.
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let n = 20_000;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
        let mut x = Vec::with_capacity(n);
        let mut held = 0.0;
        for (i, ti) in t.iter().enumerate() {
            if i % 100 == 0 {
                held = ((5.0 * ti + gauss(&mut rng)) / 0.5).round() * 0.5;
            }
            x.push(held);
        }
        let e = estimate_noise(&t, &x);
        assert!(e.sd > 0.5, "{e:?}");
        assert!((e.quantum - 0.5).abs() < 1e-9, "{e:?}");
    }

    #[test]
    fn a_noisy_burst_does_not_set_the_estimate() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let n = 10_000;
        let t: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let x: Vec<f64> = (0..n)
            .map(|i| {
                let sd = if (4000..5000).contains(&i) {
                    0.05
                } else {
                    0.01
                };
                sd * gauss(&mut rng)
            })
            .collect();
        let e = estimate_noise(&t, &x);
        assert!((e.sd - 0.01).abs() < 0.0015, "{e:?}");
        assert!(e.block_range.1 > 3.0 * e.block_range.0, "{e:?}");
    }
}
