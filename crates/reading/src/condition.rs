//! Conditioning of the imposed column: isotonic fit per monotone run between the true reversals,
//! flat holds (the events themselves are found by [`crate::imposed`]).
//!
//! Lab files carry measurement noise on the imposed column too: during a hold the slip jitters
//! and goes backwards by a fraction of a micrometre. The friction model is elastically very
//! stiff, so such a spurious reversal would be simulated as a full unloading. Conditioning keeps
//! the real reversals (found with a hysteresis threshold of several noise SDs) and replaces the
//! column within each monotone run by its isotonic regression (PAVA), so that no spurious
//! reversal remains; holds whose jitter stays within the threshold become exactly flat.

use crate::imposed::{detect, run_directions, SegmentOptions};
use crate::noise::NoiseEstimate;
use subfric_data::set::TestData;

/// The imposed column after conditioning.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Conditioned {
    /// Conditioned imposed values, one per row (slip in mm or shear in kPa).
    pub values: Vec<f64>,
    /// Estimated noise standard deviation of the raw imposed column (same unit).
    pub noise_sd: f64,
    /// The noise estimate of the raw imposed column (SD, quantisation, floor or measured).
    pub noise: NoiseEstimate,
    /// The smallest motion taken for real (reversal hysteresis), same unit.
    pub band: f64,
    /// True when `values` differ from the raw column.
    pub changed: bool,
}

pub use crate::imposed::REVERSAL_SDS;

/// Conditions the imposed column of a test with the default [`SegmentOptions`].
///
/// ```
/// use subfric_data::{ControlColumn, TestData, TestSpec};
/// use subfric_reading::condition_imposed;
/// // a ramp, a noisy hold that goes backwards, a ramp
/// let slip = [0.0, 0.1, 0.2, 0.3, 0.3002, 0.2998, 0.3001, 0.2999, 0.3003, 0.2997, 0.3, 0.4, 0.5, 0.6];
/// let n = slip.len();
/// let t = TestData {
///     spec: TestSpec::new("shs", "shs.csv", ControlColumn::Slip, 100.0),
///     path: "shs.csv".into(),
///     time_s: (0..n).map(|i| i as f64).collect(),
///     slip_mm: slip.to_vec(),
///     shear_kpa: vec![0.0; n],
///     normal_kpa: vec![100.0; n],
///     friction_given: false,
///     line_of_row: (2..n + 2).collect(),
///     comments: vec![],
///     reading_notes: vec![],
///     channels: vec![],
/// };
/// let c = condition_imposed(&t);
/// assert!(c.changed);
/// assert!(c.values.windows(2).all(|w| w[1] >= w[0]), "no reversal left");
/// ```
pub fn condition_imposed(test: &TestData) -> Conditioned {
    condition_imposed_with(test, &SegmentOptions::default())
}

/// Conditions the imposed column of a test; `opts` sets what counts as a hold.
pub fn condition_imposed_with(test: &TestData, opts: &SegmentOptions) -> Conditioned {
    analyze(&test.time_s, test.imposed(), opts).conditioned
}

/// Isotonic (non-decreasing) regression by pool-adjacent-violators, equal weights.
pub fn pava_increasing(y: &[f64]) -> Vec<f64> {
    let mut sums: Vec<f64> = Vec::with_capacity(y.len());
    let mut counts: Vec<usize> = Vec::with_capacity(y.len());
    for &v in y {
        sums.push(v);
        counts.push(1);
        while sums.len() > 1 {
            let k = sums.len() - 1;
            let last = sums[k] / counts[k] as f64;
            let prev = sums[k - 1] / counts[k - 1] as f64;
            if prev > last {
                sums[k - 1] += sums[k];
                counts[k - 1] += counts[k];
                sums.pop();
                counts.pop();
            } else {
                break;
            }
        }
    }
    let mut out = Vec::with_capacity(y.len());
    for (s, c) in sums.iter().zip(&counts) {
        let m = s / *c as f64;
        out.extend(std::iter::repeat_n(m, *c));
    }
    out
}

fn pava(y: &[f64], dir: i8) -> Vec<f64> {
    if dir >= 0 {
        pava_increasing(y)
    } else {
        let neg: Vec<f64> = y.iter().map(|v| -v).collect();
        pava_increasing(&neg).into_iter().map(|v| -v).collect()
    }
}

/// Everything found while conditioning a column.
#[derive(Clone, Debug)]
pub(crate) struct Analysis {
    pub conditioned: Conditioned,
    /// Rows at the extremes where the direction changes.
    pub reversals: Vec<usize>,
    /// Holds as half-open row ranges `[start, end)`: the rows whose incoming interval is a hold.
    pub holds: Vec<(usize, usize)>,
    /// Distance-weighted median |rate| of the column (the typical sliding rate).
    pub ref_rate: f64,
    /// Travel of the chunks rates are measured over.
    pub chunk_travel: f64,
}

/// Robust noise SD of a sampled signal (see [`crate::noise::estimate_noise`]).
///
/// ```
/// let t: Vec<f64> = (0..200).map(|i| i as f64 * 0.5).collect();
/// let x: Vec<f64> = t.iter().map(|t| 0.01 * t).collect();
/// assert!(subfric_reading::condition::noise_sd(&t, &x) < 1e-12);
/// ```
pub fn noise_sd(t: &[f64], x: &[f64]) -> f64 {
    crate::noise::noise_sd(t, x)
}

/// Finds the events of `x` sampled at `t`, fits each monotone run isotonically and makes the
/// holds exactly flat.
pub(crate) fn analyze(t: &[f64], x: &[f64], opts: &SegmentOptions) -> Analysis {
    let n = t.len().min(x.len());
    let raw: Vec<f64> = x[..n].to_vec();
    let ev = detect(&t[..n], &raw, opts);
    let finite = raw.iter().chain(&t[..n]).all(|v| v.is_finite());
    let mut values = raw.clone();
    if n >= 3 && finite {
        fit_runs(&raw, &ev.reversals, &mut values);
        flatten_holds(&mut values, &ev.reversals, &ev.holds, &ev.noise);
    }
    let changed = values.iter().zip(&raw).any(|(a, b)| a != b);
    Analysis {
        conditioned: Conditioned {
            values,
            noise_sd: ev.noise.sd,
            noise: ev.noise,
            band: ev.band,
            changed,
        },
        reversals: ev.reversals,
        holds: ev.holds,
        ref_rate: ev.ref_rate,
        chunk_travel: ev.chunk_travel,
    }
}

/// Makes every hold exactly flat at its mean, kept between its neighbours so that the motion
/// into and out of it stays monotone.
fn flatten_holds(
    values: &mut [f64],
    reversals: &[usize],
    holds: &[(usize, usize)],
    noise: &NoiseEstimate,
) {
    // A reading off the hold's level by more than this is not at it: four SDs of one reading,
    // or two and a half quanta of a quantised column.
    let off_level = (4.0 * noise.sd).max(2.5 * noise.quantum);
    let n = values.len();
    let mut bounds: Vec<usize> = vec![0];
    bounds.extend(reversals);
    bounds.push(n - 1);
    let dirs = run_directions(values, &bounds);
    let dir_of_interval = |i: usize| -> i8 {
        let k = bounds.partition_point(|&b| b < i).saturating_sub(1);
        dirs.get(k).copied().unwrap_or(1)
    };
    for &(s, e) in holds {
        let b = (e - 1).min(n - 1); // last row of the hold
        if b < s {
            continue;
        }
        // The row where the hold begins (the last moving row), unless its reading is off the
        // hold's level (the end of a slow unload whose last interval read as still, moving
        // less than the band that makes a motion an event but far more than one reading's
        // noise): that row keeps its reading, and the level starts after it.
        let mut hold_rows = values[s..=b].to_vec();
        let level = crate::stats::median(&mut hold_rows).unwrap_or(0.0);
        let a = if (values[s - 1] - level).abs() > off_level {
            s
        } else {
            s - 1
        };
        if b <= a {
            continue;
        }
        let mut c = values[a..=b].iter().sum::<f64>() / (b - a + 1) as f64;
        if a > 0 {
            let before = values[a - 1];
            c = if dir_of_interval(a) > 0 {
                c.max(before)
            } else {
                c.min(before)
            };
        }
        if b + 1 < n {
            let after = values[b + 1];
            c = if dir_of_interval(b + 1) > 0 {
                c.min(after)
            } else {
                c.max(after)
            };
        }
        for v in &mut values[a..=b] {
            *v = c;
        }
    }
}

/// Replaces `values` by the isotonic fit of `raw` within each monotone run.
fn fit_runs(raw: &[f64], reversals: &[usize], values: &mut [f64]) {
    let n = raw.len();
    let mut bounds: Vec<usize> = vec![0];
    bounds.extend(reversals);
    bounds.push(n - 1);
    bounds.dedup();
    let dirs = run_directions(raw, &bounds);
    let mut shared: Vec<Option<f64>> = vec![None; bounds.len()];
    for (k, w) in bounds.windows(2).enumerate() {
        let (s, e) = (w[0], w[1]);
        let fit = pava(&raw[s..=e], dirs[k]);
        for (i, v) in fit.iter().enumerate() {
            values[s + i] = *v;
        }
        // the reversal row at the start is shared with the previous run
        if let Some(prev) = shared[k] {
            let first = fit[0];
            // a peak keeps the larger of the two fits, a valley the smaller
            values[s] = if dirs[k] < 0 {
                prev.max(first)
            } else {
                prev.min(first)
            };
        }
        shared[k + 1] = fit.last().copied();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pava_pools_violators() {
        assert_eq!(
            pava_increasing(&[1.0, 3.0, 2.0, 4.0]),
            vec![1.0, 2.5, 2.5, 4.0]
        );
        assert_eq!(pava(&[3.0, 1.0, 2.0, 0.0], -1), vec![3.0, 1.5, 1.5, 0.0]);
        assert!(pava_increasing(&[]).is_empty());
    }

    #[test]
    fn the_last_row_of_a_slow_unload_keeps_its_reading_when_the_hold_after_it_is_flattened() {
        // A load point backing off slowly (0.0005 mm/s) into a hold, read to 0.1 µm with a
        // noise of 0.14 µm: the last interval of the unload (1.1 µm over 2 s) read as still.
        // Its first row is 8 SDs off the hold's level — 7 kPa of an elastic unload on a stiff
        // rig — and keeps its reading; the hold's rows take their level.
        let noise = NoiseEstimate {
            sd: 0.00014,
            quantum: 0.0001,
            floor: false,
            block_range: (0.00014, 0.00014),
            residuals: 14,
        };
        let unload = [2.1499, 2.1492, 2.1476, 2.1460, 2.1437];
        let hold = [
            2.1426, 2.1427, 2.1426, 2.1424, 2.1427, 2.1426, 2.1427, 2.1427, 2.1425,
        ];
        let mut values: Vec<f64> = unload.iter().chain(&hold).copied().collect();
        let n = values.len();
        let (s, e) = (unload.len(), n);
        flatten_holds(&mut values, &[], &[(s, e)], &noise);
        assert_eq!(values[s - 1], 2.1437, "the unload's last row moved");
        assert!(
            values[s..].iter().all(|&v| (v - 2.14261).abs() < 2e-5),
            "{values:?}"
        );
        // A last moving row within a reading's noise of the level is the hold's first row, as
        // before: it takes the level.
        let mut values: Vec<f64> = [2.1460, 2.1427].iter().chain(&hold).copied().collect();
        let (s, e) = (2, values.len());
        flatten_holds(&mut values, &[], &[(s, e)], &noise);
        assert!((values[s - 1] - values[s]).abs() < 1e-12, "{values:?}");
    }

    #[test]
    fn noise_sd_of_white_noise() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let noise = Normal::new(0.0, 0.002).expect("a valid SD");
        let t: Vec<f64> = (0..4000).map(|i| i as f64).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|t| 0.01 * t + noise.sample(&mut rng))
            .collect();
        let sd = noise_sd(&t, &x);
        assert!((sd - 0.002).abs() < 0.0002, "{sd}");
    }
}
