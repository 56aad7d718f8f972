//! One test as the calibration's objective sees it ([`FitTest`]: the conditioned imposed
//! column, the measured one, its noise and weights), and the typical slip rate of a set.

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
    /// alternative, `subfric_fit::drift`); set on every test of a set or on none.
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
        let noise = crate::condition::noise_sd(&time, &measured).max(1e-4 * scale);
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
    let r = crate::stats::median(&mut rates).unwrap_or(0.0);
    if r > 0.0 && r.is_finite() {
        r
    } else {
        0.01
    }
}
