//! The residual vector of tests as the objective sees them ([`FitTest`], read by
//! `subfric-reading`).

use crate::residuals::Bounded;
use serde::Serialize;
use subfric_model::{simulate_predicted_into, simulate_predicted_while, Control, Model};
use subfric_reading::FitTest;

/// Residual assigned to every row of a test the model cannot simulate (e.g. runaway under
/// traction control), in noise units: large, finite, so optimisers move away.
pub const FAILED_RESIDUAL: f64 = 1e3;

/// A model run simulates its tests in parallel from this many tests ...
const PARALLEL_TESTS: usize = 64;
/// ... and this many rows: a set of many tests keeps every core busy even where the calibration
/// runs one model at a time (the last local run, the last profile). Below, one thread does it
/// (a small problem would only pay for the threads). The residuals are the same either way.
const PARALLEL_ROWS: usize = 20_000;

/// Whether a model run simulates `tests` (`rows` in all) in parallel.
fn in_parallel(tests: &[FitTest], rows: usize) -> bool {
    tests.len() >= PARALLEL_TESTS && rows >= PARALLEL_ROWS
}

/// Writes the weighted, noise-normalised residuals (prediction − measurement)·√w/σ of all
/// tests into `out`; returns how many tests failed to simulate.
pub fn residuals_into(
    tests: &[FitTest],
    m: &Model,
    out: &mut Vec<f64>,
    scratch: &mut Vec<f64>,
) -> usize {
    use rayon::prelude::*;
    out.clear();
    let total: usize = tests.iter().map(FitTest::len).sum();
    out.resize(total, 0.0);
    let mut slices = Vec::with_capacity(tests.len());
    let mut rest = &mut out[..];
    for t in tests {
        let (here, after) = rest.split_at_mut(t.len());
        slices.push(here);
        rest = after;
    }
    let simulated: Vec<bool> = if in_parallel(tests, total) {
        tests
            .par_iter()
            .zip(slices.par_iter_mut())
            .map_init(Vec::new, |scratch, (t, r)| test_residuals(t, m, r, scratch))
            .collect()
    } else {
        tests
            .iter()
            .zip(slices.iter_mut())
            .map(|(t, r)| test_residuals(t, m, r, scratch))
            .collect()
    };
    if tests.iter().any(|t| t.detrend) {
        // One drift for the whole set (the load cell's creep is shared by its tests), learned
        // on the tests the model could simulate.
        crate::drift::remove_drift(
            tests,
            &mut slices,
            |ti, i| simulated[ti] && tests[ti].counted_rows().contains(&i),
            |ti| {
                if simulated[ti] {
                    tests[ti].counted_rows()
                } else {
                    0..0
                }
            },
        );
    }
    let failed = simulated.iter().filter(|ok| !**ok).count();
    failed
}

/// [`residuals_into`], unless the sum of squares of the residuals, added in order, is sure to
/// end above `ceiling` (or to be NaN): then [`Bounded::Above`], the model run stopped at the row
/// where that became sure, and `out` holds nothing meaningful. A set whose drift is removed
/// (every residual moves with the drift learned from all of them) or whose tests run in
/// parallel is computed whole.
pub fn residuals_into_unless_above(
    tests: &[FitTest],
    m: &Model,
    out: &mut Vec<f64>,
    scratch: &mut Vec<f64>,
    ceiling: f64,
) -> Bounded {
    let total: usize = tests.iter().map(FitTest::len).sum();
    if tests.iter().any(|t| t.detrend) || in_parallel(tests, total) {
        residuals_into(tests, m, out, scratch);
        return Bounded::Computed;
    }
    out.clear();
    out.resize(total, 0.0);
    let mut sum = 0.0;
    let mut start = 0;
    for t in tests {
        let here = &mut out[start..start + t.len()];
        if test_residuals_unless_above(t, m, here, scratch, &mut sum, ceiling) == Bounded::Above {
            return Bounded::Above;
        }
        start += t.len();
    }
    Bounded::Computed
}

/// `sum` with `rows` residuals of [`FAILED_RESIDUAL`] added one by one: what a test that fails
/// to simulate adds to the sum of squares.
fn plus_failed_rows(sum: f64, rows: usize) -> f64 {
    (0..rows).fold(sum, |acc, _| acc + FAILED_RESIDUAL * FAILED_RESIDUAL)
}

/// The residuals of one test into `out` (its rows, zeroed) with their squares added to `sum`,
/// as [`test_residuals`] writes them, unless the sum is sure to end above `ceiling`.
///
/// A row's square only raises the sum, so once the sum so far is above the ceiling the whole
/// is — unless the test fails to simulate further on, when every one of its rows weighs
/// [`FAILED_RESIDUAL`] instead: the run stops only where that sum is above the ceiling too.
fn test_residuals_unless_above(
    t: &FitTest,
    m: &Model,
    out: &mut [f64],
    scratch: &mut Vec<f64>,
    sum: &mut f64,
    ceiling: f64,
) -> Bounded {
    let rows = t.counted_rows();
    if rows.is_empty() {
        return Bounded::Computed;
    }
    let k = t.weight.sqrt() / t.noise_sd;
    let residual = |i: usize, predicted: f64| row_residual(t, k, i, predicted);
    let before = *sum;
    let mut acc = before;
    let mut may_stop = true;
    let run = simulate_predicted_while(m, &t.protocol_until(rows.end), scratch, |i, v| {
        if i < rows.start {
            return true;
        }
        let r = residual(i, v);
        acc += r * r;
        if may_stop && above(acc, ceiling) {
            if above(plus_failed_rows(before, rows.len()), ceiling) {
                return false;
            }
            may_stop = false;
        }
        true
    });
    match run {
        Ok(false) => return Bounded::Above,
        Ok(true) => {
            for i in rows {
                out[i] = residual(i, scratch[i]);
            }
            *sum = acc;
        }
        Err(_) => {
            out[rows.clone()].fill(FAILED_RESIDUAL);
            *sum = plus_failed_rows(before, rows.len());
        }
    }
    // The tests after this one only add to the sum.
    if above(*sum, ceiling) {
        Bounded::Above
    } else {
        Bounded::Computed
    }
}

/// Whether a sum of squares is above `ceiling` or NaN (a NaN sum is never kept).
fn above(sum: f64, ceiling: f64) -> bool {
    !matches!(
        sum.partial_cmp(&ceiling),
        Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
    )
}

/// The residual of row `i` of `t` where the model predicts `predicted`: k √w (predicted −
/// measured), k the test's weight over its noise SD and w the row's weight (1 unless thinned).
#[inline(always)]
fn row_residual(t: &FitTest, k: f64, i: usize, predicted: f64) -> f64 {
    if t.row_weight.is_empty() {
        k * (predicted - t.measured[i])
    } else {
        k * t.row_weight[i].sqrt() * (predicted - t.measured[i])
    }
}

/// The residuals of one test into `out` (its rows, zeroed); false when it failed to simulate.
fn test_residuals(t: &FitTest, m: &Model, out: &mut [f64], scratch: &mut Vec<f64>) -> bool {
    let k = t.weight.sqrt() / t.noise_sd;
    let rows = t.counted_rows();
    if rows.is_empty() {
        return true;
    }
    // The state at a row depends on the whole history: simulate from the start.
    match simulate_predicted_into(m, &t.protocol_until(rows.end), scratch) {
        Ok(()) => {
            for i in rows.clone() {
                out[i] = row_residual(t, k, i, scratch[i]);
            }
            true
        }
        Err(_) => {
            for i in rows {
                out[i] = FAILED_RESIDUAL;
            }
            false
        }
    }
}

/// Misfit of one test.
#[derive(Clone, Debug, Serialize)]
pub struct TestMisfit {
    /// Test name.
    pub name: String,
    /// Rows.
    pub rows: usize,
    /// RMS error in the measured column's unit (kPa or mm).
    pub rms: f64,
    /// RMS error relative to the test's scale [%].
    pub rms_percent: f64,
    /// Estimated noise SD of the measured column.
    pub noise_sd: f64,
    /// RMS error / noise SD (1 = at the noise level).
    pub rms_over_noise: f64,
    /// Mean squared error / noise variance (1 = at the noise level): the misfit as the reports
    /// give it ("× the noise variance"), the square of `rms_over_noise`.
    pub reduced_chi2: f64,
    /// Unit of `rms`.
    pub unit: &'static str,
}

/// Per-row residuals k √w (prediction − measurement) of every test in noise units (k the
/// test's weight over its noise SD, w the row's weight), NaN on every row of a test the model
/// cannot simulate: what the reports' misfits and [`crate::localise`] are made of.
pub fn residuals_in_noise_units(tests: &[FitTest], m: &Model) -> Vec<Vec<f64>> {
    tests
        .iter()
        .map(|t| {
            let k = t.weight.sqrt() / t.noise_sd;
            match t.predict(m) {
                Ok(p) => (0..t.len())
                    .map(|i| k * t.weight_of(i).sqrt() * (p[i] - t.measured[i]))
                    .collect(),
                Err(_) => vec![f64::NAN; t.len()],
            }
        })
        .collect()
}

/// Per-test misfit of a model.
pub fn misfits(tests: &[FitTest], m: &Model) -> Vec<TestMisfit> {
    tests
        .iter()
        .map(|t| {
            let rms = match t.predict(m) {
                Ok(p) => (p
                    .iter()
                    .zip(&t.measured)
                    .map(|(a, b)| (a - b).powi(2))
                    .sum::<f64>()
                    / t.len().max(1) as f64)
                    .sqrt(),
                Err(_) => f64::INFINITY,
            };
            TestMisfit {
                name: t.name.clone(),
                rows: t.len(),
                rms,
                rms_percent: 100.0 * rms / t.scale,
                noise_sd: t.noise_sd,
                rms_over_noise: rms / t.noise_sd,
                reduced_chi2: (rms / t.noise_sd).powi(2),
                unit: match t.control {
                    Control::Slip => "kPa",
                    Control::Shear => "mm",
                },
            }
        })
        .collect()
}
