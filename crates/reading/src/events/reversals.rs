//! Each reversal read on its own: the steady friction of the sliding before and after it, and
//! across reversals how much weaker backward sliding is than forward sliding.

use super::{Estimate, TestView};
use crate::stats::mean_var;
use serde::Serialize;

/// The change of steady friction at one reversal.
#[derive(Clone, Debug, Serialize)]
pub struct ReversalChange {
    /// Test.
    pub test: String,
    /// Row of the reversal.
    pub row: usize,
    /// Direction of the sliding after it (+1 forward, −1 backward).
    pub direction_after: f64,
    /// |friction| of the steady sliding before the reversal.
    pub before: f64,
    /// |friction| of the steady sliding after it.
    pub after: f64,
    /// after − before, with its uncertainty.
    pub change: Estimate,
}

/// Forward against backward sliding over all reversals.
#[derive(Clone, Debug, Serialize)]
pub struct DirectionAsymmetry {
    /// Reversals used.
    pub reversals: usize,
    /// d = 1 − |μ backward| / μ forward, from the levels after the reversals (95 % interval).
    pub backward_weakening: Estimate,
}

/// Share of a stretch of sliding, at its end, that gives its steady level.
const STEADY_SHARE: f64 = 0.3;

/// Every reversal of a slip-controlled test with sliding on both sides.
pub(super) fn reversals(t: &TestView) -> Vec<ReversalChange> {
    let seg = t.segmentation;
    let mut bounds: Vec<usize> = seg.reversals.clone();
    bounds.extend(seg.rate_changes.iter().map(|r| r + 1));
    for &(s, e) in &seg.holds {
        bounds.push(s);
        bounds.push(e);
    }
    bounds.push(0);
    bounds.push(t.time.len());
    bounds.sort_unstable();
    bounds.dedup();
    let level = |from: usize, to: usize| -> Option<(f64, f64, f64)> {
        let n = to.saturating_sub(from);
        if n < 6 {
            return None;
        }
        let start = to - ((n as f64 * STEADY_SHARE).ceil() as usize).max(3);
        let vals: Vec<f64> = (start..to).map(|i| t.friction(i).abs()).collect();
        let m = vals.iter().sum::<f64>() / vals.len() as f64;
        let sign = (t.slip[to - 1] - t.slip[from]).signum();
        Some((m, sign, t.noise_friction / (vals.len() as f64).sqrt()))
    };
    let mut out = Vec::new();
    for &r in &seg.reversals {
        let i = bounds.partition_point(|&b| b < r);
        let (Some(&prev), Some(&next)) = (bounds.get(i.wrapping_sub(1)), bounds.get(i + 1)) else {
            continue;
        };
        let (Some(b), Some(a)) = (level(prev, r), level(r, next)) else {
            continue;
        };
        if a.1 == 0.0 || a.1 == b.1 {
            continue;
        }
        let se = (a.2 * a.2 + b.2 * b.2).sqrt();
        out.push(ReversalChange {
            test: t.name.to_string(),
            row: r,
            direction_after: a.1,
            before: b.0,
            after: a.0,
            change: Estimate::symmetric(a.0 - b.0, 1.96 * se),
        });
    }
    out
}

/// d = 1 − mean backward level / mean forward level, with a 95 % interval from the scatter of
/// the levels.
pub(super) fn asymmetry(changes: &[ReversalChange]) -> Option<DirectionAsymmetry> {
    let fwd: Vec<f64> = changes
        .iter()
        .filter(|c| c.direction_after > 0.0)
        .map(|c| c.after)
        .collect();
    let bwd: Vec<f64> = changes
        .iter()
        .filter(|c| c.direction_after < 0.0)
        .map(|c| c.after)
        .collect();
    if fwd.is_empty() || bwd.is_empty() {
        return None;
    }
    let stats = |v: &[f64]| {
        let (m, var) = mean_var(v);
        (m, var / v.len() as f64)
    };
    let (mf, vf) = stats(&fwd);
    let (mb, vb) = stats(&bwd);
    if mf <= 0.0 {
        return None;
    }
    let d = 1.0 - mb / mf;
    // δd ≈ (mb/mf) √(vb/mb² + vf/mf²); with one level on a side the scatter is unknown.
    let se = if fwd.len() > 1 && bwd.len() > 1 {
        (mb / mf) * (vb / (mb * mb) + vf / (mf * mf)).sqrt()
    } else {
        f64::INFINITY
    };
    Some(DirectionAsymmetry {
        reversals: changes.len(),
        backward_weakening: Estimate::symmetric(d, 1.96 * se),
    })
}
