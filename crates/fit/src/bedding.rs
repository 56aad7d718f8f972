//! Bedding: the travel a specimen and its box take up while they seat under the first shear,
//! modelled as a closing compliance in series with the interface and fitted, not cut.
//!
//! A shear box seats as its first loading rises: gaps between the specimen, the box and the
//! plate close, and the load-point travel counts the closure as slip although the interface
//! has not moved. The closure is stiffening and one-off, as a rock joint closes under normal
//! load (Bandis, Lumsden and Barton 1983): once closed at a shear it stays closed, so it grows
//! only while the shear exceeds every shear before it. Its law differs from rig to rig (a gap
//! that closes at once, a toe, a soft layer), so no form is assumed: the closure is any
//! non-decreasing function c(x) of the running peak x of the measured shear (smoothed against
//! the noise, as a share of the first loading's peak), zero at the first row, saturating where
//! the shear nears its peak, at most [`MAX_SHARE_OF_TRAVEL`] of the travel to the peak. The
//! interface slip is the imposed travel less c(x).
//!
//! Given a model, c is found as the horizontal misfit of the rise: at each row the travel by
//! which the model's rise must be shifted to pass through the measured shear (the vertical
//! misfit over the model's slope there), projected on non-decreasing functions of x (pool
//! adjacent violators, each row weighted as its vertical misfit counts), a few rounds against
//! the model's response to the corrected travel. A rise the model already follows leaves a
//! closure near zero and a misfit that barely moves; a toe, a gap or a soft seating leaves one
//! that takes the rise's misfit away. Fitted per test (each specimen seats its own way) with
//! the base model refitted on the corrected travel, read against and judged under that model at
//! the test's own level (its friction scaled to the test's peak: a closure is a matter of the
//! rise's shape, see `level_matched`), and kept only where it halves the first loading's misfit
//! (the share [`crate::stiffness::TRIAL_SHARE`] a freed stiffness must earn).
//!
//! Reading the running peak off the measurement, not the model, keeps the correction a fixed
//! transformation of the imposed column once fitted: every later fit (candidates, folds) sees
//! the corrected travel and needs no parameter of the rig.

use crate::stiffness::TRIAL_SHARE;
use serde::Serialize;
use subfric_model::{simulate_predicted_into, Control, Initial, Model};
use subfric_reading::guess::loading_end;
use subfric_reading::stats::upper_median;
use subfric_reading::{typical_rate, FitTest, PreparedTest};

/// The closure is read on the rise up to this share of the peak shear and held beyond: near
/// the peak the curve is flat, and a horizontal misfit there says nothing about the travel.
const SATURATION: f64 = 0.95;

/// The closure may take up at most this share of the travel to the peak: the interface itself
/// must move for the shear to peak.
pub const MAX_SHARE_OF_TRAVEL: f64 = 0.9;

/// Rows either side over which the measured shear is averaged before its running peak is
/// read (a noisy maximum runs ahead of the true one).
const SMOOTH_ROWS: usize = 2;

/// Model runs of the global stage of the calibration [`seat`] reads closures against, at most.
const SEAT_EVALUATIONS: usize = 1000;

/// Local runs of that calibration, at most.
const SEAT_STARTS: usize = 4;

/// Rounds of (base refitted, closures read again) at most.
const ALTERNATIONS: usize = 6;

/// The closures have settled when none moves by more than this share of itself in a round.
const SETTLED: f64 = 0.02;

/// Fewest rows a first loading must span to be read for bedding.
const MIN_ROWS: usize = 8;

/// The closure fitted to one test.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Bedding {
    /// Test name.
    pub test: String,
    /// Travel closed by the time the shear nears its first peak [mm].
    pub closure_mm: f64,
    /// Share of the peak shear at which half of that travel had closed.
    pub half_closed_at: f64,
    /// Travel from the first row to the peak of the first loading, as recorded [mm].
    pub travel_to_peak_mm: f64,
    /// Misfit of the first loading (mean square residual / noise variance) with the travel
    /// as recorded, under the base model fitted to it.
    pub misfit_without: f64,
    /// The same with the closure taken out, under the base refitted with it.
    pub misfit_with: f64,
    /// The closure curve: (share of the peak shear, travel closed [mm]), non-decreasing.
    pub curve: Vec<(f64, f64)>,
}

impl Bedding {
    /// What the closure is and what it did, in one sentence for the reports.
    pub fn describe(&self) -> String {
        format!(
            "bedding: the first loading's travel held {:.4} mm of closure by its peak (half of it closed by {:.0} % of the peak shear; {:.0} % of the {:.4} mm travel to the peak), taken out as the rig's, not the interface's: the first loading's misfit falls from {:.3}× to {:.3}× the noise variance",
            self.closure_mm,
            100.0 * self.half_closed_at,
            100.0 * self.closure_mm / self.travel_to_peak_mm.max(f64::MIN_POSITIVE),
            self.travel_to_peak_mm,
            self.misfit_without,
            self.misfit_with
        )
    }

    /// The closure at a running peak that is share `x` of the first loading's peak (linear
    /// between the curve's points, constant beyond its ends).
    pub fn closure_at(&self, x: f64) -> f64 {
        closure_at(&self.curve, x)
    }
}

fn closure_at(curve: &[(f64, f64)], x: f64) -> f64 {
    let Some(&(x0, c0)) = curve.first() else {
        return 0.0;
    };
    if x <= x0 {
        return c0;
    }
    for w in curve.windows(2) {
        let ((xa, ca), (xb, cb)) = (w[0], w[1]);
        if x <= xb {
            return if xb > xa {
                ca + (cb - ca) * (x - xa) / (xb - xa)
            } else {
                cb
            };
        }
    }
    curve.last().map_or(0.0, |p| p.1)
}

/// The first loading of a slip-controlled test that starts at rest or loaded: one past its
/// last row, its direction, the row of its peak, and the running peak of the smoothed shear
/// over the whole test as a share of that peak.
#[derive(Clone, Debug)]
struct FirstLoading {
    end: usize,
    sign: f64,
    peak_row: usize,
    share: Vec<f64>,
}

fn first_loading(t: &FitTest) -> Option<FirstLoading> {
    if t.control != Control::Slip
        || matches!(t.initial, Initial::Sliding { .. })
        || t.len() < MIN_ROWS
    {
        return None;
    }
    let u0 = t.imposed[0];
    let moved = t.imposed.iter().position(|u| (u - u0).abs() > 1e-9)?;
    let sign = (t.imposed[moved] - u0).signum();
    let end = loading_end(t, moved.saturating_sub(1), sign);
    if end < MIN_ROWS || !t.measured.iter().all(|v| v.is_finite()) {
        return None;
    }
    let n = t.len();
    let smooth: Vec<f64> = (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(SMOOTH_ROWS), (i + SMOOTH_ROWS + 1).min(n));
            t.measured[a..b].iter().map(|v| v * sign).sum::<f64>() / (b - a) as f64
        })
        .collect();
    let (peak_row, &peak) = smooth[..end]
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    // A loading that has not turned over may still be rising: its peak is not read.
    if peak <= 0.0 || peak_row + 2 >= end {
        return None;
    }
    let mut running = f64::NEG_INFINITY;
    let share = smooth
        .iter()
        .map(|&s| {
            running = running.max(s.abs());
            running / peak
        })
        .collect();
    Some(FirstLoading {
        end,
        sign,
        peak_row,
        share,
    })
}

/// `t` with the closure `curve` taken out of its imposed travel; `share` as read on the
/// record, `kept[i]` the record's row that row `i` of `t` stands for.
fn corrected(
    t: &FitTest,
    share: &[f64],
    kept: &[usize],
    sign: f64,
    curve: &[(f64, f64)],
) -> FitTest {
    let mut out = t.clone();
    let c0 = closure_at(curve, share[kept[0]]);
    for (i, u) in out.imposed.iter_mut().enumerate() {
        *u -= sign * (closure_at(curve, share[kept[i]]) - c0);
    }
    out
}

/// Sum of squared noise-normalised residuals of `model` on rows `..end` of `t` (∞ when it
/// cannot be simulated); `scratch` receives the prediction.
fn ssr_until(t: &FitTest, model: &Model, end: usize, scratch: &mut Vec<f64>) -> f64 {
    if simulate_predicted_into(model, &t.protocol_until(end), scratch).is_err() {
        return f64::INFINITY;
    }
    let k = t.weight / (t.noise_sd * t.noise_sd);
    (0..end.min(scratch.len()))
        .map(|i| {
            let r = scratch[i] - t.measured[i];
            k * t.weight_of(i) * r * r
        })
        .sum()
}

/// `model` with its friction scaled to the level test `t` shows on its first loading (rows
/// `..end`, loaded in direction `sign`): μ_s, μ_k (and μ_0) times the ratio of the measured
/// peak to the model's. A closure is a matter of the rise's shape; a model fitted to every test
/// together can miss one test's level (a pressure effect not yet modelled puts the tests at 50
/// and 400 kPa 10 % off their peaks), and against a rise of the wrong height the closure is
/// misread and the first loading's misfit is the level's, which no closure halves: the toe was
/// left in, and the first loadings held out at those stresses then outweighed the pressure law
/// the tests' levels showed (generated sets with a seating). The shape stays the jointly
/// fitted model's: a base refitted on one test alone bends its rise to the toe instead.
fn level_matched(
    t: &FitTest,
    model: &Model,
    end: usize,
    sign: f64,
    scratch: &mut Vec<f64>,
) -> Model {
    if simulate_predicted_into(model, &t.protocol_until(end), scratch).is_err() {
        return *model;
    }
    // The peaks compared. The maximum of a noisy record reads its level high, by about
    // √(2 ln n) noise SDs over n rows: within that, and one SD more, the level is the model's.
    let end = end.min(scratch.len()).min(t.len());
    let peak = |v: &[f64]| v.iter().map(|x| sign * x).fold(f64::MIN, f64::max);
    let (measured, predicted) = (peak(&t.measured[..end]), peak(&scratch[..end]));
    let within_noise = (2.0 * (end.max(2) as f64).ln()).sqrt() + 1.0;
    if (measured - predicted).abs() <= within_noise * t.noise_sd {
        return *model;
    }
    let ratio = measured / predicted;
    if !(ratio.is_finite() && ratio > 0.0) {
        return *model;
    }
    let mut m = *model;
    m.params.mu_s *= ratio;
    m.params.mu_k *= ratio;
    m.params.mu_0 = m.params.mu_0.map(|v| v * ratio);
    m
}

/// Pool-adjacent-violators: the non-decreasing sequence closest to `y` in weighted least
/// squares (weights `w` > 0).
fn isotonic(y: &[f64], w: &[f64]) -> Vec<f64> {
    // Blocks of (mean, weight, count).
    let mut blocks: Vec<(f64, f64, usize)> = Vec::with_capacity(y.len());
    for (&v, &wi) in y.iter().zip(w) {
        blocks.push((v, wi, 1));
        while blocks.len() >= 2 {
            let (m2, w2, n2) = blocks[blocks.len() - 1];
            let (m1, w1, n1) = blocks[blocks.len() - 2];
            if m1 <= m2 {
                break;
            }
            blocks.pop();
            let wsum = w1 + w2;
            *blocks.last_mut().expect("two blocks") = ((m1 * w1 + m2 * w2) / wsum, wsum, n1 + n2);
        }
    }
    blocks
        .into_iter()
        .flat_map(|(m, _, n)| std::iter::repeat_n(m, n))
        .collect()
}

/// Points of the model's own rise a closure is read against.
const RISE_POINTS: usize = 2000;

/// The closure curve that fits the rise of `t`'s first loading under `model`: the model's
/// rise from the test's start at its loading rate, on a fine grid; at each row of the
/// record's rise the travel the model needs to reach the measured shear, and the closure the
/// rest of the recorded travel; projected on non-decreasing functions of the running peak,
/// each row weighted as its vertical misfit counts (the model's slope there squared).
fn closure_curve(
    t: &FitTest,
    kept: &[usize],
    fl: &FirstLoading,
    model: &Model,
    c_max: f64,
) -> Vec<(f64, f64)> {
    // Rows of `t` on the rise: up to the first that reaches SATURATION of the peak.
    let Some(rise_end) = (0..t.len())
        .position(|i| fl.share[kept[i]] >= SATURATION || kept[i] >= fl.peak_row)
        .map(|i| i + 1)
    else {
        return Vec::new();
    };
    if rise_end < 3 {
        return Vec::new();
    }
    let travel = fl.sign * (t.imposed[rise_end - 1] - t.imposed[0]);
    let duration = t.time[rise_end - 1] - t.time[0];
    if !(travel > 0.0 && duration > 0.0) {
        return Vec::new();
    }
    // The model's rise over the recorded travel and a half again, at the loading's rate.
    let span = 1.5 * travel;
    let rate = travel / duration;
    let time: Vec<f64> = (0..RISE_POINTS)
        .map(|k| span / rate * k as f64 / (RISE_POINTS - 1) as f64)
        .collect();
    let slip: Vec<f64> = (0..RISE_POINTS)
        .map(|k| t.imposed[0] + fl.sign * span * k as f64 / (RISE_POINTS - 1) as f64)
        .collect();
    let Some(normal) = upper_median(&mut t.normal[..rise_end].to_vec()) else {
        return Vec::new();
    };
    let normal = vec![normal; RISE_POINTS];
    let proto = subfric_model::Protocol {
        control: Control::Slip,
        time: &time,
        imposed: &slip,
        normal: &normal,
        initial_slip: t.initial_slip,
        initial: t.initial,
    };
    let mut tau = Vec::new();
    if simulate_predicted_into(model, &proto, &mut tau).is_err() {
        return Vec::new();
    }
    // The rise as a non-decreasing shear against travel, to its peak.
    let top = tau
        .iter()
        .enumerate()
        .max_by(|a, b| (fl.sign * a.1).total_cmp(&(fl.sign * b.1)))
        .map_or(0, |(k, _)| k);
    let du = span / (RISE_POINTS - 1) as f64;
    let travel_to = |shear: f64| -> Option<(f64, f64)> {
        // First point at or above `shear` on the rise, interpolated; the slope there.
        let k = (1..=top).find(|&k| fl.sign * tau[k] >= shear)?;
        let (a, b) = (fl.sign * tau[k - 1], fl.sign * tau[k]);
        let slope = (b - a) / du;
        let frac = if b > a { (shear - a) / (b - a) } else { 0.0 };
        Some(((k - 1) as f64 * du + frac * du, slope))
    };
    let (mut target, mut weight) = (vec![0.0; rise_end], vec![0.0; rise_end]);
    for i in 0..rise_end {
        let recorded = fl.sign * (t.imposed[i] - t.imposed[0]);
        let shear = fl.sign * t.measured[i];
        match travel_to(shear) {
            Some((u, slope)) if slope > 0.0 => {
                target[i] = (recorded - u).clamp(0.0, c_max);
                weight[i] = slope * slope * t.weight_of(i);
            }
            // Below the model's start or above its peak: nothing read here.
            _ => {
                target[i] = 0.0;
                weight[i] = 0.0;
            }
        }
    }
    // The first row is where the closure is counted from.
    target[0] = 0.0;
    let heaviest = weight.iter().cloned().fold(0.0, f64::max);
    if heaviest <= 0.0 {
        return Vec::new();
    }
    weight[0] = 1e6 * heaviest;
    for w in weight.iter_mut() {
        *w = w.max(1e-12 * heaviest);
    }
    let c = isotonic(&target, &weight);
    // The curve is a function of x: one value per distinct running peak along the rise.
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(c.len());
    for i in 0..rise_end {
        let x = fl.share[kept[i]];
        match out.last_mut() {
            Some(last) if x <= last.0 => last.1 = last.1.max(c[i]),
            _ => out.push((x, c[i])),
        }
    }
    out
}

/// A test's first loading as read for bedding, with the rows of `fit` it spans.
struct Candidate {
    index: usize,
    loading: FirstLoading,
    /// One past the last row of `fit` in the first loading.
    fit_end: usize,
    travel_to_peak: f64,
}

fn candidates(tests: &[PreparedTest]) -> Vec<Candidate> {
    tests
        .iter()
        .enumerate()
        .filter_map(|(index, p)| {
            let loading = first_loading(&p.full)?;
            let fit_end = p.kept.iter().take_while(|&&r| r < loading.end).count();
            let travel_to_peak = (p.full.imposed[loading.peak_row] - p.full.imposed[0]).abs();
            (fit_end >= MIN_ROWS && travel_to_peak > 0.0).then_some(Candidate {
                index,
                loading,
                fit_end,
                travel_to_peak,
            })
        })
        .collect()
}

/// Takes `curve` out of test `p`'s fitted rows (a trial: the rows stay segmented as they
/// were).
fn apply(p: &mut PreparedTest, fl: &FirstLoading, curve: &[(f64, f64)]) {
    let all: Vec<usize> = (0..p.full.len()).collect();
    p.full = corrected(&p.full, &fl.share, &all, fl.sign, curve);
    p.fit = corrected(&p.fit, &fl.share, &p.kept, fl.sign, curve);
}

/// Test `p` prepared again with `curve` taken out of its record's travel.
fn reprepared(p: &PreparedTest, fl: &FirstLoading, curve: &[(f64, f64)]) -> PreparedTest {
    let c0 = closure_at(curve, fl.share[0]);
    let shift: Vec<f64> = fl
        .share
        .iter()
        .map(|&x| fl.sign * (closure_at(curve, x) - c0))
        .collect();
    p.with_travel_less(&shift)
}

/// Mean square of the normalised residuals over the rows a test's SSR was taken on.
fn per_row(t: &FitTest, ssr: f64, end: usize) -> f64 {
    let rows: f64 = (0..end.min(t.len())).map(|i| t.weight_of(i)).sum();
    ssr / (t.weight * rows).max(1.0)
}

/// Whether a closure curve closes as a gap does: fastest at first, stiffening as it closes
/// (a joint closing under load, Bandis et al. 1983; the toe of a seating). Such a curve is
/// concave in the running peak and lies above its chord from its first point to its last;
/// read row by row it must at least do so on average: the area under it is at least that
/// under the chord. A curve that closes mostly near the peak takes up what the model's rise
/// there lacks, not a gap: read against a base at the test's level, closures half closed only
/// at 49–88 % of the peak took the rise's shape away and misled the verdicts that followed
/// (generated rig sets; their seating toes half closed by 13–42 %).
fn closes_as_it_loads(curve: &[(f64, f64)]) -> bool {
    let (Some(&(x0, _)), Some(&(x1, c1))) = (curve.first(), curve.last()) else {
        return false;
    };
    let area: f64 = curve
        .windows(2)
        .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
        .sum();
    area >= 0.5 * c1 * (x1 - x0)
}

/// Share of the peak shear at which half of the curve's closure had closed.
fn half_closed_at(curve: &[(f64, f64)]) -> f64 {
    let total = curve.last().map_or(0.0, |p| p.1);
    curve
        .iter()
        .find(|p| p.1 >= 0.5 * total)
        .map_or(f64::NAN, |p| p.0)
}

/// Fits a closure to the first loading of every test that starts at rest (or loaded) under
/// slip control, against `base` (the base model fitted to the tests as recorded), refitting
/// the base on the corrected travel with `refit(tests, start)`; returns the tests with the
/// closures that halve their first loading's misfit taken out, and those closures.
pub fn fit_bedding(
    tests: &[PreparedTest],
    base: &Model,
    refit: &dyn Fn(&[FitTest], &Model) -> Model,
) -> (Vec<PreparedTest>, Vec<Bedding>) {
    let found = candidates(tests);
    if found.is_empty() {
        return (tests.to_vec(), Vec::new());
    }
    let mut scratch = Vec::new();
    // Each test's closure is read against, and judged under, the model at that test's own
    // level ([`level_matched`]).
    let matched = |t: &FitTest, c: &Candidate, model: &Model, scratch: &mut Vec<f64>| {
        level_matched(t, model, c.fit_end, c.loading.sign, scratch)
    };
    let without: Vec<f64> = found
        .iter()
        .map(|c| {
            let t = &tests[c.index].fit;
            let m = matched(t, c, base, &mut scratch);
            ssr_until(t, &m, c.fit_end, &mut scratch)
        })
        .collect();
    let curves_against = |model: &Model| -> Vec<Vec<(f64, f64)>> {
        let mut scratch = Vec::new();
        found
            .iter()
            .map(|c| {
                let p = &tests[c.index];
                closure_curve(
                    &p.fit,
                    &p.kept,
                    &c.loading,
                    &matched(&p.fit, c, model, &mut scratch),
                    MAX_SHARE_OF_TRAVEL * c.travel_to_peak,
                )
            })
            .collect()
    };
    let correct = |curves: &[Vec<(f64, f64)>]| {
        let mut out = tests.to_vec();
        for (c, curve) in found.iter().zip(curves) {
            apply(&mut out[c.index], &c.loading, curve);
        }
        out
    };
    let fits = |ps: &[PreparedTest]| ps.iter().map(|p| p.fit.clone()).collect::<Vec<_>>();
    // Against the base as fitted to the recorded travel first; then, in turn, the base
    // refitted on the corrected travel (it had bent to the uncorrected rise, and a bent rise
    // hides part of the closure) and the closures read again against it, until they settle.
    let mut curves = curves_against(base);
    let mut refitted = *base;
    for _ in 0..ALTERNATIONS {
        refitted = refit(&fits(&correct(&curves)), &refitted);
        let next = curves_against(&refitted);
        let settled = next.iter().zip(&curves).all(|(a, b)| {
            let (a, b) = (a.last().map_or(0.0, |p| p.1), b.last().map_or(0.0, |p| p.1));
            (a - b).abs() <= SETTLED * a.max(b)
        });
        curves = next;
        if settled {
            break;
        }
    }
    let trial = correct(&curves);
    let mut kept = Vec::new();
    let mut out = tests.to_vec();
    for ((c, curve), &before) in found.iter().zip(&curves).zip(&without) {
        let t = &trial[c.index].fit;
        let m = matched(t, c, &refitted, &mut scratch);
        let after = ssr_until(t, &m, c.fit_end, &mut scratch);
        let closure_mm = curve.last().map_or(0.0, |p| p.1);
        if closure_mm > 0.0
            && closes_as_it_loads(curve)
            && after.is_finite()
            && after <= TRIAL_SHARE * before
        {
            out[c.index] = reprepared(&tests[c.index], &c.loading, curve);
            kept.push(Bedding {
                test: tests[c.index].full.name.clone(),
                closure_mm,
                half_closed_at: half_closed_at(curve),
                travel_to_peak_mm: c.travel_to_peak,
                misfit_without: per_row(&tests[c.index].fit, before, c.fit_end),
                misfit_with: per_row(t, after, c.fit_end),
                curve: curve.clone(),
            });
        }
    }
    (out, kept)
}

/// What seating the first loadings showed: the tests with every kept closure taken out of
/// their travel, the closures, and the base model calibrated on the corrected travel.
#[derive(Clone, Debug)]
pub struct Seated {
    /// The tests as corrected.
    pub tests: Vec<PreparedTest>,
    /// The closures kept, one per test that showed one.
    pub bedding: Vec<Bedding>,
    /// The base model fitted to the corrected tests (a start for later calibrations).
    pub base: Option<Model>,
}

/// The bedding of a set's first loadings, for `fit` and `diagnose` alike: the base model
/// (parameters `free` of `template`) calibrated with `options` on the tests as recorded, the
/// closures fitted against it ([`fit_bedding`]) with the base refitted by least squares on
/// the corrected travel.
pub fn seat(
    tests: &[PreparedTest],
    template: &Model,
    free: &[crate::Param],
    options: &crate::FitOptions,
) -> Seated {
    let unchanged = || Seated {
        tests: tests.to_vec(),
        bedding: Vec::new(),
        base: None,
    };
    if candidates(tests).is_empty() {
        return unchanged();
    }
    let fits: Vec<FitTest> = tests.iter().map(|t| t.fit.clone()).collect();
    let Ok(space) = crate::Space::try_with_rate(*template, free, &[], typical_rate(&fits)) else {
        return unchanged();
    };
    // A coarse calibration, as the stiffness trial's: the closures are read against its rise.
    let opts = crate::FitOptions {
        profiles: false,
        statistics: false,
        global_evaluations: options.global_evaluations.min(SEAT_EVALUATIONS),
        starts: options.starts.min(SEAT_STARTS),
        ..options.clone()
    };
    let Ok(base) = crate::calibrate(&fits, space.clone(), &opts, &|_| {}) else {
        return unchanged();
    };
    let refit_opts = crate::FitOptions {
        global_evaluations: 0,
        starts: 1,
        informed_guesses: false,
        ..opts
    };
    let refit = |fits: &[FitTest], start: &Model| -> Model {
        crate::calibrate_from(fits, space.clone(), &[*start], &refit_opts, &|_| {})
            .map_or(*start, |r| r.model)
    };
    let (corrected, bedding) = fit_bedding(tests, &base.model, &refit);
    if bedding.is_empty() {
        return Seated {
            tests: corrected,
            bedding,
            base: Some(base.model),
        };
    }
    let fits: Vec<FitTest> = corrected.iter().map(|t| t.fit.clone()).collect();
    let model = refit(&fits, &base.model);
    Seated {
        tests: corrected,
        bedding,
        base: Some(model),
    }
}

#[cfg(test)]
mod tests;
