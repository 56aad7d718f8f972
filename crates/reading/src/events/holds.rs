//! Each hold read on its own: how far friction relaxes during it and how far the peak on
//! reloading rises above the friction before it; across holds, the healing rate per decade of
//! hold time (the slide-hold-slide reading of Dieterich and of Marone's lab).

use super::{Estimate, TestView};
use crate::stats::student_t95;
use serde::Serialize;

/// One hold and its reload.
#[derive(Clone, Debug, Serialize)]
pub struct HoldHealing {
    /// Test.
    pub test: String,
    /// First row of the hold.
    pub row: usize,
    /// Duration [s].
    pub duration_s: f64,
    /// Friction before the hold (mean of the sliding just before it).
    pub before: f64,
    /// Relaxation during the hold: friction before minus the lowest friction in the hold.
    pub relaxation: f64,
    /// Peak on reloading minus the friction before the hold (with its uncertainty).
    pub peak_gain: Estimate,
}

/// Healing across holds: Δμ_peak against log₁₀ of the hold time.
#[derive(Clone, Debug, Serialize)]
pub struct HealingTrend {
    /// Holds used.
    pub holds: usize,
    /// Δμ per decade of hold time (95 % interval; open with fewer than three holds of
    /// different durations).
    pub per_decade: Estimate,
}

/// Rows of sliding before a hold that give its friction level.
const LEVEL_ROWS: usize = 10;

/// Rows after a hold searched for the reload's peak: until the next event, at most this many.
const RELOAD_ROWS: usize = 400;

/// Every hold of a slip-controlled test.
pub(super) fn holds(t: &TestView) -> Vec<HoldHealing> {
    let seg = t.segmentation;
    let mut out = Vec::new();
    for &(s, e) in &seg.holds {
        if s < 3 || e + 3 >= t.time.len() {
            continue;
        }
        // An unload before the hold (the last event before it a reversal) makes an
        // unload–hold–reload, whose reload peak is no healing: only slide–hold–slide counts.
        if last_event_is_reversal(t, s) {
            continue;
        }
        let sign = direction_before(t, s);
        if sign == 0.0 {
            continue;
        }
        let from = s.saturating_sub(LEVEL_ROWS).max(previous_event(t, s));
        if s - from < 3 {
            continue;
        }
        let mu = |i: usize| sign * t.friction(i);
        let before = (from..s).map(mu).sum::<f64>() / (s - from) as f64;
        let lowest = (s..e).map(mu).fold(f64::MAX, f64::min);
        let next = next_event(t, e).min(e + RELOAD_ROWS).min(t.time.len());
        if next <= e + 2 {
            continue;
        }
        let peak = (e..next).map(mu).fold(f64::MIN, f64::max);
        let se = t.noise_friction * (1.0 + 1.0 / (s - from) as f64).sqrt();
        out.push(HoldHealing {
            test: t.name.to_string(),
            row: s,
            duration_s: t.time[e - 1] - t.time[s.saturating_sub(1)],
            before,
            relaxation: before - lowest,
            peak_gain: Estimate::symmetric(peak - before, 1.96 * se),
        });
    }
    out
}

/// The sign of the sliding just before row `s` (0 when it did not slide).
/// True when the last event before row `s` (a rate change, a reversal or the end of a hold) is
/// a reversal.
fn last_event_is_reversal(t: &TestView, s: usize) -> bool {
    let seg = t.segmentation;
    let last_reversal = seg.reversals.iter().copied().filter(|&r| r < s).max();
    let last_other = seg
        .rate_changes
        .iter()
        .copied()
        .filter(|&r| r < s)
        .chain(seg.holds.iter().map(|h| h.1).filter(|&e| e <= s))
        .max();
    match (last_reversal, last_other) {
        (Some(r), Some(o)) => r >= o,
        (Some(_), None) => true,
        _ => false,
    }
}

fn direction_before(t: &TestView, s: usize) -> f64 {
    let u = t.slip;
    let back = s.saturating_sub(LEVEL_ROWS);
    let d = u[s - 1] - u[back];
    if d == 0.0 {
        0.0
    } else {
        d.signum()
    }
}

/// The last event (step, reversal, hold end) at or before row `s`, or 0.
fn previous_event(t: &TestView, s: usize) -> usize {
    let seg = t.segmentation;
    let mut last = 0;
    for &r in seg.rate_changes.iter().chain(&seg.reversals) {
        if r < s {
            last = last.max(r + 1);
        }
    }
    for &(_, e) in &seg.holds {
        if e <= s {
            last = last.max(e);
        }
    }
    last
}

/// The first event after row `e`, or the end of the test.
fn next_event(t: &TestView, e: usize) -> usize {
    let seg = t.segmentation;
    let mut next = t.time.len();
    for &r in seg.rate_changes.iter().chain(&seg.reversals) {
        if r > e {
            next = next.min(r);
        }
    }
    for &(s, _) in &seg.holds {
        if s > e {
            next = next.min(s);
        }
    }
    next
}

/// The healing rate across holds: a weighted line through (log₁₀ t_hold, Δμ_peak).
pub(super) fn healing_trend(holds: &[HoldHealing]) -> Option<HealingTrend> {
    let pts: Vec<(f64, f64)> = holds
        .iter()
        .filter(|h| h.duration_s > 0.0)
        .map(|h| (h.duration_s.log10(), h.peak_gain.value))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let (x, y): (Vec<f64>, Vec<f64>) = pts.iter().copied().unzip();
    let line = crate::stats::fit_line(&x, &y)?;
    // Holds too close in duration (a spread of log10 hold time, Σ(x − x̄)², under 0.1) say
    // nothing of a trend per decade.
    if line.sxx < 0.1 {
        return None;
    }
    let slope = line.slope;
    let per_decade = if pts.len() >= 3 {
        // The residual scatter, but never below the uncertainty of one peak reading.
        let floor = holds
            .iter()
            .map(|h| h.peak_gain.half_width() / 1.96)
            .fold(0.0, f64::max);
        let sd = line.residual_sd().max(floor);
        Estimate::symmetric(slope, student_t95(pts.len() - 2) * sd / line.sxx.sqrt())
    } else {
        Estimate::open(slope)
    };
    Some(HealingTrend {
        holds: pts.len(),
        per_decade,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hold(duration_s: f64, gain: f64) -> HoldHealing {
        HoldHealing {
            test: "shs".into(),
            row: 0,
            duration_s,
            before: 0.6,
            relaxation: 0.0,
            peak_gain: Estimate::symmetric(gain, 0.001),
        }
    }

    #[test]
    fn a_log_linear_healing_gives_its_rate_per_decade() {
        let h: Vec<HoldHealing> = [3.0, 10.0, 30.0, 100.0, 300.0]
            .iter()
            .map(|&t: &f64| hold(t, 0.01 * t.log10() + 0.002))
            .collect();
        let tr = healing_trend(&h).unwrap();
        assert!((tr.per_decade.value - 0.01).abs() < 1e-9);
        // The points lie on the line: the interval comes from the uncertainty of one peak
        // reading (±0.001 at 95 %), spread over the durations' spread, with t at 3 degrees of
        // freedom.
        let x: Vec<f64> = [3.0f64, 10.0, 30.0, 100.0, 300.0]
            .iter()
            .map(|t| t.log10())
            .collect();
        let mx = x.iter().sum::<f64>() / 5.0;
        let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
        let half = 3.182 * (0.001 / 1.96) / sxx.sqrt();
        assert!((tr.per_decade.half_width() - half).abs() < 1e-9 * half);
        assert!(tr.per_decade.lo > 0.0);
    }

    #[test]
    fn two_holds_give_an_open_interval_and_equal_durations_none() {
        let tr = healing_trend(&[hold(10.0, 0.01), hold(100.0, 0.02)]).unwrap();
        assert!(tr.per_decade.lo.is_infinite());
        assert!(healing_trend(&[hold(10.0, 0.01), hold(10.0, 0.02)]).is_none());
    }
}
