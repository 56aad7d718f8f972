//! μ_s and μ_k beside what the record shows. The paper reads μ_s off the measured peak stress
//! ratio and μ_k off the residual one (its Section 5, item 2), then tunes κ, ξ and ũ to the
//! transients. A calibration may move them — a recovery ξ carries part of the steady level, a
//! rate effect shifts it — but when a fitted μ_s lies far above every peak the record shows, or
//! μ_k far below every residual, the fit has usually bent them to make up for something else (a
//! seating toe, a compliance, an effect the model lacks), and a reader must be told.
//!
//! The peak and the residual are read on the first monotonic loading of each slip-controlled
//! test ([`crate::guess::features`]): the peak only where the test starts from rest or loaded
//! and the loading slides past it (a record cut from a longer run starts past its peak; a
//! loading reversed while still rising has not peaked), the residual only where the loading
//! slides long enough after its peak for the excess to have decayed. The fitted model is read
//! the same way on the same tests.
//!
//! μ_s is not the peak, nor μ_k the residual: the model's stress ratio is r μ with r < 1 while
//! μ already falls from μ_s (Table 1 smooth: the paper's μ_s = 0.2 peaks at 0.14), and its
//! steady level is μ_k raised by the recovery ξ (Eq. 24). So what is checked is whether the
//! fitted model keeps the peak and the residual the record shows; where it does, the gap
//! between the parameter and the ratio is the model's shape; where it does not, the fit has
//! traded them for something else, and the report says so.

use crate::fit_test::FitTest;
use crate::guess::features;
// After its peak a loading must slide this many decay lengths for its end to be read as the
// residual stress ratio: one rule with the tests' level readings.
use crate::levels::RESIDUAL_DECAYS;
use crate::stats::median;
use serde::Serialize;
use subfric_model::{Control, Initial, Model};

/// The fitted model keeps a measured stress ratio when it lies within this share of it, or
/// within [`NOISE_MULTIPLE`] noise SDs when the noise is larger: a peak or residual missed by
/// more is a level the fit gave up, not a curve followed to within its noise.
pub const DEPARTURE_SHARE: f64 = 0.03;

/// Noise SDs of friction within which a stress ratio is kept (see [`DEPARTURE_SHARE`]).
pub const NOISE_MULTIPLE: f64 = 3.0;

/// A stress ratio of one test: measured, and of the fitted model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Reading {
    /// Test name.
    pub test: String,
    /// Read on the record.
    pub measured: f64,
    /// Read on the fitted model's curve of the same test.
    pub model: f64,
    /// Within which the model keeps it: the larger of the share and the noise multiple.
    pub tolerance: f64,
}

impl Reading {
    /// Whether the fitted model misses the measured ratio by more than the tolerance.
    pub fn missed(&self) -> bool {
        // A reading that is not a number is missed too.
        (self.model - self.measured)
            .abs()
            .partial_cmp(&self.tolerance)
            .is_none_or(|o| o == std::cmp::Ordering::Greater)
    }
}

/// One base parameter beside the stress ratio the paper reads it off.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReadOff {
    /// `mu_s` or `mu_k`.
    pub param: &'static str,
    /// What the record shows: `peak` (for μ_s) or `residual` (for μ_k).
    pub measured_as: &'static str,
    /// The fitted value.
    pub fitted: f64,
    /// The median of the measured ratio over the tests that show it.
    pub measured: f64,
    /// The median of the fitted model's ratio over the same tests.
    pub model: f64,
    /// Per test.
    pub readings: Vec<Reading>,
    /// The fitted value over the measured median, minus one, in per cent (the model's shape
    /// alone makes μ_s above the peak and μ_k below the residual).
    pub gap_percent: f64,
    /// The fitted model misses the measured ratio of at least one test.
    pub departs: bool,
}

impl ReadOff {
    /// One line for a report.
    pub fn sentence(&self) -> String {
        self.sentence_reading(None)
    }

    /// One line for a report, the fitted value written as `reads` when the data do not
    /// determine it ("not determined (≤ 0.30)": the optimiser's point in a flat valley is no
    /// value to set beside the record's).
    pub fn sentence_reading(&self, reads: Option<&str>) -> String {
        let symbol = if self.param == "mu_s" { "μ_s" } else { "μ_k" };
        let tests = match &self.readings[..] {
            [one] => one.test.clone(),
            many => format!("median of {} tests", many.len()),
        };
        let head = match reads {
            Some(reads) => format!(
                "{symbol} {reads} (the record's {} stress ratio {:.4}, {tests}; the fitted model's {:.4})",
                self.measured_as, self.measured, self.model
            ),
            None => format!(
                "{symbol} {:.4} ({:+.1} % from the record's {} stress ratio {:.4}, {tests}; the fitted model's {:.4})",
                self.fitted, self.gap_percent, self.measured_as, self.measured, self.model
            ),
        };
        if !self.departs {
            return format!(
                "{head}: the model keeps the measured {}; the gap is its shape ({})",
                self.measured_as,
                if self.param == "mu_s" {
                    "r μ with r < 1 while μ falls from μ_s"
                } else {
                    "μ_k raised by the recovery ξ, Eq. 24, and by any rate term"
                }
            );
        }
        let worst = self
            .readings
            .iter()
            .filter(|r| r.missed())
            .max_by(|a, b| {
                let d = |r: &Reading| (r.model - r.measured).abs() / r.tolerance;
                d(a).total_cmp(&d(b))
            })
            .expect("a departure has a missed reading");
        format!(
            "{head}: DEPARTS from what the record shows — in {} the model's {} is {:.4} where the record's is {:.4} ({:+.1} %, more than {:.4})",
            worst.test,
            self.measured_as,
            worst.model,
            worst.measured,
            100.0 * (worst.model / worst.measured - 1.0),
            worst.tolerance
        )
    }
}

/// The peaks and residuals of `tests`, measured and of the fitted `model`, beside μ_s and μ_k;
/// a parameter no test shows is left out, and so is a test the model cannot simulate.
pub fn read_off(tests: &[FitTest], model: &Model) -> Vec<ReadOff> {
    let mut peaks = Vec::new();
    let mut residuals = Vec::new();
    for t in tests.iter().filter(|t| t.control == Control::Slip) {
        // A record that starts at rest (a hold while the normal stress was raised) is read
        // from its first movement.
        let first = t
            .imposed
            .iter()
            .position(|u| (u - t.imposed[0]).abs() > 1e-9)
            .map_or(0, |i| i.saturating_sub(1));
        // The rows from there on, with `measured` as the measured column (only what the
        // features read; no noise estimate of its own).
        let from = |measured: &[f64]| FitTest {
            name: t.name.clone(),
            time: t.time[first..].to_vec(),
            imposed: t.imposed[first..].to_vec(),
            measured: measured[first..].to_vec(),
            normal: t.normal[first..].to_vec(),
            fit_rows: 0..usize::MAX,
            row_weight: Vec::new(),
            ..*t
        };
        let Some(c) = features(&from(&t.measured)) else {
            continue;
        };
        let Ok(predicted) = t.predict(model) else {
            continue;
        };
        let Some(m) = features(&from(&predicted)) else {
            continue;
        };
        let normal = median(&mut t.normal.clone()).unwrap_or(0.0);
        let noise = NOISE_MULTIPLE * t.noise_sd / normal;
        let reading = |measured: f64, model: f64| Reading {
            test: t.name.clone(),
            measured,
            model,
            tolerance: (DEPARTURE_SHARE * measured.abs()).max(noise),
        };
        let peaked = c.slide_after_peak_mm >= c.rise_mm && c.slide_after_peak_mm > 0.0;
        if peaked && !matches!(t.initial, Initial::Sliding { .. }) {
            peaks.push(reading(c.peak, m.peak));
        }
        let slid = c
            .decay_mm
            .is_none_or(|l| c.slide_after_peak_mm >= RESIDUAL_DECAYS * l);
        if slid && c.slide_after_peak_mm > 0.0 {
            residuals.push(reading(c.plateau, m.plateau));
        }
    }
    let p = &model.params;
    [
        ("mu_s", "peak", p.mu_s, peaks),
        ("mu_k", "residual", p.mu_k, residuals),
    ]
    .into_iter()
    .filter_map(|(param, measured_as, fitted, v)| compare(param, measured_as, fitted, v))
    .collect()
}

fn compare(
    param: &'static str,
    measured_as: &'static str,
    fitted: f64,
    mut readings: Vec<Reading>,
) -> Option<ReadOff> {
    readings.retain(|r| r.measured.is_finite() && r.measured > 0.0 && r.model.is_finite());
    if readings.is_empty() || !fitted.is_finite() {
        return None;
    }
    let measured =
        median(&mut readings.iter().map(|r| r.measured).collect::<Vec<_>>()).unwrap_or(0.0);
    let model = median(&mut readings.iter().map(|r| r.model).collect::<Vec<_>>()).unwrap_or(0.0);
    Some(ReadOff {
        param,
        measured_as,
        fitted,
        measured,
        model,
        gap_percent: 100.0 * (fitted / measured - 1.0),
        departs: readings.iter().any(Reading::missed),
        readings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfric_model::{simulate, Control, Params, Protocol};

    /// A slide of 3 mm at 0.01 mm/s of the model, measured without noise.
    fn slide(model: &Model, name: &str, initial: Initial) -> FitTest {
        let time: Vec<f64> = (0..=300).map(f64::from).collect();
        let slip: Vec<f64> = time.iter().map(|t| 0.01 * t).collect();
        let normal = vec![100.0; time.len()];
        let proto = Protocol {
            control: Control::Slip,
            time: &time,
            imposed: &slip,
            normal: &normal,
            initial_slip: 0.0,
            initial: Initial::Rest,
        };
        let shear = simulate(model, &proto)
            .expect("the sample model slides")
            .shear;
        let mut t = FitTest::new(name, Control::Slip, time, slip, shear, normal);
        t.initial = initial;
        t
    }

    #[test]
    fn an_undetermined_parameter_reads_as_its_bound_never_as_the_optimiser_s_point() {
        let r = ReadOff {
            param: "mu_k",
            measured_as: "residual",
            fitted: 1e-9,
            measured: 0.31,
            model: 0.30,
            readings: vec![Reading {
                test: "a".into(),
                measured: 0.31,
                model: 0.30,
                tolerance: 0.02,
            }],
            gap_percent: -100.0,
            departs: false,
        };
        assert!(
            r.sentence().starts_with("μ_k 0.0000 (-100.0 %"),
            "{}",
            r.sentence()
        );
        let s = r.sentence_reading(Some("not determined (≤ 0.2)"));
        assert!(
            s.starts_with("μ_k not determined (≤ 0.2) (the record's residual stress ratio 0.3100"),
            "{s}"
        );
        assert!(!s.contains("0.0000") && !s.contains("%"), "{s}");
    }

    #[test]
    fn the_generating_model_keeps_its_own_peak_and_residual_above_and_below_its_parameters() {
        let model = Model::base(Params::sample()).unwrap();
        let t = slide(&model, "a", Initial::Rest);
        let r = read_off(&[t], &model);
        assert_eq!(r.len(), 2, "{r:?}");
        let (s, k) = (&r[0], &r[1]);
        assert_eq!((s.param, k.param), ("mu_s", "mu_k"));
        // The peak is below μ_s and the residual above μ_k, by the model's shape only.
        assert!(s.measured < s.fitted && k.measured > k.fitted, "{r:?}");
        assert!(!s.departs && !k.departs, "{r:?}");
        assert!(
            s.sentence().contains("the gap is its shape"),
            "{}",
            s.sentence()
        );
    }

    #[test]
    fn a_fit_that_gives_up_the_peak_departs_and_names_the_test() {
        let truth = Model::base(Params::sample()).unwrap();
        let tests = [
            slide(&truth, "a", Initial::Rest),
            slide(&truth, "b", Initial::Rest),
        ];
        // μ_s doubled: the model now peaks far above the record.
        let mut bent = truth;
        bent.params.mu_s *= 2.0;
        let r = read_off(&tests, &bent);
        let s = &r[0];
        assert!(s.departs, "{s:?}");
        assert!(
            s.readings.iter().all(|x| x.model > x.measured * 1.03),
            "{s:?}"
        );
        let line = s.sentence();
        assert!(
            line.contains("DEPARTS") && line.contains(" the model's peak is 0.79"),
            "{line}"
        );
        // A μ_k halved moves the residual the model gives, and is reported too.
        let mut low = truth;
        low.params.mu_k *= 0.5;
        let k = read_off(&tests, &low)
            .into_iter()
            .find(|x| x.param == "mu_k")
            .unwrap();
        assert!(k.departs && k.model < k.measured, "{k:?}");
    }

    #[test]
    fn a_record_cut_from_a_longer_run_or_reversed_while_rising_shows_no_peak() {
        let model = Model::base(Params::sample()).unwrap();
        let t = slide(
            &model,
            "mid-run",
            Initial::Sliding {
                shear_kpa: 30.0,
                rate_mm_s: 0.01,
            },
        );
        let r = read_off(&[t], &model);
        assert!(r.iter().all(|x| x.param != "mu_s"), "{r:?}");
        // A loading cut off while still rising (a slow ũ: the rise spans many rows): its
        // largest value is at its end.
        let mut slow = model;
        slow.params.u_tilde = 0.3;
        let whole = slide(&slow, "rising", Initial::Rest);
        let half = whole
            .measured
            .iter()
            .position(|m| *m > 0.5 * whole.measured[300])
            .unwrap();
        let n = half + 3;
        let rising = FitTest::new(
            "rising",
            Control::Slip,
            whole.time[..n].to_vec(),
            whole.imposed[..n].to_vec(),
            whole.measured[..n].to_vec(),
            whole.normal[..n].to_vec(),
        );
        assert!(n >= 20, "{n} rows");
        assert!(read_off(&[rising], &slow).is_empty());
    }
}
