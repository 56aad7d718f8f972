//! Conditioning of the imposed column: noise estimate, true reversals, isotonic fit per
//! monotone run, flat holds.
//!
//! Lab files carry measurement noise on the imposed column too: during a hold the slip jitters
//! and goes backwards by a fraction of a micrometre. The friction model is elastically very
//! stiff, so such a spurious reversal would be simulated as a full unloading. Conditioning keeps
//! the real reversals (found with a hysteresis threshold of several noise SDs) and replaces the
//! column within each monotone run by its isotonic regression (PAVA), so that no spurious
//! reversal remains; holds whose jitter stays within the threshold become exactly flat.

use crate::segment::SegmentOptions;
use crate::set::TestData;

/// The imposed column after conditioning.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Conditioned {
    /// Conditioned imposed values, one per row (slip in mm or shear in kPa).
    pub values: Vec<f64>,
    /// Estimated noise standard deviation of the raw imposed column (same unit).
    pub noise_sd: f64,
    /// True when `values` differ from the raw column.
    pub changed: bool,
}

/// Hysteresis threshold in noise SDs: a reversal is real when the column moves back by more
/// than this many SDs.
pub const REVERSAL_SDS: f64 = 10.0;

/// Conditions the imposed column of a test with the default [`SegmentOptions`].
///
/// ```
/// use subfric_data::{condition_imposed, Control, TestData, TestSpec};
/// // a ramp, a noisy hold that goes backwards, a ramp
/// let slip = [0.0, 0.1, 0.2, 0.3, 0.3002, 0.2998, 0.3001, 0.2999, 0.3003, 0.2997, 0.3, 0.4, 0.5, 0.6];
/// let n = slip.len();
/// let t = TestData {
///     spec: TestSpec::new("shs", "shs.csv", Control::Slip, 100.0),
///     path: "shs.csv".into(),
///     time_s: (0..n).map(|i| i as f64).collect(),
///     slip_mm: slip.to_vec(),
///     shear_kpa: vec![0.0; n],
///     normal_kpa: vec![100.0; n],
///     friction_given: false,
///     line_of_row: (2..n + 2).collect(),
///     comments: vec![],
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
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// Robust noise SD of a sampled signal: MAD of the residuals of each point from the linear
/// interpolation of its two neighbours (time-aware second differences), normalised so that white
/// noise of SD σ gives σ.
///
/// ```
/// let t: Vec<f64> = (0..200).map(|i| i as f64 * 0.5).collect();
/// let x: Vec<f64> = t.iter().map(|t| 0.01 * t).collect();
/// assert!(subfric_data::condition::noise_sd(&t, &x) < 1e-12);
/// ```
pub fn noise_sd(t: &[f64], x: &[f64]) -> f64 {
    let n = t.len().min(x.len());
    let mut r = Vec::with_capacity(n.saturating_sub(2));
    for i in 1..n.saturating_sub(1) {
        let (d1, d2) = (t[i] - t[i - 1], t[i + 1] - t[i]);
        if !(d1 > 0.0 && d2 > 0.0) {
            continue;
        }
        let a = d2 / (d1 + d2);
        let b = d1 / (d1 + d2);
        let res = (x[i] - (a * x[i - 1] + b * x[i + 1])) / (1.0 + a * a + b * b).sqrt();
        if res.is_finite() {
            r.push(res);
        }
    }
    if r.is_empty() {
        return 0.0;
    }
    let med = median(&mut r.clone());
    let mut dev: Vec<f64> = r.iter().map(|v| (v - med).abs()).collect();
    1.4826 * median(&mut dev)
}

/// Smallest non-zero step between consecutive values (the resolution, for quantised data).
fn smallest_step(x: &[f64]) -> f64 {
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    x.windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| d.is_finite() && *d > 1e-12 * scale)
        .fold(f64::INFINITY, f64::min)
}

/// Rows of the true reversals, found with hysteresis `h`: the extreme before a move back by
/// more than `h`.
pub(crate) fn reversals_hysteresis(x: &[f64], h: f64) -> Vec<usize> {
    let n = x.len();
    let mut out = Vec::new();
    if n < 3 {
        return out;
    }
    // direction 0 = undetermined, +1 up, -1 down
    let mut dir = 0i8;
    let (mut imax, mut imin) = (0usize, 0usize);
    for i in 1..n {
        let v = x[i];
        if !v.is_finite() {
            continue;
        }
        match dir {
            0 => {
                if v > x[imax] {
                    imax = i;
                }
                if v < x[imin] {
                    imin = i;
                }
                if x[imax] - x[imin] > h {
                    if imax > imin {
                        dir = 1;
                        // the run starts at the minimum; a fall before it larger than h would
                        // have set the direction already, so no reversal is recorded
                    } else {
                        dir = -1;
                    }
                }
            }
            1 => {
                if v >= x[imax] {
                    imax = i;
                } else if x[imax] - v > h {
                    out.push(imax);
                    dir = -1;
                    imin = i;
                }
            }
            _ => {
                if v <= x[imin] {
                    imin = i;
                } else if v - x[imin] > h {
                    out.push(imin);
                    dir = 1;
                    imax = i;
                }
            }
        }
    }
    out
}

/// Direction (+1 / -1) of each run between reversals, from the values at its ends.
fn run_directions(x: &[f64], bounds: &[usize]) -> Vec<i8> {
    bounds
        .windows(2)
        .map(|w| if x[w[1]] >= x[w[0]] { 1 } else { -1 })
        .collect()
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

fn median3(x: &[f64]) -> Vec<f64> {
    let n = x.len();
    (0..n)
        .map(|i| {
            if i == 0 || i + 1 == n {
                x[i]
            } else {
                let mut w = [x[i - 1], x[i], x[i + 1]];
                w.sort_by(f64::total_cmp);
                w[1]
            }
        })
        .collect()
}

/// Number of intervals on each side of the median rate window.
const RATE_HALF_WINDOW: usize = 4;

/// Conditions `x` sampled at `t`, finds reversals and holds.
pub(crate) fn analyze(t: &[f64], x: &[f64], opts: &SegmentOptions) -> Analysis {
    let n = t.len().min(x.len());
    let raw: Vec<f64> = x[..n].to_vec();
    let t = &t[..n];
    let sd = noise_sd(t, &raw);
    let q = smallest_step(&raw);
    let q = if q.is_finite() { q } else { 0.0 };
    let h = (REVERSAL_SDS * sd).max(2.5 * q).max(1e-12);
    let finite = raw.iter().all(|v| v.is_finite()) && t.iter().all(|v| v.is_finite());
    if n < 3 || !finite {
        return Analysis {
            conditioned: Conditioned {
                values: raw,
                noise_sd: if sd.is_finite() { sd } else { 0.0 },
                changed: false,
            },
            reversals: Vec::new(),
            holds: Vec::new(),
            ref_rate: 0.0,
        };
    }

    // 1. true reversals, on a median-of-3 filtered copy when the data are noisy (spikes), then
    //    refined to the raw extreme next to it
    let mut reversals = if sd > 0.0 {
        let f = median3(&raw);
        let revs = reversals_hysteresis(&f, h);
        let mut out: Vec<usize> = Vec::with_capacity(revs.len());
        let mut bounds: Vec<usize> = vec![0];
        bounds.extend(&revs);
        bounds.push(n - 1);
        let dirs = run_directions(&f, &bounds);
        for (k, &r) in revs.iter().enumerate() {
            // run k ends at r: direction dirs[k]
            let lo = r.saturating_sub(1).max(out.last().map_or(0, |p| p + 1));
            let hi = (r + 1).min(n - 1);
            let mut best = r;
            for i in lo..=hi {
                let better = if dirs[k] > 0 {
                    raw[i] > raw[best]
                } else {
                    raw[i] < raw[best]
                };
                if better {
                    best = i;
                }
            }
            if best > 0 && best < n - 1 && out.last().is_none_or(|&p| best > p) {
                out.push(best);
            }
        }
        out
    } else {
        reversals_hysteresis(&raw, h)
    };

    // 2. isotonic fit per run, the reversal rows shared by both runs
    //    (identity on runs that are already monotone, as in clean data)
    let mut values = raw.clone();
    fit_runs(&raw, &reversals, &mut values);

    // 3. holds from a robust rate estimate
    let (mut holds, ref_rate) = find_holds(t, &values, &reversals, opts, sd);
    refine_holds(
        t,
        &values,
        &mut holds,
        ref_rate * opts.hold_rate_fraction,
        3.0 * sd,
    );
    merge_holds(&values, &reversals, &mut holds, h);
    holds.retain(|&(s, e)| {
        still_in_raw_data(
            t,
            &raw,
            s - 1,
            e - 1,
            ref_rate * opts.hold_rate_fraction,
            ref_rate,
            sd,
        )
    });

    // 4. flatten holds whose jitter stays within the hysteresis threshold
    if sd > 0.0 {
        // direction of the run holding the interval (i-1, i], from the runs as fitted
        let mut bounds: Vec<usize> = vec![0];
        bounds.extend(&reversals);
        bounds.push(n - 1);
        let dirs = run_directions(&values, &bounds);
        let dir_of_interval = |i: usize| -> i8 {
            let k = bounds.partition_point(|&b| b < i).saturating_sub(1);
            dirs.get(k).copied().unwrap_or(1)
        };
        let mut moved: Vec<usize> = Vec::with_capacity(reversals.len());
        let mut ri = 0;
        for &(s, e) in &holds {
            let a = s - 1; // the row where the hold begins (last moving row)
            let b = e - 1; // last row of the hold
            while ri < reversals.len() && reversals[ri] < a {
                moved.push(reversals[ri]);
                ri += 1;
            }
            let first_inside = ri;
            while ri < reversals.len() && reversals[ri] <= b {
                ri += 1;
            }
            let inside = ri - first_inside;
            let (lo, hi) = values[a..=b]
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), &v| {
                    (l.min(v), u.max(v))
                });
            if hi - lo > h || hi == lo {
                moved.extend(&reversals[first_inside..ri]);
                continue;
            }
            let mut c = values[a..=b].iter().sum::<f64>() / (b - a + 1) as f64;
            // keep the neighbours monotone: the motion into the hold ends at c, the motion out
            // of it starts from c
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
            // reversals inside a hold: the direction changes when the motion resumes (an even
            // number of them cancel out)
            if inside % 2 == 1 {
                moved.push(b);
            }
        }
        moved.extend(&reversals[ri..]);
        moved.dedup();
        moved.retain(|&r| r > 0 && r + 1 < n);
        reversals = moved;
    }

    let changed = values.iter().zip(&raw).any(|(a, b)| a != b);
    Analysis {
        conditioned: Conditioned {
            values,
            noise_sd: sd,
            changed,
        },
        reversals,
        holds,
        ref_rate,
    }
}

/// Moves hold boundaries over the adjacent intervals (at most [`RATE_HALF_WINDOW`] on each
/// side) whose motion is at noise level (`|Δy| ≤ noise_move`) or slower than `threshold`: the
/// windowed rate estimate can shift a boundary by a row when the noise is large.
fn refine_holds(
    t: &[f64],
    y: &[f64],
    holds: &mut [(usize, usize)],
    threshold: f64,
    noise_move: f64,
) {
    let n = y.len();
    let still = |i: usize| {
        let dy = (y[i] - y[i - 1]).abs();
        let dt = t[i] - t[i - 1];
        dy <= noise_move || (dt > 0.0 && dy / dt < threshold)
    };
    for k in 0..holds.len() {
        let prev_end = if k > 0 { holds[k - 1].1 } else { 1 };
        let next_start = holds.get(k + 1).map_or(n, |h| h.0);
        let (mut s, mut e) = holds[k];
        let mut steps = 0;
        while s > prev_end.max(1) && steps < RATE_HALF_WINDOW && still(s - 1) {
            s -= 1;
            steps += 1;
        }
        steps = 0;
        while e < next_start && e < n && steps < RATE_HALF_WINDOW && still(e) {
            e += 1;
            steps += 1;
        }
        holds[k] = (s, e);
    }
}

/// Confirms a hold on the raw data of rows `a..=b`: the least-squares slope must be below
/// `threshold` or not significantly different from zero (4 standard errors, noise `sd`), and
/// significantly below half the sliding rate `ref_rate`. Isotonic fits of a noisy slow ramp
/// have flat blocks that a windowed rate takes for a hold.
fn still_in_raw_data(
    t: &[f64],
    x: &[f64],
    a: usize,
    b: usize,
    threshold: f64,
    ref_rate: f64,
    sd: f64,
) -> bool {
    if b <= a + 1 {
        return true;
    }
    let n = (b - a + 1) as f64;
    let tm = t[a..=b].iter().sum::<f64>() / n;
    let xm = x[a..=b].iter().sum::<f64>() / n;
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for i in a..=b {
        sxx += (t[i] - tm) * (t[i] - tm);
        sxy += (t[i] - tm) * (x[i] - xm);
    }
    if sxx <= 0.0 || sxx.is_nan() {
        return true;
    }
    let slope = (sxy / sxx).abs();
    let se = sd / sxx.sqrt();
    (slope <= threshold || slope <= 4.0 * se)
        && (ref_rate <= 0.0 || slope + 4.0 * se < 0.5 * ref_rate)
}

/// Merges holds that touch, or that are separated only by a motion smaller than the
/// hysteresis threshold `h` within one monotone run.
fn merge_holds(y: &[f64], reversals: &[usize], holds: &mut Vec<(usize, usize)>, h: f64) {
    let mut out: Vec<(usize, usize)> = Vec::with_capacity(holds.len());
    for &(s, e) in holds.iter() {
        if let Some(last) = out.last_mut() {
            let gap_from = last.1 - 1;
            let gap_to = s - 1;
            let reversal_between = reversals.iter().any(|&r| r > gap_from && r < gap_to);
            if s <= last.1 || (!reversal_between && (y[gap_to] - y[gap_from]).abs() <= h) {
                last.1 = last.1.max(e);
                continue;
            }
        }
        out.push((s, e));
    }
    *holds = out;
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

/// Median of |rate| over the intervals `lo..=hi` (interval i joins rows i-1 and i).
fn window_rate(rates: &[f64], lo: usize, hi: usize) -> f64 {
    let mut w: Vec<f64> = rates[lo..=hi].iter().map(|r| r.abs()).collect();
    median(&mut w)
}

/// Finds holds: runs of intervals whose median-filtered |rate| is below
/// `hold_rate_fraction` × the typical sliding rate.
fn find_holds(
    t: &[f64],
    y: &[f64],
    reversals: &[usize],
    opts: &SegmentOptions,
    sd: f64,
) -> (Vec<(usize, usize)>, f64) {
    let n = t.len();
    // rates[i] for the interval (i-1, i]; rates[0] unused
    let mut rates = vec![0.0; n];
    for i in 1..n {
        let dt = t[i] - t[i - 1];
        rates[i] = if dt > 0.0 {
            (y[i] - y[i - 1]) / dt
        } else {
            0.0
        };
    }
    // distance-weighted median of |rate|
    let mut pairs: Vec<(f64, f64)> = (1..n)
        .map(|i| (rates[i].abs(), (y[i] - y[i - 1]).abs()))
        .filter(|(r, w)| r.is_finite() && w.is_finite() && *w > 0.0)
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = pairs.iter().map(|p| p.1).sum();
    let mut acc = 0.0;
    let mut ref_rate = 0.0;
    for (r, w) in &pairs {
        acc += w;
        if acc >= 0.5 * total {
            ref_rate = *r;
            break;
        }
    }
    let threshold = opts.hold_rate_fraction.max(0.0) * ref_rate;
    // run id of each interval, so windows do not straddle a reversal
    let mut run_of = vec![0usize; n];
    let mut k = 0usize;
    let mut ri = 0usize;
    for (i, slot) in run_of.iter_mut().enumerate().skip(1) {
        while ri < reversals.len() && reversals[ri] < i {
            ri += 1;
            k += 1;
        }
        *slot = k;
    }
    let mut hold_like = vec![false; n];
    let mut dts: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let median_dt = median(&mut dts);
    for i in 1..n {
        let mut lo = i.saturating_sub(RATE_HALF_WINDOW).max(1);
        while run_of[lo] != run_of[i] {
            lo += 1;
        }
        let mut hi = (i + RATE_HALF_WINDOW).min(n - 1);
        while run_of[hi] != run_of[i] {
            hi -= 1;
        }
        let m = window_rate(&rates, lo, hi);
        let dt = t[i] - t[i - 1];
        // net motion over the window at noise level, and slow: noise, not sliding
        let net = (y[hi] - y[lo - 1]).abs();
        let span = t[hi] - t[lo - 1];
        let noise_only =
            sd > 0.0 && hi > lo && net <= 4.0 * sd && span > 0.0 && net / span < 0.1 * ref_rate;
        hold_like[i] = if ref_rate <= 0.0 {
            true
        } else {
            m < threshold || noise_only || (rates[i].abs() < threshold && dt > 5.0 * median_dt)
        };
    }
    let mut holds = Vec::new();
    let mut i = 1;
    while i < n {
        if hold_like[i] {
            let s = i;
            while i < n && hold_like[i] {
                i += 1;
            }
            let count = i - s;
            let duration = t[i - 1] - t[s - 1];
            if count >= 3 || duration >= 10.0 * median_dt {
                holds.push((s, i));
            }
        } else {
            i += 1;
        }
    }
    (holds, ref_rate)
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
    fn hysteresis_ignores_small_wiggles() {
        let x = [0.0, 1.0, 2.0, 1.9, 2.1, 3.0, 2.0, 1.0, 1.05, 0.0, 1.0];
        assert_eq!(reversals_hysteresis(&x, 0.5), vec![5, 9]);
    }

    #[test]
    fn hysteresis_with_initial_fall() {
        let x = [0.0, -1.0, -2.0, -1.0, 0.0];
        assert_eq!(reversals_hysteresis(&x, 0.5), vec![2]);
    }

    #[test]
    fn noise_sd_of_white_noise() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let t: Vec<f64> = (0..4000).map(|i| i as f64).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|t| {
                // Box-Muller
                let (u1, u2): (f64, f64) = (rng.gen::<f64>().max(1e-12), rng.gen());
                0.01 * t + 0.002 * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
            })
            .collect();
        let sd = noise_sd(&t, &x);
        assert!((sd - 0.002).abs() < 0.0002, "{sd}");
    }
}
