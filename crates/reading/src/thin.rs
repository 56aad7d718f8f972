//! Rows that carry the information: a long record is fitted on bins of rows, so that a dense
//! steady stretch does not cost what a transient costs.
//!
//! Each segment of the test (initial loading, the transient after a velocity step, a hold, the
//! reload after it, a reversal, steady sliding) is cut into bins: transients into many bins of
//! equal imposed travel, holds into bins of equal log-time from the start of the hold (their
//! relaxation is logarithmic), steady sliding into few. The first and last row of every segment
//! are bins of their own, so the imposed path keeps its corners (events) exactly. A bin stands
//! for its rows: it is simulated at its middle row and compared with the mean of its
//! measurements, weighted by its size — the weighted least squares stays an honest estimate of
//! the least squares over all rows (the misfit on all rows is reported separately).

use crate::fit_test::FitTest;
use crate::{SegmentKind, Segmentation};

/// Bins per segment before scaling to the budget, by kind.
fn base_bins(kind: SegmentKind) -> f64 {
    match kind {
        SegmentKind::SteadySliding => 40.0,
        SegmentKind::Hold => 60.0,
        _ => 120.0,
    }
}

/// Fewest interior bins of a segment.
const MIN_BINS: f64 = 6.0;

/// A thinned test: the bins' representative rows (full-record indices) and their sizes.
#[derive(Clone, Debug, PartialEq)]
pub struct Bins {
    /// Half-open row ranges of the bins, consecutive, covering every row.
    pub ranges: Vec<(usize, usize)>,
}

impl Bins {
    /// Number of bins.
    pub fn len(&self) -> usize {
        self.ranges.len()
    }

    /// True when there are no bins.
    pub fn is_empty(&self) -> bool {
        self.ranges.is_empty()
    }

    /// The row that stands for each bin: its middle row.
    pub fn representatives(&self) -> Vec<usize> {
        self.ranges.iter().map(|&(a, b)| (a + b - 1) / 2).collect()
    }
}

/// Interior bins of rows `a..b` (exclusive of the segment's first and last rows), `count` of
/// them, cut at equal steps of `key` (monotone over the rows).
fn split_by(key: &[f64], a: usize, b: usize, count: usize, out: &mut Vec<(usize, usize)>) {
    if b <= a {
        return;
    }
    if count <= 1 || b - a <= count {
        // Few rows: each its own bin.
        if b - a <= count {
            out.extend((a..b).map(|i| (i, i + 1)));
        } else {
            out.push((a, b));
        }
        return;
    }
    let (k0, k1) = (key[a], key[b - 1]);
    let mut start = a;
    for j in 1..=count {
        let edge = k0 + (k1 - k0) * j as f64 / count as f64;
        let mut end = start;
        while end < b && (key[end] <= edge || j == count) {
            end += 1;
        }
        if end > start {
            out.push((start, end));
            start = end;
        }
    }
    if start < b {
        out.push((start, b));
    }
}

/// Bins of one test with `scale` × the base number of bins per segment.
pub fn bins(test: &FitTest, seg: &Segmentation, scale: f64) -> Bins {
    let n = test.len();
    let travel: Vec<f64> = {
        // Cumulative |imposed| travel: monotone, so equal steps of it are equal travel.
        let mut acc = 0.0;
        let mut v = Vec::with_capacity(n);
        for i in 0..n {
            if i > 0 {
                acc += (test.imposed[i] - test.imposed[i - 1]).abs();
            }
            v.push(acc);
        }
        v
    };
    let mut ranges = Vec::new();
    for s in &seg.segments {
        let (a, b) = (s.start.min(n), s.end.min(n));
        if b <= a {
            continue;
        }
        ranges.push((a, a + 1));
        if b - a == 1 {
            continue;
        }
        let count = (base_bins(s.kind) * scale).max(MIN_BINS).round() as usize;
        if s.kind == SegmentKind::Hold {
            // Log-time from the start of the hold (the last moving row).
            let t0 = test.time[a.saturating_sub(1)];
            let first = (test.time[a] - t0).max(1e-9);
            let key: Vec<f64> = (0..n)
                .map(|i| {
                    if i < a || i >= b {
                        0.0
                    } else {
                        ((test.time[i] - t0).max(first) / first).ln()
                    }
                })
                .collect();
            split_by(&key, a + 1, b - 1, count, &mut ranges);
        } else {
            split_by(&travel, a + 1, b - 1, count, &mut ranges);
        }
        ranges.push((b - 1, b));
    }
    ranges.sort_unstable();
    ranges.dedup();
    Bins { ranges }
}

/// The test seen through `bins`: one row per bin at its middle row, the bin's mean measurement,
/// weighted by its size.
pub fn thin_test(test: &FitTest, bins: &Bins) -> FitTest {
    let reps = bins.representatives();
    let mut t = test.clone();
    t.time = reps.iter().map(|&i| test.time[i]).collect();
    t.imposed = reps.iter().map(|&i| test.imposed[i]).collect();
    t.normal = reps.iter().map(|&i| test.normal[i]).collect();
    t.measured = bins
        .ranges
        .iter()
        .map(|&(a, b)| test.measured[a..b].iter().sum::<f64>() / (b - a) as f64)
        .collect();
    t.row_weight = bins.ranges.iter().map(|&(a, b)| (b - a) as f64).collect();
    // A bin's row may not repeat the time of the one before (equal middle rows cannot happen
    // for disjoint bins; this keeps the protocol valid whatever the input).
    t.fit_rows = 0..usize::MAX;
    t
}

/// The scale of the base bin counts whose bins come closest to `budget` rows without
/// exceeding it (below 1 for a long record, above 1 for a short one).
pub fn scale_for_budget(test: &FitTest, seg: &Segmentation, budget: usize) -> f64 {
    let (mut lo, mut hi) = (1e-3f64, 1e3f64);
    for _ in 0..30 {
        let mid = (lo * hi).sqrt();
        if bins(test, seg, mid).len() <= budget {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi / lo < 1.05 {
            break;
        }
    }
    lo
}
