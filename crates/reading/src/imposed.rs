//! Events of the imposed column, found at the resolution of the data: reversals of the
//! direction, holds, and the rate levels between velocity steps.
//!
//! Real records jitter, change their sampling rate with the sliding rate and quantise the
//! displacement, so no event is read off one row or a fixed number of rows:
//!
//! - the **resolution** of the column is its noise SD and quantisation step, and the band
//!   `max(10 SD, 2.5 steps)` is the smallest motion taken for real;
//! - a **reversal** is a move back by more than the band (hysteresis);
//! - a **hold** is a stretch that stays still — within the band plus a drift of a twentieth of
//!   the slowest sliding rate — for at least the time the slowest sliding would need to cross
//!   five bands (so it must last);
//! - **rates** are measured over chunks of travel that are long against the band (not over rows
//!   or seconds), and a **velocity step** is a change between levels of at least the rate ratio
//!   that persists over several chunks on both sides and happens at once (a ramp is no step).
//!
//! Boundaries are then placed where the straight lines fitted to the two sides intersect.

use crate::noise::{estimate_noise, NoiseEstimate};
use crate::stats::median;
use serde::{Deserialize, Serialize};

/// Options of the event detection and segmentation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SegmentOptions {
    /// Slip (mm) after a start, step, hold or reversal labelled as a transient. Default 0.2.
    pub transient_mm: f64,
    /// A sliding-rate change by at least this factor is a velocity step. Default 2.0.
    pub rate_ratio: f64,
    /// A hold drifts by less than this fraction of the slowest sliding rate. Default 0.05.
    pub hold_rate_fraction: f64,
    /// Chunks of travel over which rates are measured, in bands. Default 10.
    pub chunk_bands: f64,
    /// A velocity level must last at least this many chunks. Default 3.
    pub min_level_chunks: usize,
}

impl Default for SegmentOptions {
    fn default() -> Self {
        SegmentOptions {
            transient_mm: 0.2,
            rate_ratio: 2.0,
            hold_rate_fraction: 0.05,
            chunk_bands: 10.0,
            min_level_chunks: 3,
        }
    }
}

/// Hysteresis threshold in noise SDs: a reversal is real when the column moves back by more
/// than this many SDs.
pub const REVERSAL_SDS: f64 = 10.0;

/// The smallest motion of the imposed column taken for real, from its noise and quantisation.
pub fn band_of(noise: &NoiseEstimate) -> f64 {
    let sd = if noise.floor { 0.0 } else { noise.sd };
    (REVERSAL_SDS * sd).max(2.5 * noise.quantum).max(1e-12)
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
                    dir = if imax > imin { 1 } else { -1 };
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

pub(crate) fn median3(x: &[f64]) -> Vec<f64> {
    let n = x.len();
    (0..n)
        .map(|i| {
            if i == 0 || i + 1 == n {
                x[i]
            } else {
                median(&mut [x[i - 1], x[i], x[i + 1]]).unwrap_or(x[i])
            }
        })
        .collect()
}

/// Direction (+1 / -1) of each run between consecutive bounds, from the values at its ends.
pub(crate) fn run_directions(x: &[f64], bounds: &[usize]) -> Vec<i8> {
    bounds
        .windows(2)
        .map(|w| if x[w[1]] >= x[w[0]] { 1 } else { -1 })
        .collect()
}

/// Reversals of a noisy column: hysteresis on a median-of-3 copy (spikes), each refined to the
/// raw extreme next to it.
pub(crate) fn reversals(raw: &[f64], band: f64, noisy: bool) -> Vec<usize> {
    let n = raw.len();
    if !noisy {
        return reversals_hysteresis(raw, band);
    }
    let f = median3(raw);
    let revs = reversals_hysteresis(&f, band);
    let mut bounds: Vec<usize> = vec![0];
    bounds.extend(&revs);
    bounds.push(n - 1);
    let dirs = run_directions(&f, &bounds);
    let mut out: Vec<usize> = Vec::with_capacity(revs.len());
    for (k, &r) in revs.iter().enumerate() {
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
}

/// A stretch of rows `start..=end` moving `travel` in `duration`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Chunk {
    pub start: usize,
    pub end: usize,
    pub travel: f64,
    pub duration: f64,
}

impl Chunk {
    pub fn rate(&self) -> f64 {
        if self.duration > 0.0 {
            self.travel / self.duration
        } else {
            0.0
        }
    }
}

/// Splits rows `from..=to` into consecutive chunks (sharing their end rows) that each move at
/// least `travel`; a short remainder joins the last chunk.
pub(crate) fn chunks(t: &[f64], y: &[f64], from: usize, to: usize, travel: f64) -> Vec<Chunk> {
    let mut out: Vec<Chunk> = Vec::new();
    if to <= from {
        return out;
    }
    let mut s = from;
    for i in from + 1..=to {
        if (y[i] - y[s]).abs() >= travel || i == to {
            out.push(Chunk {
                start: s,
                end: i,
                travel: (y[i] - y[s]).abs(),
                duration: t[i] - t[s],
            });
            s = i;
        }
    }
    if out.len() >= 2 && out[out.len() - 1].travel < 0.5 * travel {
        let last = out.pop().expect("two chunks");
        let prev = out.last_mut().expect("one chunk left");
        prev.end = last.end;
        prev.travel = (y[prev.end] - y[prev.start]).abs();
        prev.duration = t[prev.end] - t[prev.start];
    }
    out
}

/// The `q`-quantile of chunk rates weighted by travel (the rate at which that share of the
/// distance was covered).
pub(crate) fn travel_quantile(chunks: &[Chunk], q: f64) -> f64 {
    let mut pairs: Vec<(f64, f64)> = chunks
        .iter()
        .map(|c| (c.rate(), c.travel))
        .filter(|(r, w)| r.is_finite() && *r > 0.0 && *w > 0.0)
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = pairs.iter().map(|p| p.1).sum();
    let mut acc = 0.0;
    for (r, w) in &pairs {
        acc += w;
        if acc >= q * total {
            return *r;
        }
    }
    pairs.last().map_or(0.0, |p| p.0)
}

/// Least-squares line y = a + b t through rows `rows`.
fn line(t: &[f64], y: &[f64], rows: std::ops::RangeInclusive<usize>) -> Option<(f64, f64)> {
    let l = crate::stats::fit_line(&t[rows.clone()], &y[rows])?;
    Some((l.intercept, l.slope))
}

/// The row where two straight pieces meet: the row nearest to the intersection of the lines
/// fitted to `left` and `right`, kept within `lo..=hi`; `fallback` when the lines are parallel
/// or meet outside.
fn corner(
    t: &[f64],
    y: &[f64],
    left: std::ops::RangeInclusive<usize>,
    right: std::ops::RangeInclusive<usize>,
    (lo, hi): (usize, usize),
    fallback: usize,
) -> usize {
    let (Some((a1, b1)), Some((a2, b2))) = (line(t, y, left), line(t, y, right)) else {
        return fallback;
    };
    if (b1 - b2).abs() <= 1e-12 * (b1.abs() + b2.abs()) {
        return fallback;
    }
    let ts = (a2 - a1) / (b1 - b2);
    if !(ts >= t[lo] && ts <= t[hi]) {
        return fallback;
    }
    let k = lo + t[lo..=hi].partition_point(|&v| v <= ts);
    // t[k - 1] <= ts < t[k]: the nearer of the two.
    if k > lo && (k > hi || ts - t[k - 1] <= t[k] - ts) {
        k - 1
    } else {
        k.min(hi)
    }
}

/// Holds as half-open row ranges `[start, end)` (the rows whose incoming interval is still):
/// stretches that stay within `band` plus a drift of `v_hold` for at least `min_duration`.
pub(crate) fn holds(
    t: &[f64],
    y: &[f64],
    band: f64,
    v_hold: f64,
    min_duration: f64,
) -> Vec<(usize, usize)> {
    let n = t.len();
    if n < 3 {
        return Vec::new();
    }
    // covered_to[i] = j when the window from row i over `min_duration` (ending at row j) stays
    // within the tolerance; both ends only move forward and the window's extremes are kept in
    // monotone queues, so the scan is linear in the rows.
    let mut covered_to: Vec<usize> = vec![0; n];
    let mut maxq: std::collections::VecDeque<usize> = Default::default();
    let mut minq: std::collections::VecDeque<usize> = Default::default();
    let mut j = 0usize;
    let mut pushed = 0usize;
    for i in 0..n {
        while maxq.front().is_some_and(|&k| k < i) {
            maxq.pop_front();
        }
        while minq.front().is_some_and(|&k| k < i) {
            minq.pop_front();
        }
        // The shortest window from row i that lasts `min_duration`.
        j = j.max(i);
        while j + 1 < n && t[j] - t[i] < min_duration {
            j += 1;
        }
        while pushed <= j {
            let v = y[pushed];
            while maxq.back().is_some_and(|&k| y[k] <= v) {
                maxq.pop_back();
            }
            maxq.push_back(pushed);
            while minq.back().is_some_and(|&k| y[k] >= v) {
                minq.pop_back();
            }
            minq.push_back(pushed);
            pushed += 1;
        }
        if t[j] - t[i] < 0.999 * min_duration || j == i {
            continue;
        }
        let (Some(&hi), Some(&lo)) = (maxq.front(), minq.front()) else {
            continue;
        };
        if y[hi] - y[lo] <= band + v_hold * (t[j] - t[i]) {
            covered_to[i] = j;
        }
    }
    // Union of still windows.
    let mut out: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < n {
        if covered_to[i] == 0 {
            i += 1;
            continue;
        }
        let s = i;
        let mut e = covered_to[i];
        let mut k = i;
        while k <= e && k < n {
            e = e.max(covered_to[k]);
            k += 1;
        }
        out.push((s, e));
        i = e + 1;
    }
    // Sharpen the ends where the lines of the motion and of the hold meet.
    let spans: Vec<(usize, usize)> = out.clone();
    for (k, (s, e)) in out.iter_mut().enumerate() {
        let prev_end = if k > 0 { spans[k - 1].1 } else { 0 };
        let next_start = spans.get(k + 1).map_or(n - 1, |h| h.0);
        let (s0, e0) = (*s, *e);
        let inner = (s0 + (e0 - s0) / 4, e0 - (e0 - s0) / 4);
        if s0 > prev_end + 2 {
            let before = motion_window(t, y, s0, prev_end, band, false);
            *s = corner(t, y, before..=s0, inner.0..=inner.1, (before, inner.0), s0);
        }
        if e0 + 2 < next_start {
            let after = motion_window(t, y, e0, next_start, band, true);
            *e = corner(t, y, inner.0..=inner.1, e0..=after, (inner.1, after), e0);
        }
    }
    out.retain(|(s, e)| e > s);
    out.into_iter().map(|(s, e)| (s + 1, e + 1)).collect()
}

/// The row a motion window of some ten bands reaches from `from`, not beyond `limit`.
fn motion_window(
    t: &[f64],
    y: &[f64],
    from: usize,
    limit: usize,
    band: f64,
    forward: bool,
) -> usize {
    let _ = t;
    let want = 10.0 * band;
    let mut k = from;
    if forward {
        while k < limit && (y[k] - y[from]).abs() < want {
            k += 1;
        }
    } else {
        while k > limit && (y[from] - y[k]).abs() < want {
            k -= 1;
        }
    }
    k
}

/// Velocity levels of the sliding stretch `p..=q` (one monotone run, no hold) from chunks of
/// travel `travel`; returns the rows of the velocity steps (last row at the old rate).
pub(crate) fn velocity_steps(
    t: &[f64],
    y: &[f64],
    p: usize,
    q: usize,
    travel: f64,
    opts: &SegmentOptions,
) -> Vec<usize> {
    let cs = chunks(t, y, p, q, travel);
    if cs.len() < 2 * opts.min_level_chunks {
        return Vec::new();
    }
    let lr = opts.rate_ratio.max(1.0 + 1e-9).ln();
    let lnv: Vec<f64> = cs.iter().map(|c| c.rate().max(1e-300).ln()).collect();
    // Bottom-up: merge the closest neighbours while they differ by less than the ratio.
    let mut groups: Vec<(usize, usize)> = (0..cs.len()).map(|k| (k, k)).collect();
    let group_rate = |g: (usize, usize)| -> f64 {
        let travel: f64 = cs[g.0..=g.1].iter().map(|c| c.travel).sum();
        let duration: f64 = cs[g.0..=g.1].iter().map(|c| c.duration).sum();
        if duration > 0.0 {
            (travel / duration).max(1e-300).ln()
        } else {
            0.0
        }
    };
    loop {
        let mut best: Option<(usize, f64)> = None;
        for k in 0..groups.len().saturating_sub(1) {
            let d = (group_rate(groups[k]) - group_rate(groups[k + 1])).abs();
            let short = groups[k].1 - groups[k].0 + 1 < opts.min_level_chunks
                || groups[k + 1].1 - groups[k + 1].0 + 1 < opts.min_level_chunks;
            // Too short to be a level: a transition, merged first.
            let key = if short { d - 1e3 } else { d };
            if key < lr && best.is_none_or(|b| key < b.1) {
                best = Some((k, key));
            }
        }
        let Some((k, _)) = best else { break };
        groups[k].1 = groups[k + 1].1;
        groups.remove(k + 1);
    }
    // A boundary is a step only if the change happens at once: across the three chunks around
    // it, not spread over the levels (a ramp).
    let mut steps = Vec::new();
    for w in groups.windows(2) {
        let (a, b) = (w[0], w[1]);
        let level_change = group_rate(b) - group_rate(a);
        let k = b.0;
        let across = lnv[(k + 1).min(b.1)] - lnv[k.saturating_sub(2).max(a.0)];
        if across.abs() < 0.7 * level_change.abs() || level_change.abs() < lr {
            continue;
        }
        // The step row: where the lines of the two levels meet, away from the transition.
        let left_end = cs[k.saturating_sub(1).max(a.0)].start;
        let right_start = cs[(k + 1).min(b.1)].start;
        let left = cs[a.0].start..=left_end.max(cs[a.0].start + 1);
        let right = right_start..=cs[b.1].end;
        let fallback = cs[k].start;
        let lo = cs[k.saturating_sub(1).max(a.0)].start;
        let hi = cs[(k + 1).min(b.1)].end;
        steps.push(corner(t, y, left, right, (lo, hi), fallback));
    }
    steps.dedup();
    steps
}

/// What the event detection found in one column.
#[derive(Clone, Debug)]
pub(crate) struct Events {
    pub noise: NoiseEstimate,
    pub band: f64,
    pub reversals: Vec<usize>,
    pub holds: Vec<(usize, usize)>,
    /// Distance-weighted median rate of the sliding (per s).
    pub ref_rate: f64,
    /// Slowest sliding rate (3 % of the distance was covered more slowly), per s.
    pub slow_rate: f64,
    /// Travel of a rate chunk.
    pub chunk_travel: f64,
}

/// Reversals, holds and the rates of the raw column `x` sampled at `t`.
pub(crate) fn detect(t: &[f64], x: &[f64], opts: &SegmentOptions) -> Events {
    let n = t.len().min(x.len());
    let noise = estimate_noise(&t[..n], &x[..n]);
    let band = band_of(&noise);
    let finite = x[..n].iter().chain(&t[..n]).all(|v| v.is_finite());
    let mut ev = Events {
        noise,
        band,
        reversals: Vec::new(),
        holds: Vec::new(),
        ref_rate: 0.0,
        slow_rate: 0.0,
        chunk_travel: 0.0,
    };
    if n < 3 || !finite {
        return ev;
    }
    let noisy = noise.sd > 0.0 || noise.quantum > 0.0;
    let revs = reversals(&x[..n], band, noisy);
    // Rates from chunks of travel long against the band, run by run.
    let span = x[..n].windows(2).map(|w| (w[1] - w[0]).abs()).sum::<f64>();
    let chunk_travel = (opts.chunk_bands * band).max(span / 4000.0);
    let smooth = if noisy {
        median3(&x[..n])
    } else {
        x[..n].to_vec()
    };
    let mut all_chunks = Vec::new();
    let mut bounds = vec![0];
    bounds.extend(&revs);
    bounds.push(n - 1);
    for w in bounds.windows(2) {
        all_chunks.extend(chunks(t, &smooth, w[0], w[1], chunk_travel));
    }
    ev.ref_rate = travel_quantile(&all_chunks, 0.5);
    ev.slow_rate = travel_quantile(&all_chunks, 0.03);
    ev.chunk_travel = chunk_travel;
    let mut dts: Vec<f64> = t[..n].windows(2).map(|w| w[1] - w[0]).collect();
    let median_dt = median(&mut dts).unwrap_or(0.0);
    let min_duration = if ev.slow_rate > 0.0 {
        (5.0 * band / ev.slow_rate).max(3.0 * median_dt)
    } else {
        3.0 * median_dt
    };
    let found = holds(
        t,
        &smooth,
        band,
        opts.hold_rate_fraction * ev.slow_rate,
        min_duration,
    );
    let revs = persistent_reversals(&smooth, &revs, 3.0 * band);
    ev.holds = holds_after_unloads(&smooth, &revs, merge_holds(t, &smooth, found, band), band);
    let (holds, added) = backed_off_holds(&x[..n], &revs, std::mem::take(&mut ev.holds), &noise);
    ev.holds = holds;
    let mut revs = revs;
    revs.extend(added);
    revs.sort_unstable();
    revs.dedup();
    ev.reversals = reversals_outside_holds(&smooth, &revs, &ev.holds, n, band);
    ev
}

/// Joins holds separated by a disturbance shorter than either and with no net motion beyond
/// the band between their median positions (a glitch of the transducer, a range reset): the
/// hold goes on through it.
fn merge_holds(t: &[f64], y: &[f64], holds: Vec<(usize, usize)>, band: f64) -> Vec<(usize, usize)> {
    let position = |s: usize, e: usize| median(&mut y[s - 1..e].to_vec()).unwrap_or(0.0);
    let mut out: Vec<(usize, usize)> = Vec::with_capacity(holds.len());
    for (s, e) in holds {
        if let Some(last) = out.last_mut() {
            let (end_prev, start_next) = (last.1 - 1, s - 1);
            let gap = t[start_next] - t[end_prev];
            let before = t[end_prev] - t[last.0 - 1];
            let after = t[e - 1] - t[start_next];
            let moved = (position(s, e) - position(last.0, last.1)).abs();
            if gap < before.min(after) && moved <= 2.0 * band {
                last.1 = e;
                continue;
            }
        }
        out.push((s, e));
    }
    out
}

/// Holds that begin with an unload: a rig that unloads slowly (the load point backed off by the
/// elastic travel of the shear, at a few percent of the sliding rate) and then holds looks still
/// at the scale of the sliding. A reversal inside a hold followed by a backward travel of more
/// than three bands is an unload, not drift: the hold starts where that travel ends, so that the
/// reversal and the unload stay in the record (and the reload after the hold reverses again);
/// a hold that the unload outlasts is part of it and is dropped.
fn holds_after_unloads(
    y: &[f64],
    revs: &[usize],
    holds: Vec<(usize, usize)>,
    band: f64,
) -> Vec<(usize, usize)> {
    let mut out = Vec::with_capacity(holds.len());
    for (s, e) in holds {
        let (a, b) = (s - 1, e - 1);
        let Some(&r) = revs.iter().find(|&&r| r >= a && r < b) else {
            out.push((s, e));
            continue;
        };
        // The motion before the reversal sets the forward direction; the unload goes the other way.
        let forward = if r > 0 {
            (y[r] - y[r - 1]).signum()
        } else {
            0.0
        };
        let back = |k: usize| -forward * (y[k] - y[r]);
        // A hold that starts at the reversal may be a still-looking stretch at the turning point
        // of a slowly sampled unload: the unload then goes on past the hold's end, so follow it
        // up to the next reversal (a hold that ends at a reversal is followed by its unload).
        let unload_end = if r <= a + 1 {
            revs.iter()
                .copied()
                .find(|&q| q > r)
                .unwrap_or(y.len() - 1)
                .max(b)
        } else {
            b
        };
        let furthest = (r..=unload_end)
            .max_by(|&i, &j| back(i).total_cmp(&back(j)))
            .unwrap_or(r);
        if forward == 0.0 || back(furthest) <= 3.0 * band {
            out.push((s, e));
            continue;
        }
        // The unload ends where the position first comes within a band of its furthest point.
        let end = (r..=furthest)
            .find(|&k| back(furthest) - back(k) <= band)
            .unwrap_or(furthest);
        if end + 1 < b {
            out.push((end + 1, e));
        }
    }
    out
}

/// Holds whose load point backs off inside them: an unload shorter than the reversal band (a
/// few µm of elastic travel in a noisy column) and slow enough to pass for stillness. The
/// position the hold settles at (the median of its second half) is compared with where the
/// motion into it ended (the median of its first rows); when it lies back by more than six SDs
/// of that difference, the furthest forward row before the back-off is a reversal, the hold
/// starts where the back-off has reached its level, and the reload after it reverses again. Returns the holds
/// and the reversals to add.
fn backed_off_holds(
    x: &[f64],
    revs: &[usize],
    holds: Vec<(usize, usize)>,
    noise: &NoiseEstimate,
) -> (Vec<(usize, usize)>, Vec<usize>) {
    /// Rows for where the motion ended.
    const FIRST: usize = 3;
    let sd = noise.sd.max(noise.quantum / 12f64.sqrt());
    let mut out = Vec::with_capacity(holds.len());
    let mut added = Vec::new();
    for (k, &(s, e)) in holds.iter().enumerate() {
        let (a, b) = (s - 1, e - 1);
        let run_start = revs
            .iter()
            .filter(|&&r| r < a)
            .copied()
            .chain(k.checked_sub(1).map(|j| holds[j].1 - 1))
            .max()
            .unwrap_or(0);
        let rows = b + 1 - a;
        let forward = (x[a.saturating_sub(1)] - x[run_start]).signum();
        if rows < 2 * FIRST + 3 || forward == 0.0 || revs.iter().any(|&r| r >= a && r <= b) {
            out.push((s, e));
            continue;
        }
        let second_half = a + rows / 2;
        let settled = median(&mut x[second_half..=b].to_vec()).unwrap_or(0.0);
        let ended = median(&mut x[a..a + FIRST].to_vec()).unwrap_or(0.0);
        let back = -forward * (settled - ended);
        let m = (b + 1 - second_half) as f64;
        let sd_diff = 1.25 * sd * (1.0 / FIRST as f64 + 1.0 / m).sqrt();
        if back <= (6.0 * sd_diff).max(2.5 * noise.quantum) {
            out.push((s, e));
            continue;
        }
        // The hold starts at the first row within two row SDs (or a quantum) of its level.
        let near = (2.0 * sd).max(noise.quantum);
        let start = (a..=b)
            .find(|&i| {
                (-forward * (x[i] - ended) - back).abs() <= near && -forward * (x[i] - ended) > 0.0
            })
            .unwrap_or(a);
        // The reversal: the furthest forward row between the end of the motion and the level.
        let from = a.saturating_sub(1).max(run_start);
        let peak = (from..=start.max(from))
            .max_by(|&i, &j| (forward * x[i]).total_cmp(&(forward * x[j])))
            .unwrap_or(from);
        added.push(peak);
        if start + 2 < b {
            out.push((start + 1, e));
        }
    }
    (out, added)
}

/// Drops reversals that do not persist: a run between two reversals that travels less than
/// `min_travel` (a glitch back and forth) is part of the run around it.
fn persistent_reversals(y: &[f64], revs: &[usize], min_travel: f64) -> Vec<usize> {
    let mut out: Vec<usize> = revs.to_vec();
    loop {
        let short = out
            .windows(2)
            .enumerate()
            .map(|(k, w)| (k, (y[w[1]] - y[w[0]]).abs()))
            .filter(|(_, d)| *d < min_travel)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match short {
            Some((k, _)) => {
                out.drain(k..k + 2);
            }
            None => break,
        }
    }
    out
}

/// Reversals with those inside holds replaced: a hold's drift is no reversal, but a hold between
/// opposite motions (an unload, a hold, a reload) reverses where the motion resumes.
fn reversals_outside_holds(
    y: &[f64],
    revs: &[usize],
    holds: &[(usize, usize)],
    n: usize,
    band: f64,
) -> Vec<usize> {
    let inside = |r: usize| holds.iter().position(|&(s, e)| r + 1 >= s && r < e);
    // A reversal has motion on both sides: the first and last rows are none (a column that
    // starts by moving back from its first reading has that reading as its extreme).
    let mut out: Vec<usize> = revs
        .iter()
        .copied()
        .filter(|&r| r > 0 && r + 1 < n && inside(r).is_none())
        .collect();
    for (k, &(s, e)) in holds.iter().enumerate() {
        let (a, b) = (s - 1, (e - 1).min(n - 1));
        let prev_rev = out.iter().rev().find(|&&r| r < a).map_or(0, |&r| r).min(a);
        let next_rev = out.iter().find(|&&r| r > b).map_or(n - 1, |&r| r).max(b);
        // The runs next to the hold end at the previous reversal or hold and at the next one (a
        // load point that backs off between two short holds reverses twice); when such a run
        // moves less than the band, the motion up to the previous or next reversal decides.
        let prev_hold_end = k.checked_sub(1).map_or(0, |j| (holds[j].1 - 1).min(n - 1));
        let next_hold_start = holds.get(k + 1).map_or(n - 1, |h| h.0 - 1);
        let near_before = y[a] - y[prev_rev.max(prev_hold_end).min(a)];
        let near_after = y[next_rev.min(next_hold_start).max(b)] - y[b];
        let before = if near_before.abs() > band {
            near_before
        } else {
            y[a] - y[prev_rev]
        };
        let after = if near_after.abs() > band {
            near_after
        } else {
            y[next_rev] - y[b]
        };
        if before * after < 0.0 && b > 0 && b + 1 < n {
            out.push(b);
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

#[cfg(test)]
#[path = "imposed_tests.rs"]
mod tests;
