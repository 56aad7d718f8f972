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

use super::{
    DataScales, FormGuess, Shows, TermEvidence, TermFile, TermForm, TermGuess, TermLaw, TermParam,
    ANY, MAX_TERM_PARAMS,
};

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

impl TermLaw for TimeTrend {
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

    fn term(&self, form: usize, p: &[f64; MAX_TERM_PARAMS], _s: f64, t: f64) -> (f64, f64) {
        // Neither form depends on slip: the slope in s is zero.
        if form == LINEAR {
            (p[0] * t, 0.0)
        } else {
            (p[1] * -(-t / p[2]).exp_m1(), 0.0)
        }
    }
}

impl TermFile for TimeTrend {}

impl TermGuess for TimeTrend {
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
}

impl TermEvidence for TimeTrend {
    fn shows(&self) -> &'static [Shows] {
        &[Shows::AfterFirstLoading]
    }

    fn tried_by_default(&self) -> bool {
        false
    }

    fn applies(&self, data: &DataScales) -> bool {
        data.duration_s > 0.0
    }
}

#[cfg(test)]
mod tests;
