//! Time trend: the interface's friction drifts with the time since the test started, whatever
//! it does — ageing of the metal surface (oxidation, moisture), a slow temperature change of the
//! specimen. T(t) = c t (linear) or T(t) = Δ (1 − exp(−t/t_s)) (saturating).
//!
//! On tests at one normal stress this looks like a drift of the shear measurement (which
//! `subfric diagnose` already weighs as the non-physical alternative), so the diagnosis tries
//! this family only when the user names it (`diagnose --with-family time-trend`). Where the
//! normal stress differs between tests, or a test unloads, the two part: a friction trend
//! scales with the normal stress and acts only on the cone, a drift of the measurement does
//! neither.

use super::{DataScales, FormGuess, Shows, TermFamily, TermForm, TermParam, ANY, MAX_TERM_PARAMS};

/// The time-trend family (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct TimeTrend;

const PARAMS: [TermParam; 3] = [
    TermParam {
        key: "time_trend.c",
        name: "c",
        unit: "1/s",
        log_scale: false,
        bounds: (-1e-2, 1e-2),
        default: 0.0,
        expected: "a finite rate of change of friction [1/s]",
        within: ANY,
        reference: false,
    },
    TermParam {
        key: "time_trend.delta",
        name: "delta",
        unit: "",
        log_scale: false,
        bounds: (-0.5, 0.5),
        default: 0.0,
        expected: "a finite change of the friction coefficient",
        within: ANY,
        reference: false,
    },
    TermParam {
        key: "time_trend.t_s",
        name: "t_s",
        unit: "s",
        log_scale: true,
        bounds: (1.0, 1e7),
        default: 1000.0,
        expected: "a finite time > 0 [s]",
        within: ANY,
        reference: false,
    },
];

const LINEAR: usize = 0;

const FORMS: [TermForm; 2] = [
    TermForm {
        key: "linear",
        describe: "linear in time, c t",
        params: &[0],
    },
    TermForm {
        key: "saturating",
        describe: "saturating in time, delta (1 - exp(-t/t_s))",
        params: &[1, 2],
    },
];

impl TermFamily for TimeTrend {
    fn name(&self) -> &'static str {
        "time-trend"
    }

    fn describe(&self) -> &'static str {
        "time trend: friction drifts with the time since the test started (surface ageing, temperature)"
    }

    fn params(&self) -> &'static [TermParam] {
        &PARAMS
    }

    fn forms(&self) -> &'static [TermForm] {
        &FORMS
    }

    fn shows(&self) -> &'static [Shows] {
        &[Shows::AfterFirstLoading]
    }

    fn tried_by_default(&self) -> bool {
        false
    }

    fn applies(&self, data: &DataScales) -> bool {
        data.duration_s > 0.0
    }

    fn guess(&self, form: usize, data: &DataScales) -> FormGuess {
        // A trend worth naming changes friction by a few hundredths over the longest test.
        let t = data.duration_s.max(1.0);
        if form == LINEAR {
            FormGuess {
                starts: vec![vec![0.03 / t], vec![-0.03 / t], vec![0.005 / t]],
                neutral: vec![0.0],
                bounds: vec![(0, -1.0 / t, 1.0 / t)],
                references: vec![],
            }
        } else {
            FormGuess {
                starts: vec![
                    vec![0.03, t / 3.0],
                    vec![-0.03, t / 3.0],
                    vec![0.03, 3.0 * t],
                ],
                neutral: vec![0.0, t],
                bounds: vec![(1, t / 100.0, 10.0 * t)],
                references: vec![],
            }
        }
    }

    fn term(&self, form: usize, p: &[f64; MAX_TERM_PARAMS], _s: f64, t: f64) -> (f64, f64) {
        // Neither form depends on slip: the slope in s is zero.
        if form == LINEAR {
            (p[0] * t, 0.0)
        } else {
            (p[1] * -(-t / p[2]).exp_m1(), 0.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_linear_form_grows_with_time_and_the_saturating_one_levels_off() {
        let mut p = [0.0; MAX_TERM_PARAMS];
        p[0] = 1e-4;
        p[1] = 0.05;
        p[2] = 100.0;
        let f = TimeTrend;
        assert_eq!(f.term(0, &p, 7.0, 0.0), (0.0, 0.0));
        assert!((f.term(0, &p, 0.0, 300.0).0 - 0.03).abs() < 1e-15);
        let early = f.term(1, &p, 0.0, 1.0).0;
        assert!((early - 0.05 * (1.0 - (-0.01f64).exp())).abs() < 1e-15);
        assert!((f.term(1, &p, 0.0, 1e5).0 - 0.05).abs() < 1e-12);
    }

    #[test]
    fn steady_sliding_carries_the_trend_times_the_normal_stress() {
        // Closed form: once a contact slides steadily (r = 1, μ at its steady value) the shear
        // is p (μ_ss + T(t)); with and without the trend it differs by p c t exactly.
        use crate::{simulate, Control, Extensions, Initial, Model, Params, Protocol};
        let time: Vec<f64> = (0..=2000).map(|i| i as f64 * 0.5).collect();
        let imposed: Vec<f64> = time.iter().map(|t| 0.01 * t).collect();
        let normal = vec![200.0; time.len()];
        let proto = Protocol {
            control: Control::Slip,
            time: &time,
            imposed: &imposed,
            normal: &normal,
            initial_slip: 0.0,
            initial: Initial::Rest,
        };
        let base = Model::base(Params::sample()).unwrap();
        let (index, _) = crate::terms::family_named("time-trend").unwrap();
        let mut trend = crate::terms::TermEffect::new(index, 0);
        trend.p[0] = 2e-5;
        let with = Model {
            ext: Extensions {
                terms: crate::terms::Terms::one(trend),
            },
            ..base
        };
        let a = simulate(&base, &proto).unwrap();
        let b = simulate(&with, &proto).unwrap();
        // From 10 mm of slip on the contact slides steadily (κ s ≫ 1, ũ s ≫ 1).
        for i in (2000..time.len()).step_by(100) {
            let expected = 200.0 * 2e-5 * time[i];
            let got = b.shear[i] - a.shear[i];
            assert!(
                (got - expected).abs() < 1e-3 * expected,
                "t {}: {got} vs {expected}",
                time[i]
            );
        }
    }

    #[test]
    fn first_guesses_scale_with_the_duration() {
        let data = |duration_s| DataScales {
            v_ref: 0.01,
            p_ref: 100.0,
            slip_span_mm: 5.0,
            duration_s,
            holds: 0,
            reversals: 0,
            pressure_levels: 1,
            sliding_rates: 1,
            traction_tests: 0,
            healing_per_decade: None,
            steps: crate::terms::StepReading::default(),
            rate_and_state: None,
            stress_trend: Default::default(),
            slip_slope_per_mm: None,
        };
        let short = TimeTrend.guess(0, &data(100.0));
        let long = TimeTrend.guess(0, &data(10_000.0));
        // Each start changes friction by the same amount over its test.
        assert!((short.starts[0][0] * 100.0 - long.starts[0][0] * 10_000.0).abs() < 1e-15);
        assert!(!TimeTrend.applies(&data(0.0)));
    }
}
