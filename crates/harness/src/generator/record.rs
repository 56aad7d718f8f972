//! What a logger writes of a run: noise on both columns (white, and a slowly correlated AR(1)
//! part on the shear), the gaps of [`Gap`], quantised displacement, timestamps to the
//! millisecond, and files cut out of a longer run.

use super::effects::Gap;
use super::path::Run;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use subfric_data::{ControlColumn, TestData, TestSpec};

/// The noise of the recorded columns.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Noise {
    /// SD of the white shear noise [kPa].
    pub white_kpa: f64,
    /// Stationary SD of the AR(1) shear noise [kPa] (0: none).
    pub ar1_kpa: f64,
    /// Its correlation time [s]: the lag-one coefficient of rows Δt apart is exp(−Δt/τ).
    pub ar1_tau_s: f64,
    /// SD of the white noise on the recorded displacement [mm].
    pub slip_mm: f64,
}

impl Noise {
    /// SD of the whole shear noise [kPa].
    pub fn shear_sd(&self) -> f64 {
        self.white_kpa.hypot(self.ar1_kpa)
    }
}

/// How the logger writes numbers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Resolution {
    /// Step of the displacement [mm] (1e-4: a 0.1 µm encoder).
    pub slip_mm: f64,
    /// Step of the shear [kPa].
    pub shear_kpa: f64,
    /// Step of the timestamps [s].
    pub time_s: f64,
}

/// A file cut out of the run at its row `from`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Cut {
    /// First row kept.
    pub from: usize,
    /// Time and displacement start again at zero (else they run on from the longer run).
    pub rezeroed: bool,
}

/// A standard normal draw.
pub fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.gen::<f64>().max(1e-300);
    let u2: f64 = rng.gen();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// `x` rounded to the step `q`, as the nearest double of a decimal with as many digits (so the
/// CSV shows `1.2345`, not `1.2345000000000002`).
pub fn quantise(x: f64, q: f64) -> f64 {
    let per_unit = (1.0 / q).round();
    let v = (x * per_unit).round() / per_unit;
    // No "-0" in a file.
    if v == 0.0 {
        0.0
    } else {
        v
    }
}

/// The columns of a recorded test.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Recorded {
    /// Time [s].
    pub t: Vec<f64>,
    /// Displacement [mm].
    pub u: Vec<f64>,
    /// Shear [kPa].
    pub f: Vec<f64>,
    /// Normal stress [kPa].
    pub p: Vec<f64>,
}

/// The shear a noise-free logger would see: the run's shear plus the gap (at the run's time).
pub fn clean_shear(run: &Run, gap: Option<&Gap>) -> Vec<f64> {
    match gap {
        Some(g) => run
            .f
            .iter()
            .zip(g.offsets(&run.t, &run.f))
            .map(|(f, o)| f + o)
            .collect(),
        None => run.f.clone(),
    }
}

/// Records `run` as a logger would: the gap added, noise, the cut, rounding.
pub fn record(
    run: &Run,
    gap: Option<&Gap>,
    noise: &Noise,
    res: &Resolution,
    cut: Option<Cut>,
    rng: &mut ChaCha8Rng,
) -> Recorded {
    let clean = clean_shear(run, gap);
    let n = run.t.len();
    let mut ar = noise.ar1_kpa * gauss(rng);
    let mut out = Recorded::default();
    let from = cut.map_or(0, |c| c.from.min(n.saturating_sub(1)));
    let (t0, u0) = match cut {
        Some(c) if c.rezeroed => (run.t[from], run.u[from]),
        _ => (0.0, 0.0),
    };
    for (i, clean_i) in clean.iter().enumerate() {
        if i > 0 {
            let a = (-(run.t[i] - run.t[i - 1]) / noise.ar1_tau_s).exp();
            ar = a * ar + (1.0 - a * a).max(0.0).sqrt() * noise.ar1_kpa * gauss(rng);
        }
        let shear = clean_i + ar + noise.white_kpa * gauss(rng);
        let slip = run.u[i] + noise.slip_mm * gauss(rng);
        if i < from {
            continue;
        }
        let mut t = quantise(run.t[i] - t0, res.time_s);
        if let Some(&last) = out.t.last() {
            if t <= last {
                t = quantise(last + res.time_s, res.time_s);
            }
        }
        out.t.push(t);
        out.u.push(quantise(slip - u0, res.slip_mm));
        out.f.push(quantise(shear, res.shear_kpa));
        out.p.push(run.p[i]);
    }
    out
}

/// A slip-controlled test of the data format from recorded columns.
pub fn test_data(name: &str, normal_kpa: f64, rec: Recorded, comments: Vec<String>) -> TestData {
    let rows = rec.t.len();
    TestData {
        spec: TestSpec::new(
            name,
            &format!("{name}.csv"),
            ControlColumn::Slip,
            normal_kpa,
        ),
        path: format!("{name}.csv").into(),
        time_s: rec.t,
        slip_mm: rec.u,
        shear_kpa: rec.f,
        normal_kpa: rec.p,
        friction_given: false,
        line_of_row: (0..rows)
            .map(|i| i + 2 + usize::from(!comments.is_empty()))
            .collect(),
        comments,
        reading_notes: Vec::new(),
        channels: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn quantised_values_are_on_the_grid_and_print_as_decimals() {
        for (x, q, text) in [
            (1.23456789, 1e-4, "1.2346"),
            (0.30000000000000004, 1e-4, "0.3"),
            (-0.00004, 1e-4, "0"),
            (12.3456, 1e-3, "12.346"),
        ] {
            let v = quantise(x, q);
            assert_eq!(format!("{v}"), text);
            assert!((v / q - (v / q).round()).abs() < 1e-6);
        }
    }

    #[test]
    fn ar1_noise_has_its_sd_and_correlation() {
        let n = 200_000;
        let run = Run {
            t: (0..n).map(|i| i as f64).collect(),
            u: vec![0.0; n],
            f: vec![0.0; n],
            p: vec![100.0; n],
            rate: vec![0.0; n],
        };
        let noise = Noise {
            white_kpa: 0.0,
            ar1_kpa: 0.5,
            ar1_tau_s: 5.0,
            slip_mm: 0.0,
        };
        let res = Resolution {
            slip_mm: 1e-4,
            shear_kpa: 1e-6,
            time_s: 1e-3,
        };
        let rec = record(
            &run,
            None,
            &noise,
            &res,
            None,
            &mut ChaCha8Rng::seed_from_u64(3),
        );
        let var = rec.f.iter().map(|x| x * x).sum::<f64>() / n as f64;
        let lag1 = rec.f.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (n - 1) as f64 / var;
        assert!((var.sqrt() / 0.5 - 1.0).abs() < 0.05, "SD {}", var.sqrt());
        assert!(
            (lag1 - (-0.2f64).exp()).abs() < 0.02,
            "lag-one correlation {lag1}"
        );
    }
}
