//! Reading one velocity step off the record: its window of rows, their thinning for the fits,
//! and the travel between rows that bounds the D_c they resolve.

use super::Window;
use crate::events::TestView;
use crate::stats::upper_median;

/// The window of the step at row `c` of `t` (from the last half of the level before, at most
/// as long as the level after, to the end of the level after); `None` when the step is not a
/// change of sliding rate in one direction.
pub(in crate::events) fn window(t: &TestView, c: usize) -> Option<Window> {
    let seg = t.segmentation;
    let before = seg.levels.iter().find(|l| l.end == c + 1)?;
    let after = seg.levels.iter().find(|l| l.start == c + 1)?;
    let (v0, v1) = (before.rate, after.rate);
    if v0 * v1 <= 0.0 || !(v0.is_finite() && v1.is_finite()) || (v1 / v0).ln().abs() < 0.3 {
        return None;
    }
    let sign = v0.signum();
    let u = t.slip;
    let travel_after = (u[after.end - 1] - u[c]).abs();
    let travel_before = (u[c] - u[before.start]).abs();
    let pre = (0.5 * travel_before).min(travel_after.max(1e-9));
    let mut first = c;
    while first > before.start && (u[c] - u[first - 1]).abs() <= pre {
        first -= 1;
    }
    let end = after.end;
    if c - first < 5 || end - c < 10 {
        return None;
    }
    let rows = first..end;
    let time: Vec<f64> = rows.clone().map(|i| t.time[i]).collect();
    let travel: Vec<f64> = rows.clone().map(|i| sign * (u[i] - u[c])).collect();
    let mu: Vec<f64> = rows.clone().map(|i| sign * t.friction(i)).collect();
    let step = c - first;
    let v_lp: Vec<f64> = (0..time.len())
        .map(|k| if k <= step { v0.abs() } else { v1.abs() })
        .collect();
    let mut normals: Vec<f64> = rows.clone().map(|i| t.normal[i]).collect();
    let normal = upper_median(&mut normals)?;
    Some(Window {
        normal,
        time,
        travel,
        v_lp,
        mu,
        step,
        v0: v0.abs(),
        v1: v1.abs(),
        sigma: t.noise_friction,
        first_row: first,
    })
}

/// Rows of the window kept before the step, at most.
const THIN_BEFORE: usize = 80;
/// After the step a row is kept once the travel since the last kept row reaches this share of
/// the travel since the step: about 100 rows per e-fold of travel.
const THIN_SHARE: f64 = 0.01;

/// The window with its rows thinned (see [`THIN_BEFORE`], [`THIN_SHARE`]); the step's rows and
/// the last row are always kept.
pub(super) fn thin(w: &Window) -> Window {
    let stride = (w.step + 1).div_ceil(THIN_BEFORE).max(1);
    let mut keep: Vec<usize> = (0..=w.step).rev().step_by(stride).collect();
    keep.reverse();
    let n = w.travel.len();
    if w.step + 1 < n {
        let mut last = w.step + 1;
        keep.push(last);
        for i in w.step + 2..n {
            let since = w.travel[i].abs();
            if (w.travel[i] - w.travel[last]).abs() >= THIN_SHARE * since || i + 1 == n {
                keep.push(i);
                last = i;
            }
        }
    }
    let pick = |v: &[f64]| keep.iter().map(|&i| v[i]).collect::<Vec<f64>>();
    Window {
        time: pick(&w.time),
        travel: pick(&w.travel),
        v_lp: pick(&w.v_lp),
        mu: pick(&w.mu),
        step: keep.iter().position(|&i| i == w.step).unwrap_or(0),
        v0: w.v0,
        v1: w.v1,
        sigma: w.sigma,
        first_row: w.first_row,
        normal: w.normal,
    }
}

/// A tenth of the travel between two rows after the step: the shortest D_c the record can
/// tell from zero.
pub(super) fn resolved_dc_floor(w: &Window) -> f64 {
    dc_floor_for(row_travel(w))
}

/// The shortest D_c resolved where the rows lie `row_travel` mm apart (a tenth of it, at least
/// 10 nm).
pub(super) fn dc_floor_for(row_travel: f64) -> f64 {
    (0.1 * row_travel).max(1e-5)
}

/// The median load-point travel between two rows after the step (0 when the rows do not
/// move).
pub(super) fn row_travel(w: &Window) -> f64 {
    let mut steps: Vec<f64> = w.travel[w.step..]
        .windows(2)
        .map(|p| (p[1] - p[0]).abs())
        .filter(|d| *d > 0.0)
        .collect();
    upper_median(&mut steps).unwrap_or(0.0)
}
