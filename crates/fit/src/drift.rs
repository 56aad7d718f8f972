//! A drift of the measurement, projected out of the residuals: the alternative to every
//! friction effect that says "the gap is the instrument's, not the interface's".
//!
//! Two drifts a shear rig's measurement is known to have, both fitted by linear least squares
//! on the residuals (a variable projection: the model's parameters are fitted with the drift
//! removed at each evaluation):
//!
//! - a **zero drift** linear in time from each test's first row (electronics, a tare that
//!   wanders), at one rate for the set: one rate for the shear channel, one for the slip
//!   channel of traction-controlled tests;
//! - a **creep of the load cell**: a loaded cell's output creeps towards a share of its load
//!   with a lag, so the measured shear is F + Σⱼ cⱼ F̄_τⱼ, where F̄_τ is the shear history (as
//!   the model predicts it) low-passed with time constant τ (a step of load F₀ reads F₀ (1 + c (1 − e^(−t/τ))) for one
//!   term, and the creep recovers when the load is taken off): the creep spectrum as a Prony
//!   series, as viscoelastic creep is written, on a fixed grid of time constants spanning the
//!   set's time scale (a tenth of the longest test's duration to three times it).
//!
//! One instrument measures every test of a set, so every coefficient is shared by all its
//! tests: a drift cannot stand in for a difference between tests (a pressure effect, two
//! specimens), only for a trend with time that every test shows alike. A zero drift of each
//! test's own would, with the creep's slow terms, be nearly collinear and predict held-out
//! rows wildly.
//!
//! The drift is a linear projection whose regressors (the time, the predicted shear
//! low-passed) change smoothly with the model's parameters, so the residual stays a smooth
//! function of them and a least-squares solver can follow it (τ is never switched between
//! evaluations). Terms the learned rows cannot tell apart are read as one
//! ([`DRIFT_COLLINEAR_SHARE`]).
//!
//! The creep acts on a measured shear only: under traction control the measured column is the
//! slip, and only the zero drift applies.

use subfric_model::Control;
use subfric_reading::FitTest;

/// Time constants of the creep's terms, as multiples of the longest test's duration.
const CREEP_TIME_CONSTANTS: [f64; 4] = [0.1, 0.316, 1.0, 3.16];

/// Combinations of the drift's terms (each scaled to unit norm over the learned rows) whose
/// norm is below this share of the largest are dropped: such a combination is a shape the
/// terms trace alike to within the readings' reproducibility between specimens
/// ([`subfric_reading::levels::REPRODUCIBILITY_SHARE`]), and its coefficient is not read from the data
/// but from their noise and misfit. Kept, it carries large coefficients of opposite sign that
/// cancel on the learned rows and not elsewhere: on a set whose long tests sit at one load, a
/// zero drift and a slow creep term (both nearly linear in time) traded that way, and a test
/// held out at another load was predicted 10 to 100× worse than by the model without any
/// drift (five load-cell creep sets of seeds 15001–17005, with the cutoff at 1e-9 of the
/// normal matrix, unscaled).
const DRIFT_COLLINEAR_SHARE: f64 = subfric_reading::levels::REPRODUCIBILITY_SHARE;

/// The shear history `shear` of `t` low-passed with time constant `tau` (zero before the
/// first row): what one creep term of the load cell adds, per unit of its coefficient.
fn creep_regressor(t: &FitTest, shear: &[f64], tau: f64, out: &mut Vec<f64>) {
    out.clear();
    let mut y = 0.0;
    let (mut last_dt, mut a) = (f64::NAN, 0.0);
    for (i, &f) in shear.iter().enumerate() {
        if i > 0 {
            let dt = (t.time[i] - t.time[i - 1]).max(0.0);
            if dt != last_dt {
                a = -(-dt / tau).exp_m1();
                last_dt = dt;
            }
        }
        if f.is_finite() {
            y += a * (f - y);
        }
        out.push(y);
    }
}

/// The creep's time constants for `tests`: a fixed grid of multiples of the longest test's
/// duration (none when no test measures shear).
fn creep_time_constants(tests: &[FitTest]) -> Vec<f64> {
    let longest = tests
        .iter()
        .filter(|t| !t.is_empty())
        .map(|t| t.time[t.len() - 1] - t.time[0])
        .fold(0.0f64, f64::max);
    if longest > 0.0 && tests.iter().any(|t| t.control == Control::Slip) {
        CREEP_TIME_CONSTANTS.iter().map(|m| m * longest).collect()
    } else {
        Vec::new()
    }
}

/// How many coefficients the drift fits to `tests`: the zero drift of each channel a test
/// measures (the shear of slip-controlled tests, the slip of traction-controlled ones) and one
/// per creep time constant. What the drift costs as an alternative to a friction effect.
pub fn drift_coefficients(tests: &[FitTest]) -> usize {
    let measures = |c: Control| tests.iter().any(|t| t.control == c && !t.is_empty());
    usize::from(measures(Control::Slip))
        + usize::from(measures(Control::Shear))
        + creep_time_constants(tests).len()
}

/// The zero drift's regressor of row `i` in the residuals' units: time from the test's first
/// row, weighted as the residuals are (k √w, k = √weight / noise SD).
#[inline]
fn zero_drift_term(t: &FitTest, k: f64, i: usize) -> f64 {
    k * t.weight_of(i).sqrt() * (t.time[i] - t.time[0])
}

/// A creep term's regressor of a row in the residuals' units (prediction − measurement, times
/// k √w): a cell that adds c ȳ to its reading leaves −c k √w ȳ in the residual.
#[inline]
fn creep_term(k: f64, row_weight: f64, low_passed: f64) -> f64 {
    -k * row_weight.sqrt() * low_passed
}

/// A drift fitted to residuals, every coefficient shared by the set's tests.
#[derive(Clone, Debug, PartialEq)]
pub struct FittedDrift {
    /// Zero drift of the measured shear [kPa/s] (slip-controlled tests).
    pub shear_rate: f64,
    /// Zero drift of the measured slip [mm/s] (traction-controlled tests).
    pub slip_rate: f64,
    /// Time constants of the creep terms [s] (empty when no test measures shear).
    pub creep_taus: Vec<f64>,
    /// Coefficient of each creep term: the share of the low-passed shear the cell adds.
    pub creep: Vec<f64>,
}

/// The drift's weighted regressors of one test whose weighted residuals are `r`, one per
/// coefficient: the zero drift of the shear channel, that of the slip channel, then one per
/// creep time constant (zero where a coefficient does not apply to the test).
///
/// The creep is that of the shear the model predicts (the measurement minus the residual),
/// not of the measured shear: a creep built from the readings would carry their own
/// differences between tests, and a combination of its terms could then stand in for them.
fn columns(t: &FitTest, r: &[f64], taus: &[f64]) -> Vec<Vec<f64>> {
    let n = t.len().min(r.len());
    let k = t.weight.sqrt() / t.noise_sd;
    let zero: Vec<f64> = (0..n).map(|i| -zero_drift_term(t, k, i)).collect();
    let mut cols = match t.control {
        Control::Slip => vec![zero, vec![0.0; n]],
        Control::Shear => vec![vec![0.0; n], zero],
    };
    let predicted: Vec<f64> = (0..n)
        .map(|i| t.measured[i] + r[i] / (k * t.weight_of(i).sqrt()))
        .collect();
    let mut y = Vec::new();
    for &tau in taus {
        cols.push(if t.control == Control::Slip {
            creep_regressor(t, &predicted, tau, &mut y);
            y.iter()
                .enumerate()
                .map(|(i, &v)| creep_term(k, t.weight_of(i), v))
                .collect()
        } else {
            vec![0.0; n]
        });
    }
    cols
}

/// Solves the drift's normal equations `normal` c = `rhs` with every term scaled to unit norm
/// and the combinations of terms shorter than [`DRIFT_COLLINEAR_SHARE`] of the longest
/// dropped (a truncated singular value decomposition; a term that never applies has a zero
/// coefficient).
fn solve_collinear_dropped(
    normal: &nalgebra::DMatrix<f64>,
    rhs: &nalgebra::DVector<f64>,
    collinear_share: f64,
) -> Vec<f64> {
    let m = rhs.len();
    let scale: Vec<f64> = (0..m)
        .map(|j| {
            let d = normal[(j, j)];
            if d > 0.0 {
                1.0 / d.sqrt()
            } else {
                0.0
            }
        })
        .collect();
    if scale.iter().all(|&s| s == 0.0) {
        return vec![0.0; m];
    }
    let scaled = nalgebra::DMatrix::from_fn(m, m, |j, l| scale[j] * normal[(j, l)] * scale[l]);
    let scaled_rhs = nalgebra::DVector::from_fn(m, |j, _| scale[j] * rhs[j]);
    let svd = scaled.svd(true, true);
    // The normal matrix's singular values are the squares of the terms' norms.
    let cutoff = collinear_share.powi(2) * svd.singular_values.max();
    match svd.solve(&scaled_rhs, cutoff) {
        Ok(y) => (0..m).map(|j| scale[j] * y[j]).collect(),
        Err(_) => vec![0.0; m],
    }
}

/// Fits the drift of the measurement to the weighted residuals `r` of `tests` (one slice per
/// test, in the noise units of [`crate::dataset::residuals_into`]) on the rows `learn` marks,
/// and removes it from the rows `apply` gives for each test. Rows with a non-finite residual
/// are not learned on and are left as they are.
pub fn remove_drift(
    tests: &[FitTest],
    r: &mut [&mut [f64]],
    learn: impl Fn(usize, usize) -> bool,
    apply: impl Fn(usize) -> std::ops::Range<usize>,
) -> FittedDrift {
    remove_drift_reading(tests, r, learn, apply, DRIFT_COLLINEAR_SHARE)
}

/// [`remove_drift`] with the combinations of terms shorter than `collinear_share` of the
/// longest dropped.
fn remove_drift_reading(
    tests: &[FitTest],
    r: &mut [&mut [f64]],
    learn: impl Fn(usize, usize) -> bool,
    apply: impl Fn(usize) -> std::ops::Range<usize>,
    collinear_share: f64,
) -> FittedDrift {
    let taus = creep_time_constants(tests);
    let m = 2 + taus.len();
    let cols: Vec<Vec<Vec<f64>>> = tests
        .iter()
        .zip(r.iter())
        .map(|(t, rt)| columns(t, rt, &taus))
        .collect();
    // Normal equations summed over the tests' learned rows.
    let mut normal = nalgebra::DMatrix::<f64>::zeros(m, m);
    let mut rhs = nalgebra::DVector::<f64>::zeros(m);
    for (ti, rt) in r.iter().enumerate() {
        let c = &cols[ti];
        for i in 0..c[0].len() {
            if !(learn(ti, i) && rt[i].is_finite()) {
                continue;
            }
            for j in 0..m {
                let cj = c[j][i];
                if cj == 0.0 {
                    continue;
                }
                rhs[j] += cj * rt[i];
                for l in j..m {
                    normal[(j, l)] += cj * c[l][i];
                }
            }
        }
    }
    for j in 0..m {
        for l in 0..j {
            normal[(j, l)] = normal[(l, j)];
        }
    }
    let coef = solve_collinear_dropped(&normal, &rhs, collinear_share);
    for (ti, rt) in r.iter_mut().enumerate() {
        let rows = apply(ti);
        let end = rows.end.min(cols[ti][0].len());
        for i in rows.start.min(end)..end {
            if rt[i].is_finite() {
                rt[i] -= cols[ti]
                    .iter()
                    .zip(&coef)
                    .map(|(c, b)| b * c[i])
                    .sum::<f64>();
            }
        }
    }
    FittedDrift {
        shear_rate: coef[0],
        slip_rate: coef[1],
        creep: coef[2..].to_vec(),
        creep_taus: taus,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A slip-controlled test of `n` rows at 1 s whose measured shear is `shear(t)`, noise 1.
    fn test(n: usize, shear: impl Fn(f64) -> f64) -> FitTest {
        let time: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let measured: Vec<f64> = time.iter().map(|&t| shear(t)).collect();
        let mut t = FitTest::new(
            "t",
            Control::Slip,
            time.clone(),
            time.iter().map(|&t| 0.01 * t).collect(),
            measured,
            vec![100.0; n],
        );
        t.noise_sd = 1.0;
        t
    }

    /// The residuals (prediction − measurement) of a model that predicts `truth` exactly.
    fn residuals(t: &FitTest, truth: impl Fn(f64) -> f64) -> Vec<f64> {
        (0..t.len())
            .map(|i| truth(t.time[i]) - t.measured[i])
            .collect()
    }

    #[test]
    fn the_drift_costs_one_coefficient_per_channel_measured_and_per_creep_term() {
        let slip = test(50, |_| 0.0);
        assert_eq!(
            drift_coefficients(std::slice::from_ref(&slip)),
            1 + CREEP_TIME_CONSTANTS.len()
        );
        // A traction-controlled test adds the slip channel's zero drift (no creep of its own).
        let mut traction = test(50, |_| 0.0);
        traction.control = Control::Shear;
        assert_eq!(drift_coefficients(&[traction.clone()]), 1);
        assert_eq!(
            drift_coefficients(&[slip, traction]),
            2 + CREEP_TIME_CONSTANTS.len()
        );
        assert_eq!(drift_coefficients(&[]), 0);
    }

    #[test]
    fn a_creep_shared_by_two_tests_is_found_and_removed() {
        // Two tests at 30 and 60 kPa read by a cell creeping 4 % with τ = 150 s (between the
        // grid's time constants: the terms together stand for it).
        let creep = |f0: f64| move |t: f64| f0 * (1.0 + 0.04 * (1.0 - (-t / 150.0).exp()));
        let tests = [test(1001, creep(30.0)), test(601, creep(60.0))];
        let mut r: Vec<Vec<f64>> = vec![
            residuals(&tests[0], |_| 30.0),
            residuals(&tests[1], |_| 60.0),
        ];
        let before: f64 = r.iter().flatten().map(|v| v * v).sum();
        let mut slices: Vec<&mut [f64]> = r.iter_mut().map(|v| &mut v[..]).collect();
        let d = remove_drift(&tests, &mut slices, |_, _| true, |ti| 0..tests[ti].len());
        let after: f64 = r.iter().flatten().map(|v| v * v).sum();
        // The terms are nearly collinear and their coefficients are not read one by one: what
        // counts is that together they take out a creep of up to 2.4 kPa to a few hundredths.
        assert_eq!(d.creep_taus.len(), d.creep.len());
        let worst = r.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(
            worst < 0.05 && after < 1e-3 * before,
            "{d:?}: {before} → {after}, worst {worst}"
        );
    }

    #[test]
    fn a_creep_cannot_stand_in_for_a_difference_between_tests() {
        // Two tests under the same load, one read 5 % high, the other 5 % low, from the first
        // row on (as two specimens' friction differs): a drift shared by both takes out
        // nothing of it; a drift of each test's own would take out most of it.
        let tests = [test(500, |_| 31.5), test(500, |_| 28.5)];
        let residuals_after = |tests: &[FitTest; 2]| {
            let mut r = [
                residuals(&tests[0], |_| 30.0),
                residuals(&tests[1], |_| 30.0),
            ];
            let mut slices: Vec<&mut [f64]> = r.iter_mut().map(|v| &mut v[..]).collect();
            remove_drift(tests, &mut slices, |_, _| true, |ti| 0..tests[ti].len());
            r.iter().flatten().map(|v| v * v).sum::<f64>()
        };
        let before = 2.0 * 500.0 * 1.5 * 1.5;
        let after = residuals_after(&tests);
        assert!(after > 0.99 * before, "{before} → {after}");
    }

    #[test]
    fn a_zero_drift_linear_in_time_shared_by_the_tests_is_removed() {
        // The shear channel drifts at 0.01 kPa/s in both tests, whatever their load.
        let tests = [
            test(200, |t| 10.0 + 0.01 * t),
            test(300, |t| 40.0 + 0.01 * t),
        ];
        let mut r = vec![
            residuals(&tests[0], |_| 10.0),
            residuals(&tests[1], |_| 40.0),
        ];
        let mut slices: Vec<&mut [f64]> = r.iter_mut().map(|v| &mut v[..]).collect();
        let d = remove_drift(&tests, &mut slices, |_, _| true, |ti| 0..tests[ti].len());
        assert!((d.shear_rate - 0.01).abs() < 1e-3, "{d:?}");
        assert!(r.iter().flatten().all(|v| v.abs() < 0.05), "{r:?}");
    }

    #[test]
    fn what_is_learned_on_some_rows_is_applied_to_the_others() {
        // Learned on the first half only, the drift predicts the second half's.
        let t = test(400, |t| 50.0 * (1.0 + 0.05 * (1.0 - (-t / 40.0).exp())));
        let tests = [t];
        let mut r = [residuals(&tests[0], |_| 50.0)];
        let mut slices: Vec<&mut [f64]> = r.iter_mut().map(|v| &mut v[..]).collect();
        remove_drift(&tests, &mut slices, |_, i| i < 200, |_| 0..400);
        // Learned on 200 s, the creep terms with τ of 126 s and more are alike to within the
        // readings' reproducibility there, and the tail is extrapolated from fewer shapes.
        let tail: f64 = r[0][200..].iter().map(|v| v.abs()).fold(0.0, f64::max);
        assert!(
            tail < 0.25 * 2.5,
            "the held rows keep {tail} of a 2.5 kPa creep"
        );
    }

    #[test]
    fn terms_the_learned_rows_cannot_tell_apart_are_not_traded_against_each_other() {
        // The learned test, 150 s at 50 kPa, leaves a misfit that is no drift (a wave of a
        // few noise units, a shape the model lacks); the held-out test, 1200 s at 200 kPa, has
        // none. Over 150 s the zero drift and the creep terms of τ 380 s and more are nearly
        // linear in time: a plain least-squares drift trades them against each other to fit
        // the wave, with coefficients of opposite sign that cancel at 50 kPa and not at
        // 200 kPa.
        let learned = test(150, |t| 50.0 + 3.0 * (t / 25.0).sin());
        let held = test(1200, |_| 200.0);
        let tests = [learned, held];
        let read = |share: f64| {
            let mut r = [
                residuals(&tests[0], |_| 50.0),
                residuals(&tests[1], |_| 200.0),
            ];
            let mut slices: Vec<&mut [f64]> = r.iter_mut().map(|v| &mut v[..]).collect();
            let d = remove_drift_reading(
                &tests,
                &mut slices,
                |ti, _| ti == 0,
                |ti| 0..tests[ti].len(),
                share,
            );
            let held_ssr: f64 = r[1].iter().map(|v| v * v).sum();
            let largest_creep = d.creep.iter().fold(0.0f64, |m, c| m.max(c.abs()));
            (held_ssr, largest_creep)
        };
        // Nearly machine precision: every combination read.
        let (plain_ssr, plain_creep) = read(1e-7);
        let (ssr, creep) = read(DRIFT_COLLINEAR_SHARE);
        assert!(
            ssr < 0.01 * plain_ssr && creep < 0.1 * plain_creep,
            "held out at 200 kPa: {ssr} (creep {creep}) against {plain_ssr} (creep {plain_creep}) read plainly"
        );
    }

    #[test]
    fn under_traction_control_only_the_zero_drift_applies() {
        let mut t = test(100, |t| 0.5 + 0.001 * t);
        t.control = Control::Shear;
        let tests = [t];
        let mut r = [residuals(&tests[0], |_| 0.5)];
        let mut slices: Vec<&mut [f64]> = r.iter_mut().map(|v| &mut v[..]).collect();
        let d = remove_drift(&tests, &mut slices, |_, _| true, |_| 0..100);
        assert!(d.creep.is_empty() && d.creep_taus.is_empty(), "{d:?}");
        assert!(
            (d.slip_rate - 0.001).abs() < 1e-6 && d.shear_rate == 0.0,
            "{d:?}"
        );
    }
}
