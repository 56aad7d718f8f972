//! What the rig did, read off the current tests and the fit: the control, rate, normal
//! stress, sampling, slip range and noise the proposals are built from.

use crate::outcome::Rig;
use subfric_model::{Control, Model};
use subfric_reading::stats::median;
use subfric_reading::{typical_rate, FitTest};

/// What a rig did, read off the tests and the fit.
pub fn rig_of(tests: &[FitTest], fit: &Model) -> Rig {
    let slip_rows: usize = tests
        .iter()
        .filter(|t| t.control == Control::Slip)
        .map(|t| t.len())
        .sum();
    let all_rows: usize = tests.iter().map(|t| t.len()).sum();
    let control = if 2 * slip_rows >= all_rows {
        Control::Slip
    } else {
        Control::Shear
    };
    let same: Vec<&FitTest> = tests.iter().filter(|t| t.control == control).collect();
    let mut normals: Vec<f64> = same.iter().flat_map(|t| t.normal.iter().copied()).collect();
    let mut steps: Vec<f64> = same
        .iter()
        .flat_map(|t| t.time.windows(2).map(|w| w[1] - w[0]))
        .filter(|d| *d > 0.0)
        .collect();
    let mut noise: Vec<f64> = same.iter().map(|t| t.noise_sd).collect();
    let slip_range_mm = same
        .iter()
        .map(|t| {
            let col = match control {
                Control::Slip => &t.imposed,
                Control::Shear => &t.measured,
            };
            let (lo, hi) = col
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
            hi - lo
        })
        .fold(0.0f64, f64::max);
    let (max_shear_kpa, period_s) = if control == Control::Shear {
        let tmax = same
            .iter()
            .flat_map(|t| t.imposed.iter())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let mut periods = Vec::new();
        for t in &same {
            let half = 0.5 * tmax;
            let ups = t
                .imposed
                .windows(2)
                .filter(|w| w[0] < half && w[1] >= half)
                .count();
            let span = t.time.last().unwrap_or(&0.0) - t.time.first().unwrap_or(&0.0);
            if ups >= 2 {
                periods.push(span / ups as f64);
            }
        }
        (tmax, median(&mut periods).unwrap_or(0.0))
    } else {
        (0.0, 0.0)
    };
    let owned: Vec<FitTest> = same.iter().map(|t| (*t).clone()).collect();
    let rate = typical_rate(&owned);
    Rig {
        control,
        rate_mm_s: rate,
        normal_stress_kpa: median(&mut normals).unwrap_or(0.0),
        dt_s: median(&mut steps).unwrap_or(0.0),
        slip_range_mm,
        noise_sd: median(&mut noise).unwrap_or(0.0),
        max_shear_kpa,
        period_s,
        decay_rate_per_mm: fit.params.kappa + fit.params.xi / rate.max(1e-300),
    }
}
