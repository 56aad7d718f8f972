//! Run-in, a demonstration family with a state, compiled only for the model's own tests (it
//! is registered under `#[cfg(test)]`): it shows that a family whose friction depends on its
//! history is one folder plus the registry line, and its tests check that the integrator
//! carries its state as its law says.
//!
//! A fresh interface carries an extra friction g that sliding wears off over a slip L and that
//! rest brings back over a time t_r. Its state φ ∈ [0, 1], the share of that friction left,
//! follows
//!
//! - φ̇ = −φ λ̇ / L while the contact slides (λ the plastic slip): φ = φ₀ e^(−Δs/L) over a slide;
//! - φ̇ = (1 − φ) / t_r at rest: φ = 1 − (1 − φ₀) e^(−Δt/t_r) over a hold;
//!
//! and adds G = g φ to the friction on top of μ. Both laws integrate in closed form over a step,
//! so a slide followed by a hold has a closed form the tests check.

use super::{
    DataScales, FormGuess, Shows, StateFamily, StateLaw, StateTerms, StateVar, TermEvidence,
    TermFile, TermForm, TermGuess, TermLaw, TermParam, ANY, MAX_TERM_PARAMS,
};

/// The run-in family (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct RunIn;

const G: usize = 0;
const L: usize = 1;
const T_R: usize = 2;

const PARAMS: [TermParam; 3] = [
    TermParam {
        key: "run_in.g",
        name: "g",
        unit: "",
        log_scale: false,
        bounds: (0.0, 0.3),
        default: 0.0,
        expected: "a finite friction",
        within: ANY,
        reference: false,
    },
    TermParam {
        key: "run_in.l",
        name: "l",
        unit: "mm",
        log_scale: true,
        bounds: (1e-3, 10.0),
        default: 1.0,
        expected: "a finite slip > 0 [mm]",
        within: ANY,
        reference: false,
    },
    TermParam {
        key: "run_in.t_r",
        name: "t_r",
        unit: "s",
        log_scale: true,
        bounds: (1.0, 1e6),
        default: 100.0,
        expected: "a finite time > 0 [s]",
        within: ANY,
        reference: false,
    },
];

const FORMS: [TermForm; 1] = [TermForm {
    key: "exponential",
    describe: "run-in friction g phi, worn off over a slip l, back over a time t_r",
    params: &[G, L, T_R],
}];

/// Its one state variable: φ, the share of the run-in friction left.
const PHI: usize = 0;

const VARS: [StateVar; 1] = [StateVar {
    name: "run_in",
    describe: "share of the run-in friction left, in [0, 1]",
}];

impl TermLaw for RunIn {
    fn name(&self) -> &'static str {
        "run-in"
    }

    fn describe(&self) -> &'static str {
        "run-in: a friction of a fresh interface that sliding wears off and rest brings back"
    }

    fn params(&self) -> &'static [TermParam] {
        &PARAMS
    }

    fn forms(&self) -> &'static [TermForm] {
        &FORMS
    }

    fn adds_term(&self) -> bool {
        // Its friction comes through its state, not as a term T(s, t).
        false
    }
}

impl TermFile for RunIn {}

impl TermGuess for RunIn {
    fn guess(&self, _form: usize, _data: &DataScales) -> FormGuess {
        FormGuess {
            starts: vec![vec![0.05, 1.0, 100.0]],
            neutral: vec![0.0, 1.0, 100.0],
            bounds: Vec::new(),
            references: Vec::new(),
        }
    }
}

impl TermEvidence for RunIn {
    fn shows(&self) -> &'static [Shows] {
        &[Shows::FirstLoadings, Shows::Holds]
    }

    fn tried_by_default(&self) -> bool {
        false
    }

    fn applies(&self, _data: &DataScales) -> bool {
        // A demonstration: the diagnosis never tries it.
        false
    }
}

/// Run-in's law for its parameters ([`StateFamily::law`]).
#[derive(Clone, Copy, Debug)]
pub struct RunInLaw {
    /// g, the run-in friction of a fresh interface.
    g: f64,
    /// L, the slip that wears it off (e-fold) [mm].
    l: f64,
    /// t_r, the time rest brings it back over (e-fold) [s].
    t_r: f64,
}

impl StateFamily for RunIn {
    type Law = RunInLaw;

    fn law(&self, _form: usize, p: &[f64; MAX_TERM_PARAMS]) -> RunInLaw {
        RunInLaw {
            g: p[G],
            l: p[L],
            t_r: p[T_R],
        }
    }
}

impl StateLaw for RunInLaw {
    fn vars(&self) -> &'static [StateVar] {
        &VARS
    }

    fn initial(&self, x: &mut [f64]) {
        // A fresh interface: the whole run-in friction.
        x[PHI] = 1.0;
    }

    fn steady(&self, _v: f64, x: &mut [f64]) {
        // Steady sliding has worn it all off (φ̇ = 0 while sliding only at φ = 0).
        x[PHI] = 0.0;
    }

    fn invalid(&self, x: &[f64]) -> Option<(usize, &'static str)> {
        (!(0.0..=1.0).contains(&x[PHI])).then_some((PHI, "a share in [0, 1]"))
    }

    fn rest(&self, x: &mut [f64], dt: f64) -> Option<f64> {
        x[PHI] = 1.0 - (1.0 - x[PHI]) * (-dt / self.t_r).exp();
        None
    }

    fn at_rest(&self, x: &[f64]) -> StateTerms {
        StateTerms {
            own: self.g * x[PHI],
            ..StateTerms::NONE
        }
    }

    fn slide(&self, start: &[f64], _dt: f64, lam: f64, end: &mut [f64]) -> StateTerms {
        self.settle(start, lam, end);
        StateTerms {
            own: self.g * end[PHI],
            down: -self.g * end[PHI] / self.l,
            ..StateTerms::NONE
        }
    }

    fn settle(&self, start: &[f64], lam: f64, end: &mut [f64]) {
        end[PHI] = start[PHI] * (-lam / self.l).exp();
    }
}

#[cfg(test)]
mod tests;
