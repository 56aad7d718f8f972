//! Tests as the objective sees them, and the residual vector.

use serde::Serialize;
use subfric_model::{simulate_predicted_into, Control, Initial, Model, Protocol, SimError};

/// One test prepared for fitting.
#[derive(Clone, Debug)]
pub struct FitTest {
    /// Test name (set name prefixed in joint fits of several sets).
    pub name: String,
    /// Imposed quantity.
    pub control: Control,
    /// Time [s].
    pub time: Vec<f64>,
    /// Imposed column (conditioned: measurement jitter removed).
    pub imposed: Vec<f64>,
    /// Measured column: shear [kPa] under slip control, slip [mm] under traction control.
    pub measured: Vec<f64>,
    /// Normal stress per row [kPa].
    pub normal: Vec<f64>,
    /// Slip at the first row (traction control).
    pub initial_slip: f64,
    /// User weight of the test (1 by default).
    pub weight: f64,
    /// Noise standard deviation of the measured column, estimated from the data itself.
    pub noise_sd: f64,
    /// Scale of the measured column (peak |shear|, or slip range) for relative errors.
    pub scale: f64,
    /// Rows whose residuals count; the others get residual 0 (held out). All rows by default.
    pub fit_rows: std::ops::Range<usize>,
    /// Project a drift of the measurement out of the residuals (the measurement-drift
    /// alternative, [`crate::drift`]); set on every test of a set or on none.
    pub detrend: bool,
    /// How the test starts (rest, loaded, or already sliding).
    pub initial: Initial,
    /// Rows of the original record each row stands for (a thinned test keeps one row per bin,
    /// the bin's mean measurement, weighted by its size); empty when every row is one row.
    pub row_weight: Vec<f64>,
}

impl FitTest {
    /// Builds a test and estimates its noise and scale.
    pub fn new(
        name: impl Into<String>,
        control: Control,
        time: Vec<f64>,
        imposed: Vec<f64>,
        measured: Vec<f64>,
        normal: Vec<f64>,
    ) -> FitTest {
        let scale = match control {
            Control::Slip => measured.iter().fold(0.0f64, |m, v| m.max(v.abs())),
            Control::Shear => {
                let (lo, hi) = measured
                    .iter()
                    .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
                hi - lo
            }
        }
        .max(1e-12);
        // A floor keeps noise-free (synthetic) data from getting infinite weight.
        let noise = subfric_reading::condition::noise_sd(&time, &measured).max(1e-4 * scale);
        FitTest {
            name: name.into(),
            control,
            initial_slip: match control {
                Control::Slip => 0.0,
                Control::Shear => measured.first().copied().unwrap_or(0.0),
            },
            time,
            imposed,
            measured,
            normal,
            weight: 1.0,
            noise_sd: noise,
            scale,
            fit_rows: 0..usize::MAX,
            detrend: false,
            initial: Initial::Rest,
            row_weight: Vec::new(),
        }
    }

    /// Weight of row `i` (the number of original rows it stands for).
    #[inline]
    pub fn weight_of(&self, i: usize) -> f64 {
        self.row_weight.get(i).copied().unwrap_or(1.0)
    }

    /// Number of original rows the test stands for.
    pub fn rows_represented(&self) -> f64 {
        if self.row_weight.is_empty() {
            self.len() as f64
        } else {
            self.row_weight.iter().sum()
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// True when the test has no rows.
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// The protocol driving the model.
    pub fn protocol(&self) -> Protocol<'_> {
        self.protocol_until(self.len())
    }

    /// The protocol of the first `end` rows.
    pub fn protocol_until(&self, end: usize) -> Protocol<'_> {
        let end = end.min(self.len());
        Protocol {
            control: self.control,
            time: &self.time[..end],
            imposed: &self.imposed[..end],
            normal: &self.normal[..end],
            initial_slip: self.initial_slip,
            initial: self.initial,
        }
    }

    /// The rows that count in the residuals, clipped to the test.
    pub fn counted_rows(&self) -> std::ops::Range<usize> {
        let end = self.fit_rows.end.min(self.len());
        self.fit_rows.start.min(end)..end
    }

    /// The model's prediction of the measured column.
    pub fn predict(&self, m: &Model) -> Result<Vec<f64>, SimError> {
        let mut out = Vec::new();
        simulate_predicted_into(m, &self.protocol(), &mut out)?;
        Ok(out)
    }
}

/// Typical slip rate of the tests [mm/s]: the median imposed rate while sliding under slip
/// control, or the mean slip rate under traction control.
pub fn typical_rate(tests: &[FitTest]) -> f64 {
    let mut rates = Vec::new();
    for t in tests {
        match t.control {
            Control::Slip => {
                let r: Vec<f64> = t
                    .imposed
                    .windows(2)
                    .zip(t.time.windows(2))
                    .map(|(u, tt)| ((u[1] - u[0]) / (tt[1] - tt[0])).abs())
                    .collect();
                let max = r.iter().cloned().fold(0.0, f64::max);
                rates.extend(r.into_iter().filter(|v| *v > 0.01 * max));
            }
            Control::Shear => {
                let span = t.time.last().unwrap_or(&0.0) - t.time.first().unwrap_or(&0.0);
                if span > 0.0 {
                    rates.push(t.scale / span);
                }
            }
        }
    }
    let r = subfric_reading::stats::median(&mut rates).unwrap_or(0.0);
    if r > 0.0 && r.is_finite() {
        r
    } else {
        0.01
    }
}

/// Residual assigned to every row of a test the model cannot simulate (e.g. runaway under
/// traction control), in noise units: large, finite, so optimisers move away.
pub const FAILED_RESIDUAL: f64 = 1e3;

/// A model run simulates its tests in parallel from this many tests ...
const PARALLEL_TESTS: usize = 64;
/// ... and this many rows: a set of many tests keeps every core busy even where the calibration
/// runs one model at a time (the last local run, the last profile). Below, one thread does it
/// (a small problem would only pay for the threads). The residuals are the same either way.
const PARALLEL_ROWS: usize = 20_000;

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
    let simulated: Vec<bool> = if tests.len() >= PARALLEL_TESTS && total >= PARALLEL_ROWS {
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
            if t.row_weight.is_empty() {
                for i in rows.clone() {
                    out[i] = k * (scratch[i] - t.measured[i]);
                }
            } else {
                for i in rows.clone() {
                    out[i] = k * t.row_weight[i].sqrt() * (scratch[i] - t.measured[i]);
                }
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
