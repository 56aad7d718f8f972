//! Held-out evidence where whole-test effects live: what a lab reads off each first loading.
//!
//! A pressure effect or a slow trend with slip acts on whole tests. A monotonic test is one
//! held-out piece, and its misfit is smooth, so the piece-by-piece likelihood ratio
//! ([`crate::score`]) counts it once per correlation length: a candidate that brings three
//! held-out tests from hundreds of times the noise to the noise gains a handful of points of
//! evidence there, never the 20 a verdict needs. A geotechnical lab judges such an effect on the
//! tests' readings instead — the peak stress ratio, the residual and the residual's slope with
//! slip — against the scatter between specimens. So each held-out first loading is read as the
//! record is read ([`subfric_fit::loading_levels`]): the measured readings with their
//! uncertainty (their noise, and never less than what two specimens of one soil tested alike
//! differ by), and the same readings off each model's prediction of the held-out loading. The
//! evidence is the difference of the two models' squared standardised errors summed over the
//! readings, a likelihood ratio in deviance units like D: independent specimens, one reading
//! each.

use crate::folds::{Piece, PieceKind};
use crate::score::HeldOut;
use std::collections::BTreeMap;
use subfric_fit::levels::REPRODUCIBILITY_SHARE;
use subfric_fit::{loading_levels, FitTest, TestLevels};

/// Two-sided 95 % quantile of the normal distribution (the readings' intervals are 95 %).
const Z95: f64 = 1.959_964;

/// What one held-out first loading shows, with each reading's standard deviation.
#[derive(Clone, Debug)]
struct Entry {
    end: usize,
    peak: Option<(f64, f64)>,
    residual: Option<(f64, f64)>,
    slope: Option<(f64, f64)>,
}

/// The readings of every first-loading piece, keyed by (test, first row).
#[derive(Clone, Debug, Default)]
pub struct Readings {
    entries: BTreeMap<(usize, usize), Entry>,
}

/// A reading and its standard deviation, from its 95 % interval.
fn with_sd(e: Option<subfric_fit::Estimate>) -> Option<(f64, f64)> {
    let e = e?;
    let sd = e.half_width() / Z95;
    (e.value.is_finite() && sd.is_finite() && sd > 0.0).then_some((e.value, sd))
}

/// Rows `start..end` of `t`, with `measured` replaced where given.
fn slice(t: &FitTest, start: usize, end: usize, measured: Option<Vec<f64>>) -> FitTest {
    let mut s = t.clone();
    s.time = t.time[start..end].to_vec();
    s.imposed = t.imposed[start..end].to_vec();
    s.normal = t.normal[start..end].to_vec();
    s.measured = measured.unwrap_or_else(|| t.measured[start..end].to_vec());
    if !t.row_weight.is_empty() {
        s.row_weight = t.row_weight[start..end].to_vec();
    }
    s.fit_rows = 0..usize::MAX;
    s
}

impl Readings {
    /// Reads the first-loading pieces of `tests` (pieces of other kinds have no readings).
    pub fn new(tests: &[FitTest], pieces: &[Piece]) -> Readings {
        let mut entries = BTreeMap::new();
        for p in pieces {
            if p.kind != PieceKind::InitialLoading || p.start != 0 {
                continue;
            }
            let Some(t) = tests.get(p.test) else {
                continue;
            };
            let end = p.end.min(t.len());
            let Some(l) = loading_levels(&slice(t, p.start, end, None)) else {
                continue;
            };
            let slope = with_sd(l.slope_per_mm).map(|(v, sd)| {
                // A slope whose change over the travel after the peak stays within what two
                // specimens differ by is no reading of a trend: its SD is never below that.
                let travel = (t.imposed[end - 1] - t.imposed[p.start]).abs()
                    - l.slip_to_peak_mm.unwrap_or(0.0);
                let level = l.residual.map_or(0.0, |r| r.value.abs());
                let floor = if travel > 0.0 {
                    REPRODUCIBILITY_SHARE * level / travel
                } else {
                    0.0
                };
                (v, sd.max(floor))
            });
            let entry = Entry {
                end,
                peak: with_sd(l.peak),
                residual: with_sd(l.residual),
                slope,
            };
            if entry.peak.is_some() || entry.residual.is_some() || entry.slope.is_some() {
                entries.insert((p.test, p.start), entry);
            }
        }
        Readings { entries }
    }

    /// The readings of the model whose residuals on rows `start..end` of `t` are `r` (noise
    /// units, as [`crate::fits::residuals`] gives them); `None` where a row is not held out.
    fn predicted(t: &FitTest, start: usize, end: usize, r: &[f64]) -> Option<TestLevels> {
        let k = t.weight.sqrt() / t.noise_sd;
        let pred: Option<Vec<f64>> = (start..end)
            .map(|i| {
                let v = *r.get(i)?;
                let scale = k * t.weight_of(i).sqrt();
                (v.is_finite() && scale > 0.0).then(|| t.measured[i] + v / scale)
            })
            .collect();
        loading_levels(&slice(t, start, end, Some(pred?)))
    }

    /// The readings' evidence for `candidate` over `reference` on the first-loading pieces
    /// among `pieces` that both hold out: Σ (z²_reference − z²_candidate) over the readings
    /// both predictions give, and how many readings counted.
    pub fn score(
        &self,
        tests: &[FitTest],
        pieces: &[Piece],
        reference: &HeldOut,
        candidate: &HeldOut,
    ) -> (f64, usize) {
        let (mut d, mut n) = (0.0, 0);
        for p in pieces {
            if p.kind != PieceKind::InitialLoading {
                continue;
            }
            let (Some(e), Some(t), Some(rb), Some(rc)) = (
                self.entries.get(&(p.test, p.start)),
                tests.get(p.test),
                reference.get(p.test),
                candidate.get(p.test),
            ) else {
                continue;
            };
            let (Some(b), Some(c)) = (
                Self::predicted(t, p.start, e.end, rb),
                Self::predicted(t, p.start, e.end, rc),
            ) else {
                continue;
            };
            let z2 = |m: Option<(f64, f64)>, pred: Option<subfric_fit::Estimate>| {
                let ((v, sd), p) = (m?, pred?);
                p.value.is_finite().then(|| ((v - p.value) / sd).powi(2))
            };
            for (m, pb, pc) in [
                (e.peak, b.peak, c.peak),
                (e.residual, b.residual, c.residual),
                (e.slope, b.slope_per_mm, c.slope_per_mm),
            ] {
                if let (Some(zb), Some(zc)) = (z2(m, pb), z2(m, pc)) {
                    d += zb - zc;
                    n += 1;
                }
            }
        }
        (d, n)
    }

    /// True when no first loading was read.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}
