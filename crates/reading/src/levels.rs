//! Each test's stress-ratio levels, and how they change with the normal stress and with slip,
//! read as a geotechnical lab reads a direct-shear programme before fitting any model: the
//! peak stress ratio of the first loading, the residual it slides to and the residual's slope
//! with slip, each with a 95 % interval; across the tests, the change of the peak and of the
//! residual per e-fold of normal stress, and the Mohr–Coulomb envelope τ = c + σ tan φ.
//!
//! They are evidence and first guesses that no global fit has bent yet: a peak ratio that falls
//! with the normal stress is what a pressure effect on μ_s does (dense sand dilates less under
//! load), a residual that rises or falls with slip what slip hardening or softening does. The
//! paper reads μ_s and μ_k off these same ratios (its Section 5, item 2).
//!
//! Only tests whose first loading runs at one common rate (within a factor
//! [`SAME_RATE`]) are compared across stresses: a rate effect would otherwise pass for a
//! pressure effect. A reading's uncertainty is its noise (correlated noise counted once per
//! correlation length) and at least [`REPRODUCIBILITY_SHARE`] of its value: repeat tests on
//! fresh specimens of one sand never agree more closely than that, so a trend across tests
//! must be larger than what a second specimen could show.

use crate::estimate::Estimate;
mod two_scales;

use crate::fit_test::FitTest;
use crate::prepare::PreparedTest;
use crate::stats::{median, Z95};
use serde::Serialize;
use subfric_model::{Control, Initial};

/// Smallest standard deviation of a test's peak or residual stress ratio, as a share of it:
/// what separates two specimens of one soil tested alike.
pub const REPRODUCIBILITY_SHARE: f64 = 0.01;

/// Tests whose first loadings run at rates within this factor count as at one rate.
pub const SAME_RATE: f64 = 1.5;

/// Normal stresses within this factor count as one level.
const SAME_STRESS: f64 = 1.05;

/// After its peak a loading must slide this many decay lengths for its end to be read as the
/// residual (the post-peak excess has fallen below e⁻³ = 5 % of itself).
pub(crate) const RESIDUAL_DECAYS: f64 = 3.0;

/// The residual is the level of this last share of the first loading's travel.
const RESIDUAL_SHARE: f64 = 0.2;

/// The peak is read on a parabola over this share of the shorter of the rise and the decay
/// lengths either side of the largest smoothed value.
const PEAK_REGION_SHARE: f64 = 0.15;

/// Fewest rows a reading is made from.
const MIN_ROWS: usize = 8;

/// What the first loading of one test shows.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TestLevels {
    /// Test name.
    pub test: String,
    /// Normal stress of the first loading (median) [kPa].
    pub normal_kpa: f64,
    /// Mean slip rate of the first loading [mm/s].
    pub rate_mm_s: f64,
    /// Peak stress ratio, when the test starts from rest (or loaded) and slides past it.
    pub peak: Option<Estimate>,
    /// Travel from the start of the first loading to the peak [mm].
    pub slip_to_peak_mm: Option<f64>,
    /// Residual stress ratio: the level of the last fifth of the first loading, when it slid
    /// long enough after its peak for the excess to have decayed.
    pub residual: Option<Estimate>,
    /// Slope of the stress ratio with slip once the peak has decayed [1/mm]: slip hardening
    /// (> 0) or softening (< 0) beyond what the model's decay from μ_s to μ_k gives.
    pub slope_per_mm: Option<Estimate>,
    /// The slip past the peak over which the slope was read [mm].
    pub slope_span_mm: Option<f64>,
}

/// How a stress ratio (the peak or the residual) changes with the normal stress.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StressTrend {
    /// Tests read.
    pub tests: usize,
    /// Distinct normal stresses among them.
    pub stresses: usize,
    /// Change of the ratio per e-fold of normal stress, dR / d ln p.
    pub per_efold: Estimate,
    /// Relative change, d ln R / d ln p: −β of a power law R ∝ p^(−β).
    pub relative_per_efold: Estimate,
    /// Mohr–Coulomb envelope of the shear stresses: intercept c [kPa]...
    pub cohesion_kpa: Estimate,
    /// ...and angle φ [degrees], τ = c + σ tan φ.
    pub friction_angle_deg: Estimate,
}

impl StressTrend {
    /// True when the ratio changes with the normal stress beyond its uncertainty.
    pub fn changes(&self) -> bool {
        self.per_efold.excludes_zero()
    }
}

/// The levels of every test and their trends.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct LevelReadings {
    /// Per test (slip-controlled tests whose first loading can be read).
    pub tests: Vec<TestLevels>,
    /// The peak stress ratio against the normal stress (tests at one rate, two stresses at
    /// least).
    pub peak: Option<StressTrend>,
    /// The residual stress ratio against the normal stress.
    pub residual: Option<StressTrend>,
    /// The residual's slope with slip over the tests that show one, pooled [1/mm].
    pub slip_slope_per_mm: Option<Estimate>,
    /// The relative change of the stress ratio with slip past the peak over the slip each test
    /// slid there (slope × slip / residual), pooled over the tests that read a slope and a
    /// residual and slid past the peak at least as far as to it (their own slip to the peak,
    /// else the tests' median): how far slip hardening or softening moves friction within a
    /// test, a share to compare with what two specimens of one sand differ by.
    pub slip_change_relative: Option<Estimate>,
}

impl LevelReadings {
    /// True when the peak or the residual stress ratio changes with the normal stress beyond
    /// its uncertainty.
    pub fn change_with_stress(&self) -> bool {
        self.peak.as_ref().is_some_and(StressTrend::changes)
            || self.residual.as_ref().is_some_and(StressTrend::changes)
    }
}

/// Reads every slip-controlled test's first loading (up to its first velocity step; the
/// residual alone where the file starts loaded, without a seating toe cut) and the trends
/// across them.
pub fn read_levels(tests: &[PreparedTest]) -> LevelReadings {
    let read: Vec<TestLevels> = tests
        .iter()
        .filter_map(|p| {
            let mut l = test_levels(&p.full, p.segmentation.rate_changes.first().copied())?;
            // A file that starts at rest under a load (a hold in which the normal stress was
            // raised) reloads an interface that slid before: its rise is no fresh peak, and
            // the slope after it is the reload's transient, not slip hardening. Where a
            // seating toe was cut, the loaded start is the same fresh loading.
            if matches!(p.full.initial, Initial::Loaded { .. }) && p.toe.is_none() {
                l.peak = None;
                l.slip_to_peak_mm = None;
                l.slope_per_mm = None;
                l.slope_span_mm = None;
            }
            Some(l)
        })
        .collect();
    levels_of(read)
}

/// The trends across readings of one test each.
fn levels_of(read: Vec<TestLevels>) -> LevelReadings {
    // One rate: the tests within SAME_RATE of the median rate of those read.
    let mut rates: Vec<f64> = read.iter().map(|t| t.rate_mm_s).collect();
    let typical = median(&mut rates).unwrap_or(0.0);
    let alike: Vec<&TestLevels> = read
        .iter()
        .filter(|t| t.rate_mm_s <= typical * SAME_RATE && t.rate_mm_s * SAME_RATE >= typical)
        .collect();
    let points = |pick: fn(&TestLevels) -> Option<Estimate>| -> Vec<(f64, Estimate)> {
        alike
            .iter()
            .filter_map(|t| pick(t).map(|e| (t.normal_kpa, e)))
            .collect()
    };
    let slopes: Vec<Estimate> = read.iter().filter_map(|t| t.slope_per_mm).collect();
    // A change over a slide shorter than the slip to the peak says nothing of a change with
    // slip, and its interval, scaled by that short slide, is the narrowest of all: pooled by
    // inverse variance, a first loading cut 0.006 mm past its peak by a velocity step (its
    // change read as 0.1 %) outweighed three monotonic tests that each hardened by 17 % over
    // 4.8 mm, and the pooled change came out 0.2 % [−0.7 %, 1.0 %] (seed 47003).
    let mut to_peak: Vec<f64> = read.iter().filter_map(|t| t.slip_to_peak_mm).collect();
    let typical_to_peak = median(&mut to_peak);
    let slid_far_enough =
        |t: &TestLevels| match (t.slope_span_mm, t.slip_to_peak_mm.or(typical_to_peak)) {
            (Some(span), Some(to_peak)) => span >= to_peak,
            _ => true,
        };
    let changes: Vec<Estimate> = read
        .iter()
        .filter(|t| slid_far_enough(t))
        .filter_map(|t| {
            let (g, span, r) = (t.slope_per_mm?, t.slope_span_mm?, t.residual?);
            let scale = span / r.value;
            (scale.is_finite() && scale > 0.0).then_some(Estimate {
                value: g.value * scale,
                lo: g.lo * scale,
                hi: g.hi * scale,
            })
        })
        .collect();
    LevelReadings {
        peak: trend(&points(|t| t.peak)),
        residual: trend(&points(|t| t.residual)),
        slip_slope_per_mm: pooled(&slopes),
        slip_change_relative: pooled(&changes),
        tests: read,
    }
}

/// The first loading of `t`: rows `first..end` moving one way from rest (as the first
/// guesses read it, [`crate::guess::loading_end`]), and its sign.
fn first_loading(t: &FitTest) -> Option<(usize, usize, f64)> {
    let u0 = t.imposed[0];
    let moved = t.imposed.iter().position(|u| (u - u0).abs() > 1e-9)?;
    let first = moved.saturating_sub(1);
    let sign = (t.imposed[moved] - u0).signum();
    let end = crate::guess::loading_end(t, first, sign);
    (end >= first + MIN_ROWS).then_some((first, end, sign))
}

/// The levels of `t`'s first loading, which ends at row `step` at the latest (the last row
/// at the first rate, when the test steps its rate): a peak and a residual are read at one
/// rate.
fn test_levels(t: &FitTest, step: Option<usize>) -> Option<TestLevels> {
    if t.control != Control::Slip || t.len() < MIN_ROWS {
        return None;
    }
    let (first, end, sign) = first_loading(t)?;
    let end = step.filter(|&s| s > first).map_or(end, |s| end.min(s + 1));
    if end < first + MIN_ROWS {
        return None;
    }
    let rows = first..end;
    let u: Vec<f64> = rows
        .clone()
        .map(|i| sign * (t.imposed[i] - t.imposed[first]))
        .collect();
    let f: Vec<f64> = rows
        .clone()
        .map(|i| sign * t.measured[i] / t.normal[i])
        .collect();
    if !f.iter().chain(&u).all(|v| v.is_finite()) {
        return None;
    }
    let normal_kpa = median(&mut t.normal[rows.clone()].to_vec()).unwrap_or(0.0);
    if normal_kpa.is_nan() || normal_kpa <= 0.0 {
        return None;
    }
    let n = f.len();
    let travel = u[n - 1];
    let duration = t.time[end - 1] - t.time[first];
    if !(travel > 0.0 && duration > 0.0) {
        return None;
    }
    // The largest value of the curve smoothed over about a hundredth of the loading.
    let smooth = moving_average(&f, (n / 100).max(2));
    let (ip, &top) = smooth
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    if top <= 0.0 {
        return None;
    }
    let tail = ((n - ip) / 10).max(1);
    let plateau = smooth[n - tail..].iter().sum::<f64>() / tail as f64;
    let rise_mm = u[smooth.iter().position(|&v| v >= 0.9 * top)?].max(1e-9);
    let decay_mm = (top - plateau > 0.02 * top)
        .then(|| {
            let target = plateau + (top - plateau) / std::f64::consts::E;
            smooth[ip..]
                .iter()
                .position(|&v| v <= target)
                .map(|k| (u[ip + k] - u[ip]).max(1e-9))
        })
        .flatten();
    // A decay read so long that the slide ends before it has run its course may be two scales,
    // the peak's decay and a trend with slip (see `two_scales`).
    let decay_mm = match decay_mm {
        Some(l) if u[ip] + RESIDUAL_DECAYS * l >= travel => {
            two_scales::short_decay(&u, &f, ip, RESIDUAL_DECAYS, rise_mm).or(Some(l))
        }
        other => other,
    };
    let after_peak = travel - u[ip];
    let peak = (after_peak >= rise_mm
        && after_peak > 0.0
        && !matches!(t.initial, Initial::Sliding { .. }))
    .then(|| {
        let half = PEAK_REGION_SHARE * rise_mm.min(decay_mm.unwrap_or(f64::INFINITY));
        peak_reading(&u, &f, ip, half)
    })
    .flatten();
    // Where the post-peak excess has decayed: three decay lengths past the peak, or, without
    // softening, three rise lengths into the loading.
    let settled = match decay_mm {
        Some(l) => u[ip] + RESIDUAL_DECAYS * l,
        None => RESIDUAL_DECAYS * rise_mm,
    };
    let residual = (settled < travel && after_peak > 0.0)
        .then(|| {
            let from = settled.max((1.0 - RESIDUAL_SHARE) * travel);
            line_over(&u, &f, from).map(|l| l.level)
        })
        .flatten();
    let slope_per_mm = (settled < travel)
        .then(|| slope_past_peak(&u, &f, ip, decay_mm, settled))
        .flatten();
    Some(TestLevels {
        test: t.name.clone(),
        normal_kpa,
        rate_mm_s: travel / duration,
        slip_to_peak_mm: peak.map(|_| u[ip]),
        peak,
        residual,
        slope_span_mm: slope_per_mm.map(|_| after_peak),
        slope_per_mm,
    })
}

/// Centred moving average over `k` rows either side (fewer at the ends).
fn moving_average(v: &[f64], k: usize) -> Vec<f64> {
    let mut prefix = vec![0.0; v.len() + 1];
    for (i, x) in v.iter().enumerate() {
        prefix[i + 1] = prefix[i] + x;
    }
    (0..v.len())
        .map(|i| {
            let (a, b) = (i.saturating_sub(k), (i + k + 1).min(v.len()));
            (prefix[b] - prefix[a]) / (b - a) as f64
        })
        .collect()
}

/// Standard deviation and lag-1 autocorrelation of residuals `r` (`dof` degrees of freedom
/// used by the fit that left them), and the inflation √((1 + ρ)/(1 − ρ)) of a mean's error that
/// the correlation brings.
fn spread(r: &[f64], dof: usize) -> (f64, f64) {
    let n = r.len();
    let ss: f64 = r.iter().map(|v| v * v).sum();
    let sd = (ss / n.saturating_sub(dof).max(1) as f64).sqrt();
    let rho = if n >= 4 && ss > 0.0 {
        (r.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / ss).clamp(0.0, 0.95)
    } else {
        0.0
    };
    (sd, ((1.0 + rho) / (1.0 - rho)).sqrt())
}

/// The peak of `f` on `u` read on a least-squares parabola over the rows within `half` of
/// row `ip` (three rows either side at least).
fn peak_reading(u: &[f64], f: &[f64], ip: usize, half: f64) -> Option<Estimate> {
    let mut a = ip;
    while a > 0 && (u[ip] - u[a - 1] <= half || ip - a < 3) {
        a -= 1;
    }
    let mut b = ip + 1;
    while b < u.len() && (u[b] - u[ip] <= half || b - ip <= 3) {
        b += 1;
    }
    let (x, y): (Vec<f64>, Vec<f64>) = (a..b).map(|i| (u[i] - u[ip], f[i])).unzip();
    if x.len() < MIN_ROWS.min(7) {
        return None;
    }
    let c = quadratic(&x, &y)?;
    let at = |x: f64| c[0] + c[1] * x + c[2] * x * x;
    let (lo, hi) = (x[0], x[x.len() - 1]);
    let vertex = -c[1] / (2.0 * c[2]);
    let value = if c[2] < 0.0 && vertex > lo && vertex < hi {
        at(vertex)
    } else {
        at(lo).max(at(hi)).max(at(0.0))
    };
    let r: Vec<f64> = x.iter().zip(&y).map(|(x, y)| y - at(*x)).collect();
    let (sd, inflation) = spread(&r, 3);
    let se = (sd * inflation / (x.len() as f64).sqrt()).max(REPRODUCIBILITY_SHARE * value.abs());
    value
        .is_finite()
        .then(|| Estimate::symmetric(value, Z95 * se))
}

/// Least-squares c₀ + c₁ x + c₂ x² (`None` when the rows do not determine it).
fn quadratic(x: &[f64], y: &[f64]) -> Option<[f64; 3]> {
    least_squares3(x, y, |x| [1.0, x, x * x]).map(|(c, _)| c)
}

/// Least squares on three basis functions: the coefficients and the diagonal of (XᵀX)⁻¹
/// (`None` when the rows do not determine them).
fn least_squares3(
    x: &[f64],
    y: &[f64],
    basis: impl Fn(f64) -> [f64; 3],
) -> Option<([f64; 3], [f64; 3])> {
    let mut m = [[0.0; 7]; 3];
    for (&xi, &yi) in x.iter().zip(y) {
        let p = basis(xi);
        for r in 0..3 {
            for c in 0..3 {
                m[r][c] += p[r] * p[c];
            }
            m[r][3] += p[r] * yi;
        }
    }
    for (r, row) in m.iter_mut().enumerate() {
        row[4 + r] = 1.0;
    }
    // Gauss–Jordan with partial pivoting on [XᵀX | Xᵀy | I].
    for col in 0..3 {
        let piv = (col..3).max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))?;
        if m[piv][col].abs() < 1e-300 {
            return None;
        }
        m.swap(col, piv);
        let d = m[col][col];
        for v in &mut m[col] {
            *v /= d;
        }
        let pivot_row = m[col];
        for (r, row) in m.iter_mut().enumerate() {
            if r != col {
                let k = row[col];
                for (v, p) in row.iter_mut().zip(&pivot_row) {
                    *v -= k * p;
                }
            }
        }
    }
    let c = [m[0][3], m[1][3], m[2][3]];
    let d = [m[0][4], m[1][5], m[2][6]];
    c.iter().chain(&d).all(|v| v.is_finite()).then_some((c, d))
}

/// The slope with slip of the stress ratio past its peak at row `ip`, beyond the exponential
/// decay of its excess: level, excess and slope fitted together over the rows from the peak on,
/// the decay length searched from a quarter to four times the `decay` read off the smoothed
/// curve; without softening, a straight line from `from`.
fn slope_past_peak(
    u: &[f64],
    f: &[f64],
    ip: usize,
    decay: Option<f64>,
    from: f64,
) -> Option<Estimate> {
    let Some(l0) = decay else {
        return line_over(u, f, from).map(|line| line.slope);
    };
    // From half a decay length past the peak: the rounding of the peak itself is no decay.
    let start = u.iter().position(|&v| v >= u[ip] + 0.5 * l0)?;
    let (x, y): (Vec<f64>, Vec<f64>) = (start..u.len()).map(|i| (u[i] - u[ip], f[i])).unzip();
    if x.len() < MIN_ROWS {
        return None;
    }
    let fit = |l: f64| -> Option<([f64; 3], [f64; 3], Vec<f64>)> {
        let basis = |x: f64| [1.0, (-x / l).exp(), x];
        let (c, diag) = least_squares3(&x, &y, basis)?;
        let r: Vec<f64> = x
            .iter()
            .zip(&y)
            .map(|(&x, y)| {
                let b = basis(x);
                y - c[0] * b[0] - c[1] * b[1] - c[2] * b[2]
            })
            .collect();
        Some((c, diag, r))
    };
    let ssr = |l: f64| fit(l).map_or(f64::INFINITY, |(_, _, r)| r.iter().map(|v| v * v).sum());
    // A coarse grid in ln l, then golden sections about its best point.
    let grid: Vec<f64> = (0..=24)
        .map(|k| l0 * 16f64.powf(k as f64 / 24.0) / 4.0)
        .collect();
    let (c, diag, r) = fit(least_over_grid(&grid, ssr)?)?;
    // Four parameters: level, excess, decay length and slope.
    let (sd, inflation) = spread(&r, 4);
    Some(Estimate::symmetric(
        c[2],
        Z95 * sd * inflation * diag[2].sqrt(),
    ))
}

/// The decay length with the least `ssr` near the best point of `grid` (increasing lengths):
/// golden sections in ln l between its neighbours.
fn least_over_grid(grid: &[f64], ssr: impl Fn(f64) -> f64) -> Option<f64> {
    let best = (0..grid.len()).min_by(|&i, &j| ssr(grid[i]).total_cmp(&ssr(grid[j])))?;
    let (mut a, mut b) = (
        grid[best.saturating_sub(1)].ln(),
        grid[(best + 1).min(grid.len() - 1)].ln(),
    );
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..30 {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        if ssr(c.exp()) < ssr(d.exp()) {
            b = d;
        } else {
            a = c;
        }
    }
    Some((0.5 * (a + b)).exp())
}

/// A straight line through a stretch: its level at the stretch's middle and its slope, each
/// with a 95 % interval.
struct Line {
    level: Estimate,
    slope: Estimate,
}

/// The least-squares line of `f` on `u` over the rows with u ≥ `from`.
fn line_over(u: &[f64], f: &[f64], from: f64) -> Option<Line> {
    let start = u.iter().position(|&v| v >= from)?;
    let (x, y) = (&u[start..], &f[start..]);
    let n = x.len();
    if n < MIN_ROWS {
        return None;
    }
    let line = crate::stats::fit_line(x, y)?;
    // The level at the stretch's middle, where it is read best.
    let my = line.at(line.x_mean);
    let slope = line.slope;
    let r = line.residuals(x, y);
    let (sd, inflation) = spread(&r, 2);
    let se_level = (sd * inflation / (n as f64).sqrt()).max(REPRODUCIBILITY_SHARE * my.abs());
    let se_slope = sd * inflation / line.sxx.sqrt();
    Some(Line {
        level: Estimate::symmetric(my, Z95 * se_level),
        slope: Estimate::symmetric(slope, Z95 * se_slope),
    })
}

/// Standard error of an estimate's value (its interval is symmetric, ±1.96 SE).
fn se_of(e: &Estimate) -> f64 {
    e.half_width() / Z95
}

/// The trend of readings `(normal stress, ratio)` with the normal stress, when they span two
/// stresses at least.
fn trend(points: &[(f64, Estimate)]) -> Option<StressTrend> {
    let points: Vec<&(f64, Estimate)> = points
        .iter()
        .filter(|(p, e)| *p > 0.0 && e.value.is_finite() && se_of(e) > 0.0)
        .collect();
    let mut stresses: Vec<f64> = points.iter().map(|(p, _)| *p).collect();
    stresses.sort_by(f64::total_cmp);
    let distinct = stresses
        .iter()
        .fold((0usize, f64::NEG_INFINITY), |(n, last), &p| {
            if p > last * SAME_STRESS {
                (n + 1, p)
            } else {
                (n, last)
            }
        })
        .0;
    if distinct < 2 {
        return None;
    }
    let x: Vec<f64> = points.iter().map(|(p, _)| p.ln()).collect();
    let y: Vec<f64> = points.iter().map(|(_, e)| e.value).collect();
    let w: Vec<f64> = points.iter().map(|(_, e)| se_of(e).powi(-2)).collect();
    let line = crate::stats::fit_weighted_line(&x, &y, &w)?;
    let (b, var_b) = (line.slope, line.var_slope);
    let per_efold = Estimate::symmetric(b, Z95 * var_b.sqrt());
    let mean = y.iter().zip(&w).map(|(y, w)| y * w).sum::<f64>() / w.iter().sum::<f64>();
    let relative_per_efold = Estimate {
        value: per_efold.value / mean,
        lo: per_efold.lo / mean,
        hi: per_efold.hi / mean,
    };
    // The envelope of the shear stresses themselves: τ = c + σ tan φ.
    let sx: Vec<f64> = points.iter().map(|(p, _)| *p).collect();
    let sy: Vec<f64> = points.iter().map(|(p, e)| p * e.value).collect();
    let sw: Vec<f64> = points
        .iter()
        .map(|(p, e)| (p * se_of(e)).powi(-2))
        .collect();
    let line = crate::stats::fit_weighted_line(&sx, &sy, &sw)?;
    let (c, tan_phi, var_c, var_t) = (
        line.intercept,
        line.slope,
        line.var_intercept,
        line.var_slope,
    );
    let half_t = Z95 * var_t.sqrt();
    let deg = |t: f64| t.atan().to_degrees();
    Some(StressTrend {
        tests: points.len(),
        stresses: distinct,
        per_efold,
        relative_per_efold,
        cohesion_kpa: Estimate::symmetric(c, Z95 * var_c.sqrt()),
        friction_angle_deg: Estimate {
            value: deg(tan_phi),
            lo: deg(tan_phi - half_t),
            hi: deg(tan_phi + half_t),
        },
    })
}

/// Inverse-variance mean of estimates, its interval widened by their scatter beyond their own
/// errors.
fn pooled(e: &[Estimate]) -> Option<Estimate> {
    let e: Vec<&Estimate> = e
        .iter()
        .filter(|e| e.value.is_finite() && se_of(e) > 0.0)
        .collect();
    if e.is_empty() {
        return None;
    }
    let w: Vec<f64> = e.iter().map(|e| se_of(e).powi(-2)).collect();
    let sw: f64 = w.iter().sum();
    let mean = e.iter().zip(&w).map(|(e, w)| e.value * w).sum::<f64>() / sw;
    let chi2: f64 = e
        .iter()
        .zip(&w)
        .map(|(e, w)| w * (e.value - mean).powi(2))
        .sum();
    let inflation = if e.len() > 1 {
        (chi2 / (e.len() - 1) as f64).max(1.0)
    } else {
        1.0
    };
    Some(Estimate::symmetric(mean, Z95 * (inflation / sw).sqrt()))
}

#[cfg(test)]
mod tests;
